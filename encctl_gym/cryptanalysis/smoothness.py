"""Smooth numbers: the factor base, smoothness tests, rational reconstruction, Dickman's rho.

The small pure functions under the index calculus (:mod:`.index_calculus`):

* :class:`FactorBase` - the primes up to a bound B, their product, a test "is x B-smooth?" that
  costs one big-integer remainder and a few squarings, and the factorisation of a smooth x;
* :func:`rational_reconstruction` - write a residue y mod p as a/b with |a|, |b| < sqrt(p), so
  that two numbers of half the size of p are tested instead of one of full size;
* :func:`dickman_rho` - the probability rho(u) that a random integer below x is x^(1/u)-smooth,
  behind the index calculus's cost model (expected smoothness tests per relation and per key).
"""

from __future__ import annotations

import math
from functools import lru_cache

import gmpy2
import numpy as np

from .._validation import check_int, check_nonnegative, format_value
from ..crypto.group.sieve import _small_primes
from ..errors import ParameterError, ResourceLimitError

__all__ = ["primes_up_to", "check_bound", "FactorBase", "rational_reconstruction", "dickman_rho", "MAX_BOUND"]

#: Largest smoothness bound B of a factor base: 2^24, 1077871 primes, built in about 4 s with a
#: peak of about 260 MB (sieve, Python integers, tuple and index). The index calculus's own choice
#: (:func:`~.index_calculus.choose_bound`) never exceeds 2^22.
MAX_BOUND = 1 << 24


def check_bound(bound: object) -> int:
    """Return the smoothness bound ``bound`` as an int after checking ``2 <= bound <= MAX_BOUND``.

    Raises
    ------
    ParameterError
        If ``bound`` is not an integer >= 2.
    ResourceLimitError
        If ``bound`` exceeds :data:`MAX_BOUND` (the sieve and the prime table would not fit).
    """
    bound = check_int("bound", bound, minimum=2)
    if bound > MAX_BOUND:
        log10_primes = math.log10(bound) - math.log10(math.log(bound) - 1.08)  # pi(B) ~ B / (ln B - 1.08)
        raise ResourceLimitError(
            f"a factor base of bound {format_value(bound)} would hold about 10^{log10_primes:.1f} primes (a sieve "
            f"of 10^{math.log10(bound):.1f} bytes and far more in Python integers); the limit is bound <= {MAX_BOUND} "
            "(MAX_BOUND)"
        )
    return bound


def primes_up_to(bound: int) -> tuple[int, ...]:
    """The primes ``2, 3, 5, ... <= bound`` (the sieve of :mod:`encctl_gym.crypto.group`, which
    the safe-prime generation uses for its candidates).

    Raises
    ------
    ParameterError
        If ``bound < 2``.
    ResourceLimitError
        If ``bound > MAX_BOUND``.
    """
    bound = check_bound(bound)
    return (2, *_small_primes(bound + 1))


class FactorBase:
    """The primes ``l <= B`` of an index calculus and the smoothness test over them.

    Parameters
    ----------
    bound : int
        The smoothness bound B, ``2 <= B <=`` :data:`MAX_BOUND` (a larger one raises
        :class:`~encctl_gym.errors.ResourceLimitError`).

    Attributes
    ----------
    primes : tuple of int
        ``2, 3, 5, ..., <= B``.
    index : dict
        Prime -> column index.
    product : gmpy2.mpz
        The product of the primes (squarefree).
    """

    def __init__(self, bound: int) -> None:
        self.bound = check_bound(bound)
        self.primes = primes_up_to(self.bound)
        self.index = {ell: i for i, ell in enumerate(self.primes)}
        self.product = _product(self.primes)
        self._np_primes = np.array(self.primes, dtype=np.uint64)

    def __len__(self) -> int:
        return len(self.primes)

    def __repr__(self) -> str:
        return f"FactorBase(bound={self.bound}, size={len(self)})"

    def is_smooth(self, x: int) -> bool:
        """True if every prime factor of ``|x|`` is ``<= B`` (x != 0).

        With P the product of the factor base, ``|x|`` is B-smooth iff ``|x|`` divides P^(2^e)
        once ``2^e >= log2 |x|`` (no prime occurs in ``|x|`` more than ``log2 |x|`` times), i.e.
        iff ``(P mod |x|)^(2^e) = 0 (mod |x|)``: one remainder of P and e squarings.

        Raises
        ------
        ParameterError
            If ``x`` is not an integer.
        """
        return self._is_smooth(check_int("x", x))

    def _is_smooth(self, x: int) -> bool:
        # is_smooth without the check: the relation search calls it for every trial.
        x = abs(x)
        if x <= 1:
            return x == 1
        e = max(1, (x.bit_length() - 1).bit_length())
        return gmpy2.powmod(self.product % x, 1 << e, x) == 0

    def factor(self, x: int) -> dict[int, int] | None:
        """The exponents ``{column: e}`` of a B-smooth ``|x|`` (``None`` if it is not smooth).

        Raises
        ------
        ParameterError
            If ``x`` is not a nonzero integer.
        """
        x = abs(check_int("x", x))
        if x == 0:
            raise ParameterError("0 has no factorisation over a factor base")
        if not self._is_smooth(x):
            return None
        out: dict[int, int] = {}
        if x < (1 << 64):
            hits = np.flatnonzero(np.uint64(x) % self._np_primes == 0)
            candidates = [self.primes[i] for i in hits]
        else:
            candidates = [ell for ell in self.primes if x % ell == 0]
        for ell in candidates:
            e = 0
            while x % ell == 0:
                x //= ell
                e += 1
            out[self.index[ell]] = e
        if x != 1:  # pragma: no cover - is_smooth guarantees full factorisation
            raise ParameterError(f"factorisation over the factor base left a cofactor {x}")
        return out


def _product(values: tuple[int, ...]) -> gmpy2.mpz:
    # Balanced product tree: far faster than a running product for thousands of factors.
    items = [gmpy2.mpz(v) for v in values] or [gmpy2.mpz(1)]
    while len(items) > 1:
        items = [items[i] * items[i + 1] if i + 1 < len(items) else items[i] for i in range(0, len(items), 2)]
    return items[0]


def rational_reconstruction(y: int, p: int, bound: int | None = None) -> tuple[int, int]:
    """Return ``(a, b)`` with ``a = b y (mod p)``, ``0 <= a <= bound`` and ``|b| < p / bound``.

    The extended Euclidean algorithm on ``(p, y)`` keeps ``r_i = t_i y (mod p)`` and stops at
    the first remainder ``r_i <= bound`` (default ``isqrt(p)``); then ``|t_i| <= p / r_{i-1} <
    p / bound``. So y = a / b (mod p) with both a and b about sqrt(p): testing the two halves
    for smoothness succeeds with probability about ``rho(u/2)^2`` instead of ``rho(u)``.

    Parameters
    ----------
    y : int
        A residue in ``[1, p)``.
    p : int
        The modulus (> 1).
    bound : int, optional
        The size of ``a``, in ``[1, p)`` (default ``isqrt(p)``).

    Returns
    -------
    (int, int)
        ``a`` and ``b``; ``b`` may be negative, never 0.

    Raises
    ------
    ParameterError
        If ``p < 2``, ``y`` is not in ``[1, p)`` or ``bound`` is not in ``[1, p)``, or one of them
        is not an integer.
    """
    p = check_int("p", p, minimum=2)
    y = check_int("y", y)
    if not 0 < y < p:
        raise ParameterError(f"y must lie in [1, p), got y = {format_value(y)} for p = {format_value(p)}")
    bound = math.isqrt(p) if bound is None else check_int("bound", bound, minimum=1)
    if bound >= p:
        raise ParameterError(f"bound must lie in [1, p), got bound = {format_value(bound)} for p = {format_value(p)}")
    r0, r1, t0, t1 = p, y, 0, 1
    while r1 > bound:
        k = r0 // r1
        r0, r1 = r1, r0 - k * r1
        t0, t1 = t1, t0 - k * t1
    return r1, t1


# ----------------------------------------------------------------------------- Dickman rho
_RHO_TERMS = 90
#: Largest u for which :func:`dickman_rho` is computed (rho(40) is about 1e-71).
RHO_MAX_U = 40


@lru_cache(maxsize=1)
def _rho_coefficients() -> tuple[tuple[float, ...], ...]:
    # On [k-1, k] write rho(u) = sum_i c_i xi^i with xi = k - u in [0, 1]. Substituting into
    # u rho'(u) = -rho(u - 1), whose right side has the coefficients d_i of the previous
    # interval in the same xi, gives (k - xi) sum_i i c_i xi^(i-1) = sum_i d_i xi^i, hence
    #   c_i = (d_{i-1} + (i - 1) c_{i-1}) / (k i)            (i >= 1),
    # and the identity u rho(u) = integral of rho over [u - 1, u] at u = k gives
    # k c_0 = sum_i c_i / (i + 1), i.e. c_0 = sum_{i>=1} c_i / (i + 1) / (k - 1): a sum of
    # positive terms (no cancellation, so rho keeps its relative precision down to 1e-70).
    # The c_i shrink like k^-i, so 90 terms reach double precision. k = 1: rho = 1.
    coeffs = [tuple([1.0] + [0.0] * (_RHO_TERMS - 1))]
    for k in range(2, RHO_MAX_U + 1):
        d = coeffs[-1]
        c = [0.0] * _RHO_TERMS
        for i in range(1, _RHO_TERMS):
            c[i] = (d[i - 1] + (i - 1) * c[i - 1]) / (k * i)
        c[0] = math.fsum(c[i] / (i + 1) for i in range(1, _RHO_TERMS)) / (k - 1)
        coeffs.append(tuple(c))
    return tuple(coeffs)


def dickman_rho(u: float) -> float:
    """Dickman's function rho(u): the asymptotic probability that an integer below x has no prime
    factor above x^(1/u).

    Solves the delay equation ``u rho'(u) = -rho(u - 1)`` (rho = 1 on [0, 1]) exactly interval
    by interval as power series (the method of Marsaglia, Zaman and Marsaglia, 1989); on [1, 2]
    it is ``1 - ln u``.

    Parameters
    ----------
    u : float
        A real number ``>= 0``; values above 40 are refused (rho(40) is about 1e-71).

    Raises
    ------
    ParameterError
        If ``u`` is not a finite real number (a string, None, complex, NaN, beyond the float64
        range), is negative or exceeds 40.
    """
    u = check_nonnegative("u", u)
    if u <= 1:
        return 1.0
    if u > RHO_MAX_U:
        raise ParameterError(f"dickman_rho is computed up to u = {RHO_MAX_U}, got u = {u:g}")
    k = math.ceil(u)
    xi = k - u
    c = _rho_coefficients()[k - 1]
    value = 0.0
    for coef in reversed(c):  # Horner
        value = value * xi + coef
    return value
