"""Shared input checks. Every public function validates through these, so that a bad value
always raises an error of :mod:`encctl_gym.errors` that names the value.

:func:`format_value` is the one way a value goes into an error message: it never fails and
never grows without bound (an integer of ten thousand digits, a string of a megabyte, an
array of a million entries are all shown in a few dozen characters), so a message can always
be built, whatever the input.

Real numbers are finite float64 values: a Python integer beyond the float range
(``10**400``) or a complex number is refused with its name, never silently truncated to its
real part or turned into ``inf``.
"""

from __future__ import annotations

import math
import numbers
import os
import stat
import sys
from fractions import Fraction
from typing import Any

import numpy as np

from .errors import ConfigError, EncctlError, ParameterError, ResourceLimitError, ShapeError, UnstableSystemError

__all__ = [
    "one_line",
    "format_value",
    "format_count",
    "check_positive",
    "check_nonnegative",
    "check_real",
    "check_int",
    "MAX_EXACT_FLOAT_INT",
    "check_bool",
    "parse_number",
    "as_finite_array",
    "check_system",
    "spectral_radius",
    "check_schur_stable",
    "check_regular_file",
    "read_bounded",
    "FLOAT_MAX",
]

#: Largest finite float64; every real input must lie within +-FLOAT_MAX.
FLOAT_MAX: float = sys.float_info.max

_MAX_INT_DIGITS_SHOWN = 40  # integers up to this many digits are printed in full
_MAX_ITEMS_SHOWN = 4


def _format_int(v: int) -> str:
    bits = abs(v).bit_length()
    if bits <= _MAX_INT_DIGITS_SHOWN * 3:  # at most ~36 digits: safe and short
        return repr(v)
    digits = int(bits * math.log10(2)) + 1  # exact to within one digit, without str(v)
    sign = "-" if v < 0 else ""
    return f"{sign}<integer of {bits} bits, about {digits} digits>"


def format_count(count: int, noun: str) -> str:
    """``"1 episode"``, ``"4 episodes"``: a count and its noun, plural unless the count is 1
    (a noun whose plural is not ``noun + "s"`` is not for this function)."""
    return f"{count} {noun}" + ("" if count == 1 else "s")


def format_value(value: Any, limit: int = 120) -> str:
    """A short, always-computable text for ``value`` in an error message.

    Integers of more than about 36 digits are shown by their size (``<integer of 1329 bits,
    about 401 digits>``: Python refuses ``str`` of integers over 4300 digits, and a message
    must never fail); strings and reprs are cut at ``limit`` characters; arrays and sequences
    show their shape or length and a few entries; the text is one line (a matrix's rows are
    joined), so that the command line's one-line error stays one line.

    Parameters
    ----------
    value : object
        Anything.
    limit : int, default 120
        Largest number of characters taken from a string or a repr.

    Returns
    -------
    str
    """
    try:
        if isinstance(value, bool) or value is None:
            return repr(value)
        if isinstance(value, (int, np.integer)):
            return _format_int(int(value))
        if isinstance(value, Fraction):
            if max(abs(value.numerator).bit_length(), value.denominator.bit_length()) <= 100:
                return f"Fraction({value.numerator}, {value.denominator})"
            return f"<fraction {_format_int(value.numerator)} / {_format_int(value.denominator)}>"
        if isinstance(value, (float, complex, np.floating, np.complexfloating)):
            return repr(value.item() if isinstance(value, np.generic) else value)
        if isinstance(value, str):
            return repr(value) if len(value) <= limit else repr(value[:limit]) + f"... ({len(value)} characters)"
        if isinstance(value, (bytes, bytearray)):
            return repr(bytes(value[:limit])) + (f"... ({len(value)} bytes)" if len(value) > limit else "")
        if isinstance(value, np.ndarray):
            if value.dtype.kind in "biufc" and value.size <= 6:
                body = one_line(np.array2string(value, threshold=6, edgeitems=2, separator=", "))
                return f"array({body}, dtype={value.dtype})"
            if value.dtype.kind in "biufc":
                body = one_line(np.array2string(value.ravel()[:_MAX_ITEMS_SHOWN], separator=", "))
                return f"<array of shape {value.shape}, dtype {value.dtype}, first entries {body[:limit]}>"
            return f"<array of shape {value.shape}, dtype {value.dtype}>"
        if isinstance(value, (list, tuple)):
            items = ", ".join(format_value(v, limit=limit // 2) for v in value[:_MAX_ITEMS_SHOWN])
            more = f", ... ({len(value)} items)" if len(value) > _MAX_ITEMS_SHOWN else ""
            text = ("[" if isinstance(value, list) else "(") + items + more + ("]" if isinstance(value, list) else ")")
            return text if len(text) <= 2 * limit else text[: 2 * limit] + "...]"
        if isinstance(value, dict):
            keys = list(value)[:_MAX_ITEMS_SHOWN]
            items = ", ".join(f"{format_value(k, limit // 4)}: {format_value(value[k], limit // 2)}" for k in keys)
            more = f", ... ({len(value)} keys)" if len(value) > _MAX_ITEMS_SHOWN else ""
            return "{" + items + more + "}"
        text = one_line(repr(value))
    except Exception:  # noqa: BLE001 - a repr that fails must not hide the real error
        return f"<{type(value).__name__} object>"
    return text if len(text) <= limit else text[:limit] + f"... ({len(text)} characters)"


def one_line(text: str) -> str:
    """``text`` with its line breaks and the indentation after them folded into single spaces
    (NumPy prints a matrix on several lines; an error message, and the command line's print of
    it, is one line)."""
    lines = text.splitlines()
    if lines == [text]:  # no line break at all
        return text
    return " ".join(part.strip() for part in lines if part.strip())


def _as_float(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"{name} must be a real number, got {format_value(value)}")
    try:
        v = float(value)
    except OverflowError:
        raise ParameterError(
            f"{name} must be a finite real number within the float64 range (|x| <= {FLOAT_MAX:.4g}), got {format_value(value)}"
        ) from None
    if not math.isfinite(v):
        raise ParameterError(f"{name} must be finite, got {format_value(value)}")
    return v


def check_real(name: str, value: Any) -> float:
    """Return ``value`` as a float, raising :class:`ParameterError` unless it is a finite real
    number (not a bool, not complex, not a string, within the float64 range)."""
    return _as_float(name, value)


def check_positive(name: str, value: Any) -> float:
    """Return ``value`` as a float, raising :class:`ParameterError` unless it is finite and > 0."""
    v = _as_float(name, value)
    if v <= 0:
        raise ParameterError(f"{name} must be > 0, got {format_value(value)}")
    return v


def check_nonnegative(name: str, value: Any) -> float:
    """Return ``value`` as a float, raising :class:`ParameterError` unless it is finite and >= 0."""
    v = _as_float(name, value)
    if v < 0:
        raise ParameterError(f"{name} must be >= 0, got {format_value(value)}")
    return v


def check_probability(name: str, value: Any) -> float:
    """Return ``value`` as a probability in [0, 1] (an audit rate, a detection level), raising
    :class:`ParameterError` naming it otherwise: the package's one rule for a rate."""
    v = check_nonnegative(name, value)
    if v > 1:
        raise ParameterError(f"{name} must lie in [0, 1], got {format_value(value)}")
    return v


#: Largest float that :func:`check_int` takes as an integer: every integer up to 2^53 is exact in
#: float64, and no float beyond it says which integer it means (``2.0**64 + 1 == 2.0**64``).
MAX_EXACT_FLOAT_INT = 2**53


def check_int(
    name: str, value: Any, minimum: int | None = None, maximum: int | None = None, *, error: type[EncctlError] = ParameterError
) -> int:
    """``value`` as an int, the package's one integer check.

    The rule: an exact integer is accepted (``int``, a NumPy integer, a ``gmpy2.mpz``: every
    :class:`numbers.Integral`), and so is a float that is an integer of at most
    :data:`MAX_EXACT_FLOAT_INT` in magnitude (``3.0``, a YAML ``1e6``: exactly the integer
    written); a bool, a fractional or larger float, a string (see
    :func:`encctl_gym.crypto.group.parse_group_integer` for the hex strings of group files) and
    everything else is refused.

    Parameters
    ----------
    name : str
        The value's name, for the message.
    value : object
        The value.
    minimum, maximum : int, optional
        Bounds (inclusive).
    error : type of EncctlError, default ParameterError
        The subclass raised (e.g. :class:`~encctl_gym.errors.GroupError` for group parameters).

    Raises
    ------
    ParameterError
        (or ``error``) naming the value, for a value the rule refuses or one outside the bounds.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        if (
            isinstance(value, (float, np.floating))
            and math.isfinite(value)
            and float(value).is_integer()
            and abs(float(value)) <= MAX_EXACT_FLOAT_INT
        ):
            value = int(value)
        else:
            raise error(f"{name} must be an integer, got {format_value(value)}")
    v = int(value)
    if minimum is not None and v < minimum:
        raise error(f"{name} must be >= {minimum}, got {format_value(v)}")
    if maximum is not None and v > maximum:
        raise error(f"{name} must be <= {maximum}, got {format_value(v)}")
    return v


def check_bool(name: str, value: Any) -> bool:
    """Return ``value`` if it is a bool (or ``numpy.bool_``); anything else, including the
    strings ``'no'`` and ``'false'`` and the integers 0 and 1, raises :class:`ParameterError`."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise ParameterError(f"{name} must be True or False, got {format_value(value)}")


def parse_number(name: str, text: Any) -> float:
    """A finite real number from a command-line string (``"1e-6"``, ``"442e15"``) or a number.

    Raises
    ------
    ParameterError
        For text that is not a number, or a number that is not finite in float64.
    """
    if isinstance(text, (numbers.Real, np.floating, np.integer)) and not isinstance(text, bool):
        return _as_float(name, text)
    if not isinstance(text, str):
        raise ParameterError(f"{name} must be a number, got {format_value(text)}")
    try:
        v = float(text.strip())
    except ValueError:
        raise ParameterError(f"{name} must be a number, got {format_value(text)}") from None
    if not math.isfinite(v):
        raise ParameterError(f"{name} must be a finite number within the float64 range, got {format_value(text)}")
    return v


def as_finite_array(
    name: str,
    value: Any,
    ndim: int | None = None,
    *,
    allow_empty: bool = False,
    overflow_error: type[EncctlError] = ParameterError,
) -> np.ndarray:
    """Convert ``value`` to a float64 array with finite real entries (and ``ndim`` dimensions if
    given): the package's one real-array check.

    Complex, boolean and string data are refused (never truncated to the real part or read as
    0/1), as are bytes (NumPy would read ``bytearray(b"1")`` as the number 49) and integers
    beyond the float64 range (``overflow_error``, default :class:`ParameterError`; the encoder
    raises :class:`~encctl_gym.errors.EncodingOverflowError`). Exact integers of any type
    (``int``, ``gmpy2.mpz``) within the range are read as floats. An empty array is refused
    unless ``allow_empty``.
    """
    if isinstance(value, (str, bytes, bytearray, memoryview)):
        raise ParameterError(f"{name} must be a numeric array, got {format_value(value)}")
    try:
        raw = value if isinstance(value, np.ndarray) else np.asarray(value)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ParameterError(f"{name} must be a numeric array, got {format_value(value)}") from exc
    kind = raw.dtype.kind
    if kind == "c":
        raise ParameterError(f"{name} must be real, got a complex array {format_value(raw)}")
    if kind == "b":
        raise ParameterError(f"{name} must be numeric, got a boolean array {format_value(raw)}")
    if kind in "USV" or kind == "M" or kind == "m":
        raise ParameterError(f"{name} must be a numeric array, got {format_value(value)}")
    if kind == "O":
        for v in raw.ravel():
            if isinstance(v, (complex, np.complexfloating)):
                raise ParameterError(f"{name} must be real, got complex entries in {format_value(value)}")
            if v is None or isinstance(v, (bool, np.bool_, str, bytes)):
                raise ParameterError(f"{name} must be a numeric array, got the entry {format_value(v)} in {format_value(value)}")
    try:
        arr = np.asarray(raw, dtype=np.float64)
    except OverflowError as exc:
        raise overflow_error(f"{name} must have entries within the float64 range, got {format_value(value)}") from exc
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name} must be a numeric array, got {format_value(value)}") from exc
    if ndim is not None and arr.ndim != ndim:
        raise ShapeError(f"{name} must have {ndim} dimension(s), got shape {arr.shape}")
    if arr.size == 0 and not allow_empty:
        raise ShapeError(f"{name} must not be empty, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"{name} must have finite entries, got {format_value(arr)}")
    return arr


def check_system(A: Any, B: Any) -> tuple[np.ndarray, np.ndarray]:
    """Validate the plant matrices of eq:system: A is n x n, B is n x m, all entries finite and real."""
    A = as_finite_array("A", A)
    B = as_finite_array("B", B)
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ShapeError(f"A must be a square matrix, got shape {A.shape}")
    if B.ndim == 1 and A.shape[0] == B.shape[0]:
        B = B.reshape(-1, 1)
    if B.ndim != 2 or B.shape[0] != A.shape[0]:
        raise ShapeError(f"B must have shape ({A.shape[0]}, m) to match A of shape {A.shape}, got {B.shape}")
    return A, B


def spectral_radius(A: np.ndarray) -> float:
    """The largest modulus of the eigenvalues of ``A``."""
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def check_schur_stable(A: np.ndarray) -> float:
    """Raise :class:`UnstableSystemError` unless A is Schur stable; return its spectral radius."""
    rho = spectral_radius(A)
    if not rho < 1.0:
        raise UnstableSystemError(f"A must be Schur stable (spectral radius < 1), got spectral radius {rho:.6g}")
    return rho


_FILE_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
               (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))  # fmt: skip


#: Longest file name component and path where the file system does not say (POSIX's usual values).
DEFAULT_NAME_MAX, DEFAULT_PATH_MAX = 255, 4096


def check_path_name(what: str, path: Any) -> str:
    """Return ``path`` as a string, raising :class:`ParameterError` for a name no file can have
    here, before any work is done: an embedded NUL, a component longer than the file system's
    ``NAME_MAX`` (asked of the nearest existing directory, 255 where it does not say) or a path
    longer than ``PATH_MAX`` (4096). The message names the limit."""
    try:
        name = os.fsdecode(os.fspath(path))
    except TypeError:
        raise ParameterError(f"{what} must be a path (a str or os.PathLike), got {format_value(path)}") from None
    if "\x00" in name:
        raise ParameterError(f"{what} {format_value(name)} holds a NUL character, which no file name can")
    if len(os.fsencode(name)) > DEFAULT_PATH_MAX:
        raise ParameterError(f"{what} is {len(os.fsencode(name))} bytes long, beyond PATH_MAX = {DEFAULT_PATH_MAX}")
    base = os.path.dirname(os.path.abspath(name))
    while not os.path.isdir(base) and os.path.dirname(base) != base:
        base = os.path.dirname(base)
    try:
        name_max = int(os.pathconf(base, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):  # no pathconf (Windows) or the name is unknown
        name_max = DEFAULT_NAME_MAX
    for part in name.replace(os.sep, "/").split("/"):
        if len(os.fsencode(part)) > name_max:
            raise ParameterError(
                f"{what}: the name {format_value(part, limit=40)} is {len(os.fsencode(part))} bytes long, "
                f"beyond the file system's NAME_MAX = {name_max}"
            )
    return name


def check_regular_file(what: str, path: Any) -> str:
    """Return ``path`` as a string, raising :class:`ConfigError` unless it names an existing
    regular file; the message says what it is instead ("does not exist", "is a directory",
    "is not a regular file: a FIFO (named pipe)", ...). Only ``os.stat`` is called: a FIFO is
    never opened, so the check cannot block."""
    try:
        name = os.fspath(path)
    except TypeError:
        raise ParameterError(f"{what} must be a path (a str or os.PathLike), got {format_value(path)}") from None
    name = os.fsdecode(name)  # a bytes path as the file system decodes it
    try:
        mode = os.stat(name).st_mode
    except FileNotFoundError:
        raise ConfigError(f"{what} {name!r} does not exist") from None
    except (OSError, ValueError) as exc:  # permission, a name too long, an embedded NUL
        raise ConfigError(f"{what} {name!r} cannot be examined: {getattr(exc, 'strerror', None) or exc}") from None
    if stat.S_ISREG(mode):
        return name
    if stat.S_ISDIR(mode):
        raise ConfigError(f"{what} {name!r} is a directory, not a file")
    kind = next((label for test, label in _FILE_KINDS if test(mode)), "a special file")
    raise ConfigError(f"{what} {name!r} is not a regular file: it is {kind}")


def read_bounded(what: str, path: Any, limit: int, limit_name: str, *, error: type[EncctlError] = ResourceLimitError) -> bytes:
    """The bytes of the file ``path``, the package's one bounded file read: a file of more than
    ``limit`` bytes is refused before it is read, and at most ``limit + 1`` bytes are ever read
    (a file that grows meanwhile cannot make it read more).

    Parameters
    ----------
    what : str
        What the file is, for messages (``"system file"``, ``"config file"``, ...).
    path : str or os.PathLike
        The file (callers check first that it is a regular file where a FIFO could block).
    limit : int
        Most bytes accepted.
    limit_name : str
        The constant that holds ``limit``, named in the message.
    error : type of EncctlError, default ResourceLimitError
        Raised for a file over the limit.

    Raises
    ------
    ConfigError
        If the file cannot be opened or read.
    ResourceLimitError
        (or ``error``) for a file of more than ``limit`` bytes; the message gives both sizes.
    """
    name = os.fspath(path)

    def too_large(size: int) -> EncctlError:
        return error(f"{what} {name!r} has {size} bytes, more than {limit_name} = {limit}")

    try:
        with open(name, "rb") as f:
            size = os.fstat(f.fileno()).st_size
            if size > limit:
                raise too_large(size)
            raw = f.read(limit + 1)
    except OSError as exc:
        raise ConfigError(f"cannot read {what} {name!r}: {exc.strerror or exc}") from None
    if len(raw) > limit:
        raise too_large(len(raw))
    return raw
