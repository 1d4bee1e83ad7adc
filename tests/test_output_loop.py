"""The loop with outputs: controller design (loop.output_feedback) and both backends on y."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import SolverError
from encctl_gym.loop import make_loop
from encctl_gym.loop.backend import lqr_gain
from encctl_gym.loop.output_feedback import OutputLoop, controller_matrix, loop_controller, lqg_controller, static_output_feedback

A2 = np.array([[0.6, 0.2], [-0.1, 0.5]])
B2 = np.array([[1.0, 0.0], [0.3, 0.8]])


def _dare_gain(A, B):
    """LQR gain from scipy's DARE solved independently of lqr_gain's formula (Q = R = I)."""
    P = scipy.linalg.solve_discrete_are(A, B, np.eye(A.shape[0]), np.eye(B.shape[1]))
    return np.linalg.inv(np.eye(B.shape[1]) + B.T @ P @ B) @ B.T @ P @ A


def test_static_output_feedback_with_every_state_measured_is_the_lqr_gain():
    # C = I: the LQ-optimal static gain is the LQR gain (for any initial covariance)
    Phi = static_output_feedback(A2, B2, np.eye(2))
    np.testing.assert_allclose(Phi, -_dare_gain(A2, B2), atol=1e-8)


def test_static_output_feedback_decreases_the_cost_from_its_start_and_stabilises():
    rng = np.random.default_rng(0)
    A = np.array([[0.9, 0.3, 0.0], [0.0, 0.8, 0.2], [0.1, 0.0, 0.7]])
    B = rng.normal(size=(3, 2))
    C = np.array([[1.0, 0.0, 1.0]])
    Phi = static_output_feedback(A, B, C)

    def cost(F):
        Acl = A + B @ F @ C
        if max(abs(np.linalg.eigvals(Acl))) >= 1:
            return np.inf
        P = scipy.linalg.solve_discrete_lyapunov(Acl.T, np.eye(3) + (F @ C).T @ (F @ C))
        return np.trace(P)

    assert max(abs(np.linalg.eigvals(A + B @ Phi @ C))) < 1
    start = -lqr_gain(A, B) @ np.linalg.pinv(C)
    assert cost(Phi) < np.inf and cost(Phi) <= min(cost(np.zeros((2, 1))), cost(start))
    # a first-order optimum: no small perturbation lowers the cost
    for _ in range(5):
        d = rng.normal(size=Phi.shape) * 1e-4
        assert cost(Phi + d) >= cost(Phi) - 1e-10


def test_no_stabilising_static_gain_is_an_error():
    # the double integrator seen through its position: z^2 - 2 z + 1 - f has roots summing to 2,
    # so no static gain f puts both inside the unit circle (hand count)
    A = np.array([[1.0, 1.0], [0.0, 1.0]])
    B = np.array([[0.0], [1.0]])
    with pytest.raises(SolverError, match="no stabilising static output feedback"):
        static_output_feedback(A, B, np.array([[1.0, 0.0]]))


def test_lqg_closed_loop_has_the_separated_eigenvalues():
    C = np.array([[1.0, 0.0]])
    ctrl = lqg_controller(A2, B2, C, sigma_w2=0.1, sigma_v2=0.01)
    K = _dare_gain(A2, B2)
    S = scipy.linalg.solve_discrete_are(A2.T, C.T, 0.1 * np.eye(2), 0.01 * np.eye(1))
    L = A2 @ S @ C.T @ np.linalg.inv(C @ S @ C.T + 0.01)
    want = np.sort_complex(np.concatenate([np.linalg.eigvals(A2 - B2 @ K), np.linalg.eigvals(A2 - L @ C)]))
    got = np.sort_complex(np.linalg.eigvals(ctrl.closed_loop(A2, B2, C)))
    np.testing.assert_allclose(got, want, atol=1e-9)
    assert ctrl.matrix.shape == (2 + 2, 2 + 1)


def test_state_loop_keeps_the_lqr_gain_bit_for_bit():
    p = resolve_params({"preset": "small", "max_samples": 50})
    np.testing.assert_array_equal(controller_matrix(p), -lqr_gain(p.A, p.B))
    assert loop_controller(p).kind == "state"


@pytest.mark.parametrize("controller", ["static", "lqg"])
def test_both_backends_run_the_output_loop_bit_for_bit(controller):
    cfg = {
        "preset": "small-output",
        "observe": "output",
        "controller": controller,
        "max_samples": 50,
        "key_length": 64,
        "x_bound": 16.0,
    }
    runs = []
    for crypto in ("ideal", "elgamal"):
        p = resolve_params({**cfg, "crypto": crypto, "crypto_seed": 5})
        ctrl = loop_controller(p)
        loop = OutputLoop(make_loop(p.loop), ctrl)
        loop.start(1)
        rng = np.random.default_rng(7)
        x = rng.normal(size=(1, 2))
        us, ys = [], []
        for _ in range(25):
            y = x @ p.C.T + np.sqrt(p.sigma_v2) * rng.normal(size=(1, 1))
            ys.append(loop.collect(y))
            u = loop.control(y)
            us.append(u)
            x = x @ p.A.T + u @ p.B.T + np.sqrt(p.sigma_w2) * rng.normal(size=(1, 2))
        runs.append((np.array(us), np.array(ys), x))
    for a, b in zip(runs[0], runs[1]):
        np.testing.assert_array_equal(a, b)
    # the encrypted loop follows the controller's real arithmetic up to quantisation (and is stable)
    assert np.all(np.abs(runs[0][2]) < 10)
