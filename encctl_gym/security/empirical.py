"""An empirical sample identifying complexity, and the design that follows from it.

Theorem thm:sic gives a closed form ``gamma(N)`` below the expected least-squares error; for
other identification methods (subspace identification from outputs, :mod:`encctl_gym.ident.subspace`)
there is none. Definition def:sic only asks for a function of ``N`` that the expected error does
not fall below, so a Monte Carlo estimate of ``E[error](N)`` with its uncertainty can stand in:

1. :func:`fit_empirical_complexity` fits ``E[error](N) ~ c / N^a`` by least squares on the log
   of the per-``N`` mean error over ``R`` runs, and bootstraps the runs (whole runs, so the
   correlation of one run's errors along ``N`` is kept) for intervals of ``a`` and ``c``.
2. :func:`empirical_design` turns the fit into ``N*`` (the smallest ``N`` with
   ``c / N^a < gamma_c``, as eq:opt_sec does with eq:sic2), ``lambda*`` by eq:opt_sec and ``k*``
   by eq:opt_key under a deciphering-cost model, each with the interval the bootstrap carries to
   it. ``N*`` beyond the largest simulated ``N`` is an extrapolation of the fitted rate and is
   flagged as one.
3. Where the accuracy target is itself a Monte Carlo estimate (the output design moves
   ``gamma_c`` into another error measure by evaluating a second fit at the paper's ``N*``,
   :mod:`encctl_gym.security.output_design`), :func:`empirical_design` takes that fit as
   ``reference=(fit, N)``: every bootstrap replicate designs against its own replicate of the
   target. The two fits resample the same runs (same run count, replicates and seed), so the
   correlation of the two errors, measured on the same trajectories, is kept too.

Only sample sizes where the mean error exists should be fitted: at ``N <= n + m + 2`` the
least-squares error has no mean (the smallest eigenvalue of the Gram matrix has a density that
does not vanish at zero), so the default starts at ``N_min = 2 (n + m)``-like values chosen by
the caller; the fit refuses grids of fewer than three sizes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_positive
from ..errors import ParameterError, ShapeError
from .design import optimal_security_parameter
from .key_length import design_key_length
from .threat import ThreatModel

__all__ = ["EmpiricalComplexity", "EmpiricalDesign", "empirical_design", "fit_empirical_complexity", "paired"]


@dataclass(frozen=True)
class EmpiricalComplexity:
    """A fitted rate ``c / N^a`` of the mean error, with bootstrap intervals.

    Attributes
    ----------
    N : ndarray (G,)
        The fitted sample sizes.
    mean, low, high : ndarray (G,)
        Mean error per ``N`` and its bootstrap interval (the band).
    a, c : float
        The fitted exponent and constant.
    a_interval, c_interval : tuple of float
        Their bootstrap percentile intervals at ``level``.
    level : float
        Confidence level of the intervals.
    runs : int
        Number of runs behind every mean.
    boot_a, boot_c : ndarray (B,)
        The bootstrap replicates (for carrying the uncertainty to ``N*`` and ``k*``).
    seed : int
        Seed of the resampling: two fits of ``R`` runs with the same seed and ``B`` resampled
        the same runs in every replicate (:func:`paired`).
    """

    N: np.ndarray
    mean: np.ndarray
    low: np.ndarray
    high: np.ndarray
    a: float
    c: float
    a_interval: tuple[float, float]
    c_interval: tuple[float, float]
    level: float
    runs: int
    boot_a: np.ndarray
    boot_c: np.ndarray
    seed: int = 0

    def __call__(self, N: Any) -> Any:
        """The fitted mean error ``c / N^a``."""
        return self.c / np.asarray(N, dtype=float) ** self.a


def _fit_log(N: np.ndarray, mean: np.ndarray) -> tuple[float, float]:
    """``(a, c)`` of the least-squares line ``log mean = log c - a log N``."""
    X = np.column_stack([np.ones_like(N), -np.log(N)])
    coef = np.linalg.lstsq(X, np.log(mean), rcond=None)[0]
    return float(coef[1]), float(math.exp(coef[0]))


def fit_empirical_complexity(
    N: Any, errors: Any, *, level: float = 0.95, bootstrap: int = 1000, seed: int = 0
) -> EmpiricalComplexity:
    """Fit ``E[error](N) ~ c / N^a`` to Monte Carlo errors, with bootstrap intervals (step 1 of the
    module docstring).

    Parameters
    ----------
    N : array_like of int, shape (G,)
        Strictly increasing sample sizes (at least three).
    errors : array_like, shape (R, G)
        The error of each of ``R`` runs at each ``N`` (e.g.
        :func:`~encctl_gym.sim.montecarlo.gaussian_attack_errors`); positive and finite.
    level : float
        Confidence level of the intervals, in (0, 1).
    bootstrap : int
        Number of bootstrap resamples of the runs (>= 100).
    seed : int
        Seed of the resampling (fits of the same runs with the same seed are :func:`paired`).

    Returns
    -------
    EmpiricalComplexity

    Raises
    ------
    ParameterError, ShapeError
        For a grid of fewer than three sizes, a shape mismatch, non-positive errors or a bad level.
    """
    N = as_finite_array("N", N, ndim=1)
    errors = as_finite_array("errors", errors, ndim=2)
    if len(N) < 3 or np.any(np.diff(N) <= 0) or N[0] < 1:
        raise ParameterError(f"N must be at least three strictly increasing sample sizes >= 1, got {N.tolist()[:8]}")
    if errors.shape[1] != len(N):
        raise ShapeError(f"errors must have shape (runs, {len(N)}), got {errors.shape}")
    R = errors.shape[0]
    if R < 2:
        raise ParameterError(f"at least two runs are needed for an interval, got {R}")
    if np.any(errors <= 0):
        raise ParameterError("errors must be positive (the fit is on their logarithm)")
    level = check_positive("level", level)
    if not level < 1:
        raise ParameterError(f"level must lie in (0, 1), got {level}")
    B = check_int("bootstrap", bootstrap, minimum=100, maximum=10**6)
    seed = check_int("seed", seed, minimum=0)
    mean = errors.mean(axis=0)
    a, c = _fit_log(N, mean)
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, R, size=(B, R))
    boot_means = errors[idx].mean(axis=1)  # (B, G)
    fits = np.array([_fit_log(N, m) for m in boot_means])
    q = [(1 - level) / 2, (1 + level) / 2]
    lo, hi = np.quantile(boot_means, q, axis=0)
    a_lo, a_hi = np.quantile(fits[:, 0], q)
    c_lo, c_hi = np.quantile(fits[:, 1], q)
    return EmpiricalComplexity(
        N=N,
        mean=mean,
        low=lo,
        high=hi,
        a=a,
        c=c,
        a_interval=(float(a_lo), float(a_hi)),
        c_interval=(float(c_lo), float(c_hi)),
        level=level,
        runs=R,
        boot_a=fits[:, 0],
        boot_c=fits[:, 1],
        seed=seed,
    )


def paired(first: EmpiricalComplexity, second: EmpiricalComplexity) -> bool:
    """Whether the two fits' bootstrap replicates resampled the same runs (replicate ``b`` of one
    belongs with replicate ``b`` of the other): same number of runs, of replicates, and seed."""
    return first.runs == second.runs and len(first.boot_a) == len(second.boot_a) and first.seed == second.seed


@dataclass(frozen=True)
class EmpiricalDesign:
    """``N*``, ``lambda*`` and ``k*`` from an empirical complexity, each with its interval.

    ``extrapolated`` says that ``N*`` (or the top of its interval) lies beyond the largest
    simulated sample size: there the fitted rate, not a measurement, decides it. ``target`` and
    ``target_interval`` are the accuracy target and its bootstrap interval when it came from a
    reference fit (module docstring, step 3), else ``None``.
    """

    N_star: int
    N_star_interval: tuple[int, int]
    lambda_star: int
    lambda_star_interval: tuple[int, int]
    k_star: int
    k_star_interval: tuple[int, int]
    model: str
    extrapolated: bool
    target: float | None = None
    target_interval: tuple[float, float] | None = None


def _n_star(a: float, c: float, gamma_c: float) -> int:
    """The smallest integer ``N`` with ``c / N^a < gamma_c`` (``a > 0``)."""
    if not a > 0:
        raise ParameterError(f"the fitted exponent a = {a:.3g} is not positive: the error does not decrease with N")
    log_root = (math.log(c) - math.log(gamma_c)) / a
    if log_root > 700:  # beyond float range, and far beyond any sample size a design can use
        raise ParameterError(
            f"the fitted rate c / N^a (a = {a:.3g}, c = {c:.3g}) reaches gamma_c = {gamma_c:g} only at N = e^{log_root:.0f}"
        )
    return max(int(math.floor(math.exp(log_root))) + 1, 1)


def empirical_design(
    fit: EmpiricalComplexity,
    threat: ThreatModel,
    *,
    gamma_c: float | None = None,
    level: float | None = None,
    reference: tuple[EmpiricalComplexity, int] | None = None,
) -> EmpiricalDesign:
    """The design of Theorem thm:opt_sec and eq:opt_key from an empirical complexity (step 2).

    ``N*`` is the smallest ``N`` whose fitted mean error is below ``gamma_c``; ``lambda*`` follows
    by eq:opt_sec and ``k*`` by eq:opt_key under ``model`` (:func:`design_key_length`). The
    interval of ``N*`` is the bootstrap quantile interval (at the fit's level unless ``level`` is
    given) of the same computation on each bootstrap replicate of ``(a, c)``; ``lambda*`` and
    ``k*`` are monotone in ``N*``, so their intervals are the images of the ends of that interval.

    Parameters
    ----------
    fit : EmpiricalComplexity
        From :func:`fit_empirical_complexity`.
    threat : ThreatModel
        Defense period, adversary FLOPS and deciphering-cost model (eq:opt_key), and the
        acceptable error ``gamma_c`` in the fitted error's own measure.
    gamma_c : float, optional
        Overrides ``threat.gamma_c`` (an error measure other than Definition def:error needs its
        own threshold).
    level : float, optional
        Confidence level of the intervals.
    reference : (EmpiricalComplexity, int), optional
        The target as a Monte Carlo estimate (step 3): ``gamma_c = ref(N_ref)``, and replicate
        ``b`` of ``fit`` designs against replicate ``b`` of ``ref`` at ``N_ref``, so the interval
        of ``N*`` carries the target's spread. Exclusive with ``gamma_c``; the two fits must be
        :func:`paired`.

    Returns
    -------
    EmpiricalDesign

    Raises
    ------
    ParameterError
        A non-positive fitted exponent (for most replicates too), ``reference`` with ``gamma_c``,
        or a reference fit not paired with ``fit``.
    """
    tau_c, upsilon = threat.tau_c, threat.upsilon
    level = fit.level if level is None else check_positive("level", level)
    q = [(1 - level) / 2, (1 + level) / 2]
    if reference is None:
        gamma_c = check_positive("gamma_c", threat.require("gamma_c").gamma_c if gamma_c is None else gamma_c)
        targets = np.full(len(fit.boot_a), gamma_c)
        target_interval = None
    else:
        ref, at = reference
        at = check_int("reference sample size", at, minimum=1)
        if gamma_c is not None:
            raise ParameterError("give either gamma_c or reference (the target as a fit), not both")
        if not paired(fit, ref):
            raise ParameterError(
                f"the reference fit is not paired with the fit (runs {ref.runs} / {fit.runs}, replicates "
                f"{len(ref.boot_a)} / {len(fit.boot_a)}, seed {ref.seed} / {fit.seed}): fit the same runs with one seed"
            )
        gamma_c = float(ref(at))
        targets = ref.boot_c / float(at) ** ref.boot_a
        lo_t, hi_t = np.quantile(targets, q)
        target_interval = (float(lo_t), float(hi_t))
    N_star = _n_star(fit.a, fit.c, gamma_c)
    boot = np.array([_n_star(a, c, g) for a, c, g in zip(fit.boot_a, fit.boot_c, targets) if a > 0])
    if len(boot) < 0.5 * len(fit.boot_a):
        raise ParameterError("most bootstrap fits have a non-positive exponent: the data do not show a decreasing error")
    n_lo, n_hi = (int(v) for v in np.quantile(boot, q, method="nearest"))
    lam = optimal_security_parameter(N_star, tau_c=tau_c, upsilon=upsilon)
    lam_ends = sorted(optimal_security_parameter(v, tau_c=tau_c, upsilon=upsilon) for v in (n_lo, n_hi))
    k = design_key_length(N_star, threat).k_star
    k_ends = sorted(design_key_length(v, threat).k_star for v in (n_lo, n_hi))
    return EmpiricalDesign(
        N_star=N_star,
        N_star_interval=(n_lo, n_hi),
        lambda_star=lam,
        lambda_star_interval=(lam_ends[0], lam_ends[1]),
        k_star=k,
        k_star_interval=(k_ends[0], k_ends[1]),
        model=str(getattr(threat.cost_model, "name", threat.cost_model)),
        extrapolated=bool(max(N_star, n_hi) > fit.N[-1]),
        target=None if reference is None else gamma_c,
        target_interval=target_interval,
    )
