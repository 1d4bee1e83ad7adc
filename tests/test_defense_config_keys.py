"""The defender's levers as configuration keys: ``audit_probability`` and ``defense_noise_sigma2``
give the same episodes as the policies they name, combine with each other and with
``defender``, and refuse bad values with the package's error naming the key."""

from __future__ import annotations

import numpy as np
import pytest

from encctl_gym.envs import EncryptedLTIAttackEnv
from encctl_gym.errors import ParameterError
from encctl_gym.loop.defenses import AuditDefender, CombinedDefender, NoiseDefender

BASE = {"preset": "paper-example", "decipher_delay": 0, "max_samples": 60}


def episode(**kw):
    env = EncryptedLTIAttackEnv(config={**BASE, **kw})
    obs, info = env.reset(seed=3)
    rng = np.random.default_rng(11)
    out = [obs.tobytes()]
    done = False
    while not done:
        obs, r, term, trunc, info = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
        out.append((obs.tobytes(), float(r)))
        done = term or trunc
    return out, info, env


@pytest.mark.parametrize(
    ("key", "spec"),
    [("audit_probability", {"name": "audit", "rate": 0.05}), ("defense_noise_sigma2", {"name": "noise", "sigma_d2": 0.3})],
)
def test_a_key_gives_the_episode_of_the_policy_it_names(key, spec):
    value = spec.get("rate", spec.get("sigma_d2"))
    by_key, info_key, _ = episode(**{key: value})
    by_policy, info_policy, _ = episode(defender=spec)
    assert by_key == by_policy and info_key["detected"] == info_policy["detected"]


def test_an_audit_key_stops_an_injecting_attacker_and_never_alarms_without_audits():
    _, info, _ = episode(audit_probability=0.2)
    assert info["detected"]  # the attacker replaces Phi x every step: an audit sees it
    _, info0, _ = episode(audit_probability=0.0)
    assert not info0["detected"] and info0["samples_collected"] == 60


def test_the_keys_combine_with_each_other_and_the_configured_defender():
    _, _, env = episode(audit_probability=0.0, defense_noise_sigma2=0.1, defender={"name": "chi2"})
    policy = env.episode.defender
    assert isinstance(policy, CombinedDefender)
    kinds = [type(p) for p in policy.policies]
    assert kinds[1:] == [AuditDefender, NoiseDefender] and kinds[0].__name__ == "DetectorDefender"
    # the noise lever changes the trajectory; the zero-rate audit does not
    with_noise, _, _ = episode(audit_probability=0.0, defense_noise_sigma2=0.1)
    audit_only, _, _ = episode(audit_probability=0.0)
    assert with_noise != audit_only


@pytest.mark.parametrize(
    ("key", "value"),
    [("audit_probability", -0.1), ("audit_probability", 1.5), ("defense_noise_sigma2", -1.0), ("audit_probability", "often")],
)
def test_bad_values_name_the_key(key, value):
    with pytest.raises(ParameterError, match=key):
        EncryptedLTIAttackEnv(config={**BASE, key: value})
