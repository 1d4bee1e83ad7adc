"""Training with stable-baselines3: the VecEnv adapter, configs, train --quick, save/load/evaluate."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from agents import GaussianAttacker, rollout
from agents.evaluate import budget_config
from agents.sb3 import SB3Attacker, SB3VecEnv, load_attacker
from agents.train import CONFIG_DIR, apply_override, load_config
from encctl_gym import cli
from encctl_gym.envs.config import resolve_params
from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv
from encctl_gym.errors import ParameterError

SMALL = {"preset": "small", "gamma_opt": False}


# ------------------------------------------------------------------ the VecEnv adapter
def test_sb3_vecenv_follows_the_native_vector_env_and_autoresets():
    K = 3
    venv = SB3VecEnv(SMALL, K, "full")
    native = EncryptedLTIAttackVectorEnv(K, config=SMALL)
    venv.seed(5)
    obs = venv.reset()
    nobs, _ = native.reset(seed=5)
    assert np.array_equal(obs, nobs)
    rng = np.random.default_rng(0)
    H = venv.params.horizon
    for t in range(H):
        a = rng.uniform(-0.3, 0.3, (K, venv.params.m)).astype(np.float32)
        obs, r, done, infos = venv.step(a)
        nobs, nr, te, tr, ninfo = native.step(a)
        assert np.allclose(r, nr)
        if t < H - 1:
            assert not done.any() and np.array_equal(obs, nobs) and infos[0] == {}
    assert done.all()
    for i, info in enumerate(infos):
        assert np.array_equal(info["terminal_observation"], nobs[i])
        assert info["epsilon"] == pytest.approx(ninfo["epsilon"][i])
        assert info["TimeLimit.truncated"] == bool(tr[i] and not te[i])
    assert not np.array_equal(obs, nobs)  # the returned observation is the next episode's first


def test_sb3_vecenv_observation_modes_and_reward_scaling():
    full = SB3VecEnv(SMALL, 2, "full")
    blind = SB3VecEnv(SMALL, 2, "blind")
    scaled = SB3VecEnv(SMALL, 2, "full", reward_scaling="samples")
    p = full.params
    assert blind.observation_space.shape == (p.input_history * p.m + 2,)
    for v in (full, blind, scaled):
        v.seed(1)
        v.reset()
    a = np.full((2, p.m), 0.2, dtype=np.float32)
    for _ in range(p.n + p.m + 3):
        o_full, r_full, _, _ = full.step(a)
        o_blind, _, _, _ = blind.step(a)
        _, r_scaled, _, _ = scaled.step(a)
    assert np.array_equal(o_blind, o_full[:, blind.obs_idx])
    N = full.venv._core.delivered
    assert np.allclose(r_scaled, r_full * N, rtol=1e-6)
    with pytest.raises(ParameterError):
        SB3VecEnv(SMALL, 2, "full", reward_scaling="bogus")


# ------------------------------------------------------------------ configs
@pytest.mark.parametrize("path", sorted(CONFIG_DIR.glob("*.yaml")), ids=lambda p: p.stem)
def test_every_shipped_config_loads_and_builds_its_environment(path):
    algo = path.stem.split("_")[0] if not path.stem.startswith("recurrent_ppo") else "recurrent_ppo"
    for quick in (False, True):
        cfg = load_config(algo, path=path, quick=quick)
        assert cfg["n_timesteps"] > 0 and cfg["n_envs"] >= 1
        venv = SB3VecEnv(dict(cfg["env"], gamma_opt=False), 1, cfg["observation"])
        assert venv.observation_space.shape[0] >= 1
    if cfg.get("horizon"):
        from agents.train import _env_cfg

        assert resolve_params(_env_cfg(cfg)).horizon == cfg["horizon"]


def test_config_errors_and_overrides():
    with pytest.raises(ParameterError):
        load_config("dqn", "paper-example")
    with pytest.raises(ParameterError):
        load_config("ppo", "no-such-preset")
    cfg = load_config("ppo", "paper-example")
    apply_override(cfg, "hyperparams.learning_rate=1e-3")
    apply_override(cfg, "hyperparams.policy_kwargs.net_arch={pi: [], vf: [8]}")
    assert cfg["hyperparams"]["learning_rate"] == 1e-3
    assert cfg["hyperparams"]["policy_kwargs"]["net_arch"] == {"pi": [], "vf": [8]}
    with pytest.raises(ParameterError):
        apply_override(cfg, "env.preset=nope")
    with pytest.raises(ParameterError):
        apply_override(cfg, "no_equals_sign")


def test_cli_reports_a_bad_config_in_one_line(capsys, tmp_path):
    assert cli.main(["train", "--algo", "ppo", "--preset", "no-such-preset", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no config" in err[0]


# ------------------------------------------------------------------ train --quick
def _check_run(run_dir: Path, algo: str, capsys) -> None:
    for f in ("model.zip", "best_model.zip", "vecnormalize.pkl", "evaluations.npz", "run.json"):
        assert (run_dir / f).exists(), f
    assert any((run_dir / "tb").rglob("events.out.tfevents.*"))
    meta = json.loads((run_dir / "run.json").read_text())
    assert meta["algo"] == algo and meta["n_timesteps"] > 0 and meta["train_seconds"] > 0
    ev = meta["final_evaluation"]
    for which in ("gaussian", "final", "best"):
        assert np.isfinite(ev[which]["mean_epsilon"]) and ev[which]["mean_epsilon"] > 0
    # the learned policy ran through real ElGamal ciphertexts
    assert "unavailable" not in ev["elgamal"], ev["elgamal"]
    assert np.isfinite(ev["elgamal"]["mean_epsilon"]) and ev["elgamal"]["key_length"] <= 128
    assert "ratio to gaussian" in capsys.readouterr().out

    att = load_attacker(run_dir)
    assert isinstance(att, SB3Attacker) and att.vecnormalize is not None and not att.vecnormalize.training
    cfg = dict(meta["env"])
    params = resolve_params(cfg)
    r1 = rollout(att, cfg, episodes=3, seed=4, record=True)
    r2 = rollout(load_attacker(run_dir), cfg, episodes=3, seed=4, record=True)
    assert np.array_equal(r1.epsilon, r2.epsilon)  # loading and seeding reproduce the policy exactly
    assert r1.epsilon.shape == (3, params.horizon) and np.all(np.isfinite(r1.final_epsilon))
    # through a single environment too, inside the action space
    import gymnasium as gym

    from encctl_gym.envs import ENV_ID

    env = gym.make(ENV_ID, config=cfg)
    obs, _ = env.reset(seed=0)
    att.reset(seed=0)
    for _ in range(10):
        a = att.act(obs)
        assert env.action_space.contains(a)
        obs, *_ = env.step(a)


def test_train_quick_ppo_saves_loads_and_evaluates(tmp_path, capsys):
    rc = cli.main(["train", "--algo", "ppo", "--preset", "paper-example", "--quick", "--out", str(tmp_path), "--no-progress"])
    assert rc == 0
    run_dir = tmp_path / "ppo_paper-example_d0_full_s0-quick"
    _check_run(run_dir, "ppo", capsys)


@pytest.mark.parametrize("algo", ["sac", "recurrent_ppo"])  # ~10 s each
def test_train_quick_sac_and_recurrent_ppo(tmp_path, capsys, algo):
    rc = cli.main(["train", "--algo", algo, "--preset", "paper-example", "--quick", "--out", str(tmp_path), "--no-progress"])
    assert rc == 0
    (run_dir,) = list(tmp_path.iterdir())
    _check_run(run_dir, algo, capsys)


def test_recurrent_attacker_keeps_and_resets_its_state(tmp_path):
    """A tiny RecurrentPPO model (not trained) wrapped as an attacker: the LSTM state is carried
    between steps, per copy, and cleared by reset."""
    from sb3_contrib import RecurrentPPO

    venv = SB3VecEnv(SMALL, 2, "blind")
    model = RecurrentPPO("MlpLstmPolicy", venv, n_steps=8, batch_size=16, policy_kwargs={"lstm_hidden_size": 4}, seed=0, device="cpu")
    att = SB3Attacker(model, params=venv.params, observation="blind", name="rppo")
    cfg = budget_config({"preset": "small", "gamma_opt": False, "decipher_delay": "end"}, 20)
    params = resolve_params(cfg)
    native = EncryptedLTIAttackVectorEnv(4, config=cfg)
    obs, _ = native.reset(seed=0)
    att.reset(seed=1)
    a0 = att.act(obs)
    assert att._state is not None and a0.shape == (4, params.m)
    h_before = np.array(att._state[0]).copy()
    obs, *_ = native.step(a0)
    att.act(obs)
    assert not np.array_equal(np.array(att._state[0]), h_before)  # the state moved on
    att.reset(seed=1)
    assert att._state is None
    r = rollout(att, cfg, episodes=4, seed=0, record=False)
    assert np.all(np.isfinite(r.final_epsilon))
    g = rollout(GaussianAttacker(params), cfg, episodes=4, seed=0, record=False)
    assert r.N[-1] == g.N[-1] == 20
