"""Tests of encctl_gym.security.design (def:security, thm:opt_sec, eq:opt_key)."""

from __future__ import annotations

import math
import re
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym._validation import format_value
from encctl_gym.errors import ModelRangeError, ParameterError
from encctl_gym.plant import Plant
from encctl_gym.security.complexity import sic_asymptotic_from_traces, sic_from_traces
from encctl_gym.security.deciphering import sample_deciphering_time_exact
from encctl_gym.security.design import (
    PAPER_EXAMPLE,
    bit_security_of_key_length,
    design_for_sample_size,
    design_from_traces,
    design_security_parameter,
    exact_optimal_sample_size,
    exact_sic_asymptotic_function,
    exact_sic_function,
    gnfs_complexity,
    gnfs_log2_complexity,
    is_secure,
    minimum_key_length,
    minimum_sample_size,
    optimal_sample_size,
    optimal_security_parameter,
    paper_design_example,
    sample_size_for_rate,
)
from encctl_gym.security.threat import ThreatModel

EX = PAPER_EXAMPLE


def test_paper_design_example() -> None:
    d = paper_design_example()
    assert (d.N_star, d.lam_star, d.k_star) == (13159, 74, 712)
    assert d.r_sigma == pytest.approx(100)
    assert d.gamma_at_N_star < 1e-6 <= d.gamma_before_N_star
    assert d.bit_security >= 74
    # the same from the plant matrices A = sqrt(1/2) I, B = 0.5 I
    threat = ThreatModel(sigma_u2=10, sigma_w2=0.1, gamma_c=1e-6, tau_c=31536e4, upsilon=442e15)
    d2 = design_security_parameter(Plant(np.sqrt(0.5) * np.eye(4), 0.5 * np.eye(4)), threat)
    assert design_security_parameter((np.sqrt(0.5) * np.eye(4), 0.5 * np.eye(4)), threat) == d2  # a pair works too
    assert (d2.N_star, d2.lam_star, d2.k_star) == (13159, 74, 712)
    assert d2.tr_psi_w == pytest.approx(8) and d2.tr_psi_u == pytest.approx(2)


def test_paper_example_exact_sic_agrees() -> None:
    d = paper_design_example("exact")
    assert (d.N_star, d.lam_star, d.k_star) == (13159, 74, 712)
    # independent computation of the threshold: x = 8 / (1e-6 * 608), delta = 1 * 8 / (0.1 * 608)
    x, delta = 8e6 / 608, 8 / 60.8
    assert math.floor(x - delta) + 2 == 13159


def test_formula_by_hand() -> None:
    # N* = floor((m+n) / (gamma_c K)) + 2, lam* = floor(log2(Upsilon tau_c / N*)) + 1
    N = optimal_sample_size(2, 8, 4, 4, r_sigma=100, gamma_c=1e-6)
    assert N == math.floor(8 / (1e-6 * 608)) + 2 == 13159
    assert optimal_security_parameter(N, tau_c=31536e4, upsilon=442e15) == math.floor(math.log2(442e15 * 31536e4 / N)) + 1


def test_integer_ratio_edge_cases() -> None:
    # (m+n)/(gamma_c K) = 2/(0.25 * 2) = 4 exactly: N - 1 > 4 needs N = 6 = floor(4) + 2.
    gamma = exact_sic_asymptotic_function(0, 1, 1, 1, r_sigma=1)  # K = 1*(0+1) + 1 = 2
    assert gamma(5) == Fraction(1, 4)  # = gamma_c, not below
    assert optimal_sample_size(0, 1, 1, 1, r_sigma=1, gamma_c=0.25) == 6
    assert minimum_sample_size(gamma, 0.25) == 6
    # Upsilon tau_c / N* = 2^10 exactly: 2^10 N* = Upsilon tau_c is not > tau_c, so lam* = 11.
    assert optimal_security_parameter(6, tau_c=1024, upsilon=6) == 11
    assert sample_deciphering_time_exact(6, 11, 6) > 1024 >= sample_deciphering_time_exact(6, 10, 6)
    # below 1: lam* clipped at 1
    assert optimal_security_parameter(10, tau_c=1, upsilon=1) == 1
    # decimal reading: 0.1 is 1/10, so floor(1 / 0.1) + 2 = 12, not 11
    assert sample_size_for_rate(1, 0.1) == 12


def test_exact_closed_form_matches_search() -> None:
    rng = np.random.default_rng(11)
    for _ in range(50):
        m, n = int(rng.integers(1, 5)), int(rng.integers(1, 5))
        tr_u, tr_w = float(rng.uniform(0, 5)), float(n * rng.uniform(1, 4))
        su, sw, sx = (float(10 ** rng.uniform(-2, 2)) for _ in range(3))
        g_c = float(10 ** rng.uniform(-5, 0))
        N = exact_optimal_sample_size(tr_u, tr_w, m, n, sigma_u2=su, sigma_w2=sw, sigma_x2=sx, gamma_c=g_c)
        f = exact_sic_function(tr_u, tr_w, m, n, sigma_u2=su, sigma_w2=sw, sigma_x2=sx)
        assert N == minimum_sample_size(f, g_c)
        assert sic_from_traces(N, tr_u, tr_w, m, n, su, sw, sx) < g_c
        if N > 2:
            assert sic_from_traces(N - 1, tr_u, tr_w, m, n, su, sw, sx) >= g_c * (1 - 1e-12)
        # eq:sic <= eq:sic2, so the exact N* is never larger
        assert N <= optimal_sample_size(tr_u, tr_w, m, n, r_sigma=su / sw, gamma_c=g_c)
        N2 = optimal_sample_size(tr_u, tr_w, m, n, r_sigma=su / sw, gamma_c=g_c)
        assert N2 == minimum_sample_size(exact_sic_asymptotic_function(tr_u, tr_w, m, n, r_sigma=su / sw), g_c)
        assert sic_asymptotic_from_traces(N2, tr_u, tr_w, m, n, su / sw) < g_c


def test_exact_and_asymptotic_can_differ() -> None:
    # x = (m+n)/(gamma_c K) with frac(x) < delta = sigma_x2 tr_w / (sigma_w2 K): N* differs by one.
    # m = n = 1, tr_u = 0, tr_w = 1, R = 1: K = 2, x = 1/gamma_c; gamma_c = 1/10.05 -> x = 10.05
    # delta = sigma_x2 / (sigma_w2 * 2) = 0.5 with sigma_w2 = sigma_u2 = 1, sigma_x2 = 1.
    kw = dict(sigma_u2=1, sigma_w2=1, sigma_x2=1, gamma_c=Fraction(20, 201), tau_c=1, upsilon=2**40)
    a = design_from_traces(0, 1, 1, 1, method="asymptotic", **kw)
    e = design_from_traces(0, 1, 1, 1, method="exact", **kw)
    assert (a.N_star, e.N_star) == (12, 11)


def test_is_secure_against_brute_force() -> None:
    # Definition def:security literally: search every N in a small range.
    rng = np.random.default_rng(5)
    outcomes = []
    for _ in range(40):
        g = exact_sic_asymptotic_function(
            float(rng.uniform(0, 3)), float(rng.uniform(1, 4)), 1, 2, r_sigma=float(rng.uniform(0.1, 10))
        )
        g_c = float(rng.uniform(0.001, 0.2))
        lam = int(rng.integers(1, 8))
        ups, tau = float(rng.uniform(1, 50)), float(rng.uniform(1, 50))
        brute = not any(
            g(N) < Fraction(repr(g_c)) and sample_deciphering_time_exact(N, lam, ups) <= Fraction(repr(tau))
            for N in range(2, 1300)  # N_max <= 50 * 50 / 2 = 1250
        )
        assert is_secure(lam, gamma=g, gamma_c=g_c, tau_c=tau, upsilon=ups) == brute
        outcomes.append(brute)
    assert 0 < sum(outcomes) < len(outcomes)  # both verdicts occur


def test_is_secure_consistent_with_theorem() -> None:
    d = paper_design_example()
    g = exact_sic_asymptotic_function(2, 8, 4, 4, r_sigma=100)
    kw = dict(gamma=g, gamma_c=1e-6, tau_c=31536e4, upsilon=442e15)
    assert is_secure(d.lam_star, **kw)
    assert not is_secure(d.lam_star - 1, **kw)
    assert is_secure(d.lam_star + 10, **kw)
    # float-valued gamma works too
    assert is_secure(
        74, gamma=lambda N: sic_asymptotic_from_traces(N, 2, 8, 4, 4, 100), gamma_c=1e-6, tau_c=31536e4, upsilon=442e15
    )
    # a static key or a token leaked to the server: one break suffices, never secure at 74 bits
    assert not is_secure(74, scheme="static", **kw)
    assert not is_secure(74, scheme="token", adversary="server", **kw)
    assert is_secure(74, scheme="token", adversary="eavesdropper", **kw)
    # static key of 100 bits: 2^100 / Upsilon > tau_c, nothing breakable
    assert is_secure(100, scheme="static", **kw)


@settings(max_examples=40, deadline=None)
@given(
    st.floats(0, 10),
    st.floats(1, 20),
    st.integers(1, 5),
    st.integers(1, 5),
    st.floats(0.01, 100),
    st.floats(1e-7, 1e-2),
    st.floats(1, 1e9),
    st.floats(1e3, 1e18),
)
def test_theorem_is_minimal(tr_u, tr_w, m, n, r, g_c, tau, ups) -> None:
    N = optimal_sample_size(tr_u, tr_w, m, n, r_sigma=r, gamma_c=g_c)
    lam = optimal_security_parameter(N, tau_c=tau, upsilon=ups)
    g = exact_sic_asymptotic_function(tr_u, tr_w, m, n, r_sigma=r)
    assert is_secure(lam, gamma=g, gamma_c=g_c, tau_c=tau, upsilon=ups)
    if lam > 1:
        assert not is_secure(lam - 1, gamma=g, gamma_c=g_c, tau_c=tau, upsilon=ups)


def test_gnfs() -> None:
    ks = np.arange(40, 4000)
    bits = gnfs_log2_complexity(ks)
    assert np.all(np.diff(bits) > 0)  # Omega monotone
    # independent evaluation of the paper's formula
    k = 712
    omega = math.exp((64 / 9) ** (1 / 3) * math.log(2**k) ** (1 / 3) * math.log(math.log(2**k)) ** (2 / 3))
    assert gnfs_complexity(k) == pytest.approx(omega, rel=1e-12)
    assert bit_security_of_key_length(k) == pytest.approx(math.log2(omega), rel=1e-13)
    assert gnfs_log2_complexity(711) < 74 <= gnfs_log2_complexity(712)
    assert minimum_key_length(74) == 712
    for lam in (19, 40, 80, 112, 128, 200, 481):
        k = minimum_key_length(lam)
        assert gnfs_log2_complexity(k) >= lam and (k == 40 or gnfs_log2_complexity(k - 1) < lam)
    assert gnfs_complexity(65536) == pytest.approx(2 ** gnfs_log2_complexity(65536), rel=1e-9)


@pytest.mark.parametrize("k", [2, 16, 39, 65537, 10**308])
def test_key_length_outside_the_formula_range(k: int) -> None:
    with pytest.raises(ModelRangeError, match="40 ... 65536") as info:
        gnfs_log2_complexity(k)
    assert format_value(k) in str(info.value)
    with pytest.raises(ModelRangeError):
        bit_security_of_key_length([64, k])


@pytest.mark.parametrize("lam", [1, 10, 18.6, 482])
def test_security_parameter_outside_the_key_length_range(lam: float) -> None:
    with pytest.raises(ModelRangeError, match="lam") as info:
        minimum_key_length(lam)
    assert format_value(lam) in str(info.value)


def test_tiny_defense_period_is_an_error_not_a_two_bit_key() -> None:
    # Upsilon tau_c = 4.4e-283 < N*: thm:opt_sec clips lam* at 1, and eq:opt_key has no key
    # length for 1 bit inside the GNFS range: an error that says so, never k* = 2
    kw = dict(PAPER_EXAMPLE)
    kw["tau_c"] = 1e-300
    with pytest.raises(ModelRangeError, match="lam\\* = 1") as info:
        design_from_traces(kw.pop("tr_psi_u"), kw.pop("tr_psi_w"), kw.pop("m"), kw.pop("n"), **kw)
    assert "1e-300" in str(info.value)
    assert optimal_security_parameter(13159, tau_c=1e-300, upsilon=442e15) == 1


def test_design_for_sample_size_is_the_last_step_of_every_design() -> None:
    d = paper_design_example()
    g = exact_sic_asymptotic_function(2, 8, 4, 4, r_sigma=100)
    threat = ThreatModel(sigma_u2=10, sigma_w2=0.1, sigma_x2=1, gamma_c=1e-6, tau_c=31536e4, upsilon=442e15)
    again = design_for_sample_size("asymptotic", d.N_star, g, threat, m=4, n=4, tr_psi_u=2, tr_psi_w=8)
    assert again == d
    with pytest.raises(ParameterError, match="'magic'"):
        design_for_sample_size("magic", 10, g, threat, m=4, n=4, tr_psi_u=2, tr_psi_w=8)
    with pytest.raises(ParameterError, match="needs gamma_c"):
        design_for_sample_size(
            "asymptotic", 10, g, ThreatModel(sigma_u2=10, sigma_w2=0.1, tau_c=1, upsilon=1), m=4, n=4, tr_psi_u=2, tr_psi_w=8
        )


def test_bad_inputs() -> None:
    with pytest.raises(ParameterError, match="gamma_c"):
        optimal_sample_size(1, 2, 1, 1, r_sigma=1, gamma_c=0)
    with pytest.raises(ParameterError, match="r_sigma"):
        optimal_sample_size(1, 2, 1, 1, r_sigma=-1, gamma_c=0.1)
    with pytest.raises(ParameterError, match="k"):
        gnfs_log2_complexity(1)
    with pytest.raises(ParameterError, match="lam"):
        minimum_key_length(0)
    for big in (10**400, -(10**400)):  # beyond the float range: refused with its size, no OverflowError
        with pytest.raises(ParameterError, match="float64 range") as info:
            design_from_traces(2, 8, 4, 4, sigma_u2=big, sigma_w2=0.1, gamma_c=1e-6, tau_c=1, upsilon=1)
        assert "1329 bits" in str(info.value)
    with pytest.raises(ParameterError, match="upsilon"):
        optimal_security_parameter(10, tau_c=1, upsilon=10**400)
    with pytest.raises(ParameterError, match="method"):
        design_from_traces(1, 2, 1, 1, sigma_u2=1, sigma_w2=1, gamma_c=0.1, tau_c=1, upsilon=1, method="magic")
    with pytest.raises(ParameterError, match="gamma_c"):
        minimum_sample_size(lambda N: 1.0, 0.5, n_max=1000)
    with pytest.raises(ParameterError, match="tau_c"):
        is_secure(10, gamma=lambda N: 1.0, gamma_c=0.1, tau_c=-1, upsilon=1)


# --------------------------------------------------------------------------- the complexity gamma is checked
@pytest.mark.parametrize("bad", ["abc", None, 3])
def test_gamma_must_be_callable(bad: object) -> None:
    with pytest.raises(ParameterError, match=f"gamma must be a callable.*got {re.escape(format_value(bad))}"):
        is_secure(10, gamma=bad, gamma_c=0.1, tau_c=1, upsilon=1)  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match=f"gamma must be a callable.*got {re.escape(format_value(bad))}"):
        minimum_sample_size(bad, 0.1)  # type: ignore[arg-type]


@pytest.mark.parametrize("value,match", [(-1.0, r"gamma\(\d+\) must be >= 0.*-1.0"), (math.nan, "NaN"), ("x", "'x'"), (1j, "1j")])
def test_gamma_values_must_be_real_and_nonnegative(value: object, match: str) -> None:
    # tau(N) = 2^lam N / Upsilon = 2N here, tau_c = 1000: N_max = 500, so is_secure reaches gamma(500)
    with pytest.raises(ParameterError, match=match):
        is_secure(1, gamma=lambda N: value, gamma_c=1e-6, tau_c=1000, upsilon=1)
    with pytest.raises(ParameterError, match=match):
        minimum_sample_size(lambda N: value if N > 2 else 1.0, 1e-3)


def test_a_negative_complexity_is_not_taken_as_below_gamma_c() -> None:
    # -1/N < gamma_c for every N: it used to give N* = 2 (and is_secure said False)
    with pytest.raises(ParameterError, match=r"gamma\(2\) must be >= 0"):
        minimum_sample_size(lambda N: -1.0 / N, 1e-3)


@pytest.mark.parametrize("bad,match", [(-1.0, ">= 0"), (math.nan, "finite"), ("a", "real number")])
def test_gamma_infimum_is_checked_on_every_path(bad: object, match: str) -> None:
    # the modified scheme against an eavesdropper never has N_max = inf, yet the value is checked
    with pytest.raises(ParameterError, match=f"gamma_infimum must be .*{match}"):
        is_secure(74, gamma=lambda N: 1.0 / N, gamma_c=1e-6, tau_c=3.1536e8, upsilon=442e15, gamma_infimum=bad)


def test_n_max_is_checked() -> None:
    with pytest.raises(ParameterError, match="n_max must be an integer, got 'a'"):
        minimum_sample_size(lambda N: 1.0 / N, 1e-3, n_max="a")  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="n_max must be >= 2, got 1"):
        minimum_sample_size(lambda N: 1.0 / N, 1e-3, n_max=1)
    # valid: 1/N < 1e-3 first at N = 1001 (by hand), with the search bounded just above it
    assert minimum_sample_size(lambda N: Fraction(1, N), 1e-3, n_max=1001) == 1001
    assert minimum_sample_size(lambda N: Fraction(1, N), 1e-3, n_max=1025) == 1001
    with pytest.raises(ParameterError, match="up to N = 1000"):
        minimum_sample_size(lambda N: Fraction(1, N), 1e-3, n_max=1000)  # the answer 1001 lies beyond n_max
    with pytest.raises(ParameterError, match="up to N = 5"):
        minimum_sample_size(lambda N: Fraction(1, N), 1e-3, n_min=5, n_max=5)


def test_huge_sample_sizes_in_messages_are_shown_by_size() -> None:
    # str() of an integer over 4300 digits raises ValueError; the messages show its size instead
    with pytest.raises(ParameterError, match="up to N = <integer of 16610 bits, about 5001 digits>"):
        minimum_sample_size(lambda N: 1.0, 0.5, n_max=10**5000)
    # gamma_c = 1e-300 gives N* of 299 digits and lam* = 1, below the GNFS range: one short line
    with pytest.raises(ModelRangeError, match=r"N\* = <integer of 991 bits, about 299 digits>") as info:
        design_from_traces(
            EX["tr_psi_u"],
            EX["tr_psi_w"],
            EX["m"],
            EX["n"],
            sigma_u2=EX["sigma_u2"],
            sigma_w2=EX["sigma_w2"],
            gamma_c=1e-300,
            tau_c=EX["tau_c"],
            upsilon=EX["upsilon"],
        )
    assert "\n" not in str(info.value) and len(str(info.value)) < 600
