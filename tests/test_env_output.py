"""``observe="output"``: the attacker deciphers outputs and its own inputs, never the state."""

from __future__ import annotations

import numpy as np
import pytest

from encctl_gym.envs import EncryptedLTIAttackEnv
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ParameterError, ShapeError
from encctl_gym.ident.subspace import arx, markov_error

CFG = {"preset": "small-output", "observe": "output", "max_samples": 120, "key_length": 64, "x_bound": 64.0}


def _run(cfg, acts, *, seed=11, options=None):
    env = EncryptedLTIAttackEnv(config=cfg)
    obs, info = env.reset(seed=seed, options=options)
    out, rewards = [obs], []
    for a in acts:
        obs, r, te, tr, info = env.step(a)
        out.append(obs)
        rewards.append(r)
        if te or tr:
            break
    return env, np.array(out), np.array(rewards), info


def test_observation_holds_outputs_not_states():
    env, obs, _, _ = _run(CFG, np.zeros((5, 2)))
    p = env.params
    assert p.observed_dim == 1 and obs.shape[1] == 1 + 2 + 1 + p.input_history * 2 + 2
    assert env.observation_space.contains(obs[0])
    assert env.episode.delivered_data()[0].shape == (1, env.episode.delivered, 1)


def test_no_state_reaches_the_attacker():
    """Two plants with the same input-output behaviour in state bases that differ by T = 2 I
    (exact in floating point: x' = 2 x, y' = (C / 2) x' = y bit for bit) give the attacker the same
    observations, while their states differ; measured through the state, they do not."""
    acts = np.random.default_rng(3).uniform(-0.3, 0.3, (60, 2))
    base = resolve_params(CFG)
    x0 = np.array([0.3, -0.2])
    w = np.random.default_rng(4).normal(0, 0.3, (base.horizon, 2))
    common = {**CFG, "preset": None, "sigma_w2": 0.1, "sigma_u2": 1.0, "sigma_x2": 1.0, "gamma_c": 1e-3,
              "tau_c": 1e9, "upsilon": 1e9, "sigma_v2": 0.01}  # fmt: skip
    one = {**common, "A": base.A, "B": base.B, "C": base.C}
    two = {**common, "A": base.A, "B": 2 * base.B, "C": base.C / 2}
    e1, o1, r1, _ = _run(one, acts, options={"x0": x0, "noise": w})
    e2, o2, r2, _ = _run(two, acts, options={"x0": 2 * x0, "noise": 2 * w})
    np.testing.assert_array_equal(o1, o2)
    np.testing.assert_array_equal(e1.episode.x * 2, e2.episode.x)
    assert not np.array_equal(e1.episode.x, e2.episode.x)
    state = {k: v for k, v in common.items() if k not in ("C", "sigma_v2")} | {"observe": "state"}
    _, s1, _, _ = _run({**state, "A": base.A, "B": base.B}, acts, options={"x0": x0, "noise": w})
    _, s2, _, _ = _run({**state, "A": base.A, "B": 2 * base.B}, acts, options={"x0": 2 * x0, "noise": 2 * w})
    assert not np.array_equal(s1, s2)  # the test can fail: the state case does show the basis


@pytest.mark.parametrize("delay", [0, 3, "end"])
def test_output_observations_never_contain_undelivered_data(delay):
    cfg = {**CFG, "decipher_delay": delay}
    p = resolve_params(cfg)
    s0 = 15
    acts = np.random.default_rng(3).uniform(-0.3, 0.3, (p.horizon, 2))
    w = np.random.default_rng(12).normal(0, np.sqrt(p.sigma_w2), (p.horizon, 2))
    x0 = np.zeros(2)
    _, base, _, _ = _run(cfg, acts, options={"x0": x0, "noise": w})
    w2 = w.copy()
    w2[s0:] += 5.0
    _, changed, _, _ = _run(cfg, acts, options={"x0": x0, "noise": w2})
    d = len(base) if delay == "end" else delay
    for s in range(0, min(s0 + d, len(base) - 2) + 1):  # obs[s]: after step s; y_{s0+1} is the first changed
        assert np.array_equal(base[s], changed[s]), f"observation after step {s} leaked the future"
    assert not np.array_equal(base[-1], changed[-1])


@pytest.mark.parametrize("controller", ["static", "lqg"])
def test_both_backends_give_the_same_output_episode(controller):
    cfg = {**CFG, "warmup_steps": 10, "controller": controller, "crypto_seed": 2, "max_samples": 40}
    acts = np.random.default_rng(5).uniform(-0.5, 0.5, (40, 2))
    _, o1, r1, i1 = _run({**cfg, "crypto": "ideal"}, acts)
    _, o2, r2, i2 = _run({**cfg, "crypto": "elgamal"}, acts)
    np.testing.assert_array_equal(o1, o2)
    np.testing.assert_array_equal(r1, r2)
    assert i1["epsilon"] == i2["epsilon"]


def test_online_arx_error_is_the_batch_arx_error_on_the_delivered_data():
    acts = np.random.default_rng(8).uniform(-0.4, 0.4, (120, 2))
    env, _, rewards, info = _run(CFG, acts)
    y, u = env.episode.delivered_data()
    lags = env.episode.lags
    # the batch ARX fit of the same samples (u_{N-1} is never a regressor: pad it)
    est = arx(np.vstack([u[0], np.zeros((1, 2))]), y[0], na=lags, nb=lags)
    p = env.params
    want = markov_error((p.A, p.B, p.C, np.zeros((1, 2))), est, 20)
    assert info["epsilon"] == pytest.approx(want, rel=1e-8)
    assert info["epsilon"] < 0.5  # 120 samples identify this plant's impulse response
    assert np.sum(rewards) == pytest.approx(-np.log(info["epsilon"]), rel=1e-9)  # telescopes from epsilon_0 = 1


def test_bad_output_configurations_are_refused():
    with pytest.raises(ParameterError, match="observe='state'"):
        resolve_params({"preset": "small", "max_samples": 50, "C": [[1.0, 0.0]]})
    with pytest.raises(ParameterError, match="unknown observe"):
        resolve_params({**CFG, "observe": "outputs"})
    with pytest.raises(ShapeError, match="C must have shape"):
        resolve_params({**CFG, "C": [[1.0, 0.0, 0.0]]})
    with pytest.raises(ParameterError, match="not observable"):
        resolve_params({**CFG, "preset": "fig1-a", "C": [[1.0, 1.0, 1.0, 1.0]]})
    with pytest.raises(ParameterError, match="sigma_v2"):
        resolve_params({**CFG, "sigma_v2": -1.0})
    with pytest.raises(ParameterError, match="ARX least squares, N4SID, PO-MOESP"):
        resolve_params({**CFG, "estimator": "bayes"})
    with pytest.raises(ParameterError, match="unknown controller"):
        resolve_params({**CFG, "controller": "pid"})


@pytest.mark.parametrize("estimator", ["ls", "n4sid"])
def test_the_vector_environment_steps_output_copies_as_single_environments(estimator):
    """Issue 34 item 10: copy i of the vector environment, seeded s, is the single environment
    seeded s + i, bit for bit, on outputs too."""
    from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv

    cfg = {**CFG, "estimator": estimator, "max_samples": 60}
    acts = np.random.default_rng(6).uniform(-0.4, 0.4, (60, 3, 2))
    vec = EncryptedLTIAttackVectorEnv(3, config=cfg)
    obs, info = vec.reset(seed=20)
    rows, rewards, eps = [obs], [], []
    for a in acts:
        obs, r, te, tr, info = vec.step(a)
        if te.any() or tr.any():
            break
        rows.append(obs)
        rewards.append(r)
        eps.append(info["epsilon"])
    vec.close()
    for i in range(3):
        env, o, r, single = _run(cfg, acts[: len(rewards), i], seed=20 + i)
        np.testing.assert_array_equal(np.array(rows)[:, i], o)
        np.testing.assert_array_equal(np.array(rewards)[:, i], r)
        assert eps[-1][i] == single["epsilon"]
    assert np.all(np.array(eps)[-1] < 1.0)  # every copy has an estimate by then


def test_close_releases_an_output_environment_through_gym_make():
    """Issue 34 item 22: ``close()`` on ``observe="output"`` (the episode has a ``close``), through
    ``gym.make`` and its wrappers, twice."""
    import gymnasium as gym

    import encctl_gym  # noqa: F401  (registers the id)

    env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config=CFG)
    env.reset(seed=0)
    env.step(np.zeros(2))
    env.close()
    env.close()
    bare = EncryptedLTIAttackEnv(config=CFG)
    bare.close()  # before any reset too
