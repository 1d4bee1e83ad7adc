"""Lattice attacks on LWE for real, on small dimensions: the primal attack and BDD with a reduced basis.

(Not to be confused with :mod:`.lattice_sieve`, the sieve of the discrete-logarithm index
calculus.) An instance is a public key ``(A, b = A s + e mod q)`` of
:mod:`encctl_gym.crypto.lwe`: ``A`` of shape (m, n), small ``s`` and ``e`` (centred binomial,
entries in ``[-eta, eta]``). Two breakers, each in the two phases of
:mod:`~encctl_gym.cryptanalysis.base` (once per public matrix ``A``, then once per key ``b``):

``primal``
    Kannan's embedding in the Bai-Galbraith form (the lattice of
    :mod:`encctl_gym.security.cost_models.lattice`): the rows ``(q e_i, 0, 0)``,
    ``(A^T_j, e_j, 0)`` and ``(b, 0, 1)`` generate a lattice of dimension ``m + n + 1`` that
    contains ``(e, -s, 1)``. LLL, then BKZ with block sizes 4, 6, ... (``fpylll``'s BKZ 2.0)
    until a basis vector with last coordinate +-1 gives an ``s`` that passes the check. The
    embedding contains ``b``: each key is a reduction of its own, and the phase per matrix does
    nothing.
``bdd``
    Babai's nearest plane on a reduced basis of the lattice ``{(A y + q k, y)}`` of dimension
    ``m + n``, which depends on ``A`` only: the target ``(b, 0)`` lies at ``(e, -s)`` from the
    lattice point ``(A s + q k, s)``. The phase per matrix reduces the basis (LLL, then BKZ of
    growing block size) until Babai decodes every one of the attacker's own test keys (it
    knows ``A`` and the distribution, so it can make keys ``A s' + e'`` and see whether they
    decode); each key is then one Babai call, and a key that still fails makes the shared basis
    stronger (one more block size) and is retried. This is the lattice analogue of the
    discrete-logarithm precomputation: a reduction done once for a public matrix shared across
    keys makes every later key cheap.

Every recovered secret is checked: ``s`` and ``e = b - A s mod q`` (centred, computed with
Python integers) must both lie in ``[-eta, eta]``; a failed check raises
:class:`~encctl_gym.errors.BreakerError`, never a wrong key. Work expected to exceed the time
limit is refused before it starts (:class:`~encctl_gym.errors.BreakerLimitError`), from the
block size of :func:`~encctl_gym.security.cost_models.lattice.primal_usvp_estimate` and the
calibration constants below.

Needs ``fpylll`` (and ``cysignals``): ``pip install 'encctl-gym[lattice]'``; without it
:class:`~encctl_gym.errors.OptionalDependencyError` names the extra.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from .._validation import check_int, check_positive, format_value
from ..crypto.arith import RngLike
from ..crypto.lwe import ByteStream
from ..errors import BreakerError, BreakerLimitError, OptionalDependencyError, ParameterError, ShapeError
from ..registry import Registry
from ..security.cost_models.lattice import LWEParameterSet, binomial_sigma, primal_usvp_estimate
from .base import MAX_EXPECTED_SECONDS, Cost, Deadline, format_seconds

__all__ = [
    "LWEInstance",
    "RecoveredLWESecret",
    "lwe_instances",
    "verify_secret",
    "LWEBreaker",
    "PrimalAttack",
    "BDDAttack",
    "LWE_BREAKERS",
    "get_lwe_breaker",
    "fpylll_available",
    "LLL_SECONDS",
    "BKZ_SECONDS",
    "add_lwe_arguments",
    "crack_lwe",
    "AttackTiming",
    "time_attack",
    "fit_exponential",
]

_INSTALL = "pip install 'encctl-gym[lattice]'"

#: Seconds of LLL on a lattice of dimension d: ``LLL_SECONDS * d^4`` (fitted on this machine with
#: ``python benchmarks/bench_lattice_lwe.py``: primal attacks of n = 30 ... 80, q = 3329, eta = 2, m = n,
#: which LLL alone solves).
LLL_SECONDS = 3.3e-9
#: Seconds of the BKZ tours: ``BKZ_SECONDS * d^3 * 2^(0.2 beta)`` (same run, n = 90 and 100; measured
#: 2026-12-05 with other jobs sharing the two cores, so an upper estimate).
BKZ_SECONDS = 6.0e-7


def _fpylll() -> Any:
    try:
        import fpylll
    except ImportError as exc:  # pragma: no cover - the extra is installed in the test environment
        raise OptionalDependencyError(f"the lattice breakers need fpylll (and cysignals); install them with: {_INSTALL}") from exc
    return fpylll


def fpylll_available() -> bool:
    """True if ``fpylll`` can be imported."""
    try:
        _fpylll()
    except OptionalDependencyError:  # pragma: no cover
        return False
    return True


@dataclasses.dataclass(frozen=True, eq=False)
class LWEInstance:
    """A public key ``(A, b)`` to attack: ``A`` (m, n) and ``b`` (m,) with entries in ``[0, q)``,
    and the bound ``eta`` of the secret and error entries (the attacker knows the distribution)."""

    A: np.ndarray = dataclasses.field(repr=False)
    b: np.ndarray = dataclasses.field(repr=False)
    q: int
    eta: int

    def __post_init__(self) -> None:
        q = check_int("q", self.q, minimum=2)
        eta = check_int("eta", self.eta, minimum=1)
        A, b = np.asarray(self.A), np.asarray(self.b)
        if A.ndim != 2 or b.shape != (A.shape[0],) or A.dtype.kind not in "iu" or b.dtype.kind not in "iu":
            raise ShapeError(f"A must be an integer (m, n) matrix and b an integer vector of m entries, got {format_value(A)}")
        if A.size and (A.min() < 0 or A.max() >= q) or b.size and (b.min() < 0 or b.max() >= q):
            raise ShapeError(f"the entries of A and b must lie in [0, q) with q = {q}")
        object.__setattr__(self, "A", A.astype(np.int64))
        object.__setattr__(self, "b", b.astype(np.int64))
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "eta", eta)

    @property
    def n(self) -> int:
        return int(self.A.shape[1])

    @property
    def m(self) -> int:
        return int(self.A.shape[0])

    @classmethod
    def from_public_key(cls, pk: Any) -> LWEInstance:
        """The instance of an :class:`~encctl_gym.crypto.lwe.LWEPublicKey`."""
        return cls(pk.A, pk.b, pk.params.q, pk.params.eta)

    def parameter_set(self) -> LWEParameterSet:
        """The instance as the cost model sees it (secret and error of width ``sqrt(eta / 2)``)."""
        sigma = binomial_sigma(self.eta)
        return LWEParameterSet(f"LWE n={self.n} q={self.q} eta={self.eta}", self.n, self.q, sigma, sigma, self.m)

    def to_dict(self) -> dict[str, Any]:
        """``{"q", "eta", "n", "m", "A", "b"}`` with plain integers (JSON-ready)."""
        return {"q": self.q, "eta": self.eta, "n": self.n, "m": self.m, "A": self.A.tolist(), "b": self.b.tolist()}


@dataclasses.dataclass(frozen=True, eq=False)
class RecoveredLWESecret:
    """A checked secret ``s`` with its error ``e = b - A s mod q`` (centred) and what it cost."""

    s: np.ndarray = dataclasses.field(repr=False)
    e: np.ndarray = dataclasses.field(repr=False)
    cost: Cost
    method: str
    block_size: int

    def to_dict(self) -> dict[str, Any]:
        return {
            "secret": self.s.tolist(),
            "error": self.e.tolist(),
            "method": self.method,
            "block_size": self.block_size,
            **self.cost.to_dict(),
        }


def lwe_instances(
    n: int, count: int, *, q: int = 3329, eta: int = 2, m: int | None = None, rng: RngLike = None, shared_matrix: bool = True
) -> list[tuple[LWEInstance, np.ndarray]]:
    """A test set: ``count`` instances ``(A, A s + e mod q)`` with their secrets, the matrix ``A``
    shared by all (``shared_matrix``, as under key rotation with a fixed public matrix) or fresh."""
    n, count = check_int("n", n, minimum=1), check_int("count", count, minimum=1)
    m = n if m is None else check_int("m", m, minimum=1)
    q, eta = check_int("q", q, minimum=2), check_int("eta", eta, minimum=1)
    stream = ByteStream(rng, "lwe instances")
    A = stream.uniform(q, (m, n))
    out: list[Any] = []
    for _ in range(count):
        if not shared_matrix and out:
            A = stream.uniform(q, (m, n))
        s, e = stream.binomial(eta, (n,)), stream.binomial(eta, (m,))
        out.append((LWEInstance(A, (A @ s + e) % q, q, eta), s))
    return out


def verify_secret(instance: LWEInstance, s: Any, who: str = "breaker") -> np.ndarray:
    """``e = b - A s mod q`` (centred, Python integers) after checking that ``s`` and ``e`` lie in
    ``[-eta, eta]``.

    Raises
    ------
    BreakerError
        If the check fails.
    """
    s_int = [int(v) for v in np.asarray(s).ravel()]
    q, eta = instance.q, instance.eta
    if len(s_int) != instance.n or any(abs(v) > eta for v in s_int):
        raise BreakerError(f"{who}: the recovered secret is not a vector of {instance.n} entries in [-{eta}, {eta}]")
    e = []
    for row, bi in zip(instance.A.tolist(), instance.b.tolist()):
        r = (bi - sum(a * v for a, v in zip(row, s_int))) % q
        e.append(r - q if r > q // 2 else r)
    if any(abs(v) > eta for v in e):
        raise BreakerError(f"{who}: b - A s mod q has entries beyond eta = {eta}: the recovered secret is wrong")
    return np.array(e, dtype=np.int64)


def _qary_rows(fpylll: Any, A: np.ndarray, q: int, extra: int) -> Any:
    # rows (q e_i, 0) and (A^T_j, e_j) of the lattice {(A y + q k, y)}, plus `extra` zero columns and rows
    m, n = A.shape
    d = m + n + extra
    B = fpylll.IntegerMatrix(d, d)
    for i in range(m):
        B[i, i] = q
    At = A.T.tolist()
    for j in range(n):
        for i, a in enumerate(At[j]):
            B[m + j, i] = a
        B[m + j, m + j] = 1
    return B


def _bkz(fpylll: Any, B: Any, beta: int) -> None:
    # one BKZ 2.0 reduction (a few tours); long double Gram-Schmidt, mpfr if fplll's double fails
    param = fpylll.BKZ.Param(block_size=beta, max_loops=4, flags=fpylll.BKZ.AUTO_ABORT | fpylll.BKZ.MAX_LOOPS)
    try:
        fpylll.BKZ.reduction(B, param, float_type="ld")
    except RuntimeError:  # pragma: no cover - precision trouble on larger instances
        fpylll.BKZ.reduction(B, param, float_type="mpfr", precision=120)


def _next_beta(beta: int) -> int:
    return beta + 2 if beta < 20 else beta + 1


class LWEPrecomputation:
    """What a breaker computed once for a public matrix ``A``; breaks keys ``b`` one at a time."""

    def __init__(self, breaker: LWEBreaker, A: np.ndarray, q: int, eta: int, cost: Cost) -> None:
        self.breaker, self.A, self.q, self.eta, self.cost = breaker, A, q, eta, cost
        self.keys_broken = 0

    def break_key(self, instance: LWEInstance, *, time_limit: float | None = None) -> RecoveredLWESecret:
        """Recover and check the secret of ``instance`` (its matrix must be this one's)."""
        if instance.q != self.q or instance.A.shape != self.A.shape or not np.array_equal(instance.A, self.A):
            raise ParameterError("the instance's public matrix (or modulus) is not the one this precomputation reduced")
        deadline = Deadline(time_limit, f"{self.breaker.name}: breaking an LWE key of dimension {instance.n}")
        s, beta, ops = self._solve(instance, deadline)
        e = verify_secret(instance, s, self.breaker.name)
        self.keys_broken += 1
        return RecoveredLWESecret(np.asarray(s, dtype=np.int64), e, deadline.cost(ops), self.breaker.name, beta)

    def _solve(self, instance: LWEInstance, deadline: Deadline) -> tuple[np.ndarray, int, Mapping[str, int]]:
        raise NotImplementedError


class _PrimalKeys(LWEPrecomputation):
    def _solve(self, instance: LWEInstance, deadline: Deadline) -> tuple[np.ndarray, int, Mapping[str, int]]:
        fpylll = _fpylll()
        m, n = instance.A.shape
        B = _qary_rows(fpylll, instance.A, instance.q, 1)
        d = m + n + 1
        for i, v in enumerate(instance.b.tolist()):
            B[d - 1, i] = v
        B[d - 1, d - 1] = 1
        fpylll.LLL.reduction(B)
        beta, tours = 2, 0
        while True:
            s = _embedded_secret(B, instance)
            if s is not None:
                return s, beta, {"bkz_calls": tours, "dimension": d}
            deadline.check()
            beta = _next_beta(beta)
            if beta > min(d, self.breaker.max_block_size):
                raise BreakerError(f"primal: no secret found up to block size {beta - 1} (dimension {d})")
            _bkz(fpylll, B, beta)
            tours += 1


def _embedded_secret(B: Any, instance: LWEInstance) -> np.ndarray | None:
    # a basis row (e, -s, +-1) whose s and e pass the check
    m, n = instance.A.shape
    for r in range(B.nrows):
        last = B[r, m + n]
        if abs(last) != 1:
            continue
        s = np.array([-last * B[r, m + j] for j in range(n)], dtype=np.int64)
        try:
            verify_secret(instance, s)
        except BreakerError:
            continue
        return s
    return None


class _ReducedBasis(LWEPrecomputation):
    def __init__(self, breaker: LWEBreaker, A: np.ndarray, q: int, eta: int, cost: Cost, basis: Any, beta: int) -> None:
        super().__init__(breaker, A, q, eta, cost)
        self.basis, self.beta = basis, beta
        self._gso: Any = None  # fpylll's GSO.Mat, built at the first decode

    def decode(self, b: np.ndarray) -> np.ndarray | None:
        """Babai's nearest plane on the reduced basis: the candidate ``s`` for ``b`` (unchecked;
        ``None`` if it is not even short)."""
        fpylll = _fpylll()
        if self._gso is None:
            self._gso = fpylll.GSO.Mat(self.basis, float_type="ld")
            self._gso.update_gso()
        m, n = self.A.shape
        coeffs = self._gso.babai([int(v) for v in b] + [0] * n)
        v = self.basis.multiply_left(coeffs)
        s = np.array(v[m:], dtype=np.int64)
        return s if np.abs(s).max(initial=0) <= self.eta else None

    def strengthen(self) -> None:
        """One more BKZ block size on the shared basis."""
        self.beta = _next_beta(self.beta)
        _bkz(_fpylll(), self.basis, self.beta)
        self._gso = None

    def _solve(self, instance: LWEInstance, deadline: Deadline) -> tuple[np.ndarray, int, Mapping[str, int]]:
        extra = 0
        while True:
            s = self.decode(instance.b)
            if s is not None:
                try:
                    verify_secret(instance, s)
                    return s, self.beta, {"babai_calls": extra + 1, "extra_bkz": extra}
                except BreakerError:
                    pass
            deadline.check()
            if self.beta >= min(self.basis.nrows, self.breaker.max_block_size):
                raise BreakerError(f"bdd: Babai fails up to block size {self.beta} (dimension {self.basis.nrows})")
            self.strengthen()
            extra += 1


class LWEBreaker:
    """A lattice attack on LWE keys in two phases (module docstring).

    Parameters
    ----------
    max_block_size : int
        Largest BKZ block size tried (default 60).
    rng : None, int, RandomSource or numpy Generator
        The attacker's randomness (the BDD breaker's own test keys).
    """

    name: ClassVar[str] = ""

    def __init__(self, *, max_block_size: int = 60, rng: RngLike = None) -> None:
        self.max_block_size = check_int("max_block_size", max_block_size, minimum=2)
        self.rng = rng

    def __repr__(self) -> str:
        return f"{type(self).__name__}(max_block_size={self.max_block_size})"

    def expected_seconds(self, instance: LWEInstance) -> tuple[float, float]:
        """Expected ``(T_first, T_later)``: the block size of the cost model
        (:func:`~encctl_gym.security.cost_models.lattice.primal_usvp_estimate`) in the fitted
        time ``LLL_SECONDS d^4 + BKZ_SECONDS d^3 2^(0.2 beta)`` (``beta > 2``)."""
        est = primal_usvp_estimate(instance.parameter_set())
        d = instance.m + instance.n + 1
        reduction = LLL_SECONDS * d**4 + (BKZ_SECONDS * d**3 * 2 ** (0.2 * est.beta) if est.beta > 2 else 0.0)
        return reduction, self._later_seconds(reduction, d)

    def _later_seconds(self, reduction: float, d: int) -> float:
        return reduction

    def check_time(self, instance: LWEInstance, limit: float, *, keys: int = 1, limit_name: str = "the time limit") -> float:
        """The expected time of ``keys`` keys of one matrix, refused above ``limit`` (or above
        :data:`~encctl_gym.cryptanalysis.base.MAX_EXPECTED_SECONDS`) before any work.

        Raises
        ------
        BreakerLimitError
            Naming the estimate, the block size and the limit.
        """
        limit = check_positive(limit_name, limit)
        first, later = self.expected_seconds(instance)
        total = first + (check_int("keys", keys, minimum=1) - 1) * later
        beta = primal_usvp_estimate(instance.parameter_set()).beta
        if not total <= min(limit, MAX_EXPECTED_SECONDS) or beta > self.max_block_size:
            raise BreakerLimitError(
                f"breaker {self.name!r} refuses {keys} LWE key(s) of dimension n = {instance.n} (q = {instance.q}, eta = "
                f"{instance.eta}): the cost model needs block size {beta} (limit {self.max_block_size}) and about "
                f"{format_seconds(total)} on this machine, more than {limit_name} = {format_seconds(limit)}"
            )
        return total

    def precompute(self, A: Any, q: int, eta: int, *, time_limit: float | None = None) -> LWEPrecomputation:
        """The phase once per public matrix."""
        _fpylll()
        probe = LWEInstance(np.asarray(A), np.zeros(np.asarray(A).shape[0], dtype=np.int64), q, eta)
        deadline = Deadline(time_limit, f"{self.name}: reducing the public matrix")
        return self._precompute(probe, deadline)

    def _precompute(self, probe: LWEInstance, deadline: Deadline) -> LWEPrecomputation:
        raise NotImplementedError

    def break_instances(
        self, instances: list[LWEInstance], *, time_limit: float | None = None
    ) -> tuple[Cost, list[RecoveredLWESecret]]:
        """Break instances that share one matrix: ``(precomputation cost, [secrets])``."""
        if not instances:
            raise ParameterError("no instances to break")
        pre = self.precompute(instances[0].A, instances[0].q, instances[0].eta, time_limit=time_limit)
        return pre.cost, [pre.break_key(inst, time_limit=time_limit) for inst in instances]


class PrimalAttack(LWEBreaker):
    """Kannan's embedding and BKZ, one reduction per key (module docstring)."""

    name = "primal"

    def _precompute(self, probe: LWEInstance, deadline: Deadline) -> LWEPrecomputation:
        return _PrimalKeys(self, probe.A, probe.q, probe.eta, deadline.cost({}))


class BDDAttack(LWEBreaker):
    """Babai's nearest plane on a basis reduced once per matrix (module docstring).

    Parameters
    ----------
    test_keys : int
        The attacker's own keys that the reduced basis must decode before the precomputation
        ends (default 8).
    """

    name = "bdd"

    def __init__(self, *, max_block_size: int = 60, rng: RngLike = None, test_keys: int = 8) -> None:
        super().__init__(max_block_size=max_block_size, rng=rng)
        self.test_keys = check_int("test_keys", test_keys, minimum=1)

    def _later_seconds(self, reduction: float, d: int) -> float:
        return LLL_SECONDS * d**3  # one Babai call: a Gram-Schmidt pass over the basis

    def _precompute(self, probe: LWEInstance, deadline: Deadline) -> LWEPrecomputation:
        fpylll = _fpylll()
        q, eta = probe.q, probe.eta
        B = _qary_rows(fpylll, probe.A, q, 0)
        fpylll.LLL.reduction(B)
        stream = ByteStream(self.rng, "bdd test keys")
        tests = []
        for _ in range(self.test_keys):
            s, e = stream.binomial(eta, (probe.n,)), stream.binomial(eta, (probe.m,))
            tests.append(LWEInstance(probe.A, (probe.A @ s + e) % q, q, eta))
        pre = _ReducedBasis(self, probe.A, q, eta, Cost(0.0), B, 2)
        tours = 0
        while not all(_decodes(pre, t) for t in tests):
            deadline.check()
            if pre.beta >= min(B.nrows, self.max_block_size):
                raise BreakerError(f"bdd: the test keys do not decode up to block size {pre.beta}")
            pre.strengthen()
            tours += 1
        pre.cost = deadline.cost({"bkz_calls": tours, "block_size": pre.beta, "dimension": B.nrows})
        return pre


def _decodes(pre: _ReducedBasis, instance: LWEInstance) -> bool:
    s = pre.decode(instance.b)
    if s is None:
        return False
    try:
        verify_secret(instance, s)
    except BreakerError:
        return False
    return True


#: The LWE breakers by name (:class:`~encctl_gym.registry.Registry`).
LWE_BREAKERS: Registry[type[LWEBreaker]] = Registry("LWE breaker", [PrimalAttack, BDDAttack])


def get_lwe_breaker(name: str, **options: Any) -> LWEBreaker:
    """An LWE breaker by name (:data:`LWE_BREAKERS`); ``options`` go to its constructor."""
    breaker: LWEBreaker = LWE_BREAKERS.build(name, **options)
    return breaker


# ----------------------------------------------------------------------------- encctl-gym crack --scheme lwe
def add_lwe_arguments(parser: Any) -> None:
    """The options of ``encctl-gym crack --scheme lwe`` (``--keys``, ``--seed``, ``--time-limit``,
    ``--max-seconds`` and ``--json`` are the command's shared ones)."""
    group = parser.add_argument_group("--scheme lwe")
    group.add_argument("--dimension", type=int, default=30, help="LWE dimension n (default 30)")
    group.add_argument("--modulus", type=int, default=3329, help="modulus q (default 3329)")
    group.add_argument("--eta", type=int, default=2, help="centred binomial parameter of s and e (default 2)")
    group.add_argument("--samples", type=int, default=None, help="rows m of the public matrix (default n)")
    group.add_argument("--attack", default="primal", choices=list(LWE_BREAKERS), help="lattice attack (default primal)")
    group.add_argument(
        "--max-block-size", dest="max_block_size", type=int, default=60, help="largest BKZ block size (default 60)"
    )


def crack_lwe(args: Any) -> int:
    """``encctl-gym crack --scheme lwe``: ``--keys`` seeded instances sharing one public matrix,
    broken by ``--attack``; each secret checked and compared with the instance's; the table (or
    JSON with every instance ``(q, A, b)`` and its recovered secret)."""
    import json
    import sys

    from .keys import check_keys

    keys = check_keys(args.keys, "--keys")
    seed = check_int("--seed", args.seed, minimum=0)
    n = check_int("--dimension", args.dimension, minimum=2)
    breaker = get_lwe_breaker(args.attack, max_block_size=args.max_block_size, rng=seed + 2)
    items = lwe_instances(n, keys, q=args.modulus, eta=args.eta, m=args.samples, rng=seed + 1)
    instances = [inst for inst, _ in items]
    total = breaker.check_time(instances[0], args.max_seconds, keys=keys, limit_name="--max-seconds")
    estimate = primal_usvp_estimate(instances[0].parameter_set())
    out = sys.stderr if args.json else sys.stdout
    print(
        f"crack: {breaker.name} on {keys} LWE key(s) of n = {n}, q = {args.modulus}, eta = {args.eta}: the cost model needs "
        f"block size {estimate.beta}; expected about {format_seconds(total)} on this machine",
        file=out,
        flush=True,
    )
    pre, found = breaker.break_instances(instances, time_limit=args.time_limit)
    for (_, s), rec in zip(items, found):
        if not np.array_equal(rec.s, s):  # never expected: every secret passed the check
            raise BreakerError("a recovered LWE secret differs from the instance's secret")
    if args.json:
        doc = {
            "scheme": "lwe",
            "attack": breaker.name,
            "n": n,
            "q": instances[0].q,
            "eta": instances[0].eta,
            "m": instances[0].m,
            "model_block_size": estimate.beta,
            "precomputation": pre.to_dict(),
            "instances": [{**inst.to_dict(), **rec.to_dict()} for inst, rec in zip(instances, found)],
            "secrets_match": True,
        }
        print(json.dumps(doc))
        return 0
    print(f"precomputation (once for the shared matrix A): {format_seconds(pre.seconds)}")
    print(f"{'key':>5}  {'seconds':>10}  {'block size':>10}  operations")
    for i, rec in enumerate(found):
        ops = " ".join(f"{k}={v}" for k, v in rec.cost.operations.items())
        print(f"{i:>5}  {rec.cost.seconds:10.4f}  {rec.block_size:>10}  {ops}")
    print(f"all {keys} secrets checked (s and b - A s mod q within [-eta, eta]) and equal to the instances' secrets")
    return 0


# ----------------------------------------------------------------------------- measurement
@dataclasses.dataclass(frozen=True)
class AttackTiming:
    """One measurement of :func:`time_attack`: the cost model's block size beside the measured
    ones, the precomputation, the first key and the later keys (wall seconds)."""

    attack: str
    n: int
    q: int
    eta: int
    keys: int
    model_beta: int
    measured_beta: int
    precomputation_seconds: float
    first_key_seconds: float
    mean_later_seconds: float

    @property
    def first_total(self) -> float:
        """``T_first``: the precomputation and the first key."""
        return self.precomputation_seconds + self.first_key_seconds


def time_attack(attack: str, n: int, *, keys: int = 3, q: int = 3329, eta: int = 2, seed: int = 0) -> AttackTiming:
    """Break ``keys`` seeded instances of dimension ``n`` sharing one matrix (m = n) and time them;
    every secret is checked and compared with the instance's (the numbers of ``docs/lwe.md``)."""
    keys = check_int("keys", keys, minimum=2)
    items = lwe_instances(n, keys, q=q, eta=eta, rng=seed)
    breaker = get_lwe_breaker(attack, rng=seed + 1)
    pre, found = breaker.break_instances([inst for inst, _ in items])
    if not all(np.array_equal(rec.s, s) for rec, (_, s) in zip(found, items)):
        raise BreakerError(f"{attack}: a recovered secret differs from the instance's")  # pragma: no cover
    later = [rec.cost.seconds for rec in found[1:]]
    return AttackTiming(
        attack,
        n,
        q,
        eta,
        keys,
        primal_usvp_estimate(items[0][0].parameter_set()).beta,
        max(rec.block_size for rec in found),
        pre.seconds,
        found[0].cost.seconds,
        sum(later) / len(later),
    )


def fit_exponential(ns: Any, seconds: Any) -> tuple[float, float]:
    """Least-squares fit of ``log2 T = a + b n``: returns ``(a, b)`` (T doubles every ``1 / b`` dimensions)."""
    x, y = np.asarray(ns, dtype=float), np.log2(np.asarray(seconds, dtype=float))
    if x.size < 2 or not np.all(np.isfinite(y)):
        raise ParameterError("the fit needs at least two positive times")
    b, a = np.polyfit(x, y, 1)
    return float(a), float(b)
