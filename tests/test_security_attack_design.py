"""Tests of encctl_gym.security.attack_design (A-optimal attack inputs, gamma_opt, robust design)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym._validation import format_value
from encctl_gym.errors import ParameterError, ResourceLimitError, SolverError, UnstableSystemError
from encctl_gym.plant import Plant
from encctl_gym.security.attack_design import (
    gamma_opt,
    gaussian_attack_design,
    optimal_attack_design,
    robust_security_design,
    sdp_estimate,
)
from encctl_gym.security.complexity import sic_asymptotic_from_traces
from encctl_gym.security.design import paper_design_example, sample_size_for_rate
from encctl_gym.security.gramians import noise_gramian
from encctl_gym.security.threat import ThreatModel

SCALAR_CASES = [(0.5, 1.0, 1.0, 1.0), (0.9, 0.2, 1.0, 1.0), (-0.8, 1.0, 0.1, 1.0), (0.3, 2.0, 5.0, 0.5), (0.0, 1.0, 2.0, 0.3)]


def _scalar_min(a: float, b: float, su: float, sw: float, open_loop: bool) -> float:
    """min tr(Sigma^-1) for n = m = 1 by brute force over (q, c), q = Sigma_uu, c = Sigma_xu.

    Closed loop: p = (2abc + b^2 q + sw) / (1 - a^2), need p q > c^2.
    Open loop: s = (2abc + b^2 q) / (1 - a^2) with s q >= c^2, p = s + sw / (1 - a^2).
    """

    def value(q, c):  # vectorised over arrays q, c
        s = (2 * a * b * c + b * b * q) / (1 - a * a)
        p = s + sw / (1 - a * a)
        det = p * q - c * c
        ok = (det > 0) & (p > 0) & (q > 0) & (q <= su)
        if open_loop:
            ok &= s * q >= c * c
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(ok, (p + q) / det, np.inf)

    span = 20 * np.sqrt(su * (su + sw))
    q, c = np.meshgrid(np.linspace(su / 200, su, 200), np.linspace(-span, span, 4001), indexing="ij")
    vals = value(q, c)
    i = np.unravel_index(np.argmin(vals), vals.shape)
    res = scipy.optimize.minimize(
        lambda z: float(value(np.asarray(z[0]), np.asarray(z[1]))),
        [q[i], c[i]],
        method="Nelder-Mead",
        options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 5000},
    )
    return float(min(vals[i], res.fun))


def _robust(A: Any, B: Any, *, kind: str = "closed_loop", design: Any = None, **threat: Any) -> Any:
    """robust_security_design on the value objects built from the plant and threat values."""
    return robust_security_design(Plant(A, B), ThreatModel(**threat), kind=kind, design=design)


@pytest.mark.parametrize("a,b,su,sw", SCALAR_CASES)
def test_scalar_against_brute_force(a: float, b: float, su: float, sw: float) -> None:
    A, B = np.array([[a]]), np.array([[b]])
    cl = optimal_attack_design(A, B, sigma_u2=su, sigma_w2=sw)
    ol = optimal_attack_design(A, B, sigma_u2=su, sigma_w2=sw, feedback=False)
    assert cl.trace_inv == pytest.approx(_scalar_min(a, b, su, sw, open_loop=False), rel=1e-6)
    assert ol.trace_inv == pytest.approx(_scalar_min(a, b, su, sw, open_loop=True), rel=1e-6)
    # the input budget is used fully
    assert cl.Sigma[1, 1] == pytest.approx(su, rel=1e-6)


def test_gaussian_closed_form_scaled_identity() -> None:
    a, b, n = np.sqrt(0.5), 0.5, 4
    g = gaussian_attack_design(a * np.eye(n), b * np.eye(n), sigma_u2=10, sigma_w2=0.1)
    # Sigma_xx = 10 * 0.5 + 0.1 * 2 = 5.2 per channel, Sigma_uu = 10
    np.testing.assert_allclose(np.diag(g.Sigma), [5.2] * 4 + [10.0] * 4)
    assert g.trace_inv == pytest.approx(4 / 5.2 + 4 / 10)
    assert g.gamma(101) == pytest.approx(0.1 * g.trace_inv / (8 * 100))
    # sharper than eq:sic2 by tr(Sigma^-1) tr(Sigma) / (n+m)^2 (AM-HM)
    ratio = g.trace_inv * np.trace(g.Sigma) / 64
    assert ratio > 1
    assert g.gamma(101) == pytest.approx(ratio * sic_asymptotic_from_traces(101, 2, 8, 4, 4, 100))


def _stable_system(seed: int, n: int, m: int, rho: float) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    A *= rho / max(np.abs(np.linalg.eigvals(A)).max(), 1e-9)
    return A, rng.standard_normal((n, m))


@settings(max_examples=12, deadline=None, derandomize=True)
@given(
    st.integers(0, 10**6),
    st.integers(1, 3),
    st.integers(1, 2),
    st.floats(0.05, 0.95),
    st.floats(0.05, 20.0),
    st.floats(0.05, 20.0),
)
def test_ordering_constraints_and_policy(seed: int, n: int, m: int, rho: float, su: float, sw: float) -> None:
    A, B = _stable_system(seed, n, m, rho)
    cl = optimal_attack_design(A, B, sigma_u2=su, sigma_w2=sw)
    ol = optimal_attack_design(A, B, sigma_u2=su, sigma_w2=sw, feedback=False)
    ga = gaussian_attack_design(A, B, sigma_u2=su, sigma_w2=sw)
    tol = 1e-6
    assert cl.trace_inv <= ol.trace_inv * (1 + tol)
    assert ol.trace_inv <= ga.trace_inv * (1 + tol)
    assert cl.gamma(50) <= ga.gamma(50) * (1 + tol)
    G = np.hstack([A, B])
    for d in (cl, ol, ga):
        S = d.Sigma
        scale = np.abs(S).max()
        assert np.allclose(S, S.T)
        assert np.linalg.eigvalsh(S).min() > 0
        np.testing.assert_allclose(S[:n, :n], G @ S @ G.T + sw * np.eye(n), atol=1e-6 * scale)
        assert np.trace(S[n:, n:]) <= m * su * (1 + 1e-6)
        assert d.trace_inv == pytest.approx(np.trace(np.linalg.inv(S)), rel=1e-9)
        assert np.linalg.eigvalsh(d.V).min() >= 0
    # closed loop: x+ = (A + B K) x + B v + w has stationary covariance Sigma_xx
    Acl = A + B @ cl.K
    assert np.abs(np.linalg.eigvals(Acl)).max() < 1
    Sxx = scipy.linalg.solve_discrete_lyapunov(Acl, B @ cl.V @ B.T + sw * np.eye(n))
    scale = np.abs(cl.Sigma).max()
    np.testing.assert_allclose(Sxx, cl.Sigma[:n, :n], atol=1e-5 * scale)
    np.testing.assert_allclose(cl.K @ Sxx, cl.Sigma[n:, :n], atol=1e-5 * scale)
    np.testing.assert_allclose(cl.K @ Sxx @ cl.K.T + cl.V, cl.Sigma[n:, n:], atol=1e-5 * scale)
    # open loop: the input-driven part M = Sigma - blkdiag(sw Psi_w, 0) is PSD, stationary and
    # generated by u = K x_u + v: S_u = (A + B K) S_u (A + B K)^T + B V B^T
    Su = ol.input_state_cov
    M = ol.Sigma.copy()
    M[:n, :n] -= sw * noise_gramian(A)
    np.testing.assert_allclose(M[:n, :n], Su, atol=1e-6 * scale)
    assert np.linalg.eigvalsh(M).min() > -1e-6 * scale
    Aol = A + B @ ol.K
    np.testing.assert_allclose(Aol @ Su @ Aol.T + B @ ol.V @ B.T, Su, atol=1e-5 * np.abs(ol.Sigma).max())


def test_paper_example_values() -> None:
    A, B = np.sqrt(0.5) * np.eye(4), 0.5 * np.eye(4)
    cl = optimal_attack_design(A, B, sigma_u2=10, sigma_w2=0.1)

    # decoupled channels: each is the scalar problem a = sqrt(1/2), b = 1/2, q = 10:
    # p = sqrt(2) c + 5.2, minimise (p + 10) / (10 p - c^2) over c.
    def f(c):
        return (np.sqrt(2) * c + 15.2) / (10 * (np.sqrt(2) * c + 5.2) - c * c)

    res = scipy.optimize.minimize_scalar(f, bounds=(0, 10), method="bounded", options={"xatol": 1e-12})
    assert cl.trace_inv == pytest.approx(4 * res.fun, rel=1e-7)
    np.testing.assert_allclose(cl.K, res.x / (np.sqrt(2) * res.x + 5.2) * np.eye(4), atol=1e-5)
    ratio = cl.gamma(13159) / sic_asymptotic_from_traces(13159, 2, 8, 4, 4, 100)
    assert 0.5 < ratio < 1  # the best attacker beats the paper's (Jensen) bound here


def test_monte_carlo_matches_gamma_opt() -> None:
    # The closed-loop policy u = K x + v, simulated and identified by least squares, reaches
    # gamma_opt(N) asymptotically; i.i.d. Gaussian inputs reach the Gaussian gamma.
    A, B = np.array([[0.6, 0.3], [0.0, -0.5]]), np.array([[1.0], [0.4]])
    n, m = B.shape
    su, sw, N, runs = 2.0, 0.5, 400, 600
    rng = np.random.default_rng(42)
    for d in (optimal_attack_design(A, B, sigma_u2=su, sigma_w2=sw), gaussian_attack_design(A, B, sigma_u2=su, sigma_w2=sw)):
        Lv = np.linalg.cholesky(d.V + 1e-15 * np.eye(m))
        Lx = np.linalg.cholesky(d.Sigma[:n, :n])
        x = np.empty((runs, N, n))
        u = np.empty((runs, N, m))
        x[:, 0] = rng.standard_normal((runs, n)) @ Lx.T  # stationary start
        for t in range(N):
            u[:, t] = x[:, t] @ d.K.T + rng.standard_normal((runs, m)) @ Lv.T
            if t + 1 < N:
                x[:, t + 1] = x[:, t] @ A.T + u[:, t] @ B.T + np.sqrt(sw) * rng.standard_normal((runs, n))
        D = np.concatenate([x[:, :-1], u[:, :-1]], axis=2)
        theta = np.linalg.solve(D.transpose(0, 2, 1) @ D, D.transpose(0, 2, 1) @ x[:, 1:]).transpose(0, 2, 1)
        err = (np.sum((theta[:, :, :n] - A) ** 2, axis=(1, 2)) + np.sum((theta[:, :, n:] - B) ** 2, axis=(1, 2))) / (n * (n + m))
        assert err.mean() == pytest.approx(d.gamma(N), rel=0.1)


def test_robust_design_paper_example() -> None:
    A, B = np.sqrt(0.5) * np.eye(4), 0.5 * np.eye(4)
    kw = dict(sigma_u2=10, sigma_w2=0.1, gamma_c=1e-6, tau_c=31536e4, upsilon=442e15)
    cl = _robust(A, B, **kw)
    ga = _robust(A, B, kind="gaussian", **kw)
    paper = paper_design_example()
    d = optimal_attack_design(A, B, sigma_u2=10, sigma_w2=0.1)
    assert cl.N_star == sample_size_for_rate(d.rate, 1e-6)
    assert cl.gamma_at_N_star < 1e-6 <= cl.gamma_before_N_star
    assert cl.N_star < paper.N_star < ga.N_star
    assert cl.method == "closed_loop" and ga.method == "gaussian"
    assert cl.lam_star >= paper.lam_star - 1 and cl.k_star == 712


def test_gamma_opt_and_errors() -> None:
    A, B = np.array([[0.5]]), np.array([[1.0]])
    d = optimal_attack_design(A, B, sigma_u2=1, sigma_w2=1)
    np.testing.assert_allclose(gamma_opt([2, 11], A, B, sigma_u2=1, sigma_w2=1), d.gamma(np.array([2, 11])), rtol=1e-6)
    assert d.gamma(np.array([2, 11])).shape == (2,)
    with pytest.raises(ParameterError, match="N"):
        d.gamma(1)
    with pytest.raises(UnstableSystemError, match="spectral radius"):
        optimal_attack_design(np.array([[1.1]]), B, sigma_u2=1, sigma_w2=1)
    with pytest.raises(ParameterError, match="sigma_u2"):
        optimal_attack_design(A, B, sigma_u2=0, sigma_w2=1)
    with pytest.raises(SolverError, match="NOSUCHSOLVER"):
        optimal_attack_design(A, B, sigma_u2=1, sigma_w2=1, solver="NOSUCHSOLVER")
    with pytest.raises(ParameterError, match="kind"):
        _robust(A, B, sigma_u2=1, sigma_w2=1, gamma_c=0.1, tau_c=1, upsilon=1, kind="psychic")
    with pytest.raises(ParameterError, match="gaussian"):
        _robust(
            A,
            B,
            sigma_u2=1,
            sigma_w2=1,
            gamma_c=0.1,
            tau_c=1,
            upsilon=1,
            design=gaussian_attack_design(A, B, sigma_u2=1, sigma_w2=1),
        )


def test_scs_fallback_solver_agrees() -> None:
    A, B = _stable_system(3, 2, 1, 0.8)
    a = optimal_attack_design(A, B, sigma_u2=1, sigma_w2=1, solver="CLARABEL")
    s = optimal_attack_design(A, B, sigma_u2=1, sigma_w2=1, solver="SCS")
    assert s.trace_inv == pytest.approx(a.trace_inv, rel=1e-5)


def test_feedback_can_beat_open_loop_slightly() -> None:
    # Found by a random search: the closed-loop optimum lies outside the open-loop set, and both
    # Clarabel and SCS give a relative gap of 8.2e-6. Under an input-power budget feedback buys
    # almost nothing (largest gap seen over 60 random systems), but the sets do differ.
    A = np.array([[-0.0682, -0.1796, 0.1572], [-0.0856, 0.1309, 0.1214], [0.0213, -0.0445, 0.0103]])
    B = np.array([[0.0612], [0.0007], [0.1249]])
    cl = optimal_attack_design(A, B, sigma_u2=1.2686, sigma_w2=1.0)
    ol = optimal_attack_design(A, B, sigma_u2=1.2686, sigma_w2=1.0, feedback=False)
    gap = (ol.trace_inv - cl.trace_inv) / cl.trace_inv
    assert 4e-6 < gap < 2e-5
    M = cl.Sigma.copy()
    M[:3, :3] -= noise_gramian(A)
    assert np.linalg.eigvalsh(M).min() < -1e-5  # not realisable without feedback (min eig about -4e-5)


# --------------------------------------------------------------------------- hardening (bad input gets a clear error)
@pytest.mark.parametrize("bad", ["no", "False", 0, 1, None, [True], np.array([True])])
def test_feedback_must_be_a_bool(bad: object) -> None:
    A, B = np.array([[0.5]]), np.array([[1.0]])
    with pytest.raises(ParameterError, match="feedback must be True or False") as info:
        optimal_attack_design(A, B, sigma_u2=1, sigma_w2=1, feedback=bad)
    assert format_value(bad) in str(info.value)
    with pytest.raises(ParameterError, match="feedback"):
        gamma_opt(5, A, B, sigma_u2=1, sigma_w2=1, feedback=bad)
    assert optimal_attack_design(A, B, sigma_u2=1, sigma_w2=1, feedback=np.bool_(False)).kind == "open_loop"


def test_robust_design_refuses_a_design_made_for_other_values() -> None:
    A, B = np.array([[0.5, 0.1], [0.0, 0.3]]), np.array([[1.0], [0.5]])
    kw = dict(gamma_c=1e-3, tau_c=1e6, upsilon=1e12)
    for kind, feedback in (("closed_loop", True), ("open_loop", False)):
        made = optimal_attack_design(A, B, sigma_u2=1, sigma_w2=1, feedback=feedback)
        assert _robust(A, B, sigma_u2=1, sigma_w2=1, kind=kind, design=made, **kw).method == kind
        with pytest.raises(ParameterError, match="sigma_u2 = 1.0, not sigma_u2 = 2.0"):
            _robust(A, B, sigma_u2=2, sigma_w2=1, kind=kind, design=made, **kw)
        with pytest.raises(ParameterError, match="sigma_w2"):
            _robust(A, B, sigma_u2=1, sigma_w2=0.5, kind=kind, design=made, **kw)
        with pytest.raises(ParameterError, match="does not fit this plant"):
            _robust(0.5 * A, B, sigma_u2=1, sigma_w2=1, kind=kind, design=made, **kw)
    g = gaussian_attack_design(A, B, sigma_u2=1, sigma_w2=1)
    with pytest.raises(ParameterError, match="does not fit this plant"):
        _robust(A, 2 * B, sigma_u2=1, sigma_w2=1, kind="gaussian", design=g, **kw)
    with pytest.raises(ParameterError, match="AttackDesign"):
        _robust(A, B, sigma_u2=1, sigma_w2=1, kind="gaussian", design="gaussian", **kw)


def test_large_sdp_refused_before_solving_with_an_estimate() -> None:
    # n + m = 60 > 48: refused at once (the solve would take about a minute and 3 GB)
    n = m = 30
    A, B = 0.5 * np.eye(n), np.ones((n, m)) / n
    with pytest.raises(ResourceLimitError, match="n \\+ m = 60") as info:
        optimal_attack_design(A, B, sigma_u2=1, sigma_w2=1)
    secs, gb = sdp_estimate(60)
    assert f"{secs:.3g} s" in str(info.value) and f"{gb:.3g} GB" in str(info.value)
    assert secs > sdp_estimate(56)[0] and sdp_estimate(56) == (40.0, 1.6)
    with pytest.raises(ParameterError, match="max_dimension"):
        optimal_attack_design(A, B, sigma_u2=1, sigma_w2=1, max_dimension=1)
    # the closed-form Gaussian design has no such limit
    assert gaussian_attack_design(A, B, sigma_u2=1, sigma_w2=1).Sigma.shape == (60, 60)


@pytest.mark.parametrize(
    "bad,match",
    [(10**400, "<= 9007199254740992, got <integer of 1329 bits"), (2**53 + 1, "<= 9007199254740992"), (1, ">= 2"), ("a", "'a'")],
)
def test_sdp_estimate_is_bounded(bad: object, match: str) -> None:
    with pytest.raises(ParameterError, match=f"^dimension must be .*{match}"):
        sdp_estimate(bad)  # type: ignore[arg-type]


def test_sdp_estimate_by_hand() -> None:
    # 40 s (p / 56)^4.75 and 1.6 GB (p / 56)^4: at p = 112 that is 40 * 2^4.75 s and 1.6 * 16 GB
    seconds, gb = sdp_estimate(112)
    assert seconds == pytest.approx(40 * 2**4.75) and gb == pytest.approx(25.6)
    assert all(math.isfinite(v) for v in sdp_estimate(2**53))
