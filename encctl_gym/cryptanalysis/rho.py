"""Pollard rho in the order-q subgroup G, and its multiple-logarithm variant.

Both breakers share one random walk. It is an r-adding walk (Teske) with ``r = 32``
multipliers ``M_j = g^(c_j)`` that depend on the group only, never on the target:
``f(y) = y M_j`` with ``j = y mod 32``. A walk started at ``y_0 = g^(a_0) h^b`` stays of the
form ``y = g^a h^b`` with the same ``b`` and ``a = a_0 + sum c_j``, and runs until it reaches a
*distinguished point* (``y < p / 2^d``, about one point in 2^d). Two walks that meet follow the
same path from there on and stop at the same distinguished point; if their ``b`` differ,
``g^a h^b = g^a' h^b'`` gives ``s = (a - a') / (b' - b) mod q`` (parallel collision search,
van Oorschot and Wiener). About ``sqrt(pi q / 2)`` steps are needed for the first collision.

* :class:`PollardRho` (``"rho"``) forgets its distinguished points after each key: every key
  costs about ``sqrt(pi q / 2)`` steps, as the paper's per-key charge (Definition def:sdt)
  assumes.
* :class:`MultiLogRho` (``"rho-multi"``, Kuhn and Struik, 2001) keeps them: once a key is
  solved, every distinguished point of its walks has a known logarithm ``a + b s``, and a
  later key's walk that runs into any earlier trail is solved when it reaches that trail's
  distinguished point. Because the walk does not depend on the target, the table only grows
  and each later key is cheaper (about ``sqrt(2 q N)`` steps for N keys instead of
  ``N sqrt(pi q / 2)``). Optionally ``table_walks`` walks from known powers ``g^a`` fill the
  table during the precomputation (the Bernstein-Lange trade-off).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import ClassVar

import gmpy2

from .._validation import check_int, format_value
from ..crypto import arith
from ..crypto.arith import RandomSource, RngLike, format_int
from ..crypto.group import GroupParams
from ..errors import BreakerError, BreakerLimitError
from .base import Breaker, Deadline, Precomputation, format_bytes

__all__ = ["RandomWalk", "PollardRho", "MultiLogRho", "SECONDS_PER_STEP", "MAX_TABLE_WALKS"]

#: Seconds per step of the walk (one multiplication in G and one exponent addition, Python
#: integers), measured on this machine with ``python benchmarks/bench_cryptanalysis.py``.
SECONDS_PER_STEP = 1.6e-7

#: Number of multipliers of the r-adding walk (a power of two: j = y mod R).
R = 32
#: Target ratio sqrt(q) / (mean walk length): walks are short against the collision time, so
#: the detour from a collision to the next distinguished point is about 1/64 of the work.
_WALKS_PER_SQRT_Q = 64
#: A walk longer than this many mean lengths is assumed trapped in a cycle without a
#: distinguished point and abandoned (probability about e^-20 for a walk that is not).
_CAP_FACTOR = 20
_CHUNK = 4096
#: Largest ``table_walks`` of :class:`MultiLogRho`: each walk may add one distinguished point to
#: the table, a dict entry of about 140 bytes (two Python integers and the slot; 138 bytes
#: measured for a million 64-bit points), so 2^22 walks keep at most about 0.55 GiB.
MAX_TABLE_WALKS = 1 << 22
_BYTES_PER_POINT = 140


class RandomWalk(Precomputation):
    """The r-adding walk of a group and the distinguished points seen so far.

    Attributes
    ----------
    multipliers, steps : list of int
        ``M_j = g^(c_j) mod p`` and ``c_j`` (j < 32).
    dp_bits : int
        A point is distinguished when ``y < p >> dp_bits``.
    known : dict
        Distinguished point -> its logarithm to the base g (kept across keys by
        :class:`MultiLogRho`, emptied after each key by :class:`PollardRho`).
    reuse : bool
        Whether :attr:`known` persists across keys.
    """

    def __init__(self, name: str, group: GroupParams, src: RandomSource, reuse: bool, rng: RandomSource | None) -> None:
        super().__init__(name, group, rng)
        q, p, g = group.q, group.p, group.g
        self.steps = [src.between(1, q) for _ in range(R)]
        self.multipliers = [int(gmpy2.powmod(g, c, p)) for c in self.steps]
        expected = math.sqrt(math.pi * q / 2)
        self.dp_bits = max(0, int(math.log2(max(1.0, expected / _WALKS_PER_SQRT_Q))))
        self.reuse = reuse
        self.known: dict[int, int] = {}

    @property
    def mean_walk_length(self) -> int:
        """About 2^dp_bits steps between distinguished points."""
        return 1 << self.dp_bits

    def walk(self, y: int, a: int, deadline: Deadline) -> tuple[int | None, int, int]:
        """Walk from ``y`` (exponent offset ``a``) to the next distinguished point.

        Returns
        -------
        (int or None, int, int)
            The distinguished point (``None`` if the walk was abandoned as a cycle), the
            exponent offset there (not reduced mod q), and the number of steps.
        """
        p = self.group.p
        limit = p >> self.dp_bits
        table = list(zip(self.multipliers, self.steps))
        cap = _CAP_FACTOR * self.mean_walk_length + 64
        done = 0
        while done < cap:
            for i in range(_CHUNK):
                m, c = table[y & (R - 1)]
                y = y * m % p
                a += c
                if y < limit:
                    return y, a, done + i + 1
            done += _CHUNK
            deadline.check()
        return None, a, done

    def add_known_walks(self, walks: int, src: RandomSource, deadline: Deadline) -> int:
        """Run ``walks`` walks from known powers ``g^a`` and store their distinguished points;
        return the number of steps."""
        q, p, g = self.group.q, self.group.p, self.group.g
        total = 0
        for _ in range(walks):
            a0 = src.between(0, q)
            y, a, n = self.walk(int(gmpy2.powmod(g, a0, p)), a0, deadline)
            total += n
            if y is not None:
                self.known.setdefault(y, a % q)
        return total

    def _solve(self, h: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int], str]:
        q, p, g = self.group.q, self.group.p, self.group.g
        pending: dict[int, tuple[int, int]] = {}
        give_up = 100 * math.sqrt(math.pi * q / 2) + 100 * self.mean_walk_length + 10_000
        steps = walks = 0
        s: int | None = None
        while s is None:
            a0, b = src.between(0, q), src.between(1, q)
            start = int(gmpy2.powmod(g, a0, p) * gmpy2.powmod(h, b, p) % p)
            y, a, n = self.walk(start, a0, deadline)
            steps += n
            walks += 1
            if y is None:
                continue
            a %= q
            if y in self.known:  # g^a h^b = g^L
                s = (self.known[y] - a) * pow(b, -1, q) % q
            elif y in pending:
                a1, b1 = pending[y]
                if b1 != b:  # g^a h^b = g^a1 h^b1
                    s = (a - a1) * pow(b1 - b, -1, q) % q
            else:
                pending[y] = (a, b)
            if s is None and steps > give_up:  # 100 times the expected work: something is wrong
                raise BreakerError(f"{self.breaker}: no collision after {steps} steps ({walks} walks) for h = {format_int(h)}")
        if self.reuse:
            for y, (a, b) in pending.items():
                self.known.setdefault(y, (a + b * s) % q)
        ops = {"group_operations": steps, "walks": walks, "distinguished_points": len(pending) + 1}
        return s, ops, ""


class PollardRho(Breaker):
    """Pollard rho with distinguished points, every key on its own; registry name ``"rho"``.

    The precomputation is only the walk's 32 multipliers; each key costs about
    ``sqrt(pi q / 2)`` group operations (see the module docstring).

    Parameters
    ----------
    max_bits : int, optional
        The largest bit length of q accepted (default 64); p may be larger.
    rng
        See :class:`~encctl_gym.cryptanalysis.base.Breaker`.
    """

    name: ClassVar[str] = "rho"
    #: Bits of q (the walk's cost depends on q only).
    DEFAULT_MAX_BITS: ClassVar[int] = 64
    LIMIT_COUNTS_Q: ClassVar[bool] = True
    _REUSE: ClassVar[bool] = False

    def expected_seconds(self, group: GroupParams) -> tuple[float, float]:
        """``sqrt(pi q / 2)`` steps of :data:`SECONDS_PER_STEP`, for the first key and each later
        one (for ``"rho-multi"`` the later figure is an upper bound)."""
        per_key = math.sqrt(math.pi * group.q / 2) * SECONDS_PER_STEP
        return per_key, per_key

    def _walk(self, group: GroupParams, deadline: Deadline) -> RandomWalk:
        src = self.rng or arith.secure_random()
        return RandomWalk(self.name, group, src, self._REUSE, self.rng)

    def _precompute(self, group: GroupParams, deadline: Deadline) -> tuple[RandomWalk, Mapping[str, int]]:
        return self._walk(group, deadline), {"exponentiations": R}


class MultiLogRho(PollardRho):
    """Pollard rho for many logarithms in one group (Kuhn-Struik); registry name ``"rho-multi"``.

    Keeps every distinguished point with its logarithm, so later keys of the same group are
    cheaper (see the module docstring).

    Parameters
    ----------
    table_walks : int, default 0
        Walks from known powers of g run during the precomputation to fill the table, at most
        :data:`MAX_TABLE_WALKS` (a larger table is refused with
        :class:`~encctl_gym.errors.BreakerLimitError`; its time counts in :meth:`expected_seconds`).
    max_bits, rng
        See :class:`~encctl_gym.cryptanalysis.base.Breaker`.
    """

    name: ClassVar[str] = "rho-multi"
    _REUSE: ClassVar[bool] = True

    def __init__(self, *, table_walks: int = 0, max_bits: int | None = None, rng: RngLike = None) -> None:
        super().__init__(max_bits=max_bits, rng=rng)
        self.table_walks = check_int("table_walks", table_walks, minimum=0)
        if self.table_walks > MAX_TABLE_WALKS:
            raise BreakerLimitError(
                f"rho-multi refuses table_walks = {format_value(self.table_walks)}: each walk may keep a distinguished "
                f"point (about {_BYTES_PER_POINT} bytes), {format_bytes(self.table_walks * _BYTES_PER_POINT)} in all; "
                f"the limit is {MAX_TABLE_WALKS} (MAX_TABLE_WALKS)"
            )

    def expected_seconds(self, group: GroupParams) -> tuple[float, float]:
        first, per_key = super().expected_seconds(group)
        walk = math.sqrt(math.pi * group.q / 2) / _WALKS_PER_SQRT_Q
        return first + self.table_walks * walk * SECONDS_PER_STEP, per_key

    def _precompute(self, group: GroupParams, deadline: Deadline) -> tuple[RandomWalk, Mapping[str, int]]:
        walk = self._walk(group, deadline)
        steps = walk.add_known_walks(self.table_walks, self.rng or arith.secure_random(), deadline)
        return walk, {"exponentiations": R + self.table_walks, "group_operations": steps, "distinguished_points": len(walk.known)}
