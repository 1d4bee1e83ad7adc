"""Issue 34 items 20, 21 and 23: values nobody should trust (a rotation pool's depth, a nested
rotate defender given as a dict, YAML merge keys that repeat a field, an inject flag outside its
Box, C = 1e155 I, a precomputation of the wrong type, oversized or NUL names)."""

from __future__ import annotations

import time

import pytest

from encctl_gym.envs import EncryptedLTIAttackEnv
from encctl_gym.errors import ParameterError
from encctl_gym.loop import RotatingDefender
from encctl_gym.loop.elgamal import party_random_sources
from encctl_gym.loop.rotation import MAX_AHEAD, GroupPool

BASE = dict(key_length=64, max_samples=14, crypto_seed=5, delta=64, x_bound=48.0, crypto="ideal")


# ----------------------------------------------------------------------------- item 20
@pytest.mark.parametrize("ahead", [10**400, 10**5, MAX_AHEAD + 1, -1, 2.5, True])
def test_a_rotation_pool_deeper_than_max_ahead_is_refused_before_reset(ahead) -> None:
    start = time.perf_counter()
    with pytest.raises(ParameterError, match=r"ahead must be|ahead must be an integer"):
        env = EncryptedLTIAttackEnv(config={**BASE, "defender": {"name": "rotate", "every": 3, "ahead": ahead}})
        env.reset(seed=0)  # before the fix: 10**5 took 73 s, 10**400 never returned
    assert time.perf_counter() - start < 5.0
    with pytest.raises(ParameterError, match="ahead"):
        RotatingDefender(every=3, ahead=ahead)
    with pytest.raises(ParameterError, match="ahead"):
        GroupPool(64, party_random_sources(5)["plant"].spawn("group-rotation"), ahead=ahead)


def test_a_rotation_pool_at_max_ahead_runs() -> None:
    env = EncryptedLTIAttackEnv(config={**BASE, "defender": {"name": "rotate", "every": 3, "ahead": MAX_AHEAD}})
    env.reset(seed=0)
    env.close()


def test_the_games_rotation_ahead_is_bounded() -> None:
    pytest.importorskip("pettingzoo")
    from encctl_gym.multiagent import GameRules

    GameRules(rotation_ahead=MAX_AHEAD)
    for bad in (10**400, MAX_AHEAD + 1):
        with pytest.raises(ParameterError, match=rf"rotation_ahead must be <= {MAX_AHEAD}"):
            GameRules(rotation_ahead=bad)
