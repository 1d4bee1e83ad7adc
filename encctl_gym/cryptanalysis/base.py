"""The interface every key breaker implements: two phases, cost records, checked results.

A key breaker recovers the secret exponent ``s`` of a public-key element ``h = g^s mod p`` of
the order-q subgroup G of Z_p^* (Example ex:elgamal). Under dynamic keys (Example
ex:dyn_elgamal) the group (p, q, g) never changes and only ``s`` does, so an attack on the
sample deciphering time of Definition def:sdt, ``tau(N, lambda)``, splits into the two phases
whose costs that definition lumps together:

1. :meth:`Breaker.precompute` runs once per *group* and returns a :class:`Precomputation`
   (a baby-step table, a random walk's multipliers, the logarithms of a factor base) with its
   own :class:`Cost` record;
2. :meth:`Precomputation.break_key` recovers one ``s`` per *key* and returns a
   :class:`RecoveredKey` with a per-key :class:`Cost` (wall time and the operation counts the
   algorithm defines). A precomputation may keep state between keys (the multiple-logarithm
   rho keeps its distinguished points), so keys can be broken one at a time, as an attacker
   pays for samples.

Every exponent is checked (``g^s = h``) before it is returned: a failed check raises
:class:`~encctl_gym.errors.BreakerError`, never a wrong key. A group too large for a breaker
is refused before any work (:class:`~encctl_gym.errors.BreakerLimitError`, naming the limit
and the expected time from the breaker's cost model), and so is a group whose first key that
model expects to take more than :data:`MAX_EXPECTED_SECONDS` (one year) whatever ``max_bits``
allows; a call past its ``time_limit`` stops with :class:`~encctl_gym.errors.BreakerTimeoutError`.

This layer imports only :mod:`encctl_gym.crypto.arith`, :mod:`encctl_gym.crypto.group`,
:mod:`encctl_gym.errors` and :mod:`encctl_gym._validation` (plus numpy, gmpy2, python-flint
and, optionally, PARI).
"""

from __future__ import annotations

import abc
import dataclasses
import math
import threading
import time
from collections.abc import Iterable, Mapping
from typing import Any, ClassVar

from .._validation import check_int, check_positive, format_value
from ..crypto import arith
from ..crypto.arith import RandomSource, RngLike, format_int
from ..crypto.group import GroupParams
from ..errors import BreakerError, BreakerLimitError, BreakerTimeoutError, KeyMismatchError, ParameterError
from ..resources import format_bytes
from .progress import ProgressCallback, check_progress

__all__ = [
    "Cost",
    "RecoveredKey",
    "Deadline",
    "Precomputation",
    "Breaker",
    "check_element",
    "as_list",
    "verify_exponent",
    "format_seconds",
    "format_bytes",
    "MAX_EXPECTED_SECONDS",
]


@dataclasses.dataclass(frozen=True)
class Cost:
    """Cost of one phase of an attack: wall time, CPU time and operation counts.

    Attributes
    ----------
    seconds : float
        Wall time of the phase on this machine (``time.perf_counter``).
    operations : Mapping[str, int]
        Counts the algorithm defines, e.g. ``group_operations`` (multiplications in G),
        ``smoothness_tests``, ``relations``; empty where the algorithm reports none (PARI).
    cpu_seconds : float
        CPU time of this process during the phase (``time.process_time``): on a machine shared
        with other jobs, the measure of the work that their load does not inflate.
    """

    seconds: float
    operations: Mapping[str, int] = dataclasses.field(default_factory=dict)
    cpu_seconds: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict ``{"seconds": ..., "cpu_seconds": ..., "operations": {...}}``."""
        return {
            "seconds": float(self.seconds),
            "cpu_seconds": float(self.cpu_seconds),
            "operations": {k: int(v) for k, v in self.operations.items()},
        }


@dataclasses.dataclass(frozen=True)
class RecoveredKey:
    """A secret exponent ``s`` with ``g^s = h`` (checked), and what it cost.

    Attributes
    ----------
    h : int
        The public-key element attacked.
    s : int
        The recovered exponent in ``[0, q)`` (hidden from ``repr``).
    cost : Cost
        The per-key cost (precomputation excluded).
    method : str
        The breaker that produced ``s`` (for the token chain: ``"token"`` or the inner breaker).
    """

    h: int
    s: int = dataclasses.field(repr=False)
    cost: Cost = dataclasses.field(default_factory=lambda: Cost(0.0))
    method: str = ""


def format_seconds(seconds: float) -> str:
    """A duration in the most readable unit (``"3.2 ms"``, ``"41 s"``, ``"2.1e+05 years"``)."""
    if not math.isfinite(seconds):
        return "inf"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.3g} us"
    if seconds < 1:
        return f"{seconds * 1e3:.3g} ms"
    if seconds < 3600:
        return f"{seconds:.3g} s"
    if seconds < 86400 * 365:
        return f"{seconds / 3600:.3g} h"
    return f"{seconds / (86400 * 365.25):.3g} years"


class Deadline:
    """The time limit and the progress of one breaker call: :meth:`check` raises once the limit
    has passed, :meth:`report` tells the caller's progress callback how far a phase is.

    Parameters
    ----------
    time_limit : float or None
        Seconds allowed (``None``: no limit).
    what : str
        Named in the error message (``"index-calculus precomputation"``).
    progress : callable, optional
        ``progress(phase, done, total)`` (:data:`~.progress.ProgressCallback`), called by the
        breaker as a phase advances (``None``: silent, the default of library use).
    """

    __slots__ = ("limit", "what", "start", "cpu_start", "_end", "progress")

    def __init__(self, time_limit: float | None, what: str, progress: ProgressCallback | None = None) -> None:
        self.limit = None if time_limit is None else check_positive("time_limit", time_limit)
        self.what = what
        self.progress = check_progress(progress)
        self.cpu_start = time.process_time()
        self.start = time.perf_counter()
        self._end = math.inf if self.limit is None else self.start + self.limit

    @property
    def remaining(self) -> float:
        """Seconds left (``inf`` without a limit)."""
        return self._end - time.perf_counter()

    def cost(self, operations: Mapping[str, int]) -> Cost:
        """The :class:`Cost` of the call so far: wall and CPU time since the start, ``operations``."""
        return Cost(time.perf_counter() - self.start, dict(operations), time.process_time() - self.cpu_start)

    def report(self, phase: str, done: float, total: float | None = None) -> None:
        """Tell the progress callback (if any) that ``phase`` has done ``done`` of ``total`` units
        (``None``: a total not known in advance). An exception the callback raises (a
        ``KeyboardInterrupt``) propagates to the breaker, which stops there."""
        if self.progress is not None:
            self.progress(phase, done, total)

    def check(self) -> None:
        """Raise :class:`~encctl_gym.errors.BreakerTimeoutError` if the limit has passed."""
        if time.perf_counter() > self._end:
            raise self.error()

    def error(self) -> BreakerTimeoutError:
        """The error raised when the limit has passed (also used by breakers that time out inside
        a library call)."""
        return BreakerTimeoutError(
            f"{self.what} stopped at its time limit of {self.limit:g} s (after {time.perf_counter() - self.start:.3g} s)"
        )


def check_element(group: GroupParams, h: Any) -> int:
    """Return ``h`` as an int after checking that it is an element of G = <g>.

    Raises
    ------
    KeyMismatchError
        If ``h`` is not an integer of ``[1, p)`` in the order-q subgroup (a key of another group).
    """
    if isinstance(h, bool) or not (isinstance(h, int) or type(h).__name__ in ("mpz", "int64", "uint64")):
        raise KeyMismatchError(f"a public-key element must be an integer, got {format_value(h)}")
    h = int(h)
    if not group.contains(h):
        raise KeyMismatchError(
            f"h = {format_int(h)} is not an element of the order-q subgroup of this group "
            f"({group.bits}-bit p = {format_int(group.p)}): a key of another group?"
        )
    return h


def as_list(name: str, values: Any, what: str) -> list[Any]:
    """``values`` as a list, after checking that it is an iterable (not a string or bytes) of
    ``what`` (named in the message)."""
    if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
        raise ParameterError(f"{name} must be an iterable of {what}, got {format_value(values)}")
    return list(values)


def verify_exponent(group: GroupParams, h: int, s: int, who: str) -> int:
    """Return ``s mod q`` after checking ``g^s = h mod p`` (one exponentiation).

    Raises
    ------
    BreakerError
        If the check fails: a breaker never returns an unchecked key.
    """
    s = int(s) % group.q
    if int(arith.powmod(group.g, s, group.p)) != h:
        raise BreakerError(f"{who}: the recovered exponent fails the check g^s = h for h = {format_int(h)}")
    return s


#: The longest expected time of a first key (precomputation included) that any breaker starts,
#: whatever its ``max_bits``: one year. Raising ``max_bits`` lets a breaker take on larger groups,
#: never a run that its own cost model puts beyond this (a 712-bit group for rho: about 6e92 years).
MAX_EXPECTED_SECONDS = 365.25 * 86400.0


def _check_time_limit(time_limit: float | None) -> float | None:
    return None if time_limit is None else check_positive("time_limit", time_limit)


class Precomputation:
    """What a breaker computed once for a group; breaks keys of that group one at a time.

    Subclasses implement :meth:`_solve`. Attributes are plain Python and numpy data, so a
    precomputation pickles (it is shipped to Dask workers by the ``crack`` command); the random
    source is not pickled (a worker passes its own ``rng``).

    Attributes
    ----------
    breaker : str
        The registry name of the breaker that made it.
    group : GroupParams
        The group (verified).
    cost : Cost
        The cost of the precomputation.
    rng : RandomSource or None
        Default randomness of :meth:`break_key` (``None``: secure).
    keys_broken : int
        Number of keys broken with it so far.
    """

    def __init__(self, breaker: str, group: GroupParams, rng: RandomSource | None = None) -> None:
        self.breaker = breaker
        self.group = group
        self.rng = rng
        self.cost = Cost(0.0)
        self.keys_broken = 0

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["rng"] = None  # gmpy2 random states do not pickle; workers pass their own rng
        return state

    def break_key(self, h: Any, *, time_limit: float | None = None, rng: RngLike = None) -> RecoveredKey:
        """Recover ``s`` with ``g^s = h`` (checked) and its per-key cost.

        Parameters
        ----------
        h : int
            A public-key element of this precomputation's group.
        time_limit : float, optional
            Seconds allowed for this call.
        rng : None, int, RandomSource or numpy.random.Generator
            Randomness of the attack (``None``: the precomputation's source, else secure).

        Returns
        -------
        RecoveredKey

        Raises
        ------
        KeyMismatchError
            If ``h`` is not in G of this group.
        BreakerTimeoutError
            Past ``time_limit``.
        BreakerError
            If no logarithm was found or the result fails the check.
        """
        h = check_element(self.group, h)
        src = arith.as_random_source(rng) if rng is not None else (self.rng or arith.secure_random())
        deadline = Deadline(_check_time_limit(time_limit), f"{self.breaker}: breaking h = {format_int(h)}")
        s, ops, method = self._solve(h, deadline, src)
        s = verify_exponent(self.group, h, s, self.breaker)
        cost = deadline.cost(ops)
        self.keys_broken += 1
        return RecoveredKey(h, s, cost, method or self.breaker)

    @abc.abstractmethod
    def _solve(self, h: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int], str]:
        """Return ``(s, operations, method)`` for ``h`` (unchecked; :meth:`break_key` checks)."""


class Breaker(abc.ABC):
    """A discrete-logarithm attack on the keys of one group, in two phases (see module docstring).

    Subclasses set :attr:`name`, :attr:`DEFAULT_MAX_BITS`, implement :meth:`expected_seconds`
    (the cost model behind the refusal message) and :meth:`_precompute`.

    Parameters
    ----------
    max_bits : int, optional
        The largest bit length of p accepted (default :attr:`DEFAULT_MAX_BITS`); a larger group
        is refused by :meth:`check_feasible` before any work.
    rng : None, int, RandomSource or numpy.random.Generator
        Randomness of the attack (``None``: secure; a seed makes the work reproducible).
    """

    #: Registry name.
    name: ClassVar[str] = ""
    #: Default size limit (bits of p, or of q when :attr:`LIMIT_COUNTS_Q`).
    DEFAULT_MAX_BITS: ClassVar[int] = 0
    #: Whether :attr:`max_bits` counts the bits of q (generic attacks, whose cost depends on q
    #: only) rather than of p.
    LIMIT_COUNTS_Q: ClassVar[bool] = False
    #: Set by breakers that need a process's main thread (PARI).
    MAIN_THREAD_ONLY: ClassVar[bool] = False
    #: The constructor option that takes another breaker (the token chain's ``inner``): the
    #: registry builds a breaker given there by name before it builds this one.
    WRAPS_OPTION: ClassVar[str | None] = None

    def __init__(self, *, max_bits: int | None = None, rng: RngLike = None) -> None:
        self.max_bits = check_int("max_bits", self.DEFAULT_MAX_BITS if max_bits is None else max_bits, minimum=2)
        self.rng: RandomSource | None = None if rng is None else arith.as_random_source(rng)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(max_bits={self.max_bits})"

    # ------------------------------------------------------------------ cost model and limits
    @abc.abstractmethod
    def expected_seconds(self, group: GroupParams) -> tuple[float, float]:
        """Expected ``(T_first, T_1)`` on this machine: the precomputation plus the first key, and
        each later key, from the algorithm's complexity and a documented calibration constant."""

    def check_feasible(self, group: GroupParams) -> None:
        """Refuse a group larger than :attr:`max_bits`, or one whose first key the cost model
        (:meth:`expected_seconds`) expects to take longer than :data:`MAX_EXPECTED_SECONDS`,
        before any work.

        Raises
        ------
        BreakerLimitError
            Naming the limit and the expected time of the first key.
        """
        size = group.q.bit_length() if self.LIMIT_COUNTS_Q else group.bits
        if size > self.max_bits:
            first, per_key = self.expected_seconds(group)
            what = f"a {group.bits}-bit group with a {size}-bit q" if self.LIMIT_COUNTS_Q else f"a {group.bits}-bit group"
            raise BreakerLimitError(
                f"breaker {self.name!r} refuses {what}: its limit is {self.max_bits} bits "
                f"({'of q, ' if self.LIMIT_COUNTS_Q else ''}max_bits); expected time on this machine about {format_seconds(first)} for the first key "
                f"and {format_seconds(per_key)} for each later one"
            )
        first, per_key = self.expected_seconds(group)
        if not first <= MAX_EXPECTED_SECONDS:
            raise BreakerLimitError(
                f"breaker {self.name!r} refuses a {group.bits}-bit group even with max_bits = {self.max_bits}: "
                f"the expected time of the first key on this machine, about {format_seconds(first)}, exceeds "
                f"the ceiling of {MAX_EXPECTED_SECONDS / (86400 * 365.25):g} year (MAX_EXPECTED_SECONDS)"
            )

    def check_time(
        self, group: GroupParams, limit: float, *, keys: int = 1, limit_name: str = "the time limit", advice: str = ""
    ) -> tuple[float, float, float]:
        """The feasibility estimate of breaking ``keys`` keys of ``group``, checked against ``limit``.

        One estimate for the environment (``breaker_time_limit``, one key) and ``encctl-gym
        crack`` (``--max-seconds``, the whole sequence): :meth:`check_feasible`, then the cost
        model's :meth:`expected_seconds`, ``T_first + (keys - 1) T_1``, refused above ``limit``
        before any work.

        Parameters
        ----------
        group : GroupParams
        limit : float
            Seconds allowed for the expected work.
        keys : int
            Number of keys of the sequence (>= 1).
        limit_name, advice : str
            The name of the limit and what to do instead, for the message.

        Returns
        -------
        (float, float, float)
            Expected ``T_first``, ``T_1`` and total seconds.

        Raises
        ------
        BreakerLimitError
            Above ``limit`` (the message gives the estimate), or from :meth:`check_feasible`.
        """
        keys = check_int("keys", keys, minimum=1)
        self.check_feasible(group)
        first, per_key = self.expected_seconds(group)
        total = first + (keys - 1) * per_key
        if not total <= limit:
            if keys == 1:
                what = f"{format_seconds(first)} for the first key of the {group.bits}-bit group (then "
            else:
                what = f"{format_seconds(total)} for {keys} keys of the {group.bits}-bit group ({format_seconds(first)} for the first key, then "
            raise BreakerLimitError(
                f"breaker {self.name!r} would take about {what}{format_seconds(per_key)} per key), more than "
                f"{limit_name} = {format_seconds(limit)}" + (f"; {advice}" if advice else "")
            )
        return first, per_key, total

    def _check_group(self, group: GroupParams) -> None:
        """Further structural requirements of a breaker (raise GroupError); none by default."""

    # ------------------------------------------------------------------ the two phases
    def precompute(
        self, group: GroupParams, *, time_limit: float | None = None, progress: ProgressCallback | None = None
    ) -> Precomputation:
        """Phase 1: the work that depends only on the group (once per group).

        Parameters
        ----------
        group : GroupParams
            The group (verified here).
        time_limit : float, optional
            Seconds allowed for this call.
        progress : callable, optional
            ``progress(phase, done, total)``, called as the phases advance (the index calculus
            reports ``"relations"`` and ``"linear algebra"``; :class:`~.progress.PhaseBars`
            draws them); ``None`` (default): silent.

        Returns
        -------
        Precomputation
            Reusable for every key of the group; its ``cost`` records this phase.

        Raises
        ------
        BreakerLimitError
            If the group is beyond the breaker's limit (before any work).
        GroupError
            If the group is invalid or lacks a structure the breaker needs.
        BreakerTimeoutError
            Past ``time_limit``.
        """
        if not isinstance(group, GroupParams):
            raise ParameterError(f"group must be a GroupParams, got {group!r}")
        group = group.verify()
        self.check_feasible(group)
        self._check_group(group)
        self._check_thread()
        limit = _check_time_limit(time_limit)
        self._prepare(group)  # before the clock: what the process loads once is not the attack's time
        deadline = Deadline(limit, f"{self.name} precomputation", progress)
        pre, ops = self._precompute(group, deadline)
        pre.cost = deadline.cost(ops)
        return pre

    def _prepare(self, group: GroupParams) -> None:
        """Work of the process, not of the attack, done before :meth:`precompute` starts its
        clock (the index calculus loads its compiled sieve); none by default."""

    @abc.abstractmethod
    def _precompute(self, group: GroupParams, deadline: Deadline) -> tuple[Precomputation, Mapping[str, int]]:
        """Return the precomputation and its operation counts."""

    def break_key(self, h: Any, pre: Precomputation, *, time_limit: float | None = None, rng: RngLike = None) -> RecoveredKey:
        """Phase 2: recover one key with a precomputation of this breaker (see
        :meth:`Precomputation.break_key`)."""
        if not isinstance(pre, Precomputation) or pre.breaker != self.name:
            raise ParameterError(f"pre must be a precomputation of breaker {self.name!r}, got {pre!r}")
        self._check_thread()
        return pre.break_key(h, time_limit=time_limit, rng=rng if rng is not None else self.rng)

    def _check_thread(self) -> None:
        if self.MAIN_THREAD_ONLY and threading.current_thread() is not threading.main_thread():
            raise BreakerError(
                f"breaker {self.name!r} runs only in the main thread of a process (its library is not "
                "thread-safe); use a process-based scheduler (joblib, the default) instead of threads"
            )
