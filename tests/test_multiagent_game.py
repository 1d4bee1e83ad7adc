"""The attacker-defender game (encctl_gym.multiagent): PettingZoo's API, bit-for-bit agreement
with the single environment, the levers, the rewards and what the defender may see."""

from __future__ import annotations

import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("pettingzoo")

from pettingzoo.test import parallel_api_test, parallel_seed_test  # noqa: E402

import encctl_gym  # noqa: E402,F401
from encctl_gym.agents.evaluate import budget_config, env_config  # noqa: E402
from encctl_gym.agents.game import defender_action  # noqa: E402
from encctl_gym.errors import ParameterError  # noqa: E402
from encctl_gym.loop.backend import lqr_gain  # noqa: E402
from encctl_gym.loop.defenses import audit_tolerance  # noqa: E402
from encctl_gym.multiagent import EncryptedControlGame, GameRules  # noqa: E402

N = 40
NONE = defender_action()  # no audit, no noise
AUDIT = defender_action(audit=1.0)


def _cfg(**kw):
    return budget_config(env_config({"preset": "paper-example", **kw}), N)


def _inputs(m, seed=3):
    return np.random.default_rng(seed).uniform(-0.5, 0.5, (N, m)).astype(np.float32)


def test_the_game_passes_pettingzoos_api_and_seed_tests():
    cfg = _cfg()
    parallel_api_test(EncryptedControlGame(cfg), num_cycles=200)
    parallel_seed_test(lambda: EncryptedControlGame(cfg), num_cycles=200)


@pytest.mark.parametrize("noise", [None, 0.5])
def test_a_fixed_defender_reproduces_the_single_environment_bit_for_bit(noise):
    cfg = _cfg()
    game = EncryptedControlGame(cfg)
    m, s2 = game.params.m, game.params.sigma_u2
    single_cfg = cfg if noise is None else {**cfg, "defender": {"name": "noise", "sigma_d2": s2 * noise}}
    env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config=single_cfg)
    d = NONE if noise is None else defender_action(noise=noise)
    o1, i1 = env.reset(seed=11)
    o2, i2 = game.reset(seed=11)
    assert np.array_equal(o1, o2["attacker"]) and i1 == i2["attacker"]
    for a in _inputs(m):
        o1, r1, te1, tr1, i1 = env.step(a)
        o2, r2, te2, tr2, i2 = game.step({"attacker": np.r_[a, 1.0].astype(np.float32), "defender": d})
        assert np.array_equal(o1, o2["attacker"])
        assert r1 == r2["attacker"] and r2["defender"] == -r1 - i2["defender"]["cost"]
        assert i1 == i2["attacker"] and (te1, tr1) == (te2["attacker"], tr2["attacker"])
        if te1 or tr1:
            break
    assert te1 and not game.agents


def test_an_audit_catches_an_injected_input_and_never_a_passed_through_one():
    rules = {"detection_penalty": 2.5, "audit_cost": 0.0}
    game = EncryptedControlGame(_cfg(), rules)
    m = game.params.m
    game.reset(seed=0)
    passing = np.r_[np.full(m, 0.3), -1.0].astype(np.float32)
    steps = 0
    while game.agents:
        _, rew, term, trunc, info = game.step({"attacker": passing, "defender": AUDIT})
        steps += 1
        assert not info["attacker"]["detected"]
    assert steps == N and info["defender"]["audits"] == N - 1  # N samples, N actions; no input to audit at the first step
    # the recorded inputs are the controller's: within the encoding's error of Phi x
    X, U = game.episode.delivered_data()
    Phi = -lqr_gain(game.params.A, game.params.B)
    tol = audit_tolerance(Phi, X[0, :-1], game.params.delta, game.levers.max_shift)
    assert np.all(np.abs(U[0] - X[0, :-1] @ Phi.T) <= tol)
    assert info["attacker"]["input_energy"] == 0.0
    # an injected input is caught by the first audit (step 1 audits the input of step 0)
    game.reset(seed=0)
    inject = np.r_[np.full(m, 0.3), 1.0].astype(np.float32)
    game.step({"attacker": inject, "defender": NONE})
    _, rew, term, trunc, info = game.step({"attacker": inject, "defender": AUDIT})
    assert term["attacker"] and term["defender"] and info["attacker"]["detected"] and not game.agents
    assert rew["attacker"] == pytest.approx(-rew["defender"] - 2.5)


def test_the_audit_budget_and_the_costs_are_the_hand_count():
    rules = GameRules(audit_budget=3, audit_cost=0.25, noise_weight=0.5)
    game = EncryptedControlGame(_cfg(), rules)
    m = game.params.m
    game.reset(seed=2)
    passing = np.r_[np.zeros(m), -1.0].astype(np.float32)
    costs = []
    for k in range(10):
        noise = 0.5 if k == 4 else -1.0
        _, rew, _, _, info = game.step({"attacker": passing, "defender": defender_action(audit=1.0, noise=noise)})
        costs.append(info["defender"]["cost"])
        assert rew["defender"] == -rew["attacker"] - costs[-1]
    assert info["defender"]["audits"] == 3
    unit = game.levers.unit_noise_price
    # step 0 has no input to audit; steps 1-3 use the budget; step 4 adds noise, its audit is past the budget
    want = [0.0, 0.25, 0.25, 0.25, 0.5 * unit * 0.5 * game.params.sigma_u2] + [0.0] * 5
    assert costs == pytest.approx(want)


def test_the_zero_sum_rules_make_the_rewards_sum_to_zero():
    game = EncryptedControlGame(_cfg(), {"zero_sum": True, "audit_cost": 0.1})
    m = game.params.m
    game.reset(seed=4)
    rng = np.random.default_rng(0)
    while game.agents:
        a = np.r_[rng.uniform(-1, 1, m), rng.choice([-1.0, 1.0])].astype(np.float32)
        d = defender_action(audit=rng.choice([-1.0, 1.0]) * (rng.random() < 0.2), noise=rng.uniform(-1, 1))
        _, rew, _, _, _ = game.step({"attacker": a, "defender": d})
        assert rew["attacker"] + rew["defender"] == 0.0


def test_the_defender_sees_only_the_plant_side():
    """Attackers differing only in what they decipher and estimate (delay, estimator, reward)
    leave the defender's observation unchanged bit for bit; the attacker's changes."""
    runs = []
    for kw in ({}, {"decipher_delay": 5, "estimator": "forgetting", "reward": "logdet"}):
        game = EncryptedControlGame(_cfg(**kw))
        m, n = game.params.m, game.params.n
        obs, _ = game.reset(seed=9)
        seen, theirs = [obs["defender"]], [obs["attacker"]]
        for a in _inputs(m, seed=5)[:20]:
            obs, *_ = game.step({"attacker": np.r_[a, 1.0], "defender": defender_action(noise=0.2)})
            seen.append(obs["defender"])
            theirs.append(obs["attacker"])
            x = game.episode.state.x[0]
            assert np.array_equal(obs["defender"][:n], x.astype(np.float32))  # the plant's own state
        runs.append((np.array(seen), np.array(theirs)))
    assert np.array_equal(runs[0][0], runs[1][0])
    assert not np.array_equal(runs[0][1], runs[1][1])


@pytest.mark.parametrize(
    "make, text",
    [
        (lambda: EncryptedControlGame(_cfg(), {"audit_bugdet": 3}), "audit_bugdet"),
        (lambda: EncryptedControlGame(_cfg(), {"audit_cost": -1}), "audit_cost"),
        (lambda: EncryptedControlGame({**_cfg(), "defender": "audit"}), "defender"),
        (lambda: EncryptedControlGame({**_cfg(), "rotate_group_every": 8}), "rotate_group_every"),
    ],
)
def test_bad_game_settings_are_refused_naming_them(make, text):
    with pytest.raises(ParameterError, match=text):
        make()


def test_bad_actions_are_refused_naming_them():
    game = EncryptedControlGame(_cfg())
    m = game.params.m
    with pytest.raises(ParameterError, match="reset"):
        game.step({"attacker": np.zeros(m + 1), "defender": NONE})
    game.reset(seed=0)
    with pytest.raises(ParameterError, match="both agents"):
        game.step({"attacker": np.zeros(m + 1)})
    with pytest.raises(ParameterError, match="attacker's action must have shape"):
        game.step({"attacker": np.zeros(m), "defender": NONE})
    with pytest.raises(ParameterError, match="defender's action must"):
        game.step({"attacker": np.zeros(m + 1), "defender": defender_action(noise=2.0)})
    with pytest.raises(ParameterError, match="unknown agent"):
        game.action_space("server")


def test_a_missing_pettingzoo_is_one_line_naming_the_extra():
    code = "import sys; sys.modules['pettingzoo'] = None\ntry:\n import encctl_gym.multiagent\nexcept ImportError as e:\n print(type(e).__name__, e)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out.startswith("OptionalDependencyError") and "encctl-gym[multiagent]" in out and "\n" not in out


def test_the_game_runs_on_real_ciphertexts_and_a_passed_input_is_the_controllers():
    from encctl_gym.agents.evaluate import elgamal_config

    game = EncryptedControlGame(elgamal_config(env_config({"preset": "paper-example"}), 12, key_length=64))
    m = game.params.m
    game.reset(seed=1)
    for k in range(11):
        inject = 1.0 if k == 6 else -1.0
        _, _, term, _, info = game.step({"attacker": np.r_[np.full(m, 0.1), inject], "defender": AUDIT})
        assert info["attacker"]["detected"] == (k == 7)  # step 7 audits the input injected at step 6
        if term["attacker"]:
            break
    assert k == 7 and info["defender"]["audits"] == 7


def test_passed_through_steps_give_the_same_numbers_on_every_step_path():
    """Injected and passed-through steps mixed: the ideal backend (its compiled steps) and real
    ElGamal (the generic step) give the same trajectory bit for bit, as the single environment's do."""
    from encctl_gym.agents.evaluate import elgamal_config

    cfg = elgamal_config(env_config({"preset": "paper-example"}), 16, key_length=64)
    ideal = {k: v for k, v in cfg.items() if k != "crypto_seed"} | {"crypto": "ideal"}
    runs = []
    for c in (cfg, ideal):
        game = EncryptedControlGame(c)
        obs, _ = game.reset(seed=3)
        seq = [obs["attacker"]]
        for k, a in enumerate(_inputs(game.params.m)[:15]):
            obs, rew, *_ = game.step({"attacker": np.r_[a, 1.0 if k % 3 else -1.0], "defender": defender_action(noise=0.1)})
            seq.append(np.r_[obs["attacker"], obs["defender"], rew["attacker"]])
        runs.append(np.concatenate(seq))
    assert np.array_equal(runs[0], runs[1])


def test_rotating_every_k_steps_reproduces_the_rotate_defender_bit_for_bit():
    from encctl_gym.agents.game import RotateEvery

    cfg = {"key_length": 64, "max_samples": 14, "crypto_seed": 5, "delta": 64, "x_bound": 48.0, "gamma_opt": False}
    env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config={**cfg, "defender": {"name": "rotate", "every": 4}})
    game = EncryptedControlGame(cfg, {"rotation_cost": 0.5})
    rotate = RotateEvery(4)
    o1, _ = env.reset(seed=2)
    o2, _ = game.reset(seed=2)
    rotate.reset()
    rng = np.random.default_rng(7)
    done, costs = False, []
    while not done:
        a = rng.uniform(-1, 1, game.params.m).astype(np.float32)
        o1, r1, te, tr, i1 = env.step(a)
        o2, r2, _, _, i2 = game.step({"attacker": np.r_[a, 1.0], "defender": rotate.act(o2["defender"])})
        assert np.array_equal(o1, o2["attacker"]) and r1 == r2["attacker"] and i1["epsilon"] == i2["attacker"]["epsilon"]
        costs.append(i2["defender"]["cost"])
        done = te or tr
    assert i1["group_rotations"] == i2["attacker"]["group_rotations"] == i2["defender"]["rotations"] == 3  # steps 3, 7, 11 of 14
    assert costs == [0.5 if k in (3, 7, 11) else 0.0 for k in range(14)]
    env.close()
    game.close()


def test_with_the_rotation_lever_off_its_entry_is_ignored():
    game = EncryptedControlGame(_cfg(), {"rotation": False, "rotation_cost": 1.0})
    m = game.params.m
    game.reset(seed=0)
    for _ in range(5):
        _, _, _, _, info = game.step({"attacker": np.r_[np.zeros(m), -1.0], "defender": defender_action(rotate=1.0)})
        assert (
            info["defender"]["rotations"] == 0 and info["defender"]["cost"] == 0.0 and "group_rotations" not in info["attacker"]
        )
