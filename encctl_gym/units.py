"""Units of time: the one parser of durations (the defense period tau_c of Definition def:security).

The paper's year has 365 days: its defense period of 10 years is ``tau_c = 31536e4 s``.
:func:`parse_duration` is used by the ``design`` command, by plant files
(:mod:`encctl_gym.plant_file`) and is meant for every other place that accepts ``tau_c``, so
that ``"5y"`` means the same thing everywhere.

=========  ================================  =============
unit       spellings                          seconds
=========  ================================  =============
second     ``s``, ``sec``, ``second(s)``      1
minute     ``min``, ``mins``, ``minute(s)``   60
hour       ``h``, ``hour(s)``                 3600
day        ``d``, ``day(s)``                  86400
year       ``y``, ``yr``, ``year(s)``         31536000
=========  ================================  =============

``m`` alone is refused (minute or month?).
"""

from __future__ import annotations

import math
import numbers
import re
from typing import Any

import numpy as np

from ._validation import check_positive, format_value
from .errors import ParameterError

__all__ = ["SECONDS_PER_YEAR", "SECONDS_PER_UNIT", "parse_duration"]

#: The paper's year: tau_c = 31536e4 s is 10 years of 365 days.
SECONDS_PER_YEAR: int = 365 * 24 * 3600

#: Seconds per canonical unit.
SECONDS_PER_UNIT: dict[str, float] = {"s": 1.0, "min": 60.0, "h": 3600.0, "d": 86400.0, "y": float(SECONDS_PER_YEAR)}

_ALIASES: dict[str, str] = {
    "": "s",
    "s": "s",
    "sec": "s",
    "second": "s",
    "seconds": "s",
    "min": "min",
    "mins": "min",
    "minute": "min",
    "minutes": "min",
    "h": "h",
    "hour": "h",
    "hours": "h",
    "d": "d",
    "day": "d",
    "days": "d",
    "y": "y",
    "yr": "y",
    "year": "y",
    "years": "y",
}

_DURATION = re.compile(r"([0-9]*\.?[0-9]+(?:e[+-]?[0-9]+)?|[0-9]+\.)\s*([a-z]*)")
_MAX_TEXT = 64  # a duration is a short string; longer text is refused before the regex runs


def parse_duration(value: Any, name: str = "tau_c") -> float:
    """A duration in seconds from ``"10y"``, ``"5d"``, ``"2h"``, ``"30min"``, ``"3600s"``, ``"1.5 h"``
    or a plain number of seconds (a number or a numeric string).

    Parameters
    ----------
    value : str, int or float
        The duration.
    name : str, default "tau_c"
        Name used in error messages.

    Returns
    -------
    float
        Seconds, finite and > 0.

    Raises
    ------
    ParameterError
        For an unknown unit, a malformed number, a non-positive duration or one beyond the
        float64 range (``"1e308y"``).
    """
    if isinstance(value, (numbers.Real, np.floating, np.integer)) and not isinstance(value, bool):
        return check_positive(name, value)
    if not isinstance(value, str):
        raise ParameterError(f"{name} must be a duration (a number of seconds or text like '10y'), got {format_value(value)}")
    s = value.strip().lower()
    match = _DURATION.fullmatch(s) if len(s) <= _MAX_TEXT else None
    if not match:
        raise ParameterError(f"{name} must be a duration like 10y, 5d, 2h, 30min, 3600s or seconds, got {format_value(value)}")
    number, unit = match.groups()
    canonical = _ALIASES.get(unit)
    if canonical is None:
        raise ParameterError(f"{name} has unknown unit {unit!r} in {format_value(value)}; use s, min, h, d or y")
    seconds = float(number) * SECONDS_PER_UNIT[canonical]
    if not math.isfinite(seconds):
        raise ParameterError(f"{name} must be finite in seconds, got {format_value(value)}")
    if seconds <= 0:  # "0y", or "1e-400s" that underflows to 0: name the text that was typed
        raise ParameterError(f"{name} must be > 0 s, got {format_value(value)}")
    return seconds
