"""Plant files: the one schema and the one bounded reader for a plant of eq:system and its design values.

A plant file is JSON, YAML or NPZ with these fields (nothing else):

===========  ========  ============================================================
field        required  meaning
===========  ========  ============================================================
``A``        yes       n x n system matrix (Schur stable for a design)
``B``        yes       n x m input matrix (a flat list of n numbers is one column)
``C``        no        p x n output matrix of ``y = C x + v`` (a flat list of n
                       numbers is one output); ``(A, C)`` observable. Without it
                       the state is measured
``sigma_v2`` no        measurement noise variance of ``v`` (>= 0, default 0)
``sigma_u2`` no        attack input power per channel (variance, > 0)
``sigma_w2`` no        process noise variance (> 0)
``sigma_x2`` no        variance of x_0 (>= 0)
``gamma_c``  no        acceptable estimation error (> 0)
``tau_c``    no        defense period: seconds or a duration such as ``"10y"``
                       (:func:`encctl_gym.units.parse_duration`)
``upsilon``  no        adversary computing speed in FLOPS (> 0)
===========  ========  ============================================================

A missing optional field takes its default (the paper's design example unless the caller passes
others), and :class:`PlantSpec` records which values came from the file and which from the
defaults. Unknown fields, and a field given twice, are an error naming them. In YAML a number
with an exponent but no dot (``1e-6``, ``442e15``) is a number, as in JSON and on the command line
(PyYAML's YAML 1.1 would read it as a string); a quoted value stays a string.

Reading is bounded: files over :data:`MAX_FILE_BYTES` are refused before they are read; YAML is
read by :func:`encctl_gym.safe_yaml.load_yaml`, with aliases allowed but counted expanded within
:data:`MAX_YAML_NODES` nodes before any Python object is built (a few hundred bytes of nested
aliases would otherwise take gigabytes), nesting at most :data:`MAX_YAML_DEPTH` levels; NPZ members are checked
for their uncompressed size and for the size their ``.npy`` headers declare (shape times itemsize) before any
array is allocated, and loaded without pickles (:func:`encctl_gym._npz.read_npz`); a corrupt archive is a
:class:`~encctl_gym.errors.ConfigError`. Numbers must be real and finite in
float64: booleans, strings, NaN, infinities, complex data and integers beyond the float range
(``10**400``) are refused, naming the field and the position of the first bad entry (``A[1][0]``).
"""

from __future__ import annotations

import json
import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ._npz import read_npz
from ._validation import (
    FLOAT_MAX,
    as_finite_array,
    check_nonnegative,
    check_positive,
    check_regular_file,
    check_system,
    format_value,
    read_bounded,
)
from .errors import ConfigError, ParameterError, ResourceLimitError
from .presets import DESIGN_FIELDS, SystemPreset, design_defaults
from .safe_yaml import load_yaml
from .units import parse_duration

__all__ = [
    "PlantSpec",
    "load_plant_file",
    "load_system",
    "PLANT_FIELDS",
    "FIELD_MEANINGS",
    "fields_help",
    "MAX_FILE_BYTES",
    "MAX_YAML_NODES",
    "MAX_YAML_DEPTH",
    "SUFFIXES",
]

#: The fields of the measurement ``y = C x + v`` (optional; without them the state is measured).
OUTPUT_FIELDS: tuple[str, ...] = ("C", "sigma_v2")
#: Every field a plant file may hold.
PLANT_FIELDS: tuple[str, ...] = ("A", "B", *OUTPUT_FIELDS, *DESIGN_FIELDS)
#: One line per field of :data:`PLANT_FIELDS` (the table of the module docstring), for ``--help``.
FIELD_MEANINGS: dict[str, str] = {
    "A": "required: n x n system matrix (Schur stable for a design)",
    "B": "required: n x m input matrix (a flat list of n numbers is one column)",
    "C": "p x n output matrix of y = C x + v, (A, C) observable (a flat list is one output); without it the state is measured",
    "sigma_v2": "measurement noise variance of v (>= 0, default 0)",
    "sigma_u2": "attack input power per channel (> 0)",
    "sigma_w2": "process noise variance (> 0)",
    "sigma_x2": "variance of x_0 (>= 0)",
    "gamma_c": "acceptable estimation error (> 0)",
    "tau_c": "defense period: seconds or a duration such as 10y",
    "upsilon": "adversary computing speed in FLOPS (> 0)",
}


def fields_help() -> str:
    """The plant-file fields as lines of text (``encctl-gym design --help``)."""
    width = max(map(len, PLANT_FIELDS))
    return "\n".join(f"  {name:<{width}}  {FIELD_MEANINGS[name]}" for name in PLANT_FIELDS)


#: Largest plant file read (bytes): room for matrices of about 1000 x 1000 in text.
MAX_FILE_BYTES: int = 64 * 2**20
#: Largest number of YAML nodes after alias expansion.
MAX_YAML_NODES: int = 4_000_000
#: Deepest nesting of mappings and lists in a YAML plant file (the top-level mapping is one level).
MAX_YAML_DEPTH: int = 32
#: Accepted file name endings.
SUFFIXES: tuple[str, ...] = (".json", ".yaml", ".yml", ".npz")
_MAX_NPZ_MEMBERS = len(PLANT_FIELDS)


@dataclass(frozen=True)
class PlantSpec:
    """A plant read from a file, with its design values and where each came from.

    Attributes
    ----------
    path : str
        The file.
    preset : SystemPreset
        ``A``, ``B`` and the design values (file values, else defaults), named ``file:<path>``.
    from_file : tuple of str
        Fields given in the file.
    from_defaults : tuple of str
        Fields taken from the defaults.
    """

    path: str
    preset: SystemPreset
    from_file: tuple[str, ...]
    from_defaults: tuple[str, ...]

    @property
    def A(self) -> np.ndarray:
        """System matrix."""
        return self.preset.A

    @property
    def B(self) -> np.ndarray:
        """Input matrix."""
        return self.preset.B

    @property
    def C(self) -> np.ndarray | None:
        """Output matrix, or ``None`` when the state is measured."""
        return self.preset.C

    def values(self) -> dict[str, float]:
        """The design values by :data:`~encctl_gym.presets.DESIGN_FIELDS`."""
        return {key: getattr(self.preset, key) for key in DESIGN_FIELDS}

    def describe_sources(self) -> str:
        """One line: which values came from the file and which from the defaults."""
        text = f"from {self.path}: {', '.join(self.from_file)}"
        if self.from_defaults:
            text += f"; defaults: {', '.join(self.from_defaults)}"
        return text


def _fail(path: Path, msg: str) -> ConfigError:
    return ConfigError(f"system file {str(path)!r}: {msg}")


# --------------------------------------------------------------------------- bounded decoding
def _refuse_duplicate_keys(path: Path, keys: list[Any]) -> None:
    """A JSON field given twice is an error: the reader would otherwise keep the last one silently."""
    seen: set[Any] = set()
    for k in keys:
        if k in seen:
            raise _fail(path, f"field {format_value(k)} is given more than once")
        seen.add(k)


def _load_npz(path: Path, raw: bytes) -> dict[str, Any]:
    return read_npz(
        raw,
        where=f"system file {str(path)!r}",
        max_bytes=MAX_FILE_BYTES,
        max_members=_MAX_NPZ_MEMBERS,
        limit_name="MAX_FILE_BYTES",
    )


def _json_object(path: Path, pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    _refuse_duplicate_keys(path, [k for k, _ in pairs])
    return dict(pairs)


def _decode(path: Path) -> Any:
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise ConfigError(f"system file {str(path)!r} must end in .json, .yaml, .yml or .npz")
    raw = read_bounded("system file", path, MAX_FILE_BYTES, "MAX_FILE_BYTES")
    if suffix == ".npz":
        return _load_npz(path, raw)
    try:
        text = raw.decode("utf-8")
        if suffix == ".json":
            return json.loads(text, object_pairs_hook=lambda pairs: _json_object(path, pairs))
        return load_yaml(
            text, what=f"system file {str(path)!r}", max_nodes=MAX_YAML_NODES, max_depth=MAX_YAML_DEPTH, aliases=True
        )
    except (ConfigError, ResourceLimitError):
        raise
    except Exception as exc:  # noqa: BLE001 - any parse failure (syntax, tags, depth, digits) is one ConfigError
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ConfigError(f"cannot read system file {str(path)!r}: {format_value(first)}") from None


# --------------------------------------------------------------------------- field checks
def _where(key: str, index: tuple[int, ...]) -> str:
    return key + "".join(f"[{i}]" for i in index)


def _check_leaves(path: Path, key: str, value: Any) -> None:
    """Walk nested lists (iteratively) and refuse anything but finite real numbers within float64,
    naming the first bad entry and where it is (``A[0][1]``)."""
    stack: list[tuple[Any, tuple[int, ...]]] = [(value, ())]
    while stack:
        v, index = stack.pop()
        if isinstance(v, (list, tuple)):
            stack.extend((item, (*index, i)) for i, item in reversed(list(enumerate(v))))
        elif isinstance(v, bool) or v is None or isinstance(v, (str, bytes, dict, complex)):
            raise _fail(path, f"{key} must hold real numbers, got {format_value(v)} at {_where(key, index)}")
        elif isinstance(v, numbers.Integral):
            if abs(int(v)) > FLOAT_MAX:
                raise _fail(path, f"{key} holds a number beyond the float64 range: {format_value(v)} at {_where(key, index)}")
        elif not isinstance(v, numbers.Real):
            raise _fail(path, f"{key} must hold real numbers, got {format_value(v)} at {_where(key, index)}")
        elif not math.isfinite(v):
            raise _fail(path, f"{key} must hold finite numbers, got {format_value(v)} at {_where(key, index)}")


def _check_array(path: Path, key: str, value: np.ndarray) -> None:
    """An array read from an NPZ file: real numeric entries, all finite; the first bad one is named."""
    if value.dtype.kind == "c":
        bad = np.argwhere(value.imag != 0)
        if bad.size == 0:
            raise _fail(path, f"{key} must be real, got an array of dtype {value.dtype}")
        index = tuple(int(i) for i in bad[0])
        raise _fail(
            path, f"{key} must be real, got the complex entry {format_value(value[index].item())} at {_where(key, index)}"
        )
    if value.dtype.kind not in "iuf":
        raise _fail(path, f"{key} must be a numeric matrix, got an array of dtype {value.dtype}")
    if value.dtype.kind == "f":
        bad = np.argwhere(~np.isfinite(value))
        if bad.size:
            index = tuple(int(i) for i in bad[0])
            raise _fail(path, f"{key} must hold finite numbers, got {format_value(value[index].item())} at {_where(key, index)}")


def _matrix(path: Path, key: str, value: Any) -> np.ndarray:
    if isinstance(value, np.ndarray):
        _check_array(path, key, value)
    else:
        if not isinstance(value, (list, tuple)):
            raise _fail(path, f"{key} must be a matrix (a list of rows), got {format_value(value)}")
        _check_leaves(path, key, value)
    try:
        return as_finite_array(key, value)
    except ParameterError as exc:
        raise _fail(path, f"{key} is not a numeric matrix ({exc})") from None


def _scalar(path: Path, key: str, value: Any) -> Any:
    if isinstance(value, np.ndarray):
        if value.ndim != 0 and value.size != 1:
            raise _fail(path, f"{key} must be a single value, got an array of shape {value.shape}")
        if value.dtype.kind == "c":
            raise _fail(path, f"{key} must be real, got {format_value(value)}")
        if value.dtype.kind == "U" and key == "tau_c":
            return str(value.reshape(()))
        if value.dtype.kind not in "iuf":
            raise _fail(path, f"{key} must be a number, got an array of dtype {value.dtype}")
        value = value.reshape(()).item()
    if key == "tau_c" and isinstance(value, str):
        return value
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise _fail(path, f"{key} must be a number, got {format_value(value)}")
    return value


def _design_value(key: str, value: Any) -> float:
    if key == "tau_c":
        return parse_duration(value, "tau_c")
    if key == "sigma_x2":
        return check_nonnegative(key, value)
    return check_positive(key, value)


def _measurement(path: Path, data: Mapping[str, Any], A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray | None, float]:
    """``C`` and ``sigma_v2`` of the file (``None`` and 0 when absent), checked as :class:`~encctl_gym.plant.Plant`
    checks them (shape, observability, sign)."""
    from .plant import Plant

    C = _matrix(path, "C", data["C"]) if "C" in data else None
    sigma_v2 = _scalar(path, "sigma_v2", data["sigma_v2"]) if "sigma_v2" in data else 0.0
    if "sigma_v2" in data and C is None:
        raise _fail(path, "sigma_v2 is the noise of the outputs y = C x + v: give C too")
    try:
        plant = Plant(A, B, stable=False, C=C, sigma_v2=sigma_v2)
    except ParameterError as exc:
        raise type(exc)(f"system file {str(path)!r}: {exc}") from None
    return plant.C, plant.sigma_v2


def load_plant_file(path: str | Path, *, defaults: Mapping[str, Any] | SystemPreset | None = None) -> PlantSpec:
    """Read a plant file (see the module table) into a :class:`PlantSpec`.

    Parameters
    ----------
    path : str or Path
        ``.json``, ``.yaml``/``.yml`` or ``.npz``.
    defaults : mapping or SystemPreset, optional
        Values of the optional fields the file does not give; default: the paper's design
        example (:func:`~encctl_gym.presets.design_defaults`).

    Returns
    -------
    PlantSpec

    Raises
    ------
    ConfigError
        If the file is missing, unreadable, of unknown type, lacks ``A`` or ``B``, has unknown
        fields, or holds values that are not real numbers.
    ResourceLimitError
        If the file, its uncompressed arrays or its expanded YAML aliases exceed the bounds.
    ParameterError, ShapeError
        For values out of their domain (a negative variance), shapes that do not fit, or
        ``defaults`` that is not a mapping of design values (or holds unknown fields).
    """
    p = Path(check_regular_file("system file", path))
    data = _decode(p)
    if not isinstance(data, Mapping):
        raise _fail(p, f"must hold a mapping with 'A' and 'B', got {format_value(data)}")
    keys = [str(k) for k in data]
    unknown = sorted(set(keys) - set(PLANT_FIELDS))
    if unknown:
        raise _fail(p, f"unknown field(s) {unknown}; a plant file may hold {', '.join(PLANT_FIELDS)}")
    if "A" not in data or "B" not in data:
        raise ConfigError(f"system file {str(p)!r} must define 'A' and 'B'")
    A = _matrix(p, "A", data["A"])
    B = _matrix(p, "B", data["B"])
    try:
        A, B = check_system(A, B)
    except ParameterError as exc:
        raise type(exc)(f"system file {str(p)!r}: {exc}") from None
    if defaults is None:
        base: dict[str, Any] = design_defaults()
    elif isinstance(defaults, SystemPreset):
        base = {key: getattr(defaults, key) for key in DESIGN_FIELDS}
    elif isinstance(defaults, Mapping):
        base = dict(defaults)
        extra = sorted(str(k) for k in base if k not in DESIGN_FIELDS)
        if extra:
            raise ParameterError(f"defaults has unknown field(s) {extra}; design values are {', '.join(DESIGN_FIELDS)}")
    else:
        raise ParameterError(f"defaults must be a mapping of design values or a SystemPreset, got {format_value(defaults)}")
    missing = [key for key in DESIGN_FIELDS if key not in data and key not in base]
    if missing:
        raise _fail(p, f"{', '.join(missing)} {'is' if len(missing) == 1 else 'are'} neither in the file nor in the defaults")
    C, sigma_v2 = _measurement(p, data, A, B)
    values: dict[str, float] = {}
    from_file: list[str] = ["A", "B", *(k for k in OUTPUT_FIELDS if k in data)]
    from_defaults: list[str] = []
    for key in DESIGN_FIELDS:
        if key in data:
            raw, from_file_ = _scalar(p, key, data[key]), True
        else:
            raw, from_file_ = base[key], False
        try:
            values[key] = _design_value(key, raw)
        except ParameterError as exc:
            where = f"system file {str(p)!r}" if from_file_ else "default"
            raise type(exc)(f"{where}: {exc}") from None
        (from_file if from_file_ else from_defaults).append(key)
    preset = SystemPreset(
        name=f"file:{p}",
        description=f"plant from {p}",
        A=A,
        B=B,
        C=C,
        sigma_v2=sigma_v2,
        sigma_w2=values["sigma_w2"],
        sigma_u2=values["sigma_u2"],
        sigma_x2=values["sigma_x2"],
        gamma_c=values["gamma_c"],
        tau_c=values["tau_c"],
        upsilon=values["upsilon"],
    )
    return PlantSpec(str(p), preset, tuple(from_file), tuple(from_defaults))


def load_system(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """``A`` and ``B`` of a plant file (:func:`load_plant_file` without the design values).

    Returns
    -------
    (ndarray, ndarray)
        ``A`` (n x n) and ``B`` (n x m), validated by ``check_system``.
    """
    spec = load_plant_file(path)
    return spec.A, spec.B
