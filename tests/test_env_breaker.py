"""The environment breaks the keys for real: ``breaker=...`` and ``deciphering_clock``.

The loop's group for ``key_length = 64`` is the shipped 64-bit group, which the index calculus
breaks in about half a second (then about a millisecond per key).
"""

from __future__ import annotations

import numpy as np
import pytest

from encctl_gym.attacks.decipherer import KeyBreaking, KeyOracle
from encctl_gym.crypto.plant_side import PlantParty
from encctl_gym.envs import EncryptedLTIAttackEnv
from encctl_gym.errors import BreakerLimitError, EncctlError, OptionalDependencyError, ParameterError

BASE = dict(crypto="elgamal", key_length=64, max_samples=12, crypto_seed=5)


def make(**kw):
    return EncryptedLTIAttackEnv(config={**BASE, **kw})


def rollout(env, seed=1, steps=None):
    """Observations, rewards, infos and the end flags of one episode with a fixed action sequence."""
    obs, info = env.reset(seed=seed)
    rng = np.random.default_rng(7)
    out = [(obs.tobytes(), None, dict(info))]
    term = trunc = False
    while not (term or trunc):
        obs, r, term, trunc, info = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
        out.append((obs.tobytes(), float(r), dict(info)))
    return out, term, trunc


@pytest.mark.parametrize(
    "scheme,adversary,max_samples",
    [("modified", "eavesdropper", 12), ("token", "eavesdropper", 12), ("token", "server", 12), ("static", "eavesdropper", 12)],
)
def test_model_clock_with_real_breaking_is_bit_identical(scheme, adversary, max_samples):
    plain = make(scheme=scheme, adversary=adversary, max_samples=max_samples)
    broken = make(scheme=scheme, adversary=adversary, max_samples=max_samples, breaker="index-calculus")
    assert isinstance(plain.unwrapped.episode.loop.decipherer, KeyOracle)
    assert isinstance(broken.unwrapped.episode.loop.decipherer, KeyBreaking)
    a, ta, ua = rollout(plain)
    b, tb, ub = rollout(broken)
    assert (ta, ua) == (tb, ub)
    assert a == b  # observations, rewards and info, bit for bit
    costs = broken.unwrapped.episode.loop.decipherer.costs
    assert costs[0][0] == "precomputation"
    methods = [m for m, _ in costs[1:]]
    if scheme == "static":
        assert methods == ["index-calculus"]  # one key, broken once
    elif adversary == "server":
        assert methods[0] == "index-calculus" and set(methods[1:]) == {"token"}  # prop:vulnerability
    else:
        assert methods == ["index-calculus"] * 12  # x_0 .. x_11: one key per sample


def test_plant_secret_is_not_read(monkeypatch):
    """With a breaker, the adversary's data come from recovered exponents only: the plant's
    secret keys are never read (reading them raises here), yet the data are the same."""
    reference, _, _ = rollout(make())

    def forbidden(self):
        raise AssertionError("the plant's secret key was read")

    monkeypatch.setattr(PlantParty, "secret_key", property(forbidden))
    monkeypatch.setattr(PlantParty, "initial_secret_key", property(forbidden))
    with pytest.raises(AssertionError, match="secret key was read"):
        rollout(make())  # the oracle reads it: the patch bites
    broken, _, _ = rollout(make(breaker="index-calculus"))
    assert broken == reference


def test_recovered_exponents_are_the_plant_keys():
    env = make(breaker="index-calculus", max_samples=10)
    env.reset(seed=0)
    loop = env.unwrapped.episode.loop
    for _ in range(5):
        sk = loop.plant.secret_key  # privileged, in the test only
        assert loop.decipherer.secret(loop.plant.pk) == sk.s
        env.step(np.zeros(env.action_space.shape, dtype=np.float32))


def test_precomputation_once_per_group_across_episodes(monkeypatch):
    env = make(breaker="index-calculus", max_samples=10)
    dec = env.unwrapped.episode.loop.decipherer
    calls = []
    original = dec.breaker.precompute

    def counting(group, **kw):
        calls.append(group.bits)
        return original(group, **kw)

    monkeypatch.setattr(dec.breaker, "precompute", counting)
    for seed in range(3):
        rollout(env, seed=seed)
        assert dec.costs[0][0] == "precomputation"  # charged to every episode
    assert calls == [64]  # computed once


def test_measured_clock_charges_the_breakers_seconds():
    env = make(breaker="index-calculus", deciphering_clock="measured", tau_c=3600.0)
    out, term, trunc = rollout(env)
    assert trunc and not term  # max_samples reached well within an hour
    times = [info["deciphering_time"] for _, _, info in out]
    assert all(b >= a for a, b in zip(times, times[1:]))
    dec = env.unwrapped.episode.loop.decipherer
    assert times[-1] == pytest.approx(sum(c.seconds for _, c in dec.costs))
    assert times[0] >= dec.costs[0][1].seconds > 0  # the first sample carries the precomputation


class FixedClock:
    """A decipherer double for the episode's clock logic: the true key, a fixed time per key."""

    def __init__(self, read_key, seconds_per_key):
        self._read, self._dt = read_key, seconds_per_key
        self.seconds = 0.0

    def start_episode(self):
        self.seconds = 0.0

    def secret(self, pk):
        self.seconds += self._dt
        return self._read().s

    def observe_token(self, token):
        pass


def test_measured_clock_terminates_when_tau_c_passes():
    env = make(breaker="index-calculus", deciphering_clock="measured", tau_c=4.5, max_samples=50)
    loop = env.unwrapped.episode.loop
    loop.decipherer = FixedClock(lambda: loop.plant.secret_key, 1.0)
    out, term, trunc = rollout(env)
    assert term and not trunc
    last = out[-1][2]
    assert last["samples_collected"] == 4  # keys 1..4 take 4 s; the fifth would end at 5 s > tau_c
    assert last["deciphering_time"] == pytest.approx(4.0)
    assert env.unwrapped.episode.expired


def test_measured_clock_first_break_too_late():
    env = make(breaker="index-calculus", deciphering_clock="measured", tau_c=1e-9)
    out, term, trunc = rollout(env)
    assert term and len(out) == 2 and out[-1][2]["samples_collected"] == 0


@pytest.mark.parametrize(
    "kw,match",
    [
        (dict(crypto="ideal", breaker="index-calculus"), "needs crypto='elgamal'"),
        (dict(breaker="nfs"), "unknown breaker 'nfs'"),
        (dict(breaker=3), "unknown breaker 3"),
        (dict(deciphering_clock="measured"), "needs a breaker"),
        (dict(deciphering_clock="wall", breaker="pari"), "unknown deciphering_clock 'wall'"),
        (dict(breaker="index-calculus", deciphering_clock="measured", max_samples=None, scheme="modified"), "set max_samples"),
        (dict(breaker="index-calculus", breaker_time_limit=-1), "breaker_time_limit"),
    ],
)
def test_bad_breaker_configuration(kw, match):
    with pytest.raises(ParameterError, match=match):
        make(**kw)


@pytest.mark.parametrize(
    "kw,match",
    [
        (dict(key_length=712, max_samples=12), "refuses a 712-bit group"),  # beyond index calculus' 112 bits
        (dict(breaker="bsgs"), "limit is 56 bits"),
        (dict(breaker="rho"), "breaker_time_limit"),  # about 9 minutes per key at 64 bits
        (dict(breaker_time_limit=1e-4), "breaker_time_limit"),
    ],
)
def test_breaker_refused_before_any_work(kw, match):
    kw = {"breaker": "index-calculus", **kw}
    with pytest.raises(BreakerLimitError, match=match) as info:
        make(**kw)
    assert "expected" in str(info.value) or "about" in str(info.value)
    assert isinstance(info.value, EncctlError)


def test_pari_missing_is_one_line_naming_the_extra(monkeypatch):
    import sys

    import encctl_gym.cryptanalysis.pari as pari

    monkeypatch.setattr(pari, "_PARI", None)
    monkeypatch.setitem(sys.modules, "cypari", None)
    with pytest.raises(OptionalDependencyError, match=r"pip install 'encctl-gym\[cryptanalysis\]'") as err:
        make(breaker="pari")
    assert "\n" not in str(err.value)


@pytest.mark.skipif(
    not __import__("encctl_gym.cryptanalysis.pari", fromlist=["x"]).pari_available(), reason="needs the cryptanalysis extra"
)
def test_pari_breaker_in_the_loop_matches():
    a, _, _ = rollout(make(max_samples=9))
    b, _, _ = rollout(make(max_samples=9, breaker="pari"))
    assert a == b


def test_the_readme_real_break_without_max_samples_runs_with_a_capped_horizon():
    """crypto="elgamal", key_length=64, breaker="index-calculus" and nothing else: 64-bit keys buy
    about 9e18 samples, which no episode can hold; the attack is capped (and truncated) at
    MAX_DEFAULT_HORIZON with a warning instead of being refused for memory."""
    import gymnasium as gym

    from encctl_gym.envs import ENV_ID
    from encctl_gym.envs.config import MAX_DEFAULT_HORIZON

    with pytest.warns(UserWarning, match="MAX_DEFAULT_HORIZON"):
        env = gym.make(ENV_ID, config=dict(crypto="elgamal", key_length=64, breaker="index-calculus"))
    p = env.unwrapped.params
    assert p.horizon == MAX_DEFAULT_HORIZON < p.budget_samples and not p.budget_limited
    env.reset(seed=0)
    for _ in range(3):
        _, reward, term, trunc, info = env.step(env.action_space.sample())
        assert np.isfinite(reward) and not (term or trunc)
    assert info["samples_collected"] == 4
    env.close()
