"""What the plant side's defences do to the attack, and what they cost: the analysis.

The paper fixes the defender: one group, one key length, nothing checked. Its only defence policy
(Section on the variance ratio, after eq:sic2) is to shrink the Gramians, and it notes the limit
eq:bound. This module gives the closed forms behind four levers (the loop that applies them and
the experiments that measure them live elsewhere):

* **Noise injection.** The plant side adds ``d[t] ~ N(0, sigma_d2 I_m)`` to the input it applies.
  The attacker, who knows only its own ``a[t]``, then faces the noise ``B d[t] + w[t]`` of
  covariance ``Sigma = sigma_d2 B B^T + sigma_w2 I`` (no longer a multiple of the identity).
  :func:`sic_with_input_noise` is eq:sic generalised by the paper's own proof of Theorem thm:sic:
  the first steps give ``E[eps] = tr(Sigma) / (n (n + m)) tr E[(D D^T)^-1]`` (``E[W^T W] =
  tr(Sigma) I``), Jensen's step is unchanged, and the state energy gains ``sigma_d2 tr Psi_u``
  because ``Psi`` is linear in the noise covariance. At ``sigma_d2 = 0`` it is eq:sic exactly. Like
  eq:sic it is a lower bound (it inherits the proof's treatment of ``W`` as independent of ``D``).
  The price is the closed-loop state covariance and quadratic cost of normal operation
  (:func:`noise_defense_price`, a discrete Lyapunov equation).
* **Audits.** At each step the plant side, which encrypted ``Phi`` and so knows it, recomputes
  ``Phi x`` with probability ``p`` and compares; an attacker who injects at every step collects
  ``N`` samples unseen with probability ``(1 - p)^N`` (:func:`undetected_probability`), so the rate
  ``p* = 1 - delta^(1 / N*)`` (about ``-ln(delta) / N*``) stops it before ``N*`` with probability
  at least ``1 - delta`` whatever the key length (:func:`minimum_audit_rate`).
* **A chi-squared detector** on the closed-loop innovation ``x[t+1] - (A + B Phi) x[t]``, whose
  covariance without an attack is ``Sigma``: the window statistic is chi-squared with ``n W``
  degrees of freedom (:func:`chi2_threshold` for a false-alarm rate per step,
  :func:`chi2_detection_probability` for an attack of a given energy).
* **A CUSUM detector** on the same innovation: the log-likelihood ratio of a covariance
  ``c Sigma`` against ``Sigma`` accumulated as ``g = max(0, g + z)``, alarm at ``g > h``
  (:func:`cusum_threshold` for a false-alarm rate per step, :func:`cusum_run_length` for the mean
  delay under an innovation covariance ``r Sigma``; Brook and Evans' Markov chain).
* **Group rotation** every ``K`` steps: the attacker pays the precomputation of a discrete
  logarithm once per group, ``ceil(N / K)`` times (:func:`rotated_deciphering_operations`).
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np

from .._validation import (
    as_finite_array,
    check_int,
    check_nonnegative,
    check_positive,
    check_probability,
    check_schur_stable,
    check_system,
)
from ..errors import ParameterError, ShapeError
from ..plant import as_plant
from .complexity import _out, check_sample_size
from .design import SecurityDesign, design_for_sample_size
from .gramians import controllability_gramian, noise_gramian, solve_gramian
from .sample_size import minimum_sample_size
from .threat import ThreatModel

__all__ = [
    "chi2_detection_probability",
    "chi2_threshold",
    "cusum_run_length",
    "cusum_threshold",
    "closed_loop_state_covariance",
    "input_noise_covariance",
    "minimum_audit_rate",
    "noise_defense_design",
    "noise_defense_price",
    "rotated_deciphering_operations",
    "rotation_precomputations",
    "sic_with_input_noise",
    "sic_with_input_noise_asymptotic",
    "undetected_probability",
]


def input_noise_covariance(B: Any, sigma_w2: float, sigma_d2: float) -> np.ndarray:
    """``Sigma = sigma_d2 B B^T + sigma_w2 I``: the noise the attacker faces when the plant side adds
    ``d[t] ~ N(0, sigma_d2 I)`` to the applied input (module docstring)."""
    B = as_finite_array("B", B, ndim=2)
    sw = check_positive("sigma_w2", sigma_w2)
    sd = check_nonnegative("sigma_d2", sigma_d2)
    return sd * (B @ B.T) + sw * np.eye(B.shape[0])


def _noise_terms(A: Any, B: Any, sigma_w2: float, sigma_d2: float) -> tuple[float, float, float, int, int]:
    A, B = check_system(A, B)
    n, m = B.shape
    tr_u = float(np.trace(controllability_gramian(A, B)))
    tr_w = float(np.trace(noise_gramian(A)))
    tr_sigma = float(np.trace(input_noise_covariance(B, sigma_w2, sigma_d2)))
    return tr_u, tr_w, tr_sigma, n, m


def sic_with_input_noise(
    N: Any, A: Any, B: Any, *, sigma_u2: float, sigma_w2: float, sigma_d2: float, sigma_x2: float = 1.0
) -> float | np.ndarray:
    """eq:sic generalised to the defender's input noise (module docstring, "Noise injection").

    ``gamma_d(N) = (m + n) (tr Sigma / n) / (sigma_x2 tr Psi_w + (N - 1) [sigma_u2 (tr Psi_u + m)
    + sigma_d2 tr Psi_u + sigma_w2 tr Psi_w])`` with ``Sigma = sigma_d2 B B^T + sigma_w2 I``.
    ``sigma_d2 = 0`` gives eq:sic.

    Parameters
    ----------
    N : int or array_like of int
        Sample size(s) >= 2.
    A, B : array_like
        Plant of eq:system (``A`` Schur stable).
    sigma_u2, sigma_w2 : float
        Attack input and process noise variances (> 0).
    sigma_d2 : float
        Variance of the defender's input noise (>= 0).
    sigma_x2 : float, default 1.0
        Variance of x_0 (>= 0).

    Returns
    -------
    float or ndarray
        Same shape as ``N``.
    """
    Nf, scalar = check_sample_size(N)
    tr_u, tr_w, tr_sigma, n, m = _noise_terms(A, B, sigma_w2, sigma_d2)
    su = check_positive("sigma_u2", sigma_u2)
    sd = check_nonnegative("sigma_d2", sigma_d2)
    sx = check_nonnegative("sigma_x2", sigma_x2)
    with np.errstate(over="ignore", invalid="ignore"):
        den = sx * tr_w + (Nf - 1.0) * (su * (tr_u + m) + sd * tr_u + sigma_w2 * tr_w)
        value = (m + n) * (tr_sigma / n) / den
    return _out(value, scalar)


def sic_with_input_noise_asymptotic(
    N: Any, A: Any, B: Any, *, sigma_u2: float, sigma_w2: float, sigma_d2: float
) -> float | np.ndarray:
    """The large-sample form (eq:sic2 generalised): :func:`sic_with_input_noise` without the
    ``sigma_x2`` term. At ``sigma_d2 = 0`` it is eq:sic2 with ``R_sigma = sigma_u2 / sigma_w2``."""
    Nf, scalar = check_sample_size(N)
    tr_u, tr_w, tr_sigma, n, m = _noise_terms(A, B, sigma_w2, sigma_d2)
    su = check_positive("sigma_u2", sigma_u2)
    sd = check_nonnegative("sigma_d2", sigma_d2)
    return _out((m + n) * (tr_sigma / n) / ((Nf - 1.0) * (su * (tr_u + m) + sd * tr_u + sigma_w2 * tr_w)), scalar)


def noise_defense_design(plant: Any, threat: ThreatModel, *, sigma_d2: float) -> SecurityDesign:
    """Theorem thm:opt_sec and eq:opt_key under the defender's input noise: ``N*`` from
    :func:`sic_with_input_noise_asymptotic` (the large-sample form, as the paper designs with
    eq:sic2), then ``lambda*`` and ``k*``. At ``sigma_d2 = 0`` it is the paper's design.

    Parameters
    ----------
    plant : Plant or (A, B)
        The plant of eq:system.
    threat : ThreatModel
        With ``sigma_u2``, ``sigma_w2`` and ``gamma_c``.
    sigma_d2 : float
        Variance of the defender's input noise (>= 0).

    Returns
    -------
    SecurityDesign
        With ``method = "input_noise"``; ``tr_psi_w`` is the trace of the Gramian of the whole
        noise ``Sigma`` (``sigma_d2 tr Psi_u / sigma_w2 + tr Psi_w``, in units of ``sigma_w2``).
    """
    p = as_plant(plant)
    threat = threat.require("sigma_u2", "sigma_w2", "gamma_c")
    sw = float(threat.sigma_w2)
    sd = check_nonnegative("sigma_d2", sigma_d2)
    tr_u, tr_w, _, n, m = _noise_terms(p.A, p.B, sw, sd)

    def gamma(N: int) -> float:
        return float(sic_with_input_noise_asymptotic(N, p.A, p.B, sigma_u2=threat.sigma_u2, sigma_w2=sw, sigma_d2=sd))

    N_star = minimum_sample_size(gamma, threat.gamma_c)
    return design_for_sample_size("input_noise", N_star, gamma, threat, m=m, n=n, tr_psi_u=tr_u, tr_psi_w=tr_w + sd * tr_u / sw)


def closed_loop_state_covariance(A: Any, B: Any, Phi: Any, *, sigma_w2: float, sigma_d2: float) -> np.ndarray:
    """Stationary state covariance ``P`` of normal operation ``x[t+1] = (A + B Phi) x[t] + B d[t] + w[t]``:
    the solution of ``(A + B Phi) P (A + B Phi)^T - P + Sigma = 0`` (Sigma of :func:`input_noise_covariance`).

    Raises
    ------
    UnstableSystemError
        If ``A + B Phi`` is not Schur stable.
    """
    A, B = check_system(A, B)
    Phi = as_finite_array("Phi", Phi, ndim=2)
    if Phi.shape != (B.shape[1], B.shape[0]):
        raise ShapeError(f"Phi must have shape {(B.shape[1], B.shape[0])}, got {Phi.shape}")
    A_cl = A + B @ Phi
    check_schur_stable(A_cl)
    return solve_gramian(A_cl, input_noise_covariance(B, sigma_w2, sigma_d2))


def noise_defense_price(
    A: Any, B: Any, Phi: Any, *, sigma_w2: float, sigma_d2: float, Q: Any = None, R: Any = None
) -> dict[str, float]:
    """What the defender's input noise costs in normal operation (module docstring).

    Returns the stationary ``tr P`` and the quadratic cost ``J = E[x^T Q x + v^T R v]`` of the
    applied input ``v = Phi x + d``, i.e. ``tr(Q P) + tr(R Phi P Phi^T) + sigma_d2 tr R``, with and
    without the noise, and their increases (``Q = I``, ``R = I`` unless given).
    """
    A, B = check_system(A, B)
    n, m = B.shape
    Q = np.eye(n) if Q is None else as_finite_array("Q", Q, ndim=2)
    R = np.eye(m) if R is None else as_finite_array("R", R, ndim=2)
    if Q.shape != (n, n) or R.shape != (m, m):
        raise ShapeError(f"Q and R must have shapes {(n, n)} and {(m, m)}, got {Q.shape} and {R.shape}")
    Phi = as_finite_array("Phi", Phi, ndim=2)
    sd = check_nonnegative("sigma_d2", sigma_d2)
    out: dict[str, float] = {}
    for key, s in (("base", 0.0), ("defended", sd)):
        P = closed_loop_state_covariance(A, B, Phi, sigma_w2=sigma_w2, sigma_d2=s)
        out[f"trace_P_{key}"] = float(np.trace(P))
        out[f"cost_{key}"] = float(np.trace(Q @ P) + np.trace(R @ Phi @ P @ Phi.T) + s * np.trace(R))
    out["trace_P_increase"] = out["trace_P_defended"] - out["trace_P_base"]
    out["cost_increase"] = out["cost_defended"] - out["cost_base"]
    return out


def undetected_probability(N: Any, audit_rate: float) -> float:
    """``(1 - p)^N``: the probability that an attacker injecting at each of ``N`` steps meets no audit."""
    N = check_int("N", N, minimum=0)
    p = check_probability("audit_rate", audit_rate)
    if p == 1.0:
        return 0.0 if N else 1.0
    return math.exp(N * math.log1p(-p))


def minimum_audit_rate(N_star: Any, delta: float) -> float:
    """The smallest audit rate with ``(1 - p)^{N*} <= delta``: ``p* = 1 - delta^(1 / N*)``.

    An attacker needs ``N*`` samples (Theorem thm:opt_sec) and injects at each; at rate ``p*`` it
    collects them unseen with probability at most ``delta``. About ``-ln(delta) / N*``.
    """
    N_star = check_int("N_star", N_star, minimum=1)
    delta = check_positive("delta", delta)
    if delta >= 1:
        raise ParameterError(f"delta must lie in (0, 1), got {delta}")
    return -math.expm1(math.log(delta) / N_star)


def chi2_threshold(n: int, window: int, false_alarm_rate: float) -> float:
    """Threshold ``h`` of the window statistic ``S = sum_{k < W} r_k^T Sigma^-1 r_k`` with
    ``P(S > h) = false_alarm_rate`` without an attack (``S`` is chi-squared with ``n W`` degrees of
    freedom: ``W`` independent Gaussian innovations of dimension ``n``)."""
    from scipy.stats import chi2

    n = check_int("n", n, minimum=1)
    window = check_int("window", window, minimum=1, maximum=10**6)
    alpha = check_positive("false_alarm_rate", false_alarm_rate)
    if alpha >= 1:
        raise ParameterError(f"false_alarm_rate must lie in (0, 1), got {alpha}")
    return float(chi2.isf(alpha, n * window))


def chi2_detection_probability(n: int, window: int, false_alarm_rate: float, noncentrality: float) -> float:
    """``P(S > h)`` under an attack whose innovations carry ``noncentrality = sum_k e_k^T Sigma^-1 e_k``
    over the window (``e_k = B (a_k - Phi x_k)``, the part of the innovation the attack adds): the
    noncentral chi-squared tail at :func:`chi2_threshold`."""
    from scipy.stats import ncx2

    h = chi2_threshold(n, window, false_alarm_rate)
    lam = check_nonnegative("noncentrality", noncentrality)
    if lam == 0:
        return float(false_alarm_rate)
    return float(ncx2.sf(h, n * window, lam))


def _cusum_increment(n: int, variance_ratio: float) -> tuple[float, float]:
    """``(a, b)`` of the CUSUM's log-likelihood-ratio increment ``z = a s - b`` for the statistic
    ``s = r^T Sigma^-1 r`` of an innovation whose covariance is ``Sigma`` (no attack) or
    ``c Sigma`` (the change it is tuned for): ``a = (1 - 1/c) / 2``, ``b = n ln(c) / 2``."""
    c = check_positive("variance_ratio", variance_ratio)
    if c <= 1:
        raise ParameterError(f"variance_ratio must be > 1, got {c}")
    return 0.5 * (1.0 - 1.0 / c), 0.5 * n * math.log(c)


def cusum_run_length(n: int, variance_ratio: float, threshold: float, *, actual_ratio: float = 1.0, cells: int = 100) -> float:
    """Mean steps to the first alarm of the CUSUM ``g[t] = max(0, g[t-1] + z[t])``, alarm at
    ``g > h``, from ``g = 0``, when the innovation's covariance is ``actual_ratio Sigma``
    (1: no attack, the average run length to a false alarm).

    ``z = a s - b`` (:func:`_cusum_increment`) with ``s / actual_ratio`` chi-squared with ``n``
    degrees of freedom. Brook and Evans' Markov chain: ``cells`` states ``g = j w``,
    ``w = 2 h / (2 cells - 1)``; the run length is the first entry of ``(I - R)^-1 1``.
    """
    from scipy.stats import chi2

    n = check_int("n", n, minimum=1)
    a, b = _cusum_increment(n, variance_ratio)
    h = check_positive("threshold", threshold)
    r = check_positive("actual_ratio", actual_ratio)
    cells = check_int("cells", cells, minimum=2, maximum=5000)
    w = 2.0 * h / (2 * cells - 1)
    v = w * np.arange(cells)

    def F(t: np.ndarray) -> np.ndarray:  # P(z <= t)
        return chi2.cdf(np.maximum((t + b) / (a * r), 0.0), n)

    d = v[None, :] - v[:, None]  # (j -> k): g moves by k w - j w
    R = F(d + w / 2) - F(d - w / 2)
    R[:, 0] = F(-v + w / 2)
    arl = np.linalg.solve(np.eye(cells) - R, np.ones(cells))
    return float(arl[0])


def cusum_threshold(n: int, variance_ratio: float, false_alarm_rate: float, *, cells: int = 100) -> float:
    """Threshold ``h`` of the CUSUM with a false-alarm rate per step ``alpha``: its average run
    length without an attack (:func:`cusum_run_length`, restarted after each alarm) is
    ``1 / alpha``. Bisection in ``h`` to a relative 1e-7 (cached: defenders ask once per episode)."""
    n = check_int("n", n, minimum=1)
    _cusum_increment(n, variance_ratio)
    alpha = check_positive("false_alarm_rate", false_alarm_rate)
    if alpha >= 1:
        raise ParameterError(f"false_alarm_rate must lie in (0, 1), got {alpha}")
    return _cusum_threshold(n, float(variance_ratio), alpha, check_int("cells", cells, minimum=2, maximum=5000))


@lru_cache(maxsize=64)
def _cusum_threshold(n: int, c: float, alpha: float, cells: int) -> float:
    target = 1.0 / alpha
    lo, hi = 0.0, 1.0
    while cusum_run_length(n, c, hi, cells=cells) < target:
        lo, hi = hi, 2.0 * hi
        if hi > 1e4:
            raise ParameterError(f"no CUSUM threshold below 1e4 reaches a false-alarm rate of {alpha}")
    while hi - lo > 1e-7 * hi:
        mid = 0.5 * (lo + hi)
        if cusum_run_length(n, c, mid, cells=cells) < target:
            lo = mid
        else:
            hi = mid
    return hi


def rotation_precomputations(N: Any, K: Any) -> int:
    """``ceil(N / K)``: the groups an attacker meets over ``N`` samples when the group rotates every ``K`` steps."""
    N = check_int("N", N, minimum=1)
    K = check_int("K", K, minimum=1)
    return -(-N // K)


def rotated_deciphering_operations(N: Any, K: Any, precomputation: float, per_key: float) -> float:
    """``ceil(N / K) C_pre + N C_key``: the attacker's work under the precomputation model when the
    group rotates every ``K`` steps (``K >= N`` is the fixed group: one precomputation)."""
    c_pre = check_nonnegative("precomputation", precomputation)
    c_key = check_nonnegative("per_key", per_key)
    groups = rotation_precomputations(N, K)
    return groups * c_pre + int(N) * c_key
