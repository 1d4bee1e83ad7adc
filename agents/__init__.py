"""Attackers for ``EncryptedLTIAttack-v0``: the paper's Gaussian attack, other excitation
baselines, the A-optimal design (an oracle) and policies learned with stable-baselines3.

One interface (:class:`~agents.base.Attacker`: ``reset(seed)``, ``act(obs)``), so an
experiment can loop over them; :func:`~agents.evaluate.rollout` plays them through the
environment. The stable-baselines3 pieces (:mod:`agents.sb3`, :mod:`agents.train`) need the
``[rl]`` extra and are imported lazily.
"""

from .base import OBSERVATION_MODES, Attacker, observation_indices, params_of
from .baselines import ColoredGaussianAttacker, GaussianAttacker, PRBSAttacker
from .evaluate import Rollout, env_config, rollout
from .optimal import OptimalDesignAttacker

__all__ = [
    "Attacker",
    "OBSERVATION_MODES",
    "observation_indices",
    "params_of",
    "GaussianAttacker",
    "PRBSAttacker",
    "ColoredGaussianAttacker",
    "OptimalDesignAttacker",
    "Rollout",
    "rollout",
    "env_config",
    "SB3Attacker",
    "load_attacker",
]


def __getattr__(name: str):  # lazy: stable-baselines3 and torch only when asked for
    if name in ("SB3Attacker", "load_attacker"):
        from . import sb3

        return getattr(sb3, name)
    raise AttributeError(f"module 'encctl_gym.agents' has no attribute {name!r}")
