"""The identification-strategies benchmark: its pieces and a quick run end to end."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from encctl_gym.errors import ParameterError
from encctl_gym.experiments import identification_strategies as strat
from encctl_gym.experiments import reproduce
from encctl_gym.experiments.compare.settings import make_setting


def test_table_sizes_and_grid_reach_n_star_of_the_design_example() -> None:
    s = make_setting("paper-example", 0, cap=strat.DEFAULT_CAP)
    small, medium, top, capped = strat.table_sizes(s, strat.DEFAULT_CAP)
    assert (small, top, capped) == (9, 13159, False)  # n + m + 1 and N* of eq:opt_sec
    assert small < medium < top and medium == round(np.sqrt(9 * 13159))
    grid = strat.attack_lengths(s, strat.DEFAULT_CAP, 12)
    assert {small, medium, top} <= set(grid.tolist()) and grid[-1] == 13159 and np.all(np.diff(grid) > 0)
    g = make_setting("fig1-g", 0, cap=strat.DEFAULT_CAP)
    assert strat.table_sizes(g, strat.DEFAULT_CAP)[2:] == (strat.DEFAULT_CAP, True)  # N* ~ 1e6: capped


def test_quick_run_end_to_end(tmp_path: Path) -> None:
    res = strat.compute(("small",), episodes=3, cap=24, points=3, seed=1)
    names = [e.label for e in res.estimators]
    assert names == ["ls", "bayes(evidence)", "forgetting(0.999)", "iv"]
    assert res.env_check["small"] < 1e-9  # the ls estimator reproduces the environment's own epsilon
    curves = res.curves["small"]
    assert len(curves) == 4 * 4  # attackers x estimators
    for c in curves:
        assert c.errors.shape == (3, c.N.size)
        fin = np.isfinite(c.errors)
        assert fin[:, -1].all() and np.all(c.errors[fin] > 0)
    iv = next(c for c in curves if c.estimator == "iv")
    assert np.all(np.isnan(iv.errors[:, 0]))  # N = n + m + 1 = 5 is below what the instruments need
    bayes = next(c for c in curves if c.estimator.startswith("bayes") and c.attacker == "gaussian")
    ls = next(c for c in curves if c.estimator == "ls" and c.attacker == "gaussian")
    assert bayes.mean[0] < ls.mean[0]  # at N = n + m + 1 least squares interpolates the noise
    files = strat.write_csvs(res, tmp_path)
    pngs = strat.plot(res, tmp_path)
    for p in [*files, *pngs]:
        assert p.stat().st_size > 0
    assert pngs[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = list(csv.DictReader((tmp_path / "curves.csv").open()))
    assert len(rows) == 16 * curves[0].N.size and set(strat.CURVE_COLUMNS) == set(rows[0])
    sec = list(csv.DictReader((tmp_path / "security.csv").open()))
    assert len(sec) == 16
    md = strat.summary_markdown(res, command="cmd", plots=pngs)
    assert "| gaussian | ls |" in md and "paper gamma (eq:sic2)" in md and "Findings:" in md
    assert ("strategies", "encctl_gym.experiments.identification_strategies") in reproduce.STEPS


def test_security_rows_refuse_to_extrapolate_a_curve_that_does_not_fall_like_one_over_n() -> None:
    s = make_setting("small", 0, cap=40)
    N = np.array([5, 10, 20, 40, 80, 160])
    falling = strat.Curve("gaussian", False, "ls", N, np.tile(0.5 / (N - 1.0), (3, 1)))
    flat = strat.Curve("gaussian", False, "forgetting(0.5)", N, np.tile(0.5 / (N - 1.0) + 0.01, (3, 1)))
    res = strat.Result([s], [], {"small": [falling, flat]}, {"small": 0.0}, {"small": strat.table_sizes(s, 40)}, 0.0)
    by = {r["estimator"]: r for r in strat.security_rows(res)}
    assert (
        by["ls"]["N_to_gamma_c"] == 502 and by["ls"]["N_how"] == "fit, extrapolated 3.14x beyond N = 160"
    )  # floor(0.5 / 1e-3) + 2 (gamma_c = 1e-3)
    assert by["ls"]["first_below"] is None  # 0.5 / 159 > 1e-3 at N = 160
    assert by["ls"]["lambda_needed"] is not None and by["ls"]["slope"] == pytest.approx(-1.0)
    r = by["forgetting(0.5)"]  # the error levels off: no extrapolation
    assert r["N_to_gamma_c"] is None and r["N_how"].startswith("not reached") and r["lambda_needed"] is None


def test_bad_options_are_refused() -> None:
    with pytest.raises(ParameterError, match="unknown estimator 'tls'"):
        strat.compute(("small",), estimators=("tls",), episodes=2, cap=20, points=2)
    with pytest.raises(ParameterError, match="episodes must be >= 2"):
        strat.compute(("small",), episodes=1, cap=20, points=2)
    with pytest.raises(ParameterError, match="unknown preset"):
        strat.compute(("nope",), episodes=2, cap=20, points=2)


def test_a_learned_attacker_from_a_run_directory_joins(tmp_path: Path) -> None:
    pytest.importorskip("stable_baselines3")
    import json

    from encctl_gym.agents.sb3 import SB3VecEnv, algorithm_class

    env_cfg = {"preset": "small", "decipher_delay": 0, "gamma_opt": False, "max_samples": 32}
    model = algorithm_class("ppo")("MlpPolicy", SB3VecEnv(env_cfg, 2, "full"), n_steps=8, batch_size=16, seed=0, device="cpu")
    run = tmp_path / "ppo_full"
    run.mkdir()
    model.save(str(run / "model.zip"))  # an untrained policy in the format of agents.train
    config = {
        "quick": False,
        "policy": "MlpPolicy",
        "hyperparams": {"n_steps": 8, "batch_size": 16},
    }  # as agents.train records it
    (run / "run.json").write_text(json.dumps({"algo": "ppo", "observation": "full", "env": env_cfg, "config": config}))
    res = strat.compute(("small",), estimators=("ls", "bayes"), episodes=2, cap=16, points=2, runs=strat.find_runs([tmp_path]))
    learned = [c for c in res.curves["small"] if c.attacker == "ppo"]
    assert [c.estimator for c in learned] == ["ls", "bayes(evidence)"] and np.all(np.isfinite(learned[0].errors))
