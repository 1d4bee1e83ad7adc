"""The primal uSVP cost model (encctl_gym.security.cost_models.lattice): the root Hermite factor
against an independent evaluation, the block size as the smallest one meeting the condition
(checked by a plain loop written here), and the published estimates of standard parameter sets."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.errors import ModelRangeError, ParameterError
from encctl_gym.security.cost_models import lattice as L


def condition(n: int, q: int, sigma: float, m: int, beta: int) -> bool:
    """ADPS16's GSA condition for sigma_s = sigma_e, written out from the paper."""
    d = m + n + 1
    delta = (
        ((math.pi * beta) ** (1 / beta) * beta / (2 * math.pi * math.e)) ** (1 / (2 * beta - 2))
        if beta >= L.FORMULA_FROM
        else None
    )
    if delta is None:
        delta = L.root_hermite_factor(beta)
    return sigma * math.sqrt(beta) <= delta ** (2 * beta - d - 1) * q ** (m / d)


def test_root_hermite_factor() -> None:
    b = 100
    assert L.root_hermite_factor(b) == pytest.approx(
        ((math.pi * b) ** (1 / b) * b / (2 * math.pi * math.e)) ** (1 / 198), rel=1e-15
    )
    for b, delta in L.GAMA_NGUYEN_DELTA.items():
        assert L.root_hermite_factor(b) == pytest.approx(delta, rel=1e-12)
    values = [L.root_hermite_factor(b) for b in range(2, 400)]
    assert all(x > y for x, y in zip(values, values[1:]))  # stronger reduction, shorter vectors
    with pytest.raises(ParameterError):
        L.root_hermite_factor(1)


@settings(max_examples=15, deadline=None)
@given(n=st.integers(40, 160), logq=st.integers(8, 16), eta=st.integers(1, 4))
def test_block_size_is_the_smallest_meeting_the_condition(n: int, logq: int, eta: int) -> None:
    q = 2**logq + 1
    sigma = math.sqrt(eta / 2)
    p = L.LWEParameterSet("t", n, q, sigma, sigma, n)
    est = L.primal_usvp_estimate(p)
    assert L.primal_usvp_succeeds(p, est.m, est.beta)
    assert condition(n, q, sigma, est.m, est.beta)
    if est.beta > 2:
        assert not any(condition(n, q, sigma, m, est.beta - 1) for m in range(max(1, est.beta - 1 - n - 1), n + 1))
    # more samples never hurt the attacker, a larger n never helps it
    assert L.primal_usvp_estimate(L.LWEParameterSet("t", n, q, sigma, sigma, 2 * n)).beta <= est.beta
    assert L.primal_usvp_estimate(L.LWEParameterSet("t", n + 20, q, sigma, sigma, n + 20)).beta >= est.beta


@pytest.mark.parametrize("name", sorted(L.STANDARD_PARAMETER_SETS))
def test_published_core_svp_estimates_within_two_bits(name: str) -> None:
    p = L.STANDARD_PARAMETER_SETS[name]
    assert p.source
    est = L.primal_usvp_estimate(p)
    for model, bits in p.published.items():
        assert abs(est.bits(model) - bits) <= 2.0, (name, model, est.bits(model), bits)


def test_core_svp_exponents_and_refusals() -> None:
    assert L.CORE_SVP_EXPONENTS["classical"] == pytest.approx(0.2925, abs=5e-4)
    assert L.CORE_SVP_EXPONENTS["quantum"] == pytest.approx(0.2653, abs=5e-4)
    assert L.CORE_SVP_EXPONENTS["plausible"] == pytest.approx(0.2075, abs=5e-4)
    est = L.primal_usvp_estimate(L.STANDARD_PARAMETER_SETS["Kyber-768"])
    with pytest.raises(ParameterError, match="core-SVP model"):
        est.bits("enumeration")
    with pytest.raises(ModelRangeError, match="modelled"):
        L.LWEParameterSet("huge", 8192, 12289, 1.0, 1.0, 8192)
    # an error as wide as q leaves no unique short vector
    with pytest.raises(ModelRangeError, match="no block size"):
        L.primal_usvp_estimate(L.LWEParameterSet("wide", 20, 17, 40.0, 40.0, 20))


def test_smallest_secure_dimension_is_the_first_that_reaches_the_bits() -> None:
    def modulus(n: int) -> int:
        return 3329

    n, est = L.smallest_secure_dimension(modulus, 1.0, 100.0)
    assert est.bits() >= 100.0 and est.parameters.n == n
    below = L.primal_usvp_estimate(L.LWEParameterSet("b", n - 1, 3329, 1.0, 1.0, n - 1))
    assert below.bits() < 100.0
    with pytest.raises(ModelRangeError, match="even n"):
        L.smallest_secure_dimension(modulus, 1.0, 100.0, n_max=64)


def test_key_costs_of_rotation() -> None:
    est = L.primal_usvp_estimate(L.STANDARD_PARAMETER_SETS["Kyber-768"])
    assert L.key_costs(est, shared_matrix=False) == (est.bits(), est.bits())
    first, later = L.key_costs(est, shared_matrix=True, model="quantum")
    assert first == est.bits("quantum") and later == pytest.approx(2 * math.log2(768 + est.m))
