"""The attacker-defender game on Ray RLlib's multi-agent API (the optional ``[ray]`` and
``[multiagent]`` extras).

RLlib runs a PettingZoo ``ParallelEnv`` through its wrapper
``ray.rllib.env.wrappers.pettingzoo_env.ParallelPettingZooEnv``: :func:`register_game` registers
a creator (:func:`make_game`) under :data:`GAME_NAME`, and :func:`game_ppo_config` returns a
``PPOConfig`` with one policy per agent (``"attacker"`` and ``"defender"``, each agent mapped to
its own), so both sides learn at once, each from its own reward. For example::

    from encctl_gym.agents.rllib_game import train_game
    rows = train_game({"preset": "paper-example", "gamma_opt": False, "max_samples": 128},
                      iterations=50, address="auto", num_env_runners=32)

The game's rules (:class:`~encctl_gym.multiagent.levers.GameRules`) go in the creator's
configuration under ``"rules"``; every other key is the environment's.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .rllib import _require_rllib, register_factory, run_training, with_ppo_hyperparameters

__all__ = ["GAME_NAME", "make_game", "register_game", "game_ppo_config", "train_game"]

#: The name the game is registered under in RLlib.
GAME_NAME = "encctl_gym/EncryptedControlGame-v0"


def _split(env_config: Mapping[str, Any]) -> tuple[dict[str, Any], Any]:
    cfg = dict(env_config)
    return cfg, cfg.pop("rules", None)


def make_game(env_config: Mapping[str, Any]) -> Any:
    """The game for one RLlib env runner, wrapped in RLlib's ``ParallelPettingZooEnv``."""
    from ray.rllib.env.wrappers.pettingzoo_env import ParallelPettingZooEnv

    from encctl_gym.multiagent import EncryptedControlGame

    cfg, rules = _split(env_config)
    return ParallelPettingZooEnv(EncryptedControlGame(cfg, rules))


def register_game(name: str = GAME_NAME) -> str:
    """Register :func:`make_game` with RLlib under ``name``; return the name."""
    return register_factory(name, make_game)


def game_ppo_config(
    env_config: Mapping[str, Any],
    *,
    num_env_runners: int = 0,
    train_batch_size: int = 4096,
    minibatch_size: int = 256,
    num_epochs: int = 10,
    gamma: float = 0.999,
    lr: float = 3e-4,
    seed: int | None = 0,
) -> Any:
    """An RLlib ``PPOConfig`` for the game: one policy per agent (see the module docstring).

    The configuration is checked here (the game is built once) before any worker starts.
    """
    _require_rllib()
    from ray.rllib.algorithms.ppo import PPOConfig
    from ray.rllib.core.rl_module.multi_rl_module import MultiRLModuleSpec
    from ray.rllib.core.rl_module.rl_module import RLModuleSpec

    from encctl_gym.multiagent import AGENTS, EncryptedControlGame

    cfg, rules = _split(env_config)
    EncryptedControlGame(cfg, rules)  # a bad configuration fails here, not in a remote worker
    config = (
        PPOConfig()
        .environment(register_game(), env_config=dict(env_config))
        .env_runners(num_env_runners=int(num_env_runners))
        .multi_agent(policies=set(AGENTS), policy_mapping_fn=lambda agent_id, *args, **kwargs: agent_id)
        .rl_module(rl_module_spec=MultiRLModuleSpec(rl_module_specs={a: RLModuleSpec() for a in AGENTS}))
    )
    return with_ppo_hyperparameters(
        config,
        train_batch_size=train_batch_size,
        minibatch_size=minibatch_size,
        num_epochs=num_epochs,
        gamma=gamma,
        lr=lr,
        seed=seed,
    )


def train_game(
    env_config: Mapping[str, Any], *, iterations: int, address: str | None = None, **kwargs: Any
) -> list[dict[str, Any]]:
    """Train both sides with RLlib's PPO for ``iterations`` iterations; one summary per
    iteration: ``iteration``, ``env_steps`` (lifetime), ``returns`` (the mean episode return of
    each agent in that iteration, where RLlib reports it) and ``seconds``."""
    return run_training(
        lambda: game_ppo_config(env_config, **kwargs),
        iterations,
        address,
        lambda r: {"returns": dict(r.get("env_runners", {}).get("agent_episode_returns_mean", {}))},
    )
