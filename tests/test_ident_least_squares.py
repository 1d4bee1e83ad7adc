"""Tests of encctl_gym.ident.least_squares: eq:data, eq:estimate, Definition def:error on grids."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.errors import EncctlError, ParameterError, ResourceLimitError, ShapeError
from encctl_gym.ident.error import estimation_error
from encctl_gym.ident.grid import identification_errors
from encctl_gym.ident.least_squares import (
    GRAM_COND_LIMIT,
    RecursiveLeastSquares,
    check_sample_sizes,
    data_matrices,
    least_squares,
    prefix_estimates,
)
from encctl_gym.sim.plant import LinearPlant, simulate_gaussian_attack

A3 = np.array([[0.5, 0.1, 0.0], [0.0, 0.3, 0.2], [0.1, 0.0, -0.4]])
B3 = np.array([[1.0, 0.0], [0.5, 1.0], [0.0, -0.7]])


def _data(N: int = 200, runs: int = 3, seed: int = 0, sigma_u2: float = 1.0):  # type: ignore[no-untyped-def]
    sim = simulate_gaussian_attack(LinearPlant(A3, B3, sigma_w2=0.1), N=N, runs=runs, sigma_u2=sigma_u2, seed=seed)
    return sim.states, sim.inputs


def _lstsq_prefix(x: np.ndarray, u: np.ndarray, N: int) -> np.ndarray:
    """The reference: eq:estimate on the first N pairs by numpy.linalg.lstsq (theta = [A B])."""
    D = np.concatenate([x[: N - 1], u[: N - 1]], axis=1)
    return np.linalg.lstsq(D, x[1:N], rcond=None)[0].T


def test_data_matrices_layout_columns_are_time() -> None:
    x = np.arange(12.0).reshape(4, 3)  # x_0..x_3
    u = 100 + np.arange(8.0).reshape(4, 2)
    X_f, X_p, U_p = data_matrices(x, u)
    assert X_f.shape == (3, 3) and X_p.shape == (3, 3) and U_p.shape == (2, 3)
    np.testing.assert_array_equal(X_f[:, 0], x[1])
    np.testing.assert_array_equal(X_f[:, -1], x[3])
    np.testing.assert_array_equal(X_p[:, -1], x[2])
    np.testing.assert_array_equal(U_p[:, 1], u[1])
    # u with N - 1 rows is accepted as well (u_{t_f} never enters eq:data).
    np.testing.assert_array_equal(data_matrices(x, u[:3])[2], U_p)


def test_eq_data_identity_holds() -> None:
    sim = simulate_gaussian_attack(LinearPlant(A3, B3, sigma_w2=0.2), N=30, runs=2, sigma_u2=1.0, seed=1)
    X_f, X_p, U_p = data_matrices(sim.states, sim.inputs)
    W_p = np.swapaxes(sim.noises, -1, -2)
    np.testing.assert_allclose(X_f, A3 @ X_p + B3 @ U_p + W_p, atol=1e-12)


def test_least_squares_recovers_noise_free_system_exactly() -> None:
    rng = np.random.default_rng(3)
    N = 12
    u = rng.standard_normal((N, 2))
    x = np.zeros((N, 3))
    x[0] = rng.standard_normal(3)
    for t in range(N - 1):
        x[t + 1] = A3 @ x[t] + B3 @ u[t]
    A_hat, B_hat = least_squares(x, u)
    np.testing.assert_allclose(A_hat, A3, atol=1e-10)
    np.testing.assert_allclose(B_hat, B3, atol=1e-10)


def test_least_squares_batched_matches_lstsq() -> None:
    x, u = _data(N=40, runs=4)
    A_hat, B_hat = least_squares(x, u)
    assert A_hat.shape == (4, 3, 3) and B_hat.shape == (4, 3, 2)
    for r in range(4):
        theta = _lstsq_prefix(x[r], u[r], 40)
        np.testing.assert_allclose(np.concatenate([A_hat[r], B_hat[r]], axis=1), theta, rtol=1e-10, atol=1e-12)


def test_least_squares_needs_n_plus_m_plus_1_samples() -> None:
    x, u = _data(N=50, runs=1)
    least_squares(x[0, :6], u[0, :6])  # N = 6 = n + m + 1 is the minimum
    with pytest.raises(ParameterError, match=r"N=5.*N >= n \+ m \+ 1 = 6"):
        least_squares(x[0, :5], u[0, :5])


@pytest.mark.parametrize(
    "x, u, exc",
    [
        (np.zeros((10, 3)), np.zeros((10, 2, 1)), ShapeError),
        (np.zeros((10, 3)), np.zeros((7, 2)), ShapeError),
        (np.zeros((2, 10, 3)), np.zeros((3, 10, 2)), ShapeError),
        (np.zeros(10), np.zeros(10), ShapeError),
        (np.zeros((1, 3)), np.zeros((1, 2)), ParameterError),
        (np.full((10, 3), np.nan), np.zeros((10, 2)), ParameterError),
        (np.zeros((10, 3)), np.full((10, 2), np.inf), ParameterError),
    ],
)
def test_data_matrices_reject_bad_input(x, u, exc) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(exc):
        data_matrices(x, u)


# ----------------------------------------------------------------------------- recursive LS
def test_rls_equals_batch_least_squares_at_every_step() -> None:
    x, u = _data(N=150, runs=1, seed=4)
    x, u = x[0], u[0]
    rls = RecursiveLeastSquares(3, 2)
    for t in range(149):
        if t < 5:
            with pytest.raises(ParameterError, match="too small"):
                rls.estimate()
        rls.update(x[t], u[t], x[t + 1])
        assert rls.count == t + 1
        N = t + 2
        if N >= 6 and (N < 20 or N % 17 == 0 or N == 150):
            A_hat, B_hat = rls.estimate()
            theta = _lstsq_prefix(x, u, N)
            np.testing.assert_allclose(np.concatenate([A_hat, B_hat], axis=1), theta, rtol=1e-8, atol=1e-10)
            D = np.concatenate([x[: N - 1], u[: N - 1]], axis=1)
            np.testing.assert_allclose(rls.gram, D.T @ D, rtol=1e-12)
            np.testing.assert_allclose(rls.logdet_gram(), np.linalg.slogdet(D.T @ D)[1], rtol=1e-10)
    # Cached estimate is returned as a copy.
    a1, _ = rls.estimate()
    a1[:] = 0
    assert not np.allclose(rls.estimate()[0], 0)


def test_rls_singular_data_and_bad_updates() -> None:
    rls = RecursiveLeastSquares(2, 1)
    assert rls.logdet_gram() == float("-inf")
    for _ in range(10):
        rls.update(np.ones(2), np.zeros(1), np.ones(2))  # u never excited, x constant
    with pytest.raises(ParameterError, match="singular"):
        rls.estimate()
    before = rls.gram
    with pytest.raises(ShapeError):
        rls.update(np.ones(3), np.zeros(1), np.ones(2))
    with pytest.raises(ShapeError):
        rls.update(1.0, np.zeros(1), np.ones(2))
    with pytest.raises(ParameterError):
        rls.update(np.array([np.nan, 0.0]), np.zeros(1), np.ones(2))
    assert rls.count == 10
    np.testing.assert_array_equal(rls.gram, before)
    rls.reset()
    assert rls.count == 0 and not rls.gram.any()
    with pytest.raises(ParameterError):
        RecursiveLeastSquares(0, 1)


def test_rls_collinear_regressors_are_refused() -> None:
    rng = np.random.default_rng(0)
    rls = RecursiveLeastSquares(2, 1)
    for _ in range(20):
        x = rng.standard_normal(2)
        rls.update(x, x[:1], rng.standard_normal(2))  # u_t = x_t[0]: rank-deficient regressors
    with pytest.raises(ParameterError, match="singular"):
        rls.estimate()


# --------------------------------------------------------------------------- grids of N
GRID = [6, 7, 10, 25, 60, 61, 150, 400]


@pytest.mark.parametrize("method", ["auto", "gram", "qr"])
def test_prefix_estimates_match_lstsq_on_every_prefix(method: str) -> None:
    x, u = _data(N=400, runs=3, seed=5)
    theta = prefix_estimates(x, u, GRID, method=method)
    assert theta.shape == (3, len(GRID), 3, 5)
    for r in range(3):
        for k, N in enumerate(GRID):
            ref = _lstsq_prefix(x[r], u[r], N)
            np.testing.assert_allclose(theta[r, k], ref, rtol=0, atol=1e-10 * np.abs(ref).max())


def _trajectory(u_of_x, N: int = 400, seed: int = 0):  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(seed)
    x = np.zeros((N, 3))
    u = np.zeros((N, 2))
    x[0] = rng.standard_normal(3)
    for t in range(N):
        u[t] = u_of_x(x[t], rng)
        if t < N - 1:
            x[t + 1] = A3 @ x[t] + B3 @ u[t] + 0.1 * rng.standard_normal(3)
    return x, u


def _rel_dev(theta: np.ndarray, x: np.ndarray, u: np.ndarray, grid: list[int]) -> float:
    ref = np.stack([_lstsq_prefix(x, u, N) for N in grid])
    return float(np.abs(theta - ref).max() / np.abs(ref).max())


def test_badly_scaled_inputs_are_handled_by_the_gram_path() -> None:
    # Input 1e-7 times smaller than the state: cond(D) ~ 1e7, but Jacobi scaling fixes it.
    x, u = _trajectory(lambda x, rng: 1e-7 * rng.standard_normal(2))
    assert np.linalg.cond(np.concatenate([x[:-1], u[:-1]], axis=1)) > 1e6
    for method in ("gram", "auto", "qr"):
        assert _rel_dev(prefix_estimates(x, u, GRID, method=method), x, u, GRID) < 1e-10


def test_nearly_collinear_regressors_fall_back_to_qr() -> None:
    # u_t = 0.1 x_t[:2] + 1e-7 noise (a stable closed loop): intrinsically ill-conditioned, so the
    # normal equations lose ~cond^2 eps; "auto" detects it and matches lstsq like "qr".
    x, u = _trajectory(lambda x, rng: 0.1 * x[:2] + 1e-7 * rng.standard_normal(2))
    assert np.linalg.cond(np.concatenate([x[:-1], u[:-1]], axis=1)) > 1e5
    dev_gram = _rel_dev(prefix_estimates(x, u, GRID, method="gram"), x, u, GRID)
    dev_auto = _rel_dev(prefix_estimates(x, u, GRID, method="auto"), x, u, GRID)
    dev_qr = _rel_dev(prefix_estimates(x, u, GRID, method="qr"), x, u, GRID)
    assert dev_qr < 1e-9 and dev_auto < 1e-9
    assert dev_gram > 100 * dev_auto  # shows why the fallback exists (cond(G) > GRAM_COND_LIMIT)
    assert GRAM_COND_LIMIT <= 1e8


def test_identification_errors_are_def_error_on_every_prefix() -> None:
    x, u = _data(N=400, runs=4, seed=6)
    err = identification_errors(x, u, A3, B3, GRID)
    assert err.shape == (4, len(GRID))
    for r in range(4):
        for k, N in enumerate(GRID):
            theta = _lstsq_prefix(x[r], u[r], N)
            by_hand = np.sum((np.concatenate([A3, B3], axis=1) - theta) ** 2) / (3 * 5)
            np.testing.assert_allclose(err[r, k], by_hand, rtol=1e-8)
            np.testing.assert_allclose(err[r, k], estimation_error(A3, B3, theta[:, :3], theta[:, 3:]), rtol=1e-8)
    single = identification_errors(x[1], u[1], A3, B3, GRID)
    np.testing.assert_allclose(single, err[1], rtol=1e-12)


def test_errors_decrease_like_one_over_N() -> None:
    x, u = _data(N=5000, runs=30, seed=8)
    err = identification_errors(x, u, A3, B3, [50, 500, 5000]).mean(axis=0)
    ratios = err[:-1] / err[1:]
    assert np.all((ratios > 6) & (ratios < 16)), ratios  # ~10 per decade of N


@pytest.mark.parametrize(
    "grid, match",
    [
        ([], "empty"),
        ([10, 10, 20], "increasing"),
        ([20, 10], "increasing"),
        ([10, 20.5], "integers"),
        (["a", "b"], "integers"),
        ([5, 10], r"sample_sizes\[0\]=5 .*N >= n \+ m \+ 1 = 6"),
        ([10, 401], "exceeds"),
        ([[10, 20]], "1-D"),
    ],
)
def test_bad_grids_are_refused(grid, match) -> None:  # type: ignore[no-untyped-def]
    x, u = _data(N=400, runs=1)
    with pytest.raises(ParameterError, match=match):
        identification_errors(x, u, A3, B3, grid)


def test_bad_system_or_method_refused() -> None:
    x, u = _data(N=100, runs=1)
    with pytest.raises(ShapeError):
        identification_errors(x, u, np.eye(4), np.ones((4, 2)), [10])
    with pytest.raises(ShapeError):
        identification_errors(x, u, A3, np.ones((2, 2)), [10])
    with pytest.raises(ParameterError):
        identification_errors(x, u, A3 * np.nan, B3, [10])
    with pytest.raises(ParameterError):
        prefix_estimates(x, u, [10], method="svd")  # type: ignore[arg-type]
    assert check_sample_sizes(np.array([6.0, 9.0]), 3, 2).dtype == np.int64
    with pytest.raises(EncctlError):
        check_sample_sizes([True, False], 3, 2)


@settings(max_examples=25, deadline=None)
@given(
    n=st.integers(1, 3),
    m=st.integers(1, 3),
    seed=st.integers(0, 2**31 - 1),
    cuts=st.lists(st.integers(0, 60), min_size=1, max_size=5, unique=True),
)
def test_property_prefix_grid_equals_least_squares(n: int, m: int, seed: int, cuts: list[int]) -> None:
    rng = np.random.default_rng(seed)
    A = 0.9 * rng.uniform(-1, 1, (n, n)) / n
    B = rng.standard_normal((n, m))
    sim = simulate_gaussian_attack(LinearPlant(A, B, sigma_w2=0.5), N=n + m + 61, runs=2, sigma_u2=1.0, seed=seed)
    grid = sorted(n + m + 1 + c for c in cuts)
    theta = prefix_estimates(sim.states, sim.inputs, grid)
    for k, N in enumerate(grid):
        A_hat, B_hat = least_squares(sim.states[:, :N], sim.inputs[:, :N])
        ref = np.concatenate([A_hat, B_hat], axis=-1)
        np.testing.assert_allclose(theta[:, k], ref, rtol=0, atol=1e-8 * max(1.0, np.abs(ref).max()))


# ---------------------------------------------------------------- hardening
@pytest.mark.parametrize("which", ["x_t", "u_t", "x_next"])
@pytest.mark.parametrize("bad", [np.array([1j, 0.0]), np.array([True, False]), np.array(["a", "b"])])
def test_rls_update_refuses_complex_boolean_and_string_data(which, bad) -> None:
    """A complex sample is not cut to its real part, a boolean one not read as 0/1; the data so
    far are left unchanged."""
    rls = RecursiveLeastSquares(2, 2)
    good = {"x_t": np.zeros(2), "u_t": np.zeros(2), "x_next": np.zeros(2)}
    with pytest.raises(ParameterError, match=f"real numeric {which}, got <?array"):
        rls.update(**{**good, which: bad})
    assert rls.count == 0


def test_rls_update_names_the_non_finite_argument() -> None:
    rls = RecursiveLeastSquares(2, 1)
    with pytest.raises(ParameterError, match=r"finite entries in u_t, got array\(\[nan\]"):
        rls.update(np.zeros(2), np.array([np.nan]), np.zeros(2))


@pytest.mark.parametrize("n", [10**6, 10**400])
def test_rls_of_an_impossible_size_is_refused_with_its_memory(n) -> None:
    """n = 10^6 needs (2n + m)^2 * 8 bytes = about 29 800 GiB for its moment matrix."""
    with pytest.raises(ResourceLimitError, match="recursive least squares for n = .* GiB"):
        RecursiveLeastSquares(n, 1)


def test_solve_normal_equations_checks_its_arrays_and_solves_a_known_system() -> None:
    from encctl_gym.ident.least_squares import solve_normal_equations

    G = np.array([[4.0, 2.0], [2.0, 3.0]])
    C = np.array([[2.0], [1.0]])
    theta, ok = solve_normal_equations(G, C)  # G x = C: x = (1/8) [3*2 - 2*1, -2*2 + 4*1] = [0.5, 0]
    assert ok and np.allclose(theta, [[0.5, 0.0]], atol=1e-15)
    with pytest.raises(ShapeError, match=r"C must have shape \(2, 'k'\)"):
        solve_normal_equations(G, np.ones((3, 1)))
    with pytest.raises(ShapeError, match=r"C must have shape \(1, 1, 2, 'k'\)"):
        solve_normal_equations(G[None, None], C)
    with pytest.raises(ShapeError, match="square matrices"):
        solve_normal_equations(np.ones((2, 3)), C)
    with pytest.raises(ParameterError, match="G must be real"):
        solve_normal_equations(G * 1j, C)
    with pytest.raises(ParameterError, match="C must be a numeric array"):
        solve_normal_equations(G, None)
