"""The attack as a two-player game: the attacker against a defender that learns too.

:class:`~encctl_gym.multiagent.game.EncryptedControlGame` is a PettingZoo ``ParallelEnv``
(agents ``"attacker"`` and ``"defender"``) on the episode of ``EncryptedLTIAttack-v0``; the
defender's levers, observation and costs are in :mod:`encctl_gym.multiagent.levers`. PettingZoo's
factories are exported as every PettingZoo environment module exports them
(:mod:`encctl_gym.multiagent.encctl_game_v0`): ``parallel_env()``, ``raw_env()`` (the AEC form
through ``parallel_to_aec``) and ``env()``. It needs
the ``multiagent`` extra (PettingZoo): ``pip install 'encctl-gym[multiagent]'``.
"""

from __future__ import annotations

try:
    import pettingzoo  # noqa: F401
except ModuleNotFoundError:
    from ..errors import OptionalDependencyError

    raise OptionalDependencyError(
        "encctl_gym.multiagent needs PettingZoo; install the extra: pip install 'encctl-gym[multiagent]'"
    ) from None

from . import encctl_game_v0
from .encctl_game_v0 import env, parallel_env, raw_env
from .game import AGENTS, EncryptedControlGame
from .levers import LEVERS, Decision, DefenderLevers, GameRules

__all__ = [
    "AGENTS",
    "LEVERS",
    "Decision",
    "DefenderLevers",
    "EncryptedControlGame",
    "GameRules",
    "encctl_game_v0",
    "env",
    "parallel_env",
    "raw_env",
]
