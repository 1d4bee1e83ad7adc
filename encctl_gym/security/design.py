"""Security parameter design: Definition def:security, Theorem thm:opt_sec, eq:opt_key.

Definition def:security: an encrypted control system is *secure* if no sample size ``N`` has
both ``gamma(N) < gamma_c`` (the adversary identifies the plant well enough) and
``tau(N, lam) <= tau_c`` (it can break the ``N`` ciphertexts within the defense period).
``gamma`` decreases and ``tau`` increases in ``N``, so with ``N*`` the smallest ``N`` with
``gamma(N) < gamma_c`` and ``N_max`` the largest ``N`` with ``tau(N, lam) <= tau_c``, the system
is secure iff ``N_max < N*`` iff ``gamma(N_max) >= gamma_c`` (:func:`is_secure`).

Theorem thm:opt_sec (eq:opt_sec), for the large-sample complexity eq:sic2::

    N*   = floor((m + n) / (gamma_c [R_sigma (tr Psi_u + m) + tr Psi_w])) + 2
    lam* = floor(log2(Upsilon tau_c / N*)) + 1

``N*`` is the smallest integer with ``N - 1 > (m+n) / (gamma_c [...])`` (strict, so an integer
ratio ``x`` gives ``x + 2``: the paper's ``floor(x) + 2`` is right in every case), and
``lam*`` the smallest integer with ``2^lam N* > Upsilon tau_c`` (strict; a power-of-two
ratio ``2^j`` gives ``j + 1``). Both are computed in exact rational arithmetic: floats are
read as their shortest decimal representation (``1e-6`` is 10^-6, ``442e15`` is 442 * 10^15;
see :func:`~encctl_gym.security.deciphering.exact_number`), so floors of exact integers are
never lost to rounding. Edge case: if ``Upsilon tau_c < N*`` the formula gives ``lam* <= 0``;
a security parameter is at least 1, so ``lam* = 1`` is returned (any key then outlasts the
defense period for ``N*`` samples).

The same recipe applied to the exact complexity eq:sic (``method="exact"``) gives the smallest
``N`` with ``gamma_sic(N) < gamma_c`` in closed form,
``N* = max(2, floor(((m+n) sigma_w2 / gamma_c - sigma_x2 tr Psi_w) / D) + 2)`` with
``D = sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w``. eq:sic lies below eq:sic2, so its ``N*`` is
never larger. Writing ``x = (m+n) / (gamma_c K)``, ``K = R_sigma (tr Psi_u + m) + tr Psi_w``,
the exact threshold is ``x - delta`` with ``delta = sigma_x2 tr Psi_w / (sigma_w2 K)``: the two
``N*`` differ (by one) exactly when ``frac(x) < delta`` (or more if ``delta >= 1``), and then
``lam*`` differs only if ``log2(Upsilon tau_c / N)`` crosses an integer between the two.
For the paper's example ``x = 13157.89``, ``delta = 8 / 60.8 = 0.1316``: both give
``N* = 13159`` and ``lam* = 74``.

eq:opt_key: the key length ``k*`` is the smallest ``k`` with ``Omega(k) >= 2^lam*``, where
``Omega(k) = exp((64/9)^(1/3) (ln 2^k)^(1/3) (ln ln 2^k)^(2/3))`` is the running time of the
general number field sieve (the fastest known attack on the ElGamal groups used here).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Callable

import numpy as np

from .._validation import check_int, check_nonnegative, check_positive, check_system
from ..errors import ParameterError
from .deciphering import (
    check_security_parameter,
    exact_number,
    max_affordable_samples,
)
from .gramians import controllability_gramian, noise_gramian

__all__ = [
    "SecurityDesign",
    "is_secure",
    "minimum_sample_size",
    "sample_size_for_rate",
    "optimal_sample_size",
    "exact_optimal_sample_size",
    "optimal_security_parameter",
    "exact_sic_function",
    "exact_sic_asymptotic_function",
    "design_from_traces",
    "design_security_parameter",
    "paper_design_example",
    "gnfs_complexity",
    "gnfs_log2_complexity",
    "bit_security_of_key_length",
    "minimum_key_length",
    "PAPER_EXAMPLE",
]

GNFS_CONSTANT = (64.0 / 9.0) ** (1.0 / 3.0)

#: The design example of Section "Numerical Simulation" (Psi_w = 2I, Psi_u = 0.5I, R = 100).
PAPER_EXAMPLE: dict[str, Any] = {
    "tr_psi_u": 2,
    "tr_psi_w": 8,
    "m": 4,
    "n": 4,
    "sigma_u2": 10,
    "sigma_w2": 0.1,
    "sigma_x2": 1,
    "gamma_c": 1e-6,
    "tau_c": 31536e4,
    "upsilon": 442e15,
}


@dataclass(frozen=True)
class SecurityDesign:
    """Result of a security parameter design (Theorem thm:opt_sec and eq:opt_key).

    Attributes
    ----------
    method : str
        ``"asymptotic"`` (eq:sic2, the paper's Theorem thm:opt_sec), ``"exact"`` (eq:sic),
        ``"closed_loop"``, ``"open_loop"`` or ``"gaussian"`` (robust designs of
        :mod:`encctl_gym.security.attack_design`).
    N_star : int
        Smallest sample size with ``gamma(N) < gamma_c``.
    lam_star : int
        Smallest security parameter with ``tau(N*, lam) > tau_c``.
    k_star : int
        Smallest key length with ``Omega(k) >= 2^lam*`` (eq:opt_key).
    gamma_c, tau_c, upsilon : float
        Design parameters (acceptable error, defense period in s, adversary FLOPS).
    m, n : int
        Input and state dimensions.
    sigma_u2, sigma_w2, sigma_x2 : float
        Variances of attack input, noise, initial state.
    tr_psi_u, tr_psi_w : float
        Gramian traces.
    gamma_at_N_star : float
        ``gamma(N*)`` (< gamma_c).
    gamma_before_N_star : float
        ``gamma(N* - 1)`` (>= gamma_c; ``nan`` when ``N* = 2``).
    bit_security : float
        ``log2 Omega(k*)`` (>= lam*).
    """

    method: str
    N_star: int
    lam_star: int
    k_star: int
    gamma_c: float
    tau_c: float
    upsilon: float
    m: int
    n: int
    sigma_u2: float
    sigma_w2: float
    sigma_x2: float
    tr_psi_u: float
    tr_psi_w: float
    gamma_at_N_star: float
    gamma_before_N_star: float
    bit_security: float

    @property
    def r_sigma(self) -> float:
        """Variance ratio ``R_sigma = sigma_u2 / sigma_w2``."""
        return self.sigma_u2 / self.sigma_w2

    def to_dict(self) -> dict[str, Any]:
        """The fields (and ``r_sigma``) as a JSON-ready dict."""
        d = dataclasses.asdict(self)
        d["r_sigma"] = self.r_sigma
        return d


# --------------------------------------------------------------------------- exact helpers
def _to_fraction(name: str, value: Any) -> Fraction:
    """A computed number as an exact fraction (floats by their exact binary value)."""
    if isinstance(value, Fraction):
        return value
    if isinstance(value, (numbers.Integral, np.integer)) and not isinstance(value, bool):
        return Fraction(int(value))
    if isinstance(value, (numbers.Real, np.floating)) and not isinstance(value, bool):
        v = float(value)
        if math.isnan(v):
            raise ParameterError(f"{name} is NaN")
        if math.isinf(v):
            raise ParameterError(f"{name} is infinite")
        return Fraction(v)
    raise ParameterError(f"{name} must be a real number, got {value!r}")


def _floor_log2(x: Fraction) -> int:
    """Exact ``floor(log2 x)`` for a positive fraction."""
    p, q = x.numerator, x.denominator
    k = p.bit_length() - q.bit_length()
    # now 2^(k-1) < p/q < 2^(k+1); decide between k-1 and k
    if (p >= q << k) if k >= 0 else ((p << -k) >= q):
        return k
    return k - 1


def sample_size_for_rate(rate: Any, gamma_c: Any) -> int:
    """Smallest integer ``N >= 2`` with ``rate / (N - 1) < gamma_c``: ``floor(rate / gamma_c) + 2``.

    Every complexity of the form ``c / (N - 1)`` (eq:sic2 with ``c = (m+n)/K``; the A-optimal
    ``gamma_opt`` with ``c = sigma_w2 tr(Sigma^-1) / (n+m)``) is inverted by this; it is the
    ``N*`` of eq:opt_sec. Exact (rational) arithmetic.

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
    c = exact_number("rate", rate) if not isinstance(rate, Fraction) else rate
    if c <= 0:
        raise ParameterError(f"rate must be > 0, got {rate!r}")
    g = exact_number("gamma_c", gamma_c)
    return math.floor(c / g) + 2


# --------------------------------------------------------------------------- sample sizes
def _bracket(tr_psi_u: Any, tr_psi_w: Any, m: int, r_sigma: Fraction) -> Fraction:
    tr_u = exact_number("tr_psi_u", check_nonnegative("tr_psi_u", tr_psi_u), positive=False)
    tr_w = exact_number("tr_psi_w", tr_psi_w)
    return r_sigma * (tr_u + m) + tr_w


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
    r = r_sigma if isinstance(r_sigma, Fraction) else exact_number("r_sigma", r_sigma)
    if r <= 0:
        raise ParameterError(f"r_sigma must be > 0, got {r_sigma!r}")
    return sample_size_for_rate(Fraction(m + n) / _bracket(tr_psi_u, tr_psi_w, m, r), gamma_c)


def exact_optimal_sample_size(
    tr_psi_u: Any,
    tr_psi_w: Any,
    m: int,
    n: int,
    *,
    sigma_u2: Any,
    sigma_w2: Any,
    sigma_x2: Any = 1.0,
    gamma_c: Any,
) -> int:
    """Smallest ``N >= 2`` with the exact complexity eq:sic below ``gamma_c`` (closed form).

    ``gamma(N) < gamma_c  <=>  N - 1 > q = ((m+n) sigma_w2 / gamma_c - sigma_x2 tr Psi_w) / D``
    with ``D = sigma_u2 (tr Psi_u + m) + sigma_w2 tr Psi_w``, so ``N* = max(2, floor(q) + 2)``.

    Parameters
    ----------
    tr_psi_u, tr_psi_w : float
        Gramian traces.
    m, n : int
        Dimensions.
    sigma_u2, sigma_w2 : float
        Variances (> 0).
    sigma_x2 : float, default 1.0
        Variance of x_0 (>= 0).
    gamma_c : float
        Acceptable estimation error (> 0).

    Returns
    -------
    int
    """
    m = check_int("m", m, 1)
    n = check_int("n", n, 1)
    su = exact_number("sigma_u2", sigma_u2)
    sw = exact_number("sigma_w2", sigma_w2)
    sx = exact_number("sigma_x2", check_nonnegative("sigma_x2", sigma_x2), positive=False)
    g = exact_number("gamma_c", gamma_c)
    tr_u = exact_number("tr_psi_u", check_nonnegative("tr_psi_u", tr_psi_u), positive=False)
    tr_w = exact_number("tr_psi_w", tr_psi_w)
    D = su * (tr_u + m) + sw * tr_w
    q = ((m + n) * sw / g - sx * tr_w) / D
    return max(2, math.floor(q) + 2)


def minimum_sample_size(
    gamma: Callable[[int], Any], gamma_c: Any, *, n_min: int = 2, n_max: int = 2**256
) -> int:
    """Smallest integer ``N >= n_min`` with ``gamma(N) < gamma_c``, by exponential and binary search.

    ``gamma`` must be nonincreasing in ``N`` (every sample identifying complexity of this
    package is). Values are compared exactly (float results by their binary value, ``gamma_c``
    by its decimal representation).

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
        If ``gamma(N) >= gamma_c`` up to ``n_max``.
    """
    n_min = check_int("n_min", n_min, 1)
    g_c = exact_number("gamma_c", gamma_c)

    def below(N: int) -> bool:
        return _to_fraction(f"gamma({N})", gamma(N)) < g_c

    if below(n_min):
        return n_min
    lo, hi = n_min, n_min + 1  # invariant: not below(lo)
    while not below(hi):
        lo, hi = hi, n_min + 2 * (hi - n_min)
        if hi > n_max:
            raise ParameterError(f"gamma(N) stays >= gamma_c = {gamma_c!r} up to N = {n_max}")
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if below(mid):
            hi = mid
        else:
            lo = mid
    return hi


def optimal_security_parameter(N_star: int, *, tau_c: Any, upsilon: Any) -> int:
    """``lam*`` of Theorem thm:opt_sec (eq:opt_sec), exactly.

    ``lam* = floor(log2(Upsilon tau_c / N*)) + 1``, the smallest integer with
    ``tau(N*, lam) = 2^lam N* / Upsilon > tau_c``. Returns at least 1 (see module notes).

    Parameters
    ----------
    N_star : int
        Minimum sample size (>= 1).
    tau_c : float
        Defense period in seconds (> 0).
    upsilon : float
        Adversary FLOPS (> 0).

    Returns
    -------
    int
    """
    N_star = check_int("N_star", N_star, 1)
    y = exact_number("upsilon", upsilon) * exact_number("tau_c", tau_c) / N_star
    return max(1, _floor_log2(y) + 1)


# --------------------------------------------------------------------------- exact complexities
def exact_sic_function(
    tr_psi_u: Any, tr_psi_w: Any, m: int, n: int, *, sigma_u2: Any, sigma_w2: Any, sigma_x2: Any = 1.0
) -> Callable[[int], Fraction]:
    """eq:sic as an exact function ``N -> Fraction`` (for :func:`is_secure` and searches).

    Returns
    -------
    callable
        ``gamma(N) = (m+n) sigma_w2 / (sigma_x2 tr Psi_w + (N-1) D)`` as a Fraction.
    """
    m = check_int("m", m, 1)
    n = check_int("n", n, 1)
    su = exact_number("sigma_u2", sigma_u2)
    sw = exact_number("sigma_w2", sigma_w2)
    sx = exact_number("sigma_x2", check_nonnegative("sigma_x2", sigma_x2), positive=False)
    tr_u = exact_number("tr_psi_u", check_nonnegative("tr_psi_u", tr_psi_u), positive=False)
    tr_w = exact_number("tr_psi_w", tr_psi_w)
    D = su * (tr_u + m) + sw * tr_w

    def gamma(N: int) -> Fraction:
        N = check_int("N", N, 2)
        return (m + n) * sw / (sx * tr_w + (N - 1) * D)

    return gamma


def exact_sic_asymptotic_function(
    tr_psi_u: Any, tr_psi_w: Any, m: int, n: int, *, r_sigma: Any
) -> Callable[[int], Fraction]:
    """eq:sic2 as an exact function ``N -> Fraction``.

    Returns
    -------
    callable
        ``gamma(N) = (m+n) / ((N-1) [R_sigma (tr Psi_u + m) + tr Psi_w])`` as a Fraction.
    """
    m = check_int("m", m, 1)
    n = check_int("n", n, 1)
    r = r_sigma if isinstance(r_sigma, Fraction) else exact_number("r_sigma", r_sigma)
    K = _bracket(tr_psi_u, tr_psi_w, m, r)

    def gamma(N: int) -> Fraction:
        N = check_int("N", N, 2)
        return Fraction(m + n) / ((N - 1) * K)

    return gamma


# --------------------------------------------------------------------------- Definition def:security
def is_secure(
    lam: Any,
    *,
    gamma: Callable[[int], Any],
    gamma_c: Any,
    tau_c: Any,
    upsilon: Any,
    scheme: str = "modified",
    adversary: str = "eavesdropper",
    gamma_infimum: Any = 0.0,
) -> bool:
    """Definition def:security, evaluated exactly.

    Insecure iff some integer ``N >= 2`` has ``gamma(N) < gamma_c`` and ``tau(N, lam) <= tau_c``.
    With ``gamma`` nonincreasing and ``tau`` nondecreasing in ``N`` this holds iff the largest
    affordable ``N_max`` (:func:`~encctl_gym.security.deciphering.max_affordable_samples`,
    exact for integer ``lam``) is >= 2 and ``gamma(N_max) < gamma_c`` (exact comparison). When
    one break reveals every sample (``scheme="static"``, or ``"token"`` against a ``"server"``)
    and that break is affordable, ``N_max`` is infinite and the system is secure iff
    ``gamma_infimum >= gamma_c``. ``N = 1`` gives no regression column (eq:estimate) and never
    counts.

    Parameters
    ----------
    lam : int or float
        Security parameter (integer >= 1, or real > 0 evaluated in floating point).
    gamma : callable
        Sample identifying complexity ``int -> float | Fraction``, nonincreasing (e.g.
        :func:`exact_sic_asymptotic_function`, or ``AttackDesign.gamma``).
    gamma_c : float
        Acceptable estimation error (> 0).
    tau_c : float
        Defense period, seconds (> 0).
    upsilon : float
        Adversary FLOPS (> 0).
    scheme, adversary : str
        See :mod:`encctl_gym.security.deciphering`.
    gamma_infimum : float, default 0.0
        ``lim_{N->inf} gamma(N)`` (0 for every complexity here).

    Returns
    -------
    bool
    """
    check_security_parameter(lam)
    g_c = exact_number("gamma_c", gamma_c)
    n_max = max_affordable_samples(tau_c, lam, upsilon, scheme=scheme, adversary=adversary)
    if n_max == math.inf:
        return _to_fraction("gamma_infimum", check_nonnegative("gamma_infimum", gamma_infimum)) >= g_c
    if n_max < 2:
        return True
    return not (_to_fraction(f"gamma({n_max})", gamma(int(n_max))) < g_c)


# --------------------------------------------------------------------------- eq:opt_key
def _check_key_lengths(k: Any) -> tuple[np.ndarray, bool]:
    if np.ndim(k) == 0:
        kk = k.item() if isinstance(k, np.ndarray) else k
        return np.asarray(float(check_int("k", kk, 2))), True
    arr = np.asarray(k, dtype=np.float64)
    if arr.size == 0 or not np.all(np.isfinite(arr)) or not np.all(arr == np.round(arr)) or np.any(arr < 2):
        raise ParameterError(f"k must contain integers >= 2, got {np.asarray(k)!r}")
    return arr, False


def gnfs_log2_complexity(k: Any) -> float | np.ndarray:
    """``log2 Omega(k)``: bits of work of the general number field sieve on a ``k``-bit group (eq:opt_key).

    ``Omega(k) = exp((64/9)^(1/3) (ln 2^k)^(1/3) (ln ln 2^k)^(2/3))``, evaluated in double
    precision through logarithms (no overflow for any ``k``).

    Parameters
    ----------
    k : int or array_like of int
        Key (modulus) bit length, >= 2 (``ln ln 2^k > 0`` needs ``k >= 2``).

    Returns
    -------
    float or ndarray
    """
    kf, scalar = _check_key_lengths(k)
    ln_n = kf * math.log(2.0)
    val = GNFS_CONSTANT * np.cbrt(ln_n) * np.cbrt(np.log(ln_n) ** 2) / math.log(2.0)
    return float(val) if scalar else val


def gnfs_complexity(k: Any) -> float | np.ndarray:
    """``Omega(k)`` of eq:opt_key (operations); ``inf`` beyond the float range.

    Parameters
    ----------
    k : int or array_like of int
        Key bit length, >= 2.

    Returns
    -------
    float or ndarray
    """
    with np.errstate(over="ignore"):
        val = np.exp2(gnfs_log2_complexity(k))
    return float(val) if np.ndim(val) == 0 else val


def bit_security_of_key_length(k: Any) -> float | np.ndarray:
    """Bit security (Definition def:bit_sec) of a ``k``-bit key under the GNFS: ``log2 Omega(k)``.

    Parameters
    ----------
    k : int or array_like of int
        Key bit length, >= 2.

    Returns
    -------
    float or ndarray
    """
    return gnfs_log2_complexity(k)


def minimum_key_length(lam: Any) -> int:
    """``k*`` of eq:opt_key: the smallest ``k`` with ``Omega(k) >= 2^lam``.

    ``log2 Omega`` increases with ``k`` (``k >= 2``), so this is an exponential plus binary
    search; values are compared in double precision (ties within ~1e-12 bit are not resolved
    exactly; the paper's example ``lam = 74`` has margin 0.004 bit at ``k = 712``).

    Parameters
    ----------
    lam : int or float
        Security parameter (integer >= 1 or real > 0).

    Returns
    -------
    int
        ``k* >= 2``.
    """
    lam_v = float(check_security_parameter(lam))

    def ok(k: int) -> bool:
        return gnfs_log2_complexity(k) >= lam_v

    if ok(2):
        return 2
    lo, hi = 2, 4
    while not ok(hi):
        lo, hi = hi, hi * 2
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if ok(mid):
            hi = mid
        else:
            lo = mid
    return hi


# --------------------------------------------------------------------------- full designs
def _gamma_float(gamma: Callable[[int], Any], N: int) -> float:
    return float(gamma(N)) if N >= 2 else math.nan


def design_from_traces(
    tr_psi_u: Any,
    tr_psi_w: Any,
    m: int,
    n: int,
    *,
    sigma_u2: Any,
    sigma_w2: Any,
    sigma_x2: Any = 1.0,
    gamma_c: Any,
    tau_c: Any,
    upsilon: Any,
    method: str = "asymptotic",
) -> SecurityDesign:
    """Theorem thm:opt_sec and eq:opt_key from the Gramian traces.

    Parameters
    ----------
    tr_psi_u, tr_psi_w : float
        ``tr Psi_u >= 0`` and ``tr Psi_w > 0``.
    m, n : int
        Dimensions.
    sigma_u2, sigma_w2 : float
        Attack-input and noise variances (> 0); only ``R_sigma`` matters for ``"asymptotic"``.
    sigma_x2 : float, default 1.0
        Variance of x_0 (used by ``"exact"``).
    gamma_c, tau_c, upsilon : float
        Acceptable error, defense period (s), adversary FLOPS (all > 0).
    method : {"asymptotic", "exact"}
        ``"asymptotic"``: eq:sic2 / eq:opt_sec as in the paper; ``"exact"``: eq:sic.

    Returns
    -------
    SecurityDesign
    """
    m = check_int("m", m, 1)
    n = check_int("n", n, 1)
    su = exact_number("sigma_u2", sigma_u2)
    sw = exact_number("sigma_w2", sigma_w2)
    check_nonnegative("sigma_x2", sigma_x2)
    if method == "asymptotic":
        N_star = optimal_sample_size(tr_psi_u, tr_psi_w, m, n, r_sigma=su / sw, gamma_c=gamma_c)
        gamma = exact_sic_asymptotic_function(tr_psi_u, tr_psi_w, m, n, r_sigma=su / sw)
    elif method == "exact":
        N_star = exact_optimal_sample_size(
            tr_psi_u, tr_psi_w, m, n, sigma_u2=su, sigma_w2=sw, sigma_x2=sigma_x2, gamma_c=gamma_c
        )
        gamma = exact_sic_function(tr_psi_u, tr_psi_w, m, n, sigma_u2=su, sigma_w2=sw, sigma_x2=sigma_x2)
    else:
        raise ParameterError(f"unknown method {method!r}; expected 'asymptotic' or 'exact'")
    return _finish_design(
        method, N_star, gamma, m=m, n=n, sigma_u2=sigma_u2, sigma_w2=sigma_w2, sigma_x2=sigma_x2,
        tr_psi_u=tr_psi_u, tr_psi_w=tr_psi_w, gamma_c=gamma_c, tau_c=tau_c, upsilon=upsilon,
    )


def _finish_design(
    method: str,
    N_star: int,
    gamma: Callable[[int], Any],
    *,
    m: int,
    n: int,
    sigma_u2: Any,
    sigma_w2: Any,
    sigma_x2: Any,
    tr_psi_u: Any,
    tr_psi_w: Any,
    gamma_c: Any,
    tau_c: Any,
    upsilon: Any,
) -> SecurityDesign:
    lam_star = optimal_security_parameter(N_star, tau_c=tau_c, upsilon=upsilon)
    k_star = minimum_key_length(lam_star)
    return SecurityDesign(
        method=method,
        N_star=N_star,
        lam_star=lam_star,
        k_star=k_star,
        gamma_c=float(check_positive("gamma_c", gamma_c)),
        tau_c=float(check_positive("tau_c", tau_c)),
        upsilon=float(check_positive("upsilon", upsilon)),
        m=m,
        n=n,
        sigma_u2=float(sigma_u2),
        sigma_w2=float(sigma_w2),
        sigma_x2=float(sigma_x2),
        tr_psi_u=float(tr_psi_u),
        tr_psi_w=float(tr_psi_w),
        gamma_at_N_star=_gamma_float(gamma, N_star),
        gamma_before_N_star=_gamma_float(gamma, N_star - 1),
        bit_security=float(gnfs_log2_complexity(k_star)),
    )


def design_security_parameter(
    A: Any,
    B: Any,
    *,
    sigma_u2: Any,
    sigma_w2: Any,
    sigma_x2: Any = 1.0,
    gamma_c: Any,
    tau_c: Any,
    upsilon: Any,
    method: str = "asymptotic",
) -> SecurityDesign:
    """Theorem thm:opt_sec and eq:opt_key for the plant ``(A, B)`` (Gramians by Lyapunov solves).

    Parameters
    ----------
    A, B : array_like
        Plant of eq:system (``A`` Schur stable).
    sigma_u2, sigma_w2, sigma_x2, gamma_c, tau_c, upsilon, method
        As in :func:`design_from_traces`.

    Returns
    -------
    SecurityDesign
    """
    A, B = check_system(A, B)
    n, m = B.shape
    tr_u = float(np.trace(controllability_gramian(A, B)))
    tr_w = float(np.trace(noise_gramian(A)))
    return design_from_traces(
        tr_u, tr_w, m, n, sigma_u2=sigma_u2, sigma_w2=sigma_w2, sigma_x2=sigma_x2,
        gamma_c=gamma_c, tau_c=tau_c, upsilon=upsilon, method=method,
    )


def paper_design_example(method: str = "asymptotic") -> SecurityDesign:
    """The design example of Section "Numerical Simulation": N* = 13159, lam* = 74, k* = 712.

    Parameters
    ----------
    method : {"asymptotic", "exact"}
        ``"asymptotic"`` is the paper's computation.

    Returns
    -------
    SecurityDesign
    """
    p = dict(PAPER_EXAMPLE)
    return design_from_traces(
        p.pop("tr_psi_u"), p.pop("tr_psi_w"), p.pop("m"), p.pop("n"), method=method, **p
    )
