"""The cost of breaking the keys of one group (:class:`KeyBreakCost`) and the one base of every
deciphering-cost model (:class:`CostModel`: ``break_cost``, ``describe``, and the shared search
for the smallest safe key length).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from ..._validation import check_int, format_value
from ...errors import ModelRangeError
from ..exact import log2_fraction
from .formulas import GNFS_MIN_KEY_LENGTH, MAX_KEY_LENGTH

__all__ = ["KeyBreakCost", "CostModel"]


@dataclass(frozen=True)
class KeyBreakCost:
    """Operations to break the keys of one group under a model.

    Attributes
    ----------
    model : str
        Name of the model that produced it.
    first : Fraction
        Operations for the first key (it carries any precomputation).
    next : Fraction
        Operations for each further key of the same group.
    key_length : int or None
        Bits of p (``None`` for an explicit security parameter).
    security_parameter : int, float or None
        ``lam`` of the paper model (``first = next = 2^lam``).
    precomputation : Fraction or None
        The precomputation part of ``first`` (precomputation model).
    gnfs_correction : float
        Correction applied to the GNFS formula (bits).
    """

    model: str
    first: Fraction
    next: Fraction
    key_length: int | None = None
    security_parameter: int | float | None = None
    precomputation: Fraction | None = None
    gnfs_correction: float = 0.0

    @property
    def first_bits(self) -> float:
        """``log2`` of the first key's operations."""
        return log2_fraction(self.first)

    @property
    def next_bits(self) -> float:
        """``log2`` of a further key's operations."""
        return log2_fraction(self.next)

    def operations(self, keys: int) -> Fraction:
        """Operations to break ``keys`` keys of the group: 0, or ``first + (keys - 1) next``."""
        keys = check_int("keys", keys, 0)
        return Fraction(0) if keys == 0 else self.first + (keys - 1) * self.next

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (costs as log2 bits)."""
        return {
            "model": self.model,
            "key_length": self.key_length,
            "security_parameter": self.security_parameter,
            "first_key_bits": self.first_bits,
            "next_key_bits": self.next_bits,
            "precomputation_bits": None if self.precomputation is None else log2_fraction(self.precomputation),
            "gnfs_correction": self.gnfs_correction,
        }


class CostModel(ABC):
    """Base of the shipped models: the key-length search shared by all of them."""

    name: str = ""
    key_length_range: tuple[int, int] = (GNFS_MIN_KEY_LENGTH, MAX_KEY_LENGTH)

    @abstractmethod
    def break_cost(self, key_length: int) -> KeyBreakCost:
        """The cost of breaking keys of a ``key_length``-bit group."""

    @abstractmethod
    def describe(self) -> dict[str, Any]:
        """The model's name, formula, parameters and sources (JSON-ready)."""

    def minimum_key_length(self, keys: int, budget: Fraction) -> int:
        """Smallest ``k`` in the model's range with ``operations(keys) > budget`` (binary search;
        every shipped model's cost is nondecreasing in ``k``).

        Parameters
        ----------
        keys : int
            Keys the adversary must break (>= 1).
        budget : Fraction
            Operations it can perform within the defense period (``Upsilon tau_c``).

        Returns
        -------
        int

        Raises
        ------
        ModelRangeError
            If no key length of the range suffices, or if even the smallest one does (the
            answer then lies below the range where the model holds).
        """
        keys = check_int("keys", keys, 1)
        lo, hi = self.key_length_range

        def safe(k: int) -> bool:
            return self.break_cost(k).operations(keys) > budget

        if not safe(hi):
            raise ModelRangeError(
                f"under the {self.name} model no key length up to {hi} bits makes {format_value(keys)} key(s) cost more than "
                f"2^{log2_fraction(budget):.3f} operations ({format_value(keys)} key(s) at {hi} bits cost "
                f"2^{log2_fraction(self.break_cost(hi).operations(keys)):.3f})"
            )
        if safe(lo):
            raise ModelRangeError(
                f"under the {self.name} model even the smallest key length of its range ({lo} bits) makes {format_value(keys)} "
                f"key(s) cost more than 2^{log2_fraction(budget):.3f} operations; the answer lies below {lo} bits, "
                "where the model does not hold (any key of at least that length meets the requirement)"
            )
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if safe(mid):
                hi = mid
            else:
                lo = mid
        return hi
