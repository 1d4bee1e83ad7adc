"""Issue 34 items 17 and 19: a precomputation file's relation count and row lengths are bounded
before any relation is checked, and its header's cost values are finite, non-negative numbers."""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pytest

from encctl_gym.cryptanalysis import get_breaker
from encctl_gym.cryptanalysis.index_calculus import EXTRA_CONSTANT, EXTRA_FRACTION, IndexCalculus
from encctl_gym.cryptanalysis.precomputation_file import PrecomputationInterrupted, load_precomputation, max_relations
from encctl_gym.cryptanalysis.smoothness import primes_up_to
from encctl_gym.crypto.group import get_group
from encctl_gym.errors import ConfigError, ResourceLimitError


@pytest.fixture(scope="module")
def group():
    return get_group(48)


@pytest.fixture(scope="module")
def partial(group, tmp_path_factory) -> Path:
    def stop(phase: str, done: float, total: float | None) -> None:
        if phase == "relations" and done >= 30:
            raise KeyboardInterrupt

    with pytest.raises(PrecomputationInterrupted) as interrupted:
        get_breaker("index-calculus", rng=5).precompute(group, progress=stop)
    return Path(interrupted.value.state.save(tmp_path_factory.mktemp("pre") / "part.npz"))


def _rewrite(path: Path, out: Path, header: dict | None = None, **arrays_changed) -> Path:
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    head = json.loads(str(arrays["header"][()]))
    for key, value in (header or {}).items():
        target = head
        *parents, last = key.split(".")
        for parent in parents:
            target = target[parent]
        target[last] = value
    arrays["header"] = np.array(json.dumps(head))
    arrays.update(arrays_changed)
    np.savez_compressed(out, **arrays)
    return out


def _empty_relations(path: Path, out: Path, count: int) -> Path:
    with np.load(path) as z:
        width = z["rhs"].shape[1]
    return _rewrite(
        path,
        out,
        indptr=np.zeros(count + 1, np.int64),
        cols=np.zeros(0, np.int64),
        coefs=np.zeros(0, np.int64),
        rhs=np.zeros((count, width), np.uint8),
    )


# ----------------------------------------------------------------------------- item 17
def test_the_relation_bound_holds_what_the_collection_writes() -> None:
    for k in (10, 383, 9700, 1_077_871):  # up to the primes below MAX_BOUND = 2^24
        most_written = (
            int(k * (1 + EXTRA_FRACTION))
            + EXTRA_CONSTANT
            + IndexCalculus.MAX_ROUNDS * max(EXTRA_CONSTANT, int(EXTRA_FRACTION * k))
        )
        assert most_written < max_relations(k) <= 3 * k + 1000


def test_a_file_of_too_many_empty_relations_is_refused_before_checking_them(group, partial: Path, tmp_path: Path) -> None:
    k = len(primes_up_to(load_precomputation(partial).bound))
    limit = max_relations(k)
    ok = load_precomputation(_empty_relations(partial, tmp_path / "ok.npz", limit))
    assert len(ok.relations) == limit  # at the bound: loaded
    many = _empty_relations(partial, tmp_path / "many.npz", 300_000)
    start = time.perf_counter()
    with pytest.raises(
        ResourceLimitError, match=rf"many\.npz.*holds 300000 relations; a factor base of {k} primes needs fewer than {limit}"
    ):
        load_precomputation(many)
    assert (
        time.perf_counter() - start < 2.0
    )  # refused before building them (unbounded, 1e6 empty relations loaded in 2.8 s, 3e7 in 83 s)


def test_a_relation_with_more_primes_than_a_sieve_pair_has_is_refused(group, partial: Path, tmp_path: Path) -> None:
    with np.load(partial) as z:
        width, count = z["rhs"].shape[1], z["rhs"].shape[0]
    most = 2 * (group.p.bit_length() + 16)
    indptr = np.zeros(count + 1, np.int64)
    indptr[1:] = most + 1  # the first relation has most + 1 entries, the others none
    bad = _rewrite(
        partial,
        tmp_path / "long.npz",
        indptr=indptr,
        cols=np.arange(most + 1, dtype=np.int64) % 10,
        coefs=np.ones(most + 1, np.int64),
        rhs=np.zeros((count, width), np.uint8),
    )
    with pytest.raises(ConfigError, match=rf"a relation of {most + 1} primes; a pair a, b of the sieve has at most {most}"):
        load_precomputation(bad)


# ----------------------------------------------------------------------------- item 19
@pytest.fixture(scope="module")
def complete(group, tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("pre") / "full.npz"
    get_breaker("index-calculus", rng=7).precompute(group).save(path)
    return path


@pytest.mark.parametrize(
    "key,value,match",
    [
        ("cost.seconds", 10**400, "cost.seconds must be a finite real number within the float64 range"),
        ("cost.seconds", -1e9, r"cost.seconds must be >= 0, got -1000000000.0"),
        ("cost.seconds", float("nan"), "cost.seconds must be finite, got nan"),
        ("cost.cpu_seconds", float("inf"), "cost.cpu_seconds must be finite, got inf"),
        ("cost.operations.relations", float("inf"), "cost.operations.relations must be an integer, got inf"),
        ("cost.operations.relations", -3, "cost.operations.relations must be >= 0, got -3"),
        ("cost.operations.relations", 2**64, r"cost.operations.relations must be <= 9223372036854775808"),
        ("cost.operations", [1], "cost.operations must be a mapping"),
        ("phase_seconds.relations", float("nan"), "phase_seconds.relations must be finite, got nan"),
        ("phase_cpu_seconds.relations", -1.0, "phase_cpu_seconds.relations must be >= 0"),
    ],
)
def test_a_bad_cost_in_the_header_is_refused(complete: Path, tmp_path: Path, key: str, value, match: str) -> None:
    bad = _rewrite(complete, tmp_path / "bad.npz", header={key: value})
    with pytest.raises(ConfigError, match=rf"bad\.npz.*has a bad header entry: .*{match}"):
        load_precomputation(bad)


def test_crack_on_an_overflowing_cost_exits_2(group, complete: Path, tmp_path: Path, capsys) -> None:
    from encctl_gym.cli import main

    bad = _rewrite(complete, tmp_path / "big.npz", header={"cost.seconds": 10**400})
    argv = ["crack", "--bits", str(group.p.bit_length()), "--keys", "1", "--load-precomputation", str(bad)]
    assert main(argv) == 2
    assert "cost.seconds must be a finite real number" in capsys.readouterr().err


def test_a_good_cost_round_trips(complete: Path) -> None:
    pre = load_precomputation(complete)
    assert pre.cost.seconds >= 0 and all(v >= 0 for v in pre.phase_seconds.values())
    assert all(isinstance(v, int) and v >= 0 for v in pre.cost.operations.values())
