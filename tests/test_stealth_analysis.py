"""encctl_gym.security.stealth: the KL closed form against Monte Carlo, the identification terms
against independent formulas, the stealthy design against a scalar root, and the detection
probabilities against simulations of the plant side's own detectors (loop.detection)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.stats import chi2, multivariate_normal

from encctl_gym.errors import ParameterError
from encctl_gym.loop.backend import lqr_gain
from encctl_gym.loop.detection import ChiSquaredDetector, CusumDetector
from encctl_gym.security.defenses import chi2_threshold
from encctl_gym.security.stealth import (
    _gaussian_step_law,
    audit_detection_probability,
    check_false_alarm_rate,
    chi2_alarm_probability,
    cusum_detection_probability,
    frontier_point,
    identification_rate,
    innovation_covariance,
    innovation_kl,
    malleability_excitation,
    prediction_error_covariance,
    regressor_covariance,
    sparse_chi2_alarm_probability,
    sparse_noncentralities,
    stealthy_design,
    window_detection_bounds,
    window_detection_probability,
)

A3 = np.array([[0.6, 0.2, 0.0], [0.0, 0.5, 0.1], [0.1, 0.0, 0.4]])
B3 = np.array([[1.0, 0.0], [0.3, 0.5], [0.0, 0.8]])


def test_kl_closed_form_matches_monte_carlo():
    sw = 0.1
    Sd = np.array([[0.05, 0.01], [0.01, 0.02]])
    S0, S1 = sw * np.eye(3), innovation_covariance(B3, sw, Sd)
    assert np.allclose(S1, sw * np.eye(3) + B3 @ Sd @ B3.T)
    r = np.random.default_rng(0).multivariate_normal(np.zeros(3), S1, size=200_000)
    llr = multivariate_normal(np.zeros(3), S1).logpdf(r) - multivariate_normal(np.zeros(3), S0).logpdf(r)
    kl = innovation_kl(S1, S0)
    assert kl == pytest.approx(llr.mean(), abs=4 * llr.std() / math.sqrt(r.shape[0]))
    assert innovation_kl(S0, S0) == pytest.approx(0.0, abs=1e-12)


def test_innovation_of_an_attack_with_a_prediction_error():
    Phi = -lqr_gain(A3, B3)
    P = prediction_error_covariance(A3, 0.1, 2)
    assert np.allclose(P, 0.1 * (np.eye(3) + A3 @ A3.T))
    assert np.allclose(prediction_error_covariance(A3, 0.1, 0), 0.0)
    S1 = innovation_covariance(B3, 0.1, np.zeros((2, 2)), Phi=Phi, prediction_error=P)
    assert np.allclose(S1, 0.1 * np.eye(3) + B3 @ Phi @ P @ Phi.T @ B3.T)


def test_regressor_covariance_and_rate_scalar_closed_form():
    a, b, phi, sw, sd = 0.9, 0.5, -0.4, 0.1, 0.3
    S = regressor_covariance([[a]], [[b]], [[phi]], sigma_w2=sw, Sigma_d=[[sd]])
    sxx = (sw + b * b * sd) / (1 - (a + b * phi) ** 2)
    assert np.allclose(S, [[sxx, phi * sxx], [phi * sxx, phi * phi * sxx + sd]])
    # tr(S^-1) = 1/sxx + (1 + phi^2)/sd
    rate = identification_rate([[a]], [[b]], [[phi]], sigma_w2=sw, Sigma_d=[[sd]])
    assert rate == pytest.approx(sw * (1 / sxx + (1 + phi * phi) / sd) / 2, rel=1e-12)
    assert math.isinf(identification_rate([[a]], [[b]], [[phi]], sigma_w2=sw, Sigma_d=[[0.0]]))


def test_malleability_excitation_is_a_fixed_point():
    Phi = -lqr_gain(A3, B3)
    Se = malleability_excitation(A3, B3, Phi, sigma_w2=0.1, delta2=0.4)
    Sxx = regressor_covariance(A3, B3, Phi, sigma_w2=0.1, Sigma_d=Se)[:3, :3]
    assert np.allclose(Se, 0.4 * np.diag(np.diag(Phi @ Sxx @ Phi.T)), rtol=1e-9)


def test_stealthy_design_isotropic_matches_the_scalar_root():
    """On the design example (A, B, Phi diagonal and equal) the design is s I with the KL budget
    active: n/2 (b^2 s / sw - ln(1 + b^2 s / sw)) = kappa."""
    A, B = 0.70710678 * np.eye(4), 0.5 * np.eye(4)
    Phi, sw, kappa = -lqr_gain(A, B), 0.1, 1e-3
    d = stealthy_design(A, B, Phi, sigma_w2=sw, kl_budget=kappa)
    s = brentq(lambda s: 2.0 * (0.25 * s / sw - math.log1p(0.25 * s / sw)) - kappa, 1e-9, 10.0)
    assert np.allclose(d.Sigma_d, s * np.eye(4), rtol=2e-3, atol=1e-6)
    assert d.kl <= kappa * (1 + 1e-4)
    assert d.rate == pytest.approx(identification_rate(A, B, Phi, sigma_w2=sw, Sigma_d=d.Sigma_d))


def test_stealthy_design_beats_isotropic_excitation_of_the_same_kl():
    Phi, sw, kappa = -lqr_gain(A3, B3), 0.1, 5e-3
    d = stealthy_design(A3, B3, Phi, sigma_w2=sw, kl_budget=kappa)
    s = brentq(lambda s: innovation_kl(innovation_covariance(B3, sw, s * np.eye(2)), sw * np.eye(3)) - kappa, 1e-9, 10.0)
    iso = identification_rate(A3, B3, Phi, sigma_w2=sw, Sigma_d=s * np.eye(2))
    assert d.rate <= iso * (1 + 1e-6)
    assert d.kl <= kappa * (1 + 1e-4)


@pytest.mark.parametrize("bad", [-1e-3, 0.0, float("nan")])
def test_bad_kl_budget_is_named(bad):
    with pytest.raises(ParameterError, match="kl_budget"):
        stealthy_design(A3, B3, -lqr_gain(A3, B3), sigma_w2=0.1, kl_budget=bad)


@pytest.mark.parametrize("bad", [0.0, 1.0, 1.5, -0.1])
def test_bad_false_alarm_rate_is_named(bad):
    with pytest.raises(ParameterError, match="false_alarm_rate"):
        check_false_alarm_rate(bad)
    with pytest.raises(ParameterError, match="false_alarm_rate"):
        cusum_detection_probability(10, 3, false_alarm_rate=bad)


def test_chi2_alarm_probability_isotropic_is_exact():
    h = chi2_threshold(4, 10, 1e-4)
    S0 = 0.1 * np.eye(4)
    assert chi2_alarm_probability(S0, S0, window=10, false_alarm_rate=1e-4) == pytest.approx(1e-4, rel=1e-9)
    lam = 1.3
    assert chi2_alarm_probability(lam * S0, S0, window=10, false_alarm_rate=1e-4) == pytest.approx(chi2.sf(h / lam, 40), rel=1e-9)


def _innovations(rng, S1, T, K):
    return rng.multivariate_normal(np.zeros(S1.shape[0]), S1, size=(T, K))


def test_detection_probabilities_against_the_detectors_themselves():
    """Monte Carlo of loop.detection's ChiSquaredDetector and CusumDetector on i.i.d. innovations
    N(0, Sigma_1) (x = 0, x_next = r with A_cl = 0): the CUSUM chain's probability inside the MC
    interval, the chi-squared MC between the window bounds."""
    rng = np.random.default_rng(1)
    n, T, K, alpha = 3, 200, 4000, 1e-3
    S0 = 0.1 * np.eye(n)
    S1 = innovation_covariance(B3, 0.1, np.diag([0.04, 0.02]))
    r = _innovations(rng, S1, T, K)
    cus = CusumDetector(np.zeros((n, n)), S0, false_alarm_rate=alpha, num_loops=K)
    chi = ChiSquaredDetector(np.zeros((n, n)), S0, window=10, false_alarm_rate=alpha, num_loops=K)
    hit_c, hit_w = np.zeros(K, bool), np.zeros(K, bool)
    zeros = np.zeros((K, n))
    for t in range(T):
        hit_c |= cus.update(zeros, r[t])
        hit_w |= chi.update(zeros, r[t])
    p_c = cusum_detection_probability(T, n, false_alarm_rate=alpha, weights=np.linalg.eigvalsh(S1 / 0.1))
    se = math.sqrt(p_c * (1 - p_c) / K)
    assert abs(hit_c.mean() - p_c) < 4 * se + 0.02  # the chain's discretisation and Satterthwaite
    beta = chi2_alarm_probability(S1, S0, window=10, false_alarm_rate=alpha)
    lo, hi = window_detection_bounds(T, 10, beta)
    assert lo - 0.02 <= hit_w.mean() <= hi + 0.02
    approx = window_detection_probability(
        T, 10, _gaussian_step_law(np.linalg.eigvalsh(S1 / 0.1), 10), chi2_threshold(n, 10, alpha)
    )
    # the clumping approximation overstates a high probability (0.66 against 0.57 measured here)
    assert abs(hit_w.mean() - approx) < 4 * math.sqrt(approx * (1 - approx) / K) + 0.1


def test_window_approximation_near_the_false_alarm_floor():
    """Where the frontier lives (a weak excitation: innovation variance 1.025 of the nominal), the
    clumping approximation is within 0.02 of the window detector's Monte Carlo."""
    rng = np.random.default_rng(4)
    n, W, alpha, T, K, lam = 4, 10, 1e-4, 1000, 3000, 1.025
    chi = ChiSquaredDetector(np.zeros((n, n)), np.eye(n), window=W, false_alarm_rate=alpha, num_loops=K)
    hit, zeros = np.zeros(K, bool), np.zeros((K, n))
    for _ in range(T):
        hit |= chi.update(zeros, math.sqrt(lam) * rng.standard_normal((K, n)))
    approx = window_detection_probability(T, W, _gaussian_step_law(np.full(n, lam), W), chi2_threshold(n, W, alpha))
    assert abs(hit.mean() - approx) < 4 * math.sqrt(approx * (1 - approx) / K) + 0.02


def test_sparse_chi2_against_monte_carlo():
    rng = np.random.default_rng(2)
    n, W, alpha, q, amp, sw, K = 2, 10, 1e-3, 0.05, 0.4, 0.1, 20000
    B = 0.5 * np.eye(n)
    lams = sparse_noncentralities(B, sw, amp)
    assert np.allclose(lams, n * (0.5 * amp) ** 2 / sw)
    hit = rng.random((K, W)) < q
    d = amp * (2.0 * rng.integers(0, 2, size=(K, W, n)) - 1.0) * hit[..., None]
    r = d @ B.T + math.sqrt(sw) * rng.standard_normal((K, W, n))
    S = np.sum(r**2, axis=(1, 2)) / sw
    mc = np.mean(S > chi2_threshold(n, W, alpha))
    p = sparse_chi2_alarm_probability(n, W, alpha, q, lams)
    assert abs(mc - p) < 4 * math.sqrt(p * (1 - p) / K) + 1e-3


def test_audit_and_frontier():
    assert audit_detection_probability(1000, 5e-4) == pytest.approx(1 - (1 - 5e-4) ** 1000)
    assert audit_detection_probability(1000, 5e-4, 0.1) == pytest.approx(1 - (1 - 5e-5) ** 1000)
    assert audit_detection_probability(0, 1.0) == 0.0
    A, B = 0.70710678 * np.eye(4), 0.5 * np.eye(4)
    Phi = -lqr_gain(A, B)
    weak = frontier_point(A, B, Phi, sigma_w2=0.1, gamma_c=1e-3, Sigma_d=1e-2 * np.eye(4))
    strong = frontier_point(A, B, Phi, sigma_w2=0.1, gamma_c=1e-3, Sigma_d=1.0 * np.eye(4))
    assert weak.samples > strong.samples and weak.kl < strong.kl
    assert strong.chi2 > weak.chi2  # more power per step: detected more surely before gamma_c
    assert weak.audit > strong.audit  # audits see every step: the longer attack is caught more surely
    honest = frontier_point(A, B, Phi, sigma_w2=0.1, gamma_c=1e-3, Sigma_d=np.zeros((4, 4)), horizon=2000)
    assert honest.audit == 0.0 and honest.steps == 2000 and np.isinf(honest.samples)
    sparse = frontier_point(A, B, Phi, sigma_w2=0.1, gamma_c=1e-6, Sigma_d=None, sparse=(0.05, 12.6))
    assert sparse.chi2 > 0.999 and sparse.chi2_lower > 0.999 and sparse.audit < 0.5
