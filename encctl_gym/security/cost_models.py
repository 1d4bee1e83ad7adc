"""Deciphering-cost models: what breaking the keys of one group costs (def:sdt, eq:opt_key, beyond).

Definition def:sdt charges ``2^lambda`` operations for every key, and eq:opt_key turns
``lambda`` into a key length through the GNFS running time
``Omega(k) = exp((64/9)^(1/3) (ln 2^k)^(1/3) (ln ln 2^k)^(2/3))``. Real attacks on a prime field
differ in two ways, and each model of this module makes one set of assumptions explicit. A
model maps a key length ``k`` (bits of p) to a :class:`KeyBreakCost`: the operations for the
*first* key of a group and for *each further* key of the same group (dynamic-key ElGamal changes
the secret key every period but never p). :mod:`~encctl_gym.security.deciphering` turns that
into the sample deciphering time ``tau(N)``; :mod:`~encctl_gym.security.key_length` into the
smallest safe key length.

==================  ===============================================  =========================
model               first key / each further key (operations)        valid key lengths
==================  ===============================================  =========================
``paper``           ``2^lam`` / ``2^lam``, ``lam = log2 Omega(k) - c``  40 ... 65536 bits
                    (Definition def:sdt, eq:opt_key); an explicit
                    integer ``lam`` is exact, as in the paper
``precomputation``  ``C_pre + C_key`` / ``C_key``, ``C_pre = Omega(k)   40 ... 65536 bits
                    2^-c`` (the index-calculus precomputation depends
                    on p only), ``C_key = C_pre 2^-r(k)``
``generic``         ``sqrt(pi q / 2)`` / the same (Pollard rho in the   16 ... 65536 bits
                    order-q subgroup, q = (p-1)/2 >= 2^(k-2))
==================  ===============================================  =========================

``c`` is the optional o(1) correction of the GNFS formula in bits (``gnfs_correction``, default 0:
the paper's numbers). The formula drops the o(1) term of ``L_p[1/3, (64/9)^(1/3) + o(1)]``;
against the records it is 8 to 12 bits too high (``security/data/deciphering_records.json``:
DLP-768 8.2, DLP-240 10.2, RSA-250 11.8 bits, counting one clock cycle as one operation). The
documented alternative is ``c = 11.91`` (:data:`GUILLEVIC_CORRECTION`, after A. Guillevic, as
CryptographicEstimators uses it), which puts the formula within 8 bits of every row of NIST SP
800-57 (see :func:`~encctl_gym.security.records.nist_key_length`).

``r(k)`` is the ratio (in bits) between the precomputation and one further logarithm,
calibrated on the records with both phases in core time (by default the 768-bit record: 5300
core-years, then 2 core-days per logarithm, ``r = 19.88``), linear between calibration points
and constant beyond them. A further key costs at least one operation.

Valid ranges (outside them every function raises :class:`~encctl_gym.errors.ModelRangeError`):

* Key lengths of the GNFS models start at 40 bits: below about 38 bits Pollard rho in the order-q
  subgroup (``sqrt(pi 2^(k-2) / 2)`` operations) is cheaper than the formula's value, so the
  formula is no longer the fastest known attack that eq:opt_key asks for (:data:`GNFS_MIN_KEY_LENGTH`).
  The generic model holds from 16 bits (a subgroup of at least 2^14 elements). Key lengths end at
  65536 bits (:data:`MAX_KEY_LENGTH`), four times NIST's largest (15360): enough for every
  security level up to 481 bits under the GNFS formula, and a bound before any code generates a
  group.
* A security parameter lies in ``[1, 2048]`` bits (:data:`LAMBDA_MAX`): ``2^lam`` is then an exact
  integer of at most 2049 bits, and Theorem thm:opt_sec never asks for more, since ``Upsilon``
  and ``tau_c`` are finite float64 numbers (``Upsilon tau_c < 2^2048``).
* A GNFS correction is finite, ``>= 0`` and below ``log2 Omega(40) = 18.70`` bits, so that the
  corrected cost stays above one operation over the whole range.

The registry :data:`DECIPHERING_MODELS` maps a name to its class; :func:`deciphering_model`
builds one by name (the ``--cost-model`` option of ``encctl-gym design``).
"""

from __future__ import annotations

import math
import numbers
from abc import ABC, abstractmethod
from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Protocol, runtime_checkable

import numpy as np

from .._validation import check_int, check_positive, format_value
from ..errors import ConfigError, ModelRangeError, ParameterError
from .exact import floor_log2, log2_fraction, pow2
from .records import RatioPoint, RecordSet, default_records, ratio_points

__all__ = [
    "GNFS_CONSTANT",
    "GNFS_MIN_KEY_LENGTH",
    "GENERIC_MIN_KEY_LENGTH",
    "MAX_KEY_LENGTH",
    "LAMBDA_MAX",
    "GUILLEVIC_CORRECTION",
    "gnfs_log2_complexity",
    "gnfs_complexity",
    "pollard_rho_log2_operations",
    "check_gnfs_correction",
    "check_security_parameter",
    "paper_security_parameter",
    "KeyBreakCost",
    "DecipheringModel",
    "CostModel",
    "PaperModel",
    "PrecomputationModel",
    "GenericModel",
    "DECIPHERING_MODELS",
    "deciphering_model",
    "bit_security_of_key_length",
    "minimum_key_length",
]

#: The constant (64/9)^(1/3) of the GNFS running time (eq:opt_key).
GNFS_CONSTANT: float = (64.0 / 9.0) ** (1.0 / 3.0)
#: Smallest key length of the GNFS models (see the module docstring for why).
GNFS_MIN_KEY_LENGTH: int = 40
#: Smallest key length of the generic model.
GENERIC_MIN_KEY_LENGTH: int = 16
#: Largest key length of every model.
MAX_KEY_LENGTH: int = 65536
#: Largest security parameter (bits).
LAMBDA_MAX: int = 2048
#: The o(1) correction of the GNFS cost after Guillevic, as CryptographicEstimators uses it (bits).
GUILLEVIC_CORRECTION: float = default_records().corrections["guillevic"][0]

_LN2 = math.log(2.0)


# --------------------------------------------------------------------------- the formulas
def _key_lengths(k: Any, lo: int, hi: int, what: str) -> tuple[np.ndarray, bool]:
    if np.ndim(k) == 0:
        kk = check_int("key length k", k.item() if isinstance(k, np.ndarray) else k)
        if not lo <= kk <= hi:
            raise ModelRangeError(f"key length k = {format_value(kk)} is outside the range {lo} ... {hi} bits where {what} holds")
        return np.asarray(float(kk)), True
    try:
        arr = np.asarray(k, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"key lengths k must be integers, got {format_value(k)}") from None
    if arr.size == 0 or not np.all(np.isfinite(arr)) or not np.all(arr == np.round(arr)):
        raise ParameterError(f"key lengths k must be integers, got {format_value(k)}")
    if np.any(arr < lo) or np.any(arr > hi):
        raise ModelRangeError(
            f"key lengths must lie in {lo} ... {hi} bits where {what} holds, got min {arr.min():g}, max {arr.max():g}"
        )
    return arr, False


def check_gnfs_correction(correction: Any) -> float:
    """Validate a GNFS o(1) correction in bits: finite, ``>= 0`` and below ``log2 Omega(40)``.

    Raises
    ------
    ParameterError
        Naming the value.
    """
    if isinstance(correction, bool) or not isinstance(correction, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"gnfs_correction must be a number of bits, got {format_value(correction)}")
    try:
        c = float(correction)
    except OverflowError:  # an integer beyond the float range
        c = math.inf
    if not math.isfinite(c) or c < 0:
        raise ParameterError(f"gnfs_correction must be finite and >= 0 bits, got {format_value(correction)}")
    top = _gnfs_bits(float(GNFS_MIN_KEY_LENGTH))
    if c >= top:
        raise ParameterError(
            f"gnfs_correction must be below {top:.3f} bits (the formula's value at {GNFS_MIN_KEY_LENGTH} bits), "
            f"got {format_value(correction)}"
        )
    return c


def _gnfs_bits(kf: Any) -> Any:
    ln_n = kf * _LN2
    return GNFS_CONSTANT * np.cbrt(ln_n) * np.cbrt(np.log(ln_n) ** 2) / _LN2


def gnfs_log2_complexity(k: Any, correction: Any = 0.0) -> float | np.ndarray:
    """``log2 Omega(k) - correction``: bits of work of the general number field sieve (eq:opt_key).

    ``Omega(k) = exp((64/9)^(1/3) (ln 2^k)^(1/3) (ln ln 2^k)^(2/3))``, evaluated in double
    precision through logarithms (no overflow).

    Parameters
    ----------
    k : int or array_like of int
        Key (modulus) bit length in ``[40, 65536]``.
    correction : float, default 0.0
        o(1) correction in bits (:func:`check_gnfs_correction`).

    Returns
    -------
    float or ndarray

    Raises
    ------
    ModelRangeError
        For key lengths outside the formula's range.
    """
    c = check_gnfs_correction(correction)
    kf, scalar = _key_lengths(k, GNFS_MIN_KEY_LENGTH, MAX_KEY_LENGTH, "the GNFS formula")
    val = _gnfs_bits(kf) - c
    return float(val) if scalar else val


def gnfs_complexity(k: Any, correction: Any = 0.0) -> float | np.ndarray:
    """``Omega(k) 2^-correction`` of eq:opt_key in operations; ``inf`` beyond the float range.

    Parameters
    ----------
    k : int or array_like of int
        Key bit length in ``[40, 65536]``.
    correction : float, default 0.0
        o(1) correction in bits.

    Returns
    -------
    float or ndarray
    """
    with np.errstate(over="ignore"):
        val = np.exp2(gnfs_log2_complexity(k, correction))
    return float(val) if np.ndim(val) == 0 else val


def pollard_rho_log2_operations(k: Any) -> float | np.ndarray:
    """``log2 sqrt(pi q / 2)``: expected group operations of Pollard rho for one key, in bits.

    The order-q subgroup of a ``k``-bit safe prime p = 2q + 1 has ``2^(k-2) <= q < 2^(k-1)``; the
    smallest q is taken, so the cost is a lower bound for any such group.

    Parameters
    ----------
    k : int or array_like of int
        Key (modulus) bit length in ``[16, 65536]``.

    Returns
    -------
    float or ndarray
        ``(k - 2 + log2(pi / 2)) / 2``.
    """
    kf, scalar = _key_lengths(k, GENERIC_MIN_KEY_LENGTH, MAX_KEY_LENGTH, "the generic (Pollard rho) model")
    val = 0.5 * (kf - 2.0 + math.log2(math.pi / 2.0))
    return float(val) if scalar else val


def check_security_parameter(lam: Any) -> int | float:
    """Validate a security parameter: an integer in ``[1, 2048]``, or a real number in ``(0, 2048]``.

    Integral floats (``74.0``) are returned as ``int``.

    Raises
    ------
    ParameterError
        If ``lam`` is not a positive finite number.
    ModelRangeError
        If ``lam`` exceeds :data:`LAMBDA_MAX` (``2^lam`` would be an unboundedly large integer).
    """
    if isinstance(lam, (numbers.Integral, np.integer)) and not isinstance(lam, bool):
        k = check_int("lam", lam, 1)
        if k > LAMBDA_MAX:
            raise ModelRangeError(f"security parameter lam must be <= {LAMBDA_MAX} bits, got {format_value(k)}")
        return k
    v = check_positive("lam", lam)
    if v > LAMBDA_MAX:
        raise ModelRangeError(f"security parameter lam must be <= {LAMBDA_MAX} bits, got {format_value(lam)}")
    return int(v) if v.is_integer() and v >= 1 else v


def paper_security_parameter(keys: int, budget: Fraction) -> int:
    """Smallest integer ``lam >= 1`` with ``keys 2^lam > budget`` (Theorem thm:opt_sec, exactly).

    ``lam = floor(log2(budget / keys)) + 1``, at least 1 (if ``budget < keys`` even one operation
    per key outlasts the budget). With ``keys = N*`` and ``budget = Upsilon tau_c`` this is
    ``lam*`` of eq:opt_sec.

    Parameters
    ----------
    keys : int
        Keys the adversary must break (>= 1).
    budget : Fraction
        Operations it can perform (> 0).

    Returns
    -------
    int
    """
    keys = check_int("keys", keys, 1)
    if not isinstance(budget, Fraction) or budget <= 0:
        raise ParameterError(f"budget must be a positive Fraction, got {format_value(budget)}")
    return max(1, floor_log2(budget / keys) + 1)


# --------------------------------------------------------------------------- the cost of breaking keys
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


@runtime_checkable
class DecipheringModel(Protocol):
    """What every deciphering-cost model provides."""

    name: str
    key_length_range: tuple[int, int]

    def break_cost(self, key_length: int) -> KeyBreakCost:
        """The cost of breaking keys of a ``key_length``-bit group."""
        ...

    def minimum_key_length(self, keys: int, budget: Fraction) -> int:
        """Smallest key length whose ``keys`` keys cost more than ``budget`` operations."""
        ...

    def describe(self) -> dict[str, Any]:
        """The model's name, formula, parameters and sources (JSON-ready)."""
        ...


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


#: Registry: model name -> class.
DECIPHERING_MODELS: dict[str, type[CostModel]] = {
    "paper": PaperModel,
    "precomputation": PrecomputationModel,
    "generic": GenericModel,
}

_OPTIONS: dict[str, tuple[str, ...]] = {
    "paper": ("gnfs_correction",),
    "precomputation": ("gnfs_correction", "calibration"),
    "generic": (),
}


def deciphering_model(name: Any = "paper", **options: Any) -> CostModel:
    """Build a cost model by name (:data:`DECIPHERING_MODELS`).

    Parameters
    ----------
    name : {"paper", "precomputation", "generic"}, default "paper"
        Or an already built model (returned as it is when no options are given).
    **options
        ``gnfs_correction`` (paper, precomputation), ``calibration`` (precomputation).

    Raises
    ------
    ParameterError
        For an unknown name or an option the model does not take.
    """
    if isinstance(name, CostModel):
        if options:
            raise ParameterError(f"options {sorted(options)} cannot be applied to an already built {name.name} model")
        return name
    if not isinstance(name, str) or name not in DECIPHERING_MODELS:
        raise ParameterError(f"unknown deciphering model {format_value(name)}; choose one of {', '.join(DECIPHERING_MODELS)}")
    bad = sorted(set(options) - set(_OPTIONS[name]))
    if bad:
        allowed = ", ".join(_OPTIONS[name]) or "none"
        raise ParameterError(f"the {name} model takes no option(s) {bad} (its options: {allowed})")
    return DECIPHERING_MODELS[name](**options)


# --------------------------------------------------------------------------- eq:opt_key under the paper model
def bit_security_of_key_length(k: Any, gnfs_correction: Any = 0.0) -> float | np.ndarray:
    """Bit security (Definition def:bit_sec) of a ``k``-bit key under the GNFS, ``log2 Omega(k) - c``:
    :func:`gnfs_log2_complexity` under the name of the paper's question (eq:opt_key read backwards)."""
    return gnfs_log2_complexity(k, gnfs_correction)


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
