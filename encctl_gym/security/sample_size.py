"""The minimum sample size ``N*`` of Theorem thm:opt_sec, for every sample identifying complexity.

``N*`` is the smallest sample size with ``gamma(N) < gamma_c`` (Definition def:security): the
adversary needs at least ``N*`` samples to identify the plant to the accuracy ``gamma_c``.

* eq:sic2 (the paper's Theorem thm:opt_sec, eq:opt_sec)::

      N* = floor((m + n) / (gamma_c [R_sigma (tr Psi_u + m) + tr Psi_w])) + 2

  the smallest integer with ``N - 1 > (m+n) / (gamma_c [...])`` (strict, so an integer ratio
  ``x`` gives ``x + 2``: the paper's ``floor(x) + 2`` is right in every case);
* eq:sic (exact complexity, Theorem thm:sic) in closed form,
  ``N* = max(2, floor(((m+n) sigma_w2 / gamma_c - sigma_x2 tr Psi_w) / D) + 2)`` with
  ``D = sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w``; eq:sic lies below eq:sic2, so its ``N*``
  is never larger. With ``x = (m+n) / (gamma_c K)``, ``K = R_sigma (tr Psi_u + m) + tr Psi_w``,
  the exact threshold is ``x - delta``, ``delta = sigma_x2 tr Psi_w / (sigma_w2 K)``: the two
  differ (by one) exactly when ``frac(x) < delta`` (by more if ``delta >= 1``). For the paper's
  example ``x = 13157.89``, ``delta = 0.1316``: both give ``N* = 13159``;
* any complexity ``c / (N - 1)`` (the A-optimal ``gamma_opt`` of
  :mod:`~encctl_gym.security.attack_design`): :func:`sample_size_for_rate`;
* any nonincreasing complexity: :func:`minimum_sample_size` (exponential and binary search).

Arithmetic is exact (:mod:`~encctl_gym.security.exact`): design parameters and traces by the
decimal rule (``1e-6`` is 10^-6), computed values (``gamma(N)`` of a float function, the rate
of a numerical design) by the binary rule.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from fractions import Fraction
from typing import Any

from .._validation import check_int, check_nonnegative, format_value
from ..errors import ParameterError
from .exact import binary_fraction, decimal_fraction

__all__ = [
    "sample_size_for_rate",
    "optimal_sample_size",
    "exact_optimal_sample_size",
    "minimum_sample_size",
    "exact_sic_function",
    "exact_sic_asymptotic_function",
    "sic2_bracket",
    "check_complexity",
    "complexity_value",
]


def check_complexity(gamma: Any) -> Callable[[int], Any]:
    """``gamma`` if it is callable (a sample identifying complexity ``int -> number``).

    Raises
    ------
    ParameterError
        If ``gamma`` is not callable.
    """
    if not callable(gamma):
        raise ParameterError(f"gamma must be a callable sample identifying complexity N -> gamma(N), got {format_value(gamma)}")
    return gamma


def complexity_value(gamma: Callable[[int], Any], N: int) -> Fraction:
    """``gamma(N)`` exactly (the binary rule), checked: a finite real number >= 0.

    A complexity bounds a squared error (Definition def:sic), so a negative, NaN or non-numeric
    value is a :class:`ParameterError` naming it, never compared as if it were a number.
    """
    value = gamma(N)
    label = f"gamma({format_value(N)})"  # N may have thousands of digits (n_max = 10**5000)
    v = binary_fraction(label, value)
    if v < 0:
        raise ParameterError(f"{label} must be >= 0 (a sample identifying complexity), got {format_value(value)}")
    return v


def sample_size_for_rate(rate: Any, gamma_c: Any) -> int:
    """Smallest integer ``N >= 2`` with ``rate / (N - 1) < gamma_c``: ``floor(rate / gamma_c) + 2``.

    Every complexity of the form ``c / (N - 1)`` (eq:sic2 with ``c = (m+n)/K``; the A-optimal
    ``gamma_opt`` with ``c = sigma_w2 tr(Sigma^-1) / (n+m)``) is inverted by this; it is the
    ``N*`` of eq:opt_sec. Exact: ``rate`` by the binary rule (it is computed), ``gamma_c`` by the
    decimal rule.

    Parameters
    ----------
    rate : float or Fraction
        ``c > 0``.
    gamma_c : float or Fraction
        Acceptable estimation error (> 0).

    Returns
    -------
    int
    """
    c = binary_fraction("rate", rate)
    if c <= 0:
        raise ParameterError(f"rate must be > 0, got {format_value(rate)}")
    g = decimal_fraction("gamma_c", gamma_c)
    return math.floor(c / g) + 2


def sic2_bracket(tr_psi_u: Any, tr_psi_w: Any, m: int, r_sigma: Fraction) -> Fraction:
    """The bracket ``K = R_sigma (tr Psi_u + m) + tr Psi_w`` of eq:sic2 and eq:opt_sec, exactly."""
    tr_u = decimal_fraction("tr_psi_u", check_nonnegative("tr_psi_u", tr_psi_u), positive=False)
    tr_w = decimal_fraction("tr_psi_w", tr_psi_w)
    return r_sigma * (tr_u + m) + tr_w


def _ratio(r_sigma: Any) -> Fraction:
    r = decimal_fraction("r_sigma", r_sigma, positive=False)
    if r <= 0:
        raise ParameterError(f"r_sigma must be > 0, got {format_value(r_sigma)}")
    return r


def optimal_sample_size(tr_psi_u: Any, tr_psi_w: Any, m: int, n: int, *, r_sigma: Any, gamma_c: Any) -> int:
    """``N*`` of Theorem thm:opt_sec (eq:opt_sec), exactly.

    ``N* = floor((m + n) / (gamma_c [R_sigma (tr Psi_u + m) + tr Psi_w])) + 2``: the smallest
    sample size with ``gamma(N) < gamma_c`` for eq:sic2.

    Parameters
    ----------
    tr_psi_u, tr_psi_w : float
        Gramian traces (``>= 0`` and ``> 0``).
    m, n : int
        Input and state dimensions.
    r_sigma : float or Fraction
        ``R_sigma = sigma_u2 / sigma_w2 > 0``.
    gamma_c : float
        Acceptable estimation error (> 0).

    Returns
    -------
    int
    """
    m = check_int("m", m, 1)
    n = check_int("n", n, 1)
    return sample_size_for_rate(Fraction(m + n) / sic2_bracket(tr_psi_u, tr_psi_w, m, _ratio(r_sigma)), gamma_c)


def exact_optimal_sample_size(
    tr_psi_u: Any, tr_psi_w: Any, m: int, n: int, *, sigma_u2: Any, sigma_w2: Any, sigma_x2: Any = 1.0, gamma_c: Any
) -> int:
    """Smallest ``N >= 2`` with the exact complexity eq:sic below ``gamma_c`` (closed form).

    ``gamma(N) < gamma_c  <=>  N - 1 > q = ((m+n) sigma_w2 / gamma_c - sigma_x2 tr Psi_w) / D``
    with ``D = sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w``, so ``N* = max(2, floor(q) + 2)``.

    Parameters
    ----------
    sigma_u2, sigma_w2 : float
        Variances (> 0).
    sigma_x2 : float, default 1.0
        Variance of x_0 (>= 0).
    tr_psi_u, tr_psi_w, m, n, gamma_c
        As in :func:`optimal_sample_size`; returns the int ``N*``.
    """
    m = check_int("m", m, 1)
    n = check_int("n", n, 1)
    su = decimal_fraction("sigma_u2", sigma_u2)
    sw = decimal_fraction("sigma_w2", sigma_w2)
    sx = decimal_fraction("sigma_x2", check_nonnegative("sigma_x2", sigma_x2), positive=False)
    g = decimal_fraction("gamma_c", gamma_c)
    tr_u = decimal_fraction("tr_psi_u", check_nonnegative("tr_psi_u", tr_psi_u), positive=False)
    tr_w = decimal_fraction("tr_psi_w", tr_psi_w)
    D = su * (tr_u + m) + sw * tr_w
    q = ((m + n) * sw / g - sx * tr_w) / D
    return max(2, math.floor(q) + 2)


def minimum_sample_size(gamma: Callable[[int], Any], gamma_c: Any, *, n_min: int = 2, n_max: int = 2**256) -> int:
    """Smallest integer ``N >= n_min`` with ``gamma(N) < gamma_c``, by exponential and binary search.

    ``gamma`` must be nonincreasing in ``N`` (every sample identifying complexity of this
    package is). Values are compared exactly (``gamma(N)`` by the binary rule, ``gamma_c`` by the
    decimal rule).

    Parameters
    ----------
    gamma : callable
        ``int -> float | Fraction``.
    gamma_c : float
        Threshold (> 0).
    n_min : int, default 2
        Smallest admissible sample size.
    n_max : int, default 2**256
        Give up beyond this.

    Returns
    -------
    int

    Raises
    ------
    ParameterError
        If ``gamma`` is not callable or returns a value that is not a finite real >= 0,
        ``n_max < n_min``, or ``gamma(N) >= gamma_c`` up to ``n_max``.
    """
    check_complexity(gamma)
    n_min = check_int("n_min", n_min, 1)
    n_max = check_int("n_max", n_max, n_min)
    g_c = decimal_fraction("gamma_c", gamma_c)

    def below(N: int) -> bool:
        return complexity_value(gamma, N) < g_c

    def give_up() -> ParameterError:
        return ParameterError(f"gamma(N) stays >= gamma_c = {format_value(gamma_c)} up to N = {format_value(n_max)}")

    if below(n_min):
        return n_min
    if n_max == n_min:
        raise give_up()
    lo, hi = n_min, n_min + 1  # invariant: not below(lo), hi <= n_max
    while not below(hi):
        if hi >= n_max:
            raise give_up()
        lo, hi = hi, min(n_min + 2 * (hi - n_min), n_max)  # the last step tries n_max itself
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if below(mid):
            hi = mid
        else:
            lo = mid
    return hi


def exact_sic_function(
    tr_psi_u: Any, tr_psi_w: Any, m: int, n: int, *, sigma_u2: Any, sigma_w2: Any, sigma_x2: Any = 1.0
) -> Callable[[int], Fraction]:
    """eq:sic as an exact function ``N -> Fraction`` (for :func:`~encctl_gym.security.design.is_secure` and searches).

    Returns
    -------
    callable
        ``gamma(N) = (m+n) sigma_w2 / (sigma_x2 tr Psi_w + (N-1) D)`` as a Fraction.
    """
    m = check_int("m", m, 1)
    n = check_int("n", n, 1)
    su = decimal_fraction("sigma_u2", sigma_u2)
    sw = decimal_fraction("sigma_w2", sigma_w2)
    sx = decimal_fraction("sigma_x2", check_nonnegative("sigma_x2", sigma_x2), positive=False)
    tr_u = decimal_fraction("tr_psi_u", check_nonnegative("tr_psi_u", tr_psi_u), positive=False)
    tr_w = decimal_fraction("tr_psi_w", tr_psi_w)
    D = su * (tr_u + m) + sw * tr_w

    def gamma(N: int) -> Fraction:
        N = check_int("N", N, 2)
        return (m + n) * sw / (sx * tr_w + (N - 1) * D)

    return gamma


def exact_sic_asymptotic_function(tr_psi_u: Any, tr_psi_w: Any, m: int, n: int, *, r_sigma: Any) -> Callable[[int], Fraction]:
    """eq:sic2 as an exact function ``N -> Fraction``.

    Returns
    -------
    callable
        ``gamma(N) = (m+n) / ((N-1) [R_sigma (tr Psi_u + m) + tr Psi_w])`` as a Fraction.
    """
    m = check_int("m", m, 1)
    n = check_int("n", n, 1)
    K = sic2_bracket(tr_psi_u, tr_psi_w, m, _ratio(r_sigma))

    def gamma(N: int) -> Fraction:
        N = check_int("N", N, 2)
        return Fraction(m + n) / ((N - 1) * K)

    return gamma
