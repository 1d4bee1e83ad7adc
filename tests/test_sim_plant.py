"""Tests of encctl_gym.sim.plant: eq:system, its validation and the seeded batched simulator."""

from __future__ import annotations

import numpy as np
import pytest

from encctl_gym.errors import EncctlError, ParameterError, ShapeError
from encctl_gym.security.gramians import controllability_gramian, noise_gramian
from encctl_gym.sim.plant import LinearPlant, simulate, simulate_gaussian_attack

A2 = np.array([[0.6, 0.2], [-0.1, 0.5]])
B2 = np.array([[1.0, 0.0], [0.3, 0.8]])


def test_plant_attributes_and_repr() -> None:
    p = LinearPlant(A2, B2, sigma_w2=0.5, sigma_x2=2.0)
    assert (p.n, p.m) == (2, 2)
    assert p.sigma_w2 == 0.5 and p.sigma_x2 == 2.0
    assert "n=2" in repr(p)
    with pytest.raises(ValueError):
        p.A[0, 0] = 1.0  # read-only: a plant cannot be changed behind the simulator's back


def test_vector_B_for_single_input() -> None:
    p = LinearPlant(np.eye(3) * 0.5, np.ones(3), sigma_w2=1.0)
    assert p.B.shape == (3, 1)


@pytest.mark.parametrize(
    "A, B, kwargs, exc",
    [
        (np.ones((2, 3)), np.ones((2, 1)), {"sigma_w2": 1.0}, ShapeError),  # A not square
        (np.eye(2), np.ones((3, 1)), {"sigma_w2": 1.0}, ShapeError),  # B rows != n
        (np.array([[np.nan, 0], [0, 0.5]]), np.eye(2), {"sigma_w2": 1.0}, ParameterError),
        (np.eye(2) * 0.5, np.array([[np.inf], [0.0]]), {"sigma_w2": 1.0}, ParameterError),
        (np.eye(2) * 0.5, np.eye(2), {"sigma_w2": -1.0}, ParameterError),
        (np.eye(2) * 0.5, np.eye(2), {"sigma_w2": 0.0}, ParameterError),
        (np.eye(2) * 0.5, np.eye(2), {"sigma_w2": 1.0, "sigma_x2": -0.1}, ParameterError),
        (np.eye(2) * 0.5, np.eye(2), {"sigma_w2": float("nan")}, ParameterError),
    ],
)
def test_plant_rejects_bad_input(A, B, kwargs, exc) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(exc) as info:
        LinearPlant(A, B, **kwargs)
    assert isinstance(info.value, EncctlError)


def test_next_state_is_eq_system_and_batched() -> None:
    p = LinearPlant(A2, B2, sigma_w2=1.0)
    rng = np.random.default_rng(1)
    x, u, w = rng.standard_normal((5, 3, 2)), rng.standard_normal((5, 3, 2)), rng.standard_normal((5, 3, 2))
    out = p.next_state(x, u, w)
    assert out.shape == (5, 3, 2)
    np.testing.assert_allclose(out[2, 1], A2 @ x[2, 1] + B2 @ u[2, 1] + w[2, 1], rtol=1e-14)
    single = p.next_state(x[0, 0], u[0, 0], w[0, 0])
    np.testing.assert_allclose(single, out[0, 0], rtol=1e-14)


def test_initial_state_and_noise_shapes_and_variance() -> None:
    p = LinearPlant(A2, B2, sigma_w2=0.25, sigma_x2=4.0)
    rng = np.random.default_rng(2)
    assert p.initial_state(rng).shape == (2,)
    assert p.noise(rng, (3, 4)).shape == (3, 4, 2)
    x0 = p.initial_state(rng, 200_000)
    w = p.noise(rng, 200_000)
    # Sample variances within ~5 standard errors (sd of a variance estimate ~ sqrt(2/N) var).
    np.testing.assert_allclose(x0.var(axis=0), 4.0, rtol=0.02)
    np.testing.assert_allclose(w.var(axis=0), 0.25, rtol=0.02)


def test_simulate_gaussian_attack_obeys_eq_system() -> None:
    p = LinearPlant(A2, B2, sigma_w2=0.3)
    sim = simulate_gaussian_attack(p, N=50, runs=4, sigma_u2=2.0, seed=7)
    assert sim.states.shape == (4, 50, 2) and sim.inputs.shape == (4, 50, 2) and sim.noises.shape == (4, 49, 2)
    assert (sim.runs, sim.N) == (4, 50)
    resid = sim.states[:, 1:] - (sim.states[:, :-1] @ A2.T + sim.inputs[:, :-1] @ B2.T)
    np.testing.assert_allclose(resid, sim.noises, atol=1e-12)


def test_seeding_reproducible_prefix_and_run_independent() -> None:
    p = LinearPlant(A2, B2, sigma_w2=0.3)
    a = simulate_gaussian_attack(p, N=100, runs=5, sigma_u2=1.0, seed=11)
    b = simulate_gaussian_attack(p, N=100, runs=5, sigma_u2=1.0, seed=11)
    np.testing.assert_array_equal(a.states, b.states)
    c = simulate_gaussian_attack(p, N=100, runs=5, sigma_u2=1.0, seed=12)
    assert not np.allclose(a.states, c.states)
    # Run r does not depend on how many runs are simulated, and shorter N is a prefix.
    d = simulate_gaussian_attack(p, N=40, runs=2, sigma_u2=1.0, seed=11)
    np.testing.assert_array_equal(d.states, a.states[:2, :40])
    np.testing.assert_array_equal(d.inputs, a.inputs[:2, :40])
    e = simulate_gaussian_attack(p, N=100, runs=5, sigma_u2=1.0, seed=np.random.SeedSequence(11))
    np.testing.assert_array_equal(e.states, a.states)


def test_initial_state_uses_sigma_x2_not_sigma_w2() -> None:
    p = LinearPlant(A2, B2, sigma_w2=0.01, sigma_x2=9.0)
    sim = simulate_gaussian_attack(p, N=2, runs=20_000, sigma_u2=1.0, seed=3)
    np.testing.assert_allclose(sim.states[:, 0].var(axis=0), 9.0, rtol=0.05)


def test_stationary_state_covariance_matches_gramians() -> None:
    # Var(x_t) -> sigma_u2 Psi_u + sigma_w2 Psi_w (the quantity bounded in Theorem thm:sic's proof).
    p = LinearPlant(A2, B2, sigma_w2=0.5, sigma_x2=0.0)
    sim = simulate_gaussian_attack(p, N=4000, runs=40, sigma_u2=2.0, seed=5)
    x = sim.states[:, 200:].reshape(-1, 2)
    expected = 2.0 * controllability_gramian(A2, B2) + 0.5 * noise_gramian(A2)
    np.testing.assert_allclose(np.cov(x.T), expected, rtol=0.05, atol=0.05 * np.abs(expected).max())


def test_simulate_with_given_inputs_and_x0() -> None:
    p = LinearPlant(A2, B2, sigma_w2=1e-3)
    u = np.zeros((30, 2))
    sim = simulate(p, u, np.random.default_rng(0), x0=[1.0, -1.0])
    assert sim.states.shape == (1, 30, 2)
    np.testing.assert_array_equal(sim.states[0, 0], [1.0, -1.0])
    # Zero input, small noise: x_t close to A^t x0.
    np.testing.assert_allclose(sim.states[0, 5], np.linalg.matrix_power(A2, 5) @ [1.0, -1.0], atol=0.2)
    again = simulate(p, u, 4, x0=[1.0, -1.0])
    np.testing.assert_array_equal(again.states, simulate(p, u, 4, x0=[1.0, -1.0]).states)


@pytest.mark.parametrize(
    "call, exc",
    [
        (lambda p: simulate(p, np.zeros((10, 3)), 0), ShapeError),
        (lambda p: simulate(p, np.full((10, 2), np.nan), 0), ParameterError),
        (lambda p: simulate(p, np.zeros((10, 2)), 0, x0=[1.0, 2.0, 3.0]), ShapeError),
        (lambda p: simulate("not a plant", np.zeros((10, 2)), 0), ParameterError),
        (lambda p: simulate_gaussian_attack(p, N=0, runs=1, sigma_u2=1.0, seed=0), ParameterError),
        (lambda p: simulate_gaussian_attack(p, N=10, runs=0, sigma_u2=1.0, seed=0), ParameterError),
        (lambda p: simulate_gaussian_attack(p, N=10, runs=1, sigma_u2=-1.0, seed=0), ParameterError),
        (lambda p: simulate_gaussian_attack(p, N=10.5, runs=1, sigma_u2=1.0, seed=0), ParameterError),
        (lambda p: simulate_gaussian_attack(p, N=10, runs=1, sigma_u2=1.0, seed=-3), ParameterError),
    ],
)
def test_simulation_rejects_bad_input(call, exc) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(exc):
        call(LinearPlant(A2, B2, sigma_w2=1.0))
