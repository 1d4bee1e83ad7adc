"""Paired ARS (agents.ars): candidates on common random numbers, the batched evaluation against
an independent replay, the step counter, schedules, stopping from a callback, and a trained
run loaded as an attacker."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("sb3_contrib")  # the rl extra; torch comes with it

import torch as th  # noqa: E402
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import VecNormalize

from encctl_gym.agents.ars import PairedARS
from encctl_gym.agents.config import apply_override, env_config, load_config
from encctl_gym.agents.hyperparams import LinearSchedule, make_schedules
from encctl_gym.agents.runs import read_run
from encctl_gym.agents.sb3 import SB3VecEnv, load_attacker
from encctl_gym.agents.train import train
from encctl_gym.errors import ConfigError

CFG = {"preset": "small", "gamma_opt": False, "reward": "a_optimality", "input_history": 0, "max_samples": 24}


class _Count(BaseCallback):
    def _on_step(self) -> bool:
        return True


def _model(n_delta: int = 3, E: int = 2, **kw) -> PairedARS:
    env = VecNormalize(SB3VecEnv(CFG, 2, "no_budget", features=["dither"]), norm_reward=False)
    model = PairedARS("LinearPolicy", env, n_delta=n_delta, n_eval_episodes=E, zero_policy=False, seed=3, **kw)
    _, model._cb = model._setup_learn(10**9, _Count(), True, "test", False)
    return model


def test_equal_candidates_get_equal_returns_and_different_ones_do_not():
    model = _model()
    w = model.weights
    same = model.evaluate_candidates(th.stack([w] * model.pop_size), model._cb, None)
    assert th.all(same == same[0])  # the same episodes and dither draws for every candidate
    other = model.evaluate_candidates(th.stack([w, w * 1.5] + [w] * (model.pop_size - 2)), model._cb, None)
    assert other[0] != other[1]
    assert other[0] != same[0]  # a new iteration plays new episodes


def test_batched_returns_equal_an_independent_replay_of_each_candidate():
    model = _model(n_delta=2, E=3)
    vn = model._vec_normalize_env
    vn.obs_rms.update(np.random.default_rng(0).normal(size=(50, vn.observation_space.shape[0])))
    mean, var = vn.obs_rms.mean.copy(), vn.obs_rms.var.copy()
    cands = th.stack([model.weights + 0.3 * th.randn(model.n_params) for _ in range(model.pop_size)])
    state = th.random.get_rng_state()
    seed = model._iteration_seed()
    th.random.set_rng_state(state)  # evaluate_candidates draws the same iteration seed
    got = model.evaluate_candidates(cands, model._cb, None)
    for i in (0, 3):
        env = SB3VecEnv(CFG, 3, "no_budget", features=["dither"])
        obs = env.reset_episodes([seed, seed + 1, seed + 2])
        W = cands[i].reshape(env.params.m, -1).numpy().astype(np.float64)
        total = np.zeros(3)
        while True:
            o = np.clip((obs - mean) / np.sqrt(var + vn.epsilon), -vn.clip_obs, vn.clip_obs)
            obs, r, done, _ = env.step((o @ W.T).astype(np.float32))
            total += r
            if done.any():
                break
        assert float(got[i]) == pytest.approx(total.mean(), rel=1e-5)


def test_step_counter_counts_every_step_played():
    env = VecNormalize(SB3VecEnv(CFG, 2, "no_budget", features=["dither"]), norm_reward=False)
    model = PairedARS("LinearPolicy", env, n_delta=2, n_eval_episodes=2, seed=3)
    model.learn(1)  # one iteration
    horizon = SB3VecEnv(CFG, 1, "no_budget").params.horizon
    played = (2 * 2 + 1) * 2 * horizon  # candidates and the current policy, two episodes each
    assert model._n_updates == 1
    assert played - model.env.num_envs < model.num_timesteps <= played


def test_bad_step_rule_and_schedules():
    env = SB3VecEnv(CFG, 1, "no_budget", features=["dither"])
    with pytest.raises(ConfigError, match="step_rule"):
        PairedARS("LinearPolicy", env, step_rule="sgd")
    with pytest.raises(ConfigError, match="adam_betas"):
        PairedARS("LinearPolicy", env, adam_betas=[0.9, 1.0])
    hp = make_schedules({"learning_rate": "lin_0.02", "delta_std": 0.01, "n_delta": 4})
    assert isinstance(hp["learning_rate"], LinearSchedule) and hp["learning_rate"](0.25) == pytest.approx(0.005)
    assert hp["delta_std"] == 0.01
    cfg = load_config("ars", "small", quick=True)
    apply_override(cfg, "hyperparams.learning_rate=lin_0.03")
    for bad in ("lin_x", "lin_-1", "fast"):
        with pytest.raises(ConfigError, match="learning_rate"):
            apply_override(cfg, f"hyperparams.learning_rate={bad}")


@pytest.fixture(scope="module")
def ars_run(tmp_path_factory):
    cfg = load_config("ars", "small", quick=True)
    return train(cfg, out=tmp_path_factory.mktemp("ars"), progress=False, tensorboard=False)


def test_a_trained_run_plays_reproducibly_with_its_features(ars_run):
    run = read_run(ars_run)
    assert run.features == ["dither"] and run.meta["status"] == "finished"
    att = load_attacker(ars_run)
    cfg = {**run.env, "gamma_opt": False}
    env = SB3VecEnv(cfg, 2, "full")
    actions = []
    for _ in range(2):
        env.seed(11)
        obs = env.reset()
        att.reset(seed=5)
        actions.append(np.stack([att.act(obs) for _ in range(3)]))
    assert np.array_equal(actions[0], actions[1])
    assert not np.array_equal(actions[0][0, 0], actions[0][0, 1])  # the dither differs between copies


@pytest.mark.parametrize("algo", ["ars", "ppo"])
def test_a_callback_can_stop_training(tmp_path, algo):
    cfg = load_config(algo, "small", quick=True)
    seen = []

    def stop(curve):
        seen.append(len(curve.timesteps))
        return len(curve.timesteps) < 2  # stop at the second evaluation

    run = train(cfg, out=tmp_path, progress=False, tensorboard=False, on_evaluation=stop)
    meta = read_run(run).meta
    assert meta["status"] == "stopped" and meta["timesteps_done"] < cfg["n_timesteps"]
    assert seen[-1] == 2
    assert resolve_horizon(cfg) >= 2


def resolve_horizon(cfg):
    from encctl_gym.envs.config import resolve_params

    return resolve_params(env_config(cfg)).horizon
