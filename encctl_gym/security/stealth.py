"""Stealth against identifiability: what an attacker that keeps ``Phi x`` shows the detectors, what
it learns, and the frontier between the two (issue 30; Bai, Pasqualetti and Gupta, Automatica 2017,
"Data-injection attacks in stochastic control systems: detectability and performance tradeoffs").

The plant side's detectors (:mod:`encctl_gym.loop.detection`) test the closed-loop innovation
``r[t] = x[t+1] - A_cl x[t]``, ``A_cl = A + B Phi``, which is ``N(0, Sigma_0)``, ``Sigma_0 =
sigma_w2 I``, without an attack. An attacker that applies ``u = Phi x + d`` with white ``d`` of
covariance ``Sigma_d`` (:class:`~encctl_gym.agents.stealth.AdditiveAttacker`) makes it
``N(0, Sigma_1)``, ``Sigma_1 = Sigma_0 + B Sigma_d B^T``; an attacker that forges
``Phi x_hat + d`` from a state ``d`` steps old adds ``B Phi P_d Phi^T B^T``, ``P_d`` the covariance
of its prediction error (:func:`prediction_error_covariance`; the true model's, a floor). The
per-step Kullback-Leibler divergence the detectors face is the Gaussian one (:func:`innovation_kl`):

    KL = (tr(Sigma_0^-1 Sigma_1) - n - ln det(Sigma_0^-1 Sigma_1)) / 2.

What it gains: the regressor ``z = [x; u]`` has the stationary covariance (:func:`regressor_covariance`)

    Sigma_zz = T blkdiag(Sigma_xx, Sigma_d) T^T,  T = [[I, 0], [Phi, I]],
    Sigma_xx = A_cl Sigma_xx A_cl^T + sigma_w2 I + B Sigma_d B^T,

so the Fisher information of a row of ``[A B]`` per sample is ``Sigma_zz / sigma_w2``
(:func:`fisher_information`) and the least-squares error (Definition def:error) is
``E[eps(N)] -> sigma_w2 tr(Sigma_zz^-1) / ((n + m)(N - 1))`` (as :mod:`~.attack_design`'s
``gamma_opt``), with ``tr(Sigma_zz^-1) = tr(Sigma_xx^-1) + tr((I + Phi Phi^T) Sigma_d^-1)``.
Samples to ``gamma_c``: :func:`samples_to_gamma_c`. Small excitation is stealthy in total: KL per
step grows as ``|Sigma_d|^2``, the samples needed as ``1 / |Sigma_d|``, so the divergence
accumulated to ``gamma_c`` vanishes with the excitation, and the deciphering budget (the horizon)
is what stops such an attacker, not the detectors.

The optimal stealthy design (:func:`stealthy_design`): the A-optimal ``Sigma_d`` (least
``tr(Sigma_zz^-1)``) under a KL budget per step (and optionally the power budget), an SDP solved
with :mod:`~.attack_design`'s solver chain. The frontier (:func:`frontier_point`): samples to
``gamma_c`` against the probability that the chi-squared window test (:func:`chi2_alarm_probability`,
:func:`window_detection_bounds`), Page's CUSUM (:func:`cusum_detection_probability`, Brook and
Evans' chain) or random audits (:func:`audit_detection_probability`) stop the attack first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_nonnegative, check_positive, check_probability, check_system
from ..errors import ParameterError, ShapeError, SolverError
from .defenses import chi2_threshold, cusum_threshold
from .gramians import solve_gramian
from .sample_size import sample_size_for_rate

__all__ = [
    "DETECTORS",
    "StealthyDesign",
    "FrontierPoint",
    "check_false_alarm_rate",
    "innovation_covariance",
    "innovation_kl",
    "prediction_error_covariance",
    "regressor_covariance",
    "fisher_information",
    "identification_rate",
    "samples_to_gamma_c",
    "malleability_excitation",
    "stealthy_design",
    "chi2_alarm_probability",
    "sparse_noncentralities",
    "sparse_chi2_alarm_probability",
    "window_detection_bounds",
    "window_detection_probability",
    "cusum_detection_probability",
    "audit_detection_probability",
    "frontier_point",
]

#: The detectors of the frontier (the defenders ``chi2``, ``cusum`` and ``audit`` of :mod:`encctl_gym.loop.defenses`).
DETECTORS: tuple[str, ...] = ("chi2", "cusum", "audit")


def check_false_alarm_rate(value: Any, name: str = "false_alarm_rate") -> float:
    """A false-alarm rate per step in the open interval (0, 1) (:func:`~encctl_gym._validation.check_probability`)."""
    v = check_probability(name, value)
    if v <= 0.0 or v >= 1.0:
        raise ParameterError(f"{name} must lie in (0, 1), got {value!r}")
    return v


def _matrices(A: Any, B: Any, Phi: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    A, B = check_system(A, B)
    Phi = as_finite_array("Phi", Phi, ndim=2)
    if Phi.shape != (B.shape[1], A.shape[0]):
        raise ShapeError(f"Phi must have shape {(B.shape[1], A.shape[0])}, got {Phi.shape}")
    return A, B, Phi


def _covariance(name: str, S: Any, size: int) -> np.ndarray:
    S = as_finite_array(name, S, ndim=2)
    if S.shape != (size, size):
        raise ShapeError(f"{name} must have shape {(size, size)}, got {S.shape}")
    S = 0.5 * (S + S.T)
    if np.linalg.eigvalsh(S).min() < -1e-12 * max(1.0, float(np.abs(S).max())):
        raise ParameterError(f"{name} must be positive semidefinite (smallest eigenvalue {np.linalg.eigvalsh(S).min():.3g})")
    return S


# ---------------------------------------------------------------------- what the detectors see
def prediction_error_covariance(A: Any, sigma_w2: float, delay: int) -> np.ndarray:
    """``P_d = sigma_w2 sum_{i < d} A^i A^iT``: the covariance of ``x_t - x_hat_t`` when ``x_hat_t``
    is predicted from ``x_{t-d}`` and the known inputs with the true model (the best an attacker
    forging ``Phi x_hat`` can do; zero at ``d = 0``)."""
    A = as_finite_array("A", A, ndim=2)
    sw = check_positive("sigma_w2", sigma_w2)
    d = check_int("delay", delay, minimum=0)
    P, Ai = np.zeros_like(A), np.eye(A.shape[0])
    for _ in range(d):
        P += sw * Ai @ Ai.T
        Ai = A @ Ai
    return P


def innovation_covariance(B: Any, sigma_w2: float, Sigma_d: Any, *, Phi: Any = None, prediction_error: Any = None) -> np.ndarray:
    """``Sigma_1 = sigma_w2 I + B Sigma_d B^T (+ B Phi P_d Phi^T B^T)``: the innovation's covariance
    under the attack (module docstring); ``prediction_error`` is ``P_d`` (needs ``Phi``)."""
    B = as_finite_array("B", B, ndim=2)
    n, m = B.shape
    S1 = check_positive("sigma_w2", sigma_w2) * np.eye(n) + B @ _covariance("Sigma_d", Sigma_d, m) @ B.T
    if prediction_error is not None:
        if Phi is None:
            raise ParameterError("a prediction error needs the controller Phi")
        Phi = as_finite_array("Phi", Phi, ndim=2)
        S1 = S1 + B @ Phi @ _covariance("prediction_error", prediction_error, n) @ Phi.T @ B.T
    return S1


def innovation_kl(Sigma_1: Any, Sigma_0: Any) -> float:
    """``KL(N(0, Sigma_1) || N(0, Sigma_0)) = (tr(Sigma_0^-1 Sigma_1) - n - ln det(Sigma_0^-1 Sigma_1)) / 2``
    in nats: the per-step divergence of the innovation under attack from the nominal one."""
    S0 = as_finite_array("Sigma_0", Sigma_0, ndim=2)
    S1 = _covariance("Sigma_1", Sigma_1, S0.shape[0])
    L = np.linalg.cholesky(0.5 * (S0 + S0.T))
    M = np.linalg.solve(L, np.linalg.solve(L, S1).T)  # L^-1 S1 L^-T
    lam = np.linalg.eigvalsh(0.5 * (M + M.T))
    if lam.min() <= 0:
        raise ParameterError("Sigma_1 must be positive definite")
    return float(0.5 * np.sum(lam - 1.0 - np.log(lam)))


# ---------------------------------------------------------------------- what the attacker learns
def regressor_covariance(A: Any, B: Any, Phi: Any, *, sigma_w2: float, Sigma_d: Any) -> np.ndarray:
    """The stationary ``Sigma_zz`` of ``z = [x; Phi x + d]`` in the loop ``x+ = A_cl x + B d + w``
    (module docstring). Raises UnstableSystemError if ``A + B Phi`` is not Schur stable."""
    A, B, Phi = _matrices(A, B, Phi)
    n, m = B.shape
    Sd = _covariance("Sigma_d", Sigma_d, m)
    Sxx = solve_gramian(A + B @ Phi, check_positive("sigma_w2", sigma_w2) * np.eye(n) + B @ Sd @ B.T)
    T = np.block([[np.eye(n), np.zeros((n, m))], [Phi, np.eye(m)]])
    D = np.block([[Sxx, np.zeros((n, m))], [np.zeros((m, n)), Sd]])
    return T @ D @ T.T


def fisher_information(A: Any, B: Any, Phi: Any, *, sigma_w2: float, Sigma_d: Any) -> np.ndarray:
    """The Fisher information of one row of ``[A B]`` per sample, ``Sigma_zz / sigma_w2`` (Gaussian
    noise; ``N - 1`` samples give ``(N - 1)`` times it, the Gram matrix ``D D^T / sigma_w2`` on average)."""
    return regressor_covariance(A, B, Phi, sigma_w2=sigma_w2, Sigma_d=Sigma_d) / check_positive("sigma_w2", sigma_w2)


def identification_rate(A: Any, B: Any, Phi: Any, *, sigma_w2: float, Sigma_d: Any) -> float:
    """``c = sigma_w2 tr(Sigma_zz^-1) / (n + m)``, so that ``E[eps(N)] ~ c / (N - 1)`` (the CRLB of
    the least-squares error, Definition def:error); infinite for a singular ``Sigma_d``."""
    Szz = regressor_covariance(A, B, Phi, sigma_w2=sigma_w2, Sigma_d=Sigma_d)
    w = np.linalg.eigvalsh(Szz)
    if w.min() <= 1e-300:
        return math.inf
    return float(sigma_w2 * np.sum(1.0 / w) / Szz.shape[0])


def samples_to_gamma_c(rate: float, gamma_c: float) -> int | float:
    """The smallest ``N`` with ``rate / (N - 1) < gamma_c`` (:func:`~.sample_size.sample_size_for_rate`);
    ``inf`` for an infinite rate (no excitation)."""
    return math.inf if math.isinf(rate) else sample_size_for_rate(rate, gamma_c)


def malleability_excitation(A: Any, B: Any, Phi: Any, *, sigma_w2: float, delta2: float, iterations: int = 200) -> np.ndarray:
    """The white excitation of the keyless row-gain attacker (:class:`~encctl_gym.agents.stealth.MalleabilityAttacker`):
    ``e_i = delta (Phi x)_i`` with ``E[delta] = 0``, ``E[delta^2] = delta2``, independent of ``x``,
    has ``Sigma_e = delta2 diag(Phi Sigma_xx Phi^T)``, and ``Sigma_xx`` depends on it: the fixed point."""
    A, B, Phi = _matrices(A, B, Phi)
    d2 = check_nonnegative("delta2", delta2)
    Se = np.zeros((B.shape[1], B.shape[1]))
    for _ in range(check_int("iterations", iterations, minimum=1)):
        Sxx = solve_gramian(A + B @ Phi, sigma_w2 * np.eye(A.shape[0]) + B @ Se @ B.T)
        new = d2 * np.diag(np.diag(Phi @ Sxx @ Phi.T))
        if np.allclose(new, Se, rtol=1e-12, atol=0.0):
            return new
        Se = new
    return Se


# ---------------------------------------------------------------------- the optimal stealthy design
@dataclass(frozen=True)
class StealthyDesign:
    """The A-optimal white excitation under a KL budget per step (:func:`stealthy_design`).

    Attributes
    ----------
    Sigma_d : ndarray (m, m)
        The excitation covariance.
    Sigma : ndarray (n + m, n + m)
        The regressor covariance it gives (:func:`regressor_covariance`).
    trace_inv : float
        ``tr(Sigma^-1)``.
    kl : float
        Its per-step KL divergence (nats), at most the budget.
    kl_budget : float
    rate : float
        ``sigma_w2 tr(Sigma^-1) / (n + m)`` (:func:`identification_rate`).
    """

    Sigma_d: np.ndarray
    Sigma: np.ndarray
    trace_inv: float
    kl: float
    kl_budget: float
    rate: float


def stealthy_design(
    A: Any, B: Any, Phi: Any, *, sigma_w2: float, kl_budget: float, sigma_u2: float | None = None, solver: str | None = None
) -> StealthyDesign:
    """The A-optimal excitation ``Sigma_d`` (least ``tr(Sigma_zz^-1)``) with per-step KL at most
    ``kl_budget`` (and ``tr Sigma_d <= m sigma_u2`` when given). Convex: the objective is
    ``tr(Sigma_xx^-1) + tr((I + Phi Phi^T) Sigma_d^-1)`` (two matrix fractions), ``Sigma_xx`` is
    affine in ``Sigma_d`` (the Lyapunov equation as a constraint), and
    ``KL = (tr(B S B^T) - ln det(I + B S B^T)) / 2`` in ``S = Sigma_d / sigma_w2`` is convex.
    Solved in units of ``sigma_w2`` (Clarabel, SCS as fallback: :mod:`~.attack_design`'s chain).

    Raises
    ------
    ParameterError
        A budget that is not positive (the error names it).
    SolverError
        The solver fails.
    """
    import cvxpy as cp

    from .attack_design import _solve

    A, B, Phi = _matrices(A, B, Phi)
    sw = check_positive("sigma_w2", sigma_w2)
    kappa = check_positive("kl_budget", kl_budget)
    n, m = B.shape
    A_cl = A + B @ Phi
    S = cp.Variable((m, m), PSD=True)
    X = cp.Variable((n, n), symmetric=True)
    L = np.linalg.cholesky(np.eye(m) + Phi @ Phi.T)
    BSB = B @ S @ B.T
    cons = [X == A_cl @ X @ A_cl.T + np.eye(n) + BSB, 0.5 * (cp.trace(BSB) - cp.log_det(np.eye(n) + BSB)) <= kappa]
    if sigma_u2 is not None:
        cons.append(cp.trace(S) <= m * check_positive("sigma_u2", sigma_u2) / sw)
    prob = cp.Problem(cp.Minimize(cp.matrix_frac(np.eye(n), X) + cp.matrix_frac(L, S)), cons)
    _solve(prob, solver)
    if S.value is None:  # pragma: no cover - _solve raises first
        raise SolverError("the stealthy design SDP returned no point")
    Sd = sw * 0.5 * (S.value + S.value.T)
    w, U = np.linalg.eigh(Sd)
    Sd = (U * np.clip(w, 0.0, None)) @ U.T
    Sigma = regressor_covariance(A, B, Phi, sigma_w2=sw, Sigma_d=Sd)
    kl = innovation_kl(innovation_covariance(B, sw, Sd), sw * np.eye(n))
    rate = identification_rate(A, B, Phi, sigma_w2=sw, Sigma_d=Sd)
    return StealthyDesign(Sd, Sigma, float(np.trace(np.linalg.inv(Sigma))), kl, kappa, rate)


# ---------------------------------------------------------------------- detection probabilities
def _satterthwaite(weights: np.ndarray, dof_each: int) -> tuple[float, float]:
    """``(scale, dof)`` of the scaled chi-squared matching the first two moments of
    ``sum_k w_k chi2_{dof_each}`` (Satterthwaite 1946; exact when the weights are equal)."""
    w = np.asarray(weights, dtype=float)
    s1, s2 = float(np.sum(w)) * dof_each, float(np.sum(w * w)) * dof_each
    return s2 / s1, s1 * s1 / s2


def _whitened_eigenvalues(Sigma_1: Any, Sigma_0: Any) -> np.ndarray:
    S0 = as_finite_array("Sigma_0", Sigma_0, ndim=2)
    L = np.linalg.cholesky(0.5 * (S0 + S0.T))
    M = np.linalg.solve(L, np.linalg.solve(L, _covariance("Sigma_1", Sigma_1, S0.shape[0])).T)
    return np.linalg.eigvalsh(0.5 * (M + M.T))


def chi2_alarm_probability(Sigma_1: Any, Sigma_0: Any, *, window: int, false_alarm_rate: float) -> float:
    """``P(S > h)`` for the window statistic ``S = sum_{k < W} r_k^T Sigma_0^-1 r_k`` of ``W``
    independent innovations ``N(0, Sigma_1)``: ``S`` is ``sum_k lambda_k chi2_W`` over the
    eigenvalues of ``Sigma_0^-1 Sigma_1``, exact when they are equal, Satterthwaite's scaled
    chi-squared otherwise; ``h`` from :func:`~.defenses.chi2_threshold`."""
    from scipy.stats import chi2

    alpha = check_false_alarm_rate(false_alarm_rate)
    lam = _whitened_eigenvalues(Sigma_1, Sigma_0)
    h = chi2_threshold(lam.size, window, alpha)
    scale, dof = _satterthwaite(lam, int(window))
    return float(chi2.sf(h / scale, dof))


def _sign_patterns(m: int) -> np.ndarray:
    return np.array(np.meshgrid(*[[-1.0, 1.0]] * m, indexing="ij")).reshape(m, -1).T


def sparse_noncentralities(B: Any, sigma_w2: float, amplitude: float) -> np.ndarray:
    """``d^T B^T B d / sigma_w2`` for the ``2^m`` equally likely injections ``d = amplitude s``
    (``s`` a sign pattern) of :class:`~encctl_gym.agents.stealth.SparseAttacker` (``add``)."""
    B = as_finite_array("B", B, ndim=2)
    D = check_positive("amplitude", amplitude) * _sign_patterns(B.shape[1])
    return np.sum((D @ B.T) ** 2, axis=1) / check_positive("sigma_w2", sigma_w2)


def sparse_chi2_alarm_probability(
    n: int, window: int, false_alarm_rate: float, q: float, noncentralities: Any, *, patterns: int = 64
) -> float:
    """The window alarm probability against a sparse attacker: each of the ``W`` innovations is
    injected with probability ``q`` (noncentrality drawn from ``noncentralities``, equally likely),
    so ``S`` is noncentral chi-squared with ``n W`` degrees of freedom and the sum of the injected
    noncentralities: ``sum_k Binom(k; W, q) E[ncx2.sf(h; nW, sum of k draws)]`` (the draws'
    sum by its mean when they differ: exact for an isotropic ``B``)."""
    from scipy.stats import binom, ncx2

    alpha = check_false_alarm_rate(false_alarm_rate)
    W = check_int("window", window, minimum=1)
    qq = check_probability("q", q)
    lam = float(np.mean(as_finite_array("noncentralities", noncentralities, ndim=1)))
    h = chi2_threshold(check_int("n", n, minimum=1), W, alpha)
    k = np.arange(W + 1)
    tails = np.where(k == 0, alpha, ncx2.sf(h, n * W, np.maximum(k * lam, 1e-300)))
    return float(np.sum(binom.pmf(k, W, qq) * tails))


def window_detection_bounds(N: int, window: int, alarm_probability: float) -> tuple[float, float]:
    """Bounds on the probability that the sliding window test alarms within ``N`` steps when each
    full window alarms with ``alarm_probability``: at least the ``floor(N / W)`` disjoint windows'
    ``1 - (1 - beta)^floor(N/W)``, at most the union bound ``min(1, (N - W + 1) beta)``."""
    N = check_int("N", N, minimum=0)
    W = check_int("window", window, minimum=1)
    beta = check_probability("alarm_probability", alarm_probability)
    if N < W:
        return 0.0, 0.0
    lo = -math.expm1((N // W) * math.log1p(-beta)) if beta < 1 else 1.0
    return float(lo), float(min(1.0, (N - W + 1) * beta))


def window_detection_probability(N: int, window: int, step_law: Any, threshold: float) -> float:
    """The probability that the sliding window test ``S_t = s_{t-W+1} + ... + s_t > h`` alarms
    within ``N`` steps, for i.i.d. per-step statistics ``s``: the first full window alarms with
    ``beta = P(S > h)``; after it, alarms start at the upcrossings ``S_{t-1} <= h < S_t``, whose rate
    ``mu = beta - P(S_{t-1} > h, S_t > h)`` follows from the ``W - 1`` terms the two windows share
    (one integral), and are counted as a Poisson stream (Aldous' clumping heuristic):
    ``1 - (1 - beta) exp(-(N - W) mu / (1 - beta))``.

    ``step_law`` is ``(pdf of the shared sum of W - 1 terms, survival function of one term, its
    survival beyond h)`` as callables of numpy arrays (:func:`_gaussian_step_law`, :func:`_sparse_step_law`).
    """
    from scipy.integrate import quad

    N = check_int("N", N, minimum=0)
    W = check_int("window", window, minimum=1)
    h = check_positive("threshold", threshold)
    if N < W:
        return 0.0
    shared_pdf, one_sf, shared_sf = step_law
    opts = {"limit": 400, "epsabs": 1e-13, "epsrel": 1e-10}
    beta = quad(lambda v: float(shared_pdf(v) * one_sf(h - v)), 0.0, h, **opts)[0] + float(shared_sf(h))
    both = quad(lambda v: float(shared_pdf(v) * one_sf(h - v) ** 2), 0.0, h, **opts)[0] + float(shared_sf(h))
    beta, mu = min(max(beta, 0.0), 1.0), max(beta - both, 0.0)
    if beta >= 1.0:
        return 1.0
    return float(1.0 - (1.0 - beta) * math.exp(-(N - W) * mu / (1.0 - beta)))


def _gaussian_step_law(weights: np.ndarray, window: int) -> tuple[Any, Any, Any]:
    """:func:`window_detection_probability`'s law for ``s = sum_k lambda_k chi2_1`` (Satterthwaite's
    scaled chi-squared ``c chi2_nu``; the shared sum ``c chi2_((W-1) nu)``)."""
    from scipy.stats import chi2

    c, nu = _satterthwaite(weights, 1)
    k = (window - 1) * nu
    if window == 1:
        return (lambda v: 0.0 * v, lambda v: chi2.sf(np.maximum(v, 0.0) / c, nu), lambda v: 0.0 * v)
    return (lambda v: chi2.pdf(v / c, k) / c, lambda v: chi2.sf(np.maximum(v, 0.0) / c, nu), lambda v: chi2.sf(v / c, k))


def _sparse_step_law(n: int, window: int, q: float, lam: float) -> tuple[Any, Any, Any]:
    """The law of a sparse attack: ``s`` is ``chi2_n`` with probability ``1 - q``, noncentral
    ``chi2_n(lam)`` with ``q``; the shared sum of ``W - 1`` terms a binomial mixture of noncentral
    chi-squared laws with ``k lam``."""
    from scipy.stats import binom, chi2, ncx2

    ks = np.arange(window)
    wk = binom.pmf(ks, window - 1, q)
    dof = n * (window - 1)

    def law(fn: Any, v: Any, k: int) -> Any:
        return getattr(chi2, fn)(v, dof) if k == 0 else getattr(ncx2, fn)(v, dof, k * lam)

    def shared_pdf(v: Any) -> Any:
        return sum(w * law("pdf", v, int(k)) for k, w in zip(ks, wk) if w > 1e-15) if window > 1 else 0.0 * v

    def shared_sf(v: Any) -> Any:
        return sum(w * law("sf", v, int(k)) for k, w in zip(ks, wk) if w > 1e-15) if window > 1 else 0.0 * v

    def one_sf(v: Any) -> Any:
        v = np.maximum(v, 0.0)
        return (1.0 - q) * chi2.sf(v, n) + q * ncx2.sf(v, n, max(lam, 1e-300))

    return shared_pdf, one_sf, shared_sf


def cusum_detection_probability(
    N: int,
    n: int,
    *,
    false_alarm_rate: float,
    variance_ratio: float = 2.0,
    weights: Any = None,
    sparse: Any = None,
    cells: int = 100,
) -> float:
    """``P(alarm within N steps)`` of the CUSUM ``g = max(0, g + z)``, ``z = a s - b`` on
    ``s = r^T Sigma_0^-1 r`` (:class:`~encctl_gym.loop.detection.CusumDetector`), from ``g = 0``:
    ``1 - e_0^T R^N 1`` with Brook and Evans' transition matrix ``R`` on ``cells`` states (the
    chain of :func:`~.defenses.cusum_run_length`) for the increment law of the attack.

    ``weights``: the eigenvalues of ``Sigma_0^-1 Sigma_1`` (Gaussian excitation; ``s`` by
    Satterthwaite's scaled chi-squared, exact for equal weights); ``sparse = (q, lambda)``: ``s`` is
    ``chi2_n`` with probability ``1 - q`` and noncentral ``chi2_n(lambda)`` with ``q``. Neither:
    no attack (the false-alarm probability within ``N``).
    """
    from scipy.stats import chi2, ncx2

    N = check_int("N", N, minimum=0)
    n = check_int("n", n, minimum=1)
    h = cusum_threshold(n, variance_ratio, check_false_alarm_rate(false_alarm_rate), cells=cells)
    c = float(variance_ratio)
    a, b = 0.5 * (1.0 - 1.0 / c), 0.5 * n * math.log(c)
    if sparse is not None:
        q, lam = check_probability("q", sparse[0]), check_nonnegative("lambda", sparse[1])

        def s_cdf(v: np.ndarray) -> np.ndarray:
            return (1.0 - q) * chi2.cdf(v, n) + q * ncx2.cdf(v, n, max(lam, 1e-300))
    else:
        scale, dof = _satterthwaite(np.ones(n) if weights is None else np.asarray(weights, dtype=float), 1)

        def s_cdf(v: np.ndarray) -> np.ndarray:
            return chi2.cdf(v / scale, dof)

    def F(t: np.ndarray) -> np.ndarray:  # P(z <= t)
        return s_cdf(np.maximum((t + b) / a, 0.0))

    w = 2.0 * h / (2 * cells - 1)
    v = w * np.arange(cells)
    d = v[None, :] - v[:, None]
    R = F(d + w / 2) - F(d - w / 2)
    R[:, 0] = F(-v + w / 2)
    alive = np.linalg.matrix_power(R, N) @ np.ones(cells) if N else np.ones(cells)
    return float(np.clip(1.0 - alive[0], 0.0, 1.0))


def audit_detection_probability(N: int, rate: float, fraction: float = 1.0) -> float:
    """``1 - (1 - p f)^N``: random audits at rate ``p`` per step catch an attack within ``N`` steps
    when a fraction ``f`` of the steps (independently) carries a deviation beyond the encoding's
    error bound (1 for an additive attacker, ``q`` for a sparse one)."""
    N = check_int("N", N, minimum=0)
    pf = check_probability("rate", rate) * check_probability("fraction", fraction)
    if pf >= 1.0:
        return 1.0 if N else 0.0
    return float(-math.expm1(N * math.log1p(-pf)))


# ---------------------------------------------------------------------- the frontier
@dataclass(frozen=True)
class FrontierPoint:
    """One attack on the frontier: its KL per step, samples to ``gamma_c`` and, per detector, the
    probability that the detector stops it within ``steps`` (the samples, or the horizon if shorter).

    Attributes
    ----------
    kl : float
        Per-step KL divergence (nats; the Gaussian moment match for a sparse attack).
    samples : int or float
        Samples to ``gamma_c`` (``inf`` without excitation).
    steps : int
        The attack length the probabilities are for.
    chi2 : float
        :func:`window_detection_probability` (the clumping approximation).
    chi2_lower : float
        The disjoint windows' lower bound (:func:`window_detection_bounds`).
    cusum, audit : float
    """

    kl: float
    samples: int | float
    steps: int
    chi2: float
    chi2_lower: float
    cusum: float
    audit: float


def frontier_point(
    A: Any,
    B: Any,
    Phi: Any,
    *,
    sigma_w2: float,
    gamma_c: float,
    Sigma_d: Any,
    window: int = 10,
    false_alarm_rate: float = 1e-4,
    variance_ratio: float = 2.0,
    audit_rate: float = 5e-4,
    sparse: tuple[float, float] | None = None,
    horizon: int | None = None,
    audit_fraction: float | None = None,
    steps: int | None = None,
) -> FrontierPoint:
    """The frontier at one attack (module docstring): Gaussian excitation ``Sigma_d``, or a sparse
    attacker ``sparse = (q, amplitude)`` (``Sigma_d = q amplitude^2 I``, its detection from the
    mixture laws). The detection is evaluated within ``min(samples, horizon)`` steps, or
    exactly ``steps`` when given (an attack longer than its samples to ``gamma_c``).
    ``audit_fraction``: the fraction of steps an audit can catch (default 1, a sparse attack's ``q``)."""
    A, B, Phi = _matrices(A, B, Phi)
    n = A.shape[0]
    sw = check_positive("sigma_w2", sigma_w2)
    alpha = check_false_alarm_rate(false_alarm_rate)
    S0 = sw * np.eye(n)
    if sparse is not None:
        q, amp = check_probability("q", sparse[0]), check_positive("amplitude", sparse[1])
        Sigma_d = q * amp * amp * np.eye(B.shape[1])
    S1 = innovation_covariance(B, sw, Sigma_d)
    samples = samples_to_gamma_c(identification_rate(A, B, Phi, sigma_w2=sw, Sigma_d=Sigma_d), gamma_c)
    length: int | float = check_int("steps", steps, minimum=1) if steps is not None else samples
    if steps is None and horizon is not None:
        length = min(samples, check_int("horizon", horizon, minimum=1))
    steps = int(min(length, 10**9))
    h = chi2_threshold(n, window, alpha)
    if sparse is not None:
        lam = float(np.mean(sparse_noncentralities(B, sw, amp)))
        beta = sparse_chi2_alarm_probability(n, window, alpha, q, [lam])
        law = _sparse_step_law(n, window, q, lam)
        cusum = cusum_detection_probability(steps, n, false_alarm_rate=alpha, variance_ratio=variance_ratio, sparse=(q, lam))
        audit = audit_detection_probability(steps, audit_rate, q if audit_fraction is None else audit_fraction)
    else:
        lams = _whitened_eigenvalues(S1, S0)
        beta = chi2_alarm_probability(S1, S0, window=window, false_alarm_rate=alpha)
        law = _gaussian_step_law(lams, window)
        cusum = cusum_detection_probability(steps, n, false_alarm_rate=alpha, variance_ratio=variance_ratio, weights=lams)
        moved = 1.0 if np.any(np.asarray(Sigma_d) != 0) else 0.0  # no excitation: nothing for an audit to see
        audit = audit_detection_probability(steps, audit_rate, moved if audit_fraction is None else audit_fraction)
    chi = window_detection_probability(steps, window, law, h)
    return FrontierPoint(
        innovation_kl(S1, S0), samples, steps, chi, window_detection_bounds(steps, window, beta)[0], cusum, audit
    )
