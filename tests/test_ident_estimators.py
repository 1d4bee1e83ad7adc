"""Tests of the Estimator protocol, the registry and each estimator against an independent computation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.errors import EncctlError, ParameterError, ShapeError
from encctl_gym.ident import (
    BayesianLeastSquares,
    Estimator,
    ForgettingLeastSquares,
    InstrumentalVariables,
    OrdinaryLeastSquares,
    RecursiveLeastSquares,
    estimation_error,
    estimator_names,
    estimator_spec,
    identification_errors,
    least_squares,
    make_estimator,
    prefix_estimates,
)
from encctl_gym.sim.montecarlo import AttackSpec, gaussian_attack_errors, sweep_gaussian_attack
from encctl_gym.sim.plant import LinearPlant, simulate_gaussian_attack

A3 = np.array([[0.5, 0.1, 0.0], [0.0, 0.3, 0.2], [0.1, 0.0, -0.4]])
B3 = np.array([[1.0, 0.0], [0.5, 1.0], [0.0, -0.7]])
NAMES = ("ls", "bayes", "forgetting", "iv", "n4sid", "moesp")


def _data(N: int = 200, runs: int = 3, seed: int = 0, sigma_w2: float = 0.1):  # type: ignore[no-untyped-def]
    sim = simulate_gaussian_attack(LinearPlant(A3, B3, sigma_w2=sigma_w2), N=N, runs=runs, sigma_u2=1.0, seed=seed)
    return sim.states, sim.inputs


def _columns(x: np.ndarray, u: np.ndarray, N: int) -> tuple[np.ndarray, np.ndarray]:
    """D^T (N-1, d) and X_f^T (N-1, n) of eq:data, from the raw trajectory."""
    return np.concatenate([x[: N - 1], u[: N - 1]], axis=1), x[1:N]


def _feed(est, x: np.ndarray, u: np.ndarray, upto: int) -> None:  # type: ignore[no-untyped-def]
    """Deliver columns 1 .. upto - 1 of trajectories x (K, N, n), u (K, N-1, m) online."""
    for j in range(1, upto):
        est.update(np.concatenate([x[:, j - 1], u[:, j - 1]], axis=1), x[:, j])


# ----------------------------------------------------------------------------- protocol, registry
def test_every_registered_estimator_follows_the_protocol() -> None:
    assert estimator_names() == list(NAMES)
    for name in NAMES:
        est = make_estimator(name)
        assert isinstance(est, Estimator) and est.name == name
        assert make_estimator(estimator_spec(est)).params == est.params
    assert isinstance(make_estimator(), OrdinaryLeastSquares)
    e = BayesianLeastSquares(prior_variance=2.0, noise_variance=0.5)
    assert make_estimator(e) is e
    spec = estimator_spec(make_estimator({"name": "forgetting", "forgetting_factor": 0.99}))
    assert spec == {"name": "forgetting", "forgetting_factor": 0.99}


@pytest.mark.parametrize(
    "spec, params, match",
    [
        ("ridge", {}, r"unknown estimator 'ridge'; choose one of ls, bayes, forgetting, iv"),
        ("ls", {"lam": 1}, r"the estimator 'ls' has no option 'lam'; its options: method"),
        ({"lags": 2}, {}, "needs a 'name' key"),
        ({"name": "iv", "lags": 2}, {"lags": 3}, "given twice"),
        (3.0, {}, "must be a name"),
        ("forgetting", {"forgetting_factor": 0.0}, r"\(0, 1\], got 0.0"),
        ("forgetting", {"forgetting_factor": 1.5}, r"\(0, 1\], got 1.5"),
        ("forgetting", {"forgetting_factor": -0.5}, r"got -0.5"),
        ("forgetting", {"forgetting_factor": float("nan")}, r"got nan"),
        ("forgetting", {"forgetting_factor": True}, r"got True"),
        ("forgetting", {"forgetting_factor": "x"}, r"got 'x'"),
        ("bayes", {"prior_variance": 0.0, "noise_variance": 1.0}, r"prior_variance must be finite and > 0, got 0.0"),
        ("bayes", {"prior_variance": [1.0, -2.0], "noise_variance": 1.0}, r"prior_variance .* got \[1.0, -2.0\]"),
        ("bayes", {"prior_variance": 1.0, "noise_variance": -1.0}, r"noise_variance must be finite and > 0, got -1.0"),
        ("bayes", {"prior_variance": 1.0}, "noise_variance is missing"),
        ("bayes", {"noise_variance": 1.0}, "prior_variance is missing"),
        ("bayes", {"prior_mean": [1.0, 2.0]}, "prior_mean must be a finite scalar or an"),
        ("bayes", {"prior_variance": np.ones((2, 2, 2)), "noise_variance": 1.0}, r"got shape \(2, 2, 2\)"),
        ("iv", {"lags": 0}, "lags must be >= 1, got 0"),
        ("ls", {"method": "svd"}, "method must be"),
    ],
)
def test_bad_estimators_are_refused_with_the_value_named(spec, params, match) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ParameterError, match=match):
        make_estimator(spec, **params)


def test_wrong_prior_shapes_and_underdetermined_instruments_are_refused_on_use() -> None:
    x, u = _data(N=60, runs=1)
    bad_mean = BayesianLeastSquares(prior_mean=np.zeros((3, 4)))
    with pytest.raises(ShapeError, match=r"prior_mean must have shape \(3, 5\) for n=3, m=2, got \(3, 4\)"):
        bad_mean.fit(x, u)
    bad_var = BayesianLeastSquares(prior_variance=np.ones(4), noise_variance=1.0)
    with pytest.raises(ShapeError, match=r"prior_variance must be a scalar or have shape \(5,\) or \(3, 5\).*got \(4,\)"):
        bad_var.start(2, 3, 2)
    iv = InstrumentalVariables(lags=1)  # (1 + 1) * 1 = 2 instruments for n + m = 4 unknowns
    with pytest.raises(
        ParameterError, match=r"lags=1 give \(lags \+ 1\) m = 2 instruments for n \+ m = 4 unknowns.*under-determined"
    ):
        iv.start(1, 3, 1)
    with pytest.raises(ParameterError, match="under-determined"):
        iv.fit(x, u[..., :1])
    with pytest.raises(ParameterError, match="under-determined"):
        identification_errors(x, u[..., :1], A3, B3[:, :1], [20], estimator=iv)
    assert InstrumentalVariables(lags=1).fit(x[..., :1], u).shape == (1, 1, 3)  # n = 1, m = 2: 4 instruments
    assert InstrumentalVariables().lags_for(3, 1) == 3 and InstrumentalVariables().lags_for(3, 2) == 2


def test_too_few_samples_and_bad_online_data() -> None:
    x, u = _data(N=60, runs=2)
    for name in ("ls", "forgetting"):
        with pytest.raises(ParameterError, match=r"N=5 is too small.*N >= (n \+ m \+ 1 = )?6"):
            make_estimator(name).fit(x[:, :5], u[:, :5])
    with pytest.raises(ParameterError, match=r"N=8 is too small: the iv estimator needs N >= 9"):
        make_estimator("iv").fit(x[:, :8], u[:, :8])  # L = 2 lags, q = 6 instruments
    with pytest.raises(ParameterError, match=r"sample_sizes\[0\]=5 is too small"):
        identification_errors(x, u, A3, B3, [5, 10], estimator="forgetting")
    est = make_estimator("ls")
    with pytest.raises(ParameterError, match="start"):
        est.estimate()
    est.start(2, 3, 2)
    with pytest.raises(ParameterError, match="too small"):
        est.estimate()
    _feed(est, x, u, 10)
    before = est.moments()
    with pytest.raises(ShapeError):
        est.update(np.zeros((2, 4)), np.zeros((2, 3)))
    with pytest.raises(ShapeError):
        est.update(np.zeros((1, 5)), np.zeros((1, 3)))
    with pytest.raises(ParameterError, match="non-finite"):
        est.update(np.full((2, 5), np.nan), np.zeros((2, 3)))
    with pytest.raises(ParameterError, match="numeric"):
        est.update([["a"] * 5] * 2, np.zeros((2, 3)))
    assert est.count == 9
    np.testing.assert_array_equal(est.moments(), before)
    with pytest.raises(ShapeError):
        est.error(np.eye(2), np.ones((2, 2)))
    with pytest.raises(ParameterError):
        identification_errors(x, u, A3, B3, [10], estimator="bayes", method="qr")
    with pytest.raises(EncctlError):
        make_estimator("iv").start(0, 3, 2)


# ----------------------------------------------------------------------------- least squares
def test_least_squares_estimator_gives_todays_numbers_exactly() -> None:
    x, u = _data(N=400, runs=3, seed=5)
    ols = OrdinaryLeastSquares()
    A_hat, B_hat = least_squares(x, u)
    np.testing.assert_array_equal(ols.fit(x, u), np.concatenate([A_hat, B_hat], axis=-1))
    grid = [6, 7, 10, 60, 61, 400]
    np.testing.assert_array_equal(ols.prefix_estimates(x, u, grid), prefix_estimates(x, u, grid))
    np.testing.assert_array_equal(
        identification_errors(x, u, A3, B3, grid, estimator="ls"), identification_errors(x, u, A3, B3, grid)
    )
    np.testing.assert_array_equal(
        OrdinaryLeastSquares("qr").prefix_estimates(x, u, grid), prefix_estimates(x, u, grid, method="qr")
    )


def test_online_least_squares_equals_recursive_least_squares_bit_for_bit() -> None:
    x, u = _data(N=300, runs=3, seed=2)
    est = OrdinaryLeastSquares()
    est.start(3, 3, 2)
    rls = [RecursiveLeastSquares(3, 2) for _ in range(3)]
    for j in range(1, 300):
        est.update(np.concatenate([x[:, j - 1], u[:, j - 1]], axis=1), x[:, j])
        for k in range(3):
            rls[k].update(x[k, j - 1], u[k, j - 1], x[k, j])
        if j + 1 >= 6 and (j < 20 or j % 37 == 0 or j == 299):
            theta = est.estimate()
            for k in range(3):
                np.testing.assert_array_equal(theta[k], np.concatenate(rls[k].estimate(), axis=1))
            err = est.error(A3, B3)
            for k in range(3):
                assert err[k] == estimation_error(A3, B3, theta[k, :, :3], theta[k, :, 3:])


def test_online_least_squares_falls_back_to_the_pseudo_inverse_for_a_singular_copy() -> None:
    rng = np.random.default_rng(0)
    est = OrdinaryLeastSquares()
    est.start(2, 2, 1)
    for _ in range(12):
        x = rng.standard_normal((2, 2))
        u = rng.standard_normal((2, 1))
        u[1] = 0.0  # copy 1 never excites its input: eq:estimate is the minimum-norm solution
        est.update(np.concatenate([x, u], axis=1), rng.standard_normal((2, 2)))
    theta = est.estimate()
    assert np.all(np.isfinite(theta)) and np.all(theta[1, :, 2] == 0.0)


# ----------------------------------------------------------------------------- online = batch, grid = batch
@pytest.mark.parametrize("name", NAMES)
def test_online_equals_batch_and_grid_equals_batch(name: str) -> None:
    x, u = _data(N=240, runs=4, seed=7)
    est = make_estimator(name)
    # empirical Bayes locates the maximum of an evidence that is nearly flat at a few samples
    # (N = 2: one column): moments that differ by rounding move the estimate by up to ~1e-7
    # there; every other estimator agrees to rounding
    tol = 1e-6 if name == "bayes" else 1e-10
    N0 = max(est.min_sample_size(3, 2), 2)  # a batch trajectory has N >= 2
    grid = sorted({N0, N0 + 1, *(N for N in (31, 64, 65, 130, 240) if N > N0 + 1)})  # the subspace windows need more
    theta = est.prefix_estimates(x, u, grid)
    assert theta.shape == (4, len(grid), 3, 5)
    for k, N in enumerate(grid):
        ref = est.fit(x[:, :N], u[:, : N - 1])
        np.testing.assert_allclose(theta[:, k], ref, rtol=0, atol=tol)
    est.start(4, 3, 2)
    for j in range(1, 240):
        est.update(np.concatenate([x[:, j - 1], u[:, j - 1]], axis=1), x[:, j])
        N = j + 1
        if N in grid:
            np.testing.assert_allclose(est.estimate(), est.fit(x[:, :N], u[:, : N - 1]), rtol=0, atol=tol)
    np.testing.assert_allclose(est.error(A3, B3), identification_errors(x, u, A3, B3, [240], estimator=name)[:, 0], rtol=1e-6)
    single = est.prefix_estimates(x[2], u[2], grid)
    np.testing.assert_allclose(single, theta[2], rtol=0, atol=tol)


# ----------------------------------------------------------------------------- Bayesian least squares
def _posterior_mean_direct(x: np.ndarray, u: np.ndarray, m0: np.ndarray, V: np.ndarray, sw2: float) -> np.ndarray:
    """Row by row, from the raw data: precision diag(1/V_i) + D D^T / sw2, mean by an explicit inverse."""
    Dt, Y = _columns(x, u, x.shape[0])
    out = np.empty_like(m0)
    for i in range(m0.shape[0]):
        prec = np.diag(1.0 / V[i]) + Dt.T @ Dt / sw2
        out[i] = np.linalg.inv(prec) @ (m0[i] / V[i] + Dt.T @ Y[:, i] / sw2)
    return out


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), N=st.integers(2, 40), shape=st.sampled_from(["scalar", "column", "entry"]))
def test_property_bayes_posterior_mean_equals_the_direct_posterior(seed: int, N: int, shape: str) -> None:
    rng = np.random.default_rng(seed)
    x, u = _data(N=N, runs=1, seed=seed)
    x, u = x[0], u[0]
    m0 = rng.standard_normal((3, 5))
    V = {"scalar": rng.uniform(0.01, 5.0), "column": rng.uniform(0.01, 5.0, 5), "entry": rng.uniform(0.01, 5.0, (3, 5))}[shape]
    sw2 = float(rng.uniform(0.05, 2.0))
    est = BayesianLeastSquares(prior_mean=m0, prior_variance=V, noise_variance=sw2)
    ref = _posterior_mean_direct(x, u, m0, np.broadcast_to(V, (3, 5)), sw2)
    np.testing.assert_allclose(est.fit(x, u), ref, rtol=1e-8, atol=1e-10)
    # ridge as augmented least squares: [D^T; sqrt(Lambda)] theta_i = [y_i; sqrt(Lambda) m0_i]
    Dt, Y = _columns(x, u, N)
    Vb = np.broadcast_to(V, (3, 5))
    for i in range(3):
        s = np.sqrt(sw2 / Vb[i])
        sol = np.linalg.lstsq(np.vstack([Dt, np.diag(s)]), np.concatenate([Y[:, i], s * m0[i]]), rcond=None)[0]
        np.testing.assert_allclose(est.fit(x, u)[i], sol, rtol=1e-7, atol=1e-9)


def test_bayes_limits_are_least_squares_and_the_prior_mean() -> None:
    x, u = _data(N=80, runs=2, seed=3)
    m0 = np.full((3, 5), 0.25)
    wide = BayesianLeastSquares(prior_mean=m0, prior_variance=1e12, noise_variance=0.1)
    np.testing.assert_allclose(wide.fit(x, u), OrdinaryLeastSquares().fit(x, u), atol=1e-8)
    tight = BayesianLeastSquares(prior_mean=m0, prior_variance=1e-14, noise_variance=0.1)
    np.testing.assert_allclose(tight.fit(x, u), np.broadcast_to(m0, (2, 3, 5)), atol=1e-8)
    est = BayesianLeastSquares(prior_mean=m0)
    est.start(2, 3, 2)
    np.testing.assert_array_equal(est.estimate(), np.broadcast_to(m0, (2, 3, 5)))  # no data: the prior mean
    lam = BayesianLeastSquares(prior_variance=np.arange(1.0, 6.0), noise_variance=2.0).precision(3, 2)
    np.testing.assert_allclose(lam[1], np.diag(2.0 / np.arange(1.0, 6.0)))
    with pytest.raises(ParameterError, match="no fixed precision"):
        BayesianLeastSquares().precision(3, 2)


def _profiled_log_evidence_direct(x: np.ndarray, u: np.ndarray, v: float) -> float:
    """log p(X_f | v) with sigma^2 profiled, from the T x T covariance sigma^2 (I + v D^T D) (prior mean 0)."""
    Dt, Y = _columns(x, u, x.shape[0])
    T, n = Y.shape
    S = np.eye(T) + v * Dt @ Dt.T
    _, logdet = np.linalg.slogdet(S)
    quad = sum(Y[:, i] @ np.linalg.solve(S, Y[:, i]) for i in range(n))
    s2 = quad / (n * T)
    return -0.5 * n * logdet - 0.5 * n * T * math.log(s2) - 0.5 * n * T


@pytest.mark.parametrize("N", [5, 9, 30, 60])
def test_empirical_bayes_maximises_the_marginal_likelihood(N: int) -> None:
    x, u = _data(N=N, runs=1, seed=11, sigma_w2=0.5)
    x, u = x[0], u[0]
    Dt, Y = _columns(x, u, N)
    vs = np.logspace(-5, 4, 1801) / (np.trace(Dt.T @ Dt) / 5)
    ll = np.array([_profiled_log_evidence_direct(x, u, v) for v in vs])
    v_star = vs[np.argmax(ll)]
    got = BayesianLeastSquares().fit(x, u)
    if np.argmax(ll) == 0:  # the evidence prefers "all noise": both shrink to the prior mean 0
        assert np.abs(got).max() < 1e-3 * np.abs(OrdinaryLeastSquares().fit(x, u) if N >= 6 else Y).max()
        return
    T = N - 1
    quad = sum(Y[:, i] @ np.linalg.solve(np.eye(T) + v_star * Dt @ Dt.T, Y[:, i]) for i in range(3))
    s2 = quad / (3 * T)
    ref = BayesianLeastSquares(prior_variance=v_star * s2, noise_variance=s2).fit(x, u)
    np.testing.assert_allclose(got, ref, rtol=0, atol=2e-3 * np.abs(ref).max())


# ----------------------------------------------------------------------------- forgetting
def test_forgetting_is_weighted_least_squares() -> None:
    x, u = _data(N=150, runs=1, seed=4)
    x, u = x[0], u[0]
    lam = 0.97
    Dt, Y = _columns(x, u, 150)
    w = np.sqrt(lam ** np.arange(148, -1, -1.0))
    ref = np.linalg.lstsq(Dt * w[:, None], Y * w[:, None], rcond=None)[0].T
    est = ForgettingLeastSquares(lam)
    np.testing.assert_allclose(est.fit(x, u), ref, rtol=1e-9, atol=1e-11)
    theta = est.prefix_estimates(x, u, [20, 150])
    np.testing.assert_allclose(theta[-1], ref, rtol=1e-9, atol=1e-11)
    Dt20, Y20 = _columns(x, u, 20)
    w20 = np.sqrt(lam ** np.arange(18, -1, -1.0))
    np.testing.assert_allclose(
        theta[0], np.linalg.lstsq(Dt20 * w20[:, None], Y20 * w20[:, None], rcond=None)[0].T, rtol=1e-9, atol=1e-11
    )
    np.testing.assert_allclose(ForgettingLeastSquares(1.0).fit(x, u), OrdinaryLeastSquares().fit(x, u), rtol=1e-9, atol=1e-12)


# ----------------------------------------------------------------------------- instrumental variables
def _two_stage_direct(x: np.ndarray, u: np.ndarray, L: int) -> np.ndarray:
    """2SLS from raw matrices: first stage D_hat = P_Z D, second stage lstsq(D_hat, Y)."""
    Dt, Y = _columns(x, u, x.shape[0])
    T = Dt.shape[0]
    Z = np.concatenate([u[L - k : T - k] for k in range(L + 1)], axis=1)
    D, Yv = Dt[L:], Y[L:]
    D_hat = Z @ np.linalg.lstsq(Z, D, rcond=None)[0]
    return np.linalg.lstsq(D_hat, Yv, rcond=None)[0].T


@pytest.mark.parametrize("lags", [None, 3])
def test_instrumental_variables_is_two_stage_least_squares(lags) -> None:  # type: ignore[no-untyped-def]
    x, u = _data(N=200, runs=1, seed=9)
    x, u = x[0], u[0]
    est = InstrumentalVariables(lags)
    L = est.lags_for(3, 2)
    np.testing.assert_allclose(est.fit(x, u), _two_stage_direct(x, u, L), rtol=1e-8, atol=1e-10)
    if lags is None:  # just identified: the plain IV estimate (Z^T D)^{-1} Z^T Y
        Dt, Y = _columns(x, u, 200)
        Z = np.concatenate([u[L - k : 199 - k] for k in range(L + 1)], axis=1)
        q_plus = Z.shape[1]
        assert q_plus == 6  # (2 + 1) * 2 >= n + m = 5: over-identified by one
    # NaN, not a wrong number, when the inputs do not excite the instruments
    est.start(1, 3, 2)
    for _ in range(30):
        est.update(np.concatenate([np.ones((1, 3)), np.zeros((1, 2))], axis=1), np.ones((1, 3)))
    assert np.all(np.isnan(est.estimate())) and np.isnan(est.error(A3, B3)[0])


def test_instrumental_variables_stay_consistent_under_coloured_noise_where_least_squares_does_not() -> None:
    # AR(1) process noise w_t = 0.8 w_{t-1} + e_t correlates x_t with w_t: least squares is biased,
    # lagged inputs are still valid instruments.
    A = np.array([[0.6, 0.2], [-0.1, 0.5]])
    B = np.array([[1.0, 0.0], [0.3, 0.8]])
    rng = np.random.default_rng(1)
    N = 40_000
    u = rng.standard_normal((N, 2))
    x = np.zeros((N, 2))
    w = np.zeros(2)
    for t in range(N - 1):
        w = 0.8 * w + 0.5 * rng.standard_normal(2)
        x[t + 1] = A @ x[t] + B @ u[t] + w
    e_ls = estimation_error(A, B, *np.split(OrdinaryLeastSquares().fit(x, u), [2], axis=1))
    e_iv = estimation_error(A, B, *np.split(InstrumentalVariables().fit(x, u), [2], axis=1))
    assert e_ls > 0.01 and e_iv < 0.05 * e_ls, (e_ls, e_iv)


# ----------------------------------------------------------------------------- the engine
def test_engine_compares_estimators_on_common_trajectories() -> None:
    plant = LinearPlant(A3, B3, sigma_w2=0.1)
    grid = [6, 20, 100]
    ls = gaussian_attack_errors(plant, sample_sizes=grid, runs=6, sigma_u2=1.0, seed=3)
    np.testing.assert_array_equal(
        ls, gaussian_attack_errors(plant, sample_sizes=grid, runs=6, sigma_u2=1.0, seed=3, estimator="ls")
    )
    sim = simulate_gaussian_attack(plant, N=100, runs=6, sigma_u2=1.0, seed=3)
    for name in ("bayes", "forgetting"):
        got = gaussian_attack_errors(plant, sample_sizes=grid, runs=6, sigma_u2=1.0, seed=3, estimator=name)
        np.testing.assert_allclose(got, identification_errors(sim.states, sim.inputs, A3, B3, grid, estimator=name), rtol=1e-12)
    early = gaussian_attack_errors(plant, sample_sizes=[1, 2, 6], runs=2, sigma_u2=1.0, seed=3, estimator="bayes")
    np.testing.assert_allclose(early[:, 0], np.sum(np.hstack([A3, B3]) ** 2) / 15)  # the prior mean 0
    spec = AttackSpec(A3, B3, sigma_w2=0.1, sigma_u2=1.0)
    sw = sweep_gaussian_attack(
        [spec, spec], sample_sizes=grid, runs=3, seed=1, n_jobs=1, estimator={"name": "forgetting", "forgetting_factor": 0.99}
    )
    assert sw.shape == (2, 3, 3) and np.all(np.isfinite(sw))
    with pytest.raises(ParameterError, match="unknown estimator"):
        sweep_gaussian_attack([spec], sample_sizes=grid, runs=3, seed=1, n_jobs=1, estimator="tls")
    with pytest.raises(ParameterError, match="too small"):
        sweep_gaussian_attack([spec], sample_sizes=[8, 20], runs=3, seed=1, n_jobs=1, estimator="iv")
