"""Published attack costs the deciphering-cost models are calibrated on and compared with.

The data live in ``security/data/deciphering_records.json`` (package data), each figure as
published (value and unit) with its source:

* number-field-sieve records (``Record``): key length, total time, per-key time where
  published, the time basis (core time or wall-clock) and the reference CPU's clock rate;
* the NIST SP 800-57 comparable strengths (80 -> 1024, 112 -> 2048, 128 -> 3072, 192 -> 7680,
  256 -> 15360 bits);
* named o(1) corrections of the GNFS formula (``guillevic``: 11.91 bits).

:func:`load_records` reads them (or a file of the same layout, e.g. ``encctl-gym design
--calibration FILE``) and checks them: positive times, known units, ratio points and NIST rows
strictly increasing in key length. The per-key/precomputation ratio of the ``precomputation``
cost model (:mod:`encctl_gym.security.cost_models`) is taken from the records marked
``use_for_ratio`` (:attr:`RecordSet.ratio_points`).

Conventions: a core-year is 365 days of one core; one *operation* of a record is one clock cycle
of one core of its reference CPU, so ``log2 operations = log2(core-seconds x clock rate)``.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

from .._validation import check_bool, check_int, check_nonnegative, check_positive, format_value, read_bounded
from ..errors import ConfigError, ParameterError
from ..units import SECONDS_PER_YEAR

__all__ = [
    "Record",
    "RatioPoint",
    "NistRow",
    "RecordSet",
    "load_records",
    "default_records",
    "ratio_points",
    "parse_records",
    "check_increasing",
    "nist_key_length",
    "nist_strength",
    "DATA_FILE",
]

#: The shipped data file.
DATA_FILE = Path(__file__).with_name("data") / "deciphering_records.json"
#: How the shipped data file is named in outputs.
DATA_LABEL = "package data encctl_gym/security/data/deciphering_records.json"

#: Largest records (calibration) file read, in bytes: such a file is a few kilobytes.
MAX_RECORDS_FILE_BYTES = 1 << 20

#: Seconds per time unit of a record (a year is 365 days, as everywhere in the package).
_UNIT_SECONDS: dict[str, float] = {
    "second": 1.0,
    "minute": 60.0,
    "hour": 3600.0,
    "day": 86400.0,
    "week": 7 * 86400.0,
    "year": float(SECONDS_PER_YEAR),
}
_PROBLEMS = ("dlp", "factoring")
_BASES = ("core", "wall-clock")


@dataclass(frozen=True)
class Record:
    """One published number-field-sieve computation.

    Attributes
    ----------
    name : str
        Short identifier (``"dlp-768"``).
    problem : {"dlp", "factoring"}
        Prime-field discrete logarithm or integer factorization.
    key_length : int
        Bits of p (or of the modulus).
    year : int
        Year of the computation (0 to 9999; 0: not given).
    total_seconds : float
        Total time (core-seconds or wall-clock seconds, see ``time_basis``).
    per_key_seconds : float or None
        Time of one further discrete logarithm after the precomputation, if published.
    time_basis : {"core", "wall-clock"}
        Whether the times are core time (comparable as work) or wall-clock time.
    clock_hz : float or None
        Clock rate of the reference core (core time only).
    use_for_ratio : bool
        Whether the precomputation cost model calibrates its per-key ratio on this record.
    total_text, per_key_text : str
        The published figures (``"5300 core-years"``).
    source : str
        Citation.
    note : str
        Why the record is (not) used.
    """

    name: str
    problem: str
    key_length: int
    year: int
    total_seconds: float
    per_key_seconds: float | None
    time_basis: str
    clock_hz: float | None
    use_for_ratio: bool
    total_text: str
    per_key_text: str
    source: str
    note: str

    @property
    def log2_ratio(self) -> float | None:
        """``log2(total / per-key time)``: how many times cheaper a further key is (bits)."""
        if self.per_key_seconds is None:
            return None
        return math.log2(self.total_seconds / self.per_key_seconds)

    @property
    def log2_operations(self) -> float | None:
        """``log2`` of the total work in clock cycles (core-time records with a clock rate)."""
        if self.time_basis != "core" or self.clock_hz is None:
            return None
        return math.log2(self.total_seconds * self.clock_hz)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict, with the derived ``log2_ratio`` and ``log2_operations``."""
        return {
            "name": self.name,
            "problem": self.problem,
            "key_length": self.key_length,
            "year": self.year,
            "total": self.total_text,
            "per_key": self.per_key_text or None,
            "time_basis": self.time_basis,
            "clock_hz": self.clock_hz,
            "use_for_ratio": self.use_for_ratio,
            "log2_ratio": self.log2_ratio,
            "log2_operations": self.log2_operations,
            "source": self.source,
            "note": self.note,
        }


@dataclass(frozen=True)
class RatioPoint:
    """A calibration point of the precomputation model: at ``key_length`` bits a further key costs
    ``2^-ratio_bits`` of the precomputation."""

    key_length: int
    ratio_bits: float
    source: str = ""


@dataclass(frozen=True)
class NistRow:
    """A row of NIST SP 800-57 Part 1, Table 2: ``strength`` bits for a ``key_length``-bit group."""

    strength: int
    key_length: int


@dataclass(frozen=True)
class RecordSet:
    """Everything in a records file, checked.

    Attributes
    ----------
    records : tuple of Record
    nist : tuple of NistRow
        Strictly increasing in strength and key length.
    nist_source : str
    corrections : dict of str to (float, str)
        Named GNFS corrections: bits and source.
    path : str
        Where the data came from.
    """

    records: tuple[Record, ...]
    nist: tuple[NistRow, ...]
    nist_source: str
    corrections: Mapping[str, tuple[float, str]]
    path: str

    @property
    def ratio_points(self) -> tuple[RatioPoint, ...]:
        """The calibration points of the per-key ratio (records with ``use_for_ratio``)."""
        return tuple(
            RatioPoint(r.key_length, float(r.log2_ratio), f"{r.name}: {r.source}")  # type: ignore[arg-type]
            for r in self.records
            if r.use_for_ratio
        )

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {
            "path": self.path,
            "records": [r.to_dict() for r in self.records],
            "ratio_points": [{"key_length": p.key_length, "ratio_bits": p.ratio_bits} for p in self.ratio_points],
            "nist_sp800_57": {
                "source": self.nist_source,
                "rows": [{"strength": r.strength, "key_length": r.key_length} for r in self.nist],
            },
            "gnfs_corrections": {k: {"bits": b, "source": s} for k, (b, s) in self.corrections.items()},
        }


def _duration(where: str, spec: Any, basis: str) -> tuple[float, str]:
    if not isinstance(spec, Mapping) or set(spec) != {"value", "unit"}:
        raise ConfigError(f"{where} must be an object with 'value' and 'unit', got {format_value(spec)}")
    unit = spec["unit"]
    if not isinstance(unit, str):
        raise ConfigError(f"{where}: unit must be a string, got {format_value(unit)}")
    base = unit[len("core-") :] if unit.startswith("core-") else unit
    if base not in _UNIT_SECONDS:
        raise ConfigError(
            f"{where}: unknown unit {format_value(unit)}; use second, minute, hour, day, week or year "
            "(with a 'core-' prefix for core time)"
        )
    if unit.startswith("core-") != (basis == "core"):
        raise ConfigError(f"{where}: unit {unit!r} does not match time_basis {basis!r}")
    value = check_positive(f"{where}.value", spec["value"])
    seconds = value * _UNIT_SECONDS[base]
    if not math.isfinite(seconds):
        raise ConfigError(f"{where} is beyond the float range: {format_value(spec)}")
    plural = "s" if value != 1 else ""
    return seconds, f"{value:g} {unit}{plural}"


def _record(i: int, raw: Any) -> Record:
    where = f"records[{i}]"
    if not isinstance(raw, Mapping):
        raise ConfigError(f"{where} must be an object, got {format_value(raw)}")
    known = {
        "name",
        "problem",
        "key_length",
        "year",
        "total",
        "per_key",
        "time_basis",
        "clock_ghz",
        "use_for_ratio",
        "source",
        "note",
    }
    unknown = sorted(set(map(str, raw)) - known)
    if unknown:
        raise ConfigError(f"{where} has unknown field(s) {unknown}; known: {sorted(known)}")
    missing = sorted({"name", "problem", "key_length", "total", "time_basis", "source"} - set(raw))
    if missing:
        raise ConfigError(f"{where} lacks field(s) {missing}")
    name = raw["name"]
    if not isinstance(name, str) or not name:
        raise ConfigError(f"{where}.name must be a non-empty string, got {format_value(name)}")
    where = f"record {name!r}"
    if raw["problem"] not in _PROBLEMS:
        raise ConfigError(f"{where}: problem must be one of {_PROBLEMS}, got {format_value(raw['problem'])}")
    if raw["time_basis"] not in _BASES:
        raise ConfigError(f"{where}: time_basis must be one of {_BASES}, got {format_value(raw['time_basis'])}")
    basis = raw["time_basis"]
    try:
        k = check_int(f"{where}.key_length", raw["key_length"], minimum=2, maximum=1 << 20)
        year = check_int(f"{where}.year", raw.get("year", 0), minimum=0, maximum=9999)  # a publication year (0: unknown)
        total, total_text = _duration(f"{where}.total", raw["total"], basis)
        per_key, per_key_text = (None, "") if raw.get("per_key") is None else _duration(f"{where}.per_key", raw["per_key"], basis)
        clock = raw.get("clock_ghz")
        clock_hz = None if clock is None else check_positive(f"{where}.clock_ghz", clock) * 1e9
        use = check_bool(f"{where}.use_for_ratio", raw.get("use_for_ratio", False))
    except ParameterError as exc:
        raise ConfigError(str(exc)) from None
    if per_key is not None and per_key >= total:
        raise ConfigError(f"{where}: per_key ({per_key_text}) must be smaller than total ({total_text})")
    if use and (per_key is None or basis != "core"):
        raise ConfigError(f"{where}: use_for_ratio needs a per_key time in core time")
    for field in ("source", "note"):
        if not isinstance(raw.get(field, ""), str):
            raise ConfigError(f"{where}.{field} must be a string, got {format_value(raw.get(field))}")
    return Record(
        name,
        raw["problem"],
        k,
        year,
        total,
        per_key,
        basis,
        clock_hz,
        use,
        total_text,
        per_key_text,
        raw["source"],
        raw.get("note", ""),
    )


def check_increasing(what: str, key_lengths: Iterable[int]) -> None:
    """Raise :class:`ConfigError` unless ``key_lengths`` is strictly increasing (naming the pair)."""
    ks = list(key_lengths)
    for a, b in zip(ks, ks[1:]):
        if not b > a:
            raise ConfigError(f"{what} must be strictly increasing in key length, got {a} followed by {b}")


def parse_records(data: Any, path: str = "<data>") -> RecordSet:
    """Check a decoded records document (the layout of ``deciphering_records.json``).

    Raises
    ------
    ConfigError
        Naming the first bad entry: unknown fields, bad units, non-positive times, ratio points
        or NIST rows not strictly increasing in key length.
    """
    if not isinstance(data, Mapping):
        raise ConfigError(f"{path}: a records file must hold a JSON object, got {format_value(data)}")
    unknown = sorted(set(map(str, data)) - {"about", "records", "nist_sp800_57", "gnfs_corrections"})
    if unknown:
        raise ConfigError(f"{path}: unknown field(s) {unknown}")
    raw_records = data.get("records", [])
    if not isinstance(raw_records, list):
        raise ConfigError(f"{path}: records must be a list, got {format_value(raw_records)}")
    records = tuple(_record(i, r) for i, r in enumerate(raw_records))
    check_increasing(
        f"{path}: the ratio calibration points (records with use_for_ratio)", [r.key_length for r in records if r.use_for_ratio]
    )
    nist_raw = data.get("nist_sp800_57", {"source": "", "rows": []})
    if not isinstance(nist_raw, Mapping) or not isinstance(nist_raw.get("rows"), list):
        raise ConfigError(f"{path}: nist_sp800_57 must be an object with a list 'rows', got {format_value(nist_raw)}")
    rows = []
    for i, r in enumerate(nist_raw["rows"]):
        if not isinstance(r, Mapping) or set(r) != {"strength", "key_length"}:
            raise ConfigError(f"{path}: nist_sp800_57 row {i} must have 'strength' and 'key_length', got {format_value(r)}")
        try:
            rows.append(
                NistRow(
                    check_int("nist strength", r["strength"], minimum=1), check_int("nist key_length", r["key_length"], minimum=2)
                )
            )
        except ParameterError as exc:
            raise ConfigError(f"{path}: {exc}") from None
    nist = tuple(rows)
    check_increasing(f"{path}: the NIST SP 800-57 rows", [r.key_length for r in nist])
    for a, b in zip(nist, nist[1:]):
        if not b.strength > a.strength:
            raise ConfigError(f"{path}: NIST strengths must increase with key length, got {a.strength} then {b.strength}")
    corrections: dict[str, tuple[float, str]] = {}
    raw_corr = data.get("gnfs_corrections", {})
    if not isinstance(raw_corr, Mapping):
        raise ConfigError(f"{path}: gnfs_corrections must be an object, got {format_value(raw_corr)}")
    for key, spec in raw_corr.items():
        if not isinstance(spec, Mapping) or "bits" not in spec:
            raise ConfigError(f"{path}: gnfs_corrections[{key!r}] must have 'bits', got {format_value(spec)}")
        try:
            bits = check_positive(f"gnfs_corrections[{key!r}].bits", spec["bits"])
        except ParameterError as exc:
            raise ConfigError(f"{path}: {exc}") from None
        corrections[str(key)] = (bits, str(spec.get("source", "")))
    return RecordSet(records, nist, str(nist_raw.get("source", "")), corrections, path)


def load_records(path: str | Path | None = None) -> RecordSet:
    """The shipped records (``path=None``, cached) or those of a JSON file of the same layout.

    Raises
    ------
    ConfigError
        If the file is missing, unreadable or invalid (see :func:`parse_records`).
    ResourceLimitError
        If the file is larger than 1 MiB.
    """
    if path is None:
        return default_records()
    return _load(Path(path))


@lru_cache(maxsize=1)
def default_records() -> RecordSet:
    """The records shipped with the package (read and checked once)."""
    return dataclasses.replace(_load(DATA_FILE), path=DATA_LABEL)


def _load(p: Path) -> RecordSet:
    if not p.is_file():
        raise ConfigError(f"records file {str(p)!r} does not exist")
    raw = read_bounded("records file", p, MAX_RECORDS_FILE_BYTES, "MAX_RECORDS_FILE_BYTES")
    try:
        data = json.loads(raw.decode("utf-8"))
    except (ValueError, UnicodeDecodeError, RecursionError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ConfigError(f"cannot read records file {str(p)!r}: {format_value(first)}") from None
    return parse_records(data, str(p))


def ratio_points(points: Iterable[Any]) -> tuple[RatioPoint, ...]:
    """Check user-given calibration points: ``RatioPoint``s or ``(key_length, ratio_bits)`` pairs,
    strictly increasing in key length, with finite ratios >= 0.

    Raises
    ------
    ConfigError
        For a value that is not a list of points, an empty list, a malformed point or key
        lengths not strictly increasing.
    """
    if isinstance(points, (str, bytes, Mapping)) or not isinstance(points, Iterable):
        raise ConfigError(f"calibration must be a list of (key_length, ratio_bits) points, got {format_value(points)}")
    out = []
    for i, p in enumerate(points):
        if isinstance(p, RatioPoint):
            k, r, src = p.key_length, p.ratio_bits, p.source
        elif isinstance(p, (tuple, list)) and len(p) in (2, 3):
            k, r, src = p[0], p[1], (p[2] if len(p) == 3 else "")
        else:
            raise ConfigError(f"calibration point {i} must be (key_length, ratio_bits), got {format_value(p)}")
        try:
            k = check_int(f"calibration point {i} key_length", k, minimum=2)
            r = check_positive(f"calibration point {i} ratio_bits", r)
        except ParameterError as exc:
            raise ConfigError(str(exc)) from None
        out.append(RatioPoint(k, r, str(src)))
    if not out:
        raise ConfigError("the precomputation model needs at least one calibration point")
    check_increasing("calibration points", [p.key_length for p in out])
    return tuple(out)


def nist_key_length(bits: float, records: RecordSet | None = None) -> int | None:
    """The NIST SP 800-57 key length for a security strength of ``bits``: the smallest tabulated
    key length whose strength is at least ``bits`` (``None`` above the largest row).

    Raises
    ------
    ParameterError
        If ``bits`` is not a finite real number >= 0.
    """
    bits = check_nonnegative("bits", bits)
    rows = (records or default_records()).nist
    for row in rows:
        if row.strength >= bits:
            return row.key_length
    return None


def nist_strength(key_length: int, records: RecordSet | None = None) -> int | None:
    """The NIST SP 800-57 strength of a ``key_length``-bit group: the strength of the largest
    tabulated key length not above it (``None`` below the smallest row).

    Raises
    ------
    ParameterError
        If ``key_length`` is not an integer >= 2.
    """
    key_length = check_int("key_length", key_length, 2)
    best = None
    for row in (records or default_records()).nist:
        if row.key_length <= key_length:
            best = row.strength
    return best
