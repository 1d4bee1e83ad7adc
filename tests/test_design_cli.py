"""Tests of ``encctl-gym design`` through encctl_gym.cli.main."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from encctl_gym.cli import main
from encctl_gym.errors import ParameterError, ResourceLimitError
from encctl_gym.security.cost_models import GUILLEVIC_CORRECTION
from encctl_gym.security.design_cli import load_system, parse_duration
from encctl_gym.security.report import MAX_STATE_DIMENSION, design_report
from encctl_gym.security.threat import ThreatModel


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
    res = _json(
        capsys,
        [
            "design",
            "--preset",
            "paper-example",
            "--json",
            "--tau-c",
            "1y",
            "--gamma-c",
            "1e-4",
            "--upsilon",
            "1e12",
            "--sigma-u2",
            "1",
            "--sigma-w2",
            "1",
            "--sigma-x2",
            "0",
        ],
    )
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
    [
        ("10y", 31536e4),
        ("3600s", 3600.0),
        ("5d", 432000.0),
        ("2h", 7200.0),
        ("30min", 1800.0),
        ("31536e4", 31536e4),
        ("1.5 h", 5400.0),
        ("2 years", 2 * 31536e3),
    ],
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
    _fails(capsys, ["design", str(nonnum)], "A must hold real numbers, got 'x'")
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


# --------------------------------------------------------------------------- cost models (--cost-model)
def test_cost_model_table(capsys: pytest.CaptureFixture) -> None:
    assert main(["design", "--preset", "paper-example", "--cost-model", "all"]) == 0
    out = capsys.readouterr().out
    rows = {
        line.split()[0]: line.split()
        for line in out.splitlines()
        if line.strip().split(" ")[0] in ("paper", "precomputation", "generic") and len(line.split()) == 9
    }
    assert set(rows) == {"paper", "precomputation", "generic"}
    assert rows["paper"][1:4:2] == ["13159", "712"] and rows["paper"][4] == "712"
    assert rows["precomputation"][4] == "712" and int(rows["precomputation"][3]) > 712
    assert "What a 712-bit key is worth" in out and "dlp-768" in out and "5300 core-years" in out
    assert "15360" in out  # the NIST table is shown


def test_cost_model_json_agrees_with_the_library(capsys: pytest.CaptureFixture) -> None:
    from encctl_gym.security.cost_models import PrecomputationModel
    from encctl_gym.security.key_length import design_key_length
    from encctl_gym.security.threat import ThreatModel

    res = _json(
        capsys,
        [
            "design",
            "--preset",
            "paper-example",
            "--cost-model",
            "precomputation,paper",
            "--gnfs-correction",
            "guillevic",
            "--json",
        ],
    )
    cm = res["cost_models"]
    assert list(cm["designs"]) == ["precomputation", "paper"]
    assert cm["gnfs_correction"] == GUILLEVIC_CORRECTION
    lib = design_key_length(
        13159, ThreatModel(tau_c=31536e4, upsilon=442e15, cost_model=PrecomputationModel(GUILLEVIC_CORRECTION))
    )
    assert cm["designs"]["precomputation"]["k_star"] == lib.k_star
    assert cm["designs"]["paper"]["paper_k_star"] == 712 and cm["designs"]["paper"]["k_star"] > 712
    assert cm["key_value"]["key_length"] == 712
    assert res["records"]["ratio_points"][0]["key_length"] == 768
    # the table of the paper's designs is unchanged by the cost models
    assert (res["designs"]["paper_sic2"]["N_star"], res["designs"]["paper_sic2"]["k_star"]) == (13159, 712)


def test_cost_model_for_the_robust_n_star(capsys: pytest.CaptureFixture) -> None:
    res = _json(
        capsys,
        [
            "design",
            "--preset",
            "paper-example",
            "--cost-model",
            "generic",
            "--complexity",
            "closed_loop",
            "--key-length",
            "1024",
            "--json",
        ],
    )
    assert res["cost_models"]["N_star"] == res["designs"]["closed_loop"]["N_star"]
    assert res["cost_models"]["key_value"]["key_length"] == 1024


@pytest.mark.parametrize(
    "extra,match",
    [
        (["--cost-model", "quantum"], "'quantum'"),
        (["--cost-model", "all", "--gnfs-correction", "-1"], "gnfs_correction must be finite and >= 0 bits, got -1.0"),
        (["--cost-model", "all", "--gnfs-correction", "nan"], "gnfs_correction"),
        (["--cost-model", "all", "--gnfs-correction", "inf"], "gnfs_correction"),
        (["--cost-model", "all", "--key-length", "39"], "39"),
        (["--cost-model", "all", "--key-length", "7.5"], "key_length"),
        (["--gnfs-correction", "3"], "only applies with --cost-model"),
        (["--tau-c", "1e-300"], "lam* = 1"),
        (["--upsilon", "1e400"], "upsilon"),
        (["--sigma-w2", "1" + "0" * 400], "sigma_w2"),
        (["--sdp-max-dim", "x"], "sdp_max_dim"),
    ],
)
def test_bad_cost_model_options(capsys: pytest.CaptureFixture, extra: list, match: str) -> None:
    _fails(capsys, ["design", "--preset", "paper-example", *extra], match)


def test_calibration_file_not_increasing_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    from encctl_gym.security.records import DATA_FILE

    data = json.loads(DATA_FILE.read_text())
    data["records"].append(dict(data["records"][1], name="dlp-600", key_length=600))
    path = tmp_path / "cal.json"
    path.write_text(json.dumps(data))
    _fails(
        capsys,
        ["design", "--preset", "paper-example", "--cost-model", "precomputation", "--calibration", str(path)],
        "768 followed by 600",
    )


# --------------------------------------------------------------------------- plant files: one schema, values used, sources told
def test_plant_file_values_are_used_and_sources_told(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    path = tmp_path / "plant.yaml"
    path.write_text("A: [[0.5, 0.1], [0.0, 0.3]]\nB: [[1.0], [0.5]]\nsigma_u2: 2\nsigma_w2: 0.5\ntau_c: 5y\n")
    res = _json(capsys, ["design", str(path), "--json", "--upsilon", "1e15"])
    p = res["parameters"]
    assert (p["sigma_u2"], p["sigma_w2"], p["tau_c"], p["upsilon"]) == (2.0, 0.5, 5 * 31536e3, 1e15)
    assert res["sources"] == {
        "sigma_u2": "file",
        "sigma_w2": "file",
        "tau_c": "file",
        "upsilon": "option",
        "sigma_x2": "default",
        "gamma_c": "default",
    }
    assert main(["design", str(path)]) == 0
    out = capsys.readouterr().out
    assert "values sigma_u2, sigma_w2, tau_c from the file" in out and "gamma_c" in out
    assert res["system"]["r_sigma"] == pytest.approx(4.0)


def test_large_plants_work_or_are_refused_with_a_reason(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    n = 60  # n + m = 120 > 48: the SDP rows are skipped with their estimate, the rest is computed
    path = tmp_path / "big.npz"
    np.savez(path, A=0.5 * np.eye(n) + 0.01 * np.eye(n, k=1), B=np.eye(n))
    res = _json(capsys, ["design", str(path), "--json"])
    assert set(res["skipped"]) == {"closed_loop", "open_loop"} and "n + m = 120" in res["skipped"]["closed_loop"]
    assert set(res["designs"]) == {"paper_sic2", "exact_sic", "gaussian"}
    assert main(["design", str(path)]) == 0
    assert "skipped: the A-optimal design SDP for n + m = 120" in capsys.readouterr().out
    with pytest.raises(ResourceLimitError, match=f"n = {MAX_STATE_DIMENSION + 1} states"):
        design_report(
            (0.5 * np.eye(MAX_STATE_DIMENSION + 1), np.eye(MAX_STATE_DIMENSION + 1, 1)),
            ThreatModel(gamma_c=1e-6, tau_c=1e8, upsilon=1e17, sigma_u2=1, sigma_w2=1),
        )


@pytest.mark.parametrize(
    "name,content,match",
    [
        ("unknown.json", {"A": [[0.5]], "B": [[1]], "sigma_z2": 1}, "unknown field(s) ['sigma_z2']"),
        ("bigint.json", {"A": [[10**400]], "B": [[1]]}, "beyond the float64 range"),
        ("bool.json", {"A": [[True]], "B": [[1]]}, "A must hold real numbers, got True"),
        ("str.json", {"A": [[0.5]], "B": [[1]], "sigma_u2": "ten"}, "sigma_u2 must be a number, got 'ten'"),
        ("neg.json", {"A": [[0.5]], "B": [[1]], "sigma_w2": -1}, "sigma_w2 must be > 0, got -1"),
        ("tau.json", {"A": [[0.5]], "B": [[1]], "tau_c": "5 fortnights"}, "unknown unit"),
        ("list.json", [[0.5]], "must hold a mapping"),
    ],
)
def test_bad_plant_files(tmp_path: Path, capsys: pytest.CaptureFixture, name: str, content: object, match: str) -> None:
    path = tmp_path / name
    path.write_text(json.dumps(content))
    _fails(capsys, ["design", str(path)], match)


def test_hostile_files_are_bounded(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    bomb = tmp_path / "bomb.yaml"
    lines = ["a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 8)]
    bomb.write_text("\n".join(lines) + "\nA: *a7\nB: [[1]]\n")
    assert bomb.stat().st_size < 600
    _fails(capsys, ["design", str(bomb)], "expand to more than")
    tags = tmp_path / "tags.yaml"
    tags.write_text("A: !!python/object/apply:os.system ['true']\nB: [[1]]\n")
    _fails(capsys, ["design", str(tags)], "cannot read")
    cplx = tmp_path / "complex.npz"
    np.savez(cplx, A=np.array([[0.5 + 0.1j]]), B=np.array([[1.0]]))
    _fails(capsys, ["design", str(cplx)], "A must be real, got the complex entry (0.5+0.1j) at A[0][0]")
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100000 + "]" * 100000)
    _fails(capsys, ["design", str(deep)], "cannot read")
