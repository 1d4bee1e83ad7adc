"""The environment's parts through their public seams: the observation and info layout, the
rewards registry and the helper thread's lifecycle."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

from encctl_gym.envs import EncryptedLTIAttackEnv
from encctl_gym.envs.config import REWARDS
from encctl_gym.envs.helper import HelperThread
from encctl_gym.envs.layout import INFO_FIELDS, OBSERVATION_MODES, ObservationLayout
from encctl_gym.envs.rewards import REWARDS as REWARD_CLASSES
from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv
from encctl_gym.errors import ParameterError

SMALL = {"preset": "small", "gamma_opt": True, "decipher_delay": 2, "input_history": 3}


def test_the_observation_is_where_the_layout_says():
    """Each slice of the layout holds what it names: the delivered state and input (against
    delivered_data), the flag, the own past actions, the two budget fractions."""
    env = EncryptedLTIAttackEnv(config=SMALL)
    p, lay = env.params, env.params.layout
    assert lay == ObservationLayout(p.n, p.m, 3) and lay.dim == env.observation_space.shape[0]
    env.reset(seed=0)
    acts = np.random.default_rng(0).uniform(-0.5, 0.5, (30, p.m)).astype(np.float32)
    for k, a in enumerate(acts):
        obs, _, _, _, info = env.step(a)
        states, inputs = env.episode.delivered_data()
        N = info["samples_delivered"]
        assert N == max(k + 2 - 2, 0)
        if N:
            assert np.array_equal(obs[lay.state], states[0, -1].astype(np.float32))
        if N >= 2:
            assert np.array_equal(obs[lay.input], inputs[0, -1].astype(np.float32))
        assert obs[lay.flag] == (1.0 if N else 0.0)
        want_hist = np.concatenate([acts[j] for j in range(k, max(k - 3, -1), -1)] + [np.zeros((3 - min(k + 1, 3)) * p.m)])
        assert np.allclose(obs[lay.history], want_hist)
        assert obs[lay.time_fraction] == pytest.approx(info["deciphering_time"] / p.tau_c, rel=1e-6)
        assert obs[lay.energy_fraction] == pytest.approx(info["input_energy"] / p.energy_budget, rel=1e-6)


def test_observation_modes_select_columns_of_the_layout():
    lay = ObservationLayout(4, 4, 2)
    assert lay.columns("full").tolist() == list(range(lay.dim))
    assert lay.columns("no_budget").tolist() == list(range(lay.dim - 2))
    assert lay.columns("blind").tolist() == list(range(lay.history.start, lay.history.stop)) + [lay.dim - 2, lay.dim - 1]
    assert set(OBSERVATION_MODES) == {"full", "no_budget", "blind"}
    with pytest.raises(ParameterError, match="everything"):
        lay.columns("everything")
    with pytest.raises(ParameterError, match="input_history"):
        ObservationLayout(4, 4, 0).columns("blind")


def test_single_and_vector_info_have_the_layout_keys_and_agree():
    env = EncryptedLTIAttackEnv(config=SMALL)
    venv = EncryptedLTIAttackVectorEnv(num_envs=2, config=SMALL)
    _, info = env.reset(seed=5)
    _, info_v = venv.reset(seed=5)
    assert list(info) == list(info_v) == [name for name, _, _ in INFO_FIELDS]
    assert all(isinstance(v, (float, int)) and not isinstance(v, np.generic) for v in info.values())
    assert all(info_v[k][0] == info[k] for k in info)
    assert info["epsilon"] == pytest.approx(np.sum(np.hstack([env.params.A, env.params.B]) ** 2) / (2 * 4))
    no_opt = EncryptedLTIAttackEnv(config={**SMALL, "gamma_opt": False}).reset(seed=0)[1]
    assert "gamma_opt" not in no_opt


def test_reward_names_come_from_the_registry():
    assert REWARDS == tuple(REWARD_CLASSES) and all(REWARD_CLASSES[n].name == n for n in REWARDS)
    assert [n for n in REWARDS if REWARD_CLASSES[n].fused] == ["log_error"]
    assert set(REWARDS) == {"log_error", "logdet", "a_optimality"}


@pytest.mark.parametrize("delay", [0, "end"])
def test_a_optimality_reward_telescopes_to_the_trace_of_the_inverse_gram_matrix(delay):
    """The return is log(d / delta) - log tr((Z^T Z + delta I)^-1) of the delivered regressors
    Z, computed here from delivered_data; with delay "end" it all arrives at the last step."""
    cfg = {**SMALL, "reward": "a_optimality", "gamma_opt": False, "decipher_delay": delay, "logdet_regularization": 0.5}
    env = EncryptedLTIAttackEnv(config=cfg)
    p = env.params
    env.reset(seed=3)
    rewards = []
    while True:
        _, r, te, tr, _ = env.step(env.action_space.sample() * 0.5)
        rewards.append(r)
        if te or tr:
            break
    X, U = env.episode.delivered_data()
    Z = np.hstack([X[0, :-1], U[0]])
    d = p.n + p.m
    want = np.log(d / 0.5) - np.log(np.trace(np.linalg.inv(Z.T @ Z + 0.5 * np.eye(d))))
    assert sum(rewards) == pytest.approx(want, rel=1e-9)
    if delay == "end":
        assert all(r == 0.0 for r in rewards[:-1]) and rewards[-1] > 0


def test_logdet_reward_telescopes_to_the_log_det_of_the_delivered_gram_matrix():
    cfg = {**SMALL, "reward": "logdet", "gamma_opt": False, "logdet_regularization": 0.5}
    env = EncryptedLTIAttackEnv(config=cfg)
    p = env.params
    env.reset(seed=1)
    total = 0.0
    for _ in range(40):
        _, r, te, tr, _ = env.step(env.action_space.sample() * 0.5)
        total += r
    X, U = env.episode.delivered_data()
    Z = np.hstack([X[0, :-1], U[0]])
    d = p.n + p.m
    want = np.linalg.slogdet(Z.T @ Z + 0.5 * np.eye(d))[1] - d * np.log(0.5)
    assert total == pytest.approx(want, rel=1e-9)


def test_helper_thread_starts_on_use_closes_and_copies_unstarted():
    h = HelperThread()
    assert not h.started
    assert h.submit(lambda x: x + 1, 41).result() == 42 and h.started
    clone = pickle.loads(pickle.dumps(h))
    assert not clone.started and copy.deepcopy(h).started is False
    h.close()
    assert not h.started
    assert h.submit(lambda: "again").result() == "again"  # a later submit starts a new thread
    h.close()
    with pytest.raises(ZeroDivisionError):
        h.submit(lambda: 1 / 0).result()
    h.close()


def test_a_given_helper_thread_is_used_and_a_bad_one_refused():
    h = HelperThread(name="mine")
    venv = EncryptedLTIAttackVectorEnv(num_envs=2, config={**SMALL, "gamma_opt": False}, helper_thread=h)
    assert venv.helper is h
    with pytest.raises(ParameterError, match="helper_thread"):
        EncryptedLTIAttackVectorEnv(num_envs=2, config=SMALL, helper_thread="yes")
    with pytest.raises(ParameterError, match="parallel"):
        EncryptedLTIAttackVectorEnv(num_envs=2, config=SMALL, parallel="no")
