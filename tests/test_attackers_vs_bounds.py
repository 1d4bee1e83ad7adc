"""The headline experiment (``compare``, :mod:`experiments.compare`): statistics, settings, the
registry, the security table, and a --quick run end to end checked against direct rollouts."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym import cli
from encctl_gym.agents import GaussianAttacker, OptimalDesignAttacker, rollout
from encctl_gym.agents.evaluate import budget_config
from encctl_gym.errors import ConfigError, ParameterError
from encctl_gym.experiments import compare as cmp
from encctl_gym.experiments.compare.cli import QUICK_EPISODES
from encctl_gym.security.design import optimal_security_parameter, sample_size_for_rate


# ------------------------------------------------------------------ statistics
def test_fit_rate_recovers_c_of_an_exact_one_over_n_curve():
    N = np.unique(np.geomspace(17, 5000, 40).astype(int))
    assert cmp.fit_rate(N, 0.0123 / (N - 1)) == pytest.approx(0.0123, rel=1e-12)
    # only the upper half of the grid counts: a transient at small N does not bias c
    transient = 0.0123 / (N - 1) * (1 + 50.0 / N**1.5 * (N < 100))
    assert cmp.fit_rate(N, transient) == pytest.approx(0.0123, rel=1e-3)


def test_samples_to_reach_measured_or_extrapolated():
    N = np.arange(10, 1001)
    mean = 0.01 / (N - 1)
    n_meas, how = cmp.samples_to_reach(N, mean, gamma_c=1e-4)
    assert how == "measured" and n_meas == 102  # first N with 0.01 / (N - 1) < 1e-4
    n_ext, how = cmp.samples_to_reach(N, mean, gamma_c=1e-6)
    assert how == "extrapolated" and n_ext == sample_size_for_rate(0.01, 1e-6) == 10_002  # strict: N - 1 > c / gamma_c


def test_paired_ratio_by_hand():
    x = np.array([1.0, 2.0, 4.0])
    y = np.array([2.0, 2.0, 2.0])
    pr = cmp.paired_ratio(x, y)
    d = np.log([0.5, 1.0, 2.0])  # mean 0, sample sd log(2)
    assert pr.mean_log == pytest.approx(0.0, abs=1e-15) and pr.ratio == pytest.approx(1.0)
    assert pr.se_log == pytest.approx(d.std(ddof=1) / math.sqrt(3))
    assert pr.low == pytest.approx(math.exp(-1.959963984540054 * pr.se_log)) and pr.high == pytest.approx(1 / pr.low)
    assert not pr.significant_below and not pr.significant_above
    with pytest.raises(ValueError):
        cmp.paired_ratio(x, y[:2])
    with pytest.raises(ValueError):
        cmp.paired_ratio(np.array([1.0, 0.0]), np.array([1.0, 1.0]))


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(1e-8, 1e3), min_size=2, max_size=30), st.floats(1e-3, 1e3))
def test_paired_ratio_of_a_scaled_sample_is_the_scale(ys, c):
    y = np.array(ys)
    pr = cmp.paired_ratio(c * y, y)
    assert pr.ratio == pytest.approx(c, rel=1e-9) and pr.se_log == pytest.approx(0.0, abs=1e-9)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.one_of(st.integers(0, 10**6), st.just("end")), min_size=1, max_size=6))
def test_parse_delays_reads_what_it_is_given(delays):
    text = ",".join(str(d) for d in delays)
    assert cmp.parse_delays(text) == tuple(dict.fromkeys(delays))


@pytest.mark.parametrize("text", ["abc", "1,x", "-1", "", "1.5", "end,"])
def test_parse_delays_rejects_anything_else(text):
    with pytest.raises(ConfigError):
        cmp.parse_delays(text)


# ------------------------------------------------------------------ settings, registry, bounds
def test_bound_rows_reproduce_the_papers_design_example():
    s = cmp.make_setting("paper-example", 0, cap=None)
    rows = {r["attacker"]: r for r in cmp.bound_rows(s)}
    paper = rows["paper gamma (eq:sic2)"]
    assert (paper["N_to_gamma_c"], paper["lambda_needed"], paper["k_needed"]) == (13159, 74, 712)
    opt = rows["gamma_opt (closed_loop)"]
    assert opt["N_to_gamma_c"] < paper["N_to_gamma_c"] < rows["gaussian design rate"]["N_to_gamma_c"]
    assert opt["lambda_needed"] == optimal_security_parameter(opt["N_to_gamma_c"], tau_c=s.base.tau_c, upsilon=s.base.upsilon)


def test_cap_and_exact_length_keep_lambda_and_the_meaning_of_the_budget_fraction():
    s = cmp.make_setting("fig1-g", 0, cap=500)
    assert s.capped and s.params.horizon == 500 and s.params.budget_limited
    assert s.params.security_parameter == s.base.security_parameter and s.base.horizon > 500
    longer = cmp.make_setting("small", 0, None, length=300)  # longer than the preset's own budget
    assert longer.capped and longer.params.horizon == 300 > longer.base.horizon and longer.params.budget_limited


def test_registry_builds_every_attacker_and_rejects_unknown_names():
    s = cmp.make_setting("small", "end", cap=None)
    atts = cmp.make_attackers(s, cmp.DEFAULT_ATTACKERS)
    assert [a.name for a in atts] == ["gaussian", "prbs", "colored(rho=0.5)", "optimal-ol"]
    assert [a.oracle for a in atts] == [False, False, False, True]
    # the stealthy attackers read delivered states: they build at an integer delay and are
    # refused with a named reason where nothing is delivered
    stealthy = [n for n in cmp.ATTACKERS if n not in cmp.DEFAULT_ATTACKERS]
    assert stealthy == ["additive", "sparse"]
    built = cmp.make_attackers(cmp.make_setting("small", 0, cap=None), stealthy)
    assert [a.name.split("(")[0] for a in built] == stealthy
    with pytest.raises(ParameterError, match="decipher_delay='end' delivers none"):
        cmp.make_attackers(s, ["additive"])
    with pytest.raises(ConfigError, match="unknown attacker 'ppo'"):
        cmp.make_attackers(s, ["gaussian", "ppo"])


def test_oracle_beats_gaussian_where_the_theory_says_so():
    """Design example, states in time: the optimal design's rate is 0.77 of the Gaussian one
    (gamma_opt); at N = 400 the paired ratio on 24 episodes must lie significantly below 1."""
    res = cmp.compute(
        ["paper-example"],
        delays=(0,),
        episodes=24,
        seed=5,
        cap=400,
        points=1,
        attackers=("gaussian", "optimal"),
        elgamal_episodes=0,
    )
    rows = {r["attacker"]: r for r in res.security}
    s = res.settings[0]
    assert s.design.rate / s.gauss.rate < 0.8
    assert rows["optimal-cl"]["ratio_to_gaussian_high"] < 1.0
    assert rows["gaussian"]["ratio_to_oracle_low"] > 1.0


# ------------------------------------------------------------------ end to end
def _fake_run(root: Path, algo: str, observation: str) -> Path:
    """A training run directory holding an untrained model (the format of agents.train)."""
    from encctl_gym.agents.sb3 import SB3VecEnv, algorithm_class

    env_cfg = {"preset": "paper-example", "decipher_delay": 0, "gamma_opt": False, "max_samples": 64}
    venv = SB3VecEnv(env_cfg, 2, observation)
    policy = "MlpLstmPolicy" if algo == "recurrent_ppo" else "MlpPolicy"
    hp = {"n_steps": 8, "batch_size": 16, **({"policy_kwargs": {"lstm_hidden_size": 4}} if algo == "recurrent_ppo" else {})}
    model = algorithm_class(algo)(policy, venv, seed=0, device="cpu", **hp)
    d = root / f"{algo}_{observation}"
    d.mkdir(parents=True)
    model.save(str(d / "model.zip"))
    config = {"quick": False, "policy": policy, "hyperparams": hp}  # what agents.train records: the model is rebuilt from it
    (d / "run.json").write_text(json.dumps({"algo": algo, "observation": observation, "env": env_cfg, "config": config}))
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
    md = (quick_run / "summary.md").read_text()
    assert "](compare_paper-example.png)" in md  # linked beside summary.md, not from the working directory
    assert "--seed 3" in md and "--quick" in md and "vs Gaussian (paired) [95% CI]" in md


def test_compare_quick_covers_every_attacker_in_both_settings(quick_run):
    curves = _rows(quick_run / "curves.csv")
    assert list(curves[0]) == list(cmp.CURVE_COLUMNS)
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
        assert float(r["gamma_opt"]) < float(r["gaussian_design"])
    per: dict[tuple[str, str], list[float]] = {}
    for r in _rows(quick_run / "episodes.csv"):
        per.setdefault((r["delay"], r["attacker"]), []).append(float(r["average_power"]))
    assert all(len(v) == QUICK_EPISODES for v in per.values())
    assert all(0.5 * 10.0 < np.mean(v) <= 10.0 + 1e-9 for v in per.values())  # the energy budget holds


def test_compare_quick_numbers_equal_direct_rollouts_on_the_same_seeds(quick_run):
    """The Gaussian and oracle rows of the tables are the errors of direct rollouts at the same
    seeds; the CSV's means and paired ratios are those of its own episodes."""
    s = cmp.make_setting("paper-example", 0, cap=60)
    sec = {(r["delay"], r["attacker"]): r for r in _rows(quick_run / "security.csv") if r["episodes"]}
    eps = _rows(quick_run / "episodes.csv")
    for name, att in (("gaussian", GaussianAttacker(s.params)), ("optimal-cl", OptimalDesignAttacker(s.params, design=s.design))):
        r = rollout(att, s.config, episodes=QUICK_EPISODES, seed=3, record=False)
        finals = [float(e["final_error"]) for e in eps if (e["delay"], e["attacker"]) == ("0", name)]
        assert finals == list(r.final_epsilon), name  # every digit (repr in the CSV)
        assert float(sec[("0", name)]["mean_error_at_horizon"]) == pytest.approx(r.mean_final(), rel=1e-15)
    curves = [
        r
        for r in _rows(quick_run / "curves.csv")
        if r["protocol"] == "fresh" and r["delay"] == "0" and r["attacker"] == "gaussian"
    ]
    grid = cmp.length_grid(s.params, 4)
    assert [int(r["N"]) for r in curves] == list(grid)
    r_small = rollout(
        GaussianAttacker(s.params), budget_config(s.config, int(grid[0])), episodes=QUICK_EPISODES, seed=3, record=False
    )
    assert float(curves[0]["mean_error"]) == pytest.approx(r_small.mean_final(), rel=1e-15)
    for (delay, name), row in sec.items():
        mine = np.array([float(e["final_error"]) for e in eps if (e["delay"], e["attacker"]) == (delay, name)])
        gauss = np.array([float(e["final_error"]) for e in eps if (e["delay"], e["attacker"]) == (delay, "gaussian")])
        assert float(row["mean_error_at_horizon"]) == pytest.approx(mine.mean(), rel=1e-12)
        if name != "gaussian":
            assert float(row["ratio_to_gaussian"]) == pytest.approx(cmp.paired_ratio(mine, gauss).ratio, rel=1e-12)
        else:
            assert row["ratio_to_gaussian"] == ""  # no ratio of the reference to itself


def test_compare_quick_security_table(quick_run):
    sec = _rows(quick_run / "security.csv")
    attackers = [r for r in sec if r["episodes"]]
    assert len(attackers) == 6 + 5
    for r in attackers:
        N_c = int(r["N_to_gamma_c"])
        assert r["N_how"] in ("measured", "extrapolated")
        assert int(r["lambda_needed"]) == optimal_security_parameter(N_c, tau_c=31536e4, upsilon=442e15)
        assert float(r["ci95_low_at_horizon"]) < float(r["mean_error_at_horizon"]) < float(r["ci95_high_at_horizon"])
    paper = [r for r in sec if r["attacker"] == "paper gamma (eq:sic2)"]
    assert paper and all((r["N_to_gamma_c"], r["lambda_needed"], r["k_needed"]) == ("13159", "74", "712") for r in paper)


def test_compare_quick_elgamal_episodes_match_the_ideal_backend(quick_run):
    rows = _rows(quick_run / "elgamal.csv")
    assert len(rows) == 6 + 5 and all(int(r["key_length"]) <= 64 for r in rows)
    for r in rows:
        assert float(r["error_elgamal"]) == pytest.approx(float(r["error_ideal_same_seed"]), rel=1e-9)


def test_compare_bad_options_are_one_line_errors(tmp_path, capsys):
    for argv, needle in (
        (["--delays", "abc"], "decipher delay 'abc'"),
        (["--episodes", "0"], "--episodes must be >= 1"),
        (["--points", "0"], "--points must be >= 1"),
        (["--attackers", "gaussian,dqn"], "unknown attacker 'dqn'"),
        (["--runs", str(tmp_path / "none")], "does not exist"),
        (["--systems", ","], "no systems"),
    ):
        assert cli.main(["compare", "--quick", "--no-progress", "--out", str(tmp_path), *argv]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and needle in err[0], (argv, err)


# ------------------------------------------------------------------ hardening
def test_compare_refuses_empty_lists_huge_counts_and_a_file_as_out(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("x")
    for argv, needle in (
        (["--delays", ""], "decipher delay ''"),
        (["--systems", ""], "no systems in ''"),
        (["--attackers", ""], "no attackers in ''"),
        (["--max-samples", "9" * 401], "--max-samples must be <= 9223372036854775807, got <integer of 1333 bits"),
        (["--points", "100000000"], "--points must be <= 60, got 100000000"),
        (["--episodes", "1000000000000"], "episodes = 1000000000000"),
        (["--out", str(afile)], "exists and is not a directory"),
    ):
        args = ["compare", "--quick", "--no-progress", "--elgamal-episodes", "0", "--out", str(tmp_path / "c"), *argv]
        assert cli.main(args) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and needle in err[0], (argv, err)
    assert afile.read_text() == "x"


def test_length_grid_has_at_most_the_horizon_points():
    s = cmp.make_setting("small", 0, cap=20)
    assert s.params.horizon == 20
    grid = cmp.length_grid(s.params, 20)  # every length from 2 (n + m) + 1 = 9 to 20 at most once
    assert grid[0] == 9 and grid[-1] == 20 and np.all(np.diff(grid) > 0) and len(grid) <= 12
    with pytest.raises(ConfigError, match="points = 21 attack lengths exceed the horizon N = 20"):
        cmp.length_grid(s.params, 21)


def test_record_bytes_by_hand():
    from encctl_gym.experiments.compare.protocol import record_bytes

    s0 = cmp.make_setting("small", 0, cap=20)  # delivered states: one running record of 20 steps too
    s_end = cmp.make_setting("small", "end", cap=20)
    atts = [GaussianAttacker(s0.params), OptimalDesignAttacker(s0.params)]
    P = len(cmp.length_grid(s0.params, 4))
    assert record_bytes([(s0, atts)], 10, 4) == 8 * 10 * (P + 2) * 2 + 16 * 10 * 20
    assert record_bytes([(s_end, atts[:1])], 10, 4) == 8 * 10 * (P + 2)
    from encctl_gym.errors import ResourceLimitError

    with pytest.raises(ResourceLimitError, match="episodes = 1000000000000"):
        cmp.compute(["small"], delays=(0,), episodes=10**12, cap=20, points=4, attackers=("gaussian",), elgamal_episodes=0)


def test_the_kernels_are_warmed_before_the_progress_bar_starts(monkeypatch):
    """The bar's rate, and so its ETA, must not include compile time: one short episode of every
    setting is played before the bar is made, and the results do not depend on it."""
    import tqdm

    from encctl_gym.experiments.compare import protocol

    events: list[str] = []
    real_warm_up, real_tqdm = protocol.warm_up, tqdm.tqdm

    def warm_up(*args, **kwargs):
        events.append("warm")
        return real_warm_up(*args, **kwargs)

    def bar(*args, **kwargs):
        events.append("bar")
        return real_tqdm(*args, **{**kwargs, "disable": True})

    monkeypatch.setattr(protocol, "warm_up", warm_up)
    monkeypatch.setattr(tqdm, "tqdm", bar)
    kw = dict(delays=(0,), episodes=4, seed=3, cap=20, points=2, attackers=("gaussian",), elgamal_episodes=1)
    with_bar = cmp.compute(["small"], progress=True, **kw)
    assert events[:2] == ["warm", "bar"], events
    plain = cmp.compute(["small"], progress=False, **kw)
    assert with_bar.security == plain.security


def test_the_wilson_interval_against_its_closed_form():
    from encctl_gym.experiments.compare.statistics import Z95, wilson_interval

    z2 = Z95 * Z95
    lo, hi = wilson_interval(0, 10)  # no success: [0, z^2 / (n + z^2)]
    assert lo == 0.0 and abs(hi - z2 / (10 + z2)) < 1e-15
    lo, hi = wilson_interval(5, 10)  # symmetric about 1/2, half-width z sqrt(n/4 + z^2/4) / (n + z^2)
    half = Z95 * (10 / 4 + z2 / 4) ** 0.5 / (10 + z2)
    assert abs(lo - (0.5 - half)) < 1e-15 and abs(hi - (0.5 + half)) < 1e-15
    assert wilson_interval(0, 0) == (0.0, 1.0)
