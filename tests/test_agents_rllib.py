"""Ray RLlib path (agents.rllib): the environment creator runs the registered environment
unchanged; without the [ray] extra the error names it; with it, PPO trains one iteration."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from encctl_gym.agents import rllib
from encctl_gym.errors import EncctlError

SMALL = {"preset": "small", "gamma_opt": False, "max_samples": 32}


def test_env_creator_builds_the_registered_environment_unchanged():
    import gymnasium as gym
    from gymnasium.utils.env_checker import check_env

    from encctl_gym.envs import ENV_ID

    env = rllib.make_env(dict(SMALL))
    ref = gym.make(ENV_ID, config=dict(SMALL))
    check_env(env.unwrapped, skip_render_check=True)
    o1, _ = env.reset(seed=4)
    o2, _ = ref.reset(seed=4)
    assert np.array_equal(o1, o2)
    a = np.full(env.action_space.shape, 0.3, dtype=np.float32)
    for _ in range(5):
        s1, s2 = env.step(a), ref.step(a)
        assert np.array_equal(s1[0], s2[0]) and s1[1] == s2[1]


def test_without_ray_the_error_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray -> ModuleNotFoundError
    with pytest.raises(EncctlError, match=r"pip install 'encctl-gym\[ray\]'"):
        rllib.ppo_config(SMALL)


def test_rllib_ppo_trains_one_iteration():
    pytest.importorskip("ray.rllib")
    rows = rllib.train_ppo(SMALL, iterations=1, train_batch_size=128, minibatch_size=64, num_epochs=1)
    assert len(rows) == 1 and rows[0]["env_steps"] >= 128
    assert rows[0]["episode_return_mean"] is not None and np.isfinite(rows[0]["episode_return_mean"])
