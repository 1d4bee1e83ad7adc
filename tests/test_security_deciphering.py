"""Tests of encctl_gym.security.deciphering (Definition def:sdt, Remark after def:security, prop:vulnerability)."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from encctl_gym.errors import ParameterError
from encctl_gym.security.deciphering import (
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
    assert sample_deciphering_time(1, 5000, 1.0) == math.inf
    assert max_affordable_samples(1e9, 5000, 1e18) == 0
    assert sample_deciphering_time_exact(1, 5000, 1) == 2**5000


def test_exact_number_reads_decimal() -> None:
    assert exact_number("x", 1e-6) == Fraction(1, 10**6)
    assert exact_number("x", 442e15) == 442 * 10**15
    with pytest.raises(ParameterError, match="x"):
        exact_number("x", -1.0)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"scheme": "rotating"}, "rotating"),
        ({"adversary": "alice"}, "alice"),
    ],
)
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
        sample_deciphering_time(0, 10, 1.0)
    with pytest.raises(ParameterError, match="N"):
        sample_deciphering_time([1, 2.5], 10, 1.0)
    with pytest.raises(ParameterError, match="tau_c"):
        max_affordable_samples(float("nan"), 10, 1.0)
    with pytest.raises(ParameterError, match="lam"):
        sample_deciphering_time_exact(2, 1.5, 1.0)
