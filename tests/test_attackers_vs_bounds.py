"""The headline experiment (``compare``): fits, the security table, and a --quick run end to end."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from encctl_gym import cli
from encctl_gym.security.design import optimal_security_parameter, sample_size_for_rate
from experiments import attackers_vs_bounds as avb


# ------------------------------------------------------------------ pieces
def test_fit_rate_recovers_c_of_an_exact_one_over_n_curve():
    N = np.unique(np.geomspace(17, 5000, 40).astype(int))
    assert avb.fit_rate(N, 0.0123 / (N - 1)) == pytest.approx(0.0123, rel=1e-12)
    # only the upper half of the grid counts: a transient at small N does not bias c
    transient = 0.0123 / (N - 1) * (1 + 50.0 / N**1.5 * (N < 100))
    assert avb.fit_rate(N, transient) == pytest.approx(0.0123, rel=1e-3)


def test_samples_to_reach_measured_or_extrapolated():
    N = np.arange(10, 1001)
    mean = 0.01 / (N - 1)
    n_meas, how = avb.samples_to_reach(N, mean, gamma_c=1e-4)
    assert how == "measured" and n_meas == 102  # first N with 0.01 / (N - 1) < 1e-4
    n_ext, how = avb.samples_to_reach(N, mean, gamma_c=1e-6)
    assert how == "extrapolated" and n_ext == sample_size_for_rate(0.01, 1e-6) == 10_002  # strict: N - 1 > c / gamma_c


def test_bound_rows_reproduce_the_papers_design_example():
    s = avb.make_setting("paper-example", 0, cap=None)
    rows = {r["attacker"]: r for r in avb.bound_rows(s)}
    paper = rows["paper gamma (eq:sic2)"]
    assert (paper["N_to_gamma_c"], paper["lambda_needed"], paper["k_needed"]) == (13159, 74, 712)
    opt = rows["gamma_opt (closed_loop)"]
    assert opt["N_to_gamma_c"] < paper["N_to_gamma_c"] < rows["gaussian design rate"]["N_to_gamma_c"]
    assert opt["lambda_needed"] == optimal_security_parameter(opt["N_to_gamma_c"], tau_c=s.base.tau_c, upsilon=s.base.upsilon)


def test_cap_keeps_lambda_and_the_meaning_of_the_budget_fraction():
    s = avb.make_setting("fig1-g", 0, cap=500)
    assert s.capped and s.params.horizon == 500 and s.params.budget_limited
    assert s.params.security_parameter == s.base.security_parameter and s.base.horizon > 500


# ------------------------------------------------------------------ end to end
def _fake_run(root: Path, algo: str, observation: str) -> Path:
    """A training run directory holding an untrained model (the format of agents.train)."""
    from agents.sb3 import SB3VecEnv, algorithm_class

    env_cfg = {"preset": "paper-example", "decipher_delay": 0, "gamma_opt": False, "max_samples": 64}
    venv = SB3VecEnv(env_cfg, 2, observation)
    policy = "MlpLstmPolicy" if algo == "recurrent_ppo" else "MlpPolicy"
    kw = {"policy_kwargs": {"lstm_hidden_size": 4}} if algo == "recurrent_ppo" else {}
    model = algorithm_class(algo)(policy, venv, n_steps=8, batch_size=16, seed=0, device="cpu", **kw)
    d = root / f"{algo}_{observation}"
    d.mkdir(parents=True)
    model.save(str(d / "model.zip"))
    (d / "run.json").write_text(json.dumps({"algo": algo, "observation": observation, "env": env_cfg, "config": {"quick": False}}))
    return d


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory) -> Path:
    pytest.importorskip("stable_baselines3")
    tmp = tmp_path_factory.mktemp("compare")
    runs = tmp / "runs"
    _fake_run(runs, "ppo", "full")
    _fake_run(runs, "recurrent_ppo", "blind")
    out = tmp / "out"
    rc = cli.main(["compare", "--quick", "--out", str(out), "--seed", "3", "--runs", str(runs), "--no-progress"])
    assert rc == 0
    return out


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def test_compare_quick_writes_png_csv_and_summary(quick_run):
    for name in ("compare_paper-example.png", "pacing_paper-example.png"):
        png = quick_run / name
        assert png.exists() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for name in ("curves.csv", "episodes.csv", "security.csv", "elgamal.csv", "summary.md"):
        assert (quick_run / name).stat().st_size > 0
    md = (quick_run / "summary.md").read_text()
    assert "compare_paper-example.png" in md and "--seed 3" in md and "--quick" in md


def test_compare_quick_covers_every_attacker_in_both_settings(quick_run):
    curves = _rows(quick_run / "curves.csv")
    assert list(curves[0]) == list(avb.CURVE_COLUMNS)
    seen = {(r["delay"], r["attacker"]) for r in curves if r["protocol"] == "fresh"}
    assert {(r["delay"], r["protocol"]) for r in curves} == {("0", "fresh"), ("0", "along"), ("end", "fresh")}
    for r in curves:
        if r["protocol"] == "along":
            assert 0.0 <= float(r["energy_fraction"]) <= 1.0 + 1e-9
    base = {"gaussian", "prbs", "colored(rho=0.5)"}
    assert {a for d, a in seen if d == "0"} == base | {"optimal-cl", "ppo", "recurrent_ppo-blind"}
    # a policy that reads states is not run blind; the blind one is
    assert {a for d, a in seen if d == "end"} == base | {"optimal-ol", "recurrent_ppo-blind"}
    for r in curves:
        assert float(r["mean_error"]) > 0 and float(r["gamma"]) > 0 and float(r["gamma_opt"]) > 0
        assert float(r["gamma_opt"]) < float(r["gaussian_design"])
    eps = _rows(quick_run / "episodes.csv")
    per = {}
    for r in eps:
        per.setdefault((r["delay"], r["attacker"]), []).append(float(r["average_power"]))
    assert all(len(v) == avb.QUICK_EPISODES for v in per.values())
    assert all(0.5 * 10.0 < np.mean(v) <= 10.0 + 1e-9 for v in per.values())  # the energy budget holds


def test_compare_quick_security_table(quick_run):
    sec = _rows(quick_run / "security.csv")
    attackers = [r for r in sec if r["episodes"]]
    assert len(attackers) == 6 + 5
    for r in attackers:
        N_c = int(r["N_to_gamma_c"])
        assert r["N_how"] in ("measured", "extrapolated")
        assert int(r["lambda_needed"]) == optimal_security_parameter(N_c, tau_c=31536e4, upsilon=442e15)
    paper = [r for r in sec if r["attacker"] == "paper gamma (eq:sic2)"]
    assert paper and all((r["N_to_gamma_c"], r["lambda_needed"], r["k_needed"]) == ("13159", "74", "712") for r in paper)


def test_compare_quick_elgamal_episodes_match_the_ideal_backend(quick_run):
    rows = _rows(quick_run / "elgamal.csv")
    assert len(rows) == 6 + 5 and all(int(r["key_length"]) <= 64 for r in rows)
    for r in rows:
        assert float(r["error_elgamal"]) == pytest.approx(float(r["error_ideal_same_seed"]), rel=1e-9)
