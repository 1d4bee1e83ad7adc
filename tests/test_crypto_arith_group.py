"""Tests of crypto.arith (gmpy2 layer, random sources) and crypto.group (Example ex:elgamal parameters)."""

from __future__ import annotations

import json
import math
import re

import gmpy2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym._validation import format_value
from encctl_gym.crypto import arith
from encctl_gym.crypto.arith import (
    MAX_PRIMALITY_REPS,
    PowmodCounter,
    RandomSource,
    SecureRandom,
    SeededRandom,
    as_random_source,
    check_integer,
    check_rng,
    invert,
    is_prime,
    jacobi,
    legendre,
    mulmod,
    powmod,
    secure_random,
    seeded_random,
)
from encctl_gym.crypto.elgamal import keygen
from encctl_gym.crypto.group import (
    DEFAULT_MAX_GENERATION_SECONDS,
    MAX_GROUP_FILE_BYTES,
    MAX_SIEVE_LIMIT,
    MAX_SIEVE_WINDOW,
    MIN_GENERATE_BITS,
    SHIPPED_BITS,
    GroupParams,
    as_group,
    estimate_generation_seconds,
    generate_safe_prime_group,
    get_group,
    shipped_group,
    sieve_window,
)
from encctl_gym.errors import ConfigError, EncctlError, GroupError, ParameterError, ResourceLimitError

# Toy group used for known answers (hand-checked):
#   p = 23 = 2 * 11 + 1, q = 11, g = 4 = 2^2.
#   Powers of 4 mod 23: 4, 16, 18, 3, 12, 2, 8, 9, 13, 6, 1  (4^11 = 1), so
#   G = {1, 2, 3, 4, 6, 8, 9, 12, 13, 16, 18} = the quadratic residues mod 23.
TOY = GroupParams(23, 11, 4)
TOY_G = {1, 2, 3, 4, 6, 8, 9, 12, 13, 16, 18}


# ---------------------------------------------------------------------------- arith
def test_powmod_invert_known_answers():
    assert powmod(4, 3, 23) == 18  # 64 - 46
    assert powmod(12, -3, 23) == 8  # 12 = 4^5, 12^-3 = 4^-15 = 4^7 = 8
    assert invert(12, 23) * 12 % 23 == 1
    with pytest.raises(ParameterError, match="no inverse"):
        invert(6, 12)
    with pytest.raises(ParameterError):
        powmod(6, -1, 12)


def test_powmod_counter_counts_calls():
    before = arith.powmod_count()
    with PowmodCounter() as c:
        for _ in range(5):
            powmod(3, 5, 7)
    assert c.count == 5
    assert arith.powmod_count() == before + 5


def test_is_prime_and_jacobi():
    assert [n for n in range(30) if is_prime(n)] == [2, 3, 5, 7, 11, 13, 17, 19, 23, 29]
    assert not is_prime(561)  # Carmichael number
    assert not is_prime(-7)
    # The Legendre symbol mod 23 is +1 exactly on G.
    assert {m for m in range(1, 23) if jacobi(m, 23) == 1} == TOY_G
    assert arith.legendre(5, 23) == -1


def test_seeded_random_is_reproducible_and_uniform():
    a, b, c = seeded_random(7), seeded_random(7), seeded_random(8)
    sa = [a.below(10**30) for _ in range(20)]
    assert sa == [b.below(10**30) for _ in range(20)]
    assert sa != [c.below(10**30) for _ in range(20)]
    assert not a.secure and SecureRandom().secure
    # Uniformity on a small range: 14000 draws in 7 cells, each expected 2000.
    counts = np.bincount([a.below(7) for _ in range(14000)], minlength=7)
    chi2 = float(((counts - 2000) ** 2 / 2000).sum())
    assert chi2 < 30.0  # 6 degrees of freedom; p ~ 4e-5 for 30
    assert all(0 <= secure_random().below(5) < 5 for _ in range(200))
    assert {secure_random().below(2) for _ in range(200)} == {0, 1}


def test_as_random_source_and_bad_bounds():
    assert isinstance(as_random_source(None), SecureRandom)
    assert isinstance(as_random_source(3), SeededRandom)
    src = SeededRandom(1)
    assert as_random_source(src) is src
    g1 = as_random_source(np.random.default_rng(5))
    g2 = as_random_source(np.random.default_rng(5))
    assert g1.below(10**9) == g2.below(10**9)
    for bad in ("seed", 1.5, True, [1]):
        with pytest.raises(ParameterError):
            as_random_source(bad)
    with pytest.raises(ParameterError):
        seeded_random(-1)
    for bad_n in (0, -3, 2.5):
        with pytest.raises(ParameterError):
            src.below(bad_n)
    with pytest.raises(ParameterError):
        src.between(5, 5)
    with pytest.raises(NotImplementedError):
        RandomSource().below(3)


# Non-integers that gmpy2 would refuse with a bare TypeError (or, for 2.5 and 2.0**64, that would
# lose digits). By the package's one integer rule (_validation.check_int) an integral float up to
# 2^53, such as 3.0, is exactly its integer and accepted (tests/test_validation_integers.py).
NON_INTEGERS = [2.5, 2.0**64, np.float64(2.0**60), "7", None, [7], True, 2 + 0j]


@pytest.mark.parametrize("bad", NON_INTEGERS, ids=repr)
@pytest.mark.parametrize(
    "call, position",
    [
        (powmod, 0),
        (powmod, 1),
        (powmod, 2),
        (mulmod, 0),
        (mulmod, 1),
        (mulmod, 2),
        (invert, 0),
        (invert, 1),
        (jacobi, 0),
        (jacobi, 1),
        (legendre, 0),
        (legendre, 1),
    ],
    ids=lambda v: getattr(v, "__name__", str(v)),
)
def test_arith_refuses_non_integers_naming_the_value(call, position, bad):
    args = {powmod: [3, 5, 7], mulmod: [3, 5, 7], invert: [3, 7], jacobi: [3, 7], legendre: [3, 7]}[call]
    args[position] = bad
    with pytest.raises(ParameterError, match=r"must be an integer.*got " + re.escape(format_value(bad))):
        call(*args)


@pytest.mark.parametrize("mod", [1, 0, -7], ids=repr)
def test_moduli_must_exceed_one(mod):
    # gmpy2 alone returns residues in (mod, 0] for a negative modulus (powmod(3, 5, -7) = -2) and 0 modulo 1
    for call, args in ((powmod, (3, 5, mod)), (mulmod, (3, 5, mod)), (invert, (3, mod))):
        with pytest.raises(ParameterError, match=rf"mod must be an integer > 1, got {mod}"):
            call(*args)


@pytest.mark.parametrize("n", [4, 0, -7, -1], ids=repr)
def test_jacobi_needs_an_odd_positive_modulus(n):
    with pytest.raises(ParameterError, match=rf"odd n > 0, got n = {n}"):
        jacobi(3, n)


@pytest.mark.parametrize("p", [1, 4, 0, -7, 9, 15, 561], ids=repr)
def test_legendre_needs_an_odd_prime(p):
    # 9, 15 and 561 are odd composites: (a/p) there is a Jacobi symbol and does not tell squares
    with pytest.raises(ParameterError, match=rf"odd prime p, got p = {p}"):
        legendre(2, p)


def test_arith_accepts_every_exact_integer_type_with_known_answers():
    # 3^5 = 243 = 34 * 7 + 5; 6 * 5 = 30 = 4 * 7 + 2; 3 * 5 = 15 = 2 * 7 + 1
    for t in (int, gmpy2.mpz, np.int64, np.uint8):
        assert powmod(t(3), t(5), t(7)) == 5
        assert mulmod(t(6), t(5), t(7)) == 2
        assert invert(t(3), t(7)) == 5
    # (2/15) = (2/3)(2/5) = (-1)(-1) = 1 although 2 is not a square modulo 15; 3^2 = 9 = 2 (mod 7)
    assert jacobi(np.int64(2), np.int64(15)) == 1 and legendre(np.int64(2), 7) == 1 and legendre(3, 7) == -1
    assert check_integer("x", np.int16(-4)) == -4 and type(check_integer("x", np.int16(-4))) is int
    big = gmpy2.mpz(2) ** 600
    assert check_integer("x", big) is big


@pytest.mark.parametrize("reps", [0, -1, MAX_PRIMALITY_REPS + 1, 2.5, "a", None, True], ids=repr)
def test_is_prime_checks_n_and_reps(reps):
    with pytest.raises(ParameterError, match="reps"):
        is_prime(7, reps)
    assert is_prime(7, 1) and is_prime(7, MAX_PRIMALITY_REPS) and not is_prime(9, 1)
    for bad in (2.5, "7", None, [7]):
        with pytest.raises(ParameterError, match=r"n must be an integer"):
            is_prime(bad)


def test_between_checks_its_bounds():
    src = seeded_random(3)
    for bad in ("9", None, 2.5, True):
        with pytest.raises(ParameterError, match=r"high must be an integer.*got " + re.escape(format_value(bad))):
            src.between(1, bad)
    with pytest.raises(ParameterError, match="low must be an integer"):
        src.between(1.5, 5)  # 1.0 is exactly 1 (the one integer rule); 1.5 is no integer
    assert all(10 <= seeded_random(4).between(np.int64(10), gmpy2.mpz(12)) < 12 for _ in range(5))
    # the same draws whatever integer type the bounds have
    assert seeded_random(5).between(np.int32(7), 10**30) == seeded_random(5).between(7, 10**30)


@settings(max_examples=60, deadline=None)
@given(base=st.integers(-(10**30), 10**30), exp=st.integers(0, 10**6), mod=st.integers(2, 10**30))
def test_powmod_and_mulmod_equal_python_and_never_leave_zero_to_mod(base, exp, mod):
    assert powmod(base, exp, mod) == pow(base, exp, mod)
    assert mulmod(base, exp, mod) == base * exp % mod
    assert 0 <= powmod(base, exp, mod) < mod
    with pytest.raises(ParameterError):
        powmod(base, exp, -mod)


def test_check_rng_refuses_bad_values_without_drawing():
    gen = np.random.default_rng(0)
    state = gen.bit_generator.state
    assert check_rng(gen) is gen and gen.bit_generator.state == state
    src = seeded_random(1)
    assert check_rng(src) is src and check_rng(None) is None and check_rng(np.int64(5)) == 5
    for bad, match in (("seed", "'seed'"), (2.5, "2.5"), ([1], r"\[1\]"), (True, "True"), (-1, ">= 0, got -1")):
        with pytest.raises(ParameterError, match=match):
            check_rng(bad)
        # a shipped size is not generated, but a bad rng is refused all the same
        with pytest.raises(ParameterError, match=match):
            get_group(64, rng=bad)
        with pytest.raises(ParameterError, match=match):
            as_group(shipped_group(64), rng=bad)
    assert get_group(64, rng=gen) is not None and gen.bit_generator.state == state


# ---------------------------------------------------------------------------- group
def test_toy_group_known_answers():
    assert TOY.bits == 5 and TOY.cofactor == 2 and TOY.is_safe_prime and TOY.half == 11
    assert TOY.verify() is TOY and TOY.verified
    assert {m for m in range(25) if TOY.contains(m)} == TOY_G
    assert {powmod(4, i, 23) for i in range(11)} == TOY_G


def test_group_accepts_mpz_and_hex_and_stores_ints():
    g = GroupParams(gmpy2.mpz(23), "0xb", np.int64(4))
    assert g == TOY and type(g.p) is int and type(g.q) is int and type(g.g) is int


@pytest.mark.parametrize(
    "p, q, g, match",
    [
        (24, 11, 4, "does not divide"),  # 11 does not divide 23
        (23, 11, 1, "1 < g < p"),  # g = 1
        (23, 11, 23, "1 < g < p"),
        (23, 1, 4, "q must be"),
        (23, 2, 22, "q must be an odd prime"),  # G = {1, 22}: the only key s = 1 is public
        (5, 2, 4, "q must be an odd prime"),
        (3, 2, 2, "p must be"),
        ("x", 11, 4, "integer"),
        (23.5, 11, 4, "integer"),
    ],
)
def test_group_construction_errors(p, q, g, match):
    with pytest.raises(GroupError, match=match):
        GroupParams(p, q, g)


@pytest.mark.parametrize(
    "p, q, g, match",
    [
        (27, 13, 4, "p is not prime: p = 27"),  # 26 = 2 * 13 but 27 = 3^3
        (23, 22, 4, "q is not prime: q = 22"),
        (23, 11, 5, "g = 5 does not have order q"),  # 5 is a non-residue: 5^11 = -1
        (23, 11, 22, "g = 22 does not have order q"),  # 22 = -1 has order 2
        (2 * 1000003 + 1, 1000003, 4, "p is not prime"),  # 2000007 = 3 * 666669
    ],
)
def test_group_verify_errors(p, q, g, match):
    grp = GroupParams(p, q, g)
    with pytest.raises(GroupError, match=match):
        grp.verify()
    assert not grp.verified
    with pytest.raises(GroupError):
        keygen(grp)  # keys are never made over unverified parameters


def test_group_with_other_cofactor_loads_and_verifies():
    # p = 29 = 4 * 7 + 1; 2 is a primitive root mod 29, so 16 = 2^4 has order 7.
    g = GroupParams(29, 7, 16).verify()
    assert g.cofactor == 4 and not g.is_safe_prime
    members = {m for m in range(1, 29) if g.contains(m)}
    assert members == {powmod(16, i, 29) for i in range(7)}
    assert len(members) == 7
    with pytest.raises(GroupError, match="does not have order"):
        GroupParams(29, 7, 2).verify()  # 2 has order 28


def test_json_roundtrip(tmp_path):
    grp = shipped_group(128)
    text = grp.to_json()
    assert GroupParams.from_json(text) == grp
    assert json.loads(text)["bits"] == 128
    path = tmp_path / "g.json"
    grp.save(path)
    assert GroupParams.load(path) == grp
    bad = json.loads(text)
    bad["bits"] = 127
    with pytest.raises(GroupError, match="declared bits"):
        GroupParams.from_dict(bad)
    with pytest.raises(GroupError, match="invalid group JSON"):
        GroupParams.from_json("{not json")
    with pytest.raises(GroupError, match="fields p, q, g"):
        GroupParams.from_dict({"p": 23})
    with pytest.raises(GroupError):
        GroupParams.from_json("[1, 2]")
    (tmp_path / "bad.json").write_text(GroupParams(27, 13, 4).to_json())
    with pytest.raises(GroupError, match="p is not prime"):
        GroupParams.load(tmp_path / "bad.json")


def test_group_files_that_cannot_be_read_are_config_errors(tmp_path):
    grp = shipped_group(64)
    missing = tmp_path / "missing.json"
    with pytest.raises(ConfigError, match=r"cannot read the group file .*missing\.json"):
        GroupParams.load(missing)
    with pytest.raises(ConfigError, match="cannot read the group file"):
        GroupParams.load(tmp_path)  # a directory
    junk = tmp_path / "junk.json"
    junk.write_bytes(bytes(range(256)))
    with pytest.raises(ConfigError, match=r"junk\.json' is not UTF-8 text"):
        GroupParams.load(junk)
    utf16 = tmp_path / "utf16.json"
    utf16.write_bytes(grp.to_json().encode("utf-16"))
    with pytest.raises(ConfigError, match="not UTF-8"):
        GroupParams.load(utf16)
    big = tmp_path / "big.json"
    with big.open("wb") as f:  # sparse: larger than the bound on paper only
        f.seek(MAX_GROUP_FILE_BYTES)
        f.write(b" ")
    with pytest.raises(ConfigError, match=rf"more than MAX_GROUP_FILE_BYTES = {MAX_GROUP_FILE_BYTES}"):
        GroupParams.load(big)
    # a file of exactly the bound is read (and then refused for its content only)
    with big.open("r+b") as f:
        f.truncate(MAX_GROUP_FILE_BYTES)
    with pytest.raises(GroupError, match="invalid group JSON"):
        GroupParams.load(big)
    for target in (tmp_path, tmp_path / "no" / "such" / "g.json"):
        with pytest.raises(ConfigError, match="cannot write the group file"):
            grp.save(target)


@pytest.mark.parametrize(
    "text, match",
    [
        (None, "must be a str or bytes, got None"),
        (42, "must be a str or bytes, got 42"),
        (["{}"], "must be a str or bytes"),
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
        ('{"p": ' + "9" * 5000 + ', "q": 11, "g": 4}', "invalid group JSON"),
        (b"\xff\xfe", "invalid group JSON"),
    ],
    ids=["None", "int", "list", "deep", "digits", "bad-bytes"],
)
def test_from_json_refuses_non_text_and_deep_nesting(text, match):
    with pytest.raises(GroupError, match=match):
        GroupParams.from_json(text)


def test_group_methods_check_their_argument_types(tmp_path):
    grp = shipped_group(64)
    assert grp.contains(np.int64(4)) and grp.contains(gmpy2.mpz(4)) and not grp.contains(0)  # 4 = g is in G
    for bad in ("4", 2.5, None, [4]):
        with pytest.raises(ParameterError, match=r"m must be an integer.*got " + re.escape(format_value(bad))):
            grp.contains(bad)
    for bad in ("no", 1, None):
        with pytest.raises(ParameterError, match=r"recheck must be True or False, got " + re.escape(format_value(bad))):
            grp.verify(recheck=bad)
    assert grp.verify(recheck=np.bool_(True)) is grp
    path = tmp_path / "g.json"
    grp.save(str(path))
    assert GroupParams.load(str(path)) == grp
    for bad in (42, None, ["g.json"]):
        with pytest.raises(ParameterError, match=r"path must be a str or a path, got " + re.escape(format_value(bad))):
            GroupParams.load(bad)
        with pytest.raises(ParameterError, match="path must be a str or a path"):
            grp.save(bad)
    with pytest.raises(ParameterError, match="verify must be True or False, got 'no'"):
        GroupParams.load(path, verify="no")
    for bad in (np.array([23, 11, 4]), [23, 11, 4], "abc", None):
        with pytest.raises(GroupError, match="group data must be a mapping with fields p, q, g"):
            GroupParams.from_dict(bad)
    with pytest.raises(ParameterError, match="progress must be True or False, got 'no'"):
        generate_safe_prime_group(32, rng=1, progress="no")


def test_from_json_reads_utf8_bytes():
    grp = shipped_group(128)
    assert GroupParams.from_json(grp.to_json().encode("utf-8")) == grp


def _assert_safe_prime_group(grp: GroupParams, bits: int) -> None:
    assert grp.bits == bits and grp.p == 2 * grp.q + 1
    assert gmpy2.is_prime(grp.p) and gmpy2.is_prime(grp.q)
    assert grp.g != 1 and pow(grp.g, grp.q, grp.p) == 1


@pytest.mark.parametrize("bits", [MIN_GENERATE_BITS, 17, 32, 64, 100, 256, 512])
def test_generate_safe_prime_group(bits):
    grp = generate_safe_prime_group(bits, rng=bits)
    _assert_safe_prime_group(grp, bits)
    assert generate_safe_prime_group(bits, rng=bits) == grp  # reproducible from a seed


def test_generate_progress_goes_to_stderr(capsys):
    generate_safe_prime_group(128, rng=3, progress=True)
    captured = capsys.readouterr()
    assert "generated 128-bit safe prime" in captured.err and captured.out == ""


@pytest.mark.parametrize("bits", [712, pytest.param(1024, marks=pytest.mark.slow)])
def test_generation_at_key_sizes(bits):
    # Its time against estimate_generation_seconds: benchmarks/bench_crypto.py.
    _assert_safe_prime_group(generate_safe_prime_group(bits, rng=11), bits)


@pytest.mark.slow
def test_generate_2048():
    _assert_safe_prime_group(generate_safe_prime_group(2048, rng=1), 2048)


@pytest.mark.parametrize("bits", [15, 8, 0, -64, 64.5, 64.0, "64", True, None])
def test_generate_rejects_bad_bits(bits):
    with pytest.raises(ParameterError, match="bits"):
        generate_safe_prime_group(bits)
    with pytest.raises(ParameterError, match="bits"):
        get_group(bits)


def test_shipped_groups_are_safe_prime_groups_and_verify_fast():
    assert SHIPPED_BITS == (64, 128, 256, 512, 712, 1024, 2048)
    for bits in SHIPPED_BITS:
        grp = shipped_group(bits)
        _assert_safe_prime_group(grp, bits)
        assert get_group(bits) == grp
    # Verification from scratch exponentiates once (g^q; the primality tests are not counted),
    # a cached verification not at all (its time: benchmarks/bench_crypto.py).
    big = shipped_group(2048)
    with PowmodCounter() as c:
        assert big.verify(recheck=True) is big
    assert c.count == 1
    with PowmodCounter() as c:
        shipped_group(2048)
        big.verify()
    assert c.count == 0
    with pytest.raises(ParameterError, match="no shipped group of 100 bits"):
        shipped_group(100)


def test_get_group_generates_unshipped_sizes():
    grp = get_group(48, rng=2)
    _assert_safe_prime_group(grp, 48)


def test_errors_are_package_errors():
    with pytest.raises(EncctlError):
        GroupParams(27, 13, 4).verify()
    with pytest.raises(ValueError):  # GroupError is also a ValueError
        GroupParams(27, 13, 4).verify()


# ---------------------------------------------------------------------------- generation: bounded by an estimate
def test_sieve_strikes_exactly_the_candidates_with_small_factors():
    limit, q0, n = 200, (1 << 40) + 1, 3000
    primes = [ell for ell in range(3, limit) if is_prime(ell)]
    kept = set(sieve_window(q0, n, limit).tolist())
    for k in range(n):
        q = q0 + 2 * k
        has_small = any(q % ell == 0 or (2 * q + 1) % ell == 0 for ell in primes)
        assert (k in kept) == (not has_small), k


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"n_cand": -1}, "n_cand must be >= 0"),
        ({"n_cand": MAX_SIEVE_WINDOW + 1}, f"n_cand must be <= {MAX_SIEVE_WINDOW}"),
        ({"n_cand": 10**12}, f"n_cand must be <= {MAX_SIEVE_WINDOW}"),
        ({"n_cand": 2.5}, "n_cand must be an integer, got 2.5"),
        ({"limit": 2}, "limit must be >= 3"),
        ({"limit": MAX_SIEVE_LIMIT + 1}, f"limit must be <= {MAX_SIEVE_LIMIT}"),
        ({"limit": "a"}, "limit must be an integer, got 'a'"),
        ({"q0": -5}, "q0 must be odd and >= limit = 1000.*got -5"),
        ({"q0": 10**6}, "q0 must be odd.*got 1000000"),
        ({"q0": 999}, "q0 must be odd and >= limit = 1000.*got 999"),
        ({"q0": 2.5}, "q0 must be an integer.*got 2.5"),
    ],
    ids=lambda v: str(v),
)
def test_sieve_window_is_bounded_and_checks_its_arguments(kwargs, match):
    args = {"q0": 10**6 + 1, "n_cand": 100, "limit": 1000, **kwargs}
    with pytest.raises(ParameterError, match=match):
        sieve_window(**args)


def test_sieve_window_edges():
    assert sieve_window(1001, 0, 1000).size == 0
    # q0 = limit = 101: candidates 101, 103, ..., 119; kept iff q and 2q + 1 have no odd prime
    # factor below 101: 101 (203 = 7 * 29: out), 103 (207 = 9 * 23: out), 105 = 3 * 35 (out),
    # 107 (215 = 5 * 43: out), 109 (219 = 3 * 73: out), 111 = 3 * 37 (out), 113 (227 prime: kept),
    # 115 = 5 * 23 (out), 117 = 9 * 13 (out), 119 = 7 * 17 (out)
    assert sieve_window(101, 10, 101).tolist() == [6]
    with pytest.raises(ParameterError, match=f"window must be <= {MAX_SIEVE_WINDOW}"):
        generate_safe_prime_group(64, rng=1, window=MAX_SIEVE_WINDOW + 1)


def test_sieve_survival_matches_the_product_of_the_estimate():
    # The estimate keeps the fraction prod_l (1 - 2/l) of the candidates; count in real windows.
    limit = 1 << 16
    primes = np.array([ell for ell in range(3, limit) if is_prime(ell)], dtype=float)
    expected = float(np.prod(1.0 - 2.0 / primes))
    src = seeded_random(4)
    kept = sum(sieve_window(src.between(1 << 500, 1 << 501) | 1, 1 << 14, limit).size for _ in range(20))
    frac = kept / (20 * (1 << 14))
    assert abs(frac - expected) < 5 * (expected / (20 * (1 << 14))) ** 0.5 + 0.03 * expected


def test_sophie_germain_density_used_by_the_estimate():
    """Hardy-Littlewood: Sophie Germain primes q near x have density 4 C2 / (ln x ln 2x) among odd q."""
    x0, n = 1 << 30, 100_000
    count = sum(1 for k in range(n) if is_prime(x0 + 1 + 2 * k) and is_prime(2 * (x0 + 1 + 2 * k) + 1))
    expected = n * 4 * 0.6601618158468696 / (math.log(x0) * math.log(2 * x0))
    assert abs(count - expected) < 4 * expected**0.5 + 0.05 * expected  # ~590 expected


def test_generation_estimate_grows_with_bits_and_is_finite_for_any_size():
    sizes = [16, 64, 256, 512, 712, 1024, 1536, 2048, 2538, 3072, 4096, 8192, 2_560_000]
    est = [estimate_generation_seconds(b) for b in sizes]
    assert all(0 < e < math.inf for e in est)
    assert all(a < b for a, b in zip(est[2:], est[3:]))  # increasing from where the powmod dominates
    assert est[-1] > 1e9  # the 2.56-million-bit prime of the issue
    with pytest.raises(ParameterError, match="bits"):
        estimate_generation_seconds(8)


def test_generation_is_refused_before_it_starts_when_the_estimate_exceeds_the_limit():
    big = estimate_generation_seconds(4096)
    refusals = [
        (lambda: generate_safe_prime_group(2_560_000), r"2560000-bit safe-prime group is estimated to take"),
        (lambda: get_group(2_560_000), "max_seconds = 60 s"),
        (lambda: keygen(2_560_000, rng=1), "max_seconds = 60 s"),
        (lambda: generate_safe_prime_group(4096), f"{big:.3g} s"),
        (lambda: generate_safe_prime_group(3000, max_seconds=1.0), "3000-bit"),
    ]
    with PowmodCounter() as counter:
        for call, match in refusals:
            with pytest.raises(ResourceLimitError, match=match):
                call()
    assert counter.count == 0  # refused before the search started (no Fermat test ran)
    assert DEFAULT_MAX_GENERATION_SECONDS == 60.0
    for bad in (0.0, -1.0, math.nan, math.inf, "60"):
        with pytest.raises(ParameterError, match="max_seconds"):
            generate_safe_prime_group(64, max_seconds=bad)
    # Within the limit it runs as before.
    _assert_safe_prime_group(generate_safe_prime_group(96, rng=1, max_seconds=1.0), 96)


def test_int_seed_of_generation_is_keyed_by_the_purpose_group():
    assert generate_safe_prime_group(80, rng=9) == generate_safe_prime_group(80, rng=seeded_random(9, "group"))
    assert generate_safe_prime_group(80, rng=9) != generate_safe_prime_group(80, rng=seeded_random(9))


def test_error_messages_survive_integers_beyond_the_int_to_str_limit():
    big = 10**5000 + 1  # 5001 decimal digits; str(big) raises ValueError in Python >= 3.11
    assert arith.format_int(23) == "23" and arith.format_int(-(2**255)) == str(-(2**255))
    assert arith.format_int(big).endswith("(16610 bits)") and arith.format_int("x") == "'x'"
    with pytest.raises(GroupError, match=r"p has 16610 bits, more than MAX_GROUP_BITS = 16384"):
        GroupParams(big, 5, 4)
    composite = 10**1000 + 1  # 3322 bits, composite; p - 1 = 10^1000 is divisible by 5
    with pytest.raises(GroupError, match=r"p is not prime: p = 0x[0-9a-f]+\.\.\.[0-9a-f]+ \(3322 bits\)"):
        GroupParams(composite, 5, 4).verify()
    with pytest.raises(GroupError, match=r"q = 11 does not divide p - 1 = 0x.*\(3322 bits\)"):
        GroupParams(composite, 11, 4)
    with pytest.raises(GroupError, match=r"declared bits = 0x.*\(16610 bits\)"):
        GroupParams.from_dict({"p": composite, "q": 5, "g": 4, "bits": big})
    with pytest.raises(GroupError, match="invalid group JSON: Exceeds the limit"):
        GroupParams.from_json('{"p": ' + "9" * 5000 + ', "q": 5, "g": 4}')
    with pytest.raises(GroupError, match=r"\(100001 characters\)"):
        GroupParams("9" * 100_001, 5, 4)  # beyond int()'s digit limit too
    # Sizes beyond any float: the estimate is infinite, generation refused at once.
    assert estimate_generation_seconds(10**400) == math.inf
    with pytest.raises(ResourceLimitError, match="estimated to take inf s"):
        generate_safe_prime_group(10**400)
    with pytest.raises(GroupError, match="fields"):
        GroupParams.from_dict([big])
    with pytest.raises(ParameterError, match="no inverse"):
        invert(big - 1, big - 1)
    with pytest.raises(ParameterError, match=r"rng=0x.*\(16610 bits\)"):
        arith.as_random_stream(big, "encrypt")
    assert "16610 bits" in repr(seeded_random(big))
