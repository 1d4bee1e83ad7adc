"""The work of an episode that may run beside its step: process noise drawn ahead in chunks and
the Gram matrices brought up to date, on the environment's helper thread
(:class:`~encctl_gym.envs.helper.HelperThread`) or, without one, in place.

:class:`HelperWork` is a mixin of :class:`~encctl_gym.envs.episode.EpisodeCore`: the methods
read and write the episode's arrays (its noise buffers, ``X``, ``U`` and ``[G | C]``), which
the episode allocates. Moving the work to the helper changes where it runs, never what it
computes (the noise chunks are drawn in order from each copy's generator; Gram columns are
final when handed over).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import Future
from typing import Any

import numpy as np

from . import _kernels as kern
from .helper import HelperThread
from .schedule import EpisodeSchedule

__all__ = ["HelperWork"]


class HelperWork:
    """Noise ahead and Gram catch-up for an episode (module docstring); attributes are the episode's."""

    helper: HelperThread | None
    schedule: EpisodeSchedule
    X: np.ndarray
    U: np.ndarray
    _GC: np.ndarray
    _gram_scratch: np.ndarray
    gram_upto: int
    dims: Any
    _noise_future: Future | None
    _gram_future: Future | None
    _given_noise: np.ndarray | None
    _rngs: Sequence[np.random.Generator]
    _noise_draws: np.ndarray
    _sw: float
    _noise: np.ndarray
    _noise_next: np.ndarray
    _noise_ahead: bool
    _noise_pos: int
    _chunks: int
    _periods: int

    # ----------------------------------------------------------------- helper thread
    def _run(self, fn: Callable[..., Any], *args: Any) -> Future | None:
        """``fn(*args)`` on the helper thread (returns its future) or, without one, now."""
        if self.helper is not None:
            return self.helper.submit(fn, *args)
        fn(*args)
        return None

    def _wait_noise(self) -> None:
        if self._noise_future is not None:
            future, self._noise_future = self._noise_future, None
            future.result()  # re-raises what the helper raised

    def _wait_gram(self) -> None:
        if self._gram_future is not None:
            future, self._gram_future = self._gram_future, None
            future.result()

    def wait(self) -> None:
        """Wait for the helper thread's work on this episode (noise drawn ahead, Gram catch-up)."""
        self._wait_noise()
        self._wait_gram()

    # ----------------------------------------------------------------- randomness
    def _fill_noise(self, dst: np.ndarray, chunk: int) -> None:
        """Noise chunk ``chunk`` (``schedule.chunk`` periods) of every copy, into ``dst`` (C, K, n):
        drawn from each copy's generator (chunks are drawn in order), or read from the noise
        given to :meth:`reset`."""
        if self._given_noise is not None:
            C = dst.shape[0]
            part = self._given_noise[:, chunk * C : (chunk + 1) * C]
            dst[: part.shape[1]] = part.transpose(1, 0, 2)
            dst[part.shape[1] :] = 0.0  # past the episode's last period: never read
            return
        for i, rng in enumerate(self._rngs):
            rng.standard_normal(out=self._noise_draws[i])
        kern.interleave_noise(self._noise_draws, self._sw, dst)

    def _take_chunk(self) -> None:
        """Take the next noise chunk into use (the one drawn ahead, else draw it now), then draw
        the one after it ahead if the episode will reach it."""
        if self._noise_ahead:
            self._wait_noise()
            self._noise, self._noise_next = self._noise_next, self._noise
        else:
            self._fill_noise(self._noise, self._chunks)
        self._chunks += 1
        self._noise_pos = 0
        self._noise_ahead = self._chunks * self.schedule.chunk < self._periods
        if self._noise_ahead:
            self._noise_future = self._run(self._fill_noise, self._noise_next, self._chunks)

    def _draw_noise(self) -> np.ndarray:
        if self._noise_pos >= self.schedule.chunk:
            self._take_chunk()
        w = self._noise[self._noise_pos]
        self._noise_pos += 1
        return w

    # ----------------------------------------------------------------- Gram catch-up
    def _sync_gram(self, upto: int) -> None:
        """Bring G and C up to the columns j < ``upto`` (the fused step leaves them behind)."""
        self._wait_gram()
        if upto > self.gram_upto:
            kern.add_gram(self.dims, self.X, self.U, self.gram_upto, upto, self._GC, self._gram_scratch)
            self.gram_upto = upto

    def gram_behind(self, upto: int) -> None:
        """Hand the Gram catch-up of the columns j < ``upto`` to the helper thread, unless it
        is still busy with the previous one. The columns are final: rows of X and U only ever
        get written once, ahead of the columns that read them."""
        assert self.helper is not None
        if self._gram_future is not None:
            if not self._gram_future.done():
                return
            self._wait_gram()
        first, self.gram_upto = self.gram_upto, upto
        self._gram_future = self.helper.submit(
            kern.add_gram, self.dims, self.X, self.U, first, upto, self._GC, self._gram_scratch
        )
