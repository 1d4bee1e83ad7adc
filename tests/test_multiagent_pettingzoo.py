"""PettingZoo's conventions for the game (issue 34 item 9): the module's ``parallel_env``,
``raw_env`` and ``env`` factories, PettingZoo's AEC and parallel API tests, and SuperSuit's
wrappers on both forms."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

pytest.importorskip("pettingzoo")
ss = pytest.importorskip("supersuit")

from pettingzoo import AECEnv, ParallelEnv  # noqa: E402
from pettingzoo.test import api_test, parallel_api_test, seed_test  # noqa: E402

from encctl_gym.agents.evaluate import budget_config, env_config  # noqa: E402
from encctl_gym.multiagent import AGENTS, EncryptedControlGame, encctl_game_v0, env, parallel_env, raw_env  # noqa: E402

N = 30
CFG = budget_config(env_config({"preset": "paper-example", "crypto_seed": 5}), N)
#: Without the rotate lever: each rotation generates a real group (0.1-0.3 s), and its measured
#: wall-clock seconds in ``info`` differ between two runs of one seed (see the seed test).
NO_ROTATION = {"rotation": False}


def test_the_module_exports_pettingzoos_three_factories():
    assert encctl_game_v0.parallel_env is parallel_env and encctl_game_v0.env is env and encctl_game_v0.raw_env is raw_env
    par = parallel_env(config=CFG)
    assert isinstance(par, ParallelEnv) and isinstance(par, EncryptedControlGame)
    aec = env(config=CFG)
    assert isinstance(aec, AECEnv) and isinstance(raw_env(config=CFG), AECEnv)
    assert aec.unwrapped.metadata["name"] == "encctl_game_v0" == encctl_game_v0.__name__.rsplit(".", 1)[1]
    aec.reset(seed=3)
    assert aec.agent_selection == AGENTS[0] and aec.possible_agents == list(AGENTS)


def test_the_aec_form_passes_pettingzoos_api_test():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # PettingZoo's advice on unbounded spaces and unequal shapes
        api_test(env(config=CFG), num_cycles=N)
        seed_test(lambda: env(config=CFG, rules=NO_ROTATION), num_cycles=N)


def test_the_aec_form_steps_the_parallel_game_bit_for_bit():
    """parallel_to_aec, not a second game: the attacker's then the defender's action in AEC
    order give the parallel step's observations and rewards."""
    rng = np.random.default_rng(7)
    par, aec = parallel_env(config=CFG, rules=NO_ROTATION), env(config=CFG, rules=NO_ROTATION)
    par.reset(seed=11)
    aec.reset(seed=11)
    steps = 0
    while par.agents:
        acts = {a: par.action_space(a).sample() for a in AGENTS}
        acts["attacker"] = rng.uniform(-1, 1, par.action_space("attacker").shape).astype(np.float32)
        obs, rew, _, _, _ = par.step(acts)
        for a in AGENTS:
            assert aec.agent_selection == a
            aec.step(acts[a])
        for a in AGENTS:
            np.testing.assert_array_equal(aec.observe(a), obs[a])
            assert aec.rewards[a] == rew[a]
        steps += 1
    assert steps >= 2 and all(aec.terminations[a] or aec.truncations[a] for a in AGENTS)


def test_supersuit_wrappers_on_both_forms():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        api_test(ss.clip_actions_v0(env(config=CFG, rules=NO_ROTATION)), num_cycles=N)
        padded = ss.pad_action_space_v0(ss.pad_observations_v0(parallel_env(config=CFG, rules=NO_ROTATION)))
        parallel_api_test(padded, num_cycles=N)
        vec = ss.pettingzoo_env_to_vec_env_v1(
            ss.pad_action_space_v0(ss.pad_observations_v0(parallel_env(config=CFG, rules=NO_ROTATION)))
        )
    obs, _ = vec.reset(seed=0)
    dim = max(_dims())
    assert vec.num_envs == 2 and obs.shape == (2, dim)
    for _ in range(N + 2):  # through the end of an episode and its automatic reset
        obs, rew, term, trunc, _ = vec.step(np.stack([vec.action_space.sample() for _ in range(2)]))
        assert obs.shape == (2, dim) and np.isfinite(rew).all()


def _dims() -> list[int]:
    game = parallel_env(config=CFG)
    return [game.observation_space(a).shape[0] for a in AGENTS]
