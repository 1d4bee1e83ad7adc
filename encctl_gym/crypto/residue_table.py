"""Vectorised nearest-member quantisation for safe-prime groups.

The encoder of Definition def:ec maps ``v = round(Delta x)`` to the nearest element of the
order-q subgroup G of Z_p^*, searching ``v, v+1, v-1, v+2, v-2, ...``. For a safe prime
``p = 2q + 1`` the subgroup is the set of quadratic residues, so membership of an integer ``v``
is its Legendre symbol ``chi(v) = (v / p) = 1``; and because ``p = 3 (mod 4)``,
``chi(-v) = -chi(v)``.

``chi`` is completely multiplicative, so a table of ``chi(v)`` for ``0 <= v <= V`` needs the
Legendre symbol (one gmpy2 call) only at the primes below ``V``; composites follow from
``chi(v) = chi(spf(v)) chi(v / spf(v))`` with the smallest prime factor ``spf``. From ``chi`` a
table of offsets to the nearest member (with the encoder's tie-break: ``+d`` before ``-d``)
turns the quantisation of a whole batch into one gather. This is what lets the environment's
``crypto="ideal"`` backend and its vector environment apply *exactly* the encoder's
quantisation at numpy speed; :func:`nearest_member` of the encoder is the reference it is
tested against.
"""

from __future__ import annotations

import math
from functools import lru_cache

import gmpy2
import numpy as np

from ..errors import EncodingOverflowError, GroupError, ParameterError

__all__ = ["ResidueTable", "residue_table", "table_bytes", "PEAK_BYTES_PER_ENTRY"]


def _legendre_table(p: int, limit: int) -> np.ndarray:
    """``chi(v) = (v / p)`` for ``0 <= v <= limit`` as int8, via a multiplicative sieve."""
    spf = np.zeros(limit + 1, dtype=np.int64)
    for f in range(2, math.isqrt(limit) + 1):
        if spf[f] == 0:
            block = spf[f * f :: f]
            block[block == 0] = f
    chi = np.zeros(limit + 1, dtype=np.int8)
    if limit >= 1:
        chi[1] = 1
    is_prime = spf == 0
    is_prime[:2] = False
    primes = np.nonzero(is_prime)[0]
    mp = gmpy2.mpz(p)
    chi[primes] = np.fromiter((gmpy2.legendre(int(v), mp) for v in primes), dtype=np.int8, count=len(primes))
    comp = np.nonzero(spf)[0]
    f = spf[comp]
    rest = comp // f
    # chi(v) = chi(f) chi(v / f); every v / f < v, so ceil(log2(limit)) passes settle all values
    for _ in range(max(1, limit.bit_length())):
        new = chi[f] * chi[rest]
        if np.array_equal(new, chi[comp]):
            break
        chi[comp] = new
    return chi


class ResidueTable:
    """Nearest members of the quadratic-residue subgroup for integers in ``[-limit, limit]``.

    Parameters
    ----------
    p : int
        A safe prime (``p = 2q + 1``, so ``p = 3 mod 4``).
    limit : int
        Largest ``|v|`` that can be quantised. ``p`` must exceed ``4 limit`` so that the
        signed integers in range are distinct residues.
    """

    def __init__(self, p: int, limit: int) -> None:
        if p % 4 != 3:
            raise GroupError(f"the residue table needs a safe prime p = 3 (mod 4), got p mod 4 = {p % 4}")
        if limit < 2 or 4 * limit >= p:
            raise ParameterError(f"limit must satisfy 2 <= limit < p / 4, got {limit}")
        self.p = int(p)
        self.limit = int(limit)
        pad = 64  # room to search past the ends of the range
        chi_pos = _legendre_table(self.p, self.limit + pad)
        chi = np.concatenate([-chi_pos[:0:-1], chi_pos])  # chi(-v) = -chi(v); index v + L
        L = self.limit + pad
        member = chi == 1
        idx = np.arange(chi.size)
        # nearest member at or above / at or below every index
        up = np.where(member, idx, chi.size + L)
        up = np.minimum.accumulate(up[::-1])[::-1]
        down = np.where(member, idx, -(chi.size + L))
        down = np.maximum.accumulate(down)
        d_up, d_down = up - idx, idx - down
        offset = np.where(d_up <= d_down, d_up, -d_down)
        core = offset[pad : pad + 2 * self.limit + 1]
        if np.abs(core).max() > pad:
            raise ParameterError("a gap between residues exceeds the search pad; use a larger group")
        self._offset = core.astype(np.int16)
        self.max_shift = int(np.abs(core).max())

    def nearest(self, v: np.ndarray) -> np.ndarray:
        """Signed representative of the subgroup element nearest to each integer in ``v``.

        Raises
        ------
        EncodingOverflowError
            If some ``|v| > limit``.
        """
        v = np.asarray(v, dtype=np.int64)
        if v.size and np.abs(v).max() > self.limit:
            bad = v.flat[int(np.argmax(np.abs(v)))]
            raise EncodingOverflowError(f"value {int(bad)} lies outside the quantisation table range +-{self.limit}")
        return v + self._offset[v + self.limit]

    @property
    def offsets(self) -> np.ndarray:
        """The offset table: ``nearest(v) = v + offsets[v + limit]`` for ``|v| <= limit``."""
        return self._offset

    def offset_at(self, v: np.ndarray) -> np.ndarray:
        """Offsets to the nearest members for int64 ``v`` already known to satisfy ``|v| <= limit``."""
        return self._offset[v + self.limit]


@lru_cache(maxsize=8)
def residue_table(p: int, limit: int) -> ResidueTable:
    """A cached :class:`ResidueTable` (built once per process for each ``(p, limit)``)."""
    return ResidueTable(p, limit)


#: Peak bytes the construction of a :class:`ResidueTable` allocates per unit of ``limit`` (the
#: sieve and the search arrays; measured with tracemalloc: 121 at limits 1e5 to 4e6).
PEAK_BYTES_PER_ENTRY = 128


def table_bytes(limit: int) -> int:
    """Estimated peak bytes of building the residue table of ``limit`` (:data:`PEAK_BYTES_PER_ENTRY`)."""
    return PEAK_BYTES_PER_ENTRY * (int(limit) + 64)
