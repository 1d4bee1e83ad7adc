"""Bad inputs to the base checks, the duration parser, presets and plant files: a clear package error
that names the value, never a traceback, a silent truncation or a hang (issue: hardening).

The design command's side of the same classes is in ``tests/test_design_cli.py``.
"""

from __future__ import annotations

import json
import math
import re
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from encctl_gym._validation import (
    as_finite_array,
    check_bool,
    check_int,
    check_nonnegative,
    check_positive,
    check_system,
    format_value,
    parse_number,
)
from encctl_gym.errors import ConfigError, EncctlError, ParameterError, ResourceLimitError
from encctl_gym.plant_file import MAX_YAML_NODES, PLANT_FIELDS, load_plant_file
from encctl_gym.presets import PAPER_DESIGN_EXAMPLE, design_defaults, get_preset
from encctl_gym.security.exact import binary_fraction, decimal_fraction, floor_log2, log2_fraction, pow2
from encctl_gym.units import SECONDS_PER_UNIT, parse_duration


# --------------------------------------------------------------------------- messages can always be built
@settings(max_examples=60, deadline=None)
@given(
    st.one_of(
        st.integers(min_value=-(10**6000), max_value=10**6000),
        st.text(max_size=5000),
        st.lists(st.integers(min_value=-(10**5000), max_value=10**5000), max_size=50),
        st.floats(allow_nan=True, allow_infinity=True),
        st.fractions(),
        st.complex_numbers(),
        st.dictionaries(st.text(max_size=20), st.integers(), max_size=20),
    )
)
def test_format_value_never_fails_and_stays_short(value: object) -> None:
    text = format_value(value)
    assert isinstance(text, str) and len(text) <= 400


def test_format_value_of_huge_integers() -> None:
    text = format_value(10**5000)  # str() of it raises ValueError (the 4300-digit limit)
    assert text == "<integer of 16610 bits, about 5001 digits>"
    assert format_value(-(10**400)).startswith("-<integer of 1329 bits")
    assert format_value(12345) == "12345"
    assert format_value(np.zeros((1000, 1000))).startswith("<array of shape (1000, 1000), dtype float64")


@pytest.mark.parametrize(
    "call",
    [
        lambda: check_int("N", -(10**5000), 0),
        lambda: check_int("N", 10**5000, 0, 100),
        lambda: check_positive("sigma_u2", 10**5000),
        lambda: check_positive("sigma_u2", -(10**5000)),
        lambda: check_nonnegative("sigma_x2", 10**400),
        lambda: decimal_fraction("upsilon", 10**400),
        lambda: parse_number("upsilon", "1" + "0" * 5000),
    ],
)
def test_huge_integers_give_a_one_line_error(call) -> None:
    with pytest.raises(ParameterError) as info:
        call()
    assert "bits" in str(info.value) or "float64" in str(info.value)
    assert "\n" not in str(info.value)


# --------------------------------------------------------------------------- complex, boolean, string data
@settings(max_examples=40, deadline=None)
@given(
    hnp.arrays(
        np.complex128,
        hnp.array_shapes(min_dims=1, max_dims=2, max_side=4),
        elements=st.complex_numbers(max_magnitude=10, allow_nan=False),
    )
)
def test_complex_arrays_are_refused_not_truncated(arr: np.ndarray) -> None:
    with pytest.raises(ParameterError, match="A must be real, got a complex array"):
        as_finite_array("A", arr)


@pytest.mark.parametrize(
    "value,match",
    [
        ([1 + 2j, 3.0], "complex"),
        ([[0.5 + 0j]], "complex"),  # a zero imaginary part is still a complex input
        (np.array([True, False]), "boolean"),
        (["1.5", "2"], "numeric"),
        ([[10**400]], "float64 range"),
        ([1, None], "numeric"),
        ([[1, 2], [3]], "numeric"),
    ],
)
def test_bad_arrays(value: object, match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        as_finite_array("x", value)
    with pytest.raises(ParameterError):
        check_system(value, [[1.0]])


@pytest.mark.parametrize("bad", ["no", "yes", "False", 0, 1, None, "abc", math.nan, -1, [True]])
def test_booleans_must_be_booleans(bad: object) -> None:
    with pytest.raises(ParameterError, match="flag must be True or False") as info:
        check_bool("flag", bad)
    assert format_value(bad) in str(info.value)
    assert check_bool("flag", True) is True and check_bool("flag", np.bool_(False)) is False


# --------------------------------------------------------------------------- durations: one parser
@settings(max_examples=60, deadline=None)
@given(
    st.floats(1e-3, 1e6),
    st.sampled_from(
        [
            ("s", "s"),
            ("sec", "s"),
            ("min", "min"),
            ("minutes", "min"),
            ("h", "h"),
            ("hours", "h"),
            ("d", "d"),
            ("days", "d"),
            ("y", "y"),
            ("yr", "y"),
            ("years", "y"),
        ]
    ),
    st.sampled_from(["", " "]),
)
def test_parse_duration_units(value: float, unit: tuple, space: str) -> None:
    text = f"{value!r}{space}{unit[0]}"
    assert parse_duration(text) == pytest.approx(value * SECONDS_PER_UNIT[unit[1]], rel=1e-15)


def test_parse_duration_values() -> None:
    assert parse_duration("10y") == 31536e4 == parse_duration(31536e4) == parse_duration("31536e4")
    assert parse_duration("5y", "tau_c") == 5 * 365 * 86400


@pytest.mark.parametrize(
    "bad", ["10m", "abc", "-5s", "0y", "1e400", "1e308y", "5 fortnights", "", True, None, [5], 10**400, math.inf, "9" * 10000]
)
def test_parse_duration_rejects(bad: object) -> None:
    with pytest.raises(ParameterError, match="tau_c") as info:
        parse_duration(bad)
    assert len(str(info.value)) < 400


@pytest.mark.parametrize("text", ["0y", "0.0 h", "1e-400s"])
def test_a_zero_duration_names_the_text(text: str) -> None:
    # "1e-400s" underflows to 0 s: the message shows what was typed, not the float 0.0
    with pytest.raises(ParameterError, match=f"tau_c must be > 0 s, got {re.escape(repr(text))}"):
        parse_duration(text)
    assert parse_duration("1e-300s") == 1e-300  # tiny but positive: valid


# --------------------------------------------------------------------------- presets and the paper's constants
@pytest.mark.parametrize("bad", [["small"], None, 3, "figure1"])
def test_unknown_presets(bad: object) -> None:
    with pytest.raises(ParameterError, match="unknown preset") as info:
        get_preset(bad)
    assert format_value(bad) in str(info.value)


def test_paper_constants_live_in_one_place() -> None:
    p = get_preset("paper-example")
    d = design_defaults()
    for key in ("sigma_u2", "sigma_w2", "sigma_x2", "gamma_c", "tau_c", "upsilon"):
        assert d[key] == PAPER_DESIGN_EXAMPLE[key] == getattr(p, key), key


# --------------------------------------------------------------------------- exact arithmetic rules
def test_decimal_and_binary_rules() -> None:
    assert decimal_fraction("x", 0.1) == Fraction(1, 10)
    assert binary_fraction("x", 0.1) == Fraction(0.1) != Fraction(1, 10)
    with pytest.raises(ParameterError, match="NaN"):
        binary_fraction("gamma(5)", math.nan)
    assert floor_log2(Fraction(1024)) == 10 and floor_log2(Fraction(1023)) == 9 and floor_log2(Fraction(1, 3)) == -2
    assert pow2(74) == 2**74 and pow2(0.5) == Fraction(2.0**0.5)
    assert pow2(5000.25) == Fraction(2.0**0.25) * 2**5000  # beyond the float range, still exact


@pytest.mark.parametrize(
    "bad,match",
    [
        (1.5, "exact number.*1.5"),
        ("a", "exact number.*'a'"),
        (None, "exact number.*None"),
        (True, "exact number.*True"),
        (0, "positive.*0"),
        (Fraction(-1, 2), r"positive.*Fraction\(-1, 2\)"),
    ],
)
def test_exact_logarithms_take_exact_positive_numbers(bad: object, match: str) -> None:
    # a float is refused: whether 1.5 stands for its decimal or its binary value is the caller's rule
    for fn in (floor_log2, log2_fraction):
        with pytest.raises(ParameterError, match=match):
            fn(bad)  # type: ignore[arg-type]


def test_exact_logarithms_of_integers_and_huge_fractions() -> None:
    assert floor_log2(1) == 0 and floor_log2(np.int64(1025)) == 10
    assert log2_fraction(8) == 3.0
    # 2^5000 / 3 is beyond the float range: log2 = 5000 - log2(3), by hand
    assert log2_fraction(Fraction(2**5000, 3)) == pytest.approx(5000 - math.log2(3), abs=1e-9)
    assert floor_log2(Fraction(2**5000, 3)) == 4998


# --------------------------------------------------------------------------- plant files
def _write(tmp_path: Path, name: str, data: object) -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


def test_plant_file_spec_tells_the_sources(tmp_path: Path) -> None:
    path = _write(tmp_path, "p.json", {"A": [[0.5]], "B": [0.2], "sigma_u2": 3, "tau_c": "2d"})
    spec = load_plant_file(path)
    assert spec.from_file == ("A", "B", "sigma_u2", "tau_c")
    assert spec.from_defaults == ("sigma_w2", "sigma_x2", "gamma_c", "upsilon")
    assert spec.preset.sigma_u2 == 3.0 and spec.preset.tau_c == 2 * 86400.0
    assert spec.B.shape == (1, 1) and spec.values()["upsilon"] == design_defaults()["upsilon"]
    assert "defaults: sigma_w2" in spec.describe_sources()
    own = load_plant_file(path, defaults=get_preset("small"))
    assert own.preset.gamma_c == get_preset("small").gamma_c


def test_plant_file_npz_scalars_and_strings(tmp_path: Path) -> None:
    path = tmp_path / "p.npz"
    np.savez(path, A=np.array([[0.5]]), B=np.array([[1.0]]), sigma_w2=np.array(0.2), tau_c=np.array("5y"))
    spec = load_plant_file(path)
    assert spec.preset.sigma_w2 == 0.2 and spec.preset.tau_c == 5 * 31536e3
    np.savez(path, A=np.array([[0.5]]), B=np.array([[1.0]]), sigma_w2=np.array([0.2, 0.3]))
    with pytest.raises(ConfigError, match="sigma_w2 must be a single value"):
        load_plant_file(path)
    np.savez(path, A=np.array([[True]]), B=np.array([[1.0]]))
    with pytest.raises(ConfigError, match="dtype bool"):
        load_plant_file(path)


def test_plant_file_bounds(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import encctl_gym.plant_file as pf

    path = _write(tmp_path, "p.json", {"A": [[0.5]], "B": [[1.0]]})
    monkeypatch.setattr(pf, "MAX_FILE_BYTES", 10)
    with pytest.raises(ResourceLimitError, match="bytes, more than MAX_FILE_BYTES = 10"):
        load_plant_file(path)
    monkeypatch.undo()
    recursive = tmp_path / "r.yaml"
    recursive.write_text("A: &x [*x]\nB: [[1]]\n")
    with pytest.raises(ConfigError, match="recursive alias"):
        load_plant_file(recursive)
    assert MAX_YAML_NODES >= 2 * 1000 * 1000  # room for a 1000 x 1000 matrix written out
    with pytest.raises(ConfigError, match="must end in"):
        load_plant_file(_write(tmp_path, "p.txt", {}))
    assert set(PLANT_FIELDS) == {"A", "B", "C", "sigma_v2", "sigma_u2", "sigma_w2", "sigma_x2", "gamma_c", "tau_c", "upsilon"}


def test_every_plant_file_error_is_a_package_error(tmp_path: Path) -> None:
    cases = [
        '{"A": [[0.5]], "B": [[1]], "gamma_c": [1]}',
        '{"A": 5, "B": [[1]]}',
        '{"A": [[0.5]]}',
        '{"A": [[0.5]], "B": [[1]], "upsilon": 1e999}',
        '{"A": [[1e999]], "B": [[1]]}',
        "not json",
        '{"A": [[0.5, 1]], "B": [[1]]}',
        '{"A": [[0.5]], "B": [[1]], "sigma_x2": -0.1}',
    ]
    for i, text in enumerate(cases):
        path = tmp_path / f"c{i}.json"
        path.write_text(text)
        with pytest.raises(EncctlError) as info:
            load_plant_file(path)
        assert str(path) in str(info.value), text


# --------------------------------------------------------------------------- plant files: entries, YAML floats, duplicates
@pytest.mark.parametrize(
    "text,match",
    [
        ('{"A": [[0.5, 0], [0, NaN]], "B": [[1], [0]]}', r"A must hold finite numbers, got nan at A\[1\]\[1\]"),
        ('{"A": [[0.5, Infinity], [0, 0.3]], "B": [[1], [0]]}', r"A must hold finite numbers, got inf at A\[0\]\[1\]"),
        ('{"A": [[0.5, 0], [0, 0.3]], "B": [[1], ["x"]]}', r"B must hold real numbers, got 'x' at B\[1\]\[0\]"),
    ],
)
def test_plant_file_names_the_bad_entry(tmp_path: Path, text: str, match: str) -> None:
    path = tmp_path / "p.json"
    path.write_text(text)
    with pytest.raises(ConfigError, match=match) as info:
        load_plant_file(path)
    assert "\n" not in str(info.value)


def test_plant_file_npz_entries(tmp_path: Path) -> None:
    path = tmp_path / "p.npz"
    np.savez(path, A=np.array([[0.5, 0.0], [0.1j, 0.3]]), B=np.ones((2, 1)))
    with pytest.raises(ConfigError, match=r"A must be real, got the complex entry 0.1j at A\[1\]\[0\]"):
        load_plant_file(path)
    np.savez(path, A=np.array([[0.5, 0.0], [0.0, 0.3]], dtype=complex), B=np.ones((2, 1)))  # a zero imaginary part
    with pytest.raises(ConfigError, match="A must be real, got an array of dtype complex128"):
        load_plant_file(path)
    np.savez(path, A=np.array([[0.5, 0.0], [0.0, 0.3]]), B=np.array([[1.0], [np.nan]]))
    with pytest.raises(ConfigError, match=r"B must hold finite numbers, got nan at B\[1\]\[0\]") as info:
        load_plant_file(path)
    assert "\n" not in str(info.value)


def test_plant_file_yaml_reads_exponents_as_numbers(tmp_path: Path) -> None:
    # YAML 1.1 (PyYAML) would read 1e-6 and 442e15 as strings and refuse them; JSON and the CLI read numbers
    path = tmp_path / "p.yaml"
    path.write_text("A: [[5e-1]]\nB: [[1E0]]\nsigma_w2: 1e-6\nupsilon: 442e15\ngamma_c: 1.5e-3\nsigma_u2: '10'\n")
    with pytest.raises(ConfigError, match="sigma_u2 must be a number, got '10'"):  # a quoted value stays a string
        load_plant_file(path)
    path.write_text("A: [[5e-1]]\nB: [[1E0]]\nsigma_w2: 1e-6\nupsilon: 442e15\ngamma_c: 1.5e-3\n")
    spec = load_plant_file(path)
    assert spec.A[0, 0] == 0.5 and spec.B[0, 0] == 1.0
    assert (spec.preset.sigma_w2, spec.preset.upsilon, spec.preset.gamma_c) == (1e-6, 442e15, 1.5e-3)


@pytest.mark.parametrize(
    "name,text", [("p.json", '{"A": [[0.5]], "B": [[1]], "A": [[0.9]]}'), ("p.yaml", "A: [[0.5]]\nB: [[1]]\nA: [[0.9]]\n")]
)
def test_plant_file_refuses_a_field_given_twice(tmp_path: Path, name: str, text: str) -> None:
    # the readers would keep the last A silently
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ConfigError, match="field 'A' is given more than once"):
        load_plant_file(path)


@pytest.mark.parametrize(
    "bad,match",
    [
        (42, "defaults must be a mapping.*got 42"),
        ("abc", "defaults must be a mapping.*got 'abc'"),
        ({"bogus": 1}, r"defaults has unknown field\(s\) \['bogus'\]"),
    ],
)
def test_plant_file_defaults_are_checked(tmp_path: Path, bad: object, match: str) -> None:
    path = _write(tmp_path, "p.json", {"A": [[0.5]], "B": [[1.0]]})
    with pytest.raises(ParameterError, match=match):
        load_plant_file(path, defaults=bad)  # type: ignore[arg-type]


def test_plant_file_reports_every_missing_field_at_once(tmp_path: Path) -> None:
    path = _write(tmp_path, "p.json", {"A": [[0.5]], "B": [[1.0]], "sigma_u2": 2.0})
    with pytest.raises(
        ConfigError, match="sigma_w2, sigma_x2, gamma_c, tau_c, upsilon are neither in the file nor in the defaults"
    ):
        load_plant_file(path, defaults={})
    spec = load_plant_file(path, defaults={"sigma_w2": 0.5, "sigma_x2": 0, "gamma_c": 0.1, "tau_c": "2h", "upsilon": 1e9})
    assert spec.values() == {"sigma_u2": 2.0, "sigma_w2": 0.5, "sigma_x2": 0.0, "gamma_c": 0.1, "tau_c": 7200.0, "upsilon": 1e9}
    assert spec.from_file == ("A", "B", "sigma_u2") and spec.from_defaults == (
        "sigma_w2",
        "sigma_x2",
        "gamma_c",
        "tau_c",
        "upsilon",
    )
