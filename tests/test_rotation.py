"""Group rotation (``rotate_group_every``): the loop, the pool, the seam and the cost per group.

Fast: the loop's group is the shipped 64-bit one (``key_length=64``) and every fresh group has 64
bits too; ``delta`` and ``x_bound`` are small so that the ideal backend's quantisation table,
rebuilt for every group, has 2^14 entries.
"""

from __future__ import annotations

import copy
import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.crypto.group import GroupParams, shipped_group
from encctl_gym.envs import EncryptedLTIAttackEnv
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ParameterError
from encctl_gym.loop import DefenderAction, DefenderBase, RotatingDefender
from encctl_gym.loop.elgamal import party_random_sources
from encctl_gym.loop.provisioning import GroupDecipherers
from encctl_gym.loop.rotation import GroupPool
from encctl_gym.security.cost_models import KeyBreakCost
from encctl_gym.security.defenses import rotated_deciphering_operations
from encctl_gym.security.exact import decimal_fraction
from encctl_gym.security.rotation import rotated_affordable_samples, rotated_deciphering_time

BASE = dict(key_length=64, max_samples=14, crypto_seed=5, delta=64, x_bound=48.0)


def make(**kw):
    return EncryptedLTIAttackEnv(config={**BASE, **kw})


def rollout(env, seed=1):
    """Observations, rewards and infos of one episode with a fixed action sequence."""
    obs, info = env.reset(seed=seed)
    rng = np.random.default_rng(7)
    out = [(obs.tobytes(), None)]
    term = trunc = False
    while not (term or trunc):
        obs, r, term, trunc, info = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
        out.append((obs.tobytes(), float(r)))
    return out, info


# ----------------------------------------------------------------------------- configuration
@pytest.mark.parametrize("bad", [0, -3, 2.5, True, "10"])
def test_a_bad_rotation_period_is_refused_naming_it(bad):
    with pytest.raises(ParameterError, match="rotate_group_every") as err:
        resolve_params(rotate_group_every=bad, key_length=64, max_samples=10)
    assert repr(bad) in str(err.value) or str(bad) in str(err.value)


def test_no_rotation_is_the_default_and_adds_no_info():
    assert resolve_params(key_length=64, max_samples=10).rotate_group_every is None
    _, info = rollout(make(max_samples=10))
    assert "groups" not in info and "provisioning_encryptions" not in info


# ----------------------------------------------------------------------------- the cost per group
def test_the_precomputation_model_charges_one_precomputation_per_group_by_hand():
    p = resolve_params(
        preset="paper-example", key_length=712, deciphering_model="precomputation", rotate_group_every=10, max_samples=50
    )
    pre, key = p.cost.precomputation, p.cost.next
    assert p.cost.first == pre + key
    ups = float(decimal_fraction("upsilon", p.upsilon))
    Ns = np.arange(36)
    by_hand = np.array([(-(-n // 10) * float(pre) + n * float(key)) / ups for n in Ns])  # ceil(N/10) C_pre + N C_key
    np.testing.assert_allclose(p.deciphering_time(Ns), by_hand, rtol=1e-12)
    assert p.deciphering_time(Ns)[[0, 1, 10, 11, 20, 21]].tolist() == pytest.approx(
        [0.0, float(pre + key) / ups, float(pre + 10 * key) / ups, float(2 * pre + 11 * key) / ups,
         float(2 * pre + 20 * key) / ups, float(3 * pre + 21 * key) / ups],
        rel=1e-12,
    )  # fmt: skip
    for n in (1, 9, 10, 11, 35):  # the array form is the one home's scalar formula
        assert p.deciphering_time(n) == pytest.approx(rotated_deciphering_operations(n, 10, float(pre), float(key)) / ups)


def test_the_paper_model_is_unchanged_by_rotation():
    plain = resolve_params(preset="paper-example", key_length=712)
    rotated = resolve_params(preset="paper-example", key_length=712, rotate_group_every=3)
    Ns = np.arange(plain.horizon + 1)
    assert np.array_equal(plain.deciphering_time(Ns), rotated.deciphering_time(Ns))
    assert (plain.budget_samples, plain.horizon) == (rotated.budget_samples, rotated.horizon)


def test_the_budget_with_a_new_group_every_step_pays_the_first_key_every_time():
    p = resolve_params(preset="paper-example", key_length=712, deciphering_model="precomputation", rotate_group_every=1)
    budget = decimal_fraction("upsilon", p.upsilon) * decimal_fraction("tau_c", p.tau_c)
    assert p.budget_samples == math.floor(budget / p.cost.first)  # every key is a first key
    assert p.horizon == p.budget_samples and p.budget_limited
    assert p.sample_cost == pytest.approx(float(p.cost.first / decimal_fraction("upsilon", p.upsilon)))
    assert p.deciphering_time(p.horizon) <= p.tau_c < p.deciphering_time(p.horizon + 1)


def test_a_period_beyond_the_budget_is_the_fixed_group():
    plain = resolve_params(preset="paper-example", key_length=712, deciphering_model="precomputation", max_samples=10**6)
    rotated = resolve_params(
        preset="paper-example", key_length=712, deciphering_model="precomputation", max_samples=10**6, rotate_group_every=10**30
    )
    assert rotated.budget_samples == plain.budget_samples


@settings(max_examples=60, deadline=None)
@given(K=st.integers(1, 12), pre=st.integers(0, 50), key=st.integers(1, 7), budget=st.integers(1, 400), independent=st.booleans())
def test_the_affordable_samples_are_the_largest_n_within_the_budget(K, pre, key, budget, independent):
    cost = KeyBreakCost("hand", Fraction(pre + key), Fraction(key))
    scheme = "modified" if independent else "static"

    def work(n):  # by hand: every group pays its first key, further keys of a group pay C_key
        groups = -(-n // K)
        return groups * (pre + key) + (n - groups) * key if independent else groups * (pre + key)

    got = rotated_affordable_samples(budget, cost, 1, K, scheme=scheme)
    assert work(got) <= budget
    if independent:
        assert work(got + 1) > budget
    else:  # one break reveals a whole group: the next group is out of reach
        assert got % K == 0 and work(got + K) > budget
    if got:
        assert rotated_deciphering_time(got, cost, 1, K, scheme=scheme) == pytest.approx(work(got))


# ----------------------------------------------------------------------------- the loop
def test_both_backends_are_bit_identical_with_rotation():
    ideal, ii = rollout(make(crypto="ideal", rotate_group_every=4))
    real, ie = rollout(make(crypto="elgamal", rotate_group_every=4))
    assert ideal == real
    assert {k: v for k, v in ii.items() if "seconds" not in k} == {k: v for k, v in ie.items() if "seconds" not in k}


def test_the_server_is_reprovisioned_in_every_new_group_by_hand():
    env = make(crypto="elgamal", rotate_group_every=4)
    _, info = rollout(env)
    p = env.unwrapped.params
    groups = -(-p.horizon // 4)  # x_0 .. x_13 in groups of 4
    assert info["groups"] == groups and info["group_rotations"] == groups - 1
    assert info["provisioning_encryptions"] == (groups - 1) * p.n * p.m
    assert info["provisioning_bytes"] == (groups - 1) * (2 * p.n * p.m + 2) * 8  # 64-bit elements: 8 bytes
    rec = env.unwrapped.episode.rotation
    assert (rec.rotations, rec.keygens) == (groups - 1, groups - 1)
    loop = env.unwrapped.episode.loop
    assert loop.group != shipped_group(64) and loop.group.bits == 64 and loop.group.is_safe_prime
    assert loop.plant.group == loop.group == loop.server.pk0.group
    assert info["group_generation_model_seconds"] > 0 and info["group_generation_seconds"] > 0


def test_every_episode_starts_on_the_first_group_and_meets_the_same_groups():
    env = make(crypto="ideal", rotate_group_every=3)
    a, _ = rollout(env, seed=2)
    seen = env.unwrapped.episode.loop.group
    env.reset(seed=0)
    assert env.unwrapped.episode.loop.group == shipped_group(64)
    assert env.unwrapped.episode.rotation.rotations == 0
    b, _ = rollout(env, seed=2)
    assert a == b and env.unwrapped.episode.loop.group == seen


def test_the_vector_env_rotates_all_copies_and_reports_per_copy():
    from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv

    vec = EncryptedLTIAttackVectorEnv(num_envs=3, config={**BASE, "rotate_group_every": 5}, helper_thread=False)
    vec.reset(seed=0)
    for _ in range(6):
        _, _, _, _, info = vec.step(np.zeros((3, vec.params.m), dtype=np.float32))
    assert info["groups"].tolist() == [2, 2, 2]
    vec.close()


# ----------------------------------------------------------------------------- the breaker
def test_the_breaker_redoes_its_precomputation_in_every_group():
    env = make(crypto="elgamal", breaker="index-calculus", rotate_group_every=6)
    plain, _ = rollout(make(crypto="elgamal", rotate_group_every=6))
    broken, info = rollout(env)
    assert broken == plain  # the recovered exponents decrypt what the keys do
    groups = -(-env.unwrapped.params.horizon // 6)
    assert info["breaker_precomputations"] == groups
    dec = env.unwrapped.episode.loop.decipherer
    assert isinstance(dec, GroupDecipherers)
    methods = [m for m, _ in dec.costs]
    assert methods.count("precomputation") == groups and methods.count("index-calculus") == env.unwrapped.params.horizon
    assert dec.seconds == pytest.approx(sum(c.seconds for _, c in dec.costs))
    assert all(c.seconds > 0 for m, c in dec.costs if m == "precomputation")


# ----------------------------------------------------------------------------- the pool
def test_the_pool_is_seeded_from_the_plant_stream_and_does_not_depend_on_how_far_ahead_it_runs():
    def pool(ahead):
        return GroupPool(64, party_random_sources(5)["plant"].spawn("group-rotation"), ahead=ahead)

    a, b = pool(0), pool(3)
    b.prefetch(1)
    ga = [a.get(i)[0] for i in (1, 2, 3)]
    gb = [b.get(i)[0] for i in (1, 2, 3)]
    assert ga == gb and len({g.p for g in ga}) == 3
    assert all(g.bits == 64 and g.is_safe_prime for g in ga)
    env = make(crypto="ideal", rotate_group_every=4)
    rollout(env)
    assert env.unwrapped.episode.loop.group == ga[2]  # 14 samples in groups of 4: the loop ends on group 3
    c = copy.deepcopy(b)  # a copy has the groups and no worker
    assert c.get(4)[0] == b.get(4)[0]
    a.close(), b.close(), c.close()


def test_the_plant_keys_are_those_of_the_loop_without_rotation():
    plain, rot = make(crypto="elgamal"), make(crypto="elgamal", rotate_group_every=4)
    plain.reset(seed=0)
    rot.reset(seed=0)
    assert plain.unwrapped.episode.loop.plant.pk0 == rot.unwrapped.episode.loop.plant.pk0


# ----------------------------------------------------------------------------- the seam
def test_rotation_composes_with_another_policy_and_is_refused_twice():
    env = make(crypto="ideal", defender={"name": "rotate", "every": 5, "inner": {"name": "noise", "sigma_d2": 0.01}})
    _, info = rollout(env)
    assert info["groups"] == 3
    with pytest.raises(ParameterError, match="rotates already"):
        make(defender={"name": "rotate", "every": 5}, rotate_group_every=3)
    with pytest.raises(ParameterError, match="every must be >= 1"):
        RotatingDefender(every=0)


class _BadGroup(DefenderBase):
    name = "bad-group"

    def __init__(self, group):
        self.bad = group

    def group(self, params):
        return shipped_group(64)

    def reset(self, K, n, m, rngs):
        pass

    def act(self, view):
        return DefenderAction(new_group=self.bad)


@pytest.mark.parametrize(
    "group,text", [("p", "safe-prime GroupParams"), (GroupParams(23, 11, 4), "64 bits"), (shipped_group(128), "64 bits")]
)
def test_a_bad_new_group_is_refused_naming_it(group, text):
    env = make(defender=_BadGroup(group))
    env.reset(seed=0)
    with pytest.raises(ParameterError, match=text):
        env.step(np.zeros(env.action_space.shape, dtype=np.float32))


@pytest.mark.parametrize("K", [1, 10, 100, 13159])
def test_the_rotated_key_length_is_the_smallest_whose_groups_cost_more_than_the_budget(K):
    from encctl_gym.security.cost_models import PaperModel, PrecomputationModel
    from encctl_gym.security.rotation import rotated_minimum_key_length

    budget = Fraction(442 * 10**15) * Fraction(315_360_000)  # the design example: Upsilon tau_c
    model, N = PrecomputationModel(), 13159
    k = rotated_minimum_key_length(model, N, K, budget)

    def work(bits):  # by hand: ceil(N / K) precomputations and N per-key descents
        c = model.break_cost(bits)
        return -(-N // K) * c.precomputation + N * c.next

    assert work(k) > budget >= work(k - 1)
    if K >= N:
        assert k == model.minimum_key_length(N, budget)  # one group: the fixed-group design
    assert rotated_minimum_key_length(PaperModel(), N, K, budget) == PaperModel().minimum_key_length(N, budget)


def test_an_audit_composed_with_rotation_follows_the_encoding_of_each_new_group():
    """The honest controller, audited at every step across rotations, never alarms: the audit's
    error bound takes every new group's largest shift."""
    from encctl_gym.crypto.residue_table import residue_table
    from encctl_gym.loop import make_loop
    from encctl_gym.loop.backend import table_limit
    from encctl_gym.loop.defender import PlantView
    from encctl_gym.loop.defenses import AuditDefender

    p = resolve_params({**BASE, "max_samples": 40})
    d = RotatingDefender(every=3, inner=AuditDefender(rate=1.0))
    loop = make_loop(p.loop, d)
    K, T = 20, 30
    rng = np.random.default_rng(3)
    x, U = np.zeros((K, p.n)), np.zeros((T, K, p.m))
    step = {"k": 0}
    view = PlantView(x, U, lambda: step["k"])
    d.reset(K, p.n, p.m, [np.random.default_rng(i) for i in range(K)])
    moves = 0
    for k in range(T):
        step["k"] = k
        x[...] = rng.uniform(-5, 5, size=(K, p.n))
        action = d.act(view)
        assert action is None or not action.end
        if action is not None and action.new_group is not None:
            loop.rotate_group(action.new_group)
            moves += 1
            assert d.inner.max_shift == residue_table(loop.group, table_limit(p.loop, loop.Phi)).max_shift
        U[k] = loop.control(x)
    assert moves == T // 3 and d.inner.audits == K * (T - 1)


def test_the_measured_clock_charges_every_group_s_precomputation():
    env = make(crypto="elgamal", breaker="index-calculus", deciphering_clock="measured", rotate_group_every=5, max_samples=10)
    _, info = rollout(env)
    dec = env.unwrapped.episode.loop.decipherer
    pre = [c.seconds for m, c in dec.costs if m == "precomputation"]
    assert len(pre) == info["breaker_precomputations"] == 2
    assert info["deciphering_time"] == pytest.approx(dec.seconds) and dec.seconds >= sum(pre)


def test_the_generic_model_is_unchanged_by_rotation():
    kw = dict(preset="paper-example", key_length=64, deciphering_model="generic", max_samples=50)
    plain, rotated = resolve_params(**kw), resolve_params(**kw, rotate_group_every=7)
    Ns = np.arange(51)
    assert np.array_equal(plain.deciphering_time(Ns), rotated.deciphering_time(Ns))


@pytest.mark.slow
def test_the_rotation_table_counts_one_precomputation_per_group():
    from encctl_gym.experiments.defenses_rotation import format_rotation, rotation_rows

    rows = rotation_rows(samples=12, seed=1)
    ks = [r["k_star_precomputation"] for r in rows["design"]]
    assert ks == sorted(ks) and len(set(r["k_star_paper"] for r in rows["design"])) == 1  # paper model: unchanged
    for r in rows["measured"]:
        assert r["precomputations"] == r["groups"] == r["groups_expected"] == -(-12 // r["K"])
        assert r["encryptions"] == (r["groups"] - 1) * 16
    assert format_rotation(rows).count("\n") == 2 + 4 + 1 + 2 + 4 - 1


def test_a_copied_rotating_episode_runs_on_as_the_original():
    env = make(crypto="ideal", rotate_group_every=3)
    env.reset(seed=4)
    a = np.full(env.action_space.shape, 0.3, dtype=np.float32)
    for _ in range(4):
        env.step(a)
    twin = copy.deepcopy(env)
    for _ in range(5):
        o1, r1, *_, i1 = env.step(a)
        o2, r2, *_, i2 = twin.step(a)
        assert o1.tobytes() == o2.tobytes() and i1["groups"] == i2["groups"]  # the loop and its groups
    assert twin.unwrapped.episode.loop.group == env.unwrapped.episode.loop.group


def test_closing_the_env_stops_the_group_pools_worker():
    env = make(crypto="ideal", rotate_group_every=3)
    rollout(env)
    pool = env.unwrapped.episode.defender.pool
    assert pool._executor is not None  # the worker ran ahead during the episode
    env.close()
    assert pool._executor is None
