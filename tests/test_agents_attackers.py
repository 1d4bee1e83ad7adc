"""The hand-written attackers: interface, action space, power, and the optimal design's gain."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import encctl_gym  # noqa: F401  (registers the environment)
from encctl_gym.agents import (
    Attacker,
    ColoredGaussianAttacker,
    GaussianAttacker,
    OptimalDesignAttacker,
    PRBSAttacker,
    observation_indices,
    rollout,
)
from encctl_gym.agents.evaluate import budget_config
from encctl_gym.envs import ENV_ID, EncryptedLTIAttackEnv
from encctl_gym.envs.config import resolve_params
from encctl_gym.envs.layout import ObservationLayout
from encctl_gym.errors import ParameterError
from encctl_gym.security.attack_design import gaussian_attack_design, optimal_attack_design

SMALL = {"preset": "small", "gamma_opt": False}
BASELINES = (GaussianAttacker, PRBSAttacker, ColoredGaussianAttacker)


def all_attackers(params):
    return [cls(params) for cls in BASELINES] + [OptimalDesignAttacker(params, feedback=params.decipher_delay is not None)]


@pytest.mark.parametrize("delay", [0, 2, "end"])
def test_every_attacker_runs_through_the_single_env_inside_the_action_space(delay):
    env = gym.make(ENV_ID, config={**SMALL, "decipher_delay": delay})
    for att in all_attackers(env.unwrapped.params):
        assert isinstance(att, Attacker)
        obs, info = env.reset(seed=3)
        att.reset(seed=4)
        steps = 0
        while True:
            a = att.act(obs)
            assert a.shape == env.action_space.shape and a.dtype == np.float32
            assert env.action_space.contains(a)
            obs, r, te, tr, info = env.step(a)
            steps += 1
            if te or tr:
                break
        assert steps == env.unwrapped.params.horizon
        assert np.isfinite(info["epsilon"]) and info["epsilon"] < 1.0, att.name


def test_from_env_works_on_wrapped_single_and_vector_envs():
    env = gym.make(ENV_ID, config=SMALL)
    venv = gym.make_vec(ENV_ID, num_envs=3, config=SMALL)
    for e in (env, venv):
        att = GaussianAttacker.from_env(e)
        assert att.params.horizon == env.unwrapped.params.horizon
    opt = OptimalDesignAttacker.from_env(gym.make(ENV_ID, config={**SMALL, "gamma_opt": True}))
    assert opt.design.kind == "closed_loop"


def test_batched_act_matches_the_vector_env():
    params = resolve_params(SMALL)
    venv = gym.make_vec(ENV_ID, num_envs=5, config=SMALL)
    obs, _ = venv.reset(seed=0)
    for att in all_attackers(params):
        att.reset(seed=1)
        a = att.act(obs)
        assert a.shape == (5, params.m) and np.all(np.abs(a) <= 1.0)
        with pytest.raises(ParameterError):
            att.act(obs[:2])  # batch size may not change within an episode
        att.reset(seed=1)
        assert np.array_equal(att.act(obs), a)  # same seed, same actions


def test_attacker_seed_reproduces_and_different_seeds_differ():
    params = resolve_params(SMALL)
    obs = np.zeros(ObservationLayout.of(params).dim, dtype=np.float32)
    for cls in BASELINES:
        a, b = cls(params), cls(params)
        a.reset(seed=11)
        b.reset(seed=11)
        xa = np.stack([a.act(obs) for _ in range(20)])
        xb = np.stack([b.act(obs) for _ in range(20)])
        assert np.array_equal(xa, xb)
        b.reset(seed=12)
        assert not np.array_equal(xa, np.stack([b.act(obs) for _ in range(20)]))


def test_bad_inputs_raise():
    params = resolve_params(SMALL)
    att = GaussianAttacker(params)
    with pytest.raises(ParameterError):
        att.act(np.zeros(3))
    with pytest.raises(ParameterError):
        ColoredGaussianAttacker(params, rho=1.0)
    with pytest.raises(ParameterError):
        GaussianAttacker({"preset": "small"})  # type: ignore[arg-type]
    with pytest.raises(ParameterError):
        OptimalDesignAttacker(resolve_params({**SMALL, "decipher_delay": "end"}), feedback=True)
    with pytest.raises(ParameterError):
        observation_indices(params, "everything")


def test_observation_modes_select_the_documented_columns():
    params = resolve_params(SMALL)
    lay = ObservationLayout.of(params)
    assert lay.dim == EncryptedLTIAttackEnv(config=SMALL).observation_space.shape[0]
    assert observation_indices(params, "full").tolist() == list(range(lay.dim))
    assert observation_indices(params, "no_budget").tolist() == list(range(lay.dim - 2))
    blind = observation_indices(params, "blind").tolist()
    assert blind == list(range(lay.history.start, lay.history.stop)) + [lay.dim - 2, lay.dim - 1]
    assert not set(blind) & set(range(lay.n + lay.m + 1))  # no delivered data in the blind view


# ------------------------------------------------------------------ power
@pytest.mark.parametrize("cls", BASELINES)
def test_baseline_input_power_is_sigma_u2(cls):
    params = resolve_params({"preset": "paper-example", "gamma_opt": False})
    att = cls(params)
    att.reset(seed=0)
    obs = np.zeros((64, ObservationLayout.of(params).dim), dtype=np.float32)
    u = np.concatenate([att.act(obs) for _ in range(300)]) * params.u_max  # 64 * 300 * m draws
    power = float(np.mean(u**2))
    tol = 1e-6 if cls is PRBSAttacker else 0.03  # binary: exactly sigma_u^2 (float32 rounding)
    assert abs(power / params.sigma_u2 - 1.0) < tol, (cls.__name__, power)
    assert abs(float(u.mean())) < 0.05 * math.sqrt(params.sigma_u2)


def test_colored_attacker_has_the_requested_lag_one_correlation():
    params = resolve_params({"preset": "paper-example", "gamma_opt": False})
    att = ColoredGaussianAttacker(params, rho=0.7)
    att.reset(seed=2)
    obs = np.zeros((32, ObservationLayout.of(params).dim), dtype=np.float32)
    u = np.stack([att.act(obs) for _ in range(2000)])  # (T, K, m)
    c = np.mean(u[1:] * u[:-1]) / np.mean(u * u)
    assert abs(c - 0.7) < 0.03


def test_average_power_through_the_env_matches_sigma_u2():
    cfg = budget_config({"preset": "paper-example", "gamma_opt": False}, 400)
    params = resolve_params(cfg)
    for cls in BASELINES:
        r = rollout(cls(params), cfg, episodes=16, seed=0, record=False)
        assert np.all(r.average_power <= params.sigma_u2 * (1 + 1e-9))  # the energy budget holds
        assert r.average_power.mean() > 0.95 * params.sigma_u2, cls.__name__


# ------------------------------------------------------------------ the optimal design
@pytest.mark.parametrize("delay", [0, "end"])
def test_optimal_design_attacker_beats_gaussian_where_the_design_predicts_a_gain(delay):
    # Figure 2's Psi_u = 0.1 I system: the design predicts a 37 % lower asymptotic error.
    preset = "fig2-psi0.1"
    cfg = budget_config({"preset": preset, "gamma_opt": False, "decipher_delay": delay}, 300)
    params = resolve_params(cfg)
    design = optimal_attack_design(params.A, params.B, sigma_u2=params.sigma_u2, sigma_w2=params.sigma_w2, feedback=delay == 0)
    gauss = gaussian_attack_design(params.A, params.B, sigma_u2=params.sigma_u2, sigma_w2=params.sigma_w2)
    assert design.rate / gauss.rate < 0.7  # check the prediction first
    g = rollout(GaussianAttacker(params), cfg, episodes=40, seed=100, record=False)
    o = rollout(OptimalDesignAttacker(params, design=design, feedback=delay == 0), cfg, episodes=40, seed=100, record=False)
    d = np.log(o.final_epsilon) - np.log(g.final_epsilon)  # paired: same environment seeds
    se = d.std(ddof=1) / math.sqrt(d.size)
    assert d.mean() + 3 * se < 0, (d.mean(), se)
    assert o.mean_final() < 0.85 * g.mean_final()
    assert abs(o.average_power.mean() / params.sigma_u2 - 1) < 0.05  # at (about) the same power


def test_optimal_design_attacker_with_a_delay_uses_the_model_prediction():
    cfg = budget_config({"preset": "fig2-psi0.1", "gamma_opt": False, "decipher_delay": 3}, 300)
    params = resolve_params(cfg)
    g = rollout(GaussianAttacker(params), cfg, episodes=30, seed=7, record=False)
    o = rollout(OptimalDesignAttacker(params), cfg, episodes=30, seed=7, record=False)
    assert o.mean_final() < g.mean_final()


@pytest.mark.parametrize("delay", [0, "end"])
def test_every_attacker_runs_through_real_elgamal_ciphertexts(delay):
    """A small key (64 bits) keeps it fast; the same attackers, the same interface."""
    cfg = budget_config({"preset": "small", "gamma_opt": False, "decipher_delay": delay, "key_length": 64}, 15)
    cfg.update(crypto="elgamal", crypto_seed=0)
    params = resolve_params(cfg)
    assert params.crypto == "elgamal" and params.key_length <= 64
    ideal = {k: v for k, v in cfg.items() if k not in ("crypto", "crypto_seed")}
    for att in all_attackers(params):
        r = rollout(att, cfg, episodes=1, seed=2, record=True)
        assert r.crypto == "elgamal" and r.N[-1] == 15 and np.isfinite(r.final_epsilon).all()
        # the ideal backend computes the same arithmetic without big integers: same episode
        r_ideal = rollout(att, ideal, episodes=1, seed=2, record=True)
        assert np.allclose(r.epsilon, r_ideal.epsilon, rtol=1e-9), att.name


# ------------------------------------------------------------------ realised design
def test_rollout_covariance_is_the_delivered_regressors_gram_over_their_count():
    cfg = budget_config({"preset": "small", "gamma_opt": False}, 40)
    p = resolve_params(cfg)
    r = rollout(GaussianAttacker(p), cfg, episodes=3, seed=2, record=False, covariance=True, batch=2)
    from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv

    att = GaussianAttacker(p)
    G, cols = 0.0, 0
    for chunk, k in [(0, 0), (0, 1), (1, 0)]:  # batches of 2: episodes 0, 1, then episode 2
        venv = EncryptedLTIAttackVectorEnv(2, config=cfg)
        obs, _ = venv.reset(seed=2 + 2 * chunk)
        att.reset(seed=np.random.SeedSequence([2, chunk]))
        while True:
            obs, _, te, tr, _ = venv.step(att.act(obs))
            if te[0] or tr[0]:
                break
        X, U = venv.episode.delivered_data()
        Z = np.concatenate([X[k, :-1], U[k]], axis=1)
        G, cols = G + Z.T @ Z, cols + Z.shape[0]
    assert np.allclose(r.covariance, G / cols, rtol=1e-12)


def test_design_efficiency_of_the_gaussian_attack_and_the_oracle():
    from encctl_gym.agents.evaluate import design_efficiency

    cfg = budget_config({"preset": "paper-example", "gamma_opt": False}, 2048)
    p = resolve_params(cfg)
    opt = optimal_attack_design(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2)
    gauss = gaussian_attack_design(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2)
    from scipy.optimize import minimize_scalar

    assert design_efficiency(gauss.Sigma, opt) == pytest.approx(opt.trace_inv / gauss.trace_inv, rel=1e-12)
    # by hand: one channel x+ = a x + b u + w under u = k x + v with E u^2 = s_u (A, B diagonal)
    a, b, sw, su = p.A[0, 0], p.B[0, 0], p.sigma_w2, p.sigma_u2

    def tr_inv(k):
        sxx = (b * b * su + sw) / (1 - (a + b * k) ** 2 + b * b * k * k)
        v = su - k * k * sxx
        return (sxx + su) / (sxx * v) if v > 0 and abs(a + b * k) < 1 else np.inf

    best = minimize_scalar(tr_inv, bounds=(-1.0, 1.0), method="bounded")
    assert opt.trace_inv == pytest.approx(p.n * best.fun, rel=1e-6) and opt.K[0, 0] == pytest.approx(best.x, abs=1e-3)
    assert gauss.trace_inv == pytest.approx(p.n * tr_inv(0.0), rel=1e-12)
    assert design_efficiency(opt.Sigma, opt) == pytest.approx(1.0, rel=1e-9)
    assert design_efficiency(np.diag([1.0, 0.0]), opt) == 0.0
    g = rollout(GaussianAttacker(p), cfg, episodes=16, seed=0, record=False, covariance=True)
    o = rollout(OptimalDesignAttacker(p, design=opt), cfg, episodes=16, seed=0, record=False, covariance=True)
    # 16 x 2047 regressors: the realised designs come within a few per cent of their closed forms
    assert design_efficiency(g.covariance, opt) == pytest.approx(best.fun / tr_inv(0.0), abs=0.02)
    assert design_efficiency(o.covariance, opt) == pytest.approx(1.0, abs=0.02)
    assert np.allclose(np.diag(g.covariance)[p.n :], p.sigma_u2, rtol=0.05)


def test_the_design_noise_root_does_not_depend_on_the_eigenvector_basis():
    """The design example's V is a multiple of the identity up to the solver's last digits: any
    orthonormal basis diagonalises it, so an eigenvector factor U diag(sqrt(w)) (and the inputs
    of a seed) is set by rounding; the symmetric root is sqrt(c) I for every such perturbation."""
    from encctl_gym.agents.optimal import psd_sqrt

    rng = np.random.default_rng(0)
    c, n = 8.5, 4
    roots = []
    for _ in range(3):
        E = rng.standard_normal((n, n)) * 1e-12
        S = c * np.eye(n) + (E + E.T)
        L = psd_sqrt(S)
        assert np.allclose(L @ L.T, S, rtol=0, atol=1e-9)
        roots.append(L)
    for L in roots:
        assert np.allclose(L, np.sqrt(c) * np.eye(n), rtol=0, atol=1e-9)
    # a rank-deficient covariance keeps its null space
    u = np.array([[1.0], [2.0], [0.0], [0.0]])
    L = psd_sqrt(u @ u.T)
    assert np.allclose(L @ L.T, u @ u.T, atol=1e-12) and np.allclose(L[2:], 0.0)
