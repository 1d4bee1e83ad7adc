"""Bad values for the probe: a fixed catalogue per kind of parameter, plus values drawn from
hypothesis strategies with ``derandomize=True`` (the same values on every run, chosen by
hypothesis rather than by hand).

Each entry is ``(value, cls)``: the value and the failure class it mainly tests (a huge integer
tests for a hang or a traceback from ``str``; a NaN, a negative number or a bool that is taken
as a number, for a silent wrong number; a string or a list, for a traceback).

Kinds
-----
``pos``       a finite real > 0 (variances, Upsilon, Delta, ...)
``nonneg``    a finite real >= 0
``real``      any finite real
``prob``      a real in (0, 1]
``int``       an integer count >= 1 (``int0``: >= 0)
``bool``      True or False only
``name``      a string picking a branch (scheme, reward, method, ...)
``seed``      None or a non-negative integer
``matrix``    a real 2 x 2 array (``vector``: a real 1-D array)
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Callable
from typing import Any

import numpy as np
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

__all__ = ["BAD", "bad_values", "draw", "STRATEGIES", "label"]

NAN = float("nan")
INF = float("inf")
HUGE = 10**400  # beyond float64, and str() works
HUGER = 10**5000  # beyond Python's int-to-str limit of 4300 digits

_TYPES_WRONG: list[tuple[Any, str]] = [("abc", "traceback"), (None, "traceback"), ([1.0, 2.0], "traceback")]

_REAL_WRONG: list[tuple[Any, str]] = [
    (NAN, "silent"),
    (INF, "silent"),
    (True, "silent"),
    (2 + 1j, "silent"),
    (HUGE, "traceback"),
    (HUGER, "traceback"),
    (np.array([1.0, 2.0]), "traceback"),
    *_TYPES_WRONG,
]

BAD: dict[str, list[tuple[Any, str]]] = {
    "pos": [(0.0, "silent"), (-1.0, "silent"), *_REAL_WRONG],
    "nonneg": [(-1.0, "silent"), (-1e-300, "silent"), *_REAL_WRONG],
    "real": list(_REAL_WRONG),
    "prob": [(0.0, "silent"), (1.5, "silent"), (-0.5, "silent"), *_REAL_WRONG],
    "int": [
        (0, "silent"),
        (-1, "silent"),
        (2.5, "silent"),
        (True, "silent"),
        (NAN, "silent"),
        (INF, "silent"),
        (3 + 0j, "silent"),
        (HUGE, "hang"),
        (HUGER, "traceback"),
        ("3", "traceback"),
        (None, "traceback"),
        ([3], "traceback"),
    ],
    "int0": [
        (-1, "silent"),
        (2.5, "silent"),
        (True, "silent"),
        (NAN, "silent"),
        (INF, "silent"),
        (3 + 0j, "silent"),
        (-HUGE, "traceback"),
        (HUGER, "traceback"),
        ("3", "traceback"),
        (None, "traceback"),
        ([3], "traceback"),
    ],
    "bool": [
        ("no", "silent"),
        ("false", "silent"),
        (0, "silent"),
        (1, "silent"),
        (2, "silent"),
        (NAN, "silent"),
        ([True], "silent"),
        (None, "silent"),
        (np.array([True, False]), "traceback"),
    ],
    "name": [
        ("bogus", "silent"),
        ("", "silent"),
        (3, "traceback"),
        (None, "traceback"),
        (["x"], "traceback"),
        ("x" * 10**6, "traceback"),
    ],
    "seed": [
        (-1, "silent"),
        (2.5, "silent"),
        (True, "silent"),
        (NAN, "silent"),
        ("abc", "traceback"),
        ([1, 2], "traceback"),
        (2 + 0j, "silent"),
    ],
    "matrix": [
        (np.array([[0.5, 0.1], [0.0, 0.3 + 1j]]), "silent"),
        (np.array([[0.5, NAN], [0.0, 0.3]]), "silent"),
        (np.array([[0.5, INF], [0.0, 0.3]]), "silent"),
        (np.array([[True, False], [False, True]]), "silent"),
        (np.array([[0.5, 0.1, 0.0], [0.0, 0.3, 0.0]]), "traceback"),
        (np.array([0.5, 0.3]), "traceback"),
        (np.zeros((2, 2, 2)), "traceback"),
        (np.zeros((0, 0)), "traceback"),
        ([[0.5, 0.1], [0.0]], "traceback"),
        ([["a", "b"], ["c", "d"]], "traceback"),
        (np.array([[0.5, None], [0.0, 0.3]], dtype=object), "traceback"),
        ([[HUGE, 0], [0, 0.3]], "traceback"),
        ("abc", "traceback"),
        (None, "traceback"),
    ],
    "vector": [
        (np.array([0.5, 0.3 + 1j]), "silent"),
        (np.array([0.5, NAN]), "silent"),
        (np.array([INF, 0.0]), "silent"),
        (np.array([True, False]), "silent"),
        (np.array(["a", "b"]), "traceback"),
        (np.zeros(0), "traceback"),
        (np.zeros((2, 2, 2)), "traceback"),
        ([HUGE, 0.0], "traceback"),
        ("abc", "traceback"),
        (None, "traceback"),
        (np.array([0.5, None], dtype=object), "traceback"),
    ],
}
BAD["duration"] = [
    ("abc", "traceback"),
    ("-5y", "silent"),
    ("5 parsecs", "traceback"),
    ("", "traceback"),
    ("nany", "silent"),
    ("1e400y", "silent"),
    ("infy", "silent"),
    ("5y5y", "traceback"),
    ("9" * 10**6, "hang"),
    (0.0, "silent"),
    (-1.0, "silent"),
    (NAN, "silent"),
    (INF, "silent"),
    (True, "silent"),
    (2 + 1j, "silent"),
    (HUGE, "traceback"),
    (None, "traceback"),
    ([1.0], "traceback"),
]


def label(value: Any) -> str:
    """A short name of a bad value for a case name (its kind, never its full text)."""
    if isinstance(value, float) and math.isnan(value):
        return "nan"
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**30:
        digits = len(str(abs(value))) if abs(value).bit_length() < 14000 else int(abs(value).bit_length() * 0.30103) + 1
        return ("-" if value < 0 else "") + f"10^{digits - 1}"
    if isinstance(value, str) and len(value) > 24:
        return f"str[{len(value)}]"
    if isinstance(value, np.ndarray):
        if value.size > 4:
            body = "" if value.dtype.kind == "O" else f"#{zlib.crc32(value.tobytes()) % 10000:04d}"
        else:
            body = "=" + np.array2string(value.ravel(), separator=",", precision=2, max_line_width=400)
        return f"array{value.shape}:{value.dtype}" + body.replace(" ", "").replace("\n", "")
    if isinstance(value, (list, tuple)):
        inner = ", ".join(label(v) for v in value[:4]) + (", ..." if len(value) > 4 else "")
        text = ("[%s]" if isinstance(value, list) else "(%s)") % inner
        return text if len(text) <= 40 else f"{type(value).__name__}[{len(value)}]"
    if isinstance(value, dict):
        text = "{" + ", ".join(f"{label(k)}: {label(v)}" for k, v in list(value.items())[:4]) + "}"
        return text if len(text) <= 60 else f"dict[{len(value)}]"
    if isinstance(value, np.generic):
        return f"np.{type(value).__name__}({value.item()!r})"
    text = repr(value)
    return text if len(text) <= 30 else text[:27] + "..."


# --------------------------------------------------------------------------- hypothesis draws
def draw(strategy: st.SearchStrategy, n: int) -> list[Any]:
    """``n`` distinct values from ``strategy``, the same on every run (``derandomize=True``)."""
    seen: list[Any] = []
    keys: set[str] = set()

    @settings(
        max_examples=max(4 * n, 20),
        derandomize=True,
        database=None,
        phases=[Phase.generate],
        deadline=None,
        suppress_health_check=list(HealthCheck),
    )
    @given(strategy)
    def collect(value: Any) -> None:
        key = label(value) + type(value).__name__
        if key not in keys and len(seen) < n:
            keys.add(key)
            seen.append(value)

    collect()
    return seen


_non_positive = st.floats(max_value=0.0, allow_nan=False, allow_infinity=False)
_complex = st.complex_numbers(max_magnitude=1e6, allow_nan=False, allow_infinity=False).filter(lambda z: z.imag != 0)
_LETTERS = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ_-+/ .,:;!?"
_words = st.text(alphabet=_LETTERS, min_size=1, max_size=8)  # no digits: never a number or a duration
_non_number = st.one_of(_words, st.lists(st.floats(allow_nan=False), min_size=1, max_size=3))

#: Strategies of bad values per kind; :func:`bad_values` draws a few of each.
STRATEGIES: dict[str, st.SearchStrategy] = {
    "pos": st.one_of(_non_positive, _complex, _non_number),
    "nonneg": st.one_of(st.floats(max_value=-1e-300, allow_nan=False, allow_infinity=False), _complex, _non_number),
    "real": st.one_of(_complex, _non_number, st.integers(min_value=10**309, max_value=10**600)),
    "prob": st.one_of(st.floats(min_value=1.0000001, max_value=1e300), _non_positive, _complex),
    "int": st.one_of(
        st.integers(max_value=0),
        st.floats(allow_nan=False, allow_infinity=False).filter(lambda v: not float(v).is_integer()),
        _non_number,
    ),
    "int0": st.one_of(
        st.integers(max_value=-1), st.floats(allow_nan=False, allow_infinity=False).filter(lambda v: not float(v).is_integer())
    ),
    "bool": st.one_of(st.integers(), _words, st.floats(allow_nan=True)),
    "name": st.one_of(
        st.text(min_size=1, max_size=10).filter(lambda s: s.isidentifier() and s not in _NAMES_IN_USE), st.integers()
    ),
    "seed": st.one_of(st.integers(max_value=-1), st.floats(allow_nan=False).filter(lambda v: not float(v).is_integer())),
    "matrix": st.lists(
        st.lists(st.complex_numbers(max_magnitude=0.4, allow_nan=False).filter(lambda z: z.imag != 0), min_size=2, max_size=2),
        min_size=2,
        max_size=2,
    ).map(np.array),
    "vector": st.lists(
        st.complex_numbers(max_magnitude=0.4, allow_nan=False).filter(lambda z: z.imag != 0), min_size=2, max_size=2
    ).map(np.array),
    "duration": st.one_of(_words, _non_positive),
}

# names that pick a valid branch somewhere (a drawn "name" must not be one of them by chance)
_NAMES_IN_USE = {
    "modified",
    "token",
    "static",
    "eavesdropper",
    "server",
    "paper",
    "precomputation",
    "generic",
    "ideal",
    "elgamal",
    "ls",
    "bayes",
    "forgetting",
    "iv",
    "log_error",
    "logdet",
    "a_optimality",
    "asymptotic",
    "exact",
    "sic",
    "sic2",
    "closed_loop",
    "open_loop",
    "gaussian",
    "bsgs",
    "rho",
    "pari",
    "auto",
    "gram",
    "qr",
    "model",
    "measured",
    "end",
    "all",
    "guillevic",
    "small",
    "fresh",
    "shipped",
    "best",
    "final",
    "prbs",
    "colored",
    "optimal",
}

_DRAWN: dict[str, list[Any]] = {}


def bad_values(kind: str, drawn: int = 2) -> list[tuple[Any, str]]:
    """The catalogue of ``kind`` plus ``drawn`` values drawn from its strategy; a kind ending in
    ``?`` is optional (``None`` is valid and left out)."""
    optional = kind.endswith("?")
    kind = kind.rstrip("?")
    out = [(v, c) for v, c in BAD[kind] if not (optional and v is None)]
    if drawn:
        if kind not in _DRAWN:
            _DRAWN[kind] = draw(STRATEGIES[kind], 8)
        cls = "silent" if kind in ("pos", "nonneg", "prob", "int", "int0", "bool", "seed", "matrix", "vector") else "traceback"
        taken = {label(v) for v, _ in out}
        fresh = [v for v in _DRAWN[kind] if label(v) not in taken]
        out += [(v, cls) for v in fresh[:drawn]]
    return out


def explicit(values: list[Any], cls: str = "silent") -> list[tuple[Any, str]]:
    """Hand-picked bad values, all of class ``cls``."""
    return [(v, cls) for v in values]


Checker = Callable[[Any], None]


class Named:
    """A callable with a readable name (for bad ``gamma`` functions and the like)."""

    def __init__(self, name: str, fn: Callable[..., Any]) -> None:
        self.name, self.fn = name, fn

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.fn(*args, **kwargs)

    def __repr__(self) -> str:
        return self.name
