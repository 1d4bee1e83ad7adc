"""encctl-gym: adversarial experiments on encrypted control systems.

Layers, importing downward only::

    crypto (arith -> group -> encoding -> elgamal -> dyn_elgamal -> modified -> controller)
    sim (plant, identification, parallel)
    security (pure math, beside the others)
    envs (the Gymnasium environment)

Implements K. Teranishi and K. Kogiso, "Optimal Security Parameter for Encrypted Control
Systems Against Eavesdropper and Malicious Server" (arXiv 2303.13059).
"""

from __future__ import annotations

from .errors import (
    BreakerError,
    BreakerLimitError,
    BreakerTimeoutError,
    BudgetError,
    CiphertextError,
    ConfigError,
    EncctlError,
    EncodingOverflowError,
    GroupError,
    KeyMismatchError,
    OptionalDependencyError,
    ParameterError,
    PlaintextError,
    ShapeError,
    SolverError,
    UnstableSystemError,
)

__version__ = "0.1.0"

__all__ = [
    "__version__",
    "EncctlError",
    "ParameterError",
    "ShapeError",
    "UnstableSystemError",
    "GroupError",
    "KeyMismatchError",
    "PlaintextError",
    "CiphertextError",
    "EncodingOverflowError",
    "SolverError",
    "BudgetError",
    "ConfigError",
    "BreakerError",
    "BreakerLimitError",
    "BreakerTimeoutError",
    "OptionalDependencyError",
]


def _register() -> None:
    # Register the Gymnasium environment on import, without importing the environment module
    # (and its dependencies) until gymnasium.make asks for it.
    import gymnasium as gym

    env_id = "encctl_gym/EncryptedLTIAttack-v0"
    if env_id not in gym.registry:
        gym.register(
            id=env_id,
            entry_point="encctl_gym.envs.encrypted_lti_attack:EncryptedLTIAttackEnv",
            vector_entry_point="encctl_gym.envs.vector:EncryptedLTIAttackVectorEnv",
        )


_register()
