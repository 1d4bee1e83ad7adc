"""The defences' closed forms (encctl_gym.security.defenses) against hand computations, eq:sic,
scipy and Monte Carlo."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from encctl_gym.errors import ParameterError, UnstableSystemError
from encctl_gym.security.complexity import sample_identifying_complexity
from encctl_gym.security.defenses import (
    chi2_detection_probability,
    chi2_threshold,
    closed_loop_state_covariance,
    minimum_audit_rate,
    noise_defense_price,
    rotated_deciphering_operations,
    rotation_precomputations,
    sic_with_input_noise,
    sic_with_input_noise_asymptotic,
    undetected_probability,
)

A2 = np.array([[0.5, 0.2], [0.0, -0.3]])
B2 = np.array([[1.0], [0.5]])


def test_no_defender_noise_is_eq_sic():
    N = np.array([5, 50, 5000])
    got = sic_with_input_noise(N, A2, B2, sigma_u2=2.0, sigma_w2=0.5, sigma_d2=0.0, sigma_x2=1.5)
    ref = sample_identifying_complexity(N, A2, B2, sigma_u2=2.0, sigma_w2=0.5, sigma_x2=1.5)
    np.testing.assert_allclose(got, ref, rtol=1e-14)


def test_a_diagonal_plant_by_hand():
    """A = a I, B = b I (n = m = 2): Psi_u = b^2 / (1 - a^2) I, Psi_w = 1 / (1 - a^2) I,
    tr Sigma = n (sigma_d2 b^2 + sigma_w2)."""
    a, b, n, m = 0.6, 2.0, 2, 2
    su, sw, sd, sx, N = 3.0, 0.5, 4.0, 1.0, 101
    tr_u, tr_w = n * b**2 / (1 - a**2), n / (1 - a**2)
    expected = (m + n) * (sd * b**2 + sw) / (sx * tr_w + (N - 1) * (su * (tr_u + m) + sd * tr_u + sw * tr_w))
    got = sic_with_input_noise(N, a * np.eye(2), b * np.eye(2), sigma_u2=su, sigma_w2=sw, sigma_d2=sd, sigma_x2=sx)
    assert got == pytest.approx(expected, rel=1e-12)
    asym = sic_with_input_noise_asymptotic(N, a * np.eye(2), b * np.eye(2), sigma_u2=su, sigma_w2=sw, sigma_d2=sd)
    assert asym == pytest.approx((m + n) * (sd * b**2 + sw) / ((N - 1) * (su * (tr_u + m) + sd * tr_u + sw * tr_w)), rel=1e-12)


def test_the_generalised_complexity_stays_below_the_least_squares_error_with_defender_noise():
    """Monte Carlo: least squares on (x, a) when the plant applies a + d; the mean error over 400
    runs lies above gamma_d at every N, and above the error without the defender's noise."""
    rng = np.random.default_rng(0)
    R, n, m = 400, 2, 1
    su, sw, sd = 1.0, 0.1, 2.0
    Ns = [10, 40, 160]
    T = max(Ns)
    for sigma_d2, store in ((sd, "with"), (0.0, "without")):
        a = rng.normal(scale=math.sqrt(su), size=(R, T, m))
        d = rng.normal(scale=math.sqrt(sigma_d2), size=(R, T, m)) if sigma_d2 else np.zeros((R, T, m))
        x = np.zeros((R, T + 1, n))
        x[:, 0] = rng.normal(size=(R, n))
        for t in range(T):
            x[:, t + 1] = x[:, t] @ A2.T + (a[:, t] + d[:, t]) @ B2.T + rng.normal(scale=math.sqrt(sw), size=(R, n))
        errs = []
        for N in Ns:
            Dm = np.concatenate([x[:, : N - 1], a[:, : N - 1]], axis=2)  # (R, N-1, n+m)
            e = []
            for r in range(R):
                est = np.linalg.lstsq(Dm[r], x[r, 1:N], rcond=None)[0].T  # eq:estimate, one run
                e.append(np.sum((est - np.hstack([A2, B2])) ** 2) / (n * (n + m)))
            errs.append(np.mean(e))
        if store == "with":
            with_noise = np.array(errs)
        else:
            without = np.array(errs)
    gamma_d = sic_with_input_noise(np.array(Ns), A2, B2, sigma_u2=su, sigma_w2=sw, sigma_d2=sd)
    assert np.all(with_noise > gamma_d)
    assert np.all(with_noise > without)


def test_closed_loop_covariance_against_scipy_and_by_hand():
    Phi = np.array([[-0.2, 0.1]])
    P = closed_loop_state_covariance(A2, B2, Phi, sigma_w2=0.3, sigma_d2=2.0)
    A_cl = A2 + B2 @ Phi
    ref = scipy.linalg.solve_discrete_lyapunov(A_cl, 2.0 * B2 @ B2.T + 0.3 * np.eye(2))
    np.testing.assert_allclose(P, ref, rtol=1e-10)
    # scalar: P = (sigma_d2 b^2 + sigma_w2) / (1 - (a + b phi)^2)
    p = closed_loop_state_covariance([[0.9]], [[1.0]], [[-0.5]], sigma_w2=1.0, sigma_d2=3.0)
    assert p[0, 0] == pytest.approx(4.0 / (1 - 0.4**2), rel=1e-12)
    price = noise_defense_price([[0.9]], [[1.0]], [[-0.5]], sigma_w2=1.0, sigma_d2=3.0)
    # J = P + phi^2 P + sigma_d2 (Q = R = 1)
    assert price["cost_defended"] == pytest.approx(4.0 / 0.84 * 1.25 + 3.0, rel=1e-12)
    assert price["cost_increase"] == pytest.approx(4.0 / 0.84 * 1.25 + 3.0 - 1.0 / 0.84 * 1.25, rel=1e-12)
    with pytest.raises(UnstableSystemError):
        closed_loop_state_covariance([[0.9]], [[1.0]], [[0.5]], sigma_w2=1.0, sigma_d2=0.0)


def test_audit_rates():
    p = minimum_audit_rate(13159, 1e-3)
    assert undetected_probability(13159, p) == pytest.approx(1e-3, rel=1e-9)
    assert p == pytest.approx(-math.log(1e-3) / 13159, rel=1e-3)
    assert undetected_probability(13159, p * 1.01) < 1e-3 < undetected_probability(13159, p * 0.99)
    assert undetected_probability(0, 0.5) == 1.0 and undetected_probability(3, 1.0) == 0.0
    assert undetected_probability(10, 0.0) == 1.0  # no audit never alarms


def test_the_chi2_threshold_meets_its_false_alarm_rate():
    rng = np.random.default_rng(1)
    n, W, alpha = 3, 4, 0.01
    h = chi2_threshold(n, W, alpha)
    S = np.sum(rng.normal(size=(200_000, W, n)) ** 2, axis=(1, 2))  # whitened innovations
    rate = float(np.mean(S > h))
    assert abs(rate - alpha) < 4 * math.sqrt(alpha * (1 - alpha) / len(S))
    assert chi2_detection_probability(n, W, alpha, 0.0) == alpha
    probs = [chi2_detection_probability(n, W, alpha, lam) for lam in (1.0, 10.0, 100.0)]
    assert alpha < probs[0] < probs[1] < probs[2] < 1.0


def test_rotation_counts_by_hand():
    assert rotation_precomputations(10, 3) == 4
    assert rotation_precomputations(10, 10) == rotation_precomputations(10, 10**6) == 1
    assert rotated_deciphering_operations(10, 3, 100.0, 1.0) == 4 * 100.0 + 10 * 1.0


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: rotation_precomputations(10, 0), "K must be >= 1"),
        (lambda: undetected_probability(10, 1.5), "audit_rate must lie in \\[0, 1\\], got 1.5"),
        (lambda: minimum_audit_rate(100, 1.0), "delta must lie in \\(0, 1\\)"),
        (lambda: sic_with_input_noise(10, A2, B2, sigma_u2=1.0, sigma_w2=1.0, sigma_d2=-1.0), "sigma_d2"),
        (lambda: chi2_threshold(2, 3, 0.0), "false_alarm_rate"),
    ],
)
def test_refusals_name_the_bad_value(call, match):
    with pytest.raises(ParameterError, match=match):
        call()


def test_the_noise_defense_design_without_noise_is_the_papers_design():
    from encctl_gym.plant import Plant
    from encctl_gym.presets import get_preset
    from encctl_gym.security.defenses import noise_defense_design
    from encctl_gym.security.design import design_security_parameter
    from encctl_gym.security.threat import ThreatModel

    p = get_preset("paper-example")
    plant = Plant(p.A, p.B)
    threat = ThreatModel(sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2, gamma_c=p.gamma_c, tau_c=p.tau_c, upsilon=p.upsilon)
    ref = design_security_parameter(plant, threat)
    d0 = noise_defense_design(plant, threat, sigma_d2=0.0)
    assert (d0.N_star, d0.lam_star, d0.k_star) == (ref.N_star, ref.lam_star, ref.k_star) == (13159, 74, 712)
    d1 = noise_defense_design(plant, threat, sigma_d2=p.sigma_w2)
    assert d1.N_star > d0.N_star and d1.lam_star <= d0.lam_star and d1.k_star <= d0.k_star
