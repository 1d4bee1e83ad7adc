"""The plant side's checks (encctl_gym.loop.detection): the chi-squared detector's false-alarm
rate measured against its target, its alarms under an injection, audits that never alarm
without an injection and catch one at their rate."""

from __future__ import annotations

import math

import numpy as np
import pytest

from encctl_gym.errors import ParameterError, ShapeError
from encctl_gym.loop.detection import Audit, ChiSquaredDetector

A = np.array([[0.5, 0.2], [0.0, -0.3]])
B = np.array([[1.0], [0.5]])
PHI = np.array([[-0.2, 0.1]])
A_CL = A + B @ PHI
SW = 0.2


def run(detector, steps, rng, injection=None):
    K = detector.K
    x = np.zeros((K, 2))
    alarms = np.zeros((steps, K), dtype=bool)
    for t in range(steps):
        u = x @ PHI.T if injection is None else injection(t, x)
        x_next = x @ A.T + u @ B.T + rng.normal(scale=math.sqrt(SW), size=(K, 2))
        alarms[t] = detector.update(x, x_next)
        x = x_next
    return alarms


def test_the_false_alarm_rate_per_step_meets_its_target():
    alpha, W, K, T = 0.01, 5, 200, 2000
    det = ChiSquaredDetector(A_CL, SW * np.eye(2), window=W, false_alarm_rate=alpha, num_loops=K)
    alarms = run(det, T, np.random.default_rng(0))[W - 1 :]
    rate = alarms.mean()
    # consecutive windows overlap (W - 1 shared terms): about K (T - W) / W independent windows
    se = math.sqrt(alpha * (1 - alpha) / (K * (T - W) / W))
    assert abs(rate - alpha) < 5 * se


def test_an_injection_is_detected():
    alpha, W, K = 1e-3, 5, 50
    det = ChiSquaredDetector(A_CL, SW * np.eye(2), window=W, false_alarm_rate=alpha, num_loops=K)
    rng = np.random.default_rng(1)
    alarms = run(det, 200, rng, injection=lambda t, x: rng.normal(scale=3.0, size=(K, 1)))
    assert alarms[W - 1 :].mean() > 0.5
    det.reset()
    assert not det.update(np.zeros((K, 2)), np.zeros((K, 2))).any()  # the window is empty again


def test_audits_never_alarm_without_an_injection_and_catch_one_at_their_rate():
    rng = np.random.default_rng(2)
    K, T = 100, 500
    audit = Audit(PHI, rate=0.1, rngs=[np.random.default_rng([3, k]) for k in range(K)], tolerance=1e-3)
    caught_honest = 0
    caught_attack = 0
    for _ in range(T):
        x = rng.normal(size=(K, 2))
        honest = x @ PHI.T + rng.uniform(-1e-3, 1e-3, size=(K, 1))  # within the encoder's error
        caught_honest += int(audit.check(x, honest).sum())
        caught_attack += int(audit.check(x, honest + 1.0).sum())
    assert caught_honest == 0
    rate = caught_attack / (K * T)
    assert abs(rate - 0.1) < 5 * math.sqrt(0.1 * 0.9 / (K * T))
    assert audit.audits > 0


def test_refusals():
    with pytest.raises(ParameterError, match="audit_rate must lie in \\[0, 1\\], got 1.5"):
        Audit(PHI, rate=1.5, rngs=[np.random.default_rng()])
    with pytest.raises(ParameterError, match="positive definite"):
        ChiSquaredDetector(A_CL, np.zeros((2, 2)), window=3, false_alarm_rate=0.01)
    with pytest.raises(ShapeError, match="same size"):
        ChiSquaredDetector(A_CL, np.eye(3), window=3, false_alarm_rate=0.01)
    with pytest.raises(ParameterError, match="window"):
        ChiSquaredDetector(A_CL, np.eye(2), window=0, false_alarm_rate=0.01)


def _binomial_interval(trials: int, p: float, tail: float = 1e-6) -> tuple[int, int]:
    from scipy.stats import binom

    return int(binom.ppf(tail / 2, trials, p)), int(binom.isf(tail / 2, trials, p))


def test_the_cusum_false_alarm_rate_per_step_meets_its_target():
    """Restarted after each alarm, the CUSUM's run length to a false alarm is close to geometric
    with mean 1/alpha, so its alarm count over K T steps is close to binomial(K T, alpha): the
    count must fall in that distribution's central 1 - 1e-6 interval."""
    from encctl_gym.loop.detection import CusumDetector

    alpha, K, T = 1e-3, 200, 5000
    det = CusumDetector(A_CL, SW * np.eye(2), false_alarm_rate=alpha, num_loops=K)
    count = int(run(det, T, np.random.default_rng(4)).sum())
    lo, hi = _binomial_interval(K * T, alpha)
    assert lo <= count <= hi, (lo, count, hi)


def test_the_cusum_detects_an_inflated_innovation_within_its_run_length():
    """An attack that inflates the innovation covariance by r: the mean delay over K loops is
    the Markov chain's run length under r Sigma, within four standard errors of the mean."""
    from encctl_gym.loop.detection import CusumDetector
    from encctl_gym.security.defenses import cusum_run_length

    K, r = 2000, 4.0
    det = CusumDetector(A_CL, SW * np.eye(2), false_alarm_rate=1e-4, variance_ratio=2.0, num_loops=K)
    expected = cusum_run_length(2, 2.0, det.threshold, actual_ratio=r)
    rng = np.random.default_rng(5)
    x = np.zeros((K, 2))
    delay = np.zeros(K)
    for t in range(1, 2000):
        x_next = x @ A_CL.T + rng.normal(scale=math.sqrt(r * SW), size=(K, 2))
        alarms = det.update(x, x_next)
        delay[(delay == 0) & alarms] = t
        x = x_next
        if (delay > 0).all():
            break
    assert (delay > 0).all()
    assert abs(delay.mean() - expected) < 4 * delay.std() / math.sqrt(K), (delay.mean(), expected)


def test_the_cusum_stops_a_real_injection():
    """An attacker that replaces Phi x by N(0, 3^2) inputs is caught in every loop."""
    from encctl_gym.loop.detection import CusumDetector

    K = 500
    det = CusumDetector(A_CL, SW * np.eye(2), false_alarm_rate=1e-4, num_loops=K)
    rng = np.random.default_rng(6)
    alarms = run(det, 300, rng, injection=lambda t, x: rng.normal(scale=3.0, size=(K, 1)))
    assert alarms.any(axis=0).all()
