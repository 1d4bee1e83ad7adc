"""Tests of the encoder/decoder of Definition def:ec (crypto.encoding)."""

from __future__ import annotations

import math
import re
from fractions import Fraction

import gmpy2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym._validation import format_value
from encctl_gym.crypto.arith import PowmodCounter, seeded_random
from encctl_gym.crypto.elgamal import decrypt, encrypt, keygen
from encctl_gym.crypto.encoding import (
    DEFAULT_MAX_SHIFT,
    Encoder,
    decode_int,
    decode_scaled,
    default_max_shift,
    encode_int,
    lift,
    nearest_member,
)
from encctl_gym.crypto.group import GroupParams, shipped_group
from encctl_gym.errors import EncodingOverflowError, GroupError, ParameterError, PlaintextError

TOY = GroupParams(23, 11, 4)  # G = {1, 2, 3, 4, 6, 8, 9, 12, 13, 16, 18}
G64, G128 = shipped_group(64), shipped_group(128)


def test_known_answers_toy_group():
    # Delta = 1, max_shift = 2: representable |round(x)| <= 11 - 2 = 9.
    enc = Encoder(TOY, 1.0, max_shift=2)
    cases = {
        # x: (signed w, plaintext, shift)
        5: (6, 6, 1),  # 5 not in G; 6 is
        -5: (-5, 18, 0),  # -5 = 18 mod 23 is in G: stored as p - |v|
        0: (1, 1, 1),  # 0 is never in G; +1 is tried first
        7: (8, 8, 1),
        9: (9, 9, 0),
        -1: (1, 1, 2),  # -1 = 22 no, 0 excluded, -2 = 21 no, 1 yes
        -9: (-10, 13, 1),  # -9 = 14 no, -8 = 15 no, -10 = 13 yes
        2.4: (2, 2, 0),  # round(2.4) = 2
        2.5: (2, 2, 0),  # round half to even
        3.5: (4, 4, 0),
    }
    for x, (w, m, s) in cases.items():
        assert enc.encode_signed(x) == w, x
        assert enc.encode_with_shift(x) == (m, s), x
        assert enc.encode(x) == m
        assert enc.decode(m) == float(w)
    assert decode_int(TOY, 18) == -5 and decode_int(TOY, 11) == 11 and decode_int(TOY, 12) == -11
    assert encode_int(TOY, -5, max_shift=2) == 18
    assert nearest_member(TOY, 10, 2) == (9, 1)  # 10 no, 11 no, 9 yes


def test_zero_encodes_to_one_in_safe_prime_groups():
    for grp in (G64, G128, shipped_group(712)):
        enc = Encoder(grp, 2.0**10)
        assert enc.encode(0.0) == 1 and enc.decode(1) == 2.0**-10


def test_max_shift_exceeded_raises():
    enc = Encoder(TOY, 1.0, max_shift=0)
    assert enc.encode(4) == 4
    with pytest.raises(PlaintextError, match="no element of the order-q subgroup within max_shift = 0 of v = 5"):
        enc.encode(5)
    with pytest.raises(PlaintextError, match="max_shift = 1 of v = -1"):
        nearest_member(TOY, -1, 1)


@settings(max_examples=300, deadline=None)
@given(x=st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False), log_delta=st.integers(0, 30), big=st.booleans())
def test_roundtrip_error_bound(x, log_delta, big):
    """|Dcd(Ecd(x)) - x| <= (1/2 + s)/Delta, with s the reported shift (exact for Delta = 2^k)."""
    grp = G128 if big else G64
    enc = Encoder(grp, 2.0**log_delta)
    m, s = enc.encode_with_shift(x)
    assert grp.contains(m) and 0 <= s <= enc.max_shift
    err = abs(Fraction(enc.decode(m)) - Fraction(x))
    assert err <= (Fraction(1, 2) + s) / Fraction(enc.delta)
    assert abs(enc.decode(m) - x) <= enc.error_bound(s)


@settings(max_examples=200, deadline=None)
@given(x=st.floats(-1e3, 1e3, allow_nan=False), delta=st.floats(0.5, 1e6))
def test_roundtrip_error_bound_any_delta(x, delta):
    """For a Delta that is not a power of two, the bound holds up to the double rounding of Delta*x."""
    enc = Encoder(G128, delta)
    m, s = enc.encode_with_shift(x)
    slack = 4 * math.ulp(abs(delta * x) + 1.0) / delta
    assert abs(enc.decode(m) - x) <= (0.5 + s) / delta + slack


def test_shift_statistics_are_small():
    enc = Encoder(shipped_group(712), 2.0**20)
    xs = np.linspace(-100, 100, 2001)
    shifts = [enc.encode_with_shift(float(x))[1] for x in xs]
    assert max(shifts) < 20 and np.mean(shifts) < 2.0


def test_membership_uses_jacobi_not_powmod_for_safe_primes():
    enc = Encoder(shipped_group(712), 2.0**16)
    with PowmodCounter() as c:
        enc.encode_signed_array(np.linspace(-5, 5, 101))
    assert c.count == 0


def test_other_cofactor_uses_powmod_membership():
    # p = 29 = 4 * 7 + 1, g = 16 of order 7: G = {1, 7, 16, 20, 23, 24, 25}.
    grp = GroupParams(29, 7, 16).verify()
    members = {m for m in range(1, 29) if pow(m, 7, 29) == 1}
    assert members == {1, 7, 16, 20, 23, 24, 25}
    assert default_max_shift(grp) == DEFAULT_MAX_SHIFT * 2
    enc = Encoder(grp, 1.0, max_shift=6)  # representable |v| <= 14 - 6 = 8
    with PowmodCounter() as c:
        w, s = nearest_member(grp, 3, 6)  # 3, 4, 2, 5, 1 -> 1 is the first member
    assert (w, s) == (1, 2) and c.count == 5
    for x in range(-8, 9):
        m = enc.encode(x)
        assert m in members
        assert abs(enc.decode(m) - x) <= 0.5 + 6
    # Full ElGamal round trip in that group.
    pk, sk = keygen(grp, 4)
    assert decrypt(sk, encrypt(pk, enc.encode(-3), seeded_random(5))) == enc.encode(-3)
    with pytest.raises(ParameterError, match="cofactor"):
        q = 1009
        n = next(n for n in range(2000, 4000, 2) if gmpy2.is_prime(n * q + 1))
        default_max_shift(GroupParams(n * q + 1, q, pow(3, n, n * q + 1)))


def test_vectorised_matches_scalar():
    enc = Encoder(G128, 1000.0)
    X = np.array([[0.1234, -5.0, 0.0], [1e-9, -1e-3, 7.77]])
    W = enc.encode_signed_array(X)
    assert W.shape == X.shape and W.dtype == object
    for idx in np.ndindex(X.shape):
        assert W[idx] == enc.encode_signed(X[idx]) and W[idx] % G128.p == enc.encode(X[idx])
        assert enc.decode_signed_array(W)[idx] == enc.decode(enc.encode(X[idx]))
    assert np.array_equal(enc.quantize_array(X), np.vectorize(enc.quantize)(X))
    assert enc.decode(enc.encode(2.0) * enc.encode(3.0) % G128.p, power=2) == pytest.approx(6.0, abs=1e-2)


def test_decode_is_exact_division():
    # The decoded float is the correctly rounded quotient w / Delta^k (Fraction arithmetic).
    enc = Encoder(G128, 0.1)  # 0.1 is not exact in binary; the ratio of the double is used.
    for w in (1, -3, 12345678901234567, -(G128.half - 5)):
        exact = Fraction(w) / Fraction(0.1) ** 2
        assert enc.decode_signed(w, power=2) == float(exact)


def test_overflow_is_never_silent():
    enc = Encoder(G64, 2.0**20, x_bound=100.0)
    assert abs(enc.decode(enc.encode(-100.0)) + 100.0) <= enc.error_bound()
    with pytest.raises(EncodingOverflowError, match=r"x = 100.5 is outside the declared input range \|x\| <= 100.0"):
        enc.encode(100.5)
    with pytest.raises(EncodingOverflowError, match="x = -1000.0"):
        enc.encode_signed_array([1.0, -1000.0])
    # Without a declared bound, the representable range of the group is the limit.
    free = Encoder(G64, 2.0**40)
    limit = (G64.half - free.max_shift) / 2.0**40
    free.encode(limit * 0.999)
    with pytest.raises(EncodingOverflowError, match="not representable"):
        free.encode(limit * 1.001)
    with pytest.raises(EncodingOverflowError, match="x_bound"):
        Encoder(G64, 2.0**40, x_bound=1e9)
    with pytest.raises(EncodingOverflowError, match="overflows a float"):
        Encoder(G64, 1e300).encode(1e10)
    with pytest.raises(EncodingOverflowError):
        encode_int(TOY, 11, max_shift=2)  # 11 -> nearest member 12 > (p-1)/2


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf"), "1.0", None, True])
def test_non_finite_inputs_raise_parameter_error(bad):
    enc = Encoder(G64, 100.0)
    with pytest.raises(ParameterError):
        enc.encode(bad)
    if bad is not None and not isinstance(bad, (str, bool)):
        with pytest.raises(ParameterError, match="finite"):
            enc.encode_signed_array([0.0, bad])


@pytest.mark.parametrize("delta", [0, -1.0, float("nan"), float("inf"), "2", None])
def test_bad_delta(delta):
    with pytest.raises(ParameterError, match="delta"):
        Encoder(G64, delta)


def test_bad_encoder_arguments():
    with pytest.raises(ParameterError, match="GroupParams"):
        Encoder(23, 1.0)
    with pytest.raises(ParameterError, match="x_bound"):
        Encoder(G64, 1.0, x_bound=-1.0)
    with pytest.raises(ParameterError, match="x_bound"):
        Encoder(G64, 1.0, x_bound=float("nan"))
    with pytest.raises(ParameterError, match="max_shift"):
        Encoder(G64, 1.0, max_shift=-1)
    with pytest.raises(PlaintextError, match="outside"):
        decode_int(TOY, 23)
    with pytest.raises(PlaintextError, match="integer"):
        decode_int(TOY, 2.5)
    assert decode_int(TOY, 2.0) == decode_int(TOY, 2)  # the one integer rule: 2.0 is exactly 2


# ---------------------------------------------------------------------------- bad input, arrays and powers
@pytest.mark.parametrize(
    "x",
    [
        [1.0, 2.0 + 3.0j],
        np.array([1.0, 2.0], dtype=np.complex128),  # complex even with a zero imaginary part
        np.array([[0.5 + 0.5j]]),
    ],
)
def test_complex_arrays_are_refused_not_truncated(x):
    enc = Encoder(G64, 2.0**10)
    with pytest.raises(ParameterError, match="complex"):
        enc.encode_signed_array(x)
    with pytest.raises(ParameterError, match="complex"):
        enc.quantize_array(x)
    with pytest.raises(ParameterError, match="real number"):
        enc.encode(2.0 + 3.0j)


@pytest.mark.parametrize(
    "x, match",
    [
        (np.array([True, False]), "boolean array"),  # the messages of _validation.as_finite_array
        (["1.0", "2.0"], "numeric array"),
        ([1.0, "a"], "numeric array"),
        ([[1.0, 2.0], [3.0]], "numeric"),  # ragged
        (np.array([1.0, None], dtype=object), "the entry None"),
        (np.array([1.0, True], dtype=object), "the entry True"),
        (np.array([1.0, 10**400], dtype=object), "within the float64 range"),
    ],
)
def test_non_numeric_arrays_are_refused(x, match):
    enc = Encoder(G64, 2.0**10)
    with pytest.raises((ParameterError, EncodingOverflowError), match=match):
        enc.encode_signed_array(x)


def test_object_arrays_of_real_numbers_are_accepted():
    enc = Encoder(G64, 2.0**10)
    mixed = np.array([1, 2.5, np.float32(-0.75), Fraction(1, 4), gmpy2.mpz(3)], dtype=object)
    w = enc.encode_signed_array(mixed)
    assert list(w) == [enc.encode_signed(float(v)) for v in mixed]


@pytest.mark.parametrize("power", [0, -1, 3, 1.0, 2.5, True, "2", None])
def test_decode_power_is_one_or_two(power):
    enc = Encoder(G64, 2.0**10)
    m = enc.encode(1.5)
    with pytest.raises(ParameterError, match="power must be one of"):
        enc.decode(m, power=power)
    with pytest.raises(ParameterError, match="power must be one of"):
        enc.decode_signed(12, power=power)
    with pytest.raises(ParameterError, match="power must be one of"):
        enc.decode_signed_array([12, 13], power=power)
    # An encoded value at power 1, the product of two at power 2 (exact quotients).
    w1, w2 = enc.encode_signed(1.5), enc.encode_signed(-2.0)
    assert enc.decode(m, power=1) == float(Fraction(w1, 1024))
    assert enc.decode_signed(w1 * w2, power=2) == float(Fraction(w1 * w2, 1024**2))
    assert enc.decode(m, power=np.int64(1)) == enc.decode(m)


@pytest.mark.parametrize("shift", [-5, -1, 65, 2.5, "1", True])
def test_error_bound_needs_a_possible_shift(shift):
    enc = Encoder(G64, 2.0**10)  # max_shift = 64
    with pytest.raises(ParameterError, match="shift"):
        enc.error_bound(shift)


def test_error_bound_known_values():
    enc = Encoder(G64, 4.0)
    assert enc.error_bound(0) == 0.125 and enc.error_bound(3) == 3.5 / 4
    assert enc.error_bound() == (0.5 + 64) / 4 and enc.error_bound(64) == enc.error_bound()


def test_encoder_needs_a_verified_group_and_huge_values_give_one_line_errors():
    with pytest.raises(GroupError, match="p is not prime"):
        Encoder(GroupParams(27, 13, 4), 1.0)  # Jacobi symbols modulo a composite would lie
    with pytest.raises(GroupError):
        encode_int(GroupParams(27, 13, 4), 3)
    enc = Encoder(G64, 2.0**10)
    with pytest.raises(EncodingOverflowError, match=r"x = 0x[0-9a-f]+\.\.\.[0-9a-f]+ \(1329 bits\) is too large"):
        enc.encode(10**400)
    with pytest.raises(EncodingOverflowError, match="too large"):
        Encoder(G64, 2.0**10, x_bound=10**400)
    with pytest.raises(PlaintextError, match=r"\(66439 bits\)"):
        decode_int(G64, 10**20000)  # more than Python's 4300-digit limit of int-to-str


@pytest.mark.parametrize("group", ["abc", 64, None, 23.0], ids=repr)
def test_integer_codec_needs_a_group(group):
    with pytest.raises(ParameterError, match=r"group must be a GroupParams, got " + re.escape(format_value(group))):
        encode_int(group, 5)
    with pytest.raises(ParameterError, match=r"group must be a GroupParams"):
        decode_int(group, 4)


@pytest.mark.parametrize(
    "ratio, match",
    [
        ((0, 1), r"delta_ratio = \(0, 1\) must have num > 0 and den > 0"),
        ((1024, 0), r"delta_ratio = \(1024, 0\)"),
        ((-1, 1), r"delta_ratio = \(-1, 1\)"),
        ((1.5, 1), r"delta_ratio\[0\] must be an integer.*got 1.5"),
        ((1, True), r"delta_ratio\[1\] must be an integer.*got True"),
        ("ab", r"delta_ratio must be a pair \(num, den\).*got 'ab'"),
        ((1, 2, 3), r"delta_ratio must be a pair.*got \(1, 2, 3\)"),
        (None, r"delta_ratio must be a pair.*got None"),
    ],
    ids=lambda v: repr(v),
)
def test_decode_scaled_checks_delta_ratio(ratio, match):
    with pytest.raises(ParameterError, match=match):
        decode_scaled(5, ratio)


@pytest.mark.parametrize("w", [2.5, 2.0**60, "5", None, True], ids=repr)
def test_decode_scaled_needs_an_integer_w(w):
    # a float w would be divided as it is (2.5 / 1024 = 0.00244140625): a silent non-plaintext;
    # an integral float up to 2^53 is exactly its integer (the one integer rule), 2^60 is not
    with pytest.raises(ParameterError, match=r"w must be an integer, got " + re.escape(format_value(w))):
        decode_scaled(w, (1024, 1))


def test_decode_scaled_known_answers_for_every_integer_type():
    # w / Delta^k with Delta = num / den: 5 / 1024; -6 / (3/2)^2 = -6 * 4 / 9 = -8/3
    assert decode_scaled(5, (1024, 1)) == 5 / 1024
    assert decode_scaled(np.int64(-6), (3, 2), 2) == float(Fraction(-8, 3))
    assert decode_scaled(gmpy2.mpz(-6), [np.int64(3), 2], 2) == float(Fraction(-8, 3))
    assert decode_scaled(10**400, (10**399, 1)) == 10.0  # exact integers beyond the float range


@pytest.mark.parametrize("x_bound", [-1.0, -1e-300, float("nan"), "a", 2 + 1j], ids=repr)
def test_max_abs_signed_needs_a_bound(x_bound):
    enc = Encoder(G64, 2.0**10)
    with pytest.raises(ParameterError, match=r"x_bound must be"):
        enc.max_abs_signed(x_bound)


def test_max_abs_signed_known_answers():
    enc = Encoder(G64, 2.0**10)  # max_shift = 64
    assert enc.max_abs_signed(0.0) == 64
    assert enc.max_abs_signed(1.5) == 1536 + 64
    assert enc.max_abs_signed(0.25 / 1024) == 0 + 64  # round(0.25) = 0
    with pytest.raises(EncodingOverflowError, match="overflows a float"):
        Encoder(G64, 1e300).max_abs_signed(1e300)


@pytest.mark.parametrize(
    "call",
    [lambda g: nearest_member(g, 5, 64), lambda g: default_max_shift(g), lambda g: lift(g, 5)],
    ids=["nearest_member", "default_max_shift", "lift"],
)
@pytest.mark.parametrize("group", ["abc", 64, None], ids=repr)
def test_group_functions_need_a_group(call, group):
    with pytest.raises(ParameterError, match=r"group must be a GroupParams, got " + re.escape(format_value(group))):
        call(group)


def test_nearest_member_and_lift_check_their_integers():
    for bad in (2.5, "5", None, True):
        with pytest.raises(ParameterError, match=r"v must be an integer"):
            nearest_member(TOY, bad, 2)
        with pytest.raises(ParameterError, match=r"m must be an integer"):
            lift(TOY, bad)
    for bad in (-1, 2.5, "a"):
        with pytest.raises(ParameterError, match=r"max_shift must be"):
            nearest_member(TOY, 5, bad)
    # in TOY, 5 is not in G = {1, 2, 3, 4, 6, ...}: 6 is tried before 4; 7 -> 8 (+1), 10 -> 9 (-1)
    assert nearest_member(TOY, np.int64(5), np.int64(1)) == (6, 1)
    assert nearest_member(TOY, 7, 1) == (8, 1) and nearest_member(TOY, 10, 1) == (9, 1)
    assert lift(TOY, np.int64(12)) == -11 and lift(TOY, 11) == 11 and lift(TOY, gmpy2.mpz(22)) == -1


def test_max_shift_must_leave_representable_values():
    # TOY: (p - 1)/2 = 11; a shift of 11 or more leaves no |round(Delta x)| + max_shift <= 11
    assert Encoder(TOY, 1.0, max_shift=10).max_shift == 10
    for bad in (11, 12, 10**400):
        with pytest.raises(ParameterError, match=r"max_shift must be <= 10, got "):
            Encoder(TOY, 1.0, max_shift=bad)
