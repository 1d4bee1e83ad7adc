"""The expected error of Bayesian least squares (security.bayes_complexity) against Monte Carlo."""

from __future__ import annotations

import numpy as np
import pytest

from encctl_gym.errors import ParameterError, ShapeError
from encctl_gym.ident import BayesianLeastSquares, OrdinaryLeastSquares, estimate_errors
from encctl_gym.presets import get_preset
from encctl_gym.security.bayes_complexity import (
    bayes_risk_given_gram,
    bayes_risk_iid_gaussian,
    bayesian_error_given_gram,
    bayesian_sample_identifying_complexity,
    bayesian_sic_from_traces,
    prior_sample_equivalent,
    stationary_regressor_covariance,
)
from encctl_gym.security.complexity import sample_identifying_complexity, sic_from_traces
from encctl_gym.security.gramians import controllability_gramian, noise_gramian
from encctl_gym.sim.plant import LinearPlant, simulate_gaussian_attack

SMALL = get_preset("small")
A, B = SMALL.A, SMALL.B
n, m, d = 2, 2, 4
THETA = np.hstack([A, B])


def _mc_close(samples: np.ndarray, value: float, k: float = 4.0) -> None:
    se = samples.std(ddof=1) / np.sqrt(samples.size)
    assert abs(samples.mean() - value) < k * se, (samples.mean(), value, se)


def test_error_given_gram_is_exact_for_a_fixed_design() -> None:
    rng = np.random.default_rng(0)
    T, sw2, R = 10, 0.3, 20_000
    D = rng.standard_normal((d, T))  # fixed regressors, independent of the noise
    G = D @ D.T
    Y = THETA @ D + np.sqrt(sw2) * rng.standard_normal((R, n, T))  # eq:data with a fixed D
    V = np.concatenate([np.broadcast_to(D.T, (R, T, d)), np.swapaxes(Y, 1, 2)], axis=2)
    M = np.swapaxes(V, 1, 2) @ V
    m0 = np.full((n, d), 0.2)
    for est in (
        BayesianLeastSquares(prior_mean=m0, prior_variance=0.4, noise_variance=sw2),
        BayesianLeastSquares(prior_mean=m0, prior_variance=np.array([0.1, 1.0, 5.0, 0.5]), noise_variance=sw2),
    ):
        err = estimate_errors(est.solve(M, T, n, m), A, B)
        _mc_close(err, bayesian_error_given_gram(A, B, G, prior_mean=m0, precision=est.precision(n, m), sigma_w2=sw2))
    err_ls = estimate_errors(OrdinaryLeastSquares().solve(M, T, n, m), A, B)
    F0 = bayesian_error_given_gram(A, B, G, prior_mean=m0, precision=np.zeros((d, d)), sigma_w2=sw2)
    assert F0 == pytest.approx(sw2 / (n + m) * np.trace(np.linalg.inv(G)), rel=1e-12)  # the identity of thm:sic's proof
    _mc_close(err_ls, F0)


def test_error_given_gram_in_the_closed_loop_of_eq_system() -> None:
    # The regressors of eq:system depend on earlier noise; (F) makes the independence step of the
    # proof of thm:sic. Measured with 20000 runs: within 0.3 % at N = 40, 1.3 % at N = 12.
    N, R = 40, 4000
    est = BayesianLeastSquares(prior_variance=0.5, noise_variance=SMALL.sigma_w2)
    sim = simulate_gaussian_attack(LinearPlant(A, B, sigma_w2=SMALL.sigma_w2), N=N, runs=R, sigma_u2=SMALL.sigma_u2, seed=1)
    err = estimate_errors(est.fit(sim.states, sim.inputs), A, B)
    Dt = np.concatenate([sim.states[:, :-1], sim.inputs[:, : N - 1]], axis=-1)
    F = bayesian_error_given_gram(
        A, B, np.swapaxes(Dt, 1, 2) @ Dt, prior_mean=0.0, precision=est.precision(n, m), sigma_w2=SMALL.sigma_w2
    )
    assert abs(err.mean() / F.mean() - 1.0) < 0.03


def _draw_and_attack(V: float, N: int, R: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Plants drawn from the prior N([A B], V) entrywise, one Gaussian attack of length N each."""
    rng = np.random.default_rng(seed)
    theta = THETA + np.sqrt(V) * rng.standard_normal((R, n, d))
    assert np.max(np.abs(np.linalg.eigvals(theta[:, :, :n]))) < 1.0  # every drawn plant is stable
    sw, su = np.sqrt(SMALL.sigma_w2), np.sqrt(SMALL.sigma_u2)
    x = np.zeros((R, N, n))
    u = su * rng.standard_normal((R, N - 1, m))
    x[:, 0] = rng.standard_normal((R, n))  # sigma_x2 = 1
    for t in range(N - 1):
        z = np.concatenate([x[:, t], u[:, t]], axis=1)
        x[:, t + 1] = np.einsum("rij,rj->ri", theta, z) + sw * rng.standard_normal((R, n))
    return theta, x, u


@pytest.mark.parametrize("N", [4, 10, 40])
def test_bayes_risk_is_the_posterior_covariance_and_gamma_B_bounds_it(N: int) -> None:
    V, R = 0.0025, 6000
    theta, x, u = _draw_and_attack(V, N, R, seed=N)
    est = BayesianLeastSquares(prior_mean=THETA, prior_variance=V, noise_variance=SMALL.sigma_w2)
    err = np.sum((est.fit(x, u) - theta) ** 2, axis=(1, 2)) / (n * d)
    Dt = np.concatenate([x[:, :-1], u], axis=-1)
    lam = est.precision(n, m)
    risk = bayes_risk_given_gram(np.swapaxes(Dt, 1, 2) @ Dt, precision=lam, sigma_w2=SMALL.sigma_w2, n=n)
    _mc_close(err - risk, 0.0)  # (B): exact, paired over the same runs
    # (C): the Gramian traces averaged over the drawn plants
    tr_u = np.mean([np.trace(controllability_gramian(t[:, :n], t[:, n:])) for t in theta[:500]])
    tr_w = np.mean([np.trace(noise_gramian(t[:, :n])) for t in theta[:500]])
    gB = bayesian_sic_from_traces(N, tr_u, tr_w, m, n, SMALL.sigma_u2, SMALL.sigma_w2, tr_precision=np.trace(lam[0]))
    assert gB < err.mean()
    # the prior is worth samples: at these N it takes the error far below the least-squares bound
    gamma = sic_from_traces(N, tr_u, tr_w, m, n, SMALL.sigma_u2, SMALL.sigma_w2)
    assert gB < gamma


def test_gamma_B_is_eq_sic_with_the_prior_as_extra_samples() -> None:
    tr_u = float(np.trace(controllability_gramian(A, B)))
    tr_w = float(np.trace(noise_gramian(A)))
    N = np.array([2, 5, 50, 5000])
    zero = bayesian_sample_identifying_complexity(N, A, B, sigma_u2=1.0, sigma_w2=0.1, precision=np.zeros((d, d)))
    np.testing.assert_array_equal(zero, sample_identifying_complexity(N, A, B, sigma_u2=1.0, sigma_w2=0.1))
    K = 1.0 * (tr_u + m) + 0.1 * tr_w
    tr_lam = 3.0 * K  # a prior worth exactly 3 samples
    assert prior_sample_equivalent(tr_lam, tr_u, tr_w, m, sigma_u2=1.0, sigma_w2=0.1) == pytest.approx(3.0)
    gB = bayesian_sic_from_traces(N, tr_u, tr_w, m, n, 1.0, 0.1, tr_precision=tr_lam)
    np.testing.assert_allclose(gB, sic_from_traces(N + 3, tr_u, tr_w, m, n, 1.0, 0.1), rtol=1e-12)
    # one trace per row: the mean of the rows' complexities
    per_row = bayesian_sic_from_traces(10, tr_u, tr_w, m, n, 1.0, 0.1, tr_precision=[0.0, tr_lam])
    assert per_row == pytest.approx(
        0.5 * (sic_from_traces(10, tr_u, tr_w, m, n, 1.0, 0.1) + sic_from_traces(13, tr_u, tr_w, m, n, 1.0, 0.1))
    )
    lam = BayesianLeastSquares(prior_variance=2.0, noise_variance=0.1).precision(n, m)
    by_plant = bayesian_sample_identifying_complexity(10, A, B, sigma_u2=1.0, sigma_w2=0.1, precision=lam)
    assert by_plant == pytest.approx(bayesian_sic_from_traces(10, tr_u, tr_w, m, n, 1.0, 0.1, tr_precision=d * 0.1 / 2.0))


def test_bad_input_is_refused() -> None:
    G = np.eye(d)
    with pytest.raises(ShapeError, match=r"precision must have shape \(4, 4\) or \(2, 4, 4\), got \(3, 3\)"):
        bayesian_error_given_gram(A, B, G, prior_mean=0.0, precision=np.eye(3), sigma_w2=0.1)
    with pytest.raises(ParameterError, match="symmetric"):
        bayes_risk_given_gram(G, precision=np.triu(np.ones((d, d))), sigma_w2=0.1, n=n)
    with pytest.raises(ParameterError, match="positive semidefinite"):
        bayes_risk_given_gram(G, precision=-np.eye(d), sigma_w2=0.1, n=n)
    with pytest.raises(ShapeError, match=r"G must have shape \(\.\.\., 4, 4\)"):
        bayesian_error_given_gram(A, B, np.eye(3), prior_mean=0.0, precision=np.eye(d), sigma_w2=0.1)
    with pytest.raises(ParameterError, match="sigma_w2"):
        bayes_risk_given_gram(G, precision=np.eye(d), sigma_w2=0.0, n=n)
    with pytest.raises(ParameterError, match=r"tr_precision must be >= 0, got \[-1.0\]"):
        bayesian_sic_from_traces(10, 1.0, 2.0, m, n, 1.0, 0.1, tr_precision=[-1.0])
    with pytest.raises(ShapeError, match="tr_precision"):
        bayesian_sic_from_traces(10, 1.0, 2.0, m, n, 1.0, 0.1, tr_precision=[1.0, 2.0, 3.0])


PAPER = get_preset("paper-example")  # n = m = 4, A = I / sqrt(2), B = I / 2


def _prior_plants_attack(p: object, V: float, N: int, R: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Plants drawn from N([A B] of ``p``, V) entrywise, one Gaussian attack of length N each."""
    A_, B_ = p.A, p.B  # type: ignore[attr-defined]
    n_, m_ = B_.shape
    rng = np.random.default_rng(seed)
    theta = np.hstack([A_, B_]) + np.sqrt(V) * rng.standard_normal((R, n_, n_ + m_))
    assert np.max(np.abs(np.linalg.eigvals(theta[:, :, :n_]))) < 1.0
    x = np.zeros((R, N, n_))
    u = np.sqrt(p.sigma_u2) * rng.standard_normal((R, N - 1, m_))  # type: ignore[attr-defined]
    x[:, 0] = np.sqrt(p.sigma_x2) * rng.standard_normal((R, n_))  # type: ignore[attr-defined]
    for t in range(N - 1):
        z = np.concatenate([x[:, t], u[:, t]], axis=1)
        x[:, t + 1] = np.einsum("rij,rj->ri", theta, z) + np.sqrt(p.sigma_w2) * rng.standard_normal((R, n_))  # type: ignore[attr-defined]
    return theta, x, u


@pytest.mark.parametrize("N", [9, 20, 100])
def test_gamma_B_is_a_lower_bound_of_the_bayes_error_on_the_design_example(N: int) -> None:
    # the Monte Carlo mean error of the posterior mean, over plants drawn from the prior, stays
    # above gamma_B by more than four standard errors (the direction of the Jensen chain)
    V, R = 0.0025, 3000
    theta, x, u = _prior_plants_attack(PAPER, V, N, R, seed=100 + N)
    nn, mm = PAPER.B.shape
    est = BayesianLeastSquares(prior_mean=np.hstack([PAPER.A, PAPER.B]), prior_variance=V, noise_variance=PAPER.sigma_w2)
    err = np.sum((est.fit(x, u) - theta) ** 2, axis=(1, 2)) / (nn * (nn + mm))
    lam = est.precision(nn, mm)
    tr_u = np.mean([np.trace(controllability_gramian(t[:, :nn], t[:, nn:])) for t in theta[:500]])
    tr_w = np.mean([np.trace(noise_gramian(t[:, :nn])) for t in theta[:500]])
    gB = bayesian_sic_from_traces(
        N, tr_u, tr_w, mm, nn, PAPER.sigma_u2, PAPER.sigma_w2, PAPER.sigma_x2, tr_precision=np.trace(lam[0])
    )
    se = err.std(ddof=1) / np.sqrt(R)
    assert err.mean() - 4.0 * se > gB, (err.mean(), se, gB)


def test_iid_gaussian_risk_is_the_inverse_wishart_mean() -> None:
    S = stationary_regressor_covariance(PAPER.A, PAPER.B, sigma_u2=PAPER.sigma_u2, sigma_w2=PAPER.sigma_w2)
    # Sigma by hand: state variance sigma_u2 b^2 / (1 - a^2) + sigma_w2 / (1 - a^2) = 10 * 0.25 / 0.5 + 0.1 / 0.5
    np.testing.assert_allclose(np.diag(S), [5.2] * 4 + [10.0] * 4, rtol=1e-12)
    zero = np.zeros((8, 8))
    T = 30
    exact, se0 = bayes_risk_iid_gaussian(T + 1, S, precision=zero, sigma_w2=0.1, n=4)
    assert se0 == 0.0 and exact == pytest.approx(0.1 * (4 / 5.2 + 4 / 10.0) / (8 * (T - 8 - 1)), rel=1e-12)
    assert bayes_risk_iid_gaussian(10, S, precision=zero, sigma_w2=0.1, n=4) == (np.inf, 0.0)  # T = d + 1: no mean
    # the exact value against i.i.d. Gaussian columns drawn directly (finite variance: T > d + 3)
    rng = np.random.default_rng(5)
    Z = np.linalg.cholesky(S) @ rng.standard_normal((20_000, 8, T))
    direct = 0.1 * np.trace(np.linalg.inv(Z @ np.swapaxes(Z, 1, 2)), axis1=1, axis2=2) / 8
    _mc_close(direct, exact)
    # with a prior: Bartlett draws against the same direct columns
    lam = 0.5 * np.eye(8)
    mc, se = bayes_risk_iid_gaussian(T + 1, S, precision=lam, sigma_w2=0.1, n=4, draws=20_000, seed=1)
    ref = bayes_risk_given_gram(Z @ np.swapaxes(Z, 1, 2), precision=lam, sigma_w2=0.1, n=4)
    assert abs(mc - ref.mean()) < 4.0 * np.hypot(se, ref.std(ddof=1) / np.sqrt(ref.size))
    # gamma_B lies below the i.i.d. value too (same Jensen chain, stationary traces)
    assert 8 * 0.1 / (np.trace(lam) + T * np.trace(S)) < mc
    with pytest.raises(ParameterError, match="positive definite"):
        bayes_risk_iid_gaussian(20, -S, precision=zero, sigma_w2=0.1, n=4)
    with pytest.raises(ShapeError):
        bayes_risk_iid_gaussian(20, S[:4, :4], precision=zero[:4, :4], sigma_w2=0.1, n=4)
    with pytest.raises(ParameterError, match="draws"):
        bayes_risk_iid_gaussian(20, S, precision=lam, sigma_w2=0.1, n=4, draws=1)
