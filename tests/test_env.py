"""Tests of EncryptedLTIAttack-v0 and its native vector environment."""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest

import encctl_gym  # noqa: F401  (registers the environment)
from encctl_gym.envs import ENV_ID, EncryptedLTIAttackEnv, resolve_params
from encctl_gym.envs.config import default_config
from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv
from encctl_gym.errors import BudgetError, ParameterError, ResourceLimitError, ShapeError, UnstableSystemError
from encctl_gym.presets import get_preset

SMALL = {"preset": "small", "gamma_opt": False}


def run_episode(env, actions, seed):
    obs, info = env.reset(seed=seed)
    out = [(obs, 0.0, info)]
    for a in actions:
        obs, r, te, tr, info = env.step(a)
        out.append((obs, r, info))
        if te or tr:
            break
    return out, te, tr


def random_actions(rng, n_steps, m, scale=0.3):
    return np.clip(rng.normal(0.0, scale, (n_steps, m)), -1, 1).astype(np.float32)


# ------------------------------------------------------------------ ecosystem
@pytest.mark.parametrize(
    "overrides",
    [
        {},
        {"decipher_delay": 3},
        {"decipher_delay": "end"},
        {"reward": "logdet"},
        {"reward": "a_optimality", "decipher_delay": "end"},
        {"warmup_steps": 5},
        {"scheme": "token", "adversary": "server", "max_samples": 40},
        {"scheme": "static", "max_samples": 40},
        {"gamma_opt": True},
    ],
)
def test_checkers_pass_without_warning(overrides):
    from gymnasium.utils.env_checker import check_env

    cfg = {**SMALL, **overrides}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(gym.make(ENV_ID, config=cfg).unwrapped)  # with a spec: also checks render modes
    sb3_checker = pytest.importorskip("stable_baselines3.common.env_checker")  # the rl extra
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_checker.check_env(EncryptedLTIAttackEnv(config=cfg), warn=True)


def test_make_and_make_vec():
    env = gym.make(ENV_ID, config=SMALL)
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    venv = gym.make_vec(ENV_ID, num_envs=4, config=SMALL)
    assert isinstance(venv.unwrapped, EncryptedLTIAttackVectorEnv)
    obs, info = venv.reset(seed=0)
    assert obs.shape == (4, env.observation_space.shape[0])
    obs, r, te, tr, info = venv.step(venv.action_space.sample())
    assert r.shape == te.shape == tr.shape == (4,) and info["gamma"].shape == (4,)
    sync = gym.make_vec(ENV_ID, num_envs=2, vectorization_mode="sync", config=SMALL)
    assert sync.reset(seed=0)[0].shape == (2, env.observation_space.shape[0])


def test_seed_reproduces_episode_exactly():
    env = EncryptedLTIAttackEnv(config=SMALL)
    acts = random_actions(np.random.default_rng(1), 200, env.params.m)
    a, _, _ = run_episode(env, acts, seed=7)
    b, _, _ = run_episode(env, acts, seed=7)
    c, _, _ = run_episode(env, acts, seed=8)
    assert all(np.array_equal(x[0], y[0]) and x[1] == y[1] for x, y in zip(a, b))
    assert not all(np.array_equal(x[0], y[0]) for x, y in zip(a, c))


# ------------------------------------------------------------------ information flow
@pytest.mark.parametrize("delay", [0, 1, 4, "end"])
def test_observations_never_contain_undelivered_data(delay):
    """Change the plant's future after step s0 (the replayed noise from w_{s0} on): observations
    up to step s0 + d are unchanged."""
    cfg = {**SMALL, "decipher_delay": delay}
    s0 = 15
    acts = random_actions(np.random.default_rng(3), 200, 2)
    p = resolve_params(cfg)
    draws = np.random.default_rng(12)
    x0, noise = draws.normal(size=p.n), draws.normal(0.0, np.sqrt(p.sigma_w2), (p.warmup_steps + p.horizon, p.n))

    def trajectory(perturb):
        env = EncryptedLTIAttackEnv(config=cfg)
        w = noise.copy()
        if perturb:
            w[s0:] += 5.0  # every noise sample from step s0 on changes
        env.reset(seed=11, options={"x0": x0, "noise": w})
        obs_list = []
        for a in acts:
            obs, _, te, tr, _ = env.step(a)
            obs_list.append(obs)
            if te or tr:
                break
        return obs_list

    base, changed = trajectory(False), trajectory(True)
    d = len(base) if delay == "end" else delay
    # after step s (1-based) the observation holds states up to x_{s-d}; x_{s0+1} is the first changed
    for s in range(1, min(s0 + d, len(base) - 1) + 1):
        assert np.array_equal(base[s - 1], changed[s - 1]), f"observation after step {s} leaked the future"
    if delay != "end":
        assert not np.array_equal(base[s0 + d], changed[s0 + d])
    else:
        assert not np.array_equal(base[-1], changed[-1])


def test_replayed_draws_give_the_drawn_episode_and_bad_options_raise():
    """reset(options={"x0", "noise"}) with the values the generator would draw reproduces the
    drawn episode bit for bit; wrong shapes, non-finite values and unknown keys are errors."""
    env = EncryptedLTIAttackEnv(config=SMALL)
    p = env.params
    acts = random_actions(np.random.default_rng(4), p.horizon, p.m)
    drawn, _, _ = run_episode(env, acts, seed=3)
    g = np.random.default_rng(3)
    x0 = g.standard_normal(p.n) * np.sqrt(p.sigma_x2)
    w = g.standard_normal((p.warmup_steps + p.horizon, p.n)) * np.sqrt(p.sigma_w2)
    obs, info = env.reset(seed=99, options={"x0": x0, "noise": w})
    replay = [(obs, 0.0, info)] + [env.step(a)[:3:2] for a in acts]
    assert all(np.array_equal(a[0], b[0]) for a, b in zip(drawn, replay))
    with pytest.raises(ShapeError, match="noise"):
        env.reset(seed=0, options={"noise": w[:-1]})
    with pytest.raises(ShapeError, match="x0"):
        env.reset(seed=0, options={"x0": np.zeros(p.n + 1)})
    with pytest.raises(ParameterError, match="x0"):
        env.reset(seed=0, options={"x0": np.full(p.n, np.nan)})
    with pytest.raises(ParameterError, match="w0"):
        env.reset(seed=0, options={"w0": w})


def test_end_delay_delivers_nothing_before_the_end():
    env = EncryptedLTIAttackEnv(config={**SMALL, "decipher_delay": "end"})
    obs, info = env.reset(seed=0)
    n, m = env.params.n, env.params.m
    rewards = []
    while True:
        obs, r, te, tr, info = env.step(env.action_space.sample())
        rewards.append(r)
        if te or tr:
            break
        assert np.all(obs[: n + m] == 0) and obs[n + m] == 0.0 and info["samples_delivered"] == 0
    assert info["samples_delivered"] == env.params.horizon and obs[n + m] == 1.0
    assert all(r == 0.0 for r in rewards[:-1]) and rewards[-1] > 0


# ------------------------------------------------------------------ budget, energy, episode end
def test_budget_terminates_and_costs_follow_def_sdt():
    env = EncryptedLTIAttackEnv(config=SMALL)
    p = env.params
    assert p.budget_limited and p.horizon == math.floor(p.tau_c * p.upsilon / 2**p.security_parameter)
    _, info = env.reset(seed=0)
    steps = 0
    while True:
        _, _, te, tr, info = env.step(env.action_space.sample())
        steps += 1
        if te or tr:
            break
    assert te and not tr and steps == p.horizon
    assert info["samples_collected"] == p.horizon
    assert info["deciphering_time"] == pytest.approx(p.horizon * 2**p.security_parameter / p.upsilon, rel=1e-12)
    assert info["deciphering_time"] <= p.tau_c
    assert (p.horizon + 1) * 2**p.security_parameter / p.upsilon > p.tau_c  # the next sample is unaffordable


@pytest.mark.parametrize("scheme,adversary", [("token", "server"), ("static", "eavesdropper")])
def test_one_break_reveals_all_pays_once_and_truncates(scheme, adversary):
    env = EncryptedLTIAttackEnv(config={**SMALL, "scheme": scheme, "adversary": adversary, "max_samples": 30})
    env.reset(seed=0)
    for _ in range(30):
        _, _, te, tr, info = env.step(env.action_space.sample())
    assert tr and not te
    assert info["deciphering_time"] == pytest.approx(2**env.params.security_parameter / env.params.upsilon)


def test_token_eavesdropper_pays_every_sample():
    env = EncryptedLTIAttackEnv(config={**SMALL, "scheme": "token", "adversary": "eavesdropper"})
    env.reset(seed=0)
    _, _, _, _, info = env.step(env.action_space.sample())
    assert info["deciphering_time"] == pytest.approx(2 * 2**env.params.security_parameter / env.params.upsilon)


def test_energy_budget_is_enforced_and_reported():
    env = EncryptedLTIAttackEnv(config=SMALL)
    p = env.params
    env.reset(seed=0)
    full = np.ones(p.m, dtype=np.float32)  # 16 sigma_u2 per channel: 16 times the allowed power
    while True:
        obs, _, te, tr, info = env.step(full)
        if te or tr:
            break
    assert info["input_energy"] == pytest.approx(p.energy_budget, rel=1e-12)
    assert info["average_power"] == pytest.approx(p.sigma_u2, rel=1e-12)
    # after the budget is spent the injected input is zero: the plant applies the quantised 0,
    # and that is the input the last delivered sample reports
    zero = env.loop.inject(np.zeros((1, p.m)))[0]
    _, inputs = env.episode.delivered_data()
    assert np.array_equal(inputs[0, -1], zero) and np.abs(zero).max() < 2 / p.delta
    assert np.array_equal(obs[p.layout.input], zero.astype(np.float32))


def test_log_error_return_telescopes():
    env = EncryptedLTIAttackEnv(config=SMALL)
    _, info0 = env.reset(seed=5)
    total = 0.0
    while True:
        _, r, te, tr, info = env.step(env.action_space.sample() * 0.3)
        total += r
        if te or tr:
            break
    assert total == pytest.approx(math.log(info0["epsilon"]) - math.log(info["epsilon"]), rel=1e-9)
    assert info["epsilon"] < info0["epsilon"]


def test_final_epsilon_equals_batch_least_squares():
    from encctl_gym.ident import estimation_error, least_squares

    env = EncryptedLTIAttackEnv(config=SMALL)
    env.reset(seed=2)
    while True:
        _, _, te, tr, info = env.step(env.action_space.sample() * 0.3)
        if te or tr:
            break
    states, inputs = env.episode.delivered_data()
    assert states.shape == (1, env.params.horizon, env.params.n) and inputs.shape[1] == env.params.horizon - 1
    A_hat, B_hat = least_squares(states[0], inputs[0])
    assert info["epsilon"] == pytest.approx(estimation_error(env.params.A, env.params.B, A_hat, B_hat), rel=1e-8)


def test_a_constant_input_gets_the_minimum_norm_estimate_every_step():
    """A constant input makes the input columns collinear: the Gram matrix stays singular, no
    copy starts its recursion, and epsilon after every step is that of the minimum-norm least
    squares on the delivered data (numpy lstsq with the matching cut-off), in the vector
    environment and the single one alike."""
    K, act = 3, np.array([0.2, -0.1], dtype=np.float32)  # within the energy budget throughout
    venv = EncryptedLTIAttackVectorEnv(num_envs=K, config=SMALL)
    single = EncryptedLTIAttackEnv(config=SMALL)
    venv.reset(seed=7)
    single.reset(seed=7)
    p, core = venv.params, venv.episode
    d = p.n + p.m
    theta = np.hstack([p.A, p.B])
    for _ in range(p.horizon):
        obs_v, r_v, _, _, info_v = venv.step(np.tile(act, (K, 1)))
        obs, r, te, tr, info = single.step(act)
        assert np.array_equal(obs_v[0], obs) and r_v[0] == r and info_v["epsilon"][0] == info["epsilon"]
        N = info["samples_delivered"]
        if N - 1 >= d:
            X, U = core.delivered_data()
            Z = np.hstack([X[0, : N - 1], U[0]])
            th = np.linalg.lstsq(Z, X[0, 1:N], rcond=np.sqrt(d * np.finfo(float).eps))[0].T
            assert info["epsilon"] == pytest.approx(np.sum((th - theta) ** 2) / theta.size, rel=1e-6)
        if te or tr:
            break
    assert not core.kernels.ready.any()
    assert np.isfinite(info["epsilon"]) and info["epsilon"] > 0


# ------------------------------------------------------------------ backends and vector env
@pytest.mark.parametrize("gamma_opt", [False, True])
def test_vector_env_matches_single_envs_bit_for_bit(gamma_opt):
    K, cfg = 5, {**SMALL, "gamma_opt": gamma_opt}
    venv = EncryptedLTIAttackVectorEnv(num_envs=K, config=cfg)
    singles = [EncryptedLTIAttackEnv(config=cfg) for _ in range(K)]
    obs_v, _ = venv.reset(seed=100)
    obs_s = [e.reset(seed=100 + i)[0] for i, e in enumerate(singles)]
    assert np.array_equal(obs_v, np.stack(obs_s))
    rng = np.random.default_rng(0)
    for _ in range(venv.params.horizon + 2):  # through the end and the autoreset
        acts = random_actions(rng, K, venv.params.m)
        obs_v, r_v, te_v, tr_v, info_v = venv.step(acts)
        for i, e in enumerate(singles):
            if e.episode.done:
                obs, info = e.reset()
                r, te = 0.0, False
            else:
                obs, r, te, _, info = e.step(acts[i])
            assert np.array_equal(obs_v[i], obs) and r_v[i] == r and te_v[i] == te
            assert info_v.keys() == info.keys() and all(info_v[key][i] == info[key] for key in info)


@pytest.mark.parametrize("scheme", ["modified", "token", "static"])
def test_elgamal_backend_reproduces_ideal_trajectory_bit_for_bit(scheme):
    cfg = {**SMALL, "scheme": scheme, "key_length": 128, "max_samples": 25, "warmup_steps": 3, "crypto_seed": 1}
    acts = random_actions(np.random.default_rng(9), 25, 2)
    ideal, _, _ = run_episode(EncryptedLTIAttackEnv(config={**cfg, "crypto": "ideal"}), acts, seed=4)
    real, _, _ = run_episode(EncryptedLTIAttackEnv(config={**cfg, "crypto": "elgamal"}), acts, seed=4)
    assert len(ideal) == len(real) == 26
    for (o1, r1, _), (o2, r2, _) in zip(ideal, real):
        assert np.array_equal(o1, o2) and r1 == r2


def test_elgamal_backend_sends_real_ciphertexts():
    from encctl_gym.crypto.modified import ModifiedCiphertext

    env = EncryptedLTIAttackEnv(config={**SMALL, "crypto": "elgamal", "key_length": 128, "max_samples": 20})
    env.reset(seed=0)
    env.step(env.action_space.sample())
    loop = env.loop
    assert all(isinstance(c, ModifiedCiphertext) for row in loop.last_output_ciphertexts for c in row)
    assert loop.plant.t == 1 and loop.group.bits == 128


def test_render_rgb_array():
    env = EncryptedLTIAttackEnv(config={**SMALL, "gamma_opt": True}, render_mode="rgb_array")
    env.reset(seed=0)
    for _ in range(20):
        env.step(env.action_space.sample())
    img = env.render()
    assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3 and img.std() > 0


def test_info_reports_bounds():
    env = EncryptedLTIAttackEnv(config={**SMALL, "gamma_opt": True})
    env.reset(seed=0)
    for _ in range(20):
        _, _, _, _, info = env.step(env.action_space.sample())
    # gamma_opt is the sharper tr(Sigma^-1) form (no Jensen step): compare it with the same form
    # for the paper's i.i.d. Gaussian attacker, which it can only improve on
    from encctl_gym.security.attack_design import gaussian_attack_design

    p = env.params
    gauss = gaussian_attack_design(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2)
    N = info["samples_delivered"]
    assert 0 < info["gamma_opt"] <= gauss.gamma(N) * (1 + 1e-9)


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize(
    "overrides,error,text",
    [
        ({"A": [[1.2, 0], [0, 0.5]], "B": [[1, 0], [0, 1]]}, UnstableSystemError, "1.2"),
        ({"A": [[0.5, 0], [0, 0.5]], "B": [[1, 0, 0]]}, ShapeError, "B"),
        ({"upsilon": 0}, ParameterError, "upsilon"),
        ({"tau_c": -1}, ParameterError, "tau_c"),
        ({"sigma_u2": 0}, ParameterError, "sigma_u2"),
        ({"sigma_w2": float("nan")}, ParameterError, "sigma_w2"),
        ({"scheme": "rsa"}, ParameterError, "rsa"),
        ({"crypto": "paillier"}, ParameterError, "paillier"),
        ({"preset": "nope"}, ParameterError, "nope"),
        ({"reward": "win"}, ParameterError, "win"),
        ({"decipher_delay": "later"}, ParameterError, "later"),
        ({"max_samples": 4}, BudgetError, r"n \+ m \+ 1"),
        ({"tau_c": 1.0, "security_parameter": 81}, BudgetError, "N = 0"),
        ({"scheme": "static"}, ParameterError, "max_samples"),
        ({"colour": "red"}, ParameterError, "colour"),
    ],
)
def test_bad_configuration_raises_named_error(overrides, error, text):
    with pytest.raises(error, match=text):
        EncryptedLTIAttackEnv(config={**SMALL, **overrides})


@pytest.mark.parametrize("action", [[2.0, 0.0], [float("nan"), 0.0], [float("-inf"), 0.0], [0.0, 0.0, 0.0]])
def test_bad_action_raises(action):
    env = EncryptedLTIAttackEnv(config=SMALL)
    env.reset(seed=0)
    with pytest.raises(ParameterError, match="action"):
        env.step(np.array(action, dtype=np.float32))


def test_actions_are_read_not_changed_and_every_form_gives_the_same_step():
    """The energy budget scales the applied input down, never the caller's array; float32,
    float64, a list and an edge value off by float32 rounding all give the same step."""
    K = 3
    venv = EncryptedLTIAttackVectorEnv(num_envs=K, config=SMALL)
    p = venv.params
    edge = np.nextafter(np.float32(1.0), np.float32(2.0))  # 1 + 1.2e-7: clipped to 1
    acts = np.full((K, p.m), edge, dtype=np.float32)
    forms = [acts, acts.astype(np.float64), acts.tolist(), np.ones((K, p.m))]
    results = []
    for a in forms:
        venv.reset(seed=4)
        keep = np.array(a, copy=True)
        for _ in range(p.horizon - 1):  # 16 times the allowed power: the budget runs out
            obs, r, *_ = venv.step(a)
        assert np.array_equal(np.asarray(a), keep)
        results.append((obs, r))
    assert all(np.array_equal(o, results[0][0]) and np.array_equal(r, results[0][1]) for o, r in results)


def test_state_outside_declared_range_raises_overflow():
    from encctl_gym.errors import EncodingOverflowError

    env = EncryptedLTIAttackEnv(config={**SMALL, "x_bound": 0.5, "sigma_x2": 100.0})
    with pytest.raises(EncodingOverflowError):
        for seed in range(20):
            env.reset(seed=seed)
            for _ in range(10):
                env.step(env.action_space.sample())


def test_both_backends_refuse_a_state_outside_x_bound_at_the_same_step():
    from encctl_gym.errors import EncodingOverflowError

    cfg = {**SMALL, "x_bound": 1.5, "sigma_x2": 0.01, "key_length": 128, "max_samples": 40}
    acts = np.ones((40, 2), dtype=np.float32)  # drives the state out of range
    steps = {}
    for crypto in ("ideal", "elgamal"):
        env = EncryptedLTIAttackEnv(config={**cfg, "crypto": crypto})
        env.reset(seed=3)
        with pytest.raises(EncodingOverflowError, match="1.5"):
            for k, a in enumerate(acts):
                steps[crypto] = k
                env.step(a)
    assert steps["ideal"] == steps["elgamal"]


def test_parallel_vector_env_gives_the_same_numbers():
    from encctl_gym.envs import _kernels

    K = 2 * _kernels.PARALLEL_CHUNK + 3  # three tasks, one of them short
    serial = EncryptedLTIAttackVectorEnv(num_envs=K, config=SMALL)
    parallel = EncryptedLTIAttackVectorEnv(num_envs=K, config=SMALL, parallel=True)
    o1, _ = serial.reset(seed=5)
    o2, _ = parallel.reset(seed=5)
    rng = np.random.default_rng(2)
    for _ in range(serial.params.horizon + 2):
        acts = random_actions(rng, K, serial.params.m)
        a = serial.step(acts)
        b = parallel.step(acts)
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]) and np.array_equal(a[2], b[2])


def test_helper_thread_gives_the_same_numbers_through_refreshes_and_early_resets():
    """The helper thread (noise drawn ahead, Gram catch-up) changes where work runs, not the
    numbers: a vector env with it matches single envs without it, step for step, through noise
    chunks, Gram hand-overs, exact refreshes, the episode end and resets in mid-episode."""
    from encctl_gym.envs.schedule import EpisodeSchedule

    schedule = EpisodeSchedule(chunk=16, gram_batch=4, refresh=40)  # many chunk, hand-over and refresh boundaries
    K, cfg = 4, {**SMALL, "scheme": "static", "max_samples": 150}
    venv = EncryptedLTIAttackVectorEnv(num_envs=K, config=cfg, helper_thread=True, schedule=schedule)
    singles = [EncryptedLTIAttackEnv(config=cfg, schedule=schedule) for _ in range(K)]
    assert venv.helper is not None and singles[0].episode.helper is None
    obs_v, _ = venv.reset(seed=7)
    obs_s = [e.reset(seed=7 + i)[0] for i, e in enumerate(singles)]
    rng = np.random.default_rng(1)
    for step in range(400):
        if step in (180, 233):  # mid-episode resets without a seed: the generators go on
            obs_v, info_v = venv.reset()
            obs_s = [e.reset()[0] for e in singles]
            assert np.array_equal(obs_v, np.stack(obs_s))
            continue
        acts = random_actions(rng, K, venv.params.m)
        obs_v, r_v, te_v, _, info_v = venv.step(acts)
        for i, e in enumerate(singles):
            if e.episode.done:
                obs, _ = e.reset()
                r, eps = 0.0, e.episode.eps[0]
            else:
                obs, r, _, _, info = e.step(acts[i])
                eps = info["epsilon"]
            assert np.array_equal(obs_v[i], obs) and r_v[i] == r and info_v["epsilon"][i] == eps, f"step {step}"
    assert venv.helper.started
    venv.close()
    assert not venv.helper.started


def test_a_vector_env_with_the_helper_busy_can_be_pickled_and_copied():
    import copy
    import pickle

    venv = EncryptedLTIAttackVectorEnv(num_envs=2, config=LONG, helper_thread=True)
    venv.reset(seed=0)
    acts = random_actions(np.random.default_rng(0), 300, venv.params.m)
    for a in acts[:270]:  # past a noise chunk and Gram hand-overs: work is on the helper
        venv.step(np.stack([a, a]))
    clones = [pickle.loads(pickle.dumps(venv)), copy.deepcopy(venv)]
    for a in acts[270:]:
        want = venv.step(np.stack([a, a]))
        for c in clones:
            got = c.step(np.stack([a, a]))
            assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])


def test_helper_thread_works_in_a_forked_child():
    """A child forked after the parent used the helper thread starts its own."""
    import multiprocessing as mp

    venv = EncryptedLTIAttackVectorEnv(num_envs=2, config=LONG, helper_thread=True)
    venv.reset(seed=0)
    for _ in range(300):  # past a noise chunk: the parent's helper thread has run
        venv.step(np.zeros((2, venv.params.m), np.float32))
    assert venv.helper.started and venv.params.horizon == 600
    child = mp.get_context("fork").Process(target=_step_past_a_chunk)
    child.start()
    child.join(120)
    alive = child.is_alive()
    if alive:
        child.kill()
    assert not alive and child.exitcode == 0


LONG = {**SMALL, "scheme": "static", "max_samples": 600}


def _step_past_a_chunk() -> None:
    venv = EncryptedLTIAttackVectorEnv(num_envs=2, config=LONG, helper_thread=True)
    venv.reset(seed=1)
    for _ in range(300):
        venv.step(np.zeros((2, venv.params.m), np.float32))
    venv.close()


# ------------------------------------------------------------------ hardening (the probe's classes)
@pytest.mark.parametrize(
    "overrides,error,text",
    [
        ({"gamma_opt": "no"}, ParameterError, "gamma_opt"),
        ({"gamma_opt": 1}, ParameterError, "gamma_opt"),
        ({"preset": ["small"]}, ParameterError, "preset"),
        ({"decipher_delay": np.array([1, 2])}, ParameterError, "decipher_delay"),
        ({"scheme": ["modified"]}, ParameterError, "scheme"),
        ({"warmup_steps": 10**9}, ParameterError, "warmup_steps"),
        ({"input_history": 10**9}, ParameterError, "input_history must be <= 64 .*got 1000000000"),
        ({"scheme": "static", "max_samples": 10**12}, ParameterError, "GiB"),
    ],
)
def test_bad_values_are_refused_before_any_work(overrides, error, text):
    with pytest.raises(error, match=text):
        EncryptedLTIAttackEnv(config={**SMALL, **overrides})


def test_a_config_that_is_not_a_mapping_is_a_config_error():
    from encctl_gym.errors import ConfigError

    with pytest.raises(ConfigError, match="abc"):
        EncryptedLTIAttackEnv(config="abc")


def test_a_huge_batch_is_refused_with_its_memory_estimate():
    with pytest.raises(ParameterError, match=r"num_envs = 1000000 .* GiB"):
        EncryptedLTIAttackVectorEnv(num_envs=10**6, config=SMALL)


def test_step_before_reset_and_bool_seeds_are_refused():
    env = EncryptedLTIAttackEnv(config=SMALL)
    with pytest.raises(ParameterError, match="before reset"):
        env.step(np.zeros(2, np.float32))
    with pytest.raises(ParameterError, match="seed"):
        env.reset(seed=True)
    venv = EncryptedLTIAttackVectorEnv(num_envs=2, config=SMALL)
    with pytest.raises(ParameterError, match="seed"):
        venv.reset(seed=[0, True])
    with pytest.raises(ParameterError, match="seed"):
        venv.reset(seed=-1)


@pytest.mark.parametrize("action", [["a", "b"], [1 + 2j, 0.0], np.array([0.5 + 0.1j, 0.0]), None])
def test_non_numeric_and_complex_actions_are_refused(action):
    env = EncryptedLTIAttackEnv(config=SMALL)
    env.reset(seed=0)
    with pytest.raises(ParameterError, match="action"):
        env.step(action)


def test_a_tiny_logdet_regularization_still_gives_finite_rewards():
    env = EncryptedLTIAttackEnv(config={**SMALL, "reward": "logdet", "logdet_regularization": 1e-300})
    env.reset(seed=0)
    rewards = [env.step(env.action_space.sample())[1] for _ in range(20)]
    assert all(math.isfinite(r) for r in rewards)


def test_a_users_plant_is_completed_from_the_default_preset_with_a_warning_and_not_with_preset_none():
    A, B = [[0.5, 0.0], [0.1, 0.4]], [[1.0], [0.5]]
    paper = get_preset(default_config()["preset"])
    with pytest.warns(UserWarning, match=f"preset '{paper.name}'.*sigma_w2"):
        d = resolve_params({"A": A, "B": B, "gamma_opt": False})
    assert d.sources["A"] == "config" and d.sources["sigma_w2"] == f"preset {paper.name}"
    assert (d.sigma_w2, d.sigma_u2, d.tau_c, d.upsilon) == (paper.sigma_w2, paper.sigma_u2, paper.tau_c, paper.upsilon)
    with pytest.raises(ParameterError) as err:
        resolve_params({"A": A, "B": B, "preset": None})
    for key in ("sigma_w2", "sigma_u2", "upsilon", "tau_c", "gamma_c"):
        assert key in str(err.value)  # every missing value named at once
    full = {"A": A, "B": B, "sigma_w2": 0.1, "sigma_u2": 1.0, "upsilon": 1e9, "tau_c": 1e3, "gamma_c": 1e-3, "key_length": 64}
    p = resolve_params({**full, "preset": None})
    assert p.sources["sigma_x2"] == "default" and p.sources["A"] == "config" and p.sources["tau_c"] == "config"
    with pytest.warns(UserWarning, match="preset 'small'.*sigma_w2"):
        q = resolve_params({"preset": "small", "A": A, "B": B, "gamma_opt": False})
    assert q.sources["sigma_w2"] == "preset small" and q.sources["A"] == "config"


@pytest.mark.parametrize("x_bound", [1e5, 1e6])
def test_a_quantisation_table_too_large_is_refused_with_its_size(x_bound):
    with pytest.raises(ResourceLimitError, match="x_bound"):
        EncryptedLTIAttackEnv(config={**SMALL, "x_bound": x_bound})


# ------------------------------------------------------------------ estimators (beyond least squares)
@pytest.mark.parametrize(
    "estimator", ["bayes", "forgetting", "iv", {"name": "bayes", "prior_variance": 1.0, "noise_variance": 0.1}]
)
def test_a_configured_estimator_gives_epsilon_and_reward_of_its_own_fit(estimator):
    """info["epsilon"] is the error of the estimator's fit on the delivered data (its batch fit
    computed here independently), the log_error return telescopes, and the vector environment
    equals single environments copy for copy."""
    from encctl_gym.ident import estimation_error
    from encctl_gym.ident.registry import make_estimator

    cfg = {**SMALL, "estimator": estimator}
    K = 3
    venv = EncryptedLTIAttackVectorEnv(num_envs=K, config=cfg)
    singles = [EncryptedLTIAttackEnv(config=cfg) for _ in range(K)]
    venv.reset(seed=20)
    infos0 = [e.reset(seed=20 + i)[1] for i, e in enumerate(singles)]
    rng, totals = np.random.default_rng(5), np.zeros(K)
    for _ in range(venv.params.horizon):
        acts = random_actions(rng, K, 2, scale=0.5)
        obs_v, r_v, te, tr, info_v = venv.step(acts)
        for i, e in enumerate(singles):
            obs, r, _, _, info = e.step(acts[i])
            assert np.array_equal(obs_v[i], obs) and r_v[i] == r and info_v["epsilon"][i] == info["epsilon"]
            totals[i] += r
        if te[0] or tr[0]:
            break
    p = venv.params
    X, U = venv.episode.delivered_data()
    for i in range(K):
        theta = make_estimator(estimator).fit(X[i], U[i])
        want = estimation_error(p.A, p.B, theta[:, : p.n], theta[:, p.n :])
        assert info_v["epsilon"][i] == pytest.approx(want, rel=1e-9)
        assert totals[i] == pytest.approx(math.log(infos0[i]["epsilon"]) - math.log(info_v["epsilon"][i]), rel=1e-9)


@pytest.mark.parametrize(
    "estimator,text",
    [
        ("ridge", "ridge"),
        ({"name": "forgetting", "forgetting_factor": 1.5}, "1.5"),
        ({"name": "forgetting", "factor": 0.9}, "factor"),
        ({"name": "bayes", "prior_variance": -1.0}, "variance"),
        (3, "3"),
    ],
)
def test_a_bad_estimator_is_refused_at_construction(estimator, text):
    with pytest.raises(ParameterError, match=text):
        EncryptedLTIAttackEnv(config={**SMALL, "estimator": estimator})


# ---------------------------------------------------------------- hardening
@pytest.mark.parametrize("action", [np.array([True, False]), [True, False], np.array([[0.1 + 1j, 0.0]]), np.array(["a", "b"])])
def test_boolean_complex_and_string_actions_are_refused_naming_them(action):
    """A boolean action is not read as 0/1, a complex one is not cut to its real part."""
    env = EncryptedLTIAttackEnv(config=SMALL)
    env.reset(seed=0)
    with pytest.raises(ParameterError, match="action must be a real numeric array") as err:
        env.step(action)
    assert ("True" in str(err.value)) if np.asarray(action).dtype.kind == "b" else True


@pytest.mark.parametrize(
    ("key", "value", "text"),
    [
        ("warmup_steps", 10**5000, "warmup_steps must be <= 100000 .*about 5001 digits"),
        ("input_history", 10**400, "input_history must be <= 64 .*about 401 digits"),
        ("input_history", 65, "input_history must be <= 64 .*got 65"),
        ("delta", 10**400, "delta must be <= 2\\^53 .*about 401 digits"),
        ("delta", 2**53 + 1, "delta must be <= 2\\^53 .*9007199254740993"),
    ],
    ids=["warmup_steps-5001-digits", "input_history-401-digits", "input_history-65", "delta-401-digits", "delta-2^53+1"],
)
def test_huge_integer_settings_are_refused_naming_the_value(key, value, text):
    with pytest.raises(ParameterError, match=text):
        resolve_params({**SMALL, key: value})


def test_an_infinite_actuator_bound_is_refused():
    """action_scale = 1e308 with sigma_u2 = 4 makes u_max = 2e308 = inf in float64."""
    with pytest.raises(ParameterError, match=r"u_max.*action_scale = 1e\+308 and sigma_u2 = 4"):
        resolve_params(
            {
                **SMALL,
                "preset": None,
                "A": [[0.5]],
                "B": [[1.0]],
                "sigma_w2": 1.0,
                "sigma_u2": 4.0,
                "upsilon": 1e9,
                "tau_c": "1y",
                "gamma_c": 1e-3,
                "action_scale": 1e308,
            }
        )


def test_a_quantisation_table_beyond_its_bound_is_refused_before_it_is_built():
    """x_bound = 2e4 at Delta = 4096 needs |round(Delta x)| up to 81 920 001 > 2^24 entries."""
    from encctl_gym.loop.ideal import MAX_TABLE_LIMIT

    assert 4096 * 20000 + 1 > MAX_TABLE_LIMIT
    with pytest.raises(ResourceLimitError, match=r"x_bound = 20000.0, Delta = 4096.*81920001.*2\^24"):
        EncryptedLTIAttackEnv(config={**SMALL, "x_bound": 2e4})
    with pytest.raises(ResourceLimitError, match=r"x_bound = 20000.0"):
        EncryptedLTIAttackVectorEnv(num_envs=2, config={**SMALL, "x_bound": 2e4}, helper_thread=False)


def test_a_batch_beyond_the_float_range_is_refused_with_its_size():
    with pytest.raises(ResourceLimitError, match=r"num_envs = <integer of 1329 bits, about 401 digits>"):
        EncryptedLTIAttackVectorEnv(num_envs=10**400, config=SMALL, helper_thread=False)


@pytest.mark.parametrize("delta", [1e-300, 1e-320, 5e-324])
def test_a_subnormal_a_optimality_regularization_gives_finite_rewards_that_telescope(delta):
    """The return of ``a_optimality`` telescopes to log(d / delta) - log tr((G_N + delta I)^-1):
    finite although d / delta overflows float64 for a subnormal delta."""
    env = EncryptedLTIAttackEnv(config={**SMALL, "reward": "a_optimality", "logdet_regularization": delta})
    env.reset(seed=0)
    rewards = []
    for _ in range(200):
        _, r, term, trunc, _ = env.step(np.full(2, 0.5, dtype=np.float32))
        rewards.append(r)
        if term or trunc:
            break
    assert all(math.isfinite(r) for r in rewards)
    # The constant action makes G exactly singular, so whether its smallest eigenvalue comes out as
    # 0, -2e-32 or 1e-17 is the machine's rounding: the reference takes the same eigenvalues as the
    # environment and never exponentiates 1 / (0 + delta) (which overflows float64), so it holds
    # whatever the BLAS returns.
    lam = np.clip(np.linalg.eigvalsh(env.episode.G[0]), 0.0, None)
    expected = (math.log(4) - math.log(delta)) - _log_sum_of_inverses(lam, delta)
    assert math.isclose(sum(rewards), expected, rel_tol=1e-9)


def _log_sum_of_inverses(lam, delta):
    """log sum_i 1 / (lam_i + delta) by a max-shifted sum of Python floats (no overflow)."""
    logs = [-math.log(float(v) + delta) for v in lam]
    top = max(logs)
    return top + math.log(math.fsum(math.exp(x - top) for x in logs))


@pytest.mark.parametrize("delta", [0.5, 1e-300, 1e-320, 5e-324])
def test_a_optimality_measure_of_an_exactly_singular_gram_matrix(delta):
    """A diagonal G has exact eigenvalues (no rounding): two exact zeros and 1, 2 give
    log(2 / delta + 1 / (1 + delta) + 1 / (2 + delta)), finite although 1 / delta overflows."""
    from types import SimpleNamespace

    from encctl_gym.envs.rewards import AOptimalityReward

    reward = AOptimalityReward(SimpleNamespace(n=2, m=2, logdet_regularization=delta), num_envs=1)
    G = np.diag([0.0, 1.0, 0.0, 2.0])[None]
    # exact reference: log(2 / delta) + log(1 + delta / 2 (1 / (1 + delta) + 1 / (2 + delta)))
    expected = math.log(2) - math.log(delta) + math.log1p(delta / 2 * (1 / (1 + delta) + 1 / (2 + delta)))
    assert math.isclose(float(reward.measure(G)[0]), expected, rel_tol=1e-12)


def test_bad_vector_flags_are_refused_before_a_helper_thread_starts():
    import threading

    before = threading.active_count()
    for kw in ({"parallel": "no"}, {"helper_thread": 1}):
        with pytest.raises(ParameterError, match="must be a bool"):
            EncryptedLTIAttackVectorEnv(num_envs=2, config=SMALL, **kw)
    assert threading.active_count() == before


@pytest.mark.parametrize("how", ["deepcopy", "pickle"])
def test_a_copied_env_rewards_and_identifies_on_as_the_original(how):
    """The copy's Gram views G and C stay views of its own [G | C] (a deep copy of a numpy view is
    an array of its own, which the kernels would no longer update: the copy's reward was 0 and its
    epsilon frozen from the copy on)."""
    import copy
    import pickle

    env = gym.make(ENV_ID, config={"preset": "paper-example", "decipher_delay": 0, "max_samples": 30})
    env.reset(seed=0)
    a = np.full(env.action_space.shape, 0.3, dtype=np.float32)
    for _ in range(4):
        env.step(a)
    twin = copy.deepcopy(env) if how == "deepcopy" else pickle.loads(pickle.dumps(env))
    for _ in range(20):
        _, r1, *_, i1 = env.step(a)
        _, r2, *_, i2 = twin.step(a)
        assert r1 == r2 and i1["epsilon"] == i2["epsilon"]
    assert r1 != 0.0
