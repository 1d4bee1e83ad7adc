"""The shipped deciphering-cost models (``paper``, ``precomputation``, ``generic``; see
:mod:`encctl_gym.security.cost_models`) and eq:opt_key's :func:`minimum_key_length`.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

from ..._validation import check_int, format_value
from ...errors import ConfigError, ModelRangeError
from ..exact import pow2
from ..records import RatioPoint, RecordSet, default_records, ratio_points
from .base import CostModel, KeyBreakCost
from .formulas import (
    GENERIC_MIN_KEY_LENGTH,
    GNFS_MIN_KEY_LENGTH,
    MAX_KEY_LENGTH,
    _gnfs_bits,
    check_gnfs_correction,
    check_security_parameter,
    gnfs_log2_complexity,
    paper_security_parameter,
    pollard_rho_log2_operations,
)

__all__ = ["PaperModel", "PrecomputationModel", "GenericModel", "minimum_key_length"]


class PaperModel(CostModel):
    """Definition def:sdt and eq:opt_key: every key costs ``2^lam = Omega(k) 2^-c`` operations.

    The design (:meth:`minimum_key_length`) is the paper's two steps: the integer ``lam*`` of
    Theorem thm:opt_sec, then the smallest ``k`` with ``log2 Omega(k) - c >= lam*`` (eq:opt_key).

    Parameters
    ----------
    gnfs_correction : float, default 0.0
        o(1) correction of the GNFS formula in bits (0: the paper's numbers).
    """

    name = "paper"
    key_length_range = (GNFS_MIN_KEY_LENGTH, MAX_KEY_LENGTH)

    def __init__(self, gnfs_correction: Any = 0.0) -> None:
        self.gnfs_correction = check_gnfs_correction(gnfs_correction)

    def security_parameter_of_key_length(self, key_length: int) -> float:
        """``lam = log2 Omega(k) - c`` of a ``k``-bit key (Definition def:bit_sec under the GNFS)."""
        return float(gnfs_log2_complexity(key_length, self.gnfs_correction))

    def break_cost(self, key_length: int) -> KeyBreakCost:
        lam = self.security_parameter_of_key_length(key_length)
        c = pow2(lam)
        return KeyBreakCost(
            "paper", c, c, key_length=int(key_length), security_parameter=lam, gnfs_correction=self.gnfs_correction
        )

    def cost_of_security_parameter(self, lam: Any) -> KeyBreakCost:
        """The cost ``2^lam`` per key for an explicit security parameter (exact for integer ``lam``)."""
        lam_v = check_security_parameter(lam)
        c = pow2(lam_v)
        return KeyBreakCost("paper", c, c, security_parameter=lam_v, gnfs_correction=self.gnfs_correction)

    def security_parameter_range(self) -> tuple[float, float]:
        """``(low, high)``: :meth:`key_length_for_security_parameter` answers for ``low < lam <= high``,
        the formula's ``log2 Omega(k) - c`` at the ends of :attr:`key_length_range` (eq:opt_key)."""
        lo, hi = self.key_length_range
        return self.security_parameter_of_key_length(lo), self.security_parameter_of_key_length(hi)

    def key_length_for_security_parameter(self, lam: Any) -> int:
        """eq:opt_key: the smallest ``k`` with ``log2 Omega(k) - c >= lam``.

        Values are compared in double precision (ties within ~1e-12 bit are not resolved
        exactly; the paper's example ``lam = 74`` has margin 0.004 bit at ``k = 712``).

        Raises
        ------
        ModelRangeError
            If ``lam`` is below the formula's value at 40 bits (every key of the range meets it;
            below the range the formula does not hold) or above its value at 65536 bits.
        """
        lam_v = float(check_security_parameter(lam))
        lo, hi = self.key_length_range
        if self.security_parameter_of_key_length(lo) >= lam_v:
            raise ModelRangeError(
                f"security parameter lam = {format_value(lam)} is at most {self.security_parameter_of_key_length(lo):.3f} "
                f"bits, the GNFS cost of the smallest key length ({lo} bits) where the formula holds; every key "
                f"of {lo} bits or more meets it (below ~38 bits Pollard rho is faster than the formula)"
            )
        if self.security_parameter_of_key_length(hi) < lam_v:
            raise ModelRangeError(
                f"security parameter lam = {format_value(lam)} has no key length under the GNFS formula: keys end at "
                f"{hi} bits (MAX_KEY_LENGTH), which reach lam <= log2 Omega({hi}) - c = "
                f"{self.security_parameter_of_key_length(hi):.3f} bits"
            )
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if self.security_parameter_of_key_length(mid) >= lam_v:
                hi = mid
            else:
                lo = mid
        return hi

    def minimum_key_length(self, keys: int, budget: Fraction) -> int:
        """Theorem thm:opt_sec then eq:opt_key: ``k*`` for ``lam* = floor(log2(budget / keys)) + 1``."""
        return self.key_length_for_security_parameter(paper_security_parameter(keys, budget))

    def describe(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "formula": "each key 2^lam, lam = log2 Omega(k) - c (def:sdt, eq:opt_key); k* via the integer lam* of thm:opt_sec",
            "gnfs_correction": self.gnfs_correction,
            "key_length_range": list(self.key_length_range),
        }


class PrecomputationModel(CostModel):
    """Index calculus: one precomputation per group, then a cheap descent per key.

    ``C_pre(k) = Omega(k) 2^-c``; a further key costs ``C_key(k) = max(1, C_pre(k) 2^-r(k))``; the
    first key costs ``C_pre + C_key``, so ``tau(N) = (C_pre + N C_key) / Upsilon`` for ``N``
    independent keys of one group.

    Parameters
    ----------
    gnfs_correction : float, default 0.0
        o(1) correction of the GNFS formula in bits.
    calibration : sequence of RatioPoint or (key_length, ratio_bits), or RecordSet, optional
        Where ``r(k)`` is known; linear in ``k`` between points, constant beyond. Default: the
        shipped records marked ``use_for_ratio`` (the 768-bit record, ``r = 19.88`` bits).

    Raises
    ------
    ConfigError
        If the calibration points are not strictly increasing in key length, or imply a per-key
        cost that decreases with the key length (a ratio rising faster than the GNFS cost).
    """

    name = "precomputation"
    key_length_range = (GNFS_MIN_KEY_LENGTH, MAX_KEY_LENGTH)

    def __init__(self, gnfs_correction: Any = 0.0, calibration: Any = None) -> None:
        self.gnfs_correction = check_gnfs_correction(gnfs_correction)
        if calibration is None:
            calibration = default_records()
        self.records: RecordSet | None = calibration if isinstance(calibration, RecordSet) else None
        pts = calibration.ratio_points if isinstance(calibration, RecordSet) else calibration
        self.points: tuple[RatioPoint, ...] = ratio_points(pts)
        ks = [p.key_length for p in self.points]
        if ks[0] < GNFS_MIN_KEY_LENGTH or ks[-1] > MAX_KEY_LENGTH:
            raise ConfigError(f"calibration key lengths must lie in {GNFS_MIN_KEY_LENGTH} ... {MAX_KEY_LENGTH}, got {ks}")
        for a, b in zip(self.points, self.points[1:]):
            slope = (b.ratio_bits - a.ratio_bits) / (b.key_length - a.key_length)
            gnfs_slope = float(_gnfs_bits(float(b.key_length)) - _gnfs_bits(float(b.key_length - 1)))
            if slope > gnfs_slope:
                raise ConfigError(
                    f"calibration points ({a.key_length}, {a.ratio_bits:g}) and ({b.key_length}, {b.ratio_bits:g}) make the "
                    f"ratio grow by {slope:.4g} bits per key bit, faster than the GNFS cost ({gnfs_slope:.4g}): the per-key "
                    "cost would fall as keys get longer"
                )

    def ratio_bits(self, key_length: int) -> float:
        """``r(k)``: how many bits cheaper a further key is than the precomputation."""
        k = check_int("key_length", key_length)
        pts = self.points
        if k <= pts[0].key_length:
            return pts[0].ratio_bits
        if k >= pts[-1].key_length:
            return pts[-1].ratio_bits
        for a, b in zip(pts, pts[1:]):
            if a.key_length <= k <= b.key_length:
                t = (k - a.key_length) / (b.key_length - a.key_length)
                return a.ratio_bits + t * (b.ratio_bits - a.ratio_bits)
        raise AssertionError("unreachable")  # pragma: no cover

    def break_cost(self, key_length: int) -> KeyBreakCost:
        pre_bits = float(gnfs_log2_complexity(key_length, self.gnfs_correction))
        pre = pow2(pre_bits)
        key = max(Fraction(1), pow2(pre_bits - self.ratio_bits(key_length)))
        return KeyBreakCost(
            "precomputation", pre + key, key, key_length=int(key_length), precomputation=pre, gnfs_correction=self.gnfs_correction
        )

    def describe(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "formula": "first key C_pre + C_key, each further key C_key; C_pre = Omega(k) 2^-c, C_key = max(1, C_pre 2^-r(k))",
            "gnfs_correction": self.gnfs_correction,
            "key_length_range": list(self.key_length_range),
            "calibration": [{"key_length": p.key_length, "ratio_bits": p.ratio_bits, "source": p.source} for p in self.points],
        }


class GenericModel(CostModel):
    """Pollard rho in the order-q subgroup: ``sqrt(pi q / 2)`` group operations for every key.

    One group operation counts as one operation (as ``2^lam`` does in def:sdt). This is what a
    group without index calculus would cost; for a prime field it overstates the security,
    since the GNFS is faster at every key length of the range.
    """

    name = "generic"
    key_length_range = (GENERIC_MIN_KEY_LENGTH, MAX_KEY_LENGTH)

    def break_cost(self, key_length: int) -> KeyBreakCost:
        c = pow2(float(pollard_rho_log2_operations(key_length)))
        return KeyBreakCost("generic", c, c, key_length=int(key_length))

    def describe(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "formula": "each key sqrt(pi q / 2) group operations, q = 2^(k-2) (smallest order-q of a k-bit safe prime)",
            "key_length_range": list(self.key_length_range),
        }


def minimum_key_length(lam: Any, gnfs_correction: Any = 0.0) -> int:
    """``k*`` of eq:opt_key: the smallest ``k`` with ``Omega(k) 2^-c >= 2^lam``.

    ``log2 Omega`` increases with ``k``, so this is a binary search over ``[40, 65536]``; values
    are compared in double precision (the paper's example ``lam = 74`` has margin 0.004 bit at
    ``k = 712``).

    Parameters
    ----------
    lam : int or float
        Security parameter in bits. The key lengths of the formula's range, 40 to 65536 bits
        (:data:`MAX_KEY_LENGTH`), reach ``log2 Omega(40) - c < lam <= log2 Omega(65536) - c``,
        i.e. ``18.70 - c < lam <= 481.38 - c`` bits
        (:meth:`PaperModel.security_parameter_range`); a larger ``lam``, though a valid security
        parameter elsewhere (up to :data:`LAMBDA_MAX` = 2048), has no key length here.
    gnfs_correction : float, default 0.0
        o(1) correction in bits.

    Returns
    -------
    int

    Raises
    ------
    ModelRangeError
        If ``lam`` lies outside the range the formula covers (see
        :meth:`PaperModel.key_length_for_security_parameter`).
    """
    return PaperModel(gnfs_correction).key_length_for_security_parameter(lam)
