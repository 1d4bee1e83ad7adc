"""Independent seeded tasks on joblib (processes) or a Dask cluster, and the seeds they get.

Infrastructure below every layer that runs sweeps: the Monte Carlo engine
(:mod:`encctl_gym.sim`), the key breakers' ``crack`` command and the experiments all spread
their tasks with :func:`run_tasks`.

Every task ``i`` of a sweep receives its own child seed, ``SeedSequence(seed).spawn(n)[i]``
(computed without mutating anything), so a result depends on ``seed`` and the task list only,
never on the number of workers, the backend or the order in which tasks finish. This is what
lets the Monte Carlo runs of the paper's figures (Figures fig:variance_ratio and fig:gramian)
be reproduced bit for bit from one integer on a laptop or a cluster.

Backends (the ``scheduler`` argument):

* ``None``: joblib on the local machine, processes (``loky``) by default;
* ``"local"``: start a :class:`dask.distributed.LocalCluster` for the duration of the call;
* ``"tcp://host:port"`` (or any Dask scheduler address): connect a
  :class:`dask.distributed.Client` to a running scheduler;
* a :class:`dask.distributed.Client` instance: use it as is.

Dask is optional (``pip install 'encctl-gym[dask]'``); it is imported only when asked for.
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import Any, TypeVar

import numpy as np

from ._validation import check_int, format_value
from .errors import ConfigError, ParameterError
from .resources import check_memory

__all__ = ["SeedLike", "as_seed_sequence", "child_seeds", "check_n_jobs", "check_scheduler", "run_tasks"]

SeedLike = int | np.integer | np.random.SeedSequence
"""An integer seed or a :class:`numpy.random.SeedSequence`."""


def as_seed_sequence(seed: SeedLike) -> np.random.SeedSequence:
    """Return ``seed`` as a :class:`numpy.random.SeedSequence`.

    Parameters
    ----------
    seed
        A non-negative integer or a ``SeedSequence`` (returned unchanged).

    Returns
    -------
    numpy.random.SeedSequence
    """
    if isinstance(seed, np.random.SeedSequence):
        return seed
    return np.random.SeedSequence(check_int("seed", seed, minimum=0))


#: Bytes one child :class:`numpy.random.SeedSequence` takes (measured: about 370; rounded up).
SEED_BYTES = 512


def check_n_jobs(n_jobs: Any) -> int:
    """``n_jobs`` of :func:`run_tasks`: ``-1`` (all cores) or a count ``>= 1``.

    Raises
    ------
    ParameterError
        For anything else (0, -5, 2.5, a string, a bool).
    """
    n_jobs = check_int("n_jobs", n_jobs)
    if n_jobs == 0 or n_jobs < -1:
        raise ParameterError(f"n_jobs must be -1 (all cores) or >= 1, got {format_value(n_jobs)}")
    return n_jobs


def check_scheduler(scheduler: Any) -> Any:
    """A ``scheduler`` of :func:`run_tasks`, checked before any work: ``None``, ``"local"``, a Dask
    scheduler address (``"tcp://host:8786"``: a location after ``protocol://``) or a
    ``distributed.Client``.

    Raises
    ------
    ParameterError
        For anything else (``"tcp://"`` alone, a string without ``://``, another object).
    """
    if scheduler is None:
        return None
    if isinstance(scheduler, str):
        if scheduler == "local":
            return scheduler
        if "://" not in scheduler:
            raise ParameterError(
                f"scheduler must be 'local' or a Dask scheduler address like 'tcp://host:8786', got {format_value(scheduler)}"
            )
        if not scheduler.partition("://")[2]:
            raise ParameterError(f"scheduler address {format_value(scheduler)} names no host:port after its protocol")
        return scheduler
    try:  # an object can be a Client only where distributed is installed
        from distributed import Client

        is_client = isinstance(scheduler, Client)
    except ImportError:
        is_client = False
    if not is_client:
        raise ParameterError(
            f"scheduler must be None, 'local', a Dask scheduler address or a distributed.Client, got {format_value(scheduler)}"
        )
    return scheduler


#: How long to wait for a remote Dask scheduler before giving up.
CONNECT_TIMEOUT = "10s"

T = TypeVar("T")
R = TypeVar("R")


def child_seeds(seed: SeedLike, n: int) -> list[np.random.SeedSequence]:
    """The ``n`` child seeds ``SeedSequence(seed).spawn(n)``, without mutating ``seed``.

    Parameters
    ----------
    seed
        Integer or :class:`numpy.random.SeedSequence`.
    n
        Number of children (>= 0).

    Returns
    -------
    list of numpy.random.SeedSequence
        Child ``i`` has spawn key ``seed.spawn_key + (i,)``; identical to what
        ``SeedSequence(seed).spawn(n)`` returns on a fresh sequence, but calling this twice
        gives the same children.
    """
    ss = as_seed_sequence(seed)
    n = check_int("n", n, minimum=0)
    check_memory(f"n = {format_value(n)} child seeds", SEED_BYTES * n, advice="spawn fewer children")
    return [np.random.SeedSequence(ss.entropy, spawn_key=(*ss.spawn_key, i), pool_size=ss.pool_size) for i in range(n)]


def _import_distributed() -> Any:
    try:
        import distributed  # noqa: F401
        from distributed import Client, LocalCluster  # noqa: F401
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ConfigError(
            "the Dask scheduler needs the optional dependency dask[distributed]; install it with: pip install 'encctl-gym[dask]'"
        ) from exc
    return distributed


@contextlib.contextmanager
def _dask_client(scheduler: Any, n_jobs: int, cluster_kwargs: dict[str, Any] | None) -> Iterator[Any]:
    distributed = _import_distributed()
    if isinstance(scheduler, distributed.Client):
        yield scheduler
        return
    if scheduler == "local":
        kwargs: dict[str, Any] = {
            "n_workers": n_jobs if n_jobs > 0 else None,
            "threads_per_worker": 1,
            "processes": True,
            "dashboard_address": None,
            "silence_logs": logging.ERROR,
        }
        kwargs.update(cluster_kwargs or {})
        with distributed.LocalCluster(**kwargs) as cluster, distributed.Client(cluster) as client:
            yield client
        return
    # an address: check_scheduler (run_tasks) has refused everything else
    if cluster_kwargs:
        raise ParameterError("cluster_kwargs only apply to scheduler='local'")
    try:
        client = distributed.Client(scheduler, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError) as exc:
        raise ConfigError(f"cannot connect to the Dask scheduler at {scheduler!r}: {exc}") from exc
    with client:
        yield client


def run_tasks(
    func: Callable[[T, np.random.SeedSequence], R],
    tasks: Sequence[T],
    *,
    seed: SeedLike,
    n_jobs: int = -1,
    scheduler: Any = None,
    backend: str = "loky",
    cluster_kwargs: dict[str, Any] | None = None,
    progress: bool = False,
    desc: str | None = None,
) -> list[R]:
    """Run ``func(task, child_seed)`` for every task, in parallel, with one child seed per task.

    Parameters
    ----------
    func
        A picklable (module-level) function of a task and a
        :class:`numpy.random.SeedSequence`. It must draw all its randomness from that seed.
    tasks
        The task descriptions (picklable).
    seed
        Integer or :class:`numpy.random.SeedSequence`; task ``i`` gets
        ``child_seeds(seed, len(tasks))[i]``.
    n_jobs
        Workers for joblib (``-1``: all cores; ``1``: run in this process). With
        ``scheduler="local"`` the number of Dask workers (``-1``: Dask's default).
    scheduler
        ``None`` (joblib locally), ``"local"`` (a temporary Dask ``LocalCluster``), a Dask
        scheduler address (``"tcp://host:port"``) or a ``distributed.Client``.
    backend
        joblib backend when ``scheduler`` is ``None``: ``"loky"`` (processes, default),
        ``"threading"`` or ``"multiprocessing"``.
    cluster_kwargs
        Extra keyword arguments for the ``LocalCluster`` (e.g. ``{"processes": False}``).
    progress
        Show a tqdm progress bar (on stderr).
    desc
        Label of the progress bar.

    Returns
    -------
    list
        ``[func(tasks[0], s_0), func(tasks[1], s_1), ...]`` in task order, identical whatever
        the backend and the number of workers.

    Raises
    ------
    ParameterError
        On a bad ``n_jobs``, ``backend`` or ``scheduler``.
    ConfigError
        If Dask is requested but not installed, or the scheduler cannot be reached.
    """
    import joblib
    from tqdm.auto import tqdm

    if not callable(func):
        raise ParameterError(f"func must be a function of a task and a seed, got {format_value(func)}")
    if isinstance(tasks, (str, bytes)) or not isinstance(tasks, Iterable):
        raise ParameterError(f"tasks must be a sequence of task descriptions, got {format_value(tasks)}")
    tasks = list(tasks)
    n_jobs = check_n_jobs(n_jobs)
    scheduler = check_scheduler(scheduler)
    if backend not in ("loky", "threading", "multiprocessing"):
        raise ParameterError(f"backend must be 'loky', 'threading' or 'multiprocessing', got {format_value(backend)}")
    seeds = child_seeds(seed, len(tasks))
    bar = tqdm(total=len(tasks), desc=desc, disable=not progress, leave=False)
    results: list[R] = []
    try:
        if scheduler is None and (n_jobs == 1 or len(tasks) <= 1):
            for task, s in zip(tasks, seeds):
                results.append(func(task, s))
                bar.update()
            return results
        calls = (joblib.delayed(func)(task, s) for task, s in zip(tasks, seeds))
        if scheduler is None:
            parallel = joblib.Parallel(n_jobs=n_jobs, backend=backend, return_as="generator")
            for r in parallel(calls):
                results.append(r)
                bar.update()
            return results
        with _dask_client(scheduler, n_jobs, cluster_kwargs) as client:
            with joblib.parallel_config(backend="dask", client=client):
                parallel = joblib.Parallel(n_jobs=-1, return_as="generator")
                for r in parallel(calls):
                    results.append(r)
                    bar.update()
        return results
    finally:
        bar.close()
