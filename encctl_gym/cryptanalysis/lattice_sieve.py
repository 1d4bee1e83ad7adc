"""A sieve over the lattice of a residue: many smooth pairs ``a = b y (mod p)`` per residue y.

For a residue y modulo p, the pairs ``(a, b)`` with ``a = b y (mod p)`` form a lattice L_y of
determinant p, with basis ``(p, 0), (y, 1)``. Lagrange (Gauss) reduction gives a basis
``v1 = (a1, b1)``, ``v2 = (a2, b2)`` of vectors of length about ``sqrt(p)``, and every
``i v1 + j v2`` (integers i, j) is again in L_y: ``a(i, j) = i a1 + j a2`` and
``b(i, j) = i b1 + j b2`` satisfy ``a = b y (mod p)``, so if both are smooth,

    lambda(a) - lambda(|b|) = lambda(y)        (lambda as in :mod:`.index_calculus`),

one relation. The rational reconstruction of y (one pair) is the point ``(i, j) = (0, 1)`` or
``(1, 0)`` of this lattice; a region ``1 <= i <= I``, ``|j| <= J`` gives ``2 I J`` pairs of
about ``sqrt(p) max(I, J)`` each, for the price of one reduction. Along a row (fixed i) both
a and b are linear in j, so a prime power m divides ``a(i, j)`` exactly for the j in one
residue class, ``j = -i a1 / a2 (mod m)``: the row is *sieved*, adding ``log2 l`` at those j
for every prime power ``m = l^e`` of the factor base, and only the j where both sums come close
to ``log2 |a|`` and ``log2 |b|`` are tested exactly (:meth:`.smoothness.FactorBase.factor`).
This replaces one smoothness test per candidate by a few additions per prime hit.

Pairs with ``gcd(i, j) > 1`` repeat a relation of a smaller pair (both a and b gain the
common factor) and are skipped.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._jit import install_compile_notice

install_compile_notice()  # one line on stderr before the first compile (encctl_gym._jit)

__all__ = ["reduced_basis", "SievePlan", "sieve_candidates"]


def reduced_basis(y: int, p: int) -> tuple[int, int, int, int]:
    """A Lagrange-reduced basis ``(a1, b1, a2, b2)`` of ``{(a, b): a = b y (mod p)}``.

    ``|v1| <= |v2|`` and ``2 |v1 . v2| <= |v1|^2``, so ``|v1|^2 <= 4 p / 3`` and
    ``|v1| |v2| <= 2 p / sqrt(3)`` (the lattice has determinant ``a1 b2 - a2 b1 = +-p``): for a
    random y both lengths are about ``sqrt(p)``.
    """
    u0, u1, v0, v1 = p, 0, y % p, 1
    nu, nv = u0 * u0 + u1 * u1, v0 * v0 + v1 * v1
    if nu < nv:
        u0, u1, v0, v1, nu, nv = v0, v1, u0, u1, nv, nu
    while True:
        # u is the longer vector: subtract the nearest multiple of v.
        k = (u0 * v0 + u1 * v1 + nv // 2) // nv
        u0, u1 = u0 - k * v0, u1 - k * v1
        nu = u0 * u0 + u1 * u1
        if nu >= nv:
            return v0, v1, u0, u1
        u0, u1, v0, v1, nu, nv = v0, v1, u0, u1, nv, nu


class SievePlan:
    """The prime powers sieved with, their ``log2 l`` and the region of each residue's lattice.

    Parameters
    ----------
    primes : sequence of int
        The factor base.
    rows, half_width : int
        The region ``1 <= i <= rows``, ``-half_width <= j < half_width``.
    max_power : int
        Prime powers ``l^e`` up to this bound are sieved too (``l`` itself always).
    skip_below : int
        Moduli below this are not sieved (they hit every few cells and cost the most additions
        for the fewest bits); :attr:`skipped_bits`, their mean share of a smooth number, is
        added to the slack.
    """

    def __init__(
        self, primes: tuple[int, ...], rows: int, half_width: int, max_power: int = 1 << 16, skip_below: int = 32
    ) -> None:
        moduli, logs = [], []
        self.skipped_bits = 0.0
        for ell in primes:
            m = ell
            while True:
                if m >= skip_below:
                    moduli.append(m)
                    logs.append(math.log2(ell))
                else:
                    self.skipped_bits += math.log2(ell) / m * (1 - 1 / ell)  # E[bits of l in x] from l^e alone
                if m * ell > max_power:
                    break
                m *= ell
        self.moduli = np.array(moduli, dtype=np.int64)
        self.logs = np.array(logs, dtype=np.float32)
        self.rows = rows
        self.half_width = half_width
        self.bound_bits = math.log2(max(primes))


def _residues(x: int, moduli: np.ndarray) -> np.ndarray:
    """``x mod m`` for every modulus (x any Python int), via 32-bit limbs."""
    sign = -1 if x < 0 else 1
    x = abs(x)
    out = np.zeros(len(moduli), dtype=np.int64)
    shift = np.int64(1 << 32) % moduli
    limbs = []
    while x:
        limbs.append(x & 0xFFFFFFFF)
        x >>= 32
    for limb in reversed(limbs):
        out = (out * shift + np.int64(limb) % moduli) % moduli
    return out if sign > 0 else (-out) % moduli


@njit(cache=True)
def _inverse(a: int, m: int) -> int:
    # Inverse of a modulo m (gcd 1 assumed by the caller), extended Euclid on machine words.
    r0, r1, t0, t1 = m, a, 0, 1
    while r1:
        k = r0 // r1
        r0, r1 = r1, r0 - k * r1
        t0, t1 = t1, t0 - k * t1
    if r0 != 1:
        return -1
    return t0 % m


@njit(cache=True)
def _roots(r1: np.ndarray, r2: np.ndarray, moduli: np.ndarray, out: np.ndarray) -> None:
    # j = -x1 / x2 (mod m) solves i x1 + j x2 = 0 for i = 1; row i has the root i times it.
    # -1: no j (x2 = 0 but x1 != 0, or l | x2 with x2 != 0 mod m: the sieve is a filter),
    # -2: every j (x1 = x2 = 0 mod m, never for a reduced basis of a prime p > m).
    for k in range(len(moduli)):
        m = moduli[k]
        if r2[k] == 0:
            out[k] = -2 if r1[k] == 0 else -1
            continue
        inv = _inverse(r2[k], m)
        out[k] = -1 if inv < 0 else (m - r1[k]) % m * inv % m


@njit(cache=True)
def _add_row(acc: np.ndarray, offsets: np.ndarray, roots: np.ndarray, moduli: np.ndarray, logs: np.ndarray) -> None:
    # Adds log2 l at every index t = offsets[k] (mod m), then moves each offset on by its root
    # (row i + 1 has the root (i + 1) root_1): no division in the loop over the moduli.
    width = len(acc)
    for k in range(len(moduli)):
        root = roots[k]
        if root == -1:
            continue
        w = logs[k]
        if root == -2:
            for t in range(width):
                acc[t] += w
            continue
        m = moduli[k]
        start = offsets[k]
        for t in range(start, width, m):
            acc[t] += w
        start += root
        if start >= m:
            start -= m
        offsets[k] = start


@njit(cache=True)
def _sieve(
    ra1: np.ndarray,
    ra2: np.ndarray,
    rb1: np.ndarray,
    rb2: np.ndarray,
    moduli: np.ndarray,
    logs: np.ndarray,
    rows: int,
    half: int,
    fa1: float,
    fa2: float,
    fb1: float,
    fb2: float,
    slack: float,
    out_i: np.ndarray,
    out_j: np.ndarray,
) -> int:
    width = 2 * half
    sa = np.zeros(width, dtype=np.float32)
    sb = np.zeros(width, dtype=np.float32)
    root_a = np.empty(len(moduli), dtype=np.int64)
    root_b = np.empty(len(moduli), dtype=np.int64)
    _roots(ra1, ra2, moduli, root_a)
    _roots(rb1, rb2, moduli, root_b)
    off_a = np.empty(len(moduli), dtype=np.int64)
    off_b = np.empty(len(moduli), dtype=np.int64)
    for k in range(len(moduli)):  # row i = 1: j = root, at index root + half
        off_a[k] = (max(root_a[k], 0) + half) % moduli[k]
        off_b[k] = (max(root_b[k], 0) + half) % moduli[k]
    found = 0
    cap = len(out_i)
    for i in range(1, rows + 1):
        sa[:] = 0.0
        sb[:] = 0.0
        _add_row(sa, off_a, root_a, moduli, logs)
        _add_row(sb, off_b, root_b, moduli, logs)
        # Cheap filter first: a cell within 2^-12 of the row's largest |a| (or |b|) needs a sum
        # of at least log2(max) - 12 - slack; only those get the exact threshold.
        big_a = max(abs(i * fa1 - half * fa2), abs(i * fa1 + half * fa2))
        big_b = max(abs(i * fb1 - half * fb2), abs(i * fb1 + half * fb2))
        lo_a = math.log2(max(big_a, 2.0)) - 12.0 - slack
        lo_b = math.log2(max(big_b, 2.0)) - 12.0 - slack
        for t in range(width):
            if sa[t] < lo_a or sb[t] < lo_b:
                continue
            j = t - half
            a = abs(i * fa1 + j * fa2)
            b = abs(i * fb1 + j * fb2)
            if a < 1.0 or b < 1.0:
                continue
            if sa[t] >= math.log2(a) - slack and sb[t] >= math.log2(b) - slack:
                if found < cap:
                    out_i[found] = i
                    out_j[found] = j
                found += 1
    return found


def sieve_candidates(y: int, p: int, plan: SievePlan, slack: float) -> tuple[tuple[int, int, int, int], list[tuple[int, int]]]:
    """The reduced basis of y's lattice and the ``(i, j)`` of its region whose a and b the sieve
    finds within ``slack`` bits of smooth (to be checked exactly; ``gcd(i, j) = 1`` only)."""
    a1, b1, a2, b2 = reduced_basis(y, p)
    cap = 4096
    out_i = np.empty(cap, dtype=np.int64)
    out_j = np.empty(cap, dtype=np.int64)
    mod = plan.moduli
    slack = slack + plan.skipped_bits
    found = _sieve(
        _residues(a1, mod),
        _residues(a2, mod),
        _residues(b1, mod),
        _residues(b2, mod),
        mod,
        plan.logs,
        plan.rows,
        plan.half_width,
        float(a1),
        float(a2),
        float(b1),
        float(b2),
        slack,
        out_i,
        out_j,
    )
    pairs = [
        (int(i), int(j)) for i, j in zip(out_i[: min(found, cap)], out_j[: min(found, cap)]) if math.gcd(int(i), int(j)) == 1
    ]
    return (a1, b1, a2, b2), pairs
