"""Sample identifying complexity (Definition def:sic) of the plant eq:system.

Implements (the estimation error of Definition def:error that these bound,
``epsilon = ||[A B] - [A_hat B_hat]||_F^2 / (n (n + m))``, lives in :mod:`encctl_gym.ident.error`
and is re-exported here)

* Theorem thm:sic (eq:sic), the complexity for i.i.d. Gaussian attack inputs,

  ``gamma(N) = (m+n) sigma_w2 / (sigma_x2 tr Psi_w + (N-1) [sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w])``;
* the Corollary (eq:sic2), its large-N form with ``R_sigma = sigma_u2 / sigma_w2``,

  ``gamma(N) = (m+n) / ((N-1) [R_sigma (tr Psi_u + m) + tr Psi_w])``;
* the upper bounds eq:bound ``(m+n) / ((N-1) m R_sigma)`` and ``(m+n) / ((N-1) n)``.

Every function comes in a trace-level form (``*_from_traces``) that needs no matrices, so the
paper's design example (``Psi_w = 2I``, ``Psi_u = 0.5I``) can be evaluated without a plant.

The sample size ``N`` (Definition def:adversary) is the number of pairs (u_t, x_t); the least
squares of eq:estimate uses ``N - 1`` regression columns, so ``N`` must be an integer >= 2
(scalar or array; the result has the same shape). ``sigma_x2`` (the variance of x_0 in
Theorem thm:sic) is kept apart from ``sigma_w2``; the threat model of the paper draws x_0
with variance ``sigma_w2`` and its simulations use ``sigma_x2 = 1``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import FLOAT_MAX, as_finite_array, check_int, check_nonnegative, check_positive, check_system, format_value
from ..errors import ParameterError
from ..ident.error import estimation_error  # Definition def:error; its home is the identification layer
from .gramians import controllability_gramian, noise_gramian

__all__ = [
    "estimation_error",
    "sample_identifying_complexity",
    "sample_identifying_complexity_asymptotic",
    "sic_from_traces",
    "sic_asymptotic_from_traces",
    "sic2_denominator",
    "input_upper_bound",
    "noise_upper_bound",
    "check_sample_size",
]


def check_sample_size(N: Any, name: str = "N") -> tuple[np.ndarray, bool]:
    """Validate a sample size (scalar or array of integers >= 2).

    Parameters
    ----------
    N : int or array_like of int
        Sample size(s) of Definition def:adversary.
    name : str
        Name used in error messages.

    Returns
    -------
    (ndarray of float64, bool)
        The sizes as floats and whether ``N`` was a scalar.

    Raises
    ------
    ParameterError
        If any entry is not an integer, is smaller than 2 or lies beyond the float64 range.
    """
    if np.ndim(N) == 0:
        return np.asarray(float(_check_count(name, N if not isinstance(N, np.ndarray) else N.item(), 2))), True
    arr = as_finite_array(name, N)
    if not np.all(arr == np.round(arr)):
        raise ParameterError(f"{name} must contain integers, got {format_value(np.asarray(N))}")
    if np.any(arr < 2):
        raise ParameterError(f"{name} must be >= 2 (N - 1 regression columns), got min {arr.min():g}")
    return arr, False


def _check_count(name: str, value: Any, minimum: int) -> int:
    """An integer count ``>= minimum`` (a sample size, a dimension) that converts to a float; a
    count beyond the float64 range is a :class:`ParameterError` naming it, never an ``OverflowError``."""
    v = check_int(name, value, minimum)
    if v > FLOAT_MAX:
        raise ParameterError(f"{name} must lie within the float64 range (<= {FLOAT_MAX:.4g}), got {format_value(v)}")
    return v


def _out(value: np.ndarray, scalar: bool) -> float | np.ndarray:
    """The result, as a float for a scalar ``N``; inputs so large that float64 overflows
    (``inf / inf``) are refused rather than returned as NaN."""
    if not np.all(np.isfinite(value)):
        raise ParameterError("the complexity overflows float64 for these inputs (a dimension, a variance or N near 1e308)")
    return float(value) if scalar else value


def _check_dims(m: Any, n: Any) -> tuple[int, int]:
    """The dimensions m and n: integers >= 1 whose sum lies within the float64 range."""
    m, n = _check_count("m", m, 1), _check_count("n", n, 1)
    _check_count("m + n", m + n, 2)
    return m, n


def sic2_denominator(tr_psi_u: float, tr_psi_w: float, m: int, r_sigma: float) -> float:
    """The bracket ``R_sigma (tr Psi_u + m) + tr Psi_w`` of eq:sic2 and eq:opt_sec.

    Parameters
    ----------
    tr_psi_u : float
        ``tr(Psi_u) >= 0``.
    tr_psi_w : float
        ``tr(Psi_w) > 0``.
    m : int
        Input dimension.
    r_sigma : float
        Variance ratio ``R_sigma = sigma_u2 / sigma_w2 > 0``.

    Returns
    -------
    float
    """
    tr_u = check_nonnegative("tr_psi_u", tr_psi_u)
    tr_w = check_positive("tr_psi_w", tr_psi_w)
    m = _check_count("m", m, 1)
    r = check_positive("r_sigma", r_sigma)
    return r * (tr_u + m) + tr_w


def sic_from_traces(
    N: Any, tr_psi_u: float, tr_psi_w: float, m: int, n: int, sigma_u2: float, sigma_w2: float, sigma_x2: float = 1.0
) -> float | np.ndarray:
    """Sample identifying complexity eq:sic (Theorem thm:sic) from the Gramian traces.

    ``gamma(N) = (m+n) sigma_w2 / (sigma_x2 tr Psi_w + (N-1)[sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w])``.

    Parameters
    ----------
    N : int or array_like of int
        Sample size(s), integers >= 2.
    tr_psi_u, tr_psi_w : float
        Traces of the Gramians ``Psi_u`` (>= 0) and ``Psi_w`` (> 0).
    m, n : int
        Input and state dimensions.
    sigma_u2, sigma_w2 : float
        Variances (> 0) of the attack input and of the noise.
    sigma_x2 : float, default 1.0
        Variance (>= 0) of the initial state x_0.

    Returns
    -------
    float or ndarray
        Same shape as ``N``.
    """
    Nf, scalar = check_sample_size(N)
    m, n = _check_dims(m, n)
    tr_u = check_nonnegative("tr_psi_u", tr_psi_u)
    tr_w = check_positive("tr_psi_w", tr_psi_w)
    su = check_positive("sigma_u2", sigma_u2)
    sw = check_positive("sigma_w2", sigma_w2)
    sx = check_nonnegative("sigma_x2", sigma_x2)
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is refused by _out
        den = sx * tr_w + (Nf - 1.0) * (su * (tr_u + m) + sw * tr_w)
        value = (m + n) * sw / den
    return _out(value, scalar)


def sic_asymptotic_from_traces(N: Any, tr_psi_u: float, tr_psi_w: float, m: int, n: int, r_sigma: float) -> float | np.ndarray:
    """Large-sample complexity eq:sic2 (Corollary of Theorem thm:sic) from the Gramian traces.

    ``gamma(N) = (m+n) / ((N-1) [R_sigma (tr Psi_u + m) + tr Psi_w])``, of the shape of ``N``.

    Parameters
    ----------
    N, tr_psi_u, tr_psi_w, m, n
        As in :func:`sic_from_traces`.
    r_sigma : float
        ``R_sigma = sigma_u2 / sigma_w2 > 0``.
    """
    Nf, scalar = check_sample_size(N)
    m, n = _check_dims(m, n)
    den = sic2_denominator(tr_psi_u, tr_psi_w, m, r_sigma)
    return _out((m + n) / ((Nf - 1.0) * den), scalar)


def sample_identifying_complexity(
    N: Any, A: Any, B: Any, *, sigma_u2: float, sigma_w2: float, sigma_x2: float = 1.0
) -> float | np.ndarray:
    """Sample identifying complexity eq:sic (Theorem thm:sic) of the plant ``(A, B)``.

    Parameters
    ----------
    A, B : array_like, shapes (n, n) and (n, m)
        Plant of eq:system; ``A`` Schur stable.
    N, sigma_u2, sigma_w2, sigma_x2
        As in :func:`sic_from_traces` (the attack input is i.i.d. Gaussian).

    Returns
    -------
    float or ndarray
        ``gamma(N)``, same shape as ``N``.

    Raises
    ------
    UnstableSystemError, ShapeError, ParameterError
    """
    tr_u, tr_w, m, n = _traces(A, B)
    return sic_from_traces(N, tr_u, tr_w, m, n, sigma_u2, sigma_w2, sigma_x2)


def sample_identifying_complexity_asymptotic(N: Any, A: Any, B: Any, *, r_sigma: float) -> float | np.ndarray:
    """Large-sample complexity eq:sic2 of the plant ``(A, B)``.

    ``N``, ``A``, ``B`` as in :func:`sample_identifying_complexity`, ``r_sigma`` as in
    :func:`sic_asymptotic_from_traces`; the result has the shape of ``N``.
    """
    tr_u, tr_w, m, n = _traces(A, B)
    return sic_asymptotic_from_traces(N, tr_u, tr_w, m, n, r_sigma)


def _traces(A: Any, B: Any) -> tuple[float, float, int, int]:
    """``tr Psi_u``, ``tr Psi_w``, m and n of the plant ``(A, B)`` (checked)."""
    A, B = check_system(A, B)
    n, m = B.shape
    return float(np.trace(controllability_gramian(A, B))), float(np.trace(noise_gramian(A))), m, n


def input_upper_bound(N: Any, m: int, n: int, r_sigma: float) -> float | np.ndarray:
    """Upper bound eq:bound of eq:sic2 as ``tr Psi_u -> 0``: ``(m+n) / ((N-1) m R_sigma)``.

    ``N``, ``m``, ``n`` as in :func:`sic_from_traces`; ``r_sigma = R_sigma > 0``.
    """
    Nf, scalar = check_sample_size(N)
    m, n = _check_dims(m, n)
    r = check_positive("r_sigma", r_sigma)
    return _out((m + n) / ((Nf - 1.0) * m * r), scalar)


def noise_upper_bound(N: Any, m: int, n: int) -> float | np.ndarray:
    """Upper bound of eq:sic2 for small ``R_sigma`` (after eq:bound): ``(m+n) / ((N-1) n)``.

    It holds because ``tr Psi_w >= n`` (with equality only for ``A = 0``).

    ``N``, ``m``, ``n`` as in :func:`sic_from_traces`.
    """
    Nf, scalar = check_sample_size(N)
    m, n = _check_dims(m, n)
    return _out((m + n) / ((Nf - 1.0) * n), scalar)
