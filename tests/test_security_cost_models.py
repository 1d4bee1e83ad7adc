"""Tests of encctl_gym.security.cost_models, records and key_length (issue: design against the attack that exists).

Every model is checked against numbers computed here independently, with plain floats and the
formulas written out: the paper's k* = 712 under ``paper``, the precomputation model's k* for the
design example, the generic model's k*, and the NIST SP 800-57 table under the corrected GNFS formula.
"""

from __future__ import annotations

import json
import math
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym._validation import format_value
from encctl_gym.errors import ConfigError, ModelRangeError, ParameterError, ResourceLimitError
from encctl_gym.presets import PAPER_DESIGN_EXAMPLE
from encctl_gym.security.cost_models import (
    DECIPHERING_MODELS,
    GNFS_MIN_KEY_LENGTH,
    GUILLEVIC_CORRECTION,
    CostModel,
    GenericModel,
    PaperModel,
    PrecomputationModel,
    check_gnfs_correction,
    deciphering_model,
    gnfs_log2_complexity,
    pollard_rho_log2_operations,
)
from encctl_gym.security.deciphering import break_cost, max_affordable_samples
from encctl_gym.security.design import is_secure, paper_design_example
from encctl_gym.security.key_length import defense_budget, design_key_length, key_length_value
from encctl_gym.security.records import DATA_FILE, default_records, load_records, nist_key_length, nist_strength
from encctl_gym.security.sample_size import exact_sic_asymptotic_function
from encctl_gym.security.threat import ThreatModel

N_STAR = 13159  # the design example's N*, recomputed by paper_design_example() in test_design_example_n_star
TAU_C, UPSILON = PAPER_DESIGN_EXAMPLE["tau_c"], PAPER_DESIGN_EXAMPLE["upsilon"]


def omega_bits(k: int) -> float:
    """log2 of exp((64/9)^(1/3) (ln 2^k)^(1/3) (ln ln 2^k)^(2/3)), written out."""
    ln_n = k * math.log(2)
    return (64 / 9) ** (1 / 3) * ln_n ** (1 / 3) * math.log(ln_n) ** (2 / 3) / math.log(2)


def budget_bits() -> float:
    return math.log2(442e15) + math.log2(31536e4)


def test_design_example_n_star() -> None:
    assert paper_design_example().N_star == N_STAR


# --------------------------------------------------------------------------- the paper model keeps the paper's numbers
def test_paper_model_reproduces_the_paper() -> None:
    d = design_key_length(N_STAR, ThreatModel(tau_c=TAU_C, upsilon=UPSILON))
    assert (d.lam_star, d.k_star, d.paper_k_star) == (74, 712, 712)
    assert d.work_bits == pytest.approx(math.log2(N_STAR) + omega_bits(712), abs=1e-9)
    assert d.dynamic_key_bits == pytest.approx(math.log2(N_STAR), abs=1e-9)
    assert d.budget_bits == pytest.approx(budget_bits(), abs=1e-12)


# --------------------------------------------------------------------------- hand computations of k*
def _smallest(ok) -> int:
    k = GNFS_MIN_KEY_LENGTH
    while not ok(k):
        k += 1
    return k


@pytest.mark.parametrize("correction", [0.0, GUILLEVIC_CORRECTION])
def test_precomputation_k_star_by_hand(correction: float) -> None:
    # r from the 768-bit record: 5300 core-years, then 2 core-days per logarithm (365-day years)
    r = math.log2(5300 * 365 / 2)
    target = budget_bits()

    def work_bits(k: int) -> float:  # log2(C_pre + N* C_key), C_key = C_pre 2^-r, in floats
        pre = omega_bits(k) - correction
        return pre + math.log2(1 + N_STAR * 2.0**-r)

    k_hand = _smallest(lambda k: work_bits(k) > target)
    assert work_bits(k_hand) - target > 1e-6 and target - work_bits(k_hand - 1) > 1e-6  # no tie to round
    d = design_key_length(N_STAR, ThreatModel(tau_c=TAU_C, upsilon=UPSILON, cost_model=PrecomputationModel(correction)))
    assert d.k_star == k_hand
    assert d.work_bits == pytest.approx(work_bits(k_hand), abs=1e-9)
    # the precomputation alone must already exceed Upsilon tau_c: the per-key term adds ~0.02 bit
    assert d.first_key_bits > target - 0.05
    assert d.dynamic_key_bits == pytest.approx(math.log2((1 + N_STAR * 2.0**-r) / (1 + 2.0**-r)), abs=1e-9)
    assert d.paper_k_star == 712


def test_generic_k_star_by_hand() -> None:
    target = budget_bits()
    k = 16
    while not 0.5 * (k - 2 + math.log2(math.pi / 2)) + math.log2(N_STAR) > target:
        k += 1
    assert design_key_length(N_STAR, ThreatModel(tau_c=TAU_C, upsilon=UPSILON, cost_model="generic")).k_star == k


@settings(max_examples=25, deadline=None)
@given(
    st.sampled_from(list(DECIPHERING_MODELS)),
    st.integers(2, 10**7),
    st.floats(1e3, 1e12),
    st.floats(1e9, 1e20),
    st.sampled_from([0.0, 5.0, GUILLEVIC_CORRECTION]),
)
def test_k_star_is_the_smallest_secure_key(model: str, N_star: int, tau_c: float, upsilon: float, c: float) -> None:
    """Definition def:security itself: secure at k*, and (but for the paper model's integer lam) not at k* - 1."""
    kw = {} if model == "generic" else {"gnfs_correction": c}
    try:
        d = design_key_length(N_star, ThreatModel(tau_c=tau_c, upsilon=upsilon, cost_model=deciphering_model(model, **kw)))
    except ModelRangeError:
        return  # the budget is below what the smallest key of the range already defeats
    gamma = exact_sic_asymptotic_function(0, 1, 1, 1, r_sigma=1)  # K = 2: gamma(N) = 1 / (N - 1)
    g_c = Fraction(2, 2 * N_star - 3)  # gamma(N*) < g_c <= gamma(N* - 1): N* is the smallest N below gamma_c
    assert gamma(N_star) < g_c and (N_star == 2 or gamma(N_star - 1) >= g_c)
    assert is_secure(break_cost(model, key_length=d.k_star, **kw), gamma=gamma, gamma_c=g_c, tau_c=tau_c, upsilon=upsilon)
    if model != "paper" and d.k_star > deciphering_model(model, **kw).key_length_range[0]:
        below = break_cost(model, key_length=d.k_star - 1, **kw)
        assert max_affordable_samples(tau_c, below, upsilon) >= N_star


# --------------------------------------------------------------------------- the GNFS correction and NIST SP 800-57
#: Stated tolerance: half the smallest gap between NIST strengths (112 -> 128), so that the
#: corrected formula lands nearer the tabulated strength than any neighbouring row would.
NIST_TOLERANCE_BITS = 8.0


def test_nist_table_under_the_corrected_formula() -> None:
    rows = default_records().nist
    assert [(r.key_length, r.strength) for r in rows] == [(1024, 80), (2048, 112), (3072, 128), (7680, 192), (15360, 256)]
    corrected = [gnfs_log2_complexity(r.key_length, GUILLEVIC_CORRECTION) - r.strength for r in rows]
    uncorrected = [omega_bits(r.key_length) - r.strength for r in rows]
    assert max(abs(d) for d in corrected) <= NIST_TOLERANCE_BITS
    assert max(abs(d) for d in uncorrected) > NIST_TOLERANCE_BITS  # the o(1) term matters: up to 13.4 bits
    for r, d in zip(rows, corrected):
        assert d == pytest.approx(omega_bits(r.key_length) - 11.91 - r.strength, abs=1e-9)


def test_nist_lookups() -> None:
    assert nist_key_length(74.0) == 1024 and nist_key_length(80) == 1024 and nist_key_length(86.9) == 2048
    assert nist_key_length(300) is None
    assert nist_strength(712) is None and nist_strength(1024) == 80 and nist_strength(3000) == 112


@pytest.mark.parametrize(
    "bad,match", [(math.nan, "finite"), (-1.0, ">= 0"), ("a", "'a'"), (None, "None"), (10**400, "1329 bits"), (2 + 1j, "2")]
)
def test_nist_key_length_checks_its_strength(bad: object, match: str) -> None:
    with pytest.raises(ParameterError, match=f"^bits .*{match}"):
        nist_key_length(bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("bad,match", [(math.nan, "integer"), (-1, ">= 2"), (2.5, "2.5"), ("a", "'a'"), (None, "None")])
def test_nist_strength_checks_its_key_length(bad: object, match: str) -> None:
    with pytest.raises(ParameterError, match=f"^key_length .*{match}"):
        nist_strength(bad)  # type: ignore[arg-type]


def test_nist_edges() -> None:
    # the table's first row is (80 bits, 1024): 0 bits needs the smallest row, 1023 bits is below it
    assert nist_key_length(0) == 1024 and nist_strength(1023) is None and nist_strength(2) is None


@pytest.mark.parametrize("bad", [-1.0, -1e-9, math.nan, math.inf, 18.7, 10**400, True, "11.9", None])
def test_bad_gnfs_correction(bad: object) -> None:
    with pytest.raises(ParameterError, match="gnfs_correction") as info:
        check_gnfs_correction(bad)
    assert format_value(bad) in str(info.value)
    for model in ("paper", "precomputation"):
        with pytest.raises(ParameterError, match="gnfs_correction"):
            deciphering_model(model, gnfs_correction=bad)


def test_gnfs_range_is_where_the_formula_beats_rho() -> None:
    # the lower end of the GNFS range: below ~38 bits Pollard rho is cheaper than the formula says
    ks = np.arange(GNFS_MIN_KEY_LENGTH, 2000)
    assert np.all(gnfs_log2_complexity(ks) <= pollard_rho_log2_operations(ks))
    assert omega_bits(36) > 0.5 * (36 - 2 + math.log2(math.pi / 2))
    with pytest.raises(ModelRangeError, match="39"):
        PaperModel().break_cost(39)
    with pytest.raises(ModelRangeError, match="15"):
        GenericModel().break_cost(15)


# --------------------------------------------------------------------------- registry, base class, errors
def test_registry_and_base_class() -> None:
    assert set(DECIPHERING_MODELS) == {"paper", "precomputation", "generic"}
    for name in DECIPHERING_MODELS:
        m = deciphering_model(name)
        assert isinstance(m, CostModel) and m.name == name
        assert m.describe()["name"] == name
    with pytest.raises(ParameterError, match="'rho'") as info:
        deciphering_model("rho")
    assert "paper, precomputation, generic" in str(info.value)
    with pytest.raises(ParameterError, match="calibration"):
        deciphering_model("paper", calibration=[(768, 19.9)])
    with pytest.raises(ParameterError, match="gnfs_correction"):
        deciphering_model("generic", gnfs_correction=1.0)
    with pytest.raises(ParameterError, match="\\['foo'\\]"):
        deciphering_model(["foo"])


def test_design_outside_the_key_length_range() -> None:
    with pytest.raises(ModelRangeError, match="below 40 bits"):
        design_key_length(2, ThreatModel(tau_c=1.0, upsilon=1.0, cost_model="precomputation"))
    with pytest.raises(ModelRangeError, match="65536"):
        design_key_length(2, ThreatModel(tau_c=1e300, upsilon=1e300, cost_model="generic"))


# --------------------------------------------------------------------------- calibration
def test_calibration_from_the_768_bit_record() -> None:
    (point,) = default_records().ratio_points
    assert point.key_length == 768 and point.ratio_bits == pytest.approx(math.log2(5300 * 365 / 2), abs=1e-12)
    m = PrecomputationModel()
    assert m.ratio_bits(512) == m.ratio_bits(768) == m.ratio_bits(4096) == point.ratio_bits  # flat beyond the point
    cost = m.break_cost(1024)
    assert math.log2(cost.precomputation) == pytest.approx(omega_bits(1024), abs=1e-9)
    assert math.log2(cost.next) == pytest.approx(omega_bits(1024) - point.ratio_bits, abs=1e-9)


def test_calibration_interpolates_linearly() -> None:
    m = PrecomputationModel(calibration=[(512, 13.0), (768, 19.0), (1024, 20.0)])
    assert m.ratio_bits(400) == 13.0 and m.ratio_bits(640) == pytest.approx(16.0) and m.ratio_bits(896) == pytest.approx(19.5)
    assert m.ratio_bits(5000) == 20.0
    # a further key never costs less than one operation
    tiny = PrecomputationModel(gnfs_correction=18.0, calibration=[(40, 30.0)]).break_cost(40)
    assert tiny.next == 1


@pytest.mark.parametrize(
    "points,match",
    [
        ([(768, 19.9), (512, 13.3)], "512"),
        ([(768, 19.9), (768, 20.0)], "768"),
        ([(512, 1.0), (513, 10.0)], "faster than the GNFS cost"),
        ([], "at least one"),
        ([(768, -1.0)], "ratio_bits"),
        ([(768.5, 19.0)], "key_length"),
        ([(20, 5.0)], "40"),
        (["768"], "'768'"),
        (42, "list of .* points, got 42"),
        ("abc", "list of .* points, got 'abc'"),
        ({"records": []}, "list of .* points, got {'records'"),
    ],
)
def test_bad_calibration(points: list, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        PrecomputationModel(calibration=points)


def _records_file(tmp_path: Path, mutate) -> Path:
    data = json.loads(DATA_FILE.read_text())
    mutate(data)
    path = tmp_path / "records.json"
    path.write_text(json.dumps(data))
    return path


def test_records_files(tmp_path: Path) -> None:
    def two_points_decreasing(d: dict) -> None:
        extra = dict(d["records"][1], name="dlp-700", key_length=700)
        d["records"].append(extra)  # after the 768-bit point: not increasing

    with pytest.raises(ConfigError, match="768 followed by 700"):
        load_records(_records_file(tmp_path, two_points_decreasing))

    def bad_unit(d: dict) -> None:
        d["records"][1]["per_key"]["unit"] = "core-fortnight"

    with pytest.raises(ConfigError, match="core-fortnight"):
        load_records(_records_file(tmp_path, bad_unit))

    def unknown_field(d: dict) -> None:
        d["records"][0]["colour"] = "red"

    with pytest.raises(ConfigError, match="colour"):
        load_records(_records_file(tmp_path, unknown_field))

    def nist_not_increasing(d: dict) -> None:
        d["nist_sp800_57"]["rows"][1]["key_length"] = 900

    with pytest.raises(ConfigError, match="1024 followed by 900"):
        load_records(_records_file(tmp_path, nist_not_increasing))

    def faster_keys(d: dict) -> None:
        d["records"][1]["per_key"] = {"value": 500, "unit": "core-day"}

    m = PrecomputationModel(calibration=load_records(_records_file(tmp_path, faster_keys)))
    assert m.points[0].ratio_bits == pytest.approx(math.log2(5300 * 365 / 500))
    big = tmp_path / "big.json"
    big.write_text(" " * (2 << 20))
    with pytest.raises(ResourceLimitError, match="big.json"):
        load_records(big)
    with pytest.raises(ConfigError, match="does not exist"):
        load_records(tmp_path / "missing.json")


# --------------------------------------------------------------------------- what a key is worth
def test_what_a_712_bit_key_is_worth() -> None:
    assert defense_budget(TAU_C, UPSILON) == 442 * 10**15 * 31536 * 10**4
    paper = key_length_value(712, ThreatModel(tau_c=TAU_C, upsilon=UPSILON, cost_model="paper"), N_star=N_STAR)
    assert paper.secure and paper.dynamic_key_bits == pytest.approx(math.log2(N_STAR), abs=1e-9)
    assert paper.affordable_samples == math.floor(442e15 * 31536e4 / 2 ** omega_bits(712))  # 7357.x, no tie
    pre = key_length_value(712, ThreatModel(tau_c=TAU_C, upsilon=UPSILON, cost_model="precomputation"), N_star=N_STAR)
    assert not pre.secure and pre.affordable_samples > 10**9
    r = math.log2(5300 * 365 / 2)
    # N = 1 + (B - C_pre - C_key) / C_key = B / C_key - 2^r
    assert pre.log2_affordable_samples == pytest.approx(math.log2(2 ** (budget_bits() - omega_bits(712) + r) - 2**r), abs=1e-6)
    generic = key_length_value(712, ThreatModel(tau_c=TAU_C, upsilon=UPSILON, cost_model="generic"), N_star=N_STAR)
    assert generic.secure and generic.affordable_samples == 0 and generic.first_key_bits > 355


@pytest.mark.parametrize(
    "year,match", [(-1, ">= 0"), (10**400, "<= 9999, got <integer of 1329 bits"), (2015.5, "2015.5"), ("2015", "'2015'")]
)
def test_record_years_are_bounded(tmp_path: Path, year: object, match: str) -> None:
    def mutate(d: dict) -> None:
        d["records"][0]["year"] = year

    with pytest.raises(ConfigError, match=f"year must be .*{match}"):
        load_records(_records_file(tmp_path, mutate))
