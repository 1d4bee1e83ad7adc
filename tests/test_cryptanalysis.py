"""Tests of the key breakers (encctl_gym.cryptanalysis): known answers, agreement with each other
and with sympy's discrete_log, hypothesis properties, the token chain against
crypto.dyn_elgamal.recover_next_secret_key, and every error of the interface."""

from __future__ import annotations

import math
import pickle
import random
import subprocess
import sys
from functools import cache

import gmpy2
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.cryptanalysis import (
    BREAKERS,
    BreakReport,
    IndexCalculus,
    MultiLogRho,
    PollardRho,
    TokenChain,
    break_sequence,
    get_breaker,
    pari_available,
)
from encctl_gym.cryptanalysis import pari as pari_mod
from encctl_gym.cryptanalysis.base import Deadline, format_seconds
from encctl_gym.cryptanalysis.keys import key_sequence
from encctl_gym.crypto import arith
from encctl_gym.crypto.dyn_elgamal import recover_next_secret_key
from encctl_gym.crypto.elgamal import SecretKey
from encctl_gym.crypto.group import GroupParams, generate_safe_prime_group, shipped_group
from encctl_gym.errors import (
    BreakerError,
    BreakerLimitError,
    BreakerTimeoutError,
    EncctlError,
    GroupError,
    KeyMismatchError,
    OptionalDependencyError,
    ParameterError,
)

# Toy group (hand-checked): p = 23 = 2 * 11 + 1, q = 11, g = 4; powers 4^s mod 23 for s = 0..10.
TOY = GroupParams(23, 11, 4)
TOY_POWERS = {1: 0, 4: 1, 16: 2, 18: 3, 3: 4, 12: 5, 2: 6, 8: 7, 9: 8, 13: 9, 6: 10}

needs_pari = pytest.mark.skipif(not pari_available(), reason="needs cypari (pip install 'encctl-gym[cryptanalysis]')")
#: Every breaker that breaks a key on its own (the token chain wraps one of them).
DIRECT = [name for name in BREAKERS if name != "token-chain"]


def direct_breakers() -> list:
    return [pytest.param(name, marks=needs_pari) if name == "pari" else name for name in DIRECT]


@cache
def group(bits: int, seed: int = 11) -> GroupParams:
    return generate_safe_prime_group(bits, rng=seed)


@cache
def sequence(bits: int, n: int, seed: int = 5) -> tuple[tuple[int, ...], tuple[int, ...], tuple]:
    hs, secrets, tokens = key_sequence(group(bits), n, arith.seeded_random(seed))
    return tuple(hs), tuple(secrets), tuple(tokens)


@cache
def precomputed(name: str, bits: int):
    return get_breaker(name, rng=3).precompute(group(bits) if bits else TOY)


# ----------------------------------------------------------------------------- known answers
def test_toy_group_table_is_right() -> None:
    assert {pow(4, s, 23): s for s in range(11)} == TOY_POWERS


@pytest.mark.parametrize("name", direct_breakers())
def test_every_breaker_recovers_every_key_of_the_toy_group(name: str) -> None:
    pre = get_breaker(name, rng=1).precompute(TOY)
    for h, s in TOY_POWERS.items():
        key = pre.break_key(h)
        assert key.s == s and key.h == h
        assert key.cost.seconds >= 0 and key.method == name


@pytest.mark.parametrize("name", direct_breakers())
def test_breakers_agree_with_the_true_secrets_and_sympy_on_36_bits(name: str) -> None:
    from sympy.ntheory import discrete_log

    grp = group(36)
    hs, secrets, _ = sequence(36, 4)
    report = break_sequence(name, grp, hs)
    assert isinstance(report, BreakReport)
    assert report.secrets == list(secrets)
    for h, s in zip(hs[:2], report.secrets):
        assert discrete_log(grp.p, h, grp.g, grp.q) == s  # an independent implementation
    tau = report.tau()
    assert tau.shape == (4,) and all(tau[1:] >= tau[:-1])
    assert tau[0] == pytest.approx(report.precomputation.seconds + report.keys[0].cost.seconds)


@pytest.mark.parametrize("name", [pytest.param("pari", marks=needs_pari), "index-calculus"])
def test_pari_and_index_calculus_agree_on_48_bits(name: str) -> None:
    hs, secrets, _ = sequence(48, 3)
    assert break_sequence(name, group(48), hs).secrets == list(secrets)


@pytest.mark.slow
@pytest.mark.parametrize("bits", [64, 80])
@pytest.mark.parametrize("name", [pytest.param("pari", marks=needs_pari), "index-calculus"])
def test_pari_and_index_calculus_agree_on_larger_groups(name: str, bits: int) -> None:
    hs, secrets, _ = sequence(bits, 4)
    assert break_sequence(name, group(bits), hs).secrets == list(secrets)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["bsgs", "rho", "rho-multi"])
def test_generic_breakers_on_48_bits(name: str) -> None:
    hs, secrets, _ = sequence(48, 2)
    assert break_sequence(name, group(48), hs).secrets == list(secrets)


# ----------------------------------------------------------------------------- properties
@pytest.mark.parametrize("name", direct_breakers())
@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_any_exponent_is_recovered_and_checked(name: str, data: st.DataObject) -> None:
    pre = precomputed(name, 24)
    grp = pre.group
    s = data.draw(st.integers(min_value=1, max_value=grp.q - 1))
    h = int(gmpy2.powmod(grp.g, s, grp.p))
    key = pre.break_key(h)
    assert key.s == s
    assert pow(grp.g, key.s, grp.p) == h


def test_h_equal_to_one_gives_zero() -> None:
    for name in ("bsgs", "rho", "rho-multi", "index-calculus"):
        assert precomputed(name, 24).break_key(1).s == 0


def test_same_seed_same_work() -> None:
    hs, _, _ = sequence(32, 3)
    runs = [break_sequence(MultiLogRho(rng=7), group(32), hs) for _ in range(2)]
    assert [k.cost.operations for k in runs[0].keys] == [k.cost.operations for k in runs[1].keys]


# ----------------------------------------------------------------------------- amortisation
def test_multiple_logarithm_rho_makes_later_keys_cheaper() -> None:
    # Kuhn-Struik: the distinguished points of solved keys stay in the table, so the walks of a
    # later key end early. Same walk, same keys: plain rho forgets its points after every key.
    grp = group(36)
    hs, secrets, _ = sequence(36, 24)
    multi = break_sequence(MultiLogRho(rng=2), grp, hs)
    plain = break_sequence(PollardRho(rng=2), grp, hs)
    assert multi.secrets == plain.secrets == list(secrets)
    steps_multi = [k.cost.operations["group_operations"] for k in multi.keys]
    steps_plain = [k.cost.operations["group_operations"] for k in plain.keys]
    expected = math.sqrt(math.pi * grp.q / 2)
    assert 0.5 * expected < sum(steps_plain) / len(steps_plain) < 2 * expected
    assert sum(steps_multi[12:]) < 0.4 * sum(steps_plain[12:])
    pre = MultiLogRho(rng=2).precompute(grp)
    pre.break_key(hs[0])
    table = len(pre.known)
    pre.break_key(hs[1])
    assert len(pre.known) > table > 0  # the table only grows


def test_bsgs_reuses_its_table() -> None:
    pre = precomputed("bsgs", 24)
    assert pre.cost.operations["group_operations"] == pre.m == math.isqrt(pre.group.q - 1) + 1
    hs, _, _ = sequence(24, 4)
    for h in hs:
        assert pre.break_key(h).cost.operations["group_operations"] <= -(-pre.group.q // pre.m)


def test_index_calculus_phases_and_descent() -> None:
    pre = precomputed("index-calculus", 48)
    ops = pre.cost.operations
    assert ops["relations"] >= ops["factor_base"] > 10
    assert ops["solved_logs"] >= 0.9 * ops["factor_base"] and ops["rank"] >= ops["solved_logs"]
    assert set(pre.phase_seconds) == set(pre.phase_cpu_seconds) == {"factor_base", "relations", "linear_algebra"}
    assert pre.backend == "nmod_mat"
    grp = pre.group
    # lambda(l) = log_g(l^n): the solved logarithms are those of the squares of the small primes.
    for ell, lam in zip(pre.factor_base.primes[:20], pre.logs[:20]):
        assert lam is not None
        assert pow(grp.g, lam, grp.p) == pow(ell, grp.cofactor, grp.p)
    hs, secrets, _ = sequence(48, 3)
    for h, s in zip(hs, secrets):
        key = pre.break_key(h)
        assert key.s == s and key.cost.operations["smoothness_tests"] >= 1


def test_index_calculus_with_multiprecision_linear_algebra() -> None:
    # q >= 2^63 takes the fmpz_mod_mat path (the 64-bit shipped group has a 63-bit q, so 66 bits).
    grp = group(66)
    pre = IndexCalculus(rng=4, bound=900).precompute(grp)
    assert pre.backend == "fmpz_mod_mat"
    hs, secrets, _ = sequence(66, 2)
    assert [pre.break_key(h).s for h in hs] == list(secrets)


# ----------------------------------------------------------------------------- token chain
def test_token_chain_derives_every_later_key_like_recover_next_secret_key() -> None:
    grp = group(40)
    hs, secrets, tokens = sequence(40, 6)
    chain = TokenChain(rng=1)  # the default inner breaker: index calculus
    report = break_sequence(chain, grp, hs, tokens=tokens)
    assert report.secrets == list(secrets)
    assert report.keys[0].method == "index-calculus"
    assert [k.method for k in report.keys[1:]] == ["token"] * 5
    sk = SecretKey(grp, report.secrets[0], 0)
    for t, token in enumerate(tokens):  # Proposition prop:vulnerability, the reference
        sk = recover_next_secret_key(sk, token)
        assert sk.s == report.secrets[t + 1]


def test_token_chain_accepts_pairs_and_falls_back_to_the_inner_breaker() -> None:
    grp = group(32)
    hs, secrets, tokens = sequence(32, 4)
    pre = get_breaker("token-chain", inner="rho", rng=1).precompute(grp)
    pre.add_tokens([(tokens[1].h, tokens[1].d)])  # only sigma_1: keys 0 and 1 need the inner breaker
    methods = [pre.break_key(h).method for h in hs]
    assert methods == ["rho", "rho", "token", "rho"]
    with pytest.raises(KeyMismatchError):
        pre.add_tokens([(grp.p - 1, 1)])  # h = -1 is not in G
    with pytest.raises(KeyMismatchError, match="outside"):
        pre.add_tokens([(hs[0], grp.q)])
    with pytest.raises(ParameterError, match="token"):
        pre.add_tokens([object()])
    with pytest.raises(ParameterError, match="itself"):
        get_breaker("token-chain", inner="token-chain")
    with pytest.raises(ParameterError, match="itself"):
        TokenChain(TokenChain())
    with pytest.raises(ParameterError, match="Breaker instance"):
        TokenChain("rho")  # type: ignore[arg-type]


def test_tokens_for_another_breaker_are_refused() -> None:
    hs, _, tokens = sequence(24, 2)
    with pytest.raises(ParameterError, match="token-chain"):
        break_sequence("rho", group(24), hs, tokens=tokens)


# ----------------------------------------------------------------------------- errors
def test_wrong_result_is_an_error_never_a_key(monkeypatch: pytest.MonkeyPatch) -> None:
    pre = get_breaker("rho", rng=1).precompute(TOY)
    real = type(pre)._solve

    def off_by_one(self, h, deadline, src):
        s, ops, method = real(self, h, deadline, src)
        return s + 1, ops, method

    monkeypatch.setattr(type(pre), "_solve", off_by_one)
    with pytest.raises(BreakerError, match="fails the check"):
        pre.break_key(4)


def test_keys_of_another_group_are_refused() -> None:
    pre = precomputed("bsgs", 24)
    with pytest.raises(KeyMismatchError, match="another group"):
        pre.break_key(pre.group.p - 1)  # -1 is not a square modulo a safe prime p = 3 mod 4
    with pytest.raises(KeyMismatchError):
        pre.break_key(0)
    with pytest.raises(KeyMismatchError):
        pre.break_key("12")
    hs, _, _ = sequence(32, 1)
    with pytest.raises(KeyMismatchError):
        break_sequence("rho", TOY, hs)
    with pytest.raises(ParameterError, match="precomputation"):
        get_breaker("rho").break_key(4, pre)


def test_too_large_groups_are_refused_before_any_work(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in ("bsgs", "rho", "rho-multi", "index-calculus"):
        cls = BREAKERS[name]
        monkeypatch.setattr(cls, "_precompute", lambda *a, **k: pytest.fail("work started"))
        with pytest.raises(BreakerLimitError, match="limit is") as err:
            get_breaker(name).precompute(shipped_group(256))
        assert "expected time" in str(err.value) and "256-bit" in str(err.value)
    with pytest.raises(BreakerLimitError, match="max_table"):
        BREAKERS["bsgs"](max_table=100).check_feasible(group(24))
    with pytest.raises(BreakerLimitError):
        get_breaker("token-chain", inner="rho", max_bits=20).precompute(group(24))
    assert issubclass(BreakerLimitError, ParameterError)


def test_index_calculus_needs_q_prime_to_the_cofactor() -> None:
    # p = 19, q = 3: p - 1 = 18 = 2 * 3^2, so q divides the cofactor 6; g = 7 has order 3.
    grp = GroupParams(19, 3, 7)
    with pytest.raises(GroupError, match="cofactor"):
        IndexCalculus().precompute(grp)
    assert get_breaker("bsgs").precompute(grp).break_key(49 % 19).s == 2  # generic breakers do not care


def test_time_limit_stops_a_breaker_with_a_clear_error() -> None:
    grp = group(56)
    hs, _, _ = sequence(56, 1)
    pre = PollardRho(rng=1).precompute(grp)
    with pytest.raises(BreakerTimeoutError, match="time limit of 0.05 s"):
        pre.break_key(hs[0], time_limit=0.05)
    with pytest.raises(BreakerTimeoutError, match="precomputation"):
        IndexCalculus(rng=1).precompute(group(90), time_limit=0.05)
    with pytest.raises(BreakerTimeoutError, match="before its linear algebra"):
        # 13848 unknowns: relations in seconds, the linear algebra above 33 s by the model
        # (about 34 s), so it is refused whenever the relations finish within the limit.
        IndexCalculus(rng=1, bound=150_000).precompute(group(40), time_limit=33.0)
    with pytest.raises(ParameterError):
        Deadline(-1.0, "x")
    assert issubclass(BreakerTimeoutError, (BreakerError, TimeoutError))


@needs_pari
def test_pari_time_limit_uses_an_alarm() -> None:
    grp = group(104)
    hs, _, _ = sequence(104, 1)
    pre = get_breaker("pari").precompute(grp)
    with pytest.raises(BreakerTimeoutError):
        pre.break_key(hs[0], time_limit=0.5)
    assert pre.break_key(4).s == 1  # PARI is usable after the alarm


@needs_pari
def test_pari_time_limit_holds_when_cysignals_owns_the_alarm() -> None:
    """With the lattice extra, fpylll imports cysignals, whose SIGALRM handler raises its own
    AlarmInterrupt once imported after PARI: the time limit is still the package's
    BreakerTimeoutError, not an interrupt that ends the caller (fresh process)."""
    pytest.importorskip("fpylll", reason="needs fpylll (pip install 'encctl-gym[lattice]')")
    code = (
        "from encctl_gym.cryptanalysis import get_breaker\n"
        "from encctl_gym.crypto.group import generate_safe_prime_group\n"
        "from encctl_gym.errors import BreakerTimeoutError\n"
        "grp = generate_safe_prime_group(104, rng=11)\n"
        "pre = get_breaker('pari').precompute(grp)\n"
        "pre.break_key(grp.g)\n"  # PARI loaded first, then cysignals takes over SIGALRM
        "import fpylll\n"
        "h = pow(grp.g, 0x1234567890ABCDEF1234567, grp.p)\n"
        "try:\n"
        "    pre.break_key(h, time_limit=0.5)\n"
        "except BreakerTimeoutError:\n"
        "    print('timeout')\n"
        "print(pre.break_key(grp.g).s)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["timeout", "1"]


def test_missing_cypari_is_one_line_naming_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(pari_mod, "_PARI", None)
    monkeypatch.setitem(sys.modules, "cypari", None)
    with pytest.raises(OptionalDependencyError, match=r"pip install 'encctl-gym\[cryptanalysis\]'") as err:
        get_breaker("pari").precompute(TOY)
    assert "\n" not in str(err.value)
    assert not pari_mod.pari_available()


def test_unknown_breaker_and_bad_options() -> None:
    with pytest.raises(ParameterError, match="unknown breaker 'nfs'; choose one of bsgs, rho"):
        get_breaker("nfs")
    with pytest.raises(ParameterError):
        get_breaker("rho", max_bits=1)
    with pytest.raises(ParameterError):
        break_sequence("rho", "not a group", [4])


def test_errors_belong_to_the_hierarchy() -> None:
    for cls in (BreakerError, BreakerLimitError, BreakerTimeoutError, OptionalDependencyError):
        assert issubclass(cls, EncctlError)
    assert format_seconds(0.0021) == "2.1 ms" and format_seconds(86400 * 365.25 * 3) == "3 years"


# ----------------------------------------------------------------------------- distribution
def test_precomputations_pickle_without_their_random_source() -> None:
    hs, secrets, _ = sequence(32, 2)
    for name in ("bsgs", "rho-multi", "index-calculus"):
        pre = precomputed(name, 32)
        copy = pickle.loads(pickle.dumps(pre))
        assert copy.rng is None
        assert [copy.break_key(h, rng=1).s for h in hs] == list(secrets)


def test_joblib_processes_give_the_same_keys() -> None:
    hs, secrets, _ = sequence(32, 6)
    report = break_sequence("index-calculus", group(32), hs, n_jobs=2)
    assert report.secrets == list(secrets)


def test_local_dask_cluster_gives_the_same_keys() -> None:
    pytest.importorskip("distributed")
    hs, secrets, _ = sequence(32, 6)
    report = break_sequence(get_breaker("rho-multi", rng=1), group(32), hs, scheduler="local", n_jobs=2)
    assert report.secrets == list(secrets)
    with pytest.raises(ParameterError, match="main thread"):
        break_sequence(BREAKERS["pari"](), group(32), hs, scheduler="local")


def test_random_draws_cover_the_exponent_range() -> None:
    rng = random.Random(0)
    grp = group(24)
    pre = precomputed("rho", 24)
    for s in (1, 2, grp.q - 1, grp.q // 2, rng.randrange(1, grp.q)):
        assert pre.break_key(int(gmpy2.powmod(grp.g, s, grp.p))).s == s


# ----------------------------------------------------------------------------- hardening
@pytest.mark.parametrize("name", list(BREAKERS))
def test_an_unknown_option_is_named_with_the_options_of_the_breaker(name: str) -> None:
    with pytest.raises(ParameterError, match="has no option 'bogus_option'") as err:
        get_breaker(name, bogus_option=1)
    assert "max_bits" in str(err.value) and "rng" in str(err.value)
    assert isinstance(get_breaker(name, rng=1), BREAKERS[name])  # a known option still builds it


def test_no_breaker_starts_a_first_key_expected_beyond_a_year(monkeypatch: pytest.MonkeyPatch) -> None:
    from encctl_gym.cryptanalysis.base import MAX_EXPECTED_SECONDS
    from encctl_gym.cryptanalysis.rho import SECONDS_PER_STEP

    monkeypatch.setattr(PollardRho, "_precompute", lambda *a, **k: pytest.fail("work started"))
    year = 365.25 * 86400
    assert MAX_EXPECTED_SECONDS == year
    big = shipped_group(712)
    with pytest.raises(BreakerLimitError, match="MAX_EXPECTED_SECONDS") as err:
        PollardRho(max_bits=100_000).precompute(big)
    # Hand computation of rho's cost model: sqrt(pi q / 2) steps of SECONDS_PER_STEP.
    years = math.sqrt(math.pi * big.q / 2) * SECONDS_PER_STEP / year
    assert f"{years:.3g} years" in str(err.value) and "max_bits = 100000" in str(err.value)
    # 64 bits: about sqrt(pi 2^62) steps, some ten minutes, well under the ceiling: accepted.
    small = shipped_group(64)
    assert math.sqrt(math.pi * small.q / 2) * SECONDS_PER_STEP < 3600
    PollardRho(max_bits=64).check_feasible(small)


def test_multi_log_rho_refuses_a_table_beyond_its_memory_limit() -> None:
    from encctl_gym.cryptanalysis.rho import MAX_TABLE_WALKS

    for walks in (MAX_TABLE_WALKS + 1, 10**12, 10**400):
        with pytest.raises(BreakerLimitError, match="MAX_TABLE_WALKS") as err:
            MultiLogRho(table_walks=walks)
        assert ("table_walks = " + ("<integer of 1329 bits" if walks == 10**400 else str(walks))) in str(err.value)
    assert MultiLogRho(table_walks=MAX_TABLE_WALKS).table_walks == MAX_TABLE_WALKS  # nothing is built yet


def test_index_calculus_refuses_a_factor_base_beyond_its_memory_limits() -> None:
    import sympy

    from encctl_gym.cryptanalysis.index_calculus import MATRIX_BYTES_PER_ENTRY, MAX_MATRIX_BYTES
    from encctl_gym.cryptanalysis.smoothness import MAX_BOUND
    from encctl_gym.errors import ResourceLimitError

    with pytest.raises(ResourceLimitError, match="MAX_BOUND") as err:
        IndexCalculus(bound=10**12)
    assert "1000000000000" in str(err.value)
    grp = group(32)
    ic = IndexCalculus(bound=400_000)
    # Independently: pi(4 10^5) = 33860 unknowns; the dense core keeps 0.4 of the (1.05 k + 20)
    # rows and of the k unknowns (plus the right-hand side).
    k = int(sympy.primepi(400_000))
    assert k == 33860
    core = 0.4 * (1.05 * k + 20) * (0.4 * k + 1) * MATRIX_BYTES_PER_ENTRY
    assert ic.matrix_bytes(grp) == pytest.approx(core, rel=0.01)
    with pytest.raises(BreakerLimitError, match="bound 400000") as err:
        ic.precompute(grp)
    assert "MAX_MATRIX_BYTES" in str(err.value) and ic.matrix_bytes(grp) > MAX_MATRIX_BYTES
    assert MAX_BOUND == 2**24 and IndexCalculus(bound=MAX_BOUND).bound == MAX_BOUND
    # The default bound of the largest group the breaker takes (128 bits) stays within the limit.
    assert IndexCalculus(max_bits=128).matrix_bytes(shipped_group(128)) < MAX_MATRIX_BYTES


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"hs": None}, "hs must be an iterable"),
        ({"hs": 42}, "got 42"),
        ({"chunks": 0}, "chunks must be >= 1, got 0"),
        ({"chunks": 2.5}, "chunks must be an integer, got 2.5"),
        ({"seed": -1}, "seed must be >= 0, got -1"),
        ({"seed": "a"}, "seed must be an integer, got 'a'"),
        ({"n_jobs": -5}, "n_jobs must be -1 (all cores) or >= 1, got -5"),
        ({"scheduler": "tcp://"}, "scheduler address 'tcp://' names no host:port"),
        ({"scheduler": 3}, "got 3"),
    ],
)
def test_break_sequence_checks_every_option_before_the_precomputation(
    monkeypatch: pytest.MonkeyPatch, kwargs: dict, message: str
) -> None:
    breaker = get_breaker("bsgs")
    monkeypatch.setattr(breaker, "precompute", lambda *a, **k: pytest.fail("work started"))
    hs, _, _ = sequence(24, 2)
    with pytest.raises(ParameterError) as err:
        break_sequence(breaker, group(24), **{"hs": list(hs), **kwargs})
    assert message in str(err.value)


def test_break_sequence_takes_a_seed_sequence_and_one_chunk() -> None:
    import numpy as np

    hs, secrets, _ = sequence(24, 3)
    report = break_sequence("bsgs", group(24), hs, n_jobs=1, chunks=1, seed=np.random.SeedSequence(4))
    assert report.secrets == list(secrets)


def test_options_given_with_a_breaker_instance_are_refused_not_ignored() -> None:
    rho = PollardRho()
    with pytest.raises(ParameterError, match="'max_bits' apply to a breaker built by name"):
        get_breaker(rho, max_bits=20)
    assert get_breaker(rho) is rho
    with pytest.raises(ParameterError, match="max_bits applies to an inner breaker built by name"):
        TokenChain(rho, max_bits=20)
    assert TokenChain(rho).max_bits == rho.max_bits == 64


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"pre": 3}, "pre must be a Precomputation, got 3"),
        ({"breaker": "token-chain", "tokens": 5}, "tokens must be an iterable of update tokens, got 5"),
        ({"progress": "no"}, "progress must be True or False, got 'no'"),
    ],
)
def test_break_sequence_refuses_a_bad_precomputation_tokens_or_progress(kwargs: dict, message: str) -> None:
    hs, _, _ = sequence(24, 1)
    with pytest.raises(ParameterError) as err:
        break_sequence(**{"breaker": "bsgs", "group": group(24), "hs": list(hs), **kwargs})
    assert message in str(err.value)


@needs_pari
def test_a_pari_failure_is_a_one_line_breaker_error(monkeypatch: pytest.MonkeyPatch) -> None:
    # cypari's own PariError, built without running PARI: once an alarm has interrupted znlog
    # (test_pari_time_limit_uses_an_alarm), any later PARI error crashes the process (a cypari
    # bug, see the pari module), so the failure is raised where znlog would give up.
    import cypari._pari as cp

    failure = cp.PariError(1, "sorry, solve recovery [too many iterations] is not yet implemented")

    class GivesUp:
        def Mod(self, *args: object) -> None:
            return None

        def znlog(self, *args: object) -> None:
            raise failure

    pre = get_breaker("pari").precompute(TOY)
    pre._objects = (None, None)
    monkeypatch.setattr(pari_mod, "_pari", lambda: GivesUp())
    with pytest.raises(BreakerError, match="pari: znlog failed for h = 4") as err:
        pre.break_key(4)
    assert "\n" not in str(err.value) and type(failure).__name__ == "PariError"


# ----------------------------------------------------------------------------- small q in a large p
@cache
def small_order_group(q_bits: int, p_bits: int, seed: int = 0) -> GroupParams:
    """A group p = n q + 1 with a q of ``q_bits`` bits and a p of ``p_bits`` bits (not a safe prime)."""
    rnd = random.Random(seed)
    q = int(gmpy2.next_prime(rnd.getrandbits(q_bits) | (1 << (q_bits - 1))))
    while True:
        n = (rnd.getrandbits(p_bits - q_bits) | (1 << (p_bits - q_bits - 1))) & ~1
        p = n * q + 1
        if p.bit_length() == p_bits and n % q and gmpy2.is_prime(p):
            break
    g = next(g for g in (pow(x, n, p) for x in range(2, 100)) if g != 1)
    return GroupParams(p, q, g)


@pytest.mark.parametrize("q_bits", [8, 12, 16])
def test_index_calculus_breaks_groups_whose_q_is_small(q_bits: int) -> None:
    # G has only q elements: powers of g alone gave too few smooth residues for the relations of
    # a 64-bit p (the system stayed rank-deficient, no logarithm determined). The lattice sieve
    # takes many pairs per residue; below that, baby-step giant-step breaks the group.
    grp = small_order_group(q_bits, 64)
    ic = IndexCalculus(rng=1)
    pre = ic.precompute(grp)
    for s in (1, 2, 123 % grp.q, grp.q - 1):
        key = pre.break_key(pow(grp.g, s, grp.p))
        assert key.s == s and key.method == "index-calculus"
    assert pickle.loads(pickle.dumps(pre)).break_key(pow(grp.g, 77, grp.p), rng=2).s == 77
    assert ic.uses_baby_steps(grp) if q_bits == 8 else True
    assert not ic.uses_baby_steps(grp) if q_bits == 16 else True  # the relations themselves
    assert not ic.uses_baby_steps(group(48))


@pytest.mark.parametrize("name", ["rho", "bsgs"])
def test_generic_limits_count_the_bits_of_q_not_of_p(name: str) -> None:
    grp = small_order_group(30, 79)
    secret = 123456789 % grp.q
    key = get_breaker(name, rng=1).precompute(grp).break_key(pow(grp.g, secret, grp.p))
    assert key.s == secret
    with pytest.raises(BreakerLimitError, match="30-bit q: its limit is 29 bits"):
        get_breaker(name, max_bits=29).precompute(grp)


def test_bsgs_checks_a_match_of_the_low_bits_beyond_64_bit_p() -> None:
    # p > 2^64: the table keeps the low 64 bits of g^j; every key of the small group is found.
    grp = small_order_group(12, 72)
    pre = get_breaker("bsgs").precompute(grp)
    assert all(pre.break_key(pow(grp.g, s, grp.p)).s == s for s in range(0, grp.q, 97))
