"""Tests of encctl_gym.security.gramians against closed forms and truncated series."""

from __future__ import annotations

import numpy as np
import pytest

from encctl_gym.errors import ParameterError, ShapeError, UnstableSystemError
from encctl_gym.security.gramians import controllability_gramian, noise_gramian, solve_gramian


@pytest.mark.parametrize("a,b,n,m", [(0.5, 1.0, 3, 3), (np.sqrt(0.5), 0.5, 4, 4), (-0.9, 2.0, 2, 2), (0.0, 1.0, 1, 1)])
def test_scaled_identity_closed_form(a: float, b: float, n: int, m: int) -> None:
    A, B = a * np.eye(n), b * np.eye(n, m)
    np.testing.assert_allclose(noise_gramian(A), np.eye(n) / (1 - a**2), rtol=1e-12)
    np.testing.assert_allclose(controllability_gramian(A, B), b**2 * np.eye(n) / (1 - a**2), rtol=1e-12)


def test_paper_example_gramians() -> None:
    # Section "Numerical Simulation": A = sqrt(1/2) I, B = 0.5 I gives Psi_w = 2I, Psi_u = 0.5I.
    A, B = np.sqrt(0.5) * np.eye(4), 0.5 * np.eye(4)
    np.testing.assert_allclose(noise_gramian(A), 2 * np.eye(4), rtol=1e-12)
    np.testing.assert_allclose(controllability_gramian(A, B), 0.5 * np.eye(4), rtol=1e-12)
    # Figure 1 system A = 0.7071 I, B = I: Psi close to (not exactly) 2I.
    np.testing.assert_allclose(controllability_gramian(0.7071 * np.eye(4), np.eye(4)), 2 * np.eye(4), rtol=1e-3)


def test_random_system_matches_series() -> None:
    rng = np.random.default_rng(0)
    for _ in range(5):
        n, m = rng.integers(1, 5), rng.integers(1, 4)
        A = rng.standard_normal((n, n))
        A *= 0.8 / max(np.abs(np.linalg.eigvals(A)).max(), 1e-9)
        B = rng.standard_normal((n, m))
        S_u, S_w = np.zeros((n, n)), np.zeros((n, n))
        Ak = np.eye(n)
        for _ in range(400):
            S_u += Ak @ B @ B.T @ Ak.T
            S_w += Ak @ Ak.T
            Ak = A @ Ak
        np.testing.assert_allclose(controllability_gramian(A, B), S_u, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(noise_gramian(A), S_w, rtol=1e-9, atol=1e-12)
        # Psi_w >= I
        assert np.linalg.eigvalsh(noise_gramian(A) - np.eye(n)).min() > -1e-12


def test_one_dimensional_B_is_a_column() -> None:
    A = np.array([[0.5, 0.1], [0.0, 0.3]])
    np.testing.assert_allclose(controllability_gramian(A, [1.0, 2.0]), controllability_gramian(A, [[1.0], [2.0]]))


def test_unstable_names_spectral_radius() -> None:
    with pytest.raises(UnstableSystemError, match="spectral radius 1.2"):
        noise_gramian(1.2 * np.eye(2))
    with pytest.raises(UnstableSystemError, match="spectral radius 1"):
        controllability_gramian(np.eye(2), np.eye(2))


def test_bad_shapes() -> None:
    with pytest.raises(ShapeError):
        noise_gramian(np.ones((2, 3)))
    with pytest.raises(ShapeError):
        controllability_gramian(0.5 * np.eye(2), np.ones((3, 1)))
    with pytest.raises(ShapeError):
        solve_gramian(0.5 * np.eye(2), np.eye(3))


def test_an_overflowing_input_gramian_is_refused() -> None:
    # B B^T = 1e400 is beyond float64: a ParameterError naming the size of B, not inf in a Lyapunov solve
    with pytest.raises(ParameterError, match=r"B B\^T overflows float64: B has entries up to 1e\+200"):
        controllability_gramian(np.array([[0.5]]), np.array([[1e200]]))
    # 1e150^2 / (1 - 0.25) = 1.333e300 is still a float: valid, by hand
    assert controllability_gramian(np.array([[0.5]]), np.array([[1e150]]))[0, 0] == pytest.approx(1e300 / 0.75, rel=1e-12)
