"""encctl_gym.agents.stopping: the stopping rule on synthetic learning curves whose answers are known by
construction, the budget scaled to the plant, and one real training run stopped by the rule."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from encctl_gym.agents.stopping import OracleStopper, StoppingRule, decide, plant_budget
from encctl_gym.errors import ConfigError

K = 32
#: t_{0.975} with 31 degrees of freedom (statistical tables).
T31 = 2.039513


def episode_noise(seed: int = 0) -> np.ndarray:
    """K numbers of mean exactly 0 and sample standard deviation exactly 1 (the same episodes at
    every evaluation: common random numbers)."""
    z = np.random.default_rng(seed).standard_normal(K)
    z -= z.mean()
    return z / z.std(ddof=1)


def curve(means: np.ndarray, spread: float = 0.02) -> np.ndarray:
    """(T, K) log ratios with the given per-evaluation means and per-episode spread."""
    return np.asarray(means)[:, None] + spread * episode_noise()[None, :]


def first_stop(rule: StoppingRule, d: np.ndarray):
    ts = np.arange(d.shape[0]) * 1000
    for t in range(1, d.shape[0] + 1):
        dec = decide(rule, ts[:t], d[:t])
        if dec.stop:
            return t - 1, dec
    return None, dec


def test_a_curve_that_converges_to_the_oracle_stops_reached_at_the_predicted_evaluation():
    rule = StoppingRule(tolerance=0.02, window=5, plateau_gain=0.0, min_evaluations=2)
    means = 0.5 * np.exp(-np.arange(40) / 4.0)
    d = curve(means, spread=0.02)
    # by hand: the upper end exp(mean + t31 * 0.02 / sqrt(32)) <= 1.02 first where mean <= log(1.02) - t31 * 0.02 / sqrt(32)
    bound = math.log(1.02) - T31 * 0.02 / math.sqrt(K)
    expected = int(np.nonzero(means <= bound)[0][0])
    at, dec = first_stop(rule, d)
    assert at == expected
    assert dec.reason == "reached" and dec.high <= 1.02
    assert dec.ratio == pytest.approx(math.exp(means[at]), rel=1e-12)


def test_a_curve_flat_above_the_oracle_stops_on_the_plateau_not_reached():
    rule = StoppingRule(tolerance=0.02, window=6, plateau_gain=0.005, min_evaluations=3)
    means = np.concatenate([np.linspace(0.6, math.log(1.10), 8), math.log(1.10) + 1e-4 * np.cos(np.arange(20))])
    at, dec = first_stop(rule, curve(means))
    assert dec.reason == "plateau"
    assert 8 <= at <= 8 + rule.window  # once a whole window lies on the flat part
    assert dec.ratio == pytest.approx(1.10, rel=1e-3)
    assert dec.slope_pessimistic is not None and -dec.slope_pessimistic * rule.window < math.log1p(0.005)


def test_a_curve_still_improving_steadily_does_not_stop():
    rule = StoppingRule(tolerance=0.02, window=5, plateau_gain=0.005)
    means = 0.5 - 0.01 * np.arange(30)  # 1 % per evaluation, never within 2 % in these 30
    at, dec = first_stop(rule, curve(means))
    assert at is None and dec.reason == "continue"
    assert dec.slope == pytest.approx(-0.01, rel=1e-9)


def test_noise_rarely_makes_an_improving_curve_look_flat():
    # a window of an improving curve (-1 % per evaluation) with 2 % evaluation-to-evaluation noise: the
    # pessimistic end of the slope's 95 % interval promises more than 0.5 % in all but a few per cent of windows
    rule = StoppingRule(tolerance=0.0, window=5, plateau_gain=0.005, min_evaluations=2)
    rng = np.random.default_rng(3)
    stops = 0
    trials = 400
    for _ in range(trials):
        means = 0.5 - 0.01 * np.arange(5) + 0.02 * rng.standard_normal(5)
        stops += decide(rule, np.arange(5), curve(means)).stop
    assert stops <= 0.05 * trials


def test_no_decision_before_min_evaluations():
    rule = StoppingRule(tolerance=0.5, min_evaluations=4)
    d = curve(np.zeros(6))
    assert [decide(rule, np.arange(t), d[:t]).stop for t in range(1, 7)] == [False, False, False, True, True, True]


def test_the_stopper_reads_a_learning_curve_against_the_oracle_and_ends_with_budget():
    class Curve:
        timesteps = np.arange(3) * 10
        epsilon = np.exp(curve(np.array([1.0, 0.8, 0.7])) - 9.0)

    oracle = np.exp(np.full(K, -9.0))
    st = OracleStopper(StoppingRule(min_evaluations=2, window=3), oracle)
    assert st(Curve) is True
    assert st.decisions[-1].ratio == pytest.approx(math.exp(0.7))
    assert st.final().reason == "budget" and st.final().stop


def test_plant_budget_scales_with_the_flatness_and_is_capped():
    assert (
        plant_budget(1.3, 1.0, iterations_per_gain=200, steps_per_iteration=1000, cap=10**9)
        == math.ceil(200 / math.log(1.3)) * 1000
    )
    flat = plant_budget(1.1, 1.0, iterations_per_gain=200, steps_per_iteration=1000, cap=10**9)
    assert flat > plant_budget(1.3, 1.0, iterations_per_gain=200, steps_per_iteration=1000, cap=10**9)
    assert plant_budget(1.01, 1.0, iterations_per_gain=200, steps_per_iteration=1000, cap=5000) == 5000
    assert plant_budget(1.0, 1.0, iterations_per_gain=200, steps_per_iteration=1000, cap=7000) == 7000
    with pytest.raises(ConfigError, match="iterations_per_gain"):
        plant_budget(1.3, 1.0, iterations_per_gain=0, steps_per_iteration=1000, cap=5000)


@pytest.mark.parametrize(
    ("kw", "match"), [({"tolerance": -0.1}, "tolerance"), ({"window": 2}, "window"), ({"min_evaluations": 1}, "min_evaluations")]
)
def test_bad_rules_are_refused(kw, match):
    with pytest.raises(ConfigError, match=match):
        StoppingRule(**kw)


@pytest.mark.slow
def test_a_real_ars_run_stops_when_the_rule_says_so(tmp_path):
    from encctl_gym.agents.config import apply_override, load_config
    from encctl_gym.agents.runs import read_run
    from encctl_gym.agents.train import train

    cfg = load_config("ars", "paper-example", quick=True)
    for item in (
        "n_timesteps=200000",
        "stopping.rule=oracle",
        "stopping.budget=fixed",
        "stopping.tolerance=1e6",  # any ratio is "within" it: stops at the first decision
        "stopping.min_evaluations=2",
        "eval.freq=4096",
    ):
        apply_override(cfg, item)
    run = train(cfg, out=tmp_path, progress=False, tensorboard=False)
    meta = read_run(run).meta
    assert meta["status"] == "stopped"
    assert meta["stopping"]["decision"]["reason"] == "reached"
    assert meta["stopping"]["decision"]["evaluation"] == 1
    assert meta["timesteps_done"] < 200000
    assert len(meta["stopping"]["curve"]) == 2
    assert json.loads((run / "run.json").read_text())["stopping"]["oracle"].startswith("optimal")


def test_the_ars_default_budget_is_scaled_to_the_plant_and_an_explicit_one_is_fixed():
    pytest.importorskip("sb3_contrib", reason="the training configurations name the rl extra's algorithms")
    from encctl_gym.agents.config import apply_override, env_config, load_config
    from encctl_gym.agents.curves import curve_for
    from encctl_gym.agents.train import training_budget
    from encctl_gym.envs.config import resolve_params

    cfg = load_config("ars", "paper-example")
    assert (cfg["stopping"]["rule"], cfg["stopping"]["budget"]) == ("oracle", "plant")
    params = resolve_params(env_config(cfg))
    c = curve_for(params, cfg["observation"], algo="ars", system="paper-example", seed=0)
    hp = cfg["hyperparams"]
    per = (2 * hp["n_delta"] + 1) * hp["n_eval_episodes"] * params.horizon
    total, how = training_budget(cfg, c)
    assert total == math.ceil(cfg["stopping"]["iterations_per_gain"] / math.log(c.gamma_gauss / c.gamma_opt)) * per
    assert how["how"] == "plant" and how["steps_per_iteration"] == per and str(total) in how["text"]
    apply_override(cfg, "stopping.budget=fixed")
    assert training_budget(cfg, c) == (cfg["n_timesteps"], {"how": "fixed", "n_timesteps": cfg["n_timesteps"]})


def test_the_stoppers_status_says_what_the_rule_is_doing():
    """Issue 34 item 6: the bar counts to the budget, a ceiling; its status says where the rule
    stands: the ratio to the oracle against its bar, then what the plateau test promises."""
    rule = StoppingRule(tolerance=0.02, window=3, plateau_gain=0.02, min_evaluations=2)
    oracle = np.exp(np.full(K, -9.0))
    st = OracleStopper(rule, oracle)
    assert "ceiling" in st.status() and "pending" in st.status()

    class Curve:
        timesteps = np.arange(1) * 10
        epsilon = np.exp(curve(np.array([0.5])) - 9.0)

    st(Curve)
    text = st.status()
    assert f"oracle ratio {math.exp(0.5):.3f}" in text and "stops at <= 1.020" in text and "1 of 2" in text
    Curve.timesteps, Curve.epsilon = np.arange(3) * 10, np.exp(curve(np.array([0.5, 0.3, 0.1])) - 9.0)
    assert st(Curve) is True
    slope_gain = -st.decisions[-1].slope_pessimistic * 3
    assert f"may gain {100 * math.expm1(slope_gain):.1f} %" in st.status() and "plateau below 2 %" in st.status()


def test_the_progress_bar_shows_the_status_as_it_changes(capsys):
    pytest.importorskip("stable_baselines3", reason="the progress bar is a stable-baselines3 callback (rl extra)")
    from encctl_gym.agents.callbacks import ProgressCallback

    said = ["first evaluation pending"]
    bar = ProgressCallback(1000, "run", status=lambda: said[0])
    bar.num_timesteps = 0
    bar._on_training_start()
    bar.num_timesteps = 400
    said[0] = "oracle ratio 1.234"
    bar._on_step()
    bar.num_timesteps = 500
    bar._on_training_end()
    err = capsys.readouterr().err
    assert "oracle ratio 1.234" in err and "500/1000" in err
