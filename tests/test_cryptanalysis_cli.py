"""Tests of ``encctl-gym crack``, the deciphering-time experiment and the smoothness/linear-algebra
helpers of the index calculus against independent computations."""

from __future__ import annotations

import json
import math
import random

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.cli import SUBCOMMANDS, main
from encctl_gym.cryptanalysis import pari_available
from encctl_gym.cryptanalysis.index_calculus import choose_bound, cost_model, relation_probability, sieve_probability
from encctl_gym.cryptanalysis.linalg import solve_mod_prime
from encctl_gym.cryptanalysis.smoothness import FactorBase, dickman_rho, primes_up_to, rational_reconstruction
from encctl_gym.errors import ParameterError
from encctl_gym.experiments import deciphering_time, reproduce


# ----------------------------------------------------------------------------- crack
def test_crack_is_registered() -> None:
    assert SUBCOMMANDS["crack"][0] == "encctl_gym.cryptanalysis.cli"


def test_crack_json_reports_checked_keys(capsys: pytest.CaptureFixture) -> None:
    assert main(["crack", "--bits", "32", "--keys", "5", "--breaker", "index-calculus", "--json", "--seed", "3"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["breaker"] == "index-calculus" and out["bits"] == 32 and out["group_source"] == "fresh"
    assert out["keys_match"] is True and len(out["keys"]) == 5
    p, g = int(out["group"]["p"], 16), int(out["group"]["g"], 16)
    for key in out["keys"]:
        assert pow(g, int(key["s"], 16), p) == int(key["h"], 16)
        assert key["seconds"] >= 0 and key["operations"]["smoothness_tests"] >= 1
    assert out["T_first"] == pytest.approx(out["precomputation"]["seconds"] + out["keys"][0]["seconds"])


def test_crack_table_on_a_shipped_group(capsys: pytest.CaptureFixture) -> None:
    assert (
        main(["crack", "--bits", "64", "--keys", "3", "--breaker", "token-chain", "--inner", "index-calculus", "--no-progress"])
        == 0
    )
    out = capsys.readouterr().out
    assert "64-bit shipped group" in out and "T_first" in out and "token" in out
    assert "all 3 keys checked" in out


def test_crack_same_keys_on_a_local_dask_cluster(capsys: pytest.CaptureFixture) -> None:
    pytest.importorskip("distributed")
    args = ["crack", "--bits", "32", "--keys", "6", "--breaker", "rho-multi", "--json", "--seed", "1"]
    assert main(args) == 0
    serial = json.loads(capsys.readouterr().out)
    assert main(args + ["--scheduler", "local", "--n-jobs", "2"]) == 0
    dask = json.loads(capsys.readouterr().out)
    assert [k["s"] for k in dask["keys"]] == [k["s"] for k in serial["keys"]]
    assert dask["group"] == serial["group"]


@pytest.mark.parametrize(
    "args, message",
    [
        (["--bits", "128", "--breaker", "bsgs"], "limit is 56 bits"),
        (["--bits", "40", "--keys", "0"], "keys"),
        (["--bits", "40", "--time-limit", "-1"], "time-limit"),
        (["--bits", "100", "--group", "shipped"], "no shipped group"),
        (["--bits", "56", "--breaker", "rho", "--time-limit", "0.05", "--keys", "1"], "time limit"),
    ],
)
def test_crack_errors_are_one_line_exit_2(capsys: pytest.CaptureFixture, args: list, message: str) -> None:
    assert main(["crack", *args, "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("encctl-gym crack: error:") and message in err[0]


# ----------------------------------------------------------------------------- experiment
@pytest.fixture(scope="module")
def quick_rows() -> list:
    return deciphering_time.compute(deciphering_time.QUICK_PLAN, seed=0, n_jobs=1)


def test_deciphering_time_rows_and_fit(quick_rows: list) -> None:
    rows = quick_rows
    assert all(set(r) == set(deciphering_time.COLUMNS) for r in rows)
    breakers = {r["breaker"] for r in rows}
    assert {"bsgs", "rho", "rho-multi", "index-calculus", "token-chain"} <= breakers
    assert ("pari" in breakers) == pari_available()
    for r in rows:
        if r["kind"] == "sequence":
            assert r["tau"] >= r["precompute"] + r["key_seconds"] - 1e-12
    fits = deciphering_time.fit(rows)
    assert {(f["breaker"], f["bits"]) for f in fits} == {(r["breaker"], r["bits"]) for r in rows}
    for f in fits:
        assert f["N_max"] == 8 and f["fresh"] == 1 and f["T_first"] > 0
        seq = sorted(
            (r for r in rows if r["breaker"] == f["breaker"] and r["bits"] == f["bits"] and r["kind"] == "sequence"),
            key=lambda r: r["N"],
        )
        slope, intercept = np.polyfit([r["N"] for r in seq], [r["tau"] for r in seq], 1)
        assert f["T_1"] == pytest.approx(slope) and f["T_0"] == pytest.approx(intercept)
        assert f["ratio"] == pytest.approx(f["T_1"] / f["T_first"])
    assert deciphering_time.n_grid(64) == [1, 2, 4, 8, 16, 32, 64] and deciphering_time.n_grid(6) == [1, 2, 4, 6]


def test_deciphering_time_csv_round_trip_and_plot(quick_rows: list, tmp_path) -> None:
    path = deciphering_time.write_csv(quick_rows, tmp_path / "d.csv")
    back = deciphering_time.read_csv(path)
    assert [r["tau"] for r in back] == [r["tau"] for r in quick_rows]
    assert [r["operations"] for r in back] == [r["operations"] for r in quick_rows]
    png = deciphering_time.plot(back, tmp_path / "d.png")
    assert png.stat().st_size > 10_000
    assert "T_1/T_first" in deciphering_time.format_table(deciphering_time.fit(back))


def test_deciphering_time_is_a_reproduce_step() -> None:
    assert ("deciphering", "encctl_gym.experiments.deciphering_time") in reproduce.STEPS


def test_full_plan_covers_the_sizes_of_the_issue() -> None:
    plan = deciphering_time.FULL_PLAN
    largest = {b: max(p.bits for p in plan if p.breaker == b) for b in {p.breaker for p in plan}}
    assert min(p.bits for p in plan) == 32
    assert largest["pari"] >= 80 and largest["index-calculus"] >= 80
    assert all(p.keys <= 64 for p in plan)


# ----------------------------------------------------------------------------- helpers
def test_dickman_rho_against_closed_forms_and_tables() -> None:
    for u in (1.0, 1.3, 1.7, 2.0):
        assert dickman_rho(u) == pytest.approx(1 - math.log(u), rel=1e-14)
    for u in (2.2, 2.5, 2.9):  # rho = 1 - (1 - ln(u-1)) ln u + Li2(1 - u) + pi^2/12 on [2, 3]
        exact = 1 - (1 - math.log(u - 1)) * math.log(u) + float(mpmath.polylog(2, 1 - u)) + math.pi**2 / 12
        assert dickman_rho(u) == pytest.approx(exact, rel=1e-12)
    # Tabulated values (e.g. Granville, "Smooth numbers", 2008).
    for u, ref in ((3, 4.8608388291e-2), (4, 4.9109256477e-3), (5, 3.5472470045e-4), (10, 2.7701718377e-11)):
        assert dickman_rho(u) == pytest.approx(ref, rel=1e-9)
    assert dickman_rho(0.5) == 1.0
    with pytest.raises(ParameterError):
        dickman_rho(-1)
    with pytest.raises(ParameterError):
        dickman_rho(41)


def test_dickman_rho_satisfies_its_integral_equation() -> None:
    # u rho(u) = integral of rho over [u - 1, u]
    for u in (3.3, 6.5, 12.0):
        integral = float(mpmath.quad(dickman_rho, [u - 1, math.floor(u), u]))
        assert u * dickman_rho(u) == pytest.approx(integral, rel=1e-9)


@settings(max_examples=200, deadline=None)
@given(st.integers(min_value=1, max_value=2**80))
def test_smoothness_test_agrees_with_trial_factorisation(x: int) -> None:
    import sympy

    fb = FactorBase(300)
    factors = sympy.factorint(x)
    smooth = all(ell <= 300 for ell in factors)
    assert fb.is_smooth(x) == smooth == fb.is_smooth(-x)
    if smooth:
        assert fb.factor(x) == {fb.index[ell]: e for ell, e in factors.items()}
    else:
        assert fb.factor(x) is None


def test_primes_up_to() -> None:
    assert primes_up_to(30) == (2, 3, 5, 7, 11, 13, 17, 19, 23, 29)
    assert len(primes_up_to(10**5)) == 9592


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_rational_reconstruction_halves_the_size(data: st.DataObject) -> None:
    p = data.draw(st.sampled_from([23, 1_000_003, 2**61 - 1, 340282366920938463463374607431768211297]))
    y = data.draw(st.integers(min_value=1, max_value=p - 1))
    a, b = rational_reconstruction(y, p)
    assert b != 0 and (a - b * y) % p == 0
    assert 0 < a <= math.isqrt(p)
    assert abs(b) * math.isqrt(p) < p  # |b| < p / r_{i-1} with r_{i-1} > isqrt(p)


def test_linear_algebra_solves_what_the_relations_determine() -> None:
    q = 1_000_000_007
    rng = random.Random(1)
    x = [rng.randrange(q) for _ in range(6)]
    rows = [{j: rng.randint(-3, 3) for j in range(5)} for _ in range(8)]  # x_5 never occurs
    rows.append({4: 1, 5: 0})
    rhs = [sum(c * x[j] for j, c in row.items()) % q for row in rows]
    sol, rank = solve_mod_prime(rows, rhs, 7, q)
    assert rank == 5 and sol[:5] == x[:5] and sol[5] is None and sol[6] is None
    # x_0 + x_1 = c alone leaves both free; x_2 = d is determined
    sol, rank = solve_mod_prime([{0: 1, 1: 1}, {2: 1}], [5, 9], 3, 11)
    assert sol == [None, None, 9] and rank == 2
    big = (1 << 89) - 1  # a Mersenne prime: the fmpz_mod_mat path
    sol, _ = solve_mod_prime([{0: 2}, {0: 1, 1: 1}], [6, 10], 2, big)
    assert sol == [3, 7]


def test_cost_model_is_consistent() -> None:
    for bits in (48, 80, 96):
        bound = choose_bound(bits)
        model = cost_model(bits, bound)
        assert model["first"] == pytest.approx(model["relations"] + model["linear_algebra"] + model["descent"])
        assert model["per_key"] < 0.05 * model["first"]
        assert 1 / model["cells_per_relation"] == pytest.approx(sieve_probability(bits, bound))
    assert choose_bound(96) > choose_bound(64) > choose_bound(32)


def test_model_curves_against_hand_computation() -> None:
    """paper and generic charge every key in full; the precomputation model's ratio at 64 bits is
    C_key / (C_pre + C_key) with C_pre = Omega(64) (eq:opt_key's GNFS formula, written out here)
    and C_key = max(1, C_pre 2^-r), r the 768-bit record's ratio: 5300 core-years of 365 days
    against 2 core-days per further logarithm."""
    import math

    curves = deciphering_time.model_curves([32, 64], [1, 2, 64], model_bits=64)
    assert np.allclose(curves["paper"]["tau"], [1, 2, 64]) and np.allclose(curves["generic"]["tau"], [1, 2, 64])
    assert math.isnan(curves["paper"]["ratio"][0])  # the GNFS formula starts at 40 bits
    assert curves["generic"]["ratio"][0] == 1.0
    ln_p = 64 * math.log(2)
    c_pre = math.exp((64 / 9) ** (1 / 3) * ln_p ** (1 / 3) * math.log(ln_p) ** (2 / 3))
    c_key = max(1.0, c_pre / (5300 * 365 / 2))
    ratio = c_key / (c_pre + c_key)
    assert curves["precomputation"]["ratio"][1] == pytest.approx(ratio, rel=1e-9)
    assert curves["precomputation"]["tau"][2] == pytest.approx(1 + 63 * ratio, rel=1e-9)


def test_models_figure_and_from_csv(quick_rows: list, tmp_path) -> None:
    path = deciphering_time.write_csv(quick_rows, tmp_path / "rec.csv")
    png = deciphering_time.plot_models(quick_rows, deciphering_time.fit(quick_rows), tmp_path / "m.png", model_bits=40)
    assert png.stat().st_size > 10_000
    out = tmp_path / "redraw"
    assert deciphering_time.main(["--from-csv", str(path), "--out", str(out), "--no-progress"]) == 0
    assert (out / "deciphering_models.png").is_file()
    assert (out / "deciphering_time.csv").read_text() == path.read_text()
    assert deciphering_time.main(["--from-csv", str(tmp_path / "missing.csv"), "--out", str(out)]) == 2


def test_a_redraw_from_csv_leaves_data_files_that_hold_the_same_values_untouched(quick_rows: list, tmp_path) -> None:
    """The fit CSV on disk differs from a refit only in the last digit (another machine's
    rounding): a redraw keeps it byte for byte; a real change of value is written."""
    out = tmp_path / "fig"
    out.mkdir()
    source = deciphering_time.write_csv(quick_rows, out / "deciphering_time.csv")
    fits = deciphering_time.fit(quick_rows)
    nudged = [dict(f, T_first=float(np.nextafter(f["T_first"], np.inf))) for f in fits]
    fit_path = deciphering_time.write_csv(nudged, out / "deciphering_time_fit.csv", deciphering_time.FIT_COLUMNS)
    before = {p.name: p.read_bytes() for p in (source, fit_path)}
    assert deciphering_time.main(["--from-csv", str(source), "--out", str(out), "--no-progress"]) == 0
    assert {p.name: p.read_bytes() for p in (source, fit_path)} == before
    changed = [dict(f, T_first=2 * f["T_first"]) for f in fits]
    deciphering_time.write_csv(changed, fit_path, deciphering_time.FIT_COLUMNS)
    assert deciphering_time.main(["--from-csv", str(source), "--out", str(out), "--no-progress"]) == 0
    redone = deciphering_time.read_csv(fit_path)
    assert [r["T_first"] for r in redone] == pytest.approx([f["T_first"] for f in fits], rel=1e-12)


# ----------------------------------------------------------------------------- hardening
@pytest.mark.parametrize(
    "args, message",
    [
        (["--bits", "32", "--keys", "1000000000000"], "--keys = 1000000000000"),
        (["--bits", "32", "--keys", "9" * 401], "--keys = <integer of 1333 bits"),
        (["--bits", "712", "--keys", "1", "--breaker", "rho", "--max-bits", "100000"], "MAX_EXPECTED_SECONDS"),
        (["--bits", "32", "--keys", "2", "--scheduler", "tcp://"], "scheduler address 'tcp://' names no host:port"),
    ],
)
def test_crack_refuses_unbounded_work_in_one_line(capsys: pytest.CaptureFixture, args: list, message: str) -> None:
    assert main(["crack", *args, "--no-progress", "--json"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err


def test_crack_refuses_at_once_what_the_environment_refuses_and_prints_its_estimate_first(capsys, monkeypatch) -> None:
    """The environment's estimate (Breaker.check_time) decides for crack too: two rho keys at 64
    bits are refused before any work, naming --max-seconds; raising it lets the job start, and
    the estimate is the first line printed."""
    from encctl_gym.cryptanalysis import get_breaker
    from encctl_gym.cryptanalysis.cli import DEFAULT_MAX_SECONDS
    from encctl_gym.crypto.group import shipped_group

    started = []

    def no_work(*args, **kwargs):
        started.append(True)
        raise KeyboardInterrupt  # stop before any key is broken (a real run takes about 17 minutes)

    monkeypatch.setattr("encctl_gym.cryptanalysis.cli.break_sequence", no_work)
    first, per_key = get_breaker("rho").expected_seconds(shipped_group(64))
    assert first + per_key > DEFAULT_MAX_SECONDS  # the case of the check below
    assert main(["crack", "--bits", "64", "--keys", "2", "--breaker", "rho", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--max-seconds" in err[0] and "rho" in err[0] and not started, err
    limit = str(2 * (first + per_key))
    assert main(["crack", "--bits", "64", "--keys", "2", "--breaker", "rho", "--no-progress", "--max-seconds", limit]) == 130
    out = capsys.readouterr().out.strip().splitlines()
    assert started and out and "expected about" in out[0] and "2 keys" in out[0], out


def test_crack_keys_limit_and_its_memory_estimate() -> None:
    from encctl_gym.cryptanalysis.keys import MAX_KEYS, check_keys
    from encctl_gym.errors import ResourceLimitError

    assert check_keys(MAX_KEYS) == MAX_KEYS and check_keys(1) == 1
    with pytest.raises(ResourceLimitError, match="MAX_KEYS") as err:
        check_keys(10**12)
    assert "2.79e+06 GiB" in str(err.value)  # 10^12 keys of 3000 bytes: 3e15 / 2^30 = 2.794e6 GiB
    with pytest.raises(ParameterError, match="keys must be an integer, got 2.5"):
        check_keys(2.5)


@pytest.mark.parametrize("u", ["a", None, 2 + 1j, 10**400, float("nan"), -1.0, True])
def test_dickman_rho_refuses_what_is_not_a_real_u(u: object) -> None:
    with pytest.raises(ParameterError, match="^u must be") as err:
        dickman_rho(u)  # type: ignore[arg-type]
    assert ("integer of 1329 bits" if u == 10**400 else repr(u)) in str(err.value)


def test_dickman_rho_takes_an_integer_u() -> None:
    assert dickman_rho(2) == pytest.approx(1 - math.log(2), rel=1e-14)
    assert dickman_rho(3) == pytest.approx(0.04860838829, rel=1e-9)  # rho(3), de Bruijn's table


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"p": "a"}, "p must be an integer, got 'a'"),
        ({"p": None}, "p must be an integer, got None"),
        ({"p": 1}, "p must be >= 2, got 1"),
        ({"y": 2.5}, "y must be an integer, got 2.5"),
        ({"y": None}, "y must be an integer, got None"),
        ({"y": 101}, "y must lie in [1, p), got y = 101 for p = 101"),
        ({"bound": 0}, "bound must be >= 1, got 0"),
        ({"bound": -1}, "bound must be >= 1, got -1"),
        ({"bound": 2.5}, "bound must be an integer, got 2.5"),
        ({"bound": "a"}, "bound must be an integer, got 'a'"),
        ({"bound": 101}, "bound must lie in [1, p), got bound = 101"),
    ],
)
def test_rational_reconstruction_refuses_bad_arguments(kwargs: dict, message: str) -> None:
    with pytest.raises(ParameterError) as err:
        rational_reconstruction(**{"y": 5, "p": 101, **kwargs})
    assert message in str(err.value)


def test_rational_reconstruction_at_the_edges_of_its_bound() -> None:
    # bound = 1: a = 1 and b = 5^-1 = 81 = -20 (mod 101), |b| < 101 (5 * 81 = 405 = 4 * 101 + 1).
    assert rational_reconstruction(5, 101, 1) == (1, -20)
    assert -20 % 101 == 81
    # bound = p - 1: y itself, b = 1.
    assert rational_reconstruction(5, 101, 100) == (5, 1)


def test_factor_base_refuses_a_bound_beyond_its_limit() -> None:
    from encctl_gym.cryptanalysis.smoothness import MAX_BOUND
    from encctl_gym.errors import ResourceLimitError

    for bound, shown in ((MAX_BOUND + 1, str(MAX_BOUND + 1)), (10**12, "1000000000000"), (10**400, "<integer of 1329 bits")):
        with pytest.raises(ResourceLimitError, match="MAX_BOUND") as err:
            FactorBase(bound)
        assert shown in str(err.value)
    with pytest.raises(ResourceLimitError):
        primes_up_to(10**12)


def test_crack_json_of_one_key_has_null_not_nan(capsys: pytest.CaptureFixture) -> None:
    assert main(["crack", "--bits", "32", "--keys", "1", "--breaker", "bsgs", "--json", "--no-progress"]) == 0
    text = capsys.readouterr().out
    out = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-JSON constant {c}"))
    assert out["mean_later_key"] is None and out["ratio"] is None and len(out["keys"]) == 1


@pytest.mark.parametrize(
    "bits, bound, message",
    [
        (10**400, 100, "bits must be <= 1048576"),
        ("a", 100, "bits must be an integer, got 'a'"),
        (64, 1, "bound must be >= 2, got 1"),
        (64, 0.5, "bound must be >= 2, got 0.5"),
        (64, "a", "bound must be a real number, got 'a'"),
    ],
)
def test_cost_model_refuses_arguments_outside_its_domain(bits: object, bound: object, message: str) -> None:
    for fn in (cost_model, relation_probability):
        with pytest.raises(ParameterError) as err:
            fn(bits, bound)  # type: ignore[arg-type]
        assert message in str(err.value)
    with pytest.raises(ParameterError, match="bits must be <= 1048576"):
        choose_bound(10**400)


def test_relation_probability_at_the_smallest_bound() -> None:
    # B = 2, 64 bits: u = 32 ln 2 / ln 2 = 32, so rho(32)^2 (beyond the closed forms: check u only).
    assert relation_probability(64, 2) == pytest.approx(dickman_rho(32.0) ** 2, rel=1e-12)
    assert relation_probability(4000, 2) == 0.0  # u = 2000 > 40: zero, not an error


def test_factor_base_tests_refuse_non_integers() -> None:
    fb = FactorBase(100)
    for bad in (2.5, "a", None):
        with pytest.raises(ParameterError, match="x must be an integer"):
            fb.is_smooth(bad)  # type: ignore[arg-type]
        with pytest.raises(ParameterError, match="x must be an integer"):
            fb.factor(bad)  # type: ignore[arg-type]
    assert fb.factor(2 * 3 * 97) == {0: 1, 1: 1, 24: 1}  # 97 is the 25th prime
    assert fb.is_smooth(-(2**10) * 97) and not fb.is_smooth(101)


def test_solve_mod_prime_refuses_a_bad_modulus_or_column() -> None:
    with pytest.raises(ParameterError, match="q must be >= 2, got 0"):
        solve_mod_prime([{0: 1}], [1], 1, 0)
    with pytest.raises(ParameterError, match="column 5, outside"):
        solve_mod_prime([{5: 1}], [1], 1, 7)
    with pytest.raises(ParameterError, match="ncols must be an integer"):
        solve_mod_prime([{0: 1}], [1], 1.5, 7)
    assert solve_mod_prime([{0: 3}], [1], 1, 7) == ([5], 1)  # 3 x = 1 (mod 7): x = 5


def test_structured_elimination_keeps_the_solutions_and_the_excess() -> None:
    from encctl_gym.cryptanalysis.linalg import _flint, _solve_dense, structured_elimination

    q = 1_000_003
    rng = random.Random(7)
    ncols = 60
    x = [rng.randrange(q) for _ in range(ncols)]
    # Sparse rows, light columns at the end (as the large primes of a factor base).
    rows = []
    for _ in range(70):
        cols = {rng.randrange(10) for _ in range(3)} | {rng.randrange(ncols) for _ in range(2)}
        rows.append({j: rng.choice([-2, -1, 1, 2, 3]) for j in cols})
    rhs = [sum(c * x[j] for j, c in row.items()) % q for row in rows]
    core, core_rhs, pivots = structured_elimination(rows, rhs, q)
    assert pivots and len(core) + len(pivots) == len(rows)  # one row per eliminated column
    eliminated = {col for col, _, _ in pivots}
    assert not eliminated & {j for row in core for j in row}
    for row, r in zip(core, core_rhs):  # the core holds for the true solution
        assert sum(c * x[j] for j, c in row.items()) % q == r
    # The same answer as the dense elimination of the whole system, and every value true.
    sol, rank = solve_mod_prime(rows, rhs, ncols, q)
    dense, dense_rank = _solve_dense(_flint(), rows, rhs, ncols, q)
    assert rank == dense_rank
    assert all(v is None or v == x[j] for j, v in enumerate(sol))
    assert [v is not None for v in sol] == [v is not None for v in dense]


def test_lattice_sieve_pairs_satisfy_the_congruence() -> None:
    import gmpy2

    from encctl_gym.cryptanalysis.lattice_sieve import SievePlan, reduced_basis, sieve_candidates

    p = int(gmpy2.next_prime(1 << 61))
    for y in (2, 12345678901, p - 1):
        a1, b1, a2, b2 = reduced_basis(y, p)
        assert abs(a1 * b2 - a2 * b1) == p  # a basis of the lattice of determinant p
        assert (a1 - b1 * y) % p == 0 and (a2 - b2 * y) % p == 0
        n1, n2, dot = a1 * a1 + b1 * b1, a2 * a2 + b2 * b2, a1 * a2 + b1 * b2
        assert n1 <= n2 and 2 * abs(dot) <= n1  # Lagrange-reduced
        assert 3 * n1 <= 4 * p and 3 * n1 * n2 <= 4 * p * p  # Hermite's bound in dimension 2
    plan = SievePlan(primes_up_to(5000), 8, 256)
    fb = FactorBase(5000)
    y = 98765432123
    (a1, b1, a2, b2), pairs = sieve_candidates(y, p, plan, slack=12.0)
    assert pairs and all(1 <= i <= 8 and -256 <= j < 256 and math.gcd(i, j) == 1 for i, j in pairs)
    # Every smooth pair of the region (found by exact tests) is among the candidates of a
    # sieve with a generous slack; with no slack at all only candidates that are smooth remain.
    smooth = {
        (i, j)
        for i in range(1, 9)
        for j in range(-256, 256)
        if math.gcd(i, j) == 1
        and fb.is_smooth(i * a1 + j * a2 or 1)
        and fb.is_smooth(i * b1 + j * b2 or 1)
        and i * a1 + j * a2
        and i * b1 + j * b2
    }
    assert smooth and smooth <= set(sieve_candidates(y, p, plan, slack=40.0)[1])


# ----------------------------------------------------------------------------- L_p[1/2, c] fit, large sizes
def test_lp_half_fit_against_scipy_linregress() -> None:
    from scipy import stats

    from encctl_gym.experiments.deciphering_models import fit_lp_half, lp_half_exponent

    bits = [64, 72, 80, 88, 96, 112, 128]
    x = np.array([math.sqrt(b * math.log(2) * math.log(b * math.log(2))) for b in bits])
    assert np.allclose(lp_half_exponent(bits), x, rtol=1e-15)
    noise = np.array([0.1, -0.05, 0.02, -0.1, 0.08, 0.0, -0.03])
    seconds = 3e-7 * np.exp(1.1 * x + noise)
    f = fit_lp_half("index-calculus", bits, seconds)
    ref = stats.linregress(x, np.log(seconds))
    t = stats.t.ppf(0.975, len(bits) - 2)
    assert f.c == pytest.approx(ref.slope, rel=1e-10) and f.a == pytest.approx(math.exp(ref.intercept), rel=1e-10)
    assert f.c_interval == pytest.approx((ref.slope - t * ref.stderr, ref.slope + t * ref.stderr), rel=1e-10)
    lo, hi = f.a_interval
    assert lo < f.a < hi and math.log(hi / f.a) == pytest.approx(t * ref.intercept_stderr, rel=1e-10)
    resid = np.log(seconds) - (ref.intercept + ref.slope * x)
    s2 = float(resid @ resid) / (len(bits) - 2)
    for b, xb in ((72, x[1]), (160, math.sqrt(160 * math.log(2) * math.log(160 * math.log(2))))):
        se = math.sqrt(s2 * (1 / len(bits) + (xb - x.mean()) ** 2 / float(((x - x.mean()) ** 2).sum())))
        lo, hi = f.band([b])
        assert float(hi[0]) / float(f(b)) == pytest.approx(math.exp(t * se), rel=1e-9) and lo[0] < f(b) < hi[0]
    exact = fit_lp_half("x", bits[:3], 2e-6 * np.exp(0.9 * x[:3]))
    assert exact.c == pytest.approx(0.9, rel=1e-10) and exact.a == pytest.approx(2e-6, rel=1e-8)
    with pytest.raises(ParameterError, match="at least three sizes"):
        fit_lp_half("x", bits[:2], seconds[:2])
    with pytest.raises(ParameterError, match="positive times"):
        fit_lp_half("x", bits[:3], [1.0, 0.0, 2.0])


def test_plan_selection_and_merging_of_recorded_rows() -> None:
    plan = deciphering_time.select_plan(False, True, ["index-calculus"])
    assert {p.breaker for p in plan} == {"index-calculus"} and {112, 128} <= {p.bits for p in plan}
    assert not any(p.bits > 96 for p in deciphering_time.select_plan(False, False, None))
    with pytest.raises(ParameterError, match="choose one"):
        deciphering_time.select_plan(True, True, None)
    with pytest.raises(ParameterError, match="unknown 'nfs'"):
        deciphering_time.select_plan(False, False, ["nfs"])
    recorded = [
        {"breaker": "pari", "bits": 64, "kind": "sequence"},
        {"breaker": "index-calculus", "bits": 64, "kind": "sequence"},
        {"breaker": "index-calculus", "bits": 80, "kind": "sequence"},
    ]
    measured = [
        {"breaker": "index-calculus", "bits": 80, "kind": "new"},
        {"breaker": "index-calculus", "bits": 128, "kind": "new"},
    ]
    merged = deciphering_time.merge_rows(recorded, measured)
    assert [(r["breaker"], r["bits"], r["kind"]) for r in merged] == [
        ("pari", 64, "sequence"),
        ("index-calculus", 64, "sequence"),
        ("index-calculus", 80, "new"),
        ("index-calculus", 128, "new"),
    ]
