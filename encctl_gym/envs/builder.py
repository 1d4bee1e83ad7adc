"""One episode builder for the single environment, the vector environment and the game.

:func:`build_episode` is the assembly every front end shares: the resolved parameters
(:func:`~encctl_gym.envs.config.resolve_params`), the memory check before anything is sized,
the defender (the configured one, :func:`~encctl_gym.loop.assembly.defender_for`, or the
front end's own: the game's levers), the loop backend on the loop's own value object
(:func:`~encctl_gym.loop.make_loop` of :attr:`AttackParams.loop`), the optimal attack design
behind ``info["gamma_opt"]`` and the episode: an :class:`~encctl_gym.envs.episode.EpisodeCore`,
or the :class:`~encctl_gym.envs.output_episode.OutputEpisode` when the plant sends outputs.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..loop import make_loop
from ..loop.assembly import defender_for
from ..loop.defender import DefenderPolicy
from .config import AttackParams, resolve_params
from .episode import EpisodeCore, attack_design_for
from .schedule import EpisodeSchedule, check_episode_memory

__all__ = ["BuiltEpisode", "build_episode"]


@dataclass(frozen=True)
class BuiltEpisode:
    """What :func:`build_episode` assembled."""

    params: AttackParams
    defender: DefenderPolicy
    loop: Any
    design: Any
    core: Any


def build_episode(
    config: Mapping[str, Any] | AttackParams | None = None,
    *,
    num_envs: int = 1,
    defender: DefenderPolicy | None = None,
    schedule: EpisodeSchedule | None = None,
    memory_limit: int | None = None,
    check: Any = None,
    **episode_options: Any,
) -> BuiltEpisode:
    """The parameters, defender, loop, attack design and episode of one front end.

    Parameters
    ----------
    config : mapping or AttackParams
        A configuration (resolved here) or resolved parameters.
    num_envs : int
        Copies stepped in lockstep (the vector environment's).
    defender : DefenderPolicy, optional
        The front end's own defender (the game's levers); default: the configured one.
    schedule, memory_limit
        The episode's work schedule and memory limit (checked before anything is sized).
    check : callable, optional
        ``check(params)``: the front end's own refusals, run on the resolved parameters first.
    **episode_options
        Passed to :class:`EpisodeCore` (``parallel``, ``helper``).
    """
    p = config if isinstance(config, AttackParams) else resolve_params(config)
    if check is not None:
        check(p)
    p.warn_if_capped()
    check_episode_memory(p, num_envs, schedule, memory_limit)  # before anything is sized by the parameters
    policy = defender_for(p.loop) if defender is None else defender
    loop = make_loop(p.loop, policy)  # refuses a loop it cannot build (the quantisation table) before the spaces are sized
    design = attack_design_for(p) if p.gamma_opt else None
    if p.observe == "output":  # the plant sends y = C x + v: the episode of envs.output_episode
        from .output_episode import OutputEpisode

        core: Any = OutputEpisode(p, loop, design, num_envs=num_envs, defender=policy)
    else:
        core = EpisodeCore(
            p, loop, design, num_envs=num_envs, schedule=schedule, memory_limit=memory_limit, defender=policy, **episode_options
        )
    return BuiltEpisode(p, policy, loop, design, core)
