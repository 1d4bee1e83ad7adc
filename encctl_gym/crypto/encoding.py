"""Encoder and decoder of Definition def:ec: signed fixed-point numbers <-> elements of G.

Encoding ``Ecd(x; Delta)``
    1. ``v = round(Delta * x)`` (IEEE double product, round half to even) as a signed integer;
    2. ``w`` = the signed integer nearest to ``v`` whose residue lies in the order-q subgroup
       G, searched deterministically in the order v, v + 1, v - 1, v + 2, v - 2, ...; the
       distance ``s = |w - v|`` is the *shift* (at most ``max_shift``, else an error);
    3. the plaintext is ``m = w mod p`` (a negative w becomes p - |w|).

    Membership is one Jacobi symbol per candidate for safe-prime groups (p = 2q + 1, where G
    is the set of quadratic residues), *not* a modular exponentiation. For a group with
    cofactor n != 2 the test is ``pow(m, q, p) == 1`` (one exponentiation per candidate;
    about n candidates are needed on average), which is allowed but slower.

    0 is not an element of G: ``Ecd(0)`` is the nearest member (1 for every safe-prime
    group, since 1 is a square and the search tries +1 before -1).

Decoding ``Dcd(m; Delta)``
    Lift m to the signed representative in (-p/2, p/2] and divide by ``Delta`` (a single
    value, ``power=1``) or ``Delta**2`` (a product of two encoded values, or a sum of such
    products, ``power=2``); no other power occurs in eq:ec and none is accepted.
    The division is exact rational arithmetic rounded once to the nearest double, so every
    party that decodes the same integer gets the bit-identical float.

Round-trip error
    ``|Dcd(Ecd(x)) - x| <= (1/2 + s) / Delta`` with s the shift of x (up to the rounding of
    the double product ``Delta * x`` and of the final division).

Overflow is never silent: an :class:`Encoder` has a declared input range ``x_bound``
(default: everything representable); a value outside raises
:class:`~encctl_gym.errors.EncodingOverflowError` naming it. NaN, infinities, booleans and
complex numbers (also inside arrays: their imaginary part would be lost) raise
:class:`~encctl_gym.errors.ParameterError`.
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_positive, format_value
from ..errors import EncodingOverflowError, ParameterError, PlaintextError
from . import arith
from .arith import format_int as fmt
from .group import GroupParams

__all__ = [
    "Encoder",
    "DEFAULT_MAX_SHIFT",
    "MAX_ENCODABLE_COFACTOR",
    "default_max_shift",
    "nearest_member",
    "encode_int",
    "decode_int",
    "lift",
    "decode_scaled",
    "DECODE_POWERS",
]

#: The powers of Delta that Dcd divides by: 1 for an encoded value, 2 for a product of two
#: encoded values or a sum of such products (eq:ec).
DECODE_POWERS = (1, 2)

#: Default largest distance from ``round(Delta x)`` to the chosen element of G, for
#: safe-prime groups. Quadratic residues have density 1/2, so a longer gap around a given
#: integer has probability about 2**-(2 * 64 + 1).
DEFAULT_MAX_SHIFT = 64

#: Largest cofactor n for which a default ``max_shift`` (64 (n // 2)) is chosen; above it the
#: nearest-element search is impractical and ``max_shift`` must be given explicitly.
MAX_ENCODABLE_COFACTOR = 1024


def default_max_shift(group: GroupParams) -> int:
    """The default ``max_shift`` for ``group``: 64 for safe primes, ``64 * (n // 2)`` for cofactor n.

    G has density 1/n among the residues, so missing it on all ``2 * max_shift + 1``
    candidates has probability about ``exp(-64)`` or less.

    Raises
    ------
    ParameterError
        If the cofactor exceeds :data:`MAX_ENCODABLE_COFACTOR`.
    """
    n = _check_group(group).cofactor
    if n > MAX_ENCODABLE_COFACTOR:
        raise ParameterError(
            f"the group's cofactor n = {n} is too large for nearest-element encoding "
            f"(G has density 1/n); pass max_shift explicitly or use a safe-prime group"
        )
    return DEFAULT_MAX_SHIFT * max(1, n // 2)


def _is_member_residue(group: GroupParams, r: int) -> bool:
    if r == 0:
        return False
    if group.cofactor == 2:
        return arith.jacobi(r, group.p) == 1
    return arith.powmod(r, group.q, group.p) == 1


def nearest_member(group: GroupParams, v: int, max_shift: int) -> tuple[int, int]:
    """Nearest signed integer ``w`` to ``v`` with ``w mod p`` in G (step 2 of Definition def:ec's Ecd).

    Candidates are tried in the order v, v + 1, v - 1, v + 2, v - 2, ... (deterministic).

    Parameters
    ----------
    group : GroupParams
        The group.
    v : int
        The signed integer to encode.
    max_shift : int
        Largest allowed distance ``|w - v|``.

    Returns
    -------
    (w, shift) : tuple of int
        The signed member and ``shift = |w - v|``.

    Raises
    ------
    ParameterError
        If ``group`` is not a :class:`GroupParams`, ``v`` is not an integer or ``max_shift`` is
        not an integer >= 0.
    PlaintextError
        If no member of G lies within ``max_shift`` of ``v``.
    """
    if type(v) is not int:
        v = check_int("v", v)
    if type(max_shift) is not int or max_shift < 0:
        max_shift = check_int("max_shift", max_shift, 0)
    p = _check_group(group).p
    if _is_member_residue(group, v % p):
        return v, 0
    for k in range(1, max_shift + 1):
        if _is_member_residue(group, (v + k) % p):
            return v + k, k
        if _is_member_residue(group, (v - k) % p):
            return v - k, k
    raise PlaintextError(f"no element of the order-q subgroup within max_shift = {max_shift} of v = {fmt(v)}")


def encode_int(group: GroupParams, v: int, max_shift: int | None = None) -> int:
    """Integer-level encoder: the plaintext ``m = w mod p`` for the signed integer ``v``.

    ``w`` is :func:`nearest_member` of ``v`` (Definition def:ec); raises
    :class:`EncodingOverflowError` if ``|w| > (p - 1)/2`` (it would not decode back).
    """
    v = check_int("v", v)
    _check_group(group).verify()
    ms = default_max_shift(group) if max_shift is None else check_int("max_shift", max_shift, 0)
    w, _ = nearest_member(group, v, ms)
    if abs(w) > group.half:
        raise EncodingOverflowError(f"v = {fmt(v)} encodes to w = {fmt(w)}, outside the representable range |w| <= (p-1)/2")
    return w % group.p


def lift(group: GroupParams, m: int) -> int:
    """Signed representative of the residue ``m`` in (-p/2, p/2] (first step of Dcd).

    ``m`` is taken as a residue in [0, p) (:func:`decode_int` checks that range); a
    non-integer ``m`` or ``group`` raises :class:`ParameterError`.
    """
    if type(m) is not int:
        m = check_int("m", m)
    half = _check_group(group).half
    return m - group.p if m > half else m


def decode_int(group: GroupParams, m: int) -> int:
    """Integer-level decoder: the signed lift of a plaintext ``m`` in [0, p) (Definition def:ec).

    Raises
    ------
    PlaintextError
        If ``m`` is not an integer in [0, p).
    """
    m = check_int("m", m, error=PlaintextError)
    if not 0 <= m < _check_group(group).p:
        raise PlaintextError(f"plaintext m = {fmt(m)} is outside [0, p) for p = {fmt(group.p)}")
    return lift(group, m)


def _check_power(power: Any) -> int:
    if type(power) is int and power in DECODE_POWERS:  # fast path
        return power
    if isinstance(power, bool) or not isinstance(power, (numbers.Integral, np.integer)) or int(power) not in DECODE_POWERS:
        raise ParameterError(
            f"power must be one of {DECODE_POWERS} (Delta for a value, Delta^2 for a product), got {format_value(power)}"
        )
    return int(power)


def _check_delta_ratio(delta_ratio: Any) -> tuple[int, int]:
    if type(delta_ratio) is tuple and len(delta_ratio) == 2:  # fast path (every decode)
        num, den = delta_ratio
        if type(num) is int and type(den) is int and num > 0 and den > 0:
            return num, den
    if not isinstance(delta_ratio, (tuple, list)) or len(delta_ratio) != 2:
        raise ParameterError(
            f"delta_ratio must be a pair (num, den) of integers > 0 with Delta = num / den, got {format_value(delta_ratio)}"
        )
    num, den = (arith.check_integer(f"delta_ratio[{i}]", v) for i, v in enumerate(delta_ratio))
    if num <= 0 or den <= 0:
        raise ParameterError(f"delta_ratio = ({fmt(num)}, {fmt(den)}) must have num > 0 and den > 0 (Delta = num / den > 0)")
    return int(num), int(den)


def decode_scaled(w: int, delta_ratio: tuple[int, int], power: int = 1) -> float:
    """Return ``w / Delta**power`` correctly rounded, with ``Delta = num/den`` given exactly.

    Parameters
    ----------
    w : int
        The signed integer to decode (``int``, ``gmpy2.mpz`` or a NumPy integer).
    delta_ratio : tuple of int
        ``(num, den)`` with ``num, den > 0``: Delta as an exact fraction
        (``float.as_integer_ratio``).
    power : int, default 1
        One of :data:`DECODE_POWERS`.

    Raises
    ------
    ParameterError
        If ``w`` is not an integer, ``delta_ratio`` is not a pair of integers > 0, or
        ``power`` is not in :data:`DECODE_POWERS`.
    EncodingOverflowError
        If the quotient does not fit in a double.
    """
    power = _check_power(power)
    num, den = _check_delta_ratio(delta_ratio)
    if type(w) is not int:
        w = check_int("w", w)
    try:
        return (w * den**power) / num**power
    except OverflowError as exc:
        raise EncodingOverflowError(f"decoded value {fmt(w)} / Delta^{power} does not fit in a float") from exc


def _check_group(group: Any) -> GroupParams:
    if not isinstance(group, GroupParams):
        raise ParameterError(f"group must be a GroupParams, got {format_value(group)}")
    return group


def _as_finite(name: str, x: Any) -> float:
    if isinstance(x, bool) or not isinstance(x, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"{name} must be a real number, got {format_value(x)}")
    try:
        xf = float(x)
    except OverflowError:
        raise EncodingOverflowError(f"{name} = {fmt(x)} is too large for a float") from None
    if not math.isfinite(xf):
        raise ParameterError(f"{name} must be finite, got {format_value(x)}")
    return xf


class Encoder:
    """Fixed-point encoder ``Ecd(.; Delta)`` and decoder ``Dcd(.; Delta)`` of Definition def:ec.

    Parameters
    ----------
    group : GroupParams
        The group whose order-q subgroup G is the plaintext space.
    delta : float
        The scaling factor Delta > 0.
    x_bound : float, optional
        Declared input range: values with ``|x| > x_bound`` raise
        :class:`EncodingOverflowError`. Default: every value whose encoding is representable,
        i.e. ``|round(Delta x)| + max_shift <= (p - 1)/2``.
    max_shift : int, optional
        Largest allowed distance between ``round(Delta x)`` and its encoding (default
        :func:`default_max_shift`: 64 for safe-prime groups), below ``(p - 1)/2``.

    Raises
    ------
    GroupError
        If ``group`` does not verify (:meth:`~.group.GroupParams.verify`).
    ParameterError
        If ``group`` is not a :class:`GroupParams`, ``delta`` is not a finite number > 0,
        ``x_bound`` is not finite and >= 0, or ``max_shift`` is not an integer in
        ``[0, (p - 1)/2)``.
    EncodingOverflowError
        If ``x_bound`` itself is not representable.

    Examples
    --------
    >>> from encctl_gym.crypto.group import shipped_group
    >>> enc = Encoder(shipped_group(64), delta=2**10)
    >>> enc.decode(enc.encode(-1.5))
    -1.5
    """

    def __init__(self, group: GroupParams, delta: float, x_bound: float | None = None, max_shift: int | None = None) -> None:
        self.group = _check_group(group).verify()  # membership tests are only meaningful in a verified group
        self.delta = check_positive("delta", delta)
        self.delta_ratio: tuple[int, int] = self.delta.as_integer_ratio()
        # a shift beyond (p - 1)/2 leaves no representable value (every encode would overflow)
        ms = default_max_shift(group) if max_shift is None else check_int("max_shift", max_shift, 0, group.half - 1)
        self.max_shift = ms
        self.x_bound: float | None = None
        if x_bound is not None:
            xb = _as_finite("x_bound", x_bound)
            if xb < 0:
                raise ParameterError(f"x_bound must be >= 0, got {format_value(x_bound)}")
            self._check_v(xb, self._round(xb), "x_bound")
            self.x_bound = xb

    # ------------------------------------------------------------------ scalars
    def _round(self, x: float) -> int:
        y = self.delta * x
        if not math.isfinite(y):
            raise EncodingOverflowError(f"x = {x!r}: Delta * x = {y!r} overflows a float")
        return int(round(y))

    def _check_v(self, x: float, v: int, name: str = "x") -> None:
        if abs(v) + self.max_shift > self.group.half:
            raise EncodingOverflowError(
                f"{name} = {x!r} is not representable: |round(Delta x)| + max_shift = "
                f"{fmt(abs(v) + self.max_shift)} > (p-1)/2 for a {self.group.bits}-bit group "
                f"and Delta = {self.delta!r}"
            )

    def quantize(self, x: float) -> int:
        """Step 1 of Ecd: ``v = round(Delta x)``, after the finiteness and range checks.

        Raises
        ------
        ParameterError
            If ``x`` is NaN, infinite or not a number.
        EncodingOverflowError
            If ``|x| > x_bound`` or ``v`` is not representable.
        """
        xf = _as_finite("x", x)
        if self.x_bound is not None and abs(xf) > self.x_bound:
            raise EncodingOverflowError(f"x = {x!r} is outside the declared input range |x| <= {self.x_bound!r}")
        v = self._round(xf)
        self._check_v(x, v)
        return v

    def encode_with_shift(self, x: float) -> tuple[int, int]:
        """Ecd of Definition def:ec with its shift: ``(m, s)``, m in G, ``s = |w - round(Delta x)|``."""
        w, s = nearest_member(self.group, self.quantize(x), self.max_shift)
        return w % self.group.p, s

    def encode_signed(self, x: float) -> int:
        """The signed integer ``w`` (in (-p/2, p/2]) whose residue is ``Ecd(x)``."""
        return nearest_member(self.group, self.quantize(x), self.max_shift)[0]

    def encode(self, x: float) -> int:
        """Ecd of Definition def:ec: the plaintext ``m`` in G (an int in [1, p))."""
        return self.encode_signed(x) % self.group.p

    def decode(self, m: int, power: int = 1) -> float:
        """Dcd of Definition def:ec: lift ``m`` to (-p/2, p/2] and divide by ``Delta**power``.

        ``power=1`` for an encoded value, ``power=2`` for a product of two encoded values
        (or a sum of such products, see :meth:`decode_signed`); any other power raises
        :class:`ParameterError`.
        """
        return decode_scaled(decode_int(self.group, m), self.delta_ratio, power)

    def decode_signed(self, w: int, power: int = 1) -> float:
        """Decode an already lifted signed integer (e.g. a row sum of lifted products)."""
        return decode_scaled(check_int("w", w), self.delta_ratio, power)

    def error_bound(self, shift: int | None = None) -> float:
        """Round-trip bound ``(1/2 + s)/Delta`` (default ``s = max_shift``).

        Raises
        ------
        ParameterError
            If ``shift`` is not an integer in ``[0, max_shift]`` (no encoding has another).
        """
        s = self.max_shift if shift is None else check_int("shift", shift, 0)
        if s > self.max_shift:
            raise ParameterError(f"shift must be <= max_shift = {self.max_shift} (no encoding has a larger one), got {s}")
        return (0.5 + s) / self.delta

    def max_abs_signed(self, x_bound: float) -> int:
        """Upper bound on ``|w|`` over all ``|x| <= x_bound``: ``round(Delta x_bound) + max_shift``.

        Raises
        ------
        ParameterError
            If ``x_bound`` is not a finite real number >= 0 (a bound on ``|x|``).
        EncodingOverflowError
            If ``Delta x_bound`` overflows a float.
        """
        xb = _as_finite("x_bound", x_bound)
        if xb < 0:
            raise ParameterError(f"x_bound must be >= 0 (a bound on |x|), got {format_value(x_bound)}")
        return self._round(xb) + self.max_shift

    # ------------------------------------------------------------------ arrays
    def quantize_array(self, x: Any) -> np.ndarray:
        """Vectorised :meth:`quantize`: an object array of Python ints of the shape of ``x``."""
        arr = as_finite_array("x", x, allow_empty=True, overflow_error=EncodingOverflowError)
        if self.x_bound is not None and arr.size and np.max(np.abs(arr)) > self.x_bound:
            bad = float(arr.flat[int(np.argmax(np.abs(arr)))])
            raise EncodingOverflowError(f"x = {bad!r} is outside the declared input range |x| <= {self.x_bound!r}")
        with np.errstate(over="ignore"):
            y = np.rint(self.delta * arr)
        out = np.empty(arr.shape, dtype=object)
        for idx, (xv, yv) in enumerate(zip(arr.ravel().tolist(), y.ravel().tolist())):
            if not math.isfinite(yv):
                raise EncodingOverflowError(f"x = {xv!r}: Delta * x overflows a float")
            v = int(yv)
            self._check_v(float(xv), v)
            out.flat[idx] = v
        return out

    def encode_signed_array(self, x: Any) -> np.ndarray:
        """Vectorised :meth:`encode_signed` (object array of signed Python ints)."""
        v = self.quantize_array(x)
        out = np.empty(v.shape, dtype=object)
        for idx, vi in enumerate(v.flat):
            out.flat[idx] = nearest_member(self.group, vi, self.max_shift)[0]
        return out

    def decode_signed_array(self, w: Any, power: int = 1) -> np.ndarray:
        """Vectorised :meth:`decode_signed`: float64 array of the shape of ``w``."""
        arr = np.asarray(w, dtype=object)
        power = _check_power(power)
        out = np.empty(arr.shape, dtype=np.float64)
        for idx, wi in enumerate(arr.flat):
            out.flat[idx] = self.decode_signed(wi, power)
        return out

    def __repr__(self) -> str:
        return f"Encoder(bits={self.group.bits}, delta={self.delta!r}, x_bound={self.x_bound!r}, max_shift={self.max_shift})"
