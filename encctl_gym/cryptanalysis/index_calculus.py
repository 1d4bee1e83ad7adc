"""Index calculus in a prime field, with its phases explicit (registry name ``"index-calculus"``).

Which logarithms are solved for
-------------------------------
The keys live in the order-q subgroup G = <g> of Z_p^* (Example ex:elgamal; safe-prime groups
p = 2q + 1 with g = 4 in this package). Small primes l are in general *not* in G (for a safe
prime, l is in G iff it is a quadratic residue), so "log_g(l)" is undefined. Let
``n = (p - 1) / q`` be the cofactor and define

    lambda(x) = log_g(x^n)  (mod q)     for x in Z_p^*.

Claim: if q is an odd prime that does not divide n, then (i) lambda is well defined and a group
homomorphism ``Z_p^* -> Z_q``, (ii) ``lambda(-1) = 0``, and (iii) ``lambda(y) = n log_g(y)``
for y in G.

Proof. Z_p^* is cyclic of order nq, so ``x^n`` has order dividing q, hence lies in the unique
subgroup of order q, which is G; so ``log_g(x^n)`` exists and is unique modulo q (g has order
q). ``(xy)^n = x^n y^n`` gives ``lambda(xy) = lambda(x) + lambda(y)``. p - 1 = nq is even and
q is odd, so n is even and ``(-1)^n = 1``: ``lambda(-1) = 0``. For ``y = g^e`` in G,
``y^n = g^(ne)``, so ``lambda(y) = n e``. QED. (For a safe prime, n = 2 and ``x^n = x^2``: the
unknowns are the logarithms of the squares ``l^2``, which are in G.)

Hence the unknowns are ``lambda_l = lambda(l)`` for the primes l of the factor base, and since n
is invertible modulo q, ``log_g(h) = lambda(h) / n``.

The phases
----------
1. **Factor base** (:class:`~.smoothness.FactorBase`): the primes ``l <= B``, with B chosen by
   the cost model :func:`choose_bound` (Dickman's rho for the smoothness probability, the
   measured cost of a sieved cell and of the linear algebra).
2. **Relation collection** (:func:`~.relations.collect_relations`): for ``y = g^e`` every pair
   ``a = b y (mod p)`` of y's lattice (:mod:`.lattice_sieve`: a reduced basis of about
   ``sqrt(p)``, a region of small combinations sieved row by row) with a and b B-smooth gives
   ``lambda(y) = lambda(|a|) - lambda(|b|)`` (by (i) and (ii)), the relation
   ``sum_l (alpha_l - beta_l) lambda_l = n e (mod q)`` (by (iii)).
3. **Linear algebra modulo q** (:func:`~.linalg.solve_mod_prime`, python-flint): all the
   ``lambda_l`` the relations determine.
4. **Descent**, per key (:class:`FactorBaseLogs`): sieve the lattices of ``z = h g^r`` until a
   pair a = b z has a, b smooth over the solved primes; then
   ``n (log_g h + r) = lambda(|a|) - lambda(|b|)``.

Phases 1-3 depend only on (p, q, g): they are the precomputation. Phase 4 needs about one
relation's worth of sieving per key (usually one lattice), a small fraction of the
precomputation, so after the first key a dynamic-key sequence (Example ex:dyn_elgamal) costs
little per key.

The precomputation is plain data: :meth:`FactorBaseLogs.save` writes it to a file that
``IndexCalculus(precomputation=path)`` loads, checked against its group
(:mod:`.precomputation_file`); phases 2 and 3 report their progress to a callback
(:mod:`.progress`), and a ``KeyboardInterrupt`` there ends the call with
:class:`~.precomputation_file.PrecomputationInterrupted`, which carries the relations collected
so far and the position of the residue walk, to save and resume from.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Mapping
from typing import ClassVar

import gmpy2

from .._validation import check_int, check_positive, format_value
from ..crypto import arith
from ..crypto.arith import RandomSource, RngLike, format_int
from ..crypto.group import GroupParams
from ..errors import BreakerError, BreakerLimitError, BreakerTimeoutError, GroupError, ParameterError
from .base import Breaker, Cost, Deadline, Precomputation, format_bytes
from .bsgs import BabyStepGiantStep, BabyStepTable
from .linalg import DENSE_BYTES_PER_ENTRY, flint_backend, solve_mod_prime
from .precomputation_file import PrecomputationInterrupted, SavedPrecomputation, load_precomputation
from .progress import ProgressCallback
from .relations import Relation, RelationWalk, collect_relations, sieve_plan, sieve_region, smooth_pairs
from .smoothness import RHO_MAX_U, FactorBase, check_bound, dickman_rho

__all__ = [
    "IndexCalculus",
    "FactorBaseLogs",
    "SmallOrderLogs",
    "Relation",
    "collect_relations",
    "choose_bound",
    "cost_model",
    "relation_probability",
    "sieve_probability",
    "sieve_region",
    "MAX_MODEL_BITS",
]

#: Calibration of the cost model, measured on this machine (2 cores, Python 3.11, numba 0.68,
#: python-flint 0.9; ``python benchmarks/bench_cryptanalysis.py`` prints current values):
#: seconds per cell of the lattice sieve (:mod:`.lattice_sieve`; both sieves of a row, the
#: threshold pass and the exact tests of the candidates), at 80 and 96 bits ...
CELL_SECONDS = 6.0e-9
#: ... the share of the model's smooth pairs the sieve reports and finds smooth (its slack of
#: 0.8 log2 B misses pairs whose sum falls short; Dickman's rho also overrates numbers of
#: this size; measured at 80 and 96 bits, B = 8192 and 21247) ...
SIEVE_YIELD = 0.33
#: ... and the linear algebra (:func:`~.linalg.solve_mod_prime`, structured elimination then
#: the dense core) as ``LINALG_* k^3 + ELIMINATION_PER_UNKNOWN k``, k unknowns, fitted at
#: 80 and 96 bits to k = 704 ... 2660 (0.11 s to 1.4 s) for q above a machine word; the cube
#: term is a quarter of that for word-size q (FLINT's nmod_mat).
LINALG_WORD = 1.2e-11
LINALG_MULTI = 4.8e-11
ELIMINATION_PER_UNKNOWN = 1.8e-4

#: The expected time on this machine (:meth:`IndexCalculus.expected_seconds`) times lattices of
#: the group itself instead of using :data:`CELL_SECONDS`, which leaves out the work per lattice
#: (its reduced basis, roots and the exact tests of its candidates: about 0.3 ms a lattice, the
#: whole cost of a lattice at 56-64 bits) and depends on the machine and its load: with the
#: documented constants the expected time of ``crack --bits 64 --keys 32`` was 4-6 times below
#: the measured one (issue 34). :func:`lattice_seconds` times :data:`PROBE_LATTICES` lattices
#: after one untimed lattice (which loads the compiled sieve) for factor-base bounds up to
#: :data:`PROBE_MAX_BOUND`; above it the documented constants stand.
PROBE_LATTICES = 5
PROBE_MAX_BOUND = 1 << 20
#: Lattices the relations take, as a share of the model's count (:func:`cost_model`): measured
#: 0.43-0.57 at 48-88 bits (9 groups, default bounds). :data:`SIEVE_YIELD` undercounts the
#: sieve's yield by about 2; it stays as it is for the choice of B (:func:`choose_bound`), which
#: was tuned with it; the expected time takes the measured share.
SIEVED_LATTICE_SHARE = 0.5
#: Relations collected beyond the number of unknowns (fraction, plus a constant).
EXTRA_FRACTION = 0.05
EXTRA_CONSTANT = 20
#: Peak bytes per entry of the dense system (:data:`~.linalg.DENSE_BYTES_PER_ENTRY`).
MATRIX_BYTES_PER_ENTRY = DENSE_BYTES_PER_ENTRY
#: Share of the rows and of the unknowns left to the dense elimination by the structured one
#: (:func:`~.linalg.structured_elimination`): measured 0.38 of the rows and 0.30 of the unknowns
#: at 80 and 96 bits; 0.4 for both, with a margin.
CORE_FRACTION = 0.4
#: Largest expected peak memory of the linear algebra (bytes): 4 GiB. The default bound of a
#: 128-bit group (about 9700 unknowns, a core of about 1.3 GiB) fits.
MAX_MATRIX_BYTES = 4 * 2**30
#: Share of the primes occurring in the relations whose logarithm must be determined.
SOLVED_FRACTION = 0.97
_CHECK_EVERY = 2048
#: The relations need G to hold many more elements than residues sieved: a q below this multiple
#: of the expected residues is broken by baby-step giant-step (:meth:`IndexCalculus.uses_baby_steps`).
SMALL_ORDER_FACTOR = 64


#: Largest bit length of p the cost model takes (far beyond any group the package builds; it keeps
#: every quantity of the model within the float range).
MAX_MODEL_BITS = 1 << 20


def _model_args(bits: object, bound: object) -> tuple[int, float]:
    bits = check_int("bits", bits, minimum=2, maximum=MAX_MODEL_BITS)
    bound = check_positive("bound", bound)
    if bound < 2:
        raise ParameterError(f"bound must be >= 2, got {format_value(bound)}")
    return bits, bound


def relation_probability(bits: int, bound: float) -> float:
    """Probability that ``y = a / b`` (both about ``bits / 2`` bits) has a and b ``bound``-smooth:
    ``rho(u)^2`` with ``u = (bits / 2) ln 2 / ln B`` (Dickman's rho, :func:`~.smoothness.dickman_rho`);
    0 past the range of the tabulated rho (``u > 40``, a probability below 1e-142), so that the
    cost model of a group far beyond reach is infinite rather than an error.

    Raises
    ------
    ParameterError
        Unless ``2 <= bits <=`` :data:`MAX_MODEL_BITS` is an integer and ``bound >= 2`` a real number.
    """
    bits, bound = _model_args(bits, bound)
    u = (bits / 2) * math.log(2) / math.log(bound)
    if u > RHO_MAX_U:
        return 0.0
    return dickman_rho(u) ** 2


def _prime_count(bound: float) -> float:
    return bound / (math.log(bound) - 1.08) if bound > 10 else 4.0


def sieve_probability(bits: int, bound: float) -> float:
    """Probability that a cell of the lattice sieve gives a relation: both ``a`` and ``b`` of
    about ``bits / 2 + log2(half_width)`` bits are ``bound``-smooth, ``rho(u)^2`` (Dickman's rho),
    times the share :data:`SIEVE_YIELD` the sieve reports; 0 past ``u > 40``."""
    bits, bound = _model_args(bits, bound)
    _, half = sieve_region(bits)
    u = (bits / 2 + math.log2(half)) * math.log(2) / math.log(bound)
    if u > RHO_MAX_U:
        return 0.0
    return SIEVE_YIELD * dickman_rho(u) ** 2


def cost_model(bits: int, bound: float) -> dict[str, float]:
    """Expected seconds of each phase for a ``bits``-bit p and factor-base bound B.

    Returns
    -------
    dict
        ``factor_base`` (k, the number of unknowns), ``cells_per_relation`` (sieved cells, the
        inverse of :func:`sieve_probability`), ``relations`` (seconds of phase 2),
        ``linear_algebra`` (phase 3, structured and dense elimination), ``descent``
        (phase 4, per key: at least one residue's region), ``first`` (phases 2-4) and
        ``per_key``.
    """
    bits, bound = _model_args(bits, bound)
    k = _prime_count(bound)
    cells = 1.0 / max(sieve_probability(bits, bound), 1e-300)
    rows, half = sieve_region(bits)
    relations = (k * (1 + EXTRA_FRACTION) + EXTRA_CONSTANT) * cells * CELL_SECONDS
    cube = LINALG_WORD if bits <= 64 else LINALG_MULTI
    linear = cube * k**3 + ELIMINATION_PER_UNKNOWN * k
    descent = max(cells, 2 * rows * half) * CELL_SECONDS
    return {
        "factor_base": k,
        "cells_per_relation": cells,
        "relations": relations,
        "linear_algebra": linear,
        "descent": descent,
        "first": relations + linear + descent,
        "per_key": descent,
    }


_LATTICE_SECONDS: dict[tuple[int, int, int], float] = {}


def lattice_seconds(group: GroupParams, bound: int) -> float:
    """Wall seconds of sieving one residue's lattice of ``group`` (and testing its candidates
    exactly, :func:`~.relations.smooth_pairs`) with the factor base up to ``bound``, on this
    machine now: the median of :data:`PROBE_LATTICES` lattices of fixed residues ``g^e``, after
    one untimed lattice that loads the compiled sieve. Cached per group and bound; draws
    nothing from any attack's randomness."""
    key = (int(group.p), int(group.g), int(bound))
    if key not in _LATTICE_SECONDS:
        fb = FactorBase(bound)
        plan = sieve_plan(group, fb)
        times = []
        for i in range(PROBE_LATTICES + 1):
            y = int(gmpy2.powmod(group.g, (0x9E3779B97F4A7C15 * (i + 1)) % (group.q - 1) + 1, group.p))
            t0 = time.perf_counter()
            smooth_pairs(fb, plan, y, group.p)
            times.append(time.perf_counter() - t0)
        _LATTICE_SECONDS[key] = float(sorted(times[1:])[PROBE_LATTICES // 2])
    return _LATTICE_SECONDS[key]


def choose_bound(bits: int) -> int:
    """The factor-base bound B minimising the expected time of the first key (:func:`cost_model`),
    searched over ``B = 2^(x/8)``, ``x/8`` from 5 to 22 (``2 <= bits <=`` :data:`MAX_MODEL_BITS`)."""
    bits = check_int("bits", bits, minimum=2, maximum=MAX_MODEL_BITS)
    best = min(range(40, 177), key=lambda x: cost_model(bits, 2 ** (x / 8))["first"])
    return max(2, int(2 ** (best / 8)))


class _PhaseClock:
    """Wall and CPU seconds per named phase (``with clock("relations"): ...``), accumulated."""

    def __init__(self, wall: Mapping[str, float] | None = None, cpu: Mapping[str, float] | None = None) -> None:
        # Resumed from a file: the seconds of the earlier runs, per phase.
        self.wall: dict[str, float] = {"factor_base": 0.0, "relations": 0.0, "linear_algebra": 0.0, **(wall or {})}
        self.cpu: dict[str, float] = {"factor_base": 0.0, "relations": 0.0, "linear_algebra": 0.0, **(cpu or {})}
        self._name = ""

    def __call__(self, name: str) -> _PhaseClock:
        self._name = name
        return self

    @property
    def current(self) -> str:
        """The phase entered last (running, or ended by an exception), with a space for the underscore."""
        return self._name.replace("_", " ")

    def __enter__(self) -> None:
        self._t0, self._c0 = time.perf_counter(), time.process_time()

    def __exit__(self, *exc: object) -> None:
        self.wall[self._name] += time.perf_counter() - self._t0
        self.cpu[self._name] += time.process_time() - self._c0


class FactorBaseLogs(Precomputation):
    """The solved factor base of a group: ``lambda(l)`` for its primes; breaks keys by descent.

    Attributes
    ----------
    bound : int
        The factor-base bound B.
    logs : list of int or None
        ``lambda(l)`` per prime of the factor base (``None``: not determined by the relations).
    phase_seconds, phase_cpu_seconds : dict
        Wall and CPU time of the phases of the precomputation: ``factor_base``, ``relations``,
        ``linear_algebra``.
    backend : str
        The FLINT matrix type of the linear algebra (``nmod_mat`` or ``fmpz_mod_mat``).
    """

    def __init__(self, group: GroupParams, bound: int, logs: list[int | None], rng: RandomSource | None) -> None:
        super().__init__(IndexCalculus.name, group, rng)
        self.bound = bound
        self.logs = logs
        self.phase_seconds: dict[str, float] = {}
        self.phase_cpu_seconds: dict[str, float] = {}
        self.backend = flint_backend(group.q)
        self._fb: FactorBase | None = None

    def __getstate__(self) -> dict:
        state = super().__getstate__()
        state["_fb"] = None  # rebuilt from the bound where needed
        return state

    @property
    def factor_base(self) -> FactorBase:
        """The factor base (rebuilt from :attr:`bound` after unpickling)."""
        if self._fb is None:
            self._fb = FactorBase(self.bound)
        return self._fb

    @property
    def solved(self) -> int:
        """Number of factor-base primes whose lambda is known."""
        return sum(v is not None for v in self.logs)

    def saved(self) -> SavedPrecomputation:
        """Its content as a :class:`~.precomputation_file.SavedPrecomputation` (``.save(path)``
        writes the file a later run loads with ``IndexCalculus(precomputation=path)``)."""
        return SavedPrecomputation(
            self.group, self.bound, list(self.logs), [], None, self.cost, dict(self.phase_seconds), dict(self.phase_cpu_seconds)
        )

    def save(self, path: str | os.PathLike[str]) -> str:
        """Write the solved factor base to ``path`` (:mod:`.precomputation_file`); returns the path."""
        return self.saved().save(path)

    def _solve(self, h: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int], str]:
        # Phase 4, the descent: a pair a = b z (mod p) of the lattice of z = h g^r with a, b
        # smooth over the solved primes gives n (log h + r) = lambda(a) - lambda(|b|).
        group, fb, logs = self.group, self.factor_base, self.logs
        p, q = group.p, group.q
        n_inv = pow(group.cofactor, -1, q)
        pm = gmpy2.mpz(p)
        plan = sieve_plan(group, fb)
        r, c = src.between(0, q), src.between(1, q)  # z = h g^r, then r += c (see collect_relations)
        z = gmpy2.mpz(h) * gmpy2.powmod(group.g, r, p) % pm
        step = gmpy2.powmod(group.g, c, p)
        lattices = tests = 0
        give_up = 1000 * cost_model(group.bits, self.bound)["cells_per_relation"] / (2 * plan.rows * plan.half_width) + 1000
        while True:
            lattices += 1
            rows, tested = smooth_pairs(fb, plan, int(z), p)
            tests += tested
            for row in rows:
                known = [(e, logs[j]) for j, e in row.items()]
                if all(v is not None for _, v in known):
                    lam = sum(e * v for e, v in known if v is not None)
                    s = (lam * n_inv - r) % q
                    return s, {"sieved_lattices": lattices, "smoothness_tests": tests}, ""
            z = z * step % pm
            r += c
            deadline.check()
            if lattices > give_up:
                raise BreakerError(f"index-calculus: no smooth pair in {lattices} lattices for h = {format_int(h)}")


class SmallOrderLogs(Precomputation):
    """The precomputation of :class:`IndexCalculus` in a group whose order q is small: a
    baby-step table (:class:`~.bsgs.BabyStepTable`) that breaks every key in about ``sqrt(q)``
    steps.

    Relations come from elements of G (``g^e`` and ``h g^r``), and G has only q elements: with
    a q of a few thousand, G holds fewer smooth elements than the factor base has primes, and
    no number of trials determines the logarithms. Baby-step giant-step needs no relations.
    :meth:`IndexCalculus.uses_baby_steps` decides, from the two cost models.

    Attributes
    ----------
    table : BabyStepTable
        The baby steps of the group.
    """

    def __init__(self, group: GroupParams, table: BabyStepTable, rng: RandomSource | None) -> None:
        super().__init__(IndexCalculus.name, group, rng)
        self.table = table

    def _solve(self, h: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int], str]:
        s, ops, _ = self.table._solve(h, deadline, src)
        return s, ops, ""


class IndexCalculus(Breaker):
    """Index calculus with a factor base, a lattice sieve and FLINT linear algebra.

    See the module docstring for the logarithms solved for and the phases.

    Parameters
    ----------
    bound : int, optional
        The factor-base bound B, at most :data:`~.smoothness.MAX_BOUND` (default: that of the
        ``precomputation`` file, else :func:`choose_bound` for the group's size); a bound whose
        linear algebra would need more than :data:`MAX_MATRIX_BYTES` is refused by
        :meth:`check_feasible`.
    max_bits : int, optional
        Size limit (default and at most 128 bits: measured on this machine, the first key of a
        112-bit group takes about 33 s of CPU time, of a 128-bit group about 260 s, with a
        factor base of about 9700 primes, and each further key about 0.06 s).
    precomputation : str or path, optional
        A file written by :meth:`FactorBaseLogs.save` or after an interruption
        (:class:`~.precomputation_file.PrecomputationInterrupted`), read and checked here
        (:func:`~.precomputation_file.load_precomputation`). :meth:`precompute` then uses its
        solved factor base, or resumes its relation collection; a group (or ``bound``) other than
        the file's is refused by :meth:`check_feasible` (``ConfigError``).
    rng
        See :class:`~encctl_gym.cryptanalysis.base.Breaker`.
    """

    name: ClassVar[str] = "index-calculus"
    DEFAULT_MAX_BITS: ClassVar[int] = 128
    #: Rounds of extra relations collected when the system leaves too many unknowns free.
    MAX_ROUNDS: ClassVar[int] = 6

    def __init__(
        self,
        *,
        bound: int | None = None,
        max_bits: int | None = None,
        precomputation: str | os.PathLike[str] | None = None,
        rng: RngLike = None,
    ) -> None:
        super().__init__(max_bits=max_bits, rng=rng)
        if self.max_bits > 128:
            raise BreakerLimitError(f"index-calculus supports at most 128 bits (max_bits), got {self.max_bits}")
        self.bound = None if bound is None else check_bound(bound)
        #: The file given as ``precomputation`` (checked), or ``None``.
        self.loaded: SavedPrecomputation | None = None if precomputation is None else load_precomputation(precomputation)

    def factor_base_bound(self, group: GroupParams) -> int:
        """B for this group: the ``bound`` given, else the loaded file's, else :func:`choose_bound`
        (at least 2, below p)."""
        bound = self.bound or (self.loaded.bound if self.loaded is not None else choose_bound(group.bits))
        return max(2, min(bound, group.p - 1))

    def _baby_steps(self, group: GroupParams) -> BabyStepGiantStep:
        return BabyStepGiantStep(max_bits=group.q.bit_length(), rng=self.rng)

    def uses_baby_steps(self, group: GroupParams) -> bool:
        """True if G is too small to supply the relations: q below :data:`SMALL_ORDER_FACTOR`
        times the residues whose lattices the relations are expected to take (:func:`cost_model`),
        where the walk over G would revisit its elements, and the baby-step table of
        :mod:`.bsgs` fits. The precomputation is then a :class:`SmallOrderLogs`."""
        if self.loaded is not None:
            return False
        bsgs = self._baby_steps(group)
        if bsgs.table_size(group) > bsgs.max_table:
            return False
        model = cost_model(group.bits, self.factor_base_bound(group))
        rows, half = sieve_region(group.bits)
        lattices = (
            model["cells_per_relation"] / (2 * rows * half) * (model["factor_base"] * (1 + EXTRA_FRACTION) + EXTRA_CONSTANT)
        )
        return group.q < SMALL_ORDER_FACTOR * max(lattices, 1.0)

    def expected_seconds(self, group: GroupParams) -> tuple[float, float]:
        """``(first, per_key)`` of :func:`cost_model` at :meth:`factor_base_bound`, or of
        baby-step giant-step when :meth:`uses_baby_steps`. Within :attr:`max_bits` the relations
        and the descent are priced by lattices of the group timed now (:func:`lattice_seconds`,
        :data:`SIEVED_LATTICE_SHARE` of the model's lattice count; one lattice a key at least)
        instead of :data:`CELL_SECONDS`. With a loaded file of this group the
        first key costs one descent (a complete file) or the relations still missing, the linear
        algebra and a descent (an interrupted one)."""
        if self.uses_baby_steps(group):
            return self._baby_steps(group).expected_seconds(group)
        bound = self.factor_base_bound(group)
        model = cost_model(group.bits, bound)
        if bound <= PROBE_MAX_BOUND and group.bits <= self.max_bits:  # timed on this machine (PROBE_LATTICES)
            per_lattice = lattice_seconds(group, bound)
            rows, half = sieve_region(group.bits)
            lattices_per_relation = SIEVED_LATTICE_SHARE * model["cells_per_relation"] / (2 * rows * half)
            need = model["factor_base"] * (1 + EXTRA_FRACTION) + EXTRA_CONSTANT
            model["relations"] = need * lattices_per_relation * per_lattice
            model["descent"] = model["per_key"] = max(1.0, lattices_per_relation) * per_lattice
            model["first"] = model["relations"] + model["linear_algebra"] + model["descent"]
        first = model["first"]
        if self.loaded is not None and self.loaded.group == group:
            if self.loaded.complete:
                first = model["per_key"]
            else:
                need = model["factor_base"] * (1 + EXTRA_FRACTION) + EXTRA_CONSTANT
                share = max(0.0, 1.0 - len(self.loaded.relations) / need)
                first = share * model["relations"] + model["linear_algebra"] + model["descent"]
        return first, model["per_key"]

    def matrix_bytes(self, group: GroupParams) -> float:
        """Expected peak memory of the first linear algebra (bytes): the dense core of
        :data:`CORE_FRACTION` of ``k (1 + EXTRA_FRACTION) + EXTRA_CONSTANT`` rows and of ``k``
        unknowns (plus the right-hand side), k the (estimated) size of the factor base, at
        :data:`MATRIX_BYTES_PER_ENTRY` each."""
        k = _prime_count(self.factor_base_bound(group))
        rows = CORE_FRACTION * (k * (1 + EXTRA_FRACTION) + EXTRA_CONSTANT)
        return rows * (CORE_FRACTION * k + 1) * MATRIX_BYTES_PER_ENTRY

    def check_feasible(self, group: GroupParams) -> None:
        """The limits of :class:`~.base.Breaker`, the loaded file's group and bound
        (:meth:`~.precomputation_file.SavedPrecomputation.check_group`), and the memory of the
        dense linear algebra (:meth:`matrix_bytes` at most :data:`MAX_MATRIX_BYTES`; none when
        :meth:`uses_baby_steps`, or when a complete file is loaded)."""
        if self.loaded is not None:
            self.loaded.check_group(group, self.bound)
        super().check_feasible(group)
        if self.uses_baby_steps(group) or (self.loaded is not None and self.loaded.complete):
            return
        need = self.matrix_bytes(group)
        if need > MAX_MATRIX_BYTES:
            bound = self.factor_base_bound(group)
            raise BreakerLimitError(
                f"index-calculus refuses factor-base bound {bound} for this {group.bits}-bit group: about "
                f"{_prime_count(bound):.0f} unknowns make a dense system of about {format_bytes(need)}, above the "
                f"limit of {format_bytes(MAX_MATRIX_BYTES)} (MAX_MATRIX_BYTES)"
            )

    def _check_group(self, group: GroupParams) -> None:
        n = group.cofactor
        if group.q == 2 or n % group.q == 0:
            raise GroupError(
                f"index-calculus needs an odd q that does not divide the cofactor (p - 1) / q; got q = {group.q}, cofactor = {n}"
            )

    def precompute(
        self, group: GroupParams, *, time_limit: float | None = None, progress: ProgressCallback | None = None
    ) -> Precomputation:
        """:meth:`~.base.Breaker.precompute`; with a loaded file, its cost is the file's (the work
        it took, as an attack from scratch pays it) plus this call's.

        Raises
        ------
        PrecomputationInterrupted
            On ``KeyboardInterrupt`` during the relations or the linear algebra (Ctrl-C, or
            raised by ``progress``): it carries the relations collected so far, to
            :meth:`~.precomputation_file.SavedPrecomputation.save` and resume from.
        """
        pre = super().precompute(group, time_limit=time_limit, progress=progress)
        if self.loaded is not None:
            prior, now = self.loaded.cost, pre.cost
            ops = {**now.operations, **({"loaded_logs": 1} if self.loaded.complete else {})}
            pre.cost = Cost(prior.seconds + now.seconds, ops, prior.cpu_seconds + now.cpu_seconds)
        return pre

    def _prepare(self, group: GroupParams) -> None:
        """Load the compiled sieve and python-flint before the clock starts (:func:`lattice_seconds`
        and a 1 x 1 solve): a one-time cost of the process (0.3-0.6 s from numba's cache on the
        development machine), not of the attack, which the first precomputation would otherwise count."""
        if self.uses_baby_steps(group):
            return
        bound = self.factor_base_bound(group)
        if bound <= PROBE_MAX_BOUND:  # the descent of a loaded file sieves too
            lattice_seconds(group, bound)
        if self.loaded is None or not self.loaded.complete:
            solve_mod_prime([{0: 1}], [1], 1, group.q)

    def _precompute(self, group: GroupParams, deadline: Deadline) -> tuple[Precomputation, Mapping[str, int]]:
        if self.uses_baby_steps(group):
            table, ops = self._baby_steps(group)._precompute(group, deadline)
            return SmallOrderLogs(group, table, self.rng), ops
        saved = self.loaded
        if saved is not None and saved.complete:
            assert saved.logs is not None
            pre = FactorBaseLogs(group, saved.bound, list(saved.logs), self.rng)
            pre.phase_seconds, pre.phase_cpu_seconds = dict(saved.phase_seconds), dict(saved.phase_cpu_seconds)
            return pre, dict(saved.cost.operations)
        src = self.rng or arith.secure_random()
        clock = _PhaseClock(*((saved.phase_seconds, saved.phase_cpu_seconds) if saved is not None else ()))
        # Phase 1: the factor base.
        with clock("factor_base"):
            fb = FactorBase(self.factor_base_bound(group))
        relations: list[Relation] = []
        counts = {"sieved_lattices": 0, "smoothness_tests": 0}
        if saved is not None:  # resume: the relations so far (once each) and the walk's position
            assert saved.walk is not None
            relations = list({(tuple(sorted(r.row.items())), r.rhs): r for r in saved.relations}.values())
            walk = RelationWalk(saved.walk.e, saved.walk.c)
            counts.update({k: saved.cost.operations.get(k, 0) for k in counts})
        else:
            walk = RelationWalk.start(group, src)
        phase = "relations"
        try:
            return self._relations_and_logs(group, fb, relations, walk, counts, clock, deadline)
        except KeyboardInterrupt:
            cost = deadline.cost({**counts, "relations": len(relations)})
            prior = saved.cost if saved is not None else Cost(0.0)
            state = SavedPrecomputation(
                group,
                fb.bound,
                None,
                relations,
                walk,
                Cost(prior.seconds + cost.seconds, cost.operations, prior.cpu_seconds + cost.cpu_seconds),
                clock.wall,
                clock.cpu,
            )
            raise PrecomputationInterrupted(clock.current or phase, state) from None

    def _relations_and_logs(
        self,
        group: GroupParams,
        fb: FactorBase,
        relations: list[Relation],
        walk: RelationWalk,
        counts: dict[str, int],
        clock: _PhaseClock,
        deadline: Deadline,
    ) -> tuple[Precomputation, Mapping[str, int]]:
        # Phase 2: relations; phase 3: linear algebra. More relations while a prime below
        # sqrt(B) (and sqrt(p), for toy groups) is undetermined, or more than SOLVED_FRACTION of
        # the primes that occur in the relations are: the descent needs those.
        k = len(fb)
        need = int(k * (1 + EXTRA_FRACTION)) + EXTRA_CONSTANT
        rank = 0
        logs: list[int | None] = [None] * k
        small = sum(1 for ell in fb.primes if ell <= max(2, math.isqrt(min(fb.bound, group.p))))
        for _ in range(self.MAX_ROUNDS):
            if len(relations) < need:  # a resumed collection may have them all
                with clock("relations"):
                    collect_relations(group, fb, relations, need, walk, deadline, counts)
            # The elimination runs inside FLINT and cannot be interrupted: refuse it up front
            # when the cost model says it would overrun the time limit.
            expected = cost_model(group.bits, fb.bound)["linear_algebra"]
            if expected > deadline.remaining:
                raise BreakerTimeoutError(
                    f"{deadline.what} stopped before its linear algebra: expected {expected:.3g} s, but only "
                    f"{max(deadline.remaining, 0.0):.3g} s of its time limit of {deadline.limit:g} s remain"
                )
            with clock("linear_algebra"):
                logs, rank = solve_mod_prime(
                    [r.row for r in relations], [r.rhs for r in relations], k, group.q, report=deadline.report
                )
            occurring = len({j for r in relations for j in r.row})
            solved = sum(v is not None for v in logs)
            if all(v is not None for v in logs[:small]) and solved >= SOLVED_FRACTION * occurring:
                break
            need = len(relations) + max(EXTRA_CONSTANT, int(EXTRA_FRACTION * k))
            deadline.check()
        else:
            raise BreakerError(
                f"index-calculus: only {sum(v is not None for v in logs)} of {k} factor-base logarithms "
                f"determined after {len(relations)} relations (rank {rank})"
            )
        pre = FactorBaseLogs(group, fb.bound, logs, self.rng)
        pre._fb = fb
        pre.phase_seconds, pre.phase_cpu_seconds = clock.wall, clock.cpu
        ops = {"factor_base": k, **counts, "relations": len(relations), "rank": rank, "solved_logs": pre.solved}
        return pre, ops
