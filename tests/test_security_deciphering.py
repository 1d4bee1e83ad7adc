"""Tests of encctl_gym.security.deciphering (Definition def:sdt, Remark after def:security, prop:vulnerability)."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym._validation import format_value
from encctl_gym.errors import ModelRangeError, ParameterError
from encctl_gym.security.deciphering import (
    KeyBreakCost,
    break_cost,
    exact_number,
    keys_to_break,
    max_affordable_samples,
    per_sample_cost,
    sample_deciphering_time,
    sample_deciphering_time_exact,
)


def test_definition_values() -> None:
    assert sample_deciphering_time(3, 10, 1024.0) == 3.0
    assert sample_deciphering_time(13159, 74, 442e15) == pytest.approx(2.0**74 * 13159 / 442e15, rel=1e-15)
    assert per_sample_cost(10, 512) == 2.0
    assert sample_deciphering_time_exact(5, 3, 0.5) == Fraction(80)
    np.testing.assert_allclose(sample_deciphering_time([1, 2, 4], 3, 2.0), [4.0, 8.0, 16.0])
    # real lam
    assert sample_deciphering_time(2, 1.5, 1.0) == pytest.approx(2 * 2**1.5)


@pytest.mark.parametrize(
    "scheme,adversary,independent",
    [
        ("modified", "eavesdropper", True),
        ("modified", "server", True),
        ("token", "eavesdropper", True),
        ("token", "server", False),  # prop:vulnerability
        ("static", "eavesdropper", False),  # Remark after def:security
        ("static", "server", False),
    ],
)
def test_schemes(scheme: str, adversary: str, independent: bool) -> None:
    N = np.array([1, 10, 1000])
    t = sample_deciphering_time(N, 20, 1e3, scheme=scheme, adversary=adversary)
    t1 = sample_deciphering_time(1, 20, 1e3)
    np.testing.assert_allclose(t, t1 * (N if independent else np.ones(3)))
    assert keys_to_break(7, scheme, adversary) == (7 if independent else 1)
    budget = max_affordable_samples(5 * t1 + 1e-9, 20, 1e3, scheme=scheme, adversary=adversary)
    assert budget == (5 if independent else math.inf)
    assert max_affordable_samples(0.5 * t1, 20, 1e3, scheme=scheme, adversary=adversary) == 0


def test_max_affordable_is_exact_at_ties() -> None:
    # Upsilon tau_c / 2^lam = 7 exactly: N = 7 is affordable (tau <= tau_c), N = 8 is not.
    assert max_affordable_samples(7, 10, 1024) == 7
    assert sample_deciphering_time_exact(7, 10, 1024) == 7
    assert max_affordable_samples(0.1, 1, 20) == 1  # 0.1 read as 1/10: 20 * 0.1 / 2 = 1 exactly
    # paper numbers: floor(442e15 * 31536e4 / 2^74)
    assert max_affordable_samples(31536e4, 74, 442e15) == (442 * 10**15 * 31536 * 10**4) // 2**74
    # real lam agrees with the integer computation away from ties
    assert max_affordable_samples(31536e4, 74.0, 442e15) == max_affordable_samples(31536e4, 74, 442e15)
    assert max_affordable_samples(1000, 0.5, 1.0) == math.floor(1000 / 2**0.5)


def test_huge_lambda() -> None:
    assert sample_deciphering_time(1, 2048, 1.0) == math.inf
    assert max_affordable_samples(1e9, 2048, 1e18) == 0
    assert sample_deciphering_time_exact(1, 2048, 1) == 2**2048


@pytest.mark.parametrize("lam", [10**12, 1e12, 2.0**53, 2049, 5000, 2048.5])
def test_lambda_above_the_bound_is_refused_not_computed(lam: object) -> None:
    # 2**lam as an exact integer for lam = 1e12 would take 125 GB: refused before it is formed
    for call in (
        lambda: max_affordable_samples(1.0, lam, 1.0),
        lambda: sample_deciphering_time(3, lam, 1.0),
        lambda: per_sample_cost(lam, 1.0),
    ):
        with pytest.raises(ModelRangeError, match="2048") as info:
            call()
        assert format_value(lam) in str(info.value)


def test_exact_number_reads_decimal() -> None:
    assert exact_number("x", 1e-6) == Fraction(1, 10**6)
    assert exact_number("x", 442e15) == 442 * 10**15
    with pytest.raises(ParameterError, match="x"):
        exact_number("x", -1.0)


@pytest.mark.parametrize("kwargs,match", [({"scheme": "rotating"}, "rotating"), ({"adversary": "alice"}, "alice")])
def test_unknown_names(kwargs: dict, match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        sample_deciphering_time(2, 10, 1.0, **kwargs)
    with pytest.raises(ParameterError, match=match):
        max_affordable_samples(1.0, 10, 1.0, **kwargs)


def test_bad_values() -> None:
    with pytest.raises(ParameterError, match="lam"):
        sample_deciphering_time(2, 0, 1.0)
    with pytest.raises(ParameterError, match="lam"):
        sample_deciphering_time(2, -1.5, 1.0)
    with pytest.raises(ParameterError, match="upsilon"):
        sample_deciphering_time(2, 10, 0.0)
    with pytest.raises(ParameterError, match="N"):
        sample_deciphering_time(-1, 10, 1.0)
    with pytest.raises(ParameterError, match="N"):
        sample_deciphering_time([0, -2], 10, 1.0)
    with pytest.raises(ParameterError, match="N"):
        sample_deciphering_time([1, 2.5], 10, 1.0)
    with pytest.raises(ParameterError, match="tau_c"):
        max_affordable_samples(float("nan"), 10, 1.0)
    with pytest.raises(ParameterError, match="lam"):
        sample_deciphering_time_exact(2, 1.5, 1.0)


# --------------------------------------------------------------------------- under a cost model (the environment's API)
def test_zero_samples_cost_nothing() -> None:
    assert sample_deciphering_time(0, 10, 1.0) == 0.0
    assert keys_to_break(0, "static") == 0
    np.testing.assert_array_equal(sample_deciphering_time([0, 1, 2], 3, 1.0, scheme="static"), [0.0, 8.0, 8.0])


def test_paper_cost_is_the_security_parameter_exactly() -> None:
    cost = break_cost("paper", security_parameter=74)
    assert cost.first == cost.next == 2**74
    for N in (1, 7379, 7380, 13159):
        assert sample_deciphering_time_exact(N, cost, 442e15) == sample_deciphering_time_exact(N, 74, 442e15)
    assert max_affordable_samples(31536e4, cost, 442e15) == max_affordable_samples(31536e4, 74, 442e15) == 7379


def test_precomputation_first_sample_carries_the_precomputation() -> None:
    cost = break_cost("precomputation", key_length=712)
    ups = 442e15
    t = sample_deciphering_time(np.arange(6), cost, ups)
    assert t[0] == 0.0
    assert t[1] == pytest.approx(float(cost.first) / ups, rel=1e-15)
    np.testing.assert_allclose(np.diff(t[1:]), float(cost.next) / ups, rtol=1e-9)
    assert cost.first == cost.precomputation + cost.next  # the first key: precomputation and its own descent
    # scalar and array agree; the exact time is tau(N) = (C_pre + N C_key) / Upsilon
    for N in (1, 2, 5):
        exact = (cost.precomputation + N * cost.next) / Fraction(442 * 10**15)
        assert sample_deciphering_time_exact(N, cost, ups) == exact
        assert t[N] == pytest.approx(float(exact), rel=1e-12)


@settings(max_examples=60, deadline=None)
@given(
    st.integers(1, 10**6),
    st.integers(1, 10**4),
    st.integers(1, 10**7),
    st.integers(1, 10**5),
    st.sampled_from([("modified", "eavesdropper"), ("token", "server"), ("static", "eavesdropper")]),
)
def test_max_affordable_samples_is_the_largest_affordable_N(first_extra: int, nxt: int, tau: int, ups: int, sa) -> None:
    # an arbitrary first/next cost: the answer is the largest N with W(N) <= Upsilon tau_c, checked
    # against the definition on both sides
    cost = KeyBreakCost("test", Fraction(nxt + first_extra), Fraction(nxt))
    scheme, adversary = sa
    n_max = max_affordable_samples(tau, cost, ups, scheme=scheme, adversary=adversary)
    budget = Fraction(tau) * ups

    def affordable(N: int) -> bool:
        return sample_deciphering_time_exact(N, cost, ups, scheme=scheme, adversary=adversary) <= tau

    if n_max == math.inf:
        assert affordable(1) and affordable(10**9)
    else:
        assert (n_max == 0 or affordable(n_max)) and not affordable(n_max + 1)
        assert n_max == (0 if cost.first > budget else 1 + (budget - cost.first) // cost.next)


def test_break_cost_arguments() -> None:
    with pytest.raises(ParameterError, match="exactly one"):
        break_cost("paper")
    with pytest.raises(ParameterError, match="exactly one"):
        break_cost("paper", key_length=712, security_parameter=74)
    with pytest.raises(ParameterError, match="generic"):
        break_cost("generic", security_parameter=74)
    with pytest.raises(ParameterError, match="'quantum'"):
        break_cost("quantum", key_length=712)
    with pytest.raises(ModelRangeError, match="39"):
        break_cost("precomputation", key_length=39)
