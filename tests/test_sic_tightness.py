"""How far below least squares eq:sic lies (issue 34 item 15): the closed-form large-N ratio
(security.bayes_complexity.sic_tightness) against hand values, an independent Lyapunov solve,
and the Monte Carlo mean of least squares on a plant where it is 0.05."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import solve_discrete_lyapunov

from encctl_gym.cli import main
from encctl_gym.security.bayes_complexity import sic_tightness
from encctl_gym.security.complexity import sample_identifying_complexity
from encctl_gym.sim.montecarlo import gaussian_attack_errors
from encctl_gym.sim.plant import LinearPlant

EXAMPLE_A = np.array([[0.5, 0.2, 0.0], [0.0, 0.6, 0.1], [0.0, 0.0, 0.4]])  # examples/plant_output.yaml
EXAMPLE_B = np.array([[1.0], [0.0], [0.5]])


def test_scalar_plants_by_hand():
    """n = m = 1, A = a, B = b: Sigma = diag((sigma_u2 b^2 + sigma_w2) / (1 - a^2), sigma_u2) and
    the ratio is 4 s x / (s + x)^2 (s, x the two variances)."""
    assert sic_tightness([[0.0]], [[1.0]], sigma_u2=1.0, sigma_w2=1.0) == pytest.approx(8 / 9, rel=1e-12)
    # x = (2 * 0.5 + 1) / 1 = 2 = sigma_u2: isotropic regressors, eq:sic is the value
    assert sic_tightness([[0.0]], [[math.sqrt(0.5)]], sigma_u2=2.0, sigma_w2=1.0) == pytest.approx(1.0, rel=1e-12)
    x = (0.1 * 4 + 10) / (1 - 0.81)
    assert sic_tightness([[0.9]], [[2.0]], sigma_u2=0.1, sigma_w2=10.0) == pytest.approx(4 * 0.1 * x / (0.1 + x) ** 2, rel=1e-10)


def test_matches_an_independent_lyapunov_solve():
    A, B, su, sw = EXAMPLE_A, EXAMPLE_B, 10.0, 0.1
    Sx = solve_discrete_lyapunov(A, su * B @ B.T + sw * np.eye(3))
    S = np.block([[Sx, np.zeros((3, 1))], [np.zeros((1, 3)), su * np.eye(1)]])
    expected = 16 / (np.trace(S) * np.trace(np.linalg.inv(S)))
    assert sic_tightness(A, B, sigma_u2=su, sigma_w2=sw) == pytest.approx(expected, rel=1e-9)
    assert 0.04 < expected < 0.06  # the shipped example: eq:sic about 20 times below least squares


def test_predicts_how_far_eq_sic_lies_below_the_monte_carlo_mean():
    """On the shipped example plant eq:sic divided by the Monte Carlo mean least-squares error at
    N = 4000 (300 attacks) is the closed form to within 10 %, not the 0.9 of the design example."""
    A, B, su, sw = EXAMPLE_A, EXAMPLE_B, 10.0, 0.1
    N = np.array([4000])
    errors = gaussian_attack_errors(LinearPlant(A, B, sigma_w2=sw), sample_sizes=N, runs=300, sigma_u2=su, seed=5)
    gamma = sample_identifying_complexity(N, A, B, sigma_u2=su, sigma_w2=sw, sigma_x2=1.0)
    ratio = float(gamma[0] / errors.mean())
    assert ratio == pytest.approx(sic_tightness(A, B, sigma_u2=su, sigma_w2=sw), rel=0.1)


def test_design_prints_it(capsys):
    assert main(["design", "--preset", "paper-example"]) == 0
    assert "eq:sic / mean least-squares error at large N = 0.900" in capsys.readouterr().out
