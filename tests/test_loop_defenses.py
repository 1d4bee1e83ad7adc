"""The defender policies with real levers (encctl_gym.loop.defenses) in the environment: audits
that never alarm on the honest controller and catch an injection at their rate, the chi-squared
detector, input noise, and refusals."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import encctl_gym  # noqa: F401  (registers the environment)
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ParameterError
from encctl_gym.loop import make_defender, make_loop
from encctl_gym.loop.defender import PlantView
from encctl_gym.loop.defenses import AuditDefender, audit_tolerance

ENV_ID = "encctl_gym/EncryptedLTIAttack-v0"
SMALL = {"preset": "small", "gamma_opt": False}


def run(defender, seed, action=None):
    env = gym.make(ENV_ID, config={**SMALL, "defender": defender})
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)  # the same actions for the same seed
    steps = 0
    while True:
        a = rng.uniform(-1, 1, size=2).astype(np.float32) if action is None else action
        _, _, term, trunc, info = env.step(a)
        steps += 1
        if term or trunc:
            return steps, info


@pytest.mark.parametrize("preset", ["small", "paper-example"])
def test_the_audit_tolerance_holds_the_honest_encrypted_controller(preset):
    """The quantised controller of the loop (eq:ec) stays within the tolerance on 20000 states
    across the encoder's range, so an audit of the honest loop never alarms."""
    p = resolve_params({"preset": preset, "gamma_opt": False})
    loop = make_loop(p.loop)
    rng = np.random.default_rng(0)
    x = rng.uniform(-p.x_bound, p.x_bound, size=(20000, p.n)) * rng.uniform(0, 1, size=(20000, 1))
    diff = np.abs(loop.control(x) - x @ loop.Phi.T)
    assert np.all(diff <= audit_tolerance(loop.Phi, x, p.delta, loop.table.max_shift))


def test_an_audit_of_the_honest_input_never_stops_the_attack_and_of_a_forged_one_always():
    p = resolve_params(SMALL)
    d = AuditDefender(rate=1.0)
    loop = make_loop(p.loop, d)
    rng = np.random.default_rng(1)
    K, T = 50, 40
    x = np.zeros((K, p.n))
    U = np.zeros((T, K, p.m))
    step = {"k": 0}
    view = PlantView(x, U, lambda: step["k"])
    d.reset(K, p.n, p.m, [np.random.default_rng(i) for i in range(K)])
    for k in range(T):  # step k: the plant is at x[k]; the input of step k - 1 was the control of x[k-1]
        step["k"] = k
        x[...] = rng.uniform(-5, 5, size=(K, p.n))
        assert d.act(view) is None
        U[k] = loop.control(x)
    step["k"] = T  # the last audit, of an input that is not the controller's
    U[T - 1] = U[T - 1] + 0.5
    x[...] = 0.0
    assert d.act(view).end
    assert d.audits == K * T  # rate 1: every copy audited at every step but the first


def test_audits_stop_an_injecting_attacker_after_a_geometric_number_of_steps():
    """Every step of the environment injects: the first audit (rate p, from the second step on,
    which checks the first) ends the attack, so the mean episode length is 1 + 1/p."""
    p_audit = 0.2
    lengths = [run({"name": "audit", "rate": p_audit}, seed)[0] for seed in range(200)]
    detected = [run({"name": "audit", "rate": p_audit}, seed)[1]["detected"] for seed in range(5)]
    assert all(detected)
    mean = float(np.mean(lengths))
    se = float(np.std(lengths) / np.sqrt(len(lengths)))
    assert abs(mean - (1 + 1 / p_audit)) < 4 * se
    steps, info = run({"name": "audit", "rate": 0.0}, 0)
    assert not info["detected"]


def test_the_chi2_detector_stops_a_large_injection_and_noise_changes_the_trajectory():
    steps, info = run({"name": "chi2", "window": 5, "false_alarm_rate": 1e-6}, 0, action=np.ones(2, dtype=np.float32))
    assert info["detected"]
    steps, info = run({"name": "cusum", "false_alarm_rate": 1e-6}, 0, action=np.ones(2, dtype=np.float32))
    assert info["detected"]
    no_noise = run({"name": "noise", "sigma_d2": 0.0}, 3)[1]
    fixed = run("fixed", 3)[1]
    assert no_noise["epsilon"] == fixed["epsilon"]  # sigma_d2 = 0 is the fixed defender, bit for bit
    noisy = run({"name": "noise", "sigma_d2": 1.0}, 3)[1]
    assert noisy["epsilon"] != fixed["epsilon"] and not noisy["detected"]


@pytest.mark.parametrize(
    "spec, match",
    [
        ({"name": "audit", "rate": 1.5}, "rate must lie in \\[0, 1\\], got 1.5"),
        ({"name": "audit", "speed": 1}, "takes no such options \\['speed'\\]"),
        ({"name": "nope"}, "unknown defender 'nope'"),
        ({"name": "noise", "sigma_d2": -1.0}, "sigma_d2"),
        ({"name": "chi2", "false_alarm_rate": 1.0}, "false_alarm_rate must lie in \\(0, 1\\)"),
        ({"name": "cusum", "false_alarm_rate": 0.0}, "false_alarm_rate must be > 0"),
        ({"name": "cusum", "variance_ratio": 1.0}, "variance_ratio must be > 1"),
    ],
)
def test_bad_defender_options_are_refused(spec, match):
    with pytest.raises(ParameterError, match=match):
        make_defender(spec)


def test_the_measured_defence_table_on_a_small_plant():
    from encctl_gym.experiments.defenses_measured import MEASURED_DEFENDERS, format_measured, measure

    rows = measure("small", episodes=1, seed=0)
    assert len(rows) == 3 * len(MEASURED_DEFENDERS)
    by = {(r["defender"], r["attacker"]): r for r in rows}
    assert all(
        by[("none", a)]["detection_rate"] == 0.0 and by[("none", a)]["time_ratio"] == 1.0 for a in ("gaussian", "ar1", "optimal")
    )
    assert all(r["detection_rate"] == 1.0 for r in rows if r["defender"].startswith("chi2"))  # every step injects
    assert all(r["samples_median"] <= r["horizon"] for r in rows)
    assert format_measured(rows).count("\n") == len(rows) + 1


@pytest.mark.slow
def test_the_detection_delay_sweep_and_its_figure_on_a_small_plant(tmp_path):
    from encctl_gym.experiments.defenses import DETECTORS, detection_delays, format_delays, plot_delays

    rows = detection_delays("small", episodes=1, seed=0, ratios=(1e-3, 100.0), max_samples=300)
    assert len(rows) == len(DETECTORS) * 2 * 3
    loud = [r for r in rows if r["power_ratio"] == 100.0]
    assert all(r["detection_rate"] == 1.0 and r["delay"][1] <= 300 for r in loud)
    assert format_delays(rows).count("\n") == len(rows) + 1
    assert plot_delays(rows, tmp_path / "delays.png").stat().st_size > 0
