"""Vectorised nearest-member quantisation for safe-prime groups (the encoder of Definition def:ec).

The encoder maps ``v = round(Delta x)`` to the nearest element of the order-q subgroup G of
Z_p^*, searching ``v, v+1, v-1, v+2, v-2, ...``. For a safe prime ``p = 2q + 1`` the subgroup
is the set of quadratic residues, so membership of an integer ``v`` is its Legendre symbol
``chi(v) = (v / p) = 1``; and because ``p = 3 (mod 4)``, ``chi(-v) = -chi(v)``.

``chi`` is completely multiplicative, so a table of ``chi(v)`` for ``0 <= v <= V`` needs the
Legendre symbol only at the primes below ``V`` (one call of :func:`~.arith.jacobi` each, which
equals it for the verified prime p): start from ``chi = 1`` and, for every prime ``l`` with
``chi(l) = -1``, flip the sign at the multiples of each power of ``l``. From ``chi`` a table of
offsets to the nearest member (with the encoder's tie-break: ``+d`` before ``-d``) turns the
quantisation of a whole batch into one gather. This is what lets the environment's
``crypto="ideal"`` backend and its vector environment apply *exactly* the encoder's quantisation
at numpy speed;
:func:`~.encoding.nearest_member` is the reference it is tested against.

Memory is estimated before anything is allocated (:func:`residue_table_bytes`: about
``6 limit`` bytes while building, ``4 limit`` kept) and a table above ``max_bytes`` is refused
with :class:`~encctl_gym.errors.ResourceLimitError`.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np

from .._validation import check_int
from ..errors import EncodingOverflowError, GroupError, ParameterError, ResourceLimitError
from ..resources import memory_headroom
from . import arith
from .group import GroupParams

__all__ = ["ResidueTable", "residue_table", "residue_table_bytes", "DEFAULT_MAX_TABLE_BYTES"]

#: Default limit on the memory of building one table (1 GiB).
DEFAULT_MAX_TABLE_BYTES = 1 << 30

# Room searched past the ends of the range; a gap between quadratic residues longer than this
# has probability about 2**-(2 * 64) per position at the shipped sizes.
_PAD = 64
# Positions resolved per block when the offsets are searched (bounds the temporaries).
_BLOCK = 1 << 20


def residue_table_bytes(limit: int) -> int:
    """Peak memory, in bytes, of building a :class:`ResidueTable` for ``limit`` (an upper estimate).

    With ``n = limit + 65`` integers searched on each side, the build has three phases: the
    sieve of the primes below n (1 byte per integer, 8 bytes per prime: at most
    ``1.26 n / ln n`` of them) and then ``chi`` (1 byte per integer); the membership mask on
    ``[-n, n]`` made from ``chi`` (5 bytes per integer with its temporaries); the int16 offset
    table (2 bytes per ``v`` in ``[-limit, limit]``) beside the mask, plus per-block
    temporaries (48 bytes per position of a block of 2**20). The finished table keeps the
    offsets only (``4 limit + 2`` bytes).
    """
    limit = check_int("limit", limit, minimum=0)
    n = limit + _PAD + 1
    primes = n * 126 // int(100 * max(1.0, math.log(n))) + 64  # integers: no float overflow
    sieve_phase = n + 8 * primes + 64 * min(primes, _BLOCK)  # + one chunk of the prime list
    mask_phase = 5 * n
    offset_phase = 2 * n + 2 * (2 * limit + 1) + 48 * _BLOCK
    return max(sieve_phase, mask_phase, offset_phase)


def _legendre_table(p: int, n: int) -> np.ndarray:
    """``chi(v) = (v / p)`` for ``0 <= v < n`` as int8 (``chi(0) = 0``), multiplicatively."""
    sieve = np.ones(n, dtype=bool)
    sieve[:2] = False
    for f in range(2, math.isqrt(n - 1) + 1):
        if sieve[f]:
            sieve[f * f :: f] = False
    primes = np.flatnonzero(sieve)
    del sieve
    chi = np.ones(n, dtype=np.int8)
    chi[0] = 0
    mp = arith.mpz(p)
    for start in range(0, primes.size, _BLOCK):
        for ell in primes[start : start + _BLOCK].tolist():
            if arith.jacobi(ell, mp) == -1:  # the Legendre symbol: p is a verified prime
                power = ell
                while power < n:  # chi(ell^k m) = (-1)^k chi(m): flip once per power dividing v
                    chi[power::power] *= -1
                    power *= ell
    return chi


def _safe_prime(group_or_p: GroupParams | int) -> int:
    if isinstance(group_or_p, GroupParams):
        if not group_or_p.is_safe_prime:
            raise GroupError(f"the residue table needs a safe-prime group (p = 2q + 1), got cofactor {group_or_p.cofactor}")
        return group_or_p.verify().p
    p = check_int("p", group_or_p, minimum=5)
    if p % 4 != 3:  # p = 2q + 1 with q odd
        raise GroupError(f"the residue table needs a safe prime p = 2q + 1, got p = {arith.format_int(p)}")
    try:  # the group's own checks: size, primality of p and q (4 = 2^2 has order q)
        return GroupParams(p, (p - 1) // 2, 4).verify().p
    except GroupError as exc:
        raise GroupError(f"the residue table needs a safe prime p = 2q + 1: {exc}") from None


class ResidueTable:
    """Nearest members of the quadratic-residue subgroup for integers in ``[-limit, limit]``.

    Parameters
    ----------
    p : GroupParams or int
        A safe-prime group, or its safe prime ``p = 2q + 1`` (checked: p and q prime).
    limit : int
        Largest ``|v|`` that can be quantised. ``p`` must exceed ``4 limit`` so that the
        signed integers in range are distinct residues.
    max_bytes : int, default :data:`DEFAULT_MAX_TABLE_BYTES`
        Limit on :func:`residue_table_bytes`, checked before anything is allocated.

    Attributes
    ----------
    max_shift : int
        The largest ``|offset|`` in the table.

    Raises
    ------
    GroupError
        If ``p`` is not a safe prime (the table computes quadratic residues, which form G only
        for safe primes).
    ParameterError
        If ``limit`` is out of range, or a gap between residues exceeds the search pad.
    ResourceLimitError
        If building the table would need more than ``max_bytes``, or more than the address space
        the process may still map under a limit (:func:`encctl_gym.resources.memory_headroom`);
        the message gives both.
    """

    def __init__(self, p: GroupParams | int, limit: int, max_bytes: int = DEFAULT_MAX_TABLE_BYTES) -> None:
        limit = check_int("limit", limit)
        max_bytes = check_int("max_bytes", max_bytes, minimum=1)
        need = residue_table_bytes(max(limit, 0))
        room = memory_headroom()
        if need > max_bytes or (room is not None and need > room):
            bound, name = (
                (max_bytes, "max_bytes")
                if need > max_bytes or room is None
                else (room, "the address space left under this process's limit")
            )
            raise ResourceLimitError(
                f"a residue table for |v| <= limit = {arith.format_int(limit)} needs about "
                f"{arith.format_int(need >> 20)} MiB to build, more than {name} = "
                f"{bound >> 20} MiB; use a smaller Delta or a smaller declared range "
                "(x_bound), or raise max_bytes"
            )
        p = _safe_prime(p)
        if limit < 2 or 4 * limit >= p:
            raise ParameterError(f"limit must satisfy 2 <= limit < p / 4, got {limit}")
        self.p = int(p)
        self.limit = int(limit)
        n = self.limit + _PAD + 1
        chi_pos = _legendre_table(self.p, n)
        # member[i] for v = i - (n - 1), i.e. v in [-(limit + pad), limit + pad]; chi(-v) = -chi(v)
        member = np.concatenate([chi_pos[:0:-1] == -1, chi_pos == 1])
        del chi_pos
        centre = n - 1
        size = 2 * self.limit + 1
        offset = np.zeros(size, dtype=np.int16)
        order = [0] + [d for k in range(1, _PAD + 1) for d in (k, -k)]
        for start in range(0, size, _BLOCK):
            todo = np.arange(start, min(start + _BLOCK, size), dtype=np.int64)
            base = todo + (centre - self.limit)  # index of v = todo - limit in `member`
            for d in order:
                hit = member[base + d]
                offset[todo[hit]] = d
                keep = ~hit
                todo, base = todo[keep], base[keep]
                if not todo.size:
                    break
            if todo.size:
                raise ParameterError("a gap between residues exceeds the search pad; use a larger group")
        self._offset = offset
        self.max_shift = int(np.abs(offset).max())

    def nearest(self, v: Any) -> np.ndarray:
        """Signed representative of the subgroup element nearest to each integer in ``v``.

        Raises
        ------
        ParameterError
            If ``v`` is not an integer array (a float would be truncated silently).
        EncodingOverflowError
            If some ``|v| > limit``.
        """
        arr = np.asarray(v)
        if arr.dtype.kind not in "iu":
            raise ParameterError(f"v must be an integer array, got dtype {arr.dtype}")
        arr = arr.astype(np.int64, copy=False)
        if arr.size and np.abs(arr).max() > self.limit:
            bad = arr.flat[int(np.argmax(np.abs(arr)))]
            raise EncodingOverflowError(f"value {int(bad)} lies outside the quantisation table range +-{self.limit}")
        return arr + self._offset[arr + self.limit]

    @property
    def offsets(self) -> np.ndarray:
        """The offset table: ``nearest(v) = v + offsets[v + limit]`` for ``|v| <= limit``."""
        return self._offset

    def offset_at(self, v: np.ndarray) -> np.ndarray:
        """Offsets to the nearest members for int64 ``v`` already known to satisfy ``|v| <= limit``."""
        return self._offset[v + self.limit]


@lru_cache(maxsize=8)
def residue_table(p: GroupParams | int, limit: int, max_bytes: int = DEFAULT_MAX_TABLE_BYTES) -> ResidueTable:
    """A cached :class:`ResidueTable` (built once per process for each ``(p, limit)``)."""
    return ResidueTable(p, limit, max_bytes)
