"""The index calculus's precomputation in a file (save, load checked against its group, resume
after an interruption) and its progress reports: library, ``encctl-gym crack`` and environment."""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.cli import main
from encctl_gym.cryptanalysis import IndexCalculus, get_breaker
from encctl_gym.cryptanalysis import index_calculus as ic
from encctl_gym.cryptanalysis import precomputation_file as pf
from encctl_gym.cryptanalysis.base import Deadline
from encctl_gym.cryptanalysis.precomputation_file import PrecomputationInterrupted, load_precomputation
from encctl_gym.cryptanalysis.progress import PhaseBars
from encctl_gym.crypto import arith
from encctl_gym.crypto.group import generate_safe_prime_group, get_group
from encctl_gym.errors import ConfigError, ParameterError, ResourceLimitError

BITS = 64


@pytest.fixture(scope="module")
def group():
    return get_group(BITS)


@pytest.fixture(scope="module")
def saved(group, tmp_path_factory) -> tuple[Path, ic.FactorBaseLogs]:
    pre = get_breaker("index-calculus", rng=11).precompute(group)
    path = tmp_path_factory.mktemp("pre") / "ic64.npz"
    pre.save(path)
    return path, pre


def _key(group, s: int) -> int:
    return pow(group.g, s, group.p)


def _no_sieving(monkeypatch: pytest.MonkeyPatch) -> None:
    def forbidden(*args, **kwargs):
        raise AssertionError("relations were collected")

    monkeypatch.setattr(ic, "collect_relations", forbidden)


# ----------------------------------------------------------------------------- round trip
def test_a_saved_precomputation_loads_whole_and_breaks_a_fresh_key(group, saved, monkeypatch) -> None:
    path, pre = saved
    loaded = load_precomputation(path)
    assert loaded.complete and loaded.group == group and loaded.bound == pre.bound
    assert loaded.logs == pre.logs and loaded.cost == pre.cost
    _no_sieving(monkeypatch)
    again = IndexCalculus(precomputation=path, rng=5).precompute(group)
    assert again.logs == pre.logs
    assert again.cost.seconds >= pre.cost.seconds and again.cost.operations["loaded_logs"] == 1  # the file's work is charged
    s = 0x1234_5678_9ABC_DEF % group.q
    key = again.break_key(_key(group, s))
    assert key.s == s and pow(group.g, key.s, group.p) == _key(group, s)  # g^s = h


def test_a_loaded_complete_file_expects_only_the_descent(group, saved) -> None:
    path, _ = saved
    first, per_key = IndexCalculus(precomputation=path).expected_seconds(group)
    fresh_first, fresh_per_key = IndexCalculus(bound=load_precomputation(path).bound).expected_seconds(group)
    assert first == per_key == fresh_per_key < fresh_first


@settings(max_examples=50, deadline=None)
@given(st.lists(st.integers(min_value=0, max_value=2**128 - 1), max_size=20))
def test_the_integers_of_the_file_round_trip(values: list[int]) -> None:
    assert pf._from_bytes(pf._to_bytes(values, 16)) == values


# ----------------------------------------------------------------------------- refusals
def test_a_file_of_another_group_or_bound_is_refused_naming_what_differs(saved) -> None:
    path, pre = saved
    other = generate_safe_prime_group(BITS, rng=arith.seeded_random(99))
    with pytest.raises(ConfigError, match=r"ic64.npz.*another group: its p = .*this group's p"):
        IndexCalculus(precomputation=path).precompute(other)
    with pytest.raises(ConfigError, match=rf"factor-base bound {pre.bound}, this breaker's bound is {pre.bound + 1}"):
        IndexCalculus(precomputation=path, bound=pre.bound + 1).precompute(pre.group)


def _rewrite(path: Path, out: Path, **changes) -> Path:
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    header = json.loads(str(arrays["header"][()]))
    header.update(changes.pop("header", {}))
    arrays["header"] = np.array(json.dumps(header))
    arrays.update(changes)
    np.savez(out, **arrays)
    return out


def test_a_corrupt_file_is_refused_naming_the_file_and_the_entry(saved, tmp_path) -> None:
    path, pre = saved
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"not a zip archive")
    with pytest.raises(ConfigError, match="junk.npz.*not a readable NPZ archive"):
        load_precomputation(junk)
    with pytest.raises(ConfigError, match="does not exist"):
        load_precomputation(tmp_path / "missing.npz")
    with np.load(path) as z:
        logs = z["logs"].copy()
    j = next(i for i, v in enumerate(pre.logs) if v is not None)
    logs[j, 0] ^= 1  # one bit of one logarithm
    with pytest.raises(ConfigError, match=rf"wrong logarithm for the prime {pre.factor_base.primes[j]}"):
        load_precomputation(_rewrite(path, tmp_path / "bit.npz", logs=logs))
    with pytest.raises(ConfigError, match="layout version 99"):
        load_precomputation(_rewrite(path, tmp_path / "v.npz", header={"version": 99}))
    with pytest.raises(ConfigError, match="bad header entry"):
        load_precomputation(_rewrite(path, tmp_path / "g.npz", header={"group": {"p": "0x17", "q": "0x5", "g": "0x4"}}))
    objects = _rewrite(path, tmp_path / "obj.npz")
    with np.load(objects) as z:
        arrays = {k: z[k] for k in z.files}
    arrays["logs"] = np.array([object()], dtype=object)
    np.savez(objects, **arrays)  # a pickled member
    with pytest.raises(ConfigError, match="without pickles"):
        load_precomputation(objects)


def test_a_file_too_large_is_refused_before_its_arrays_are_read(saved, monkeypatch) -> None:
    path, _ = saved
    with zipfile.ZipFile(path) as zf:
        total = sum(i.file_size for i in zf.infolist())
    monkeypatch.setattr(pf, "MAX_FILE_BYTES", total - 1)
    monkeypatch.setattr(np, "load", lambda *a, **k: pytest.fail("read"))
    with pytest.raises(ResourceLimitError, match="MAX_FILE_BYTES"):
        load_precomputation(path)


# ----------------------------------------------------------------------------- interruption
def _stop_after(relations: int):
    def callback(phase: str, done: float, total: float | None) -> None:
        if phase == "relations" and done >= relations:
            raise KeyboardInterrupt

    return callback


def test_an_interrupted_collection_is_saved_and_resumed(group, tmp_path) -> None:
    with pytest.raises(PrecomputationInterrupted) as stop:
        get_breaker("index-calculus", rng=3).precompute(group, progress=_stop_after(150))
    assert isinstance(stop.value, KeyboardInterrupt) and stop.value.phase == "relations"
    state = stop.value.state
    assert not state.complete and len(state.relations) >= 150 and state.cost.operations["sieved_lattices"] >= 1
    path = state.save(tmp_path / "part.npz")
    loaded = load_precomputation(path)
    assert [tuple(r) for r in loaded.relations] == [tuple(r) for r in state.relations] and loaded.walk == state.walk
    breaker = IndexCalculus(precomputation=path, rng=3)
    assert breaker.expected_seconds(group)[0] < IndexCalculus(bound=loaded.bound).expected_seconds(group)[0]
    seen: list[float] = []
    pre = breaker.precompute(group, progress=lambda phase, done, total: seen.append(done) if phase == "relations" else None)
    assert seen[0] >= 150  # resumed from the saved relations, not from zero
    assert pre.cost.operations["sieved_lattices"] > state.cost.operations["sieved_lattices"]
    assert pre.cost.cpu_seconds >= state.cost.cpu_seconds
    s = 987654321 % group.q
    assert pow(group.g, pre.break_key(_key(group, s)).s, group.p) == _key(group, s)


def test_an_interruption_in_the_linear_algebra_keeps_every_relation(group, tmp_path, monkeypatch) -> None:
    def stop_in_linear_algebra(phase: str, done: float, total: float | None) -> None:
        if phase.startswith("linear algebra"):
            raise KeyboardInterrupt

    with pytest.raises(PrecomputationInterrupted) as stop:
        get_breaker("index-calculus", rng=9).precompute(group, progress=stop_in_linear_algebra)
    assert stop.value.phase == "linear algebra"
    state = stop.value.state
    k = len(ic.FactorBase(state.bound))
    assert len(state.relations) >= k  # the collection was complete
    path = state.save(tmp_path / "la.npz")
    _no_sieving(monkeypatch)  # the resumed run goes straight to the linear algebra
    pre = IndexCalculus(precomputation=path, rng=9).precompute(group)
    s = 4242 % group.q
    assert pow(group.g, pre.break_key(_key(group, s)).s, group.p) == _key(group, s)


def test_a_relation_altered_in_the_file_is_refused(group, tmp_path) -> None:
    with pytest.raises(PrecomputationInterrupted) as stop:
        get_breaker("index-calculus", rng=4).precompute(group, progress=_stop_after(40))
    path = stop.value.state.save(tmp_path / "part.npz")
    with np.load(path) as z:
        coefs = z["coefs"].copy()
    coefs[0] += 1
    with pytest.raises(ConfigError, match=r"wrong relation \(number 0\)"):
        load_precomputation(_rewrite(path, tmp_path / "bad.npz", coefs=coefs))


# ----------------------------------------------------------------------------- progress
def test_progress_is_silent_by_default_and_bars_name_the_phases(group, capsys) -> None:
    Deadline(None, "x").report("relations", 1, 2)  # no callback: nothing
    assert capsys.readouterr() == ("", "")
    out = io.StringIO()
    bars = PhaseBars(file=out, prefix="ic ")
    get_breaker("index-calculus", rng=8).precompute(group, progress=bars)
    bars.close()
    text = out.getvalue()
    assert "ic relations" in text and "ic linear algebra: structured elimination" in text and "ic linear algebra: dense" in text
    with pytest.raises(ParameterError, match="progress must be a callable"):
        get_breaker("index-calculus").precompute(group, progress=3)


# ----------------------------------------------------------------------------- crack
def test_crack_ctrl_c_saves_the_relations_and_a_rerun_resumes(tmp_path, capsys, monkeypatch) -> None:
    path = tmp_path / "crack.npz"
    args = ["crack", "--bits", "64", "--keys", "3", "--group", "fresh", "--seed", "6"]
    original = PhaseBars.__call__

    def interrupting(self, phase, done, total=None):
        original(self, phase, done, total)
        if phase == "relations" and done >= 100:
            raise KeyboardInterrupt

    monkeypatch.setattr(PhaseBars, "__call__", interrupting)
    assert main(args) == 130
    err = capsys.readouterr().err
    assert "interrupted in the relations" in err and "not saved" in err and "Traceback" not in err
    assert main([*args, "--save-precomputation", str(path)]) == 130
    err = capsys.readouterr().err.splitlines()[-1]
    assert err.startswith("encctl-gym crack: interrupted in the relations") and f"--load-precomputation {path}" in err
    assert not load_precomputation(path).complete
    monkeypatch.setattr(PhaseBars, "__call__", original)
    assert main([*args, "--load-precomputation", str(path), "--save-precomputation", str(path), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "all 3 keys checked" in out and "saved to" in out and "phases (wall, CPU)" in out
    assert load_precomputation(path).complete


def test_crack_refuses_a_file_of_another_group_and_other_breakers_in_one_line(saved, tmp_path, capsys) -> None:
    path, _ = saved
    assert main(["crack", "--bits", "64", "--keys", "2", "--group", "fresh", "--load-precomputation", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "another group" in err and "\n" not in err
    assert main(["crack", "--bits", "32", "--breaker", "rho", "--save-precomputation", str(tmp_path / "x.npz")]) == 2
    assert "--save-precomputation is for --breaker index-calculus" in capsys.readouterr().err
    assert main(["crack", "--bits", "32", "--save-precomputation", str(tmp_path / "no" / "x.npz")]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_crack_with_a_loaded_file_does_not_sieve(saved, capsys, monkeypatch) -> None:
    path, _ = saved
    _no_sieving(monkeypatch)
    assert main(["crack", "--bits", "64", "--keys", "4", "--load-precomputation", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    p, g = int(out["group"]["p"], 16), int(out["group"]["g"], 16)
    assert out["keys_match"] and all(pow(g, int(k["s"], 16), p) == int(k["h"], 16) for k in out["keys"])


# ----------------------------------------------------------------------------- environment
@pytest.mark.slow
def test_the_environment_loads_the_file_and_recovers_the_plant_keys(saved, monkeypatch) -> None:
    from encctl_gym.envs import EncryptedLTIAttackEnv

    path, pre = saved
    _no_sieving(monkeypatch)
    env = EncryptedLTIAttackEnv(
        config=dict(
            crypto="elgamal",
            key_length=BITS,
            max_samples=12,
            crypto_seed=5,
            breaker="index-calculus",
            breaker_precomputation=str(path),
        )
    )
    env.reset(seed=0)
    loop = env.unwrapped.episode.loop
    assert loop.decipherer.breaker.loaded.group == pre.group
    for _ in range(3):
        assert loop.decipherer.secret(loop.plant.pk) == loop.plant.secret_key.s  # privileged read, in the test only
        env.step(np.zeros(env.action_space.shape, dtype=np.float32))
    assert loop.decipherer.costs[0] == ("precomputation", loop.decipherer.costs[0][1])
    assert loop.decipherer.costs[0][1].cpu_seconds >= pre.cost.cpu_seconds  # charged as from scratch


@pytest.mark.parametrize(
    "kw,error,match",
    [
        (dict(breaker_precomputation="x.npz"), ParameterError, "needs breaker='index-calculus'"),
        (dict(breaker="rho-multi", breaker_precomputation="x.npz"), ParameterError, "needs breaker='index-calculus'"),
        (dict(breaker="index-calculus", breaker_precomputation=3), ParameterError, "must be a file name"),
        (dict(breaker="index-calculus", breaker_precomputation="/no/such/file.npz"), ConfigError, "does not exist"),
    ],
)
def test_bad_breaker_precomputation(kw, error, match) -> None:
    from encctl_gym.envs import EncryptedLTIAttackEnv

    with pytest.raises(error, match=match):
        EncryptedLTIAttackEnv(config=dict(crypto="elgamal", key_length=BITS, max_samples=12, **kw))
