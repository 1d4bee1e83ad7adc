"""Breaking a whole dynamic-key sequence h_1, ..., h_N, and the measured deciphering time.

:func:`break_sequence` runs a breaker's precomputation once and then breaks the keys of one
dynamic-key sequence (Example ex:dyn_elgamal: one group, N secrets) in order, serially, or
spread over workers with :func:`encctl_gym.parallel.run_tasks` (joblib processes or a Dask
cluster: the precomputation is shipped once per chunk of keys, each chunk gets its own child
seed). The :class:`BreakReport` keeps the precomputation's cost apart from the per-key costs,
so the measured sample deciphering time

    tau(N) = T_pre + t_1 + ... + t_N

can be set against Definition def:sdt's ``tau(N, lambda) = N 2^lambda / Upsilon``, i.e. N times
the cost of one key broken from scratch.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Iterable
from typing import Any

import numpy as np

from .._validation import check_bool, check_int, format_value
from ..crypto import arith
from ..crypto.group import GroupParams
from ..errors import ParameterError
from ..parallel import check_n_jobs, check_scheduler
from .base import Breaker, Cost, Precomputation, RecoveredKey, as_list, check_element
from .progress import PhaseBars
from .registry import get_breaker

__all__ = ["BreakReport", "break_sequence"]


@dataclasses.dataclass
class BreakReport:
    """The result of :func:`break_sequence`.

    Attributes
    ----------
    breaker : str
        Registry name.
    group : GroupParams
        The group attacked.
    precomputation : Cost
        Cost of the precomputation (once for the sequence).
    keys : list of RecoveredKey
        One per public-key element, in order, each checked (g^s = h).
    """

    breaker: str
    group: GroupParams
    precomputation: Cost
    keys: list[RecoveredKey]

    @property
    def secrets(self) -> list[int]:
        """The recovered exponents s_1, ..., s_N."""
        return [k.s for k in self.keys]

    def key_seconds(self, clock: str = "wall") -> np.ndarray:
        """Per-key times t_1, ..., t_N (precomputation excluded): ``clock="wall"`` (default) or
        ``"cpu"`` (this process's CPU time, see :class:`~.base.Cost`)."""
        attr = _clock(clock)
        return np.array([getattr(k.cost, attr) for k in self.keys], dtype=float)

    def tau(self, clock: str = "wall") -> np.ndarray:
        """The measured deciphering time of the first N keys, ``T_pre + t_1 + ... + t_N``, for
        N = 1, ..., len(keys) (``clock`` as in :meth:`key_seconds`)."""
        return getattr(self.precomputation, _clock(clock)) + np.cumsum(self.key_seconds(clock))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: group, breaker, precomputation cost and per-key records (exponents in hex)."""
        return {
            "breaker": self.breaker,
            "group": self.group.to_dict(),
            "precomputation": self.precomputation.to_dict(),
            "keys": [
                {"t": i, "h": hex(k.h), "s": hex(k.s), "method": k.method, **k.cost.to_dict()} for i, k in enumerate(self.keys)
            ],
            "total_seconds": float(self.tau()[-1]) if self.keys else self.precomputation.seconds,
        }


def _clock(clock: str) -> str:
    if clock not in ("wall", "cpu"):
        raise ParameterError(f"clock must be 'wall' or 'cpu', got {clock!r}")
    return "seconds" if clock == "wall" else "cpu_seconds"


def _break_chunk(task: tuple[Precomputation, list[int], float | None], seed: np.random.SeedSequence) -> list[RecoveredKey]:
    # One task of the parallel path: a copy of the precomputation and a run of consecutive keys.
    pre, hs, time_limit = task
    rng = arith.seeded_random(int(seed.generate_state(1, np.uint64)[0]))
    return [pre.break_key(h, time_limit=time_limit, rng=rng) for h in hs]


def break_sequence(
    breaker: Any,
    group: GroupParams,
    hs: Iterable[int],
    *,
    tokens: Iterable[Any] | None = None,
    pre: Precomputation | None = None,
    time_limit: float | None = None,
    progress: bool = False,
    scheduler: Any = None,
    n_jobs: int = 1,
    chunks: int | None = None,
    seed: int | np.random.SeedSequence = 0,
) -> BreakReport:
    """Break the public-key elements ``hs`` of one group with one precomputation.

    Parameters
    ----------
    breaker : str or Breaker
        A registry name (built with defaults) or a breaker instance.
    group : GroupParams
        The group of every key.
    hs : iterable of int
        The public-key elements h_1, ..., h_N (checked to lie in G before any work).
    tokens : iterable, optional
        Update tokens, for the ``token-chain`` breaker only.
    pre : Precomputation, optional
        A precomputation of this breaker and group to reuse (its cost is reported again).
    time_limit : float, optional
        Seconds allowed for the precomputation and for each key.
    progress : bool
        Show tqdm progress bars on stderr: the phases of the precomputation
        (:class:`~.progress.PhaseBars`) and the keys.
    scheduler : None, "local", address or distributed.Client
        Run the per-key work through :func:`~encctl_gym.parallel.run_tasks` (with ``n_jobs``):
        ``None`` and ``n_jobs == 1`` break the keys in this process, in order.
    n_jobs : int
        Workers of the parallel path (``-1``: all cores, else >= 1).
    chunks : int, optional
        Number of tasks of the parallel path, >= 1 (default: the number of workers); each
        carries a copy of the precomputation and a run of consecutive keys.
    seed : int or numpy.random.SeedSequence
        Seed (>= 0) of the parallel path's per-task randomness.

    Returns
    -------
    BreakReport

    Raises
    ------
    KeyMismatchError
        If a key is not in G of ``group``.
    ParameterError
        If tokens are given to a breaker that does not use them, or on bad options (checked
        before the precomputation, whichever path the options serve).
    """
    from tqdm.auto import tqdm

    breaker = get_breaker(breaker) if isinstance(breaker, str) else breaker
    if not isinstance(breaker, Breaker):
        raise ParameterError(f"breaker must be a registry name or a Breaker, got {format_value(breaker)}")
    if not isinstance(group, GroupParams):
        raise ParameterError(f"group must be a GroupParams, got {format_value(group)}")
    hs = [check_element(group, h) for h in as_list("hs", hs, "public-key elements")]
    if tokens is not None:
        tokens = as_list("tokens", tokens, "update tokens")
    # Every option is checked before the precomputation, which may be the expensive part.
    n_jobs = check_n_jobs(n_jobs)
    if chunks is not None:
        chunks = check_int("chunks", chunks, minimum=1)
    if not isinstance(seed, np.random.SeedSequence):
        seed = check_int("seed", seed, minimum=0)
    check_scheduler(scheduler)
    if breaker.MAIN_THREAD_ONLY and scheduler is not None:
        raise ParameterError(
            f"breaker {breaker.name!r} runs only in a process's main thread and Dask runs tasks in threads: "
            "break its keys without a scheduler"
        )
    progress = check_bool("progress", progress)
    pre = _precomputation(breaker, group, pre, time_limit=time_limit, progress=progress)
    if tokens is not None:
        if not hasattr(pre, "add_tokens"):
            raise ParameterError(f"update tokens are used only by the token-chain breaker, not by {breaker.name!r}")
        pre.add_tokens(tokens)
    if scheduler is None and n_jobs == 1:
        keys = []
        for h in tqdm(hs, desc=f"{breaker.name} keys", disable=not progress, leave=False):
            keys.append(breaker.break_key(h, pre, time_limit=time_limit))
        return BreakReport(breaker.name, group, pre.cost, keys)
    keys = _break_in_tasks(
        breaker, pre, hs, time_limit, scheduler=scheduler, n_jobs=n_jobs, chunks=chunks, seed=seed, progress=progress
    )
    return BreakReport(breaker.name, group, pre.cost, keys)


def _precomputation(
    breaker: Breaker, group: GroupParams, pre: Precomputation | None, *, time_limit: float | None, progress: bool
) -> Precomputation:
    """The group's precomputation: ``pre`` checked to be of this breaker and group, or computed
    (with the phases' progress bars when asked)."""
    if pre is None:
        bars = PhaseBars(prefix=f"{breaker.name} ") if progress else None
        try:
            pre = breaker.precompute(group, time_limit=time_limit, progress=bars)
        finally:
            if bars is not None:
                bars.close()
    elif not isinstance(pre, Precomputation):
        raise ParameterError(f"pre must be a Precomputation, got {format_value(pre)}")
    elif pre.breaker != breaker.name or pre.group != group:
        raise ParameterError(f"pre is a precomputation of {pre.breaker!r} for another group or breaker")
    return pre


def _break_in_tasks(
    breaker: Breaker,
    pre: Precomputation,
    hs: list[int],
    time_limit: float | None,
    *,
    scheduler: Any,
    n_jobs: int,
    chunks: int | None,
    seed: int | np.random.SeedSequence,
    progress: bool,
) -> list[Any]:
    """The parallel path: runs of consecutive keys, each task with a copy of ``pre``, through
    :func:`~encctl_gym.parallel.run_tasks`; the keys in order."""
    from ..parallel import run_tasks

    workers = (os.cpu_count() or 1) if n_jobs == -1 else n_jobs
    n_chunks = max(1, min(len(hs), chunks if chunks is not None else workers))
    bounds = np.linspace(0, len(hs), n_chunks + 1).round().astype(int)
    tasks = [(pre, hs[a:b], time_limit) for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
    parts = run_tasks(
        _break_chunk, tasks, seed=seed, n_jobs=n_jobs, scheduler=scheduler, progress=progress, desc=f"{breaker.name} keys"
    )
    return [k for part in parts for k in part]
