"""The expected error of Bayesian least squares and its sample identifying complexity.

The Bayesian attacker of :class:`encctl_gym.ident.bayes.BayesianLeastSquares` estimates row
``i`` of ``theta = [A B]`` by the posterior mean ``theta_hat_i = (Lambda_i + G)^{-1}
(Lambda_i m0_i + C_i)`` under the prior ``theta_i ~ N(m0_i, sigma_w2 Lambda_i^{-1})``, with
``G = D D^T`` the regressor Gram matrix of eq:data (``D = [X_p; U_p]``, ``d = n + m`` rows) and
``Lambda_i`` the prior precision in units of the noise (the ridge weight). ``c = n d`` as in
Definition def:error. Three results, derived along the proof of Theorem thm:sic:

**(F) Error at a fixed plant, given the data matrix** (:func:`bayesian_error_given_gram`).
With ``P_i = (Lambda_i + G)^{-1}`` and ``delta_i = theta_i - m0_i``, eq:data gives
``theta_hat_i - theta_i = P_i (Lambda_i (m0_i - theta_i) + D w_i)``, so, for ``W_p``
independent of ``D``,

``E[epsilon | D] = (1/c) sum_i [ ||P_i Lambda_i delta_i||^2 + sigma_w2 tr(P_i G P_i) ]``:

a bias from the prior and a variance below that of least squares. ``Lambda = 0`` gives
``(sigma_w2 / (n + m)) tr(G^{-1})``, the first identity of the proof of Theorem thm:sic, which
makes the same independence step. It is exact for a fixed design; for eq:system, whose
regressors depend on earlier noise, it is the paper's approximation.

**(B) Bayes risk** (:func:`bayes_risk_given_gram`). Averaged over plants drawn from the prior,
the error of the posterior mean is the trace of the posterior covariance
``sigma_w2 P_i``:

``E[epsilon] = (sigma_w2 / c) sum_i E[tr (Lambda_i + G)^{-1}]``.

This needs no independence step: the Gaussian likelihood of a trajectory of eq:system given
``theta`` is that of a linear regression whatever the inputs, as long as the attacker chooses
them without knowing ``theta`` (any input that depends only on delivered data, feedback
included: V. Peterka, "Bayesian system identification", Automatica 17(1), 1981), and the mean
square error of a posterior mean is the expected trace of the posterior covariance (S. M. Kay,
*Fundamentals of Statistical Signal Processing: Estimation Theory*, 1993, Chapter 11).

**(C) Sample identifying complexity of the Bayesian attacker** (:func:`bayesian_sic_from_traces`).
As in the proof of Theorem thm:sic, Jensen's inequality (``X -> tr X^{-1}`` is convex, then
``tr X^{-1} >= d^2 / tr X`` and ``x -> 1/x`` is convex) and the Gramian bound
``E[tr G] <= sigma_x2 tr Psi_w + (N - 1)[sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w]`` for
i.i.d. ``N(0, sigma_u2 I)`` attack inputs and a Schur-stable plant turn (B) into

``gamma_B(N) = (1/n) sum_i (m + n) sigma_w2 / (tr Lambda_i + sigma_x2 tr Psi_w + (N - 1)[sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w])``,

eq:sic with ``sigma_x2 tr Psi_w`` increased by ``tr Lambda_i``: the prior adds to the
information of the data exactly where the initial state does. A prior is worth
``tr Lambda_i / [sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w]`` samples
(:func:`prior_sample_equivalent`).

*gamma_B is a lower bound, not an approximation.* Each step of the chain goes one way:
``E tr (Lambda_i + G)^{-1} >= tr (Lambda_i + E G)^{-1}`` (Jensen, ``X -> tr X^{-1}`` convex on
positive definite matrices), ``tr Y^{-1} >= d^2 / tr Y`` (the arithmetic-harmonic mean
inequality on the eigenvalues of ``Y``, equality iff ``Y`` is a multiple of the identity), and
``d^2 / (tr Lambda_i + E tr G)`` falls as ``E tr G`` grows, so the Gramian bound on
``E tr G`` (an upper bound) gives a smaller value again; averaging over plants drawn from the
prior, Jensen on ``t -> 1 / (a + t)`` puts the prior-averaged Gramian traces in. Hence
``gamma_B(N) <= E[epsilon]`` of (B) for plants drawn from the prior: a sample identifying
complexity in the sense of Definition def:sic for that Bayesian setting (tested against a Monte
Carlo). It is loose where ``N`` is small: the two inequalities drop the finite-sample factor
(for i.i.d. Gaussian regressors of covariance ``Sigma``, ``E G^{-1} = Sigma^{-1} / (T - d - 1)``,
``T = N - 1``, against ``1 / T``) and the spread of the eigenvalues of ``Sigma`` (``tr Sigma^{-1}``
against ``d^2 / tr Sigma``: 1.17 against 1.05 on the design example, whose states have variance
5.2 and inputs 10). At a fixed plant it is no bound at all (see the assumptions below).
:func:`bayes_risk_iid_gaussian` gives the finite-sample value for i.i.d. Gaussian regressors
(exact without a prior, a Monte Carlo over Wishart draws with its standard error with one) and
:func:`stationary_regressor_covariance` the ``Sigma`` of eq:system under the Gaussian attack.

Assumptions: Gaussian noise of the variance the posterior assumes; the attack inputs do not
use ``theta``; for (C) i.i.d. Gaussian inputs of Theorem thm:sic and stable plants; for (F) the
independence of ``W_p`` and ``D`` (as the paper). At a fixed plant (the defender's view) no
prior-free lower bound exists: a prior mean close to the plant makes the error small for any
``N``; (F) gives the error of a given prior at a given plant.

Pure math: numpy only (and the Gramians of :mod:`encctl_gym.security.gramians`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_positive, check_system, format_value
from ..errors import ParameterError, ShapeError
from ..resources import check_memory
from .complexity import sic_from_traces
from .gramians import controllability_gramian, noise_gramian

__all__ = [
    "bayesian_error_given_gram",
    "bayes_risk_given_gram",
    "bayesian_sic_from_traces",
    "bayesian_sample_identifying_complexity",
    "prior_sample_equivalent",
    "stationary_regressor_covariance",
    "sic_tightness",
    "bayes_risk_iid_gaussian",
]


def _precision(precision: Any, n: int, d: int) -> np.ndarray:
    """``Lambda`` as ``(n, d, d)``: one symmetric positive semidefinite matrix per row of theta."""
    lam = as_finite_array("precision", precision)
    if lam.shape == (d, d):
        lam = np.broadcast_to(lam, (n, d, d))
    if lam.shape != (n, d, d):
        raise ShapeError(f"precision must have shape ({d}, {d}) or ({n}, {d}, {d}), got {lam.shape}")
    if not np.allclose(lam, np.swapaxes(lam, -1, -2), rtol=1e-12, atol=0.0):
        raise ParameterError("precision must be symmetric")
    if np.min(np.linalg.eigvalsh(lam)) < -1e-12 * max(1.0, float(np.abs(lam).max())):
        raise ParameterError("precision must be positive semidefinite")
    return np.array(lam)


def _gram(G: Any, d: int) -> np.ndarray:
    G = as_finite_array("G", G)
    if G.ndim < 2 or G.shape[-2:] != (d, d):
        raise ShapeError(f"G must have shape (..., {d}, {d}), got {G.shape}")
    return G


def bayesian_error_given_gram(A: Any, B: Any, G: Any, *, prior_mean: Any, precision: Any, sigma_w2: float) -> float | np.ndarray:
    """(F): the expected error of the posterior mean at the plant ``(A, B)``, given ``G = D D^T``.

    ``E[epsilon | D] = (1/c) sum_i [ ||P_i Lambda_i (theta_i - m0_i)||^2 + sigma_w2 tr(P_i G P_i) ]``,
    ``P_i = (Lambda_i + G)^{-1}`` (see the module docstring; exact for noise independent of ``D``).

    Parameters
    ----------
    A, B : array_like
        The true plant of eq:system.
    G : array_like, shape (..., n + m, n + m)
        Regressor Gram matrices.
    prior_mean : float or array_like of shape (n, n + m)
        ``m0``.
    precision : array_like, shape (n + m, n + m) or (n, n + m, n + m)
        ``Lambda_i`` (zero: least squares, then ``G`` must be invertible).
    sigma_w2 : float
        Noise variance (> 0).

    Returns
    -------
    float or ndarray
        Shape of the leading dimensions of ``G``.
    """
    A, B = check_system(A, B)
    n, m = B.shape
    d = n + m
    sw = check_positive("sigma_w2", sigma_w2)
    G = _gram(G, d)
    lam = _precision(precision, n, d)
    m0 = (
        np.broadcast_to(as_finite_array("prior_mean", prior_mean), (n, d))
        if np.ndim(prior_mean)
        else np.full((n, d), float(prior_mean))
    )
    delta = np.hstack([A, B]) - m0  # (n, d)
    P = np.linalg.inv(G[..., None, :, :] + lam)  # (..., n, d, d)
    bias = np.einsum("...ijk,ikl,il->...ij", P, lam, delta)  # P_i Lambda_i delta_i
    var = np.einsum("...ijk,...kl,...ilj->...i", P, G, P)  # tr(P_i G P_i)
    out = (np.sum(bias**2, axis=(-2, -1)) + sw * np.sum(var, axis=-1)) / (n * d)
    return float(out) if out.ndim == 0 else out


def bayes_risk_given_gram(G: Any, *, precision: Any, sigma_w2: float, n: int) -> float | np.ndarray:
    """(B): ``(sigma_w2 / c) sum_i tr (Lambda_i + G)^{-1}``, the posterior covariance's trace.

    Its expectation over the data is the error of the posterior mean averaged over plants drawn
    from the prior (see the module docstring).

    Parameters
    ----------
    G : array_like, shape (..., d, d)
    precision : array_like, shape (d, d) or (n, d, d)
    sigma_w2 : float
    n : int
        Number of states (rows of ``theta``).

    Returns
    -------
    float or ndarray
    """
    n = check_int("n", n, minimum=1)
    sw = check_positive("sigma_w2", sigma_w2)
    G = as_finite_array("G", G)
    d = G.shape[-1]
    if d <= n:
        raise ShapeError(f"G must be (n + m) x (n + m) with m >= 1 for n={n}, got {G.shape}")
    G = _gram(G, d)
    lam = _precision(precision, n, d)
    tr = np.trace(np.linalg.inv(G[..., None, :, :] + lam), axis1=-2, axis2=-1)  # (..., n)
    out = sw * np.sum(tr, axis=-1) / (n * d)
    return float(out) if out.ndim == 0 else out


def _trace_per_row(tr_precision: Any, n: int) -> np.ndarray:
    tr = np.atleast_1d(as_finite_array("tr_precision", tr_precision))
    if tr.ndim != 1 or tr.size not in (1, n):
        raise ShapeError(f"tr_precision must be a scalar or have shape ({n},), got {np.shape(tr_precision)}")
    if np.any(tr < 0):
        raise ParameterError(f"tr_precision must be >= 0, got {np.asarray(tr_precision).tolist()}")
    return np.broadcast_to(tr, (n,))


def bayesian_sic_from_traces(
    N: Any,
    tr_psi_u: float,
    tr_psi_w: float,
    m: int,
    n: int,
    sigma_u2: float,
    sigma_w2: float,
    sigma_x2: float = 1.0,
    *,
    tr_precision: Any,
) -> float | np.ndarray:
    """(C): ``gamma_B(N)``, eq:sic with ``sigma_x2 tr Psi_w`` increased by ``tr Lambda_i``:
    a lower bound of the Bayes risk (B) (the argument is in the module docstring).

    ``gamma_B(N) = (1/n) sum_i (m+n) sigma_w2 / (tr Lambda_i + sigma_x2 tr Psi_w + (N-1)[sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w])``,
    computed by :func:`~encctl_gym.security.complexity.sic_from_traces` with the initial-state
    variance ``sigma_x2 + tr Lambda_i / tr Psi_w`` (the same formula; ``tr Lambda = 0`` is
    ``gamma(N)`` exactly).

    Parameters
    ----------
    N : int or array_like of int
        Sample sizes (>= 2).
    tr_psi_u, tr_psi_w, m, n, sigma_u2, sigma_w2, sigma_x2
        As in :func:`~encctl_gym.security.complexity.sic_from_traces`.
    tr_precision : float or array_like of shape (n,)
        ``tr Lambda_i`` (>= 0), one for all rows or one per row.

    Returns
    -------
    float or ndarray
        Same shape as ``N``.
    """
    n = check_int("n", n, minimum=1)
    tr_w = check_positive("tr_psi_w", tr_psi_w)
    rows = _trace_per_row(tr_precision, n)
    parts = [sic_from_traces(N, tr_psi_u, tr_w, m, n, sigma_u2, sigma_w2, sigma_x2 + float(t) / tr_w) for t in rows]
    out = np.mean(np.stack([np.asarray(p, dtype=float) for p in parts]), axis=0)
    return float(out) if np.ndim(out) == 0 else out


def bayesian_sample_identifying_complexity(
    N: Any, A: Any, B: Any, *, sigma_u2: float, sigma_w2: float, sigma_x2: float = 1.0, precision: Any
) -> float | np.ndarray:
    """(C) for the plant ``(A, B)``: :func:`bayesian_sic_from_traces` with its Gramians, a lower
    bound of the Bayes risk (B) for plants concentrated near ``(A, B)`` (not of the error at a
    fixed plant: a prior mean far from it adds a bias, one near it removes error).

    Parameters
    ----------
    N : int or array_like of int
    A, B : array_like
        Plant of eq:system (``A`` Schur stable).
    sigma_u2, sigma_w2, sigma_x2 : float
    precision : array_like, shape (n + m, n + m) or (n, n + m, n + m)
        ``Lambda_i`` of the prior (e.g. ``BayesianLeastSquares(...).precision(n, m)``).

    Returns
    -------
    float or ndarray
    """
    A, B = check_system(A, B)
    n, m = B.shape
    lam = _precision(precision, n, n + m)
    tr_u = float(np.trace(controllability_gramian(A, B)))
    tr_w = float(np.trace(noise_gramian(A)))
    tr_lam = np.trace(lam, axis1=-2, axis2=-1)
    return bayesian_sic_from_traces(N, tr_u, tr_w, m, n, sigma_u2, sigma_w2, sigma_x2, tr_precision=tr_lam)


def prior_sample_equivalent(
    tr_precision: Any, tr_psi_u: float, tr_psi_w: float, m: int, *, sigma_u2: float, sigma_w2: float
) -> float:
    """Samples a prior is worth in (C): ``tr Lambda / [sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w]``.

    ``gamma_B(N) = gamma(N + s)`` with ``s`` this number (for one ``tr Lambda`` shared by the
    rows): the attacker with the prior reaches an error level ``s`` samples earlier.

    Parameters
    ----------
    tr_precision : float
        ``tr Lambda`` (>= 0).
    tr_psi_u, tr_psi_w : float
        Gramian traces.
    m : int
    sigma_u2, sigma_w2 : float

    Returns
    -------
    float
    """
    t = float(_trace_per_row(tr_precision, 1)[0])
    m = check_int("m", m, minimum=1)
    K = check_positive("sigma_u2", sigma_u2) * (float(tr_psi_u) + m) + check_positive("sigma_w2", sigma_w2) * check_positive(
        "tr_psi_w", tr_psi_w
    )
    return t / K


def stationary_regressor_covariance(A: Any, B: Any, *, sigma_u2: float, sigma_w2: float) -> np.ndarray:
    """``Sigma = blockdiag(sigma_u2 Psi_u + sigma_w2 Psi_w, sigma_u2 I_m)``: the stationary
    covariance of the regressor ``z = [x; u]`` of eq:data under i.i.d. ``N(0, sigma_u2 I)``
    inputs (Theorem thm:sic), with the Gramians of :mod:`encctl_gym.security.gramians`.

    Parameters
    ----------
    A, B : array_like
        Plant of eq:system (``A`` Schur stable).
    sigma_u2, sigma_w2 : float
        Input and noise variances (> 0).

    Returns
    -------
    numpy.ndarray, shape (n + m, n + m)
    """
    A, B = check_system(A, B)
    n, m = B.shape
    su = check_positive("sigma_u2", sigma_u2)
    sw = check_positive("sigma_w2", sigma_w2)
    S = np.zeros((n + m, n + m))
    S[:n, :n] = su * controllability_gramian(A, B) + sw * noise_gramian(A)
    S[n:, n:] = su * np.eye(m)
    return S


def sic_tightness(A: Any, B: Any, *, sigma_u2: float, sigma_w2: float) -> float:
    """How far below the least-squares error eq:sic lies at large ``N``: their ratio,
    ``(n + m)^2 / (tr Sigma tr Sigma^-1)``, with ``Sigma`` of :func:`stationary_regressor_covariance`.

    The mean least-squares error of Definition def:error tends to ``sigma_w2 tr(Sigma^-1) /
    ((n + m) N)`` (the first identity of the proof of Theorem thm:sic with ``G ~ N Sigma``);
    eq:sic tends to ``(n + m) sigma_w2 / (N tr Sigma)``, its denominator being ``(N - 1) tr Sigma``.
    The proof's step ``tr X^-1 >= d^2 / tr X`` is what separates them, so the ratio is the
    harmonic over the arithmetic mean of the eigenvalues of ``Sigma``: 1 only for isotropic
    regressors, and as small as the regressors are unevenly excited (a state the inputs barely
    reach, with noise variance far below ``sigma_u2``).

    Returns
    -------
    float
        In ``(0, 1]``.
    """
    # positive definite: the state block is at least sigma_w2 Psi_w >= sigma_w2 I, the input block sigma_u2 I
    lam = np.linalg.eigvalsh(stationary_regressor_covariance(A, B, sigma_u2=sigma_u2, sigma_w2=sigma_w2))
    d = len(lam)
    return float(min(1.0, d * d / (np.sum(lam) * np.sum(1.0 / lam))))


def _wishart(rng: np.random.Generator, L: np.ndarray, T: int, draws: int) -> np.ndarray:
    """``draws`` samples of ``Wishart_d(L L^T, T)`` (Bartlett's decomposition for ``T >= d``)."""
    d = L.shape[0]
    if T < d:
        Z = rng.standard_normal((draws, d, T))
        W = Z @ np.swapaxes(Z, 1, 2)
    else:
        C = np.tril(rng.standard_normal((draws, d, d)), -1)
        idx = np.arange(d)
        C[:, idx, idx] = np.sqrt(rng.chisquare(T - idx, size=(draws, d)))
        W = C @ np.swapaxes(C, 1, 2)
    return L @ W @ L.T


def bayes_risk_iid_gaussian(
    N: int, covariance: Any, *, precision: Any, sigma_w2: float, n: int, draws: int = 20_000, seed: int = 0
) -> tuple[float, float]:
    """The Bayes risk (B) for ``T = N - 1`` i.i.d. ``N(0, Sigma)`` regressor columns, and its error.

    ``E[epsilon] = (sigma_w2 / c) sum_i E tr (Lambda_i + G)^{-1}`` with ``G ~ Wishart_d(Sigma, T)``.
    Without a prior (``precision`` zero: least squares) it is exact, from the mean of the
    inverse Wishart law, ``E G^{-1} = Sigma^{-1} / (T - d - 1)``:
    ``(sigma_w2 / d) tr Sigma^{-1} / (T - d - 1)`` for ``T > d + 1`` and infinite otherwise (the
    mean error does not exist there, :mod:`encctl_gym.ident.tails`). With a prior it is a Monte
    Carlo over ``draws`` Wishart matrices, returned with its standard error. For eq:system the
    columns are correlated in time and start from ``x_0``, so with ``Sigma`` of
    :func:`stationary_regressor_covariance` this is the i.i.d. counterpart of the attack, not its
    exact value (compare :func:`bayes_risk_given_gram` on simulated Gram matrices).

    Parameters
    ----------
    N : int
        Sample size (>= 2).
    covariance : array_like, shape (d, d)
        ``Sigma`` (symmetric positive definite).
    precision : array_like, shape (d, d) or (n, d, d)
        ``Lambda_i`` (zero: least squares).
    sigma_w2 : float
        Noise variance (> 0).
    n : int
        Rows of ``theta``.
    draws : int
        Wishart draws when a prior is given (>= 2).
    seed : int
        Seed of those draws.

    Returns
    -------
    (float, float)
        The value and its standard error (0 when exact).
    """
    N = check_int("N", N, minimum=2, maximum=2**53)
    n = check_int("n", n, minimum=1)
    sw = check_positive("sigma_w2", sigma_w2)
    S = as_finite_array("covariance", covariance)
    d = S.shape[0] if S.ndim == 2 else -1
    if S.ndim != 2 or S.shape != (d, d) or d <= n:
        raise ShapeError(f"covariance must be (n + m) x (n + m) with m >= 1 for n={n}, got {S.shape}")
    if not np.allclose(S, S.T, rtol=1e-12, atol=0.0):
        raise ParameterError("covariance must be symmetric")
    try:
        L = np.linalg.cholesky(S)
    except np.linalg.LinAlgError:
        raise ParameterError("covariance must be positive definite") from None
    lam = _precision(precision, n, d)
    T = N - 1
    if not np.any(lam):
        if T <= d + 1:
            return math.inf, 0.0
        return sw * float(np.trace(np.linalg.inv(S))) / (d * (T - d - 1)), 0.0
    draws = check_int("draws", draws, minimum=2)
    check_memory(f"draws = {format_value(draws)}", 8 * draws, advice="ask for fewer draws")
    rng = np.random.default_rng(check_int("seed", seed, minimum=0))
    vals = np.empty(draws)
    step = 4096
    for i in range(0, draws, step):
        G = _wishart(rng, L, T, min(step, draws - i))
        vals[i : i + G.shape[0]] = np.atleast_1d(bayes_risk_given_gram(G, precision=lam, sigma_w2=sw, n=n))
    return float(vals.mean()), float(vals.std(ddof=1) / math.sqrt(draws))
