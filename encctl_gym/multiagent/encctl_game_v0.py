"""The game under PettingZoo's names: ``parallel_env``, ``raw_env`` and ``env``.

A PettingZoo environment module (``pistonball_v6``, ``encctl_game_v0``) exports three
factories, all taking the environment's keyword arguments:

* :func:`parallel_env` -- the ``ParallelEnv`` itself,
  :class:`~encctl_gym.multiagent.game.EncryptedControlGame` (both agents act at once);
* :func:`raw_env` -- the same game in the agent-environment-cycle (AEC) form, through
  PettingZoo's ``parallel_to_aec`` (the attacker acts, then the defender, then the step runs):
  not a second implementation of the game;
* :func:`env` -- :func:`raw_env` as PettingZoo's documented examples hand it out (the AEC form
  with its order-enforcing wrapper, which ``parallel_to_aec`` already applies).

::

    from encctl_gym.multiagent import encctl_game_v0

    par = encctl_game_v0.parallel_env(config={"preset": "paper-example", "max_samples": 40})
    aec = encctl_game_v0.env(config={"preset": "paper-example", "max_samples": 40})

The version suffix follows the game's ``metadata["name"]``; a change of the game's behaviour
bumps it.
"""

from __future__ import annotations

from typing import Any

from pettingzoo import AECEnv
from pettingzoo.utils.conversions import parallel_to_aec

from .game import EncryptedControlGame

__all__ = ["parallel_env", "raw_env", "env"]


def parallel_env(**kwargs: Any) -> EncryptedControlGame:
    """The game as a PettingZoo ``ParallelEnv`` (``kwargs``: those of :class:`EncryptedControlGame`)."""
    return EncryptedControlGame(**kwargs)


def raw_env(**kwargs: Any) -> AECEnv:
    """The game in AEC form: ``parallel_to_aec(parallel_env(**kwargs))``."""
    return parallel_to_aec(parallel_env(**kwargs))


def env(**kwargs: Any) -> AECEnv:
    """The game in AEC form as PettingZoo hands an environment out (order enforced); see :func:`raw_env`."""
    return raw_env(**kwargs)
