"""Gymnasium environments of encctl-gym.

``encctl_gym/EncryptedLTIAttack-v0`` is registered when :mod:`encctl_gym` is imported::

    import gymnasium as gym
    import encctl_gym  # noqa: F401  (registers the environment)

    env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config={"preset": "small"})
    envs = gym.make_vec("encctl_gym/EncryptedLTIAttack-v0", num_envs=1024)  # native batched
"""

from __future__ import annotations

from ..registration import ENV_ID, register_envs
from .config import AttackParams, default_config, resolve_params
from .encrypted_lti_attack import EncryptedLTIAttackEnv

__all__ = ["EncryptedLTIAttackEnv", "default_config", "resolve_params", "AttackParams", "ENV_ID", "register_envs"]

register_envs()
