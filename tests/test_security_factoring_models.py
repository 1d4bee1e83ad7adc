"""The factoring family's cost models (security.cost_models.factoring): formulas recomputed by
hand, the published exponents of their sources, the factoring records, and the design."""

from __future__ import annotations

import math
from fractions import Fraction

import pytest

from encctl_gym.errors import ModelRangeError, ParameterError
from encctl_gym.security.cost_models import (
    FACTORING_MODELS,
    GUILLEVIC_CORRECTION,
    design_modulus_lengths,
    factoring_model,
    factoring_record_gaps,
    l_third_bits,
)
from encctl_gym.security.records import default_records


def _l_bits(k: int, c: float) -> float:  # independent: natural logs of n = 2^k
    ln_n = k * math.log(2)
    return c * ln_n ** (1 / 3) * math.log(ln_n) ** (2 / 3) / math.log(2)


@pytest.mark.parametrize("k", [40, 512, 712, 1024, 2048, 3072])
def test_l_third_bits_is_the_formula(k: int) -> None:
    assert l_third_bits(k, 1.923) == pytest.approx(_l_bits(k, 1.923), rel=1e-13)


def test_each_model_is_its_sources_formula() -> None:
    k = 1024
    gnfs = factoring_model("gnfs").break_cost(k)
    assert gnfs.first_bits == gnfs.next_bits == pytest.approx(_l_bits(k, (64 / 9) ** (1 / 3)), abs=1e-9)
    fac = factoring_model("factory").break_cost(k)
    assert fac.next_bits == pytest.approx(_l_bits(k, 1.639), abs=1e-9)
    assert fac.first == fac.precomputation + fac.next
    assert math.log2(float(fac.precomputation)) == pytest.approx(_l_bits(k, 2.008), abs=1e-9)
    batch = factoring_model("batch-nfs").break_cost(k)
    assert batch.next_bits == pytest.approx(_l_bits(k, 1.704), abs=1e-9)
    assert batch.first_bits == pytest.approx(_l_bits(k, 2.204), abs=1e-9)


def test_batch_nfs_per_key_is_its_batch_over_l_to_the_half() -> None:
    # Bernstein-Lange: area L^1.181 x time L^1.022 for L^0.5 keys = L^1.704 per key (rounded constants)
    assert 1.181 + 1.022 - 0.5 == pytest.approx(1.704, abs=1e-3)
    k = 2048
    batch = factoring_model("batch-nfs").break_cost(k)
    assert batch.first_bits - batch.next_bits == pytest.approx(_l_bits(k, 0.5), abs=1e-9)


def test_the_amortised_models_are_cheaper_per_key_and_dearer_for_the_first() -> None:
    for k in (512, 1024, 2048):
        g, f, b = (factoring_model(m).break_cost(k) for m in ("gnfs", "factory", "batch-nfs"))
        assert f.next < g.next and b.next < g.next
        assert f.first > g.first and b.first > g.first


def test_gaps_to_the_factoring_records() -> None:
    recs = {r.name: r for r in default_records().records if r.problem == "factoring"}
    rows = factoring_record_gaps(factoring_model("gnfs"))
    assert {r["record"] for r in rows} == set(recs)
    for row in rows:
        rec = recs[row["record"]]
        # the record in clock cycles, recomputed: core-years x 365 days x clock rate
        years = {"rsa-240": 900, "rsa-250": 2700}[rec.name]
        assert row["record_bits"] == pytest.approx(math.log2(years * 365 * 86400 * 2.1e9), abs=1e-9)
        assert row["gap_bits"] == pytest.approx(_l_bits(rec.key_length, (64 / 9) ** (1 / 3)) - row["record_bits"], abs=1e-9)
        assert 10 < row["gap_bits"] < 14  # the uncorrected formula is about 12 bits above a real factorisation
    for row in factoring_record_gaps(factoring_model("gnfs", gnfs_correction=GUILLEVIC_CORRECTION)):
        assert abs(row["gap_bits"]) < 1


def test_the_design_per_model_and_the_paper_baseline() -> None:
    keys, budget = 13159, Fraction(13159) * 2**73  # lam* = 74 for the paper model
    k = design_modulus_lengths(keys, budget)
    assert set(k) == set(FACTORING_MODELS)
    assert k["paper"] == 712  # the paper's design example
    for name, kk in k.items():
        m = factoring_model(name)
        assert m.break_cost(kk).operations(keys) > budget or name == "paper"
        assert m.break_cost(kk - 1).operations(keys) <= budget or name == "paper"
    assert k["factory"] > k["gnfs"]  # the factory's precomputation is the attacker's cheaper route


def test_bad_input_gets_the_packages_error() -> None:
    with pytest.raises(ModelRangeError):
        l_third_bits(39, 1.9)
    with pytest.raises(ParameterError):
        factoring_model("nfs")
    with pytest.raises(ParameterError):
        factoring_model("factory", gnfs_correction=-1)
