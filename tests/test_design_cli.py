"""Tests of ``encctl-gym design`` through encctl_gym.cli.main."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from encctl_gym.cli import main
from encctl_gym.errors import ParameterError
from encctl_gym.security.design_cli import load_system, parse_duration


def _json(capsys: pytest.CaptureFixture, argv: list[str]) -> dict:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_paper_example_table(capsys: pytest.CaptureFixture) -> None:
    assert main(["design", "--preset", "paper-example"]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.strip().startswith("(a)"))
    assert row.split()[-6:-3] == ["13159", "74", "712"]
    assert "tr Psi_u = 2 " in out and "tr Psi_w = 8 " in out and "= 100 " in out


def test_paper_example_json(capsys: pytest.CaptureFixture) -> None:
    res = _json(capsys, ["design", "--preset", "paper-example", "--json"])
    d = res["designs"]
    assert (d["paper_sic2"]["N_star"], d["paper_sic2"]["lam_star"], d["paper_sic2"]["k_star"]) == (13159, 74, 712)
    assert d["exact_sic"]["N_star"] == 13159
    assert res["system"]["tr_psi_w"] == pytest.approx(8) and res["system"]["r_sigma"] == pytest.approx(100)
    assert res["parameters"]["tau_c"] == 31536e4
    # the best attacker beats the paper's gamma; the Gaussian tr(Sigma^-1) bound is above it
    assert d["closed_loop"]["ratio_to_paper"] < 1 < d["gaussian"]["ratio_to_paper"]
    assert d["closed_loop"]["N_star"] <= d["open_loop"]["N_star"] <= d["gaussian"]["N_star"]
    assert res["bounds"]["input_upper_bound"] == pytest.approx(8 / (13158 * 4 * 100))


def test_options_override_preset(capsys: pytest.CaptureFixture) -> None:
    res = _json(capsys, ["design", "--preset", "paper-example", "--json", "--tau-c", "1y", "--gamma-c", "1e-4",
                         "--upsilon", "1e12", "--sigma-u2", "1", "--sigma-w2", "1", "--sigma-x2", "0"])
    p = res["parameters"]
    assert (p["tau_c"], p["gamma_c"], p["upsilon"], p["sigma_u2"], p["sigma_x2"]) == (31536e3, 1e-4, 1e12, 1.0, 0.0)
    # sigma_x2 = 0: eq:sic equals eq:sic2
    assert res["designs"]["exact_sic"]["N_star"] == res["designs"]["paper_sic2"]["N_star"]
    N = res["designs"]["paper_sic2"]["N_star"]
    assert N == int(8 / (1e-4 * (1 * (2 + 4) + 8))) + 2


def test_figure1_preset(capsys: pytest.CaptureFixture) -> None:
    res = _json(capsys, ["design", "--preset", "fig1-c", "--json"])
    assert res["system"]["tr_psi_u"] == pytest.approx(8, rel=1e-3)


@pytest.mark.parametrize("fmt", ["json", "yaml", "npz"])
def test_system_files(tmp_path: Path, capsys: pytest.CaptureFixture, fmt: str) -> None:
    A, B = [[0.5, 0.1], [0.0, 0.3]], [[1.0], [0.5]]
    path = tmp_path / f"sys.{fmt}"
    if fmt == "json":
        path.write_text(json.dumps({"A": A, "B": B}))
    elif fmt == "yaml":
        path.write_text("A:\n  - [0.5, 0.1]\n  - [0.0, 0.3]\nB:\n  - [1.0]\n  - [0.5]\n")
    else:
        np.savez(path, A=np.array(A), B=np.array(B))
    A2, B2 = load_system(path)
    np.testing.assert_array_equal(A2, A)
    res = _json(capsys, ["design", str(path), "--json"])
    assert (res["system"]["n"], res["system"]["m"]) == (2, 1)
    assert res["designs"]["paper_sic2"]["N_star"] >= 2


@pytest.mark.parametrize(
    "text,seconds",
    [("10y", 31536e4), ("3600s", 3600.0), ("5d", 432000.0), ("2h", 7200.0), ("30min", 1800.0), ("31536e4", 31536e4),
     ("1.5 h", 5400.0), ("2 years", 2 * 31536e3)],
)
def test_parse_duration(text: str, seconds: float) -> None:
    assert parse_duration(text) == pytest.approx(seconds)


@pytest.mark.parametrize("text", ["10m", "abc", "-5s", "0y", "1e400", "5 fortnights"])
def test_parse_duration_rejects(text: str) -> None:
    with pytest.raises(ParameterError, match="tau_c"):
        parse_duration(text)


def _fails(capsys: pytest.CaptureFixture, argv: list[str], match: str) -> None:
    assert main(argv) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert err.startswith("encctl-gym design: error:") and "\n" not in err, err
    assert match in err
    assert "Traceback" not in captured.err


def test_bad_inputs(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    _fails(capsys, ["design", str(tmp_path / "missing.json")], "does not exist")
    bad = tmp_path / "broken.json"
    bad.write_text('{"A": [[0.5,')
    _fails(capsys, ["design", str(bad)], "cannot read")
    nokey = tmp_path / "nokey.yaml"
    nokey.write_text("A: [[0.5]]\n")
    _fails(capsys, ["design", str(nokey)], "'A' and 'B'")
    txt = tmp_path / "sys.txt"
    txt.write_text("A = 1")
    _fails(capsys, ["design", str(txt)], ".json, .yaml")
    shape = tmp_path / "shape.json"
    shape.write_text(json.dumps({"A": [[0.5, 0], [0, 0.5]], "B": [[1, 2, 3]]}))
    _fails(capsys, ["design", str(shape)], "B must have shape")
    nonnum = tmp_path / "nonnum.json"
    nonnum.write_text(json.dumps({"A": [["x"]], "B": [[1]]}))
    _fails(capsys, ["design", str(nonnum)], "not a numeric matrix")
    unstable = tmp_path / "unstable.npz"
    np.savez(unstable, A=np.array([[1.2]]), B=np.array([[1.0]]))
    _fails(capsys, ["design", str(unstable)], "spectral radius 1.2")
    _fails(capsys, ["design"], "SYSTEM_FILE")
    _fails(capsys, ["design", str(shape), "--preset", "fig1-c"], "not both")
    _fails(capsys, ["design", "--preset", "paper-example", "--gamma-c", "0"], "gamma_c must be > 0")
    _fails(capsys, ["design", "--preset", "paper-example", "--sigma-w2", "-1"], "sigma_w2")
    _fails(capsys, ["design", "--preset", "paper-example", "--sigma-x2", "-1"], "sigma_x2")
    _fails(capsys, ["design", "--preset", "paper-example", "--upsilon", "fast"], "upsilon must be a number")
    _fails(capsys, ["design", "--preset", "paper-example", "--upsilon", "nan"], "upsilon")
    _fails(capsys, ["design", "--preset", "paper-example", "--tau-c", "10 months"], "unknown unit")
