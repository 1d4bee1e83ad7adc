"""Tests of encctl_gym.security.complexity (Definition def:error, eq:sic, eq:sic2, eq:bound)."""

from __future__ import annotations

import numpy as np
import pytest

from encctl_gym.errors import ParameterError, ShapeError, UnstableSystemError
from encctl_gym.security.complexity import (
    estimation_error,
    input_upper_bound,
    noise_upper_bound,
    sample_identifying_complexity,
    sample_identifying_complexity_asymptotic,
    sic_asymptotic_from_traces,
    sic_from_traces,
)


def test_estimation_error_definition() -> None:
    A, B = np.zeros((2, 2)), np.zeros((2, 1))
    # one entry off by 3: 9 / (n (n + m)) = 9 / 6
    A_hat = np.zeros((2, 2))
    A_hat[0, 1] = 3.0
    assert estimation_error(A, B, A_hat, B) == pytest.approx(1.5)
    assert estimation_error(A, B, A, [1.0, 1.0]) == pytest.approx(2 / 6)
    assert isinstance(estimation_error(A, B, A, B), float)


def test_estimation_error_broadcasts() -> None:
    rng = np.random.default_rng(1)
    A, B = rng.standard_normal((3, 3)), rng.standard_normal((3, 2))
    A_hat = rng.standard_normal((5, 4, 3, 3))
    B_hat = rng.standard_normal((4, 3, 2))
    err = estimation_error(A, B, A_hat, B_hat)
    assert err.shape == (5, 4)
    e = np.sum((A_hat[2, 1] - A) ** 2) + np.sum((B_hat[1] - B) ** 2)
    assert err[2, 1] == pytest.approx(e / 15)
    with pytest.raises(ShapeError):
        estimation_error(A, B, A_hat, rng.standard_normal((3, 3, 2)))
    with pytest.raises(ShapeError):
        estimation_error(A, B, A_hat[..., :2], B_hat)


def test_sic_closed_form_scaled_identity() -> None:
    a, b, n, m = 0.6, 1.5, 3, 2
    A, B = a * np.eye(n), b * np.eye(n, m)
    tr_w = n / (1 - a**2)
    tr_u = m * b**2 / (1 - a**2)
    su, sw, sx = 2.0, 0.5, 0.7
    for N in (2, 10, 1000):
        expected = (m + n) * sw / (sx * tr_w + (N - 1) * (su * (tr_u + m) + sw * tr_w))
        assert sample_identifying_complexity(N, A, B, sigma_u2=su, sigma_w2=sw, sigma_x2=sx) == pytest.approx(expected, rel=1e-12)
        expected2 = (m + n) / ((N - 1) * (su / sw * (tr_u + m) + tr_w))
        assert sample_identifying_complexity_asymptotic(N, A, B, r_sigma=su / sw) == pytest.approx(expected2, rel=1e-12)


def test_paper_example_value() -> None:
    # Psi_w = 2I, Psi_u = 0.5I, n = m = 4, R = 100: bracket = 100 * 6 + 8 = 608.
    assert sic_asymptotic_from_traces(13159, 2.0, 8.0, 4, 4, 100.0) == pytest.approx(8 / (13158 * 608))
    assert sic_asymptotic_from_traces(13159, 2.0, 8.0, 4, 4, 100.0) < 1e-6
    assert sic_asymptotic_from_traces(13158, 2.0, 8.0, 4, 4, 100.0) > 1e-6


def test_exact_vs_asymptotic_relation() -> None:
    # 1/gamma_sic = sigma_x2 tr Psi_w / ((m+n) sigma_w2) + 1/gamma_sic2 for every N.
    N = np.arange(2, 5000, 7)
    tr_u, tr_w, m, n, su, sw, sx = 2.0, 8.0, 4, 4, 10.0, 0.1, 1.0
    g = sic_from_traces(N, tr_u, tr_w, m, n, su, sw, sx)
    g2 = sic_asymptotic_from_traces(N, tr_u, tr_w, m, n, su / sw)
    np.testing.assert_allclose(1 / g - 1 / g2, sx * tr_w / ((m + n) * sw), rtol=1e-9)
    assert np.all(g < g2)
    assert g[-1] / g2[-1] > 0.999
    # sigma_x2 = 0 gives the asymptotic form exactly
    np.testing.assert_allclose(sic_from_traces(N, tr_u, tr_w, m, n, su, sw, 0.0), g2, rtol=1e-12)


def test_vector_matches_scalar_and_decreases() -> None:
    N = np.array([[2, 3], [100, 10**6]])
    g = sic_from_traces(N, 1.0, 3.0, 2, 3, 1.0, 1.0)
    assert g.shape == (2, 2)
    assert g[1, 0] == pytest.approx(sic_from_traces(100, 1.0, 3.0, 2, 3, 1.0, 1.0))
    flat = g.ravel()
    assert np.all(np.diff(flat) < 0)


def test_upper_bounds() -> None:
    N, m, n = 101, 4, 4
    assert input_upper_bound(N, m, n, 100.0) == pytest.approx(8 / (100 * 4 * 100))
    assert noise_upper_bound(N, m, n) == pytest.approx(8 / (100 * 4))
    rng = np.random.default_rng(3)
    for _ in range(20):
        tr_u = rng.uniform(0, 10)
        tr_w = n * rng.uniform(1, 5)  # tr Psi_w >= n
        r = 10 ** rng.uniform(-3, 3)
        g = sic_asymptotic_from_traces(N, tr_u, tr_w, m, n, r)
        assert g <= input_upper_bound(N, m, n, r)
        assert g <= noise_upper_bound(N, m, n)
    # the input bound is approached as tr Psi_u -> 0 and R grows (eq:bound)
    g = sic_asymptotic_from_traces(N, 1e-9, n, m, n, 1e9)
    assert g == pytest.approx(input_upper_bound(N, m, n, 1e9), rel=1e-6)


def test_sic_is_below_monte_carlo_mean_error() -> None:
    # Theorem thm:sic: gamma(N) <= E[epsilon(N)] for i.i.d. Gaussian inputs (independent simulation).
    rng = np.random.default_rng(7)
    A, B = np.array([[0.5, 0.2], [0.0, 0.3]]), np.array([[1.0], [0.5]])
    n, m = B.shape
    su, sw, sx, N, runs = 1.0, 0.5, 1.0, 30, 2000
    u = rng.normal(0, np.sqrt(su), (runs, N, m))
    x = np.empty((runs, N, n))
    x[:, 0] = rng.normal(0, np.sqrt(sx), (runs, n))
    for t in range(N - 1):
        x[:, t + 1] = x[:, t] @ A.T + u[:, t] @ B.T + rng.normal(0, np.sqrt(sw), (runs, n))
    D = np.concatenate([x[:, :-1], u[:, :-1]], axis=2)  # (runs, N-1, n+m), rows are regressors
    theta = np.linalg.solve(D.transpose(0, 2, 1) @ D, D.transpose(0, 2, 1) @ x[:, 1:]).transpose(0, 2, 1)
    errs = estimation_error(A, B, theta[:, :, :n], theta[:, :, n:])
    gamma = sample_identifying_complexity(N, A, B, sigma_u2=su, sigma_w2=sw, sigma_x2=sx)
    assert gamma < errs.mean()
    assert gamma > 0.2 * errs.mean()  # same order of magnitude


@pytest.mark.parametrize("bad", [1, 0, -3, 2.5, [2, 1], [3.5], np.nan])
def test_bad_sample_sizes(bad: object) -> None:
    with pytest.raises(ParameterError, match="N"):
        sic_from_traces(bad, 1.0, 2.0, 1, 1, 1.0, 1.0)


def test_bad_parameters_named() -> None:
    with pytest.raises(ParameterError, match="sigma_u2"):
        sic_from_traces(5, 1.0, 2.0, 1, 1, -1.0, 1.0)
    with pytest.raises(ParameterError, match="sigma_w2"):
        sic_from_traces(5, 1.0, 2.0, 1, 1, 1.0, 0.0)
    with pytest.raises(ParameterError, match="sigma_x2"):
        sic_from_traces(5, 1.0, 2.0, 1, 1, 1.0, 1.0, -0.1)
    with pytest.raises(ParameterError, match="tr_psi_w"):
        sic_asymptotic_from_traces(5, 1.0, 0.0, 1, 1, 1.0)
    with pytest.raises(ParameterError, match="r_sigma"):
        input_upper_bound(5, 1, 1, float("inf"))
    with pytest.raises(ParameterError, match="m"):
        noise_upper_bound(5, 0, 1)
    with pytest.raises(UnstableSystemError):
        sample_identifying_complexity(5, 1.5 * np.eye(2), np.eye(2), sigma_u2=1.0, sigma_w2=1.0)


# --------------------------------------------------------------------------- counts beyond the float range
@pytest.mark.parametrize("big", [10**400, 10**5000], ids=["10^400", "10^5000"])
def test_counts_beyond_the_float_range_are_named(big: int) -> None:
    # a ParameterError that names the size, never an OverflowError from float(N) or (m + n) * sigma_w2
    for call in (
        lambda: sic_from_traces(big, 1.0, 2.0, 1, 1, 1.0, 1.0),
        lambda: sample_identifying_complexity(big, 0.5 * np.eye(1), np.eye(1), sigma_u2=1.0, sigma_w2=1.0),
        lambda: input_upper_bound(big, 1, 1, 1.0),
    ):
        with pytest.raises(ParameterError, match="N must lie within the float64 range") as info:
            call()
        assert "bits" in str(info.value)
    for name, args in (("m", (5, 1.0, 2.0, big, 1, 1.0, 1.0)), ("n", (5, 1.0, 2.0, 1, big, 1.0, 1.0))):
        with pytest.raises(ParameterError, match=f"^{name} must lie within the float64 range"):
            sic_from_traces(*args)


def test_a_large_sample_size_inside_the_float_range_is_valid() -> None:
    # eq:sic2 by hand for N = 10**300: (m+n) / ((N-1) [R (tr_u + m) + tr_w]) = 2 / (1e300 * (1 * 2 + 2))
    assert sic_asymptotic_from_traces(10**300, 1.0, 2.0, 1, 1, 1.0) == pytest.approx(0.5e-300, rel=1e-12)


def test_an_overflowing_complexity_is_refused_not_nan() -> None:
    # m + n = 1.6e308 is a float, but (m+n) sigma_w2 = 1.6e309 is not: refused rather than inf / inf = nan
    with pytest.raises(ParameterError, match="overflows float64"):
        sic_from_traces(10**300, 1.0, 2.0, 8 * 10**307, 8 * 10**307, 1.0, 10.0)
