"""The formulas of the deciphering-cost models: the GNFS running time ``Omega(k)`` of eq:opt_key
(with an optional o(1) correction), Pollard rho in the order-q subgroup, and the checks of a
GNFS correction and of a security parameter (ranges in :mod:`encctl_gym.security.cost_models`).
"""

from __future__ import annotations

import math
import numbers
from fractions import Fraction
from typing import Any

import numpy as np

from ..._validation import check_int, check_positive, format_value
from ...errors import ModelRangeError, ParameterError
from ..exact import floor_log2
from ..records import default_records

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
    "bit_security_of_key_length",
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


def bit_security_of_key_length(k: Any, gnfs_correction: Any = 0.0) -> float | np.ndarray:
    """Bit security (Definition def:bit_sec) of a ``k``-bit key under the GNFS, ``log2 Omega(k) - c``:
    :func:`gnfs_log2_complexity` under the name of the paper's question (eq:opt_key read backwards)."""
    return gnfs_log2_complexity(k, gnfs_correction)
