"""Exact rational arithmetic for the security design (thm:opt_sec, def:security, def:sdt).

The floors of Theorem thm:opt_sec (``N* = floor(x) + 2``, ``lam* = floor(log2 y) + 1``) and the
comparisons of Definition def:security (``tau(N) <= tau_c``, ``gamma(N) < gamma_c``) are taken in
exact arithmetic, so that an exact tie is never decided by rounding. A float becomes a
:class:`~fractions.Fraction` by one of two rules, and each call site says which:

``decimal`` (:func:`decimal_fraction`, also available as :func:`exact_number`)
    For numbers a person typed: design parameters (gamma_c, tau_c, Upsilon, variances). The float
    is read as its shortest decimal representation, ``repr``: ``1e-6`` is ``1/10**6`` and
    ``442e15`` is ``442 * 10**15``, the number the user meant, not its binary neighbour.
``binary`` (:func:`binary_fraction`)
    For numbers the package computed in floating point (``gamma(N)`` of a float complexity, the
    trace ``tr(Sigma^-1)`` of a numerical solve): the float's exact binary value, since there is
    no typed decimal behind it.

Integers and fractions are exact under both rules. Every real input must be finite in float64
(``|x| <= 1.8e308``), integers included: ``10**400`` is refused with its size, as everywhere
else in the package.

Powers of two with a real exponent (a cost of ``2^74.004`` operations) are made exact by
:func:`pow2`, which also reaches beyond the float range.
"""

from __future__ import annotations

import math
import numbers
from fractions import Fraction
from typing import Any

import numpy as np

from .._validation import FLOAT_MAX, format_value
from ..errors import ModelRangeError, ParameterError

__all__ = ["decimal_fraction", "binary_fraction", "exact_number", "floor_log2", "log2_fraction", "pow2", "POW2_MAX_EXPONENT"]

#: Largest exponent :func:`pow2` accepts: 2^(2^17) is a 131073-bit integer, cheap to handle;
#: no cost model of this package gets near it for key lengths up to 65536 bits.
POW2_MAX_EXPONENT: float = float(2**17)


def _check_magnitude(name: str, value: Any, frac: Fraction) -> None:
    if abs(frac) > FLOAT_MAX:
        raise ParameterError(
            f"{name} must be a finite real number within the float64 range (|x| <= {FLOAT_MAX:.4g}), got {format_value(value)}"
        )


def _to_fraction(name: str, value: Any, rule: str) -> Fraction:
    if isinstance(value, Fraction):
        return value
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"{name} must be a real number, got {format_value(value)}")
    if isinstance(value, (numbers.Integral, np.integer)):
        frac = Fraction(int(value))
        _check_magnitude(name, value, frac)
        return frac
    v = float(value)
    if not math.isfinite(v):
        raise ParameterError(f"{name} must be finite, got {format_value(value)}")
    return Fraction(repr(v)) if rule == "decimal" else Fraction(v)


def decimal_fraction(name: str, value: Any, *, positive: bool = True) -> Fraction:
    """A typed number as an exact fraction (the ``decimal`` rule: floats by their shortest repr).

    Parameters
    ----------
    name : str
        Name of the value in error messages.
    value : int, float, Fraction or numpy scalar
        Finite; within the float64 range unless it is a Fraction.
    positive : bool, default True
        Require ``value > 0``.

    Returns
    -------
    Fraction

    Raises
    ------
    ParameterError
        If ``value`` is not a finite real number in range (or not positive when required).
    """
    frac = _to_fraction(name, value, "decimal")
    if positive and frac <= 0:
        raise ParameterError(f"{name} must be > 0, got {format_value(value)}")
    return frac


#: The historical name of :func:`decimal_fraction` (kept for ``security.deciphering.exact_number``).
exact_number = decimal_fraction


def binary_fraction(name: str, value: Any) -> Fraction:
    """A computed number as an exact fraction (the ``binary`` rule: floats by their exact value).

    Raises
    ------
    ParameterError
        If ``value`` is NaN, infinite or not a real number.
    """
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if math.isnan(v):
            raise ParameterError(f"{name} is NaN")
        if math.isinf(v):
            raise ParameterError(f"{name} is infinite")
    return _to_fraction(name, value, "binary")


def _exact_positive(what: str, x: Any) -> Fraction:
    """``x`` as a Fraction if it is an exact positive number (a Fraction or an integer, not a bool).

    Floats are refused: which rational a float stands for is the caller's choice
    (:func:`decimal_fraction` or :func:`binary_fraction`), never made here silently.
    """
    if isinstance(x, bool) or not isinstance(x, (Fraction, numbers.Integral, np.integer)):
        raise ParameterError(f"{what} needs an exact number (a Fraction or an integer), got {format_value(x)}")
    frac = Fraction(int(x)) if not isinstance(x, Fraction) else x
    if frac <= 0:
        raise ParameterError(f"{what} needs a positive number, got {format_value(x)}")
    return frac


def floor_log2(x: Fraction | int) -> int:
    """Exact ``floor(log2 x)`` for a positive fraction or integer.

    Raises
    ------
    ParameterError
        If ``x`` is not a Fraction or an integer, or is not > 0.
    """
    x = _exact_positive("floor_log2", x)
    p, q = x.numerator, x.denominator
    k = p.bit_length() - q.bit_length()
    # now 2^(k-1) < p/q < 2^(k+1); decide between k-1 and k
    if (p >= q << k) if k >= 0 else ((p << -k) >= q):
        return k
    return k - 1


def log2_fraction(x: Fraction | int) -> float:
    """``log2 x`` of a positive fraction or integer in double precision, for any size (no float
    overflow); refuses what :func:`floor_log2` refuses."""
    x = _exact_positive("log2", x)
    p, q = x.numerator, x.denominator
    sp, sq = max(p.bit_length() - 60, 0), max(q.bit_length() - 60, 0)
    return math.log2(p >> sp) - math.log2(q >> sq) + sp - sq


def pow2(x: Any) -> Fraction:
    """``2^x`` as an exact fraction, for a real ``x`` in ``[-POW2_MAX_EXPONENT, POW2_MAX_EXPONENT]``.

    An integer ``x`` gives exactly ``2^x``; otherwise ``2^x = 2^(x - floor x) 2^(floor x)`` with
    the first factor the float ``2.0 ** (x - floor x)`` taken at its exact binary value, so the
    result is a well-defined number beyond the float range, within one float rounding of 2^x.

    Raises
    ------
    ModelRangeError
        If ``|x|`` exceeds :data:`POW2_MAX_EXPONENT` (an exact integer that large is never needed
        and would take unbounded memory).
    """
    if isinstance(x, bool) or not isinstance(x, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"exponent must be a real number, got {format_value(x)}")
    if isinstance(x, (numbers.Integral, np.integer)):
        e = int(x)
        if abs(e) > POW2_MAX_EXPONENT:
            raise ModelRangeError(f"2^x needs |x| <= {POW2_MAX_EXPONENT:g}, got x = {format_value(x)}")
        return Fraction(2) ** e
    xf = float(x)
    if not math.isfinite(xf) or abs(xf) > POW2_MAX_EXPONENT:
        raise ModelRangeError(f"2^x needs a finite |x| <= {POW2_MAX_EXPONENT:g}, got x = {format_value(x)}")
    e = math.floor(xf)
    return Fraction(2.0 ** (xf - e)) * Fraction(2) ** e
