"""Lenstra's elliptic-curve method (ECM) on Montgomery curves: the factorer for moduli of up to
about 128 bits and a little beyond (registry name ``"ecm"``).

Source: H. W. Lenstra Jr., "Factoring integers with elliptic curves", Annals of Mathematics 126
(1987); the curves, the x-only arithmetic and the two stages follow P. L. Montgomery, "Speeding
the Pollard and elliptic curve methods of factorization", Math. Comp. 48 (1987), with Suyama's
parametrisation (curves with a torsion subgroup of order 12).

Phases, as visible in the code as in the cost:

1. **curve** (:func:`suyama_curve`): for a random sigma, ``u = sigma^2 - 5``, ``v = 4 sigma``,
   the point ``(u^3 : v^3)`` on ``B y^2 = x^3 + A x^2 + x`` with
   ``(A + 2) / 4 = (v - u)^3 (3u + v) / (16 u^3 v)``; a failed inversion already reveals a
   factor.
2. **stage 1** (:func:`ladder`): ``Q = [E] P`` with E the product of the prime powers up to B1,
   one Montgomery ladder over E's bits (one xADD and one xDBL per bit); a factor shows in
   ``gcd(Z_Q, n)`` when the curve's order modulo p is B1-smooth.
3. **stage 2** (:func:`stage2`): the primes ``l`` of ``(B1, B2]`` written ``l = m D +- j``
   (``D = 2310``): baby steps ``[j] Q`` for the odd ``j < D/2`` prime to D, giant steps
   ``[m D] Q``, and the product of ``X_(mD) Z_j - X_j Z_(mD)``, which vanishes modulo p when
   ``[l] Q`` is the point at infinity modulo p (the order's largest prime is one such l).

The bounds B1 and the expected number of curves per size of the smaller factor follow the
table of GMP-ECM's README (:data:`ECM_PLAN`); a modulus is attacked with the row of its balanced
factor (``k/2`` bits) and curves are drawn until one finds the factor. Each curve is
independent, so the expected time is the expected number of curves times one curve's time; the
cost model is the method's ``L_p[1/2, sqrt 2]`` in the smaller factor p with one constant
measured on this machine (:data:`ECM_SECONDS_CONSTANT`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
from typing import ClassVar

import gmpy2

from ..crypto.arith import RandomSource
from ..errors import BreakerError
from .base import Deadline
from .factoring import Factorer
from .pollard_factor import prime_array

__all__ = ["EllipticCurveMethod", "ECM_PLAN", "ECM_SECONDS_CONSTANT", "suyama_curve", "ladder", "stage2", "stage1_exponent"]

#: (largest factor digits, B1, expected curves) after GMP-ECM's README table (B2 = 100 B1 here,
#: below GMP-ECM's default B2, so the curve counts are upper bounds: the loop draws until done).
ECM_PLAN: tuple[tuple[int, int, int], ...] = (
    (10, 360, 10),
    (15, 2_000, 25),
    (20, 11_000, 90),
    (25, 50_000, 300),
    (30, 250_000, 700),
    (35, 1_000_000, 1800),
    (40, 3_000_000, 5100),
)
#: Seconds ~ ECM_SECONDS_CONSTANT exp(sqrt(2 ln p ln ln p)) for the smaller factor p of a
#: balanced modulus, fitted on this machine at 64-128 bits (``python benchmarks/bench_factoring.py``;
#: the shape grows faster than the measured times between rows of ECM_PLAN, so the model
#: overstates 128 bits by about 2x and understates 96 bits by about 1.5x).
ECM_SECONDS_CONSTANT = 8.0e-8
#: Curves tried before a modulus is given up (far beyond every row's expected count).
MAX_CURVES = 20_000
_D = 2310


@lru_cache(maxsize=16)
def stage1_exponent(B1: int) -> int:
    """E = the product of ``r^floor(log_r B1)`` over the primes ``r <= B1``."""
    E = gmpy2.mpz(1)
    for r in prime_array(B1).tolist():
        power = r
        while power * r <= B1:
            power *= r
        E *= power
    return int(E)


def suyama_curve(sigma: int, n: int) -> tuple[int, int, int] | int:
    """Suyama's curve of ``sigma``: ``(X0, Z0, a24)``, or a divisor ``g > 1`` of n that the
    inversion of ``16 u^3 v`` revealed."""
    N = gmpy2.mpz(n)
    u = (gmpy2.mpz(sigma) * sigma - 5) % N
    v = 4 * gmpy2.mpz(sigma) % N
    den = 16 * u * u * u * v % N
    g = gmpy2.gcd(den, N)
    if g != 1:
        return int(g)
    a24 = pow(v - u, 3, N) * (3 * u + v) % N * gmpy2.invert(den, N) % N
    return int(u * u * u % N), int(v * v * v % N), int(a24)


def ladder(X: int, Z: int, k: int, a24: int, n: int) -> tuple[int, int]:
    """``[k](X : Z)`` on the Montgomery curve of ``a24 = (A + 2)/4`` (x-only, k >= 1)."""
    N = gmpy2.mpz(n)
    X, Z, a = gmpy2.mpz(X), gmpy2.mpz(Z), gmpy2.mpz(a24)
    x0, z0 = X, Z
    s, d = (X + Z) ** 2 % N, (X - Z) ** 2 % N
    x1, z1 = s * d % N, (s - d) * (d + a * (s - d)) % N
    for bit in bin(k)[3:]:
        u = (x0 - z0) * (x1 + z1) % N
        v = (x0 + z0) * (x1 - z1) % N
        xa, za = Z * (u + v) ** 2 % N, X * (u - v) ** 2 % N  # the sum R0 + R1 (difference P)
        if bit == "1":
            s, d = (x1 + z1) ** 2 % N, (x1 - z1) ** 2 % N
            x0, z0, x1, z1 = xa, za, s * d % N, (s - d) * (d + a * (s - d)) % N
        else:
            s, d = (x0 + z0) ** 2 % N, (x0 - z0) ** 2 % N
            x0, z0, x1, z1 = s * d % N, (s - d) * (d + a * (s - d)) % N, xa, za
    return int(x0), int(z0)


def _add(p: tuple, q: tuple, diff: tuple, N: gmpy2.mpz) -> tuple:
    u = (p[0] - p[1]) * (q[0] + q[1]) % N
    v = (p[0] + p[1]) * (q[0] - q[1]) % N
    return diff[1] * (u + v) ** 2 % N, diff[0] * (u - v) ** 2 % N


def stage2(X: int, Z: int, a24: int, B1: int, B2: int, n: int, deadline: Deadline) -> tuple[int, int]:
    """Stage 2 over the primes of ``(B1, B2]`` (module docstring): ``(gcd, primes covered)``."""
    N = gmpy2.mpz(n)
    Q = (gmpy2.mpz(X), gmpy2.mpz(Z))
    Q2 = tuple(gmpy2.mpz(c) for c in ladder(X, Z, 2, a24, n))
    babies: dict[int, tuple] = {1: Q}
    prev, cur = Q, _add(Q2, Q, Q, N)  # [1]Q, [3]Q
    for j in range(3, _D // 2, 2):
        if math.gcd(j, _D) == 1:
            babies[j] = cur
        prev, cur = cur, _add(cur, Q2, prev, N)
    m = max(1, (B1 + _D // 2) // _D)
    DQ = tuple(gmpy2.mpz(c) for c in ladder(X, Z, _D, a24, n))
    G_prev = tuple(gmpy2.mpz(c) for c in ladder(X, Z, (m - 1) * _D, a24, n)) if m > 1 else None
    G = tuple(gmpy2.mpz(c) for c in ladder(X, Z, m * _D, a24, n))
    primes = prime_array(B2)
    primes = primes[primes > B1].tolist()
    acc, i, count = gmpy2.mpz(1), 0, 0
    while i < len(primes):
        top = m * _D + _D // 2
        while i < len(primes) and primes[i] <= top:
            j = abs(primes[i] - m * _D)
            b = babies.get(j)
            if b is not None:
                acc = acc * (G[0] * b[1] - b[0] * G[1]) % N
                count += 1
            i += 1
        G_next = _add(G, DQ, G_prev, N) if G_prev is not None else tuple(gmpy2.mpz(c) for c in ladder(X, Z, (m + 1) * _D, a24, n))
        G_prev, G, m = G, G_next, m + 1
        if m % 64 == 0:
            deadline.check()
    return int(gmpy2.gcd(acc, N)), count


def plan_for(bits: int) -> tuple[int, int]:
    """``(B1, expected curves)`` for a balanced ``bits``-bit modulus (its factor of ``bits/2`` bits)."""
    digits = math.ceil((bits // 2) * math.log10(2.0))
    for top, B1, curves in ECM_PLAN:
        if digits <= top:
            return B1, curves
    return ECM_PLAN[-1][1], ECM_PLAN[-1][2]


class EllipticCurveMethod(Factorer):
    """ECM with Suyama curves, a Montgomery-ladder stage 1 and a baby-step giant-step stage 2.

    Default limit 160 bits (balanced factors of 80 bits: hours on this machine; the cost model
    refuses what it expects to pass ``--max-seconds``).
    """

    name: ClassVar[str] = "ecm"
    DEFAULT_MAX_BITS: ClassVar[int] = 160

    def expected_seconds(self, bits: int) -> float:
        """``ECM_SECONDS_CONSTANT exp(sqrt(2 ln p ln ln p))`` with ``p = 2^(k/2)`` (module docstring)."""
        lnp = max(bits // 2, 8) * math.log(2.0)
        return ECM_SECONDS_CONSTANT * math.exp(math.sqrt(2 * lnp * math.log(lnp)))

    def _find_factor(self, n: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int]]:
        B1, expected = plan_for(n.bit_length())
        B2 = 100 * B1
        E = stage1_exponent(B1)
        for curve in range(1, MAX_CURVES + 1):
            deadline.report("curves", curve, expected)
            found = suyama_curve(src.between(6, n - 1), n)
            if isinstance(found, int):
                if 1 < found < n:
                    return found, {"curves": curve, "B1": B1}
                continue
            X0, Z0, a24 = found
            X, Z = ladder(X0, Z0, E, a24, n)
            g = math.gcd(Z, n)
            if 1 < g < n:
                return g, {"curves": curve, "B1": B1, "stage": 1}
            deadline.check()
            if g == 1:
                g, _count = stage2(X, Z, a24, B1, B2, n, deadline)
                if 1 < g < n:
                    return g, {"curves": curve, "B1": B1, "B2": B2, "stage": 2}
            deadline.check()
        raise BreakerError(f"ecm: {MAX_CURVES} curves with B1 = {B1} found no factor of the {n.bit_length()}-bit n")
