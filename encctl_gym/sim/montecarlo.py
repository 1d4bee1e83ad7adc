"""Monte Carlo estimation errors of the paper's attacker, for one system or a sweep.

One task = one system: ``runs`` trajectories of length ``N_max`` under i.i.d. Gaussian attack
inputs (Theorem thm:sic), and the error ``epsilon(N)`` of Definition def:error on a whole grid
of sample sizes from each trajectory (:func:`~encctl_gym.ident.grid.identification_errors`),
by least squares (eq:estimate) or any estimator of :mod:`encctl_gym.ident.registry`.
A sweep spreads systems over workers with :func:`~encctl_gym.parallel.run_tasks`, one
child seed per system. :func:`error_summaries` summarizes the runs per sample size with
medians and quantiles, and flags the mean where the error's tail makes it infinite or
unreliable (:mod:`encctl_gym.ident.tails`: least squares has no mean error below
``N = n + m + 3``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from .._validation import check_int, check_nonnegative, format_value
from ..errors import ParameterError
from ..ident.estimator import check_grid
from ..ident.grid import identification_errors
from ..ident.least_squares import check_sample_sizes
from ..ident.registry import make_estimator
from ..ident.tails import ErrorSummary, error_tail_exponent, summarize_errors
from ..parallel import SeedLike, run_tasks
from ..resources import check_memory
from .plant import LinearPlant, simulate_gaussian_attack

__all__ = ["AttackSpec", "gaussian_attack_errors", "sweep_gaussian_attack", "log_grid", "error_summaries"]


_N_MAX = 2**53  # the grid is spaced in float64 and rounded: integers beyond 2^53 are not exact


def log_grid(N_min: int, N_max: int, points: int) -> np.ndarray:
    """A log-spaced grid of distinct integer sample sizes from ``N_min`` to ``N_max``.

    Parameters
    ----------
    N_min, N_max
        First and last sample size (``2 <= N_min <= N_max <= 2^53``: the grid is spaced in
        float64, exact for integers up to 2^53).
    points
        Requested number of points (>= 1); rounding may merge a few at the low end.

    Returns
    -------
    numpy.ndarray of int64
        Strictly increasing, starting at ``N_min`` and ending at ``N_max``.
    """
    N_min = check_int("N_min", N_min, minimum=2)
    N_max = check_int("N_max", N_max, minimum=N_min, maximum=_N_MAX)
    points = check_int("points", points, minimum=1)
    check_memory(f"a grid of points = {format_value(points)}", 3 * 8 * points, advice="ask for fewer points")
    if points == 1:
        return np.array([N_max], dtype=np.int64)
    return np.unique(np.round(np.geomspace(N_min, N_max, points)).astype(np.int64))


@dataclass(frozen=True)
class AttackSpec:
    """One system under the Gaussian attack of Theorem thm:sic (a picklable task).

    Attributes
    ----------
    A, B : numpy.ndarray
        The plant of eq:system.
    sigma_w2, sigma_u2, sigma_x2 : float
        Noise, attack-input and initial-state variances.
    """

    A: np.ndarray
    B: np.ndarray
    sigma_w2: float
    sigma_u2: float
    sigma_x2: float = 1.0


def gaussian_attack_errors(
    plant: LinearPlant,
    *,
    sample_sizes: Any,
    runs: int,
    sigma_u2: float,
    seed: SeedLike,
    method: Literal["auto", "gram", "qr"] = "auto",
    estimator: Any = None,
) -> np.ndarray:
    """Errors ``epsilon(N)`` (Definition def:error) of ``runs`` independent Gaussian attacks.

    Each run simulates one trajectory of length ``max(sample_sizes)`` with
    ``u_t ~ N(0, sigma_u2 I)`` (Theorem thm:sic) and identifies ``(A, B)`` on every prefix in
    ``sample_sizes``, by eq:estimate unless another estimator is given.

    Parameters
    ----------
    plant
        The plant of eq:system.
    sample_sizes : array_like of int
        Strictly increasing, each ``>= n + m + 1``.
    runs
        Number of independent identifications per sample size.
    sigma_u2
        Attack input variance.
    seed
        Integer or SeedSequence (see :func:`~encctl_gym.sim.plant.simulate_gaussian_attack`).
    method
        Least-squares solver for the prefix estimates (see
        :func:`~encctl_gym.ident.least_squares.prefix_estimates`); default estimator only.
    estimator : str, mapping or Estimator, optional
        Anything :func:`~encctl_gym.ident.registry.make_estimator` takes; ``None`` (default) is
        least squares with exactly the numbers of eq:estimate's grid
        (:func:`~encctl_gym.ident.grid.identification_errors`). The same seed gives
        the same trajectories whatever the estimator, so estimators compare on common data.

    Returns
    -------
    numpy.ndarray, shape (runs, len(sample_sizes))
        NaN where the estimator has no estimate.
    """
    if estimator is None:
        grid = check_sample_sizes(sample_sizes, plant.n, plant.m)
    else:
        estimator = make_estimator(estimator)
        grid = check_grid(estimator, sample_sizes, plant.n, plant.m)
    sim = simulate_gaussian_attack(plant, N=max(int(grid[-1]), 2), runs=runs, sigma_u2=sigma_u2, seed=seed)
    return identification_errors(sim.states, sim.inputs, plant.A, plant.B, grid, method=method, estimator=estimator)


def _task(job: tuple[AttackSpec, np.ndarray, int, str, Any], seed: np.random.SeedSequence) -> np.ndarray:
    spec, grid, runs, method, estimator = job
    plant = LinearPlant(spec.A, spec.B, sigma_w2=spec.sigma_w2, sigma_x2=spec.sigma_x2)
    return gaussian_attack_errors(
        plant,
        sample_sizes=grid,
        runs=runs,
        sigma_u2=spec.sigma_u2,
        seed=seed,
        method=method,  # type: ignore[arg-type]
        estimator=estimator,
    )


def sweep_gaussian_attack(
    systems: Sequence[AttackSpec],
    *,
    sample_sizes: Any,
    runs: int,
    seed: SeedLike,
    n_jobs: int = -1,
    scheduler: Any = None,
    cluster_kwargs: dict[str, Any] | None = None,
    method: Literal["auto", "gram", "qr"] = "auto",
    estimator: Any = None,
    progress: bool = False,
    desc: str | None = None,
) -> np.ndarray:
    """:func:`gaussian_attack_errors` for several systems, in parallel, one child seed each.

    Parameters
    ----------
    systems
        The systems (:class:`AttackSpec`).
    sample_sizes, runs, method, estimator
        As in :func:`gaussian_attack_errors` (the same grid and estimator for every system).
    seed
        System ``i`` uses child ``i`` of ``SeedSequence(seed)``; the result does not depend on
        ``n_jobs`` or ``scheduler``.
    n_jobs, scheduler, cluster_kwargs, progress, desc
        See :func:`~encctl_gym.parallel.run_tasks`.

    Returns
    -------
    numpy.ndarray, shape (len(systems), runs, len(sample_sizes))
    """
    systems = list(systems)
    if not systems:
        raise ParameterError("systems must not be empty")
    runs = check_int("runs", runs, minimum=1)
    if estimator is not None:
        estimator = make_estimator(estimator)  # refuse a bad estimator before any worker starts
    jobs = []
    for i, s in enumerate(systems):
        if not isinstance(s, AttackSpec):
            raise ParameterError(f"systems[{i}] must be an AttackSpec, got {type(s).__name__}")
        # Validate in the caller, so a bad system fails before any worker starts.
        plant = LinearPlant(s.A, s.B, sigma_w2=s.sigma_w2, sigma_x2=s.sigma_x2)
        check_nonnegative("sigma_u2", s.sigma_u2)
        if estimator is None:
            grid = check_sample_sizes(sample_sizes, plant.n, plant.m)
        else:
            grid = check_grid(estimator, sample_sizes, plant.n, plant.m)
        jobs.append((s, grid, runs, method, estimator))
    out = run_tasks(
        _task, jobs, seed=seed, n_jobs=n_jobs, scheduler=scheduler, cluster_kwargs=cluster_kwargs, progress=progress, desc=desc
    )
    return np.stack(out)


def error_summaries(errors: Any, sample_sizes: Any, *, n: int, m: int, estimator: Any = None) -> list[ErrorSummary]:
    """One :class:`~encctl_gym.ident.tails.ErrorSummary` per sample size of a Monte Carlo run.

    Each carries the median and quantiles, the mean and its standard error, and the status of
    the mean from the tail rule :func:`~encctl_gym.ident.tails.error_tail_exponent` (inputs with
    a density, as the Gaussian attack) and the Hill check: ``"does not exist"`` below
    ``N = n + m + 3`` for least squares, ``"unreliable"`` where the variance is infinite.

    Parameters
    ----------
    errors : array_like, shape (runs, len(sample_sizes))
        As returned by :func:`gaussian_attack_errors` (NaN: no estimate).
    sample_sizes : array_like of int
        The grid the errors were computed on.
    n, m : int
        Plant dimensions.
    estimator : optional
        The estimator the errors are of (``None``: least squares).

    Returns
    -------
    list of ErrorSummary
    """
    try:
        errors = np.asarray(errors, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"errors must be a numeric array, got {format_value(errors)}") from None
    grid = [check_int(f"sample_sizes[{k}]", v, minimum=2) for k, v in enumerate(np.asarray(sample_sizes, dtype=object).ravel())]
    if errors.ndim != 2 or errors.shape[1] != len(grid):
        raise ParameterError(
            f"errors must have shape (runs, {len(grid)}) for sample_sizes of length {len(grid)}, got {errors.shape}"
        )
    return [summarize_errors(errors[:, k], tail_exponent=error_tail_exponent(n, m, N, estimator)) for k, N in enumerate(grid)]
