"""One seed, one episode, with group rotation and ``crypto_seed=None`` (issue #30, item 5).

Without a crypto seed the keys come from the operating system; the rotated groups (public
parameters, which the quantisation depends on) follow the episode's seed
(:class:`encctl_gym.loop.rotation.RotationGroups`). Two instances reset with one seed must run
the same episode, in the single environment and in the game, over several episodes: PettingZoo's
seed test plays one episode only.
"""

from __future__ import annotations

import numpy as np
import pytest
from episodes import rollout

from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv

CFG = {
    "preset": "small",
    "gamma_opt": False,
    "crypto": "elgamal",
    "key_length": 64,
    "max_samples": 16,
    "warmup_steps": 2,
    "decipher_delay": 0,
    "defender": {"name": "rotate", "every": 5},
    "crypto_seed": None,
}


def _groups(env: EncryptedLTIAttackEnv) -> list[int]:
    """The primes of the groups the episode's pool has handed out, in order."""
    defender = env.unwrapped._core.defender
    return [defender.pool.get(i)[0].p for i in defender.tally.indices]


def test_two_instances_reset_with_one_seed_meet_the_same_groups_and_run_the_same_episode() -> None:
    a, b = EncryptedLTIAttackEnv(config=CFG), EncryptedLTIAttackEnv(config=CFG)
    for seed in (7, 7, 8):  # the same seed twice, then another, on both instances
        ra = rollout(a, seed=seed, action_seed=seed)
        rb = rollout(b, seed=seed, action_seed=seed)
        assert len(ra) == len(rb) and all(np.array_equal(x, y) for x, y in zip(ra, rb))
        assert len(_groups(a)) >= 2 and _groups(a) == _groups(b)
    a.close()
    b.close()


def test_a_reset_without_a_seed_meets_new_groups_and_one_seed_meets_its_own_again() -> None:
    env = EncryptedLTIAttackEnv(config=CFG)
    rollout(env, seed=3, action_seed=0)
    first = _groups(env)
    rollout(env, seed=None, action_seed=0)
    assert set(_groups(env)).isdisjoint(first)  # fresh 64-bit safe primes: no repeat
    rollout(env, seed=3, action_seed=0)
    assert _groups(env) == first
    env.close()


def test_with_a_crypto_seed_every_episode_meets_the_same_groups_as_before() -> None:
    env = EncryptedLTIAttackEnv(config={**CFG, "crypto_seed": 4})
    rollout(env, seed=3, action_seed=0)
    first = _groups(env)
    rollout(env, seed=9, action_seed=0)
    assert _groups(env) == first
    env.close()


def test_the_game_reset_with_one_seed_runs_one_game_in_two_instances() -> None:
    from encctl_gym.multiagent.encctl_game_v0 import parallel_env

    cfg = {k: v for k, v in CFG.items() if k != "defender"}
    games = [parallel_env(config=cfg), parallel_env(config=cfg)]
    for seed in (5, 5):
        runs = []
        for game in games:
            obs, _ = game.reset(seed=seed)
            rng, rows, k = np.random.default_rng(seed), [(obs, {})], 0
            while game.agents:
                acts = {a: rng.uniform(-1, 1, game.action_space(a).shape).astype(np.float32) for a in game.agents}
                acts["defender"][2] = 1.0 if k % 3 == 2 else -1.0  # rotate every third step
                acts["defender"][0] = acts["defender"][3] = -1.0  # no audit, no check (LEVERS): the game runs on
                obs, rewards, _, _, _ = game.step(acts)
                rows.append((obs, rewards))
                k += 1
            runs.append(rows)
        assert len(runs[0]) == len(runs[1]) > 3
        for (oa, ra), (ob, rb) in zip(*runs):
            assert oa.keys() == ob.keys() and all(np.array_equal(oa[a], ob[a]) for a in oa)
            assert ra == rb
    for game in games:
        game.close()


def test_pools_of_reseeded_episodes_are_bounded_and_keyed_by_the_stream() -> None:
    from encctl_gym.loop.rotation import RotationGroups

    groups = RotationGroups(32, None, ahead=0)
    pools = [groups.for_episode(np.random.default_rng(s)) for s in range(RotationGroups.MAX_POOLS + 2)]
    assert len(groups._pools) == RotationGroups.MAX_POOLS
    assert groups.for_episode(np.random.default_rng(RotationGroups.MAX_POOLS + 1)) is pools[-1]
    assert groups.for_episode(np.random.default_rng(0)) is not pools[0]  # evicted, made again
    assert groups.for_episode(np.random.default_rng(0)).get(1)[0] == pools[0].get(1)[0]  # same groups
    assert RotationGroups(32, 1, ahead=0).for_episode(np.random.default_rng(0)) is not None
    groups.close()


@pytest.mark.parametrize("bad", [-1, 17, 2.5])
def test_a_bad_ahead_is_refused(bad: object) -> None:
    from encctl_gym.errors import ParameterError
    from encctl_gym.loop.rotation import RotationGroups

    with pytest.raises(ParameterError, match="ahead"):
        RotationGroups(32, None, ahead=bad)  # type: ignore[arg-type]
