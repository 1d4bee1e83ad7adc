"""The attacker against the defender: a PettingZoo ``ParallelEnv`` on the attack episode.

Two agents act at every attack step, simultaneously:

* ``"attacker"``, the adversary of Definition def:adversary, as in ``EncryptedLTIAttack-v0``:
  the same observation (delivered decrypted data under the deciphering budget, its own inputs,
  the budgets spent) and one more action entry. Its action is ``Box(-1, 1, (m + 1,))``: the
  input (as the single environment's action) and a last entry, ``>= 0`` to inject it, ``< 0`` to
  pass the controller's input through (the period runs the encrypted controller of eq:ec; no
  energy is spent, no audit can catch the step, and its regression column is closed-loop data).
* ``"defender"``, the plant side: ``Box(-1, 1, (len(LEVERS),))``, one entry per lever of
  :data:`~encctl_gym.multiagent.levers.LEVERS` (audit, input noise, group rotation, verification), and an observation of the
  plant side's own data only (:class:`~encctl_gym.multiagent.levers.DefenderLevers`).

The game runs the same :class:`~encctl_gym.envs.episode.EpisodeCore` as the single environment;
the defender's decision enters through the defender seam (:mod:`encctl_gym.loop.defender`), so
a defender that always does nothing (action ``[-1, -1]``) and an attacker that always injects
give the single environment's trajectory bit for bit.

The deciphering budget is charged per group the defender moves to
(:class:`~encctl_gym.multiagent.clock.GroupClock`): under a cost model with a precomputation
(``deciphering_model="precomputation"``) each rotation costs the attacker one more, so its attack
ends sooner (terminated at the step whose sample the budget cannot pay), and its observed budget
fraction and ``deciphering_time`` count it. The game runs on states (``observe="state"``);
``observe="output"`` is refused (the output episode has no defender seam).

Rewards per step, with ``g`` the attacker's reward of the single environment (its
identification gain, the ``reward`` key: ``log_error`` by default), ``D`` 1 at the step the
defender detects the attack (which ends it; the paid samples are still delivered) and ``c`` the
defender's cost (:meth:`DefenderLevers.cost`: audits and noise):

* attacker: ``g - detection_penalty D``;
* defender: ``-g - c``.

As configured by default the game is **not zero-sum**: the rewards sum to
``-(detection_penalty D + c)``, both parties lose by a detection and by the defender's spending.
It is zero-sum with ``detection_penalty = 0``, ``audit_cost = 0`` and ``noise_weight = 0``, or
with ``zero_sum=True`` in the rules: then the attacker's reward is ``g - detection_penalty D +
c`` (it gains what it makes the defender spend) and the defender's is exactly minus it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from pettingzoo import ParallelEnv

from .._validation import as_finite_array, format_value
from ..envs.builder import build_episode
from ..envs.config import AttackParams, resolve_params
from ..envs.encrypted_lti_attack import RESET_OPTIONS, check_seed
from ..envs.episode import EpisodeSchedule
from ..errors import ParameterError
from .clock import GroupClock
from .levers import LEVERS, DefenderLevers, GameRules

__all__ = ["EncryptedControlGame", "AGENTS"]

#: The game's agents.
AGENTS = ("attacker", "defender")


class EncryptedControlGame(ParallelEnv):
    """The attack game (module docstring).

    Parameters
    ----------
    config : dict, optional
        The environment's configuration (:func:`encctl_gym.envs.config.default_config`), as for
        ``EncryptedLTIAttack-v0``; its ``defender`` key must be left at ``"fixed"`` and
        ``rotate_group_every`` at ``None`` (the defender is the other agent; it rotates with its lever).
    rules : GameRules or dict, optional
        Budgets, costs and penalties (:class:`~encctl_gym.multiagent.levers.GameRules`).
    schedule : EpisodeSchedule, optional
        As for the single environment.
    **overrides
        Configuration keys, as for the single environment.

    Attributes
    ----------
    params : AttackParams
        The resolved parameters (privileged, as in the single environment).
    episode : EpisodeCore
        The episode (privileged).
    levers : DefenderLevers
        The defender seam's adapter (its audits, detector and costs).
    """

    metadata = {"name": "encctl_game_v0", "render_modes": [], "is_parallelizable": True}

    def __init__(
        self,
        config: dict[str, Any] | None = None,
        rules: GameRules | dict[str, Any] | None = None,
        *,
        schedule: EpisodeSchedule | None = None,
        **overrides: Any,
    ) -> None:
        params = resolve_params(config, **overrides)
        _check_game(params)
        self.rules = GameRules.of(rules)
        self.levers = DefenderLevers(self.rules, params.sigma_u2)
        built = build_episode(params, defender=self.levers, schedule=schedule)
        self.params: AttackParams = built.params
        p = self.params
        self._loop = built.loop
        self.design = built.design
        self.episode = built.core
        self.clock = GroupClock(p)  # the deciphering budget charged per group (multiagent.clock)
        self.possible_agents = list(AGENTS)
        self.agents: list[str] = []
        self.render_mode: str | None = None  # PettingZoo's attribute (its wrappers read it); no rendering
        low, high = p.observation_bounds()
        x_hi, inf = high[: p.n], np.inf  # states within the encoder's range; decoded inputs and the statistic unbounded
        self._observation_spaces = {
            "attacker": spaces.Box(low, high, dtype=np.float32),
            "defender": spaces.Box(
                np.r_[-x_hi, np.full(p.m, -inf), 0.0, 0.0, 0.0].astype(np.float32),
                np.r_[x_hi, np.full(p.m, inf), inf, 1.0, 1.0].astype(np.float32),
                dtype=np.float32,
            ),
        }
        self._action_spaces = {
            "attacker": spaces.Box(-1.0, 1.0, (p.m + 1,), np.float32),
            "defender": spaces.Box(-1.0, 1.0, (len(LEVERS),), np.float32),
        }
        self._np_random: np.random.Generator | None = None

    # ------------------------------------------------------------------ spaces
    def observation_space(self, agent: str) -> spaces.Box:
        """The agent's observation space (the same object every call)."""
        return self._observation_spaces[self._agent(agent)]

    def action_space(self, agent: str) -> spaces.Box:
        """The agent's action space (the same object every call)."""
        return self._action_spaces[self._agent(agent)]

    def _agent(self, agent: Any) -> str:
        if agent not in AGENTS:
            raise ParameterError(f"unknown agent {format_value(agent)}; the game's agents are {list(AGENTS)}")
        return str(agent)

    # ------------------------------------------------------------------ API
    def reset(self, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[dict[str, Any], dict[str, Any]]:
        """Start a game; ``seed`` seeds the episode's generator as the single environment's
        ``reset(seed=...)`` does (the defender's streams are spawned from it). ``options`` may
        give ``x0`` and ``noise`` (as the single environment's); other keys are ignored."""
        seed = check_seed(seed)
        if seed is not None or self._np_random is None:
            self._np_random, _ = seeding.np_random(seed)
        opts = {} if options is None else {k: v for k, v in dict(options).items() if k in RESET_OPTIONS}
        obs = self.episode.reset(self._np_random, **opts)
        self.clock.reset(self.episode.collected)
        self.agents = list(AGENTS)
        observations = {"attacker": obs[0], "defender": self.levers.observe(self.episode.plant_view)}
        return observations, {"attacker": self.episode.info(), "defender": self._defender_info(0.0)}

    def step(
        self, actions: dict[str, Any]
    ) -> tuple[dict[str, Any], dict[str, float], dict[str, bool], dict[str, bool], dict[str, Any]]:
        """One attack step of both agents (``actions`` maps each agent to its action)."""
        if not self.agents:
            raise ParameterError("step() called before reset() or after the game ended; call reset() first")
        if not isinstance(actions, dict) or set(actions) != set(AGENTS):
            got = sorted(actions) if isinstance(actions, dict) else format_value(actions)
            raise ParameterError(f"actions must map both agents {list(AGENTS)} to their actions, got {got}")
        m = self.params.m
        a = as_finite_array("the attacker's action", actions["attacker"]).reshape(-1)
        if a.shape != (m + 1,):
            raise ParameterError(f"the attacker's action must have shape ({m + 1},), got {np.shape(actions['attacker'])}")
        if not -1.0 <= a[m] <= 1.0:  # the input entries are checked by the episode (core.step)
            raise ParameterError(f"the attacker's inject flag must lie in [-1, 1] (its action space), got {float(a[m])!r}")
        self.levers.decide(actions["defender"])
        core, clock = self.episode, self.clock
        if clock.active and not clock.affords(self.levers.rotates_at(core.plant_view.step)):
            core.end_out_of_time()  # the budget cannot pay this step's sample in its group: the attack ends now
        gains, terminated, truncated = core.step(a[:m], injection=None if a[m] >= 0.0 else "pass")
        clock.advance(core.collected, self.levers.rotated)
        gain, detected, cost = float(gains[0]), core.stopped, self.levers.cost()
        attacker = gain - self.rules.detection_penalty * float(detected)
        if self.rules.zero_sum:
            attacker += cost
            defender = -attacker
        else:
            defender = -gain - cost
        observations = {"attacker": self._attacker_observation(), "defender": self.levers.observe(core.plant_view)}
        infos = {"attacker": self._attacker_info(), "defender": self._defender_info(cost)}
        if terminated or truncated:
            self.agents = []
        return (
            observations,
            {"attacker": attacker, "defender": defender},
            dict.fromkeys(AGENTS, bool(terminated)),
            dict.fromkeys(AGENTS, bool(truncated)),
            infos,
        )

    def _attacker_observation(self) -> np.ndarray:
        """The single environment's observation, its budget fraction charged per group once
        the defender has rotated (:mod:`encctl_gym.multiagent.clock`)."""
        obs = self.episode.observation()[0]
        if self.clock.active and self.clock.rotated:
            obs[self.episode.layout.time_fraction] = self.clock.fraction
        return obs

    def _attacker_info(self) -> dict[str, Any]:
        """The single environment's info, its ``deciphering_time`` charged per group once the
        defender has rotated."""
        info = self.episode.info()
        if self.clock.active and self.clock.rotated:
            info["deciphering_time"] = self.clock.seconds
        return info

    def _defender_info(self, cost: float) -> dict[str, Any]:
        lv = self.levers
        return {
            "cost": cost,
            "audits": lv.audits,
            "audited": lv.audited,
            "detected": self.episode.stopped,
            "sigma_d2": lv.decision.sigma_d2,
            "rotations": lv.rotations,
            "checks": lv.checks,
            "verified": lv.verified,
        }

    def render(self) -> None:
        """No rendering (``render_modes`` is empty)."""
        return None

    def close(self) -> None:
        """Stop the defender's group pool (its worker thread)."""
        self.levers.close()


def _check_game(p: AttackParams) -> None:
    """The game's refusals: its defender is the defender agent, on states."""
    if p.defender != "fixed":
        raise ParameterError(
            f"the game's defender is its 'defender' agent; leave the configuration's defender at 'fixed', got {format_value(p.defender)}"
        )
    for key in ("audit_probability", "defense_noise_sigma2"):
        if getattr(p, key) is not None:
            raise ParameterError(
                f"{key} = {format_value(getattr(p, key))} acts outside the game's defender; leave it None and use the game's levers"
            )
    if p.rotate_group_every is not None:
        raise ParameterError(
            f"rotate_group_every = {p.rotate_group_every} rotates outside the game's defender; leave it None and use the rotate lever"
        )
    if p.observe != "state":
        raise ParameterError(
            f"the game runs on states only (observe='state'); observe={format_value(p.observe)} is not supported: "
            "the output episode has no defender seam"
        )
