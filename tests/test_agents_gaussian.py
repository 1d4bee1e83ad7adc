"""The paper's Gaussian attacker through the environment agrees with the engine's simulation.

``GaussianAttacker`` played through ``EncryptedLTIAttack-v0`` (ideal backend: encoding,
quantisation, the forged input, the energy budget) must give the mean final error of the
engine's batched Monte Carlo simulation of the same attack (:mod:`encctl_gym.sim.montecarlo`,
plain floating point, no loop) within Monte Carlo error, and that error must lie above
``gamma(N)`` of eq:sic (Theorem thm:sic says gamma is a lower bound of the expectation).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from encctl_gym.agents import GaussianAttacker, rollout
from encctl_gym.envs.config import resolve_params
from encctl_gym.sim.montecarlo import gaussian_attack_errors
from encctl_gym.sim.plant import LinearPlant

N = 200
EPISODES = 100
SIM_RUNS = 2000


@pytest.fixture(scope="module")
def both() -> tuple[np.ndarray, np.ndarray, float]:
    cfg = {"preset": "paper-example", "max_samples": N, "gamma_opt": False}
    params = resolve_params(cfg)
    assert params.horizon == N
    env_eps = rollout(GaussianAttacker(params), cfg, episodes=EPISODES, seed=123, record=False)
    assert env_eps.N[-1] == N
    plant = LinearPlant(params.A, params.B, sigma_w2=params.sigma_w2, sigma_x2=params.sigma_x2)
    sim_eps = gaussian_attack_errors(plant, sample_sizes=[N], runs=SIM_RUNS, sigma_u2=params.sigma_u2, seed=7)[:, 0]
    return env_eps.final_epsilon, sim_eps, float(params.gamma(N))


def _z(a: np.ndarray, b: np.ndarray) -> float:
    se = math.sqrt(a.var(ddof=1) / a.size + b.var(ddof=1) / b.size)
    return float((a.mean() - b.mean()) / se)


def test_env_mean_error_matches_engine_simulation(both):
    env_eps, sim_eps, _ = both
    assert env_eps.size >= 50
    # within 4 standard errors, on the mean and on the mean of the log
    assert abs(_z(env_eps, sim_eps)) < 4.0, (env_eps.mean(), sim_eps.mean())
    assert abs(_z(np.log(env_eps), np.log(sim_eps))) < 4.0
    # and not by luck of a huge spread: the two means agree to a few percent
    assert abs(env_eps.mean() / sim_eps.mean() - 1.0) < 0.08


def test_env_mean_error_lies_above_gamma(both):
    env_eps, _, gamma = both
    se = env_eps.std(ddof=1) / math.sqrt(env_eps.size)
    assert env_eps.mean() - 4 * se > gamma


def test_gaussian_attack_power_is_sigma_u2(both):
    cfg = {"preset": "paper-example", "max_samples": N, "gamma_opt": False}
    params = resolve_params(cfg)
    r = rollout(GaussianAttacker(params), cfg, episodes=20, seed=5, record=False)
    # the energy budget caps the total at m sigma_u2 N: mean power within a few percent below
    assert np.all(r.average_power <= params.sigma_u2 * (1 + 1e-9))
    assert abs(r.average_power.mean() / params.sigma_u2 - 1.0) < 0.03
