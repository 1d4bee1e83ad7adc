"""The interface of the factoring breakers: one modulus per key, every factorisation checked.

A Paillier key (:mod:`encctl_gym.crypto.paillier`) is broken by factoring its modulus
``n = p q``: from p and q follow ``lambda = lcm(p-1, q-1)`` and ``mu``. Unlike the discrete
logarithms of :mod:`.base`, whose group survives every KeyUpd, a fresh Paillier key is a fresh
modulus, so nothing computed for one key serves the next (the factorization factory and batch
NFS of :mod:`encctl_gym.security.cost_models.factoring` are the exceptions, in cost only). A
:class:`Factorer` therefore has one phase: :meth:`Factorer.factor` returns a
:class:`Factorization` with its :class:`~.base.Cost`, after checking ``p q = n`` with
``1 < p <= q`` (:class:`~encctl_gym.errors.BreakerError` otherwise: a factorer never returns
an unchecked result).

Refusals mirror :class:`~.base.Breaker`: a modulus longer than ``max_bits`` or one whose
expected time (:meth:`Factorer.expected_seconds`, the method's cost model with a calibration
constant measured on this machine) exceeds :data:`~.base.MAX_EXPECTED_SECONDS` is refused
before any work with :class:`~encctl_gym.errors.BreakerLimitError`, and
:meth:`Factorer.check_time` gives ``crack --scheme paillier`` and the environment the same
estimate for ``keys`` moduli (``keys`` times the per-modulus time) against a limit.
"""

from __future__ import annotations

import abc
import dataclasses
import math
import threading
from collections.abc import Mapping
from typing import Any, ClassVar

from .._validation import check_int, check_positive, format_value
from ..crypto import arith
from ..crypto.arith import RandomSource, RngLike, format_int
from ..errors import BreakerError, BreakerLimitError, ParameterError
from .base import MAX_EXPECTED_SECONDS, Cost, Deadline, format_seconds
from .progress import ProgressCallback

__all__ = ["Factorization", "Factorer", "check_modulus", "verify_factors", "trial_division"]

#: Primes below this bound are removed by trial division before any factorer's main method.
TRIAL_BOUND = 1000


@dataclasses.dataclass(frozen=True)
class Factorization:
    """A checked factorisation ``n = p q`` with ``1 < p <= q``, and what it cost.

    Attributes
    ----------
    n : int
    p, q : int
        The two factors (hidden from ``repr``); for a Paillier modulus both are prime.
    cost : Cost
        Wall and CPU time, and the method's operation counts.
    method : str
        The factorer that found it.
    """

    n: int
    p: int = dataclasses.field(repr=False)
    q: int = dataclasses.field(repr=False)
    cost: Cost = dataclasses.field(default_factory=lambda: Cost(0.0))
    method: str = ""


def check_modulus(n: Any) -> int:
    """``n`` as an int after checking it is an odd composite integer >= 15 (a modulus to factor).

    Raises
    ------
    ParameterError
        For a non-integer, an even number, a number below 15 or a prime.
    """
    if isinstance(n, bool) or not (isinstance(n, int) or type(n).__name__ == "mpz"):
        raise ParameterError(f"a modulus to factor must be an integer, got {format_value(n)}")
    n = int(n)
    if n < 15 or n % 2 == 0 or arith.is_prime(n):
        raise ParameterError(f"a modulus to factor must be an odd composite >= 15, got n = {format_int(n)}")
    return n


def verify_factors(n: int, d: int, who: str) -> tuple[int, int]:
    """``(p, q)`` with ``p <= q`` from a divisor ``d`` of ``n``, after checking ``p q = n`` and
    ``1 < p``. Raises :class:`~encctl_gym.errors.BreakerError` if the check fails."""
    d = int(d)
    if not 1 < d < n or n % d:
        raise BreakerError(f"{who}: {format_int(d)} is not a proper divisor of n = {format_int(n)}")
    p, q = sorted((d, n // d))
    if p * q != n or p <= 1:  # pragma: no cover - guarded above
        raise BreakerError(f"{who}: the factors fail the check p q = n for n = {format_int(n)}")
    return p, q


def trial_division(n: int, bound: int = TRIAL_BOUND) -> int | None:
    """The smallest prime factor of ``n`` below ``bound``, or ``None``."""
    if n % 2 == 0:
        return 2
    d = 3
    while d < bound and d * d <= n:
        if n % d == 0:
            return d
        d += 2
    return None


class Factorer(abc.ABC):
    """A factoring method for the moduli of Paillier keys (module docstring).

    Subclasses set :attr:`name`, :attr:`DEFAULT_MAX_BITS`, implement :meth:`expected_seconds`
    and :meth:`_find_factor`.

    Parameters
    ----------
    max_bits : int, optional
        The longest modulus accepted (default :attr:`DEFAULT_MAX_BITS`).
    rng : None, int, RandomSource or numpy.random.Generator
        Randomness (starting points, curves); a seed makes the work reproducible.
    """

    name: ClassVar[str] = ""
    DEFAULT_MAX_BITS: ClassVar[int] = 0
    MAIN_THREAD_ONLY: ClassVar[bool] = False

    def __init__(self, *, max_bits: int | None = None, rng: RngLike = None) -> None:
        self.max_bits = check_int("max_bits", self.DEFAULT_MAX_BITS if max_bits is None else max_bits, minimum=4)
        self.rng: RandomSource | None = None if rng is None else arith.as_random_source(rng, f"factorer-{self.name}")

    def __repr__(self) -> str:
        return f"{type(self).__name__}(max_bits={self.max_bits})"

    @abc.abstractmethod
    def expected_seconds(self, bits: int) -> float:
        """Expected seconds to factor one balanced ``bits``-bit modulus on this machine."""

    def check_feasible(self, bits: int) -> None:
        """Refuse a modulus longer than :attr:`max_bits`, or one expected to take more than
        :data:`~.base.MAX_EXPECTED_SECONDS`, before any work (:class:`BreakerLimitError`)."""
        bits = check_int("modulus bits", bits, 4)
        seconds = self.expected_seconds(bits)
        if bits > self.max_bits:
            raise BreakerLimitError(
                f"factorer {self.name!r} refuses a {bits}-bit modulus: its limit is {self.max_bits} bits (max_bits); "
                f"expected time on this machine about {format_seconds(seconds)} per modulus"
            )
        if not seconds <= MAX_EXPECTED_SECONDS:
            raise BreakerLimitError(
                f"factorer {self.name!r} refuses a {bits}-bit modulus even with max_bits = {self.max_bits}: the expected "
                f"time on this machine, about {format_seconds(seconds)}, exceeds the ceiling of one year (MAX_EXPECTED_SECONDS)"
            )

    def check_time(
        self, bits: int, limit: float, *, keys: int = 1, limit_name: str = "the time limit", advice: str = ""
    ) -> tuple[float, float]:
        """The estimate of factoring ``keys`` moduli of ``bits`` bits (one per key: nothing is
        shared), checked against ``limit``; returns ``(per_key, total)`` expected seconds.

        Raises
        ------
        BreakerLimitError
            Above ``limit`` (naming the estimate), or from :meth:`check_feasible`.
        """
        keys = check_int("keys", keys, minimum=1)
        limit = check_positive(limit_name, limit)
        self.check_feasible(bits)
        per_key = self.expected_seconds(bits)
        total = keys * per_key
        if not total <= limit:
            raise BreakerLimitError(
                f"factorer {self.name!r} would take about {format_seconds(total)} for {keys} modulus/moduli of {bits} bits "
                f"({format_seconds(per_key)} each, a fresh modulus per key), more than {limit_name} = {format_seconds(limit)}"
                + (f"; {advice}" if advice else "")
            )
        return per_key, total

    def factor(
        self, n: Any, *, time_limit: float | None = None, rng: RngLike = None, progress: ProgressCallback | None = None
    ) -> Factorization:
        """Factor ``n`` into ``p q`` (checked) with its cost.

        Raises
        ------
        ParameterError
            If ``n`` is not an odd composite >= 15.
        BreakerLimitError
            If ``n`` is beyond the factorer's limits (before any work).
        BreakerTimeoutError
            Past ``time_limit``.
        BreakerError
            If the method found no factor within its bounds.
        """
        n = check_modulus(n)
        self.check_feasible(n.bit_length())
        if self.MAIN_THREAD_ONLY and threading.current_thread() is not threading.main_thread():
            raise BreakerError(f"factorer {self.name!r} runs only in the main thread of a process")
        src = arith.as_random_source(rng, f"factorer-{self.name}") if rng is not None else (self.rng or arith.secure_random())
        deadline = Deadline(
            None if time_limit is None else check_positive("time_limit", time_limit), f"{self.name}: factoring n", progress
        )
        small = trial_division(n)
        ops: Mapping[str, int]
        if small is not None:
            d, ops = small, {"trial_divisions": small // 2}
        else:
            d, ops = self._find_factor(n, deadline, src)
        p, q = verify_factors(n, d, self.name)
        return Factorization(n, p, q, deadline.cost(ops), self.name)

    @abc.abstractmethod
    def _find_factor(self, n: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int]]:
        """A proper divisor of ``n`` (unchecked; :meth:`factor` checks) and the operation counts.
        Raise :class:`BreakerError` if the method's bounds are exhausted."""


def balanced_factor_bits(bits: int) -> float:
    """ln of the smaller factor of a balanced ``bits``-bit modulus (about ``bits / 2`` bits)."""
    return (bits // 2) * math.log(2.0)
