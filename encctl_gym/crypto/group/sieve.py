"""The sieve of the safe-prime search: odd primes below a bound and the candidates q of a window
for which neither q nor 2q + 1 has a small factor (:func:`sieve_window`).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from ..._validation import check_int
from ...errors import ParameterError
from .. import arith
from ..arith import format_int as fmt

__all__ = ["sieve_window", "MAX_SIEVE_WINDOW", "MAX_SIEVE_LIMIT"]

#: Largest number of candidates sieved at once (:func:`sieve_window`, the ``window`` of
#: :func:`generate_safe_prime_group`): one byte each.
MAX_SIEVE_WINDOW = 1 << 24

#: Largest bound of the sieving primes of :func:`sieve_window` (the search itself uses at most
#: 2**20): the sieve of Eratosthenes below it takes one byte per integer.
MAX_SIEVE_LIMIT = 1 << 24


@cache
def _small_primes(limit: int) -> tuple[int, ...]:
    """Odd primes below ``limit`` (sieve of Eratosthenes)."""
    sieve = np.ones(limit, dtype=bool)
    sieve[:2] = False
    for i in range(2, int(limit**0.5) + 1):
        if sieve[i]:
            sieve[i * i :: i] = False
    return tuple(int(x) for x in np.flatnonzero(sieve) if x != 2)


def sieve_window(q0: int, n_cand: int, limit: int) -> np.ndarray:
    """Indices k of the candidates ``q = q0 + 2k`` (k < ``n_cand``) that survive the sieve.

    A candidate is struck out when q or 2q + 1 is divisible by an odd prime l < ``limit``:
    ``q0 + 2k = 0 (mod l)`` iff ``k = -q0 / 2``, and ``2(q0 + 2k) + 1 = 0 (mod l)`` iff
    ``k = (-1/2 - q0) / 2`` (mod l). ``q0`` must be odd and, so that a prime q is not struck
    out by itself, at least ``limit`` (larger than every sieving prime).

    Parameters
    ----------
    q0 : int
        The first candidate, odd and >= ``limit``.
    n_cand : int
        Number of candidates, in ``[0, MAX_SIEVE_WINDOW]``.
    limit : int
        Bound of the sieving primes, in ``[3, MAX_SIEVE_LIMIT]``.

    Returns
    -------
    numpy.ndarray
        The surviving indices k, ascending.

    Raises
    ------
    ParameterError
        If an argument is not an integer or is outside its range (the message names it).
    """
    q0 = arith.check_integer("q0", q0)
    n_cand = check_int("n_cand", n_cand, minimum=0, maximum=MAX_SIEVE_WINDOW)
    limit = check_int("limit", limit, minimum=3, maximum=MAX_SIEVE_LIMIT)
    if q0 % 2 == 0 or q0 < limit:
        raise ParameterError(
            f"q0 must be odd and >= limit = {limit} (a prime q below the sieve bound would strike itself out), got {fmt(q0)}"
        )
    primes = _small_primes(limit)
    inv2 = _inverses_of_two(limit)
    sieve = np.ones(n_cand, dtype=bool)
    for ell, i2 in zip(primes, inv2):
        r = q0 % ell
        sieve[(-r * i2) % ell :: ell] = False
        sieve[((-i2 - r) * i2) % ell :: ell] = False
    return np.flatnonzero(sieve)


@cache
def _inverses_of_two(limit: int) -> tuple[int, ...]:
    return tuple(pow(2, -1, ell) for ell in _small_primes(limit))
