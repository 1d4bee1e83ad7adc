"""Pollard's rho (Brent's cycle finding) and Pollard's p - 1: factorers for small moduli.

* :class:`PollardRhoFactorer` (``"rho-factor"``): J. M. Pollard, "A Monte Carlo method for
  factorization", BIT 15 (1975), with R. P. Brent's cycle finding and batched gcds ("An improved
  Monte Carlo factorization algorithm", BIT 20, 1980). The walk ``x -> x^2 + c mod n`` repeats
  modulo the smaller prime p after about ``sqrt(pi p / 2)`` steps, so a balanced k-bit modulus
  costs about ``2^(k/4)`` steps: fine to 80 bits, hopeless at 128.
* :class:`PollardPMinusOne` (``"p-1"``): J. M. Pollard, "Theorems on factorization and
  primality testing", Proc. Cambridge Philos. Soc. 76 (1974). Stage 1 computes
  ``a = 2^E mod n`` with E the product of all prime powers ``r^e <= B2`` for primes ``r <= B1``;
  stage 2 multiplies ``a^l - 1`` over the primes ``B1 < l <= B2`` (consecutive primes by their
  gaps). It finds p when ``p - 1`` is B1-smooth but for one prime up to B2, whatever the size
  of n, and nothing otherwise: the bounds rise through :data:`PM1_SCHEDULE`, and a modulus
  neither of whose ``p - 1`` is smooth enough raises :class:`~encctl_gym.errors.BreakerError`
  (every prime factor below ``min(B2, B1^2)`` is found, so moduli whose smaller prime is below
  10^7, about 46 bits, always factor).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
from typing import ClassVar

import gmpy2
import numpy as np

from ..crypto.arith import RandomSource
from ..errors import BreakerError
from .base import Deadline
from .factoring import Factorer
from .smoothness import primes_up_to

__all__ = ["PollardRhoFactorer", "PollardPMinusOne", "PM1_SCHEDULE", "RHO_SECONDS_PER_STEP", "prime_array"]

#: Seconds per step of Brent's walk (one squaring and one product modulo n, gmpy2), measured on
#: this machine (``python benchmarks/bench_factoring.py``).
RHO_SECONDS_PER_STEP = 5.0e-7
#: (B1, B2) of the successive p - 1 rounds; each continues the previous one's stage 1.
PM1_SCHEDULE: tuple[tuple[int, int], ...] = ((2_000, 100_000), (20_000, 1_000_000), (200_000, 10_000_000))
#: Measured seconds of the whole p - 1 schedule on a modulus it does not factor (the cost model).
PM1_SCHEDULE_SECONDS = 1.5
_BATCH = 256


@lru_cache(maxsize=8)
def prime_array(bound: int) -> np.ndarray:
    """The primes ``<= bound`` as an int64 array (:func:`.smoothness.primes_up_to`, cached)."""
    return np.array(primes_up_to(bound), dtype=np.int64)


def _exponent(r: int, bound: int) -> int:
    """The largest e with ``r^e <= bound`` (0 if ``r > bound``), in exact integers."""
    e, power = 0, r
    while power <= bound:
        e, power = e + 1, power * r
    return e


class PollardRhoFactorer(Factorer):
    """Pollard's rho with Brent's cycle finding (module docstring). Default limit 80 bits."""

    name: ClassVar[str] = "rho-factor"
    DEFAULT_MAX_BITS: ClassVar[int] = 80

    def expected_seconds(self, bits: int) -> float:
        """``RHO_SECONDS_PER_STEP * sqrt(pi p / 2)`` with ``p = 2^(k/2)``."""
        return RHO_SECONDS_PER_STEP * math.sqrt(math.pi * 2.0 ** (bits // 2) / 2)

    def _find_factor(self, n: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int]]:
        steps = 0
        N = gmpy2.mpz(n)
        for _attempt in range(64):
            c = gmpy2.mpz(src.between(1, n - 2))
            y = gmpy2.mpz(src.between(0, n))
            g, r, q, x, ys = gmpy2.mpz(1), 1, gmpy2.mpz(1), y, y
            while g == 1:
                x = y
                for _ in range(r):
                    y = (y * y + c) % N
                k = 0
                while k < r and g == 1:
                    ys = y
                    for _ in range(min(_BATCH, r - k)):
                        y = (y * y + c) % N
                        q = q * abs(x - y) % N
                    steps += min(_BATCH, r - k)
                    g = gmpy2.gcd(q, N)
                    k += _BATCH
                    deadline.check()
                steps += r
                r *= 2
            if g == N:  # the batch overshot: retrace it one gcd at a time
                while True:
                    ys = (ys * ys + c) % N
                    g = gmpy2.gcd(abs(x - ys), N)
                    if g > 1:
                        break
            if 1 < g < N:
                return int(g), {"steps": steps}
        raise BreakerError(f"rho-factor: 64 walks found no factor of n = {n}")  # pragma: no cover


class PollardPMinusOne(Factorer):
    """Pollard's p - 1 with a prime-by-prime stage 2 (module docstring). Default limit 64 bits."""

    name: ClassVar[str] = "p-1"
    DEFAULT_MAX_BITS: ClassVar[int] = 64

    def expected_seconds(self, bits: int) -> float:
        """The measured time of the whole schedule (:data:`PM1_SCHEDULE_SECONDS`): the work does
        not depend on the size of n below 128 bits, only on the smoothness of p - 1."""
        return PM1_SCHEDULE_SECONDS

    def _find_factor(self, n: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int]]:
        N = gmpy2.mpz(n)
        a0 = gmpy2.mpz(2 + src.below(n - 4))
        g = gmpy2.gcd(a0, N)
        if g > 1:
            return int(g), {"exponentiations": 0}
        a, done, done_b2, ops = a0, 0, 1, 0
        for B1, B2 in PM1_SCHEDULE:
            primes = prime_array(B1)
            for r in primes[primes <= done].tolist():  # the earlier primes, up to the new B2
                extra = _exponent(r, B2) - _exponent(r, done_b2)
                if extra:
                    a = gmpy2.powmod(a, r**extra, N)
            prev, fresh = a, primes[primes > done].tolist()
            for r in fresh:
                a = gmpy2.powmod(a, r ** _exponent(r, B2), N)
            ops += len(fresh)
            done, done_b2 = B1, B2
            g = gmpy2.gcd(a - 1, N)
            if g == N:  # both p - 1 and q - 1 divide E: retrace the round prime by prime
                g = self._retrace(prev, fresh, B2, N)
            if 1 < g < N:
                return int(g), {"exponentiations": ops, "B1": B1}
            deadline.check()
            g, steps = self._stage2(a, B1, B2, N, deadline)
            ops += steps
            if 1 < g < N:
                return int(g), {"exponentiations": ops, "B1": B1, "B2": B2}
        raise BreakerError(
            f"p-1 found no factor of the {n.bit_length()}-bit n with bounds up to B1 = {PM1_SCHEDULE[-1][0]}, "
            f"B2 = {PM1_SCHEDULE[-1][1]}: neither p - 1 nor q - 1 is smooth enough (use rho-factor or ecm)"
        )

    @staticmethod
    def _retrace(a: gmpy2.mpz, primes: list[int], B2: int, N: gmpy2.mpz) -> gmpy2.mpz:
        for r in primes:
            a = gmpy2.powmod(a, r ** _exponent(r, B2), N)
            g = gmpy2.gcd(a - 1, N)
            if g > 1:
                return g
        return N

    @staticmethod
    def _stage2(a: gmpy2.mpz, B1: int, B2: int, N: gmpy2.mpz, deadline: Deadline) -> tuple[gmpy2.mpz, int]:
        primes = prime_array(B2)
        primes = primes[primes > B1]
        if primes.size == 0:
            return gmpy2.mpz(1), 0
        gaps = np.diff(primes)
        powers = {int(d): gmpy2.powmod(a, int(d), N) for d in np.unique(gaps).tolist()}
        x = gmpy2.powmod(a, int(primes[0]), N)
        acc = x - 1
        for i, d in enumerate(gaps.tolist(), 1):
            x = x * powers[d] % N
            acc = acc * (x - 1) % N
            if i % 8192 == 0:
                g = gmpy2.gcd(acc, N)
                if g > 1:
                    return g, i
                deadline.check()
        return gmpy2.gcd(acc, N), int(primes.size)
