"""Phase 2 of the index calculus: relations from the lattice sieve of residues ``y = g^e``.

A relation is ``sum_l (alpha_l - beta_l) lambda_l = n e (mod q)``: a pair ``a = b y (mod p)`` of
the lattice of ``y = g^e`` (:mod:`.lattice_sieve`) with a and b smooth over the factor base, and
``lambda`` the homomorphism of :mod:`.index_calculus` (``lambda(y) = lambda(|a|) - lambda(|b|)``,
``lambda(y) = n e`` for y in G).

The residues are a walk ``e = e_0, e_0 + c, e_0 + 2c, ...`` (:class:`RelationWalk`, random
``e_0`` and ``c``): its position is plain data, saved with the relations collected so far
(:mod:`.precomputation_file`), so an interrupted collection resumes where it stopped instead of
sieving the same residues again.
"""

from __future__ import annotations

import dataclasses
import math

import gmpy2

from .._validation import check_int
from ..crypto.arith import RandomSource
from ..crypto.group import GroupParams
from .base import Deadline
from .lattice_sieve import SievePlan, sieve_candidates
from .smoothness import FactorBase

__all__ = ["Relation", "RelationWalk", "collect_relations", "sieve_region", "smooth_pairs", "sieve_plan", "MAX_REGION_BITS"]

#: Largest bit length accepted by :func:`sieve_region` (that of the cost model).
MAX_REGION_BITS = 1 << 20


class Relation(tuple):
    """One relation ``(row, rhs)``: ``sum_j row[j] lambda_j = rhs (mod q)``."""

    __slots__ = ()

    @property
    def row(self) -> dict[int, int]:
        return self[0]

    @property
    def rhs(self) -> int:
        return self[1]


@dataclasses.dataclass
class RelationWalk:
    """The residues ``y = g^e`` sieved: ``e`` the next exponent, ``c`` the step (both in [1, q)).

    Consecutive exponents would not do: with g = 4, ``4y`` has the lattice of y scaled by 4 and
    repeats its relations plus that of 4. A random step c makes the residues unrelated.
    """

    e: int
    c: int

    @classmethod
    def start(cls, group: GroupParams, src: RandomSource) -> RelationWalk:
        """A walk from a random ``e_0`` with a random step, both uniform in ``[1, q)``."""
        return cls(src.between(1, group.q), src.between(1, group.q))


def sieve_region(bits: int) -> tuple[int, int]:
    """``(rows, half_width)`` of the region ``1 <= i <= rows``, ``|j| <= half_width`` sieved in
    each residue's lattice (:mod:`.lattice_sieve`): ``half_width = 2^min(11, max(4, bits // 7))``
    and ``rows = max(2, half_width // 32)``; the pairs are about ``half_width sqrt(p)``."""
    bits = check_int("bits", bits, minimum=2, maximum=MAX_REGION_BITS)
    half = 1 << min(11, max(4, bits // 7))
    return max(2, half // 32), half


def sieve_plan(group: GroupParams, fb: FactorBase) -> SievePlan:
    """The :class:`~.lattice_sieve.SievePlan` of a group: its factor base and :func:`sieve_region`."""
    rows, half = sieve_region(group.bits)
    return SievePlan(fb.primes, rows, half)


def _pair_row(fb: FactorBase, a: int, b: int) -> dict[int, int] | None:
    """The exponent vector of lambda(|a|) - lambda(|b|), or None if a or b is not smooth (or 0)."""
    if a == 0 or b == 0 or not (fb._is_smooth(a) and fb._is_smooth(b)):
        return None
    fa, fb_ = fb.factor(a), fb.factor(b)
    assert fa is not None and fb_ is not None  # both smooth
    row = dict(fa)
    for j, e in fb_.items():
        row[j] = row.get(j, 0) - e
    return {j: e for j, e in row.items() if e}


def _sieve_slack(fb: FactorBase) -> float:
    # Bits a sieve sum may fall short of log2 |a|: prime powers above 2^16 and rounding.
    return 0.8 * math.log2(fb.bound) + 2.0


def smooth_pairs(fb: FactorBase, plan: SievePlan, y: int, p: int) -> tuple[list[dict[int, int]], int]:
    """The rows lambda(|a|) - lambda(|b|) = lambda(y) of the smooth pairs of y's lattice, and the
    number of candidates the sieve reported (each tested exactly)."""
    (a1, b1, a2, b2), pairs = sieve_candidates(y, p, plan, _sieve_slack(fb))
    rows = [_pair_row(fb, i * a1 + j * a2, i * b1 + j * b2) for i, j in pairs]
    return [row for row in rows if row is not None], len(pairs)


def collect_relations(
    group: GroupParams,
    fb: FactorBase,
    relations: list[Relation],
    until: int,
    walk: RelationWalk,
    deadline: Deadline,
    counts: dict[str, int] | None = None,
) -> dict[str, int]:
    """Phase 2: extend ``relations`` (in place) to at least ``until`` relations.

    For the residues ``y = g^e`` of ``walk`` (advanced in place, one multiplication by ``g^c``
    per residue) it sieves the region :func:`sieve_region` of y's lattice
    (:func:`~.lattice_sieve.sieve_candidates`) and keeps every pair ``a = b y (mod p)`` with a
    and b smooth (checked exactly). After each residue the relations and the walk agree (the
    walk points at the next residue) and ``deadline`` is checked and told the progress
    (phase ``"relations"``, ``len(relations)`` of ``until``), so an interruption there loses
    nothing.

    Returns
    -------
    dict
        ``counts`` (a new dict if not given), its ``sieved_lattices`` (residues sieved) and
        ``smoothness_tests`` (candidates tested exactly) increased after each residue.
    """
    counts = {} if counts is None else counts
    for key in ("sieved_lattices", "smoothness_tests"):
        counts.setdefault(key, 0)
    p, q, n = group.p, group.q, group.cofactor
    plan = sieve_plan(group, fb)
    y = gmpy2.powmod(group.g, walk.e, p)
    step = gmpy2.powmod(group.g, walk.c, p)
    pm = gmpy2.mpz(p)
    deadline.report("relations", len(relations), until)
    while len(relations) < until:
        rows, tested = smooth_pairs(fb, plan, int(y), p)
        rhs = n * walk.e % q
        relations += [Relation((row, rhs)) for row in rows]
        walk.e = (walk.e + walk.c) % q or walk.c  # e = 0 would be the identity: skip it
        counts["sieved_lattices"] += 1
        counts["smoothness_tests"] += tested
        y = gmpy2.powmod(group.g, walk.e, p) if walk.e == walk.c else y * step % pm
        deadline.check()
        deadline.report("relations", len(relations), until)
    return counts
