"""Progress of a breaker's phases: a callback in library use, bars on stderr in ``crack``.

A breaker tells its progress through the :class:`~.base.Deadline` of the call
(:meth:`~.base.Deadline.report`): ``progress(phase, done, total)`` after each unit of work (for
the index calculus: each residue sieved in ``"relations"``, each pivot of the structured
elimination, the dense elimination as one unit). Library calls pass no callback and are silent.
:class:`PhaseBars` draws one tqdm bar per phase on stderr; its time left is the phase's average
rate so far applied to the units left (``smoothing=0``), never a guess, and a phase whose total
is unknown, or that cannot report from inside (FLINT's dense elimination), shows its elapsed
time and rate only.

A callback may raise ``KeyboardInterrupt`` (as Ctrl-C does): the breaker stops at that point,
and the index calculus hands what it has collected to the caller
(:class:`~.precomputation_file.PrecomputationInterrupted`).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any, TextIO

from .._validation import format_value
from ..errors import ParameterError

__all__ = ["ProgressCallback", "PhaseBars", "check_progress"]

#: ``progress(phase, done, total)``: ``done`` units of ``total`` (``None``: unknown) of ``phase``.
ProgressCallback = Callable[[str, float, "float | None"], None]


def check_progress(progress: Any) -> ProgressCallback | None:
    """``progress`` if it is ``None`` or callable, else :class:`~encctl_gym.errors.ParameterError`."""
    if progress is not None and not callable(progress):
        raise ParameterError(f"progress must be a callable progress(phase, done, total) or None, got {format_value(progress)}")
    return progress


class PhaseBars:
    """One tqdm bar per phase (a new phase closes the previous bar, which stays on screen).

    Use as ``progress=`` of :meth:`~.base.Breaker.precompute`; :meth:`close` the last bar at the
    end (also when the work stopped with an exception).

    Parameters
    ----------
    file : text stream, optional
        Where the bars go (default ``sys.stderr``).
    prefix : str
        Put before every phase name (``"index-calculus "``).
    """

    def __init__(self, file: TextIO | None = None, prefix: str = "") -> None:
        self.file = file
        self.prefix = prefix
        self.phase: str | None = None
        self._bar: Any = None

    def __call__(self, phase: str, done: float, total: float | None = None) -> None:
        if phase != self.phase or self._bar is None:
            self._open(phase, total)
        elif total is not None and self._bar.total != total:  # a new target in the same phase
            self._bar.total = total
            self._bar.refresh()
        bar = self._bar
        if bar.total is not None and done > bar.total:  # the last unit overshot the target
            bar.total = done
        if done > bar.n:
            bar.update(done - bar.n)

    def _open(self, phase: str, total: float | None) -> None:
        from tqdm.auto import tqdm

        self.close()
        self.phase = phase
        self._bar = tqdm(
            total=total,
            desc=f"{self.prefix}{phase}",
            file=self.file if self.file is not None else sys.stderr,
            smoothing=0.0,  # the rate over the whole phase so far
            leave=True,
            dynamic_ncols=True,
        )

    def close(self) -> None:
        """Close the current bar (if any)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        self.phase = None
