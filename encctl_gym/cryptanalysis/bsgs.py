"""Baby-step giant-step (Shanks) in the order-q subgroup G: about 2 sqrt(q) group operations.

With ``m = ceil(sqrt(q))`` every exponent is ``s = i m + j`` with ``0 <= i, j < m``, and
``h (g^-m)^i = g^j``. The *baby steps* ``g^j`` (``j < m``) depend only on the group: they are
the precomputation, a sorted table of m residues (numpy, 16 bytes per entry). Each key then
takes *giant steps* ``h g^(-m i)`` until one lands in the table: at most m, on average m / 2.
So the first key of a group costs about 1.5 m group operations, each later one about m / 2:
even the oldest generic attack amortises over a dynamic-key sequence (Example ex:dyn_elgamal),
with ``T_1 / T_first`` near 1/3.

The table stores the low 64 bits of each residue (the residue itself when p < 2^64), so p may
be of any size; a match of the low bits is checked with ``g^s = h`` before it is returned (for
p >= 2^64 two residues may share their low bits). The cost depends on q only, so the size limit
counts the bits of q (by default 56, where the table would hold 2^28 entries, 4 GB: the
table limit ``max_table`` refuses it first).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar

import gmpy2
import numpy as np

from .._validation import check_int
from ..crypto.arith import RandomSource, RngLike, format_int
from ..crypto.group import GroupParams
from ..errors import BreakerError, BreakerLimitError
from .base import Breaker, Deadline, Precomputation, format_seconds

__all__ = ["BabyStepGiantStep", "BabyStepTable"]

#: Seconds per baby or giant step (one multiplication in G through gmpy2 and the table work),
#: measured on this machine (2 cores, Python 3.11, gmpy2 2.3) with
#: ``python benchmarks/bench_cryptanalysis.py``.
SECONDS_PER_STEP = 3.0e-7

_CHUNK = 1 << 14


_LOW = (1 << 64) - 1


def _powers(y: Any, step: Any, p: Any, n: int) -> tuple[np.ndarray, Any]:
    """The low 64 bits of ``y, y step, ..., y step^(n-1)`` modulo p (uint64), and ``y step^n``:
    the baby steps of the table, or the giant steps of a key."""
    out: list[Any] = []
    append = out.append
    for _ in range(n):
        append(int(y) & _LOW)
        y = y * step % p
    return np.array(out, dtype=np.uint64), y


class BabyStepTable(Precomputation):
    """The baby steps ``g^j`` (``0 <= j < m``) sorted by residue, and ``g^-m``.

    Attributes
    ----------
    m : int
        Number of baby steps.
    residues, exponents : numpy.ndarray
        The low 64 bits of ``g^j mod p`` (uint64, sorted) and the matching ``j`` (int64).
    giant : int
        ``g^-m mod p``.
    """

    def __init__(self, group: GroupParams, m: int, residues: np.ndarray, exponents: np.ndarray, rng: RandomSource | None) -> None:
        super().__init__(BabyStepGiantStep.name, group, rng)
        self.m = m
        self.residues = residues
        self.exponents = exponents
        self.giant = int(gmpy2.powmod(group.g, -m, group.p))

    def _solve(self, h: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int], str]:
        p, q, m = gmpy2.mpz(self.group.p), self.group.q, self.m
        giant = gmpy2.mpz(self.giant)
        y = gmpy2.mpz(h)
        steps = 0
        n_giant = -(-q // m)  # i ranges over [0, ceil(q / m))
        table, last = self.residues, len(self.residues) - 1
        while steps < n_giant:
            n = min(_CHUNK, n_giant - steps)
            values, y = _powers(y, giant, p, n)
            pos = np.minimum(np.searchsorted(table, values), last)
            for hit in np.flatnonzero(table[pos] == values):
                i = steps + int(hit)
                # Every baby step with these low bits (one, unless p >= 2^64 and two share them).
                for k in range(int(pos[hit]), len(table)):
                    if table[k] != values[hit]:
                        break
                    s = (i * m + int(self.exponents[k])) % q
                    if gmpy2.powmod(self.group.g, s, p) == h:
                        return s, {"group_operations": i + 1, "table_lookups": i + 1}, ""
            steps += n
            deadline.check()
        raise BreakerError(f"bsgs: no giant step met the table for h = {format_int(h)} (is h in <g>?)")


class BabyStepGiantStep(Breaker):
    """Shanks's baby-step giant-step; registry name ``"bsgs"`` (see the module docstring).

    Parameters
    ----------
    baby_steps : int, optional
        Table size m (default ``ceil(sqrt(q))``; a larger table makes later keys cheaper).
    max_table : int, default 2**26
        Largest table accepted (memory: 16 bytes per entry); a larger one is refused.
    max_bits : int, optional
        The largest bit length of q accepted (default 56); p may be larger.
    rng
        See :class:`~encctl_gym.cryptanalysis.base.Breaker`.
    """

    name: ClassVar[str] = "bsgs"
    #: Bits of q.
    DEFAULT_MAX_BITS: ClassVar[int] = 56
    LIMIT_COUNTS_Q: ClassVar[bool] = True

    def __init__(
        self, *, baby_steps: int | None = None, max_table: int = 1 << 26, max_bits: int | None = None, rng: RngLike = None
    ) -> None:
        super().__init__(max_bits=max_bits, rng=rng)
        self.baby_steps = None if baby_steps is None else check_int("baby_steps", baby_steps, minimum=1)
        self.max_table = check_int("max_table", max_table, minimum=1)

    def table_size(self, group: GroupParams) -> int:
        """The number m of baby steps for this group."""
        return min(self.baby_steps or math.isqrt(group.q - 1) + 1, group.q)

    def expected_seconds(self, group: GroupParams) -> tuple[float, float]:
        """``((m + q / (2m)) c, q / (2m) c)`` with c = :data:`SECONDS_PER_STEP`."""
        m = self.table_size(group)
        giant = group.q / (2 * m)
        return (m + giant) * SECONDS_PER_STEP, giant * SECONDS_PER_STEP

    def check_feasible(self, group: GroupParams) -> None:
        """The size limit of :class:`Breaker`, and the table's memory limit (:attr:`max_table`)."""
        super().check_feasible(group)
        m = self.table_size(group)
        if m > self.max_table:
            first, _ = self.expected_seconds(group)
            raise BreakerLimitError(
                f"bsgs refuses a table of {m} baby steps ({16 * m / 2**30:.2f} GiB) for this {group.bits}-bit "
                f"group: the limit is max_table = {self.max_table}; expected time about {format_seconds(first)}"
            )

    def _precompute(self, group: GroupParams, deadline: Deadline) -> tuple[BabyStepTable, Mapping[str, int]]:
        m = self.table_size(group)
        p, g = gmpy2.mpz(group.p), gmpy2.mpz(group.g)
        residues = np.empty(m, dtype=np.uint64)
        y = gmpy2.mpz(1)
        done = 0
        while done < m:
            n = min(_CHUNK, m - done)
            residues[done : done + n], y = _powers(y, g, p, n)
            done += n
            deadline.check()
        order = np.argsort(residues, kind="stable")
        table = BabyStepTable(group, m, residues[order], order.astype(np.int64), self.rng)
        return table, {"group_operations": m}
