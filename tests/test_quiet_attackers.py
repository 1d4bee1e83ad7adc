"""The design's sparse and passive attackers and the confidentiality floor (issue 30, item 3):
the closed forms by hand, the sparse attacker measured in the environment against them, and the
design's audit rate, key floor and output."""

from __future__ import annotations

import math

import numpy as np
import pytest

from encctl_gym import cli
from encctl_gym.errors import ParameterError
from encctl_gym.experiments.compare.statistics import wilson_interval
from encctl_gym.presets import get_preset
from encctl_gym.security.defense_design import DefenderCosts, design_defenses
from encctl_gym.security.defenses import undetected_probability
from encctl_gym.security.quiet_attackers import (
    DEFAULT_INPUT_BOUND_SIGMAS,
    NIST_FLOOR,
    NIST_FLOOR_AFTER_2030,
    check_confidentiality_floor,
    fewest_falsified_steps,
    passive_samples,
    sparse_audit_rate,
)
from encctl_gym.security.stealth import identification_rate
from encctl_gym.security.threat import ThreatModel


def test_the_fewest_falsified_steps_by_hand():
    # n = m = 1, Phi = -0.3: tr(I + Phi Phi^T) = 1.09; 0.1 * 1.09 / (2 * 2^2 * 1e-3) = 13.625 -> 14
    f = fewest_falsified_steps([[0.5]], [[1.0]], [[-0.3]], sigma_w2=0.1, gamma_c=1e-3, input_bound=2.0)
    assert (f.steps, f.excitation_trace, f.input_bound) == (14, pytest.approx(1.09), 2.0)
    # twice the bound: a quarter of the steps (ceil of 3.40625)
    assert fewest_falsified_steps([[0.5]], [[1.0]], [[-0.3]], sigma_w2=0.1, gamma_c=1e-3, input_bound=4.0).steps == 4
    # never fewer than m: B's m columns each need an excited step
    big = fewest_falsified_steps(np.eye(3) * 0.5, np.eye(3), np.zeros((3, 3)), sigma_w2=1e-6, gamma_c=1.0, input_bound=10.0)
    assert big.steps == 3


def _sparse_fraction(A, B, Phi, sigma_w2, gamma_c, u_max, N):
    """The smallest fraction q (bisected in log) whose mean excitation q u_max^2 I reaches gamma_c
    in N samples by the closed form c(q) / (N - 1)."""
    lo, hi = 1e-9, 1.0
    for _ in range(100):
        mid = math.sqrt(lo * hi)
        Sd = mid * u_max * u_max * np.eye(np.shape(B)[1])
        ok = identification_rate(A, B, Phi, sigma_w2=sigma_w2, Sigma_d=Sd) / (N - 1) < gamma_c
        lo, hi = (lo, mid) if ok else (mid, hi)
    return hi


def test_the_limit_is_approached_from_above_by_the_finite_sample_attacker():
    """``J(N) = q*(N) N`` (q* the smallest fraction reaching gamma_c in N samples) decreases to
    J_min: every finite attack falsifies more steps than the audit rate is sized for."""
    A, B, Phi = np.array([[0.6, 0.2], [0.0, 0.5]]), np.eye(2), -0.2 * np.eye(2)
    sw, gc, u = 0.1, 1e-4, 3.0
    J_min = fewest_falsified_steps(A, B, Phi, sigma_w2=sw, gamma_c=gc, input_bound=u).steps
    last = math.inf
    for N in (5_000, 20_000, 100_000, 1_000_000):
        J = _sparse_fraction(A, B, Phi, sw, gc, u, N) * N
        assert J_min - 1 < J < last  # above the limit (J_min is its ceiling), falling with N
        last = J
    assert last < 1.1 * J_min


def test_sparse_audit_rate_and_passive_samples():
    assert sparse_audit_rate(1, 0.25) == 0.75
    p = sparse_audit_rate(362, 1e-3)
    assert undetected_probability(362, p) <= 1e-3 < undetected_probability(362, math.nextafter(p, 0.0))
    A, B, Phi = np.array([[0.5]]), np.array([[1.0]]), np.array([[-0.3]])
    assert passive_samples(A, B, Phi, sigma_w2=0.1, sigma_d2=0.0, gamma_c=1e-3) == math.inf
    # the rate c of the stationary loop with white noise sigma_d2: N = floor(c / gamma_c) + 2
    c = identification_rate(A, B, Phi, sigma_w2=0.1, Sigma_d=[[0.05]])
    assert passive_samples(A, B, Phi, sigma_w2=0.1, sigma_d2=0.05, gamma_c=1e-3) == math.floor(c / 1e-3) + 2
    with pytest.raises(ParameterError, match="sigma_d2"):
        passive_samples(A, B, Phi, sigma_w2=0.1, sigma_d2=-1.0, gamma_c=1e-3)
    for bad, match in [(0, "steps must be >= 1"), (1.5, "steps")]:
        with pytest.raises(ParameterError, match=match):
            sparse_audit_rate(bad, 1e-3)
    with pytest.raises(ParameterError, match="delta must lie in"):
        sparse_audit_rate(10, 1.0)


def test_the_confidentiality_floor_reads_bits_and_nists_names():
    assert check_confidentiality_floor(None) is None
    assert check_confidentiality_floor("nist") == NIST_FLOOR == 2048
    assert check_confidentiality_floor("NIST-2031") == NIST_FLOOR_AFTER_2030 == 3072
    assert check_confidentiality_floor(1024) == 1024
    for bad in ("fips", 0, 2.5):
        with pytest.raises(ParameterError, match="confidentiality_floor"):
            check_confidentiality_floor(bad)


def test_the_default_input_bound_is_the_environments_actuator_bound():
    from encctl_gym.envs.defaults import default_config

    assert default_config()["action_scale"] == DEFAULT_INPUT_BOUND_SIGMAS


# ------------------------------------------------------------------ measured in the environment
def _audited_episodes(cfg: dict, q: float, rate: float, episodes: int) -> int:
    """Episodes (seeds 0, 1, ...) of the sparse attacker against audits at ``rate``: how many
    an audit stopped."""
    import gymnasium as gym

    from encctl_gym.agents.stealth import SparseAttacker

    env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config={**cfg, "defender": {"name": "audit", "rate": rate}})
    att = SparseAttacker(env.unwrapped.params, q=q, level=1.0)
    caught = 0
    for e in range(episodes):
        obs, _ = env.reset(seed=e)
        att.reset(np.random.SeedSequence([0, e]))
        while True:
            obs, _, term, trunc, info = env.step(att.act(obs))
            if term or trunc:
                break
        caught += bool(info["detected"])
    env.close()
    return caught


def test_a_sparse_attacker_reaches_gamma_c_with_about_the_fewest_steps_and_audits_at_p_j_stop_it():
    """Preset small, gamma_c chosen so that J_min = 30: the sparse attacker at the bound with the
    fraction that reaches gamma_c in N = 2000 samples (from the closed form) ends near gamma_c
    having falsified about J(2000) steps; audits at p_J (delta = 0.2) stop at least 80 % of its
    episodes (within the interval), and audits at the rule sized for N falsified steps almost none."""
    from encctl_gym.agents import rollout
    from encctl_gym.agents.evaluate import budget_config, env_config
    from encctl_gym.agents.stealth import SparseAttacker
    from encctl_gym.envs.config import resolve_params
    from encctl_gym.loop.backend import lqr_gain

    base = {"preset": "small", "injection": "add", "decipher_delay": 0, "gamma_opt": False}
    p = resolve_params(base)
    Phi = -lqr_gain(p.A, p.B)
    unit = fewest_falsified_steps(p.A, p.B, Phi, sigma_w2=p.sigma_w2, gamma_c=1.0, input_bound=p.u_max)
    gc = unit.excitation_trace * p.sigma_w2 / ((p.n + p.m) * p.u_max**2 * 30)
    J_min = fewest_falsified_steps(p.A, p.B, Phi, sigma_w2=p.sigma_w2, gamma_c=gc, input_bound=p.u_max).steps
    assert J_min == 30
    N = 2000
    q = _sparse_fraction(p.A, p.B, Phi, p.sigma_w2, gc, p.u_max, N)
    cfg = budget_config(env_config({**base, "gamma_c": gc}), N)
    att = SparseAttacker(resolve_params(cfg), q=q, level=1.0)
    free = rollout(att, cfg, episodes=64, seed=0, record=False)
    assert np.median(free.final_epsilon) < 1.5 * gc  # the closed form's N and q reach gamma_c
    assert J_min <= np.mean(att.injected) < 1.5 * q * N  # falsified steps: about q N, above J_min
    delta, episodes = 0.2, 32
    caught = _audited_episodes(cfg, q, sparse_audit_rate(J_min, delta), episodes)
    assert wilson_interval(caught, episodes, z=3.29)[1] >= 1 - delta  # at least 1 - delta stopped, within the interval
    assert _audited_episodes(cfg, q, sparse_audit_rate(N, delta), 8) <= 2  # sized for N falsified steps: almost none


# ------------------------------------------------------------------ the design
PRESET = get_preset("paper-example")


def _design(**kw):
    costs = DefenderCosts(4, 4, lambda k: 1e-9 * k * k, lambda k: 1e-3 * k, 1e-6)
    return design_defenses(PRESET.plant(), ThreatModel.of(PRESET), costs=costs, controller=-0.5 * np.eye(4), **kw)


def test_audit_secure_mixes_pay_the_sparse_rate_and_keys_hold_the_floor_and_the_passive_attacker():
    d = _design(cost_models=("paper",), audit_rate="auto")
    mix = d.models["paper"].chosen
    assert mix.audit_secure and mix.audit_rate == d.sparse_audit_rate > d.minimum_audit_rate
    assert mix.undetected_probability <= 1e-3 and d.audit_steps == min(d.fewest_falsified_steps, d.N_star)
    floored = _design(cost_models=("paper",), audit_rate="auto", confidentiality_floor="nist")
    assert floored.models["paper"].key_floor == 2048 and floored.models["paper"].chosen.key_length == 2048
    assert floored.models["paper"].key_only.key_length == 2048  # k* = 712 lifted too
    noisy = _design(cost_models=("paper",), audit_rate="auto", sigma_d2=0.1)
    md = noisy.models["paper"]
    assert math.isfinite(noisy.passive_samples) and md.passive_key_length is not None
    assert md.chosen.key_length >= md.passive_key_length > d.models["paper"].key_floor  # the 40-bit mix is gone
    assert md.key_floor == md.passive_key_length


def test_the_design_prints_the_quiet_attackers_and_the_floor(capsys):
    argv = ["design", "--preset", "paper-example", "--cost-model", "paper", "--audit-rate", "auto"]
    assert cli.main([*argv, "--confidentiality-floor", "nist", "--defense-noise", "0.1"]) == 0
    out = capsys.readouterr().out
    assert "J_min = " in out and "p_J = 1 - delta^(1/" in out
    assert "confidentiality floor: 2048 bits" in out and "the passive attacker needs k >= " in out
    assert cli.main(argv) == 0
    assert "confidentiality floor: none" in capsys.readouterr().out
    assert cli.main([*argv, "--confidentiality-floor", "fips"]) == 2
    err = capsys.readouterr().err
    assert "confidentiality_floor" in err and err.count("\n") == 1
    assert cli.main([*argv, "--input-bound", "-1"]) == 2
    assert "input_bound" in capsys.readouterr().err


def test_the_recorded_design_page_is_written_by_its_script(tmp_path):
    """experiments.design_options writes every command's defender section and the K table; by
    default to its --out directory, never to docs/."""
    from encctl_gym.experiments import design_options

    assert design_options.main(["--out", str(tmp_path)]) == 0
    page = (tmp_path / "design_options.md").read_text()
    for options in design_options.COMMANDS:
        assert f"## `encctl-gym design --preset paper-example {' '.join(options)}`" in page
    assert page.count("  Defender's levers") == len(design_options.COMMANDS)
    rows = [line for line in page.splitlines() if line.startswith("| ") and line[2].isdigit()]
    assert [int(r.split("|")[1]) for r in rows] == list(design_options.PERIODS)
    # the key length is nondecreasing in the rotation period (more samples per group)
    keys = [int(r.split("|")[2]) for r in rows]
    assert keys == sorted(keys) and "confidentiality floor: 2048 bits" in page


# ------------------------------------------------------------------ the detector
def _stealth(detector, alpha, delta, gamma_c=1e-3):
    from encctl_gym.loop.backend import lqr_gain
    from encctl_gym.security.quiet_attackers import stealthy_samples

    pl = PRESET.plant()
    Phi = -lqr_gain(pl.A, pl.B)
    kw = {"sigma_w2": PRESET.sigma_w2, "gamma_c": gamma_c, "false_alarm_rate": alpha, "delta": delta}
    st = stealthy_samples(pl.A, pl.B, Phi, detector=detector, power=PRESET.sigma_u2, horizon=13159, **kw)
    return st, pl, Phi, kw


@pytest.mark.parametrize("detector", ["chi2", "cusum"])
def test_the_stealthy_attacker_sits_on_the_detectors_boundary(detector):
    """Against a detector with 1e-8 false alarms and delta = 0.5 at gamma_c = 1e-3, the attacker's
    level is detected with probability at most delta within its samples, and a level 5 % higher
    (fewer samples) is detected above delta: the boundary, from the frontier's closed forms."""
    from encctl_gym.security.stealth import frontier_point

    st, pl, Phi, kw = _stealth(detector, 1e-8, 0.5)
    assert math.isfinite(st.samples) and st.detection <= 0.5 and st.false_alarm_within < 0.5
    louder = frontier_point(pl.A, pl.B, Phi, Sigma_d=1.05 * st.sigma_d2 * np.eye(4), sigma_w2=kw["sigma_w2"],
                            gamma_c=kw["gamma_c"], false_alarm_rate=1e-8)  # fmt: skip
    assert louder.samples < st.samples and getattr(louder, detector) > 0.5


def test_a_detector_whose_false_alarms_exceed_delta_secures_nothing():
    st, *_ = _stealth("chi2", 1e-4, 1e-3, gamma_c=PRESET.gamma_c)
    assert st.samples == math.inf and st.false_alarm_within > 1e-3  # 0.51 within N* = 13159 steps
    d = _design(cost_models=("paper",), detector="chi2", false_alarm_rate=1e-4)
    assert d.models["paper"].detector_only is None and not d.models["paper"].chosen.detector_secure


def test_the_detectors_mix_keeps_the_stealthy_samples_out():
    from encctl_gym.security.cost_models import deciphering_model
    from encctl_gym.security.deciphering import keys_to_break
    from encctl_gym.security.key_length import defense_budget

    d = _design(cost_models=("paper",), detector="cusum", false_alarm_rate=1e-8, detection_delta=0.5)
    st, md = d.stealth, d.models["paper"]
    assert st.samples > d.N_star  # the attacker that must stay unseen needs more samples than the one of N*
    budget = defense_budget(PRESET.tau_c, PRESET.upsilon)
    k = deciphering_model("paper").minimum_key_length(keys_to_break(int(st.samples)), budget)
    mix = md.detector_only
    assert mix.detector_secure and mix.key_length == max(k, md.key_floor) < md.k_star
    assert mix.audit_seconds == 1e-6 and mix.total_seconds == pytest.approx(mix.step_seconds + 1e-6)


def test_the_design_cli_takes_the_detector_and_refuses_bad_ones(capsys):
    argv = ["design", "--preset", "paper-example", "--cost-model", "paper"]
    assert cli.main([*argv, "--detector", "cusum", "--false-alarm", "1e-8", "--detection-delta", "0.5"]) == 0
    out = capsys.readouterr().out
    assert "detector cusum (1e-08 false alarms per step)" in out and "    detector   " in out
    for bad, match in (
        (["--detector", "kalman"], "unknown detector 'kalman'"),
        (["--false-alarm", "1e-3"], "--false-alarm needs --detector"),
        (["--detector", "chi2", "--false-alarm", "1.5"], "false_alarm_rate"),
    ):
        assert cli.main([*argv, *bad]) == 2
        err = capsys.readouterr().err
        assert match in err and err.count("\n") == 1
