"""Tests of the vectorised quantisation table (crypto.residue_table) against the encoder's
nearest-member search of Definition def:ec, and of its memory bound."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.crypto.encoding import nearest_member
from encctl_gym.crypto.group import GroupParams, shipped_group
from encctl_gym.crypto.residue_table import DEFAULT_MAX_TABLE_BYTES, ResidueTable, residue_table, residue_table_bytes
from encctl_gym.errors import EncodingOverflowError, GroupError, ParameterError, ResourceLimitError

G64, G128 = shipped_group(64), shipped_group(128)
TABLES = {bits: residue_table(shipped_group(bits), 20_000) for bits in (64, 128)}


@settings(max_examples=100, deadline=None)
@given(bits=st.sampled_from([64, 128]), vs=st.lists(st.integers(-20_000, 20_000), min_size=1, max_size=50))
def test_table_equals_the_encoders_nearest_member(bits, vs):
    table, grp = TABLES[bits], shipped_group(bits)
    got = table.nearest(np.array(vs, dtype=np.int64))
    assert [int(w) for w in got] == [nearest_member(grp, v, 64)[0] for v in vs]


def test_whole_table_known_answers_toy_range():
    # Every v in [-limit, limit] against the reference, for a small table of the 64-bit group.
    table = ResidueTable(G64.p, 3000)
    vs = np.arange(-3000, 3001)
    ref = np.array([nearest_member(G64, int(v), 64)[0] for v in vs])
    assert np.array_equal(table.nearest(vs), ref)
    assert table.max_shift == int(np.abs(ref - vs).max()) and table.offsets.dtype == np.int16
    assert np.array_equal(table.offset_at(vs), ref - vs)


def test_table_needs_a_safe_prime():
    with pytest.raises(GroupError, match="safe prime"):
        ResidueTable(19, 3)  # 19 = 2 * 9 + 1 is prime and 3 mod 4, but 9 is not prime
    with pytest.raises(GroupError, match="safe prime"):
        ResidueTable(27, 3)
    with pytest.raises(GroupError, match="cofactor 4"):
        ResidueTable(GroupParams(29, 7, 16), 3)
    with pytest.raises(ParameterError, match="limit"):
        ResidueTable(23, 6)  # 4 * 6 >= 23
    assert ResidueTable(GroupParams(23, 11, 4), 5).nearest(np.array([-5, 0, 5])).tolist() == [-5, 1, 6]


def test_nearest_refuses_floats_and_out_of_range():
    table = TABLES[64]
    with pytest.raises(ParameterError, match="integer array"):
        table.nearest(np.array([2.7]))
    with pytest.raises(EncodingOverflowError, match="20001"):
        table.nearest(np.array([5, 20_001]))


def test_memory_is_estimated_and_refused_before_allocating():
    assert DEFAULT_MAX_TABLE_BYTES == 1 << 30
    # x_bound = 2e4 at Delta = 4096 (6 GB before the bound): limit 8.2e7, now within 1 GiB.
    assert residue_table_bytes(81_920_001) < DEFAULT_MAX_TABLE_BYTES
    # x_bound = 1e6: refused at once, with the number.
    tracemalloc.start()
    with pytest.raises(ResourceLimitError, match=r"limit = 4096000001 needs about \d+ MiB"):
        ResidueTable(shipped_group(712).p, 4_096_000_001)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak < 1 << 20  # nothing was allocated
    with pytest.raises(ResourceLimitError, match="max_bytes = 1 MiB"):
        ResidueTable(G64.p, 200_000, max_bytes=1 << 20)


def test_memory_estimate_bounds_the_measured_peak():
    limit = 1_000_000
    tracemalloc.start()
    ResidueTable(G128.p, limit)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    est = residue_table_bytes(limit)
    assert peak <= est < 2.5 * peak


def test_absurd_limits_are_refused_with_their_numbers():
    with pytest.raises(ResourceLimitError, match=r"limit = 0x.*\(1329 bits\) needs about 0x"):
        ResidueTable(G64.p, 10**400)
    with pytest.raises(GroupError, match="MAX_GROUP_BITS"):
        ResidueTable((1 << 20000) + 3, 10)  # = 3 mod 4, far too large: refused before any test
