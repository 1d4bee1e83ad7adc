"""One integer rule for the whole package (_validation.check_int): the config's, the big-integer
arithmetic's, the encoder's and the training configuration's integers agree."""

from __future__ import annotations

import gmpy2
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from encctl_gym._validation import MAX_EXACT_FLOAT_INT, check_int
from encctl_gym.crypto.arith import check_integer
from encctl_gym.crypto.encoding import Encoder, lift
from encctl_gym.crypto.group import parse_group_integer, shipped_group
from encctl_gym.errors import ConfigError, GroupError, ParameterError, PlaintextError

ACCEPTED = [(7, 7), (np.int64(-3), -3), (np.uint8(200), 200), (gmpy2.mpz(2) ** 70, 2**70), (3.0, 3), (np.float32(8.0), 8)]
REFUSED = [True, np.bool_(False), 2.5, float("inf"), float("nan"), 2.0**64, "3", b"3", None, [3], 1 + 0j]


@pytest.mark.parametrize("value,expected", ACCEPTED, ids=repr)
def test_every_checker_accepts_the_same_integers(value, expected):
    assert check_int("k", value) == expected and type(check_int("k", value)) is int
    assert check_integer("k", value) == expected
    assert parse_group_integer("p", value) == expected


@pytest.mark.parametrize("value", REFUSED, ids=repr)
def test_every_checker_refuses_the_same_values_naming_them(value):
    for check in (check_int, check_integer):
        with pytest.raises(ParameterError, match="k must be an integer"):
            check("k", value)
    if not isinstance(value, str):
        with pytest.raises(GroupError, match="p must be an integer"):
            parse_group_integer("p", value)


@given(st.integers(min_value=-MAX_EXACT_FLOAT_INT, max_value=MAX_EXACT_FLOAT_INT))
def test_an_integral_float_within_2_53_is_exactly_its_integer(v):
    assert check_int("k", float(v)) == v == check_integer("k", float(v))


@given(st.floats(allow_nan=False, allow_infinity=False).filter(lambda f: not f.is_integer() or abs(f) > 2**53))
def test_any_other_float_is_refused(f):
    with pytest.raises(ParameterError):
        check_int("k", f)


def test_the_error_class_and_the_bounds_follow_the_caller():
    with pytest.raises(ConfigError, match="n must be >= 2, got 1"):
        check_int("n", 1.0, 2, error=ConfigError)
    with pytest.raises(ParameterError, match="n must be <= 4, got 5"):
        check_int("n", np.int32(5), maximum=4)
    g = shipped_group(64)
    with pytest.raises(PlaintextError, match="m must be an integer"):
        Encoder(g, 16.0).decode(2.5)
    assert lift(g, 1.0) == lift(g, 1) == 1  # the encoder follows the same rule


def test_group_files_hex_strings_are_parsed_apart():
    assert parse_group_integer("p", "0x1f") == 31 == parse_group_integer("p", "31")
    with pytest.raises(GroupError, match="decimal or 0x hex"):
        parse_group_integer("p", "thirty-one")
    with pytest.raises(ParameterError, match="k must be an integer"):
        check_int("k", "0x1f")  # the general rule takes no strings
