"""Players of the attacker-defender game (:mod:`encctl_gym.multiagent`): static baselines on both
sides, learned policies, a single-agent view with the other side frozen, and playing the game.

A *player* is any object with ``name``, ``reset(seed)`` and ``act(obs) -> action`` for one side
of :class:`~encctl_gym.multiagent.game.EncryptedControlGame` (its observation and action spaces):

* defenders (the action is one entry per lever of :data:`~encctl_gym.multiagent.levers.LEVERS`,
  in [-1, 1], built by :func:`defender_action`):
  :class:`NoDefence`, :class:`RandomAudit` (audit with probability ``p`` per step),
  :class:`DetectorAudit` (audit when the chi-squared statistic it observes passes its threshold),
  :class:`ConstantNoise` (a fixed noise level), :class:`RotateEvery` (a fresh group every ``K``
  steps), and :class:`Combined` (several of them at once: a lever is on if any of them sets it);
* attackers: :class:`ScheduledAttacker` turns any attacker of :mod:`encctl_gym.agents` (Gaussian, AR(1),
  the optimal design, a learned one) into a game player that injects on a schedule: at every
  step, at random steps with probability ``q`` (sparse), or in bursts of ``duty`` steps every
  ``period`` (timed), and passes the controller's input through otherwise. A sparse or timed
  attacker scales its input by ``1 / sqrt(fraction injected)``, so it spends the same input energy
  as one that injects at every step (the energy budget allows it);
* :class:`PassThrough`: never injects (closed-loop data only: it cannot be caught);
* :class:`LearnedPlayer`: a stable-baselines3 model (PPO, the package's ARS) with the
  observation normalisation it was trained with;
* :class:`Population`: one player of a list, drawn per episode (the opponents met so far, for
  the fictitious-play rounds of :mod:`encctl_gym.agents.game_training`).

:class:`FrozenOpponent` is the game as a single-agent Gymnasium environment for one side, the
other side's player frozen inside it, so stable-baselines3 PPO and :class:`~encctl_gym.agents.ars.PairedARS`
train one side. :func:`play` plays paired episodes (episode ``e`` seeded ``seed + e`` for every
pair of players) and returns per-episode outcomes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import gymnasium as gym
import numpy as np

from encctl_gym._validation import check_int, check_positive
from encctl_gym.errors import ParameterError
from encctl_gym.multiagent import AGENTS, LEVERS, EncryptedControlGame, GameRules

from .base import Attacker

__all__ = [
    "Player",
    "defender_action",
    "NoDefence",
    "RandomAudit",
    "DetectorAudit",
    "ConstantNoise",
    "RotateEvery",
    "Combined",
    "ScheduledAttacker",
    "PassThrough",
    "LearnedPlayer",
    "Population",
    "FrozenOpponent",
    "Outcome",
    "play",
]


class Player(Protocol):
    """One side's policy in the game (module docstring)."""

    name: str

    def reset(self, seed: int | None = None) -> None: ...

    def act(self, obs: np.ndarray) -> np.ndarray: ...


# ---------------------------------------------------------------------- static defenders
def defender_action(**levers: float) -> np.ndarray:
    """A defender's action: the given levers' entries (by name of :data:`LEVERS`), -1 (off) for
    every other lever."""
    unknown = sorted(set(levers) - set(LEVERS))
    if unknown:
        raise ParameterError(f"unknown lever(s) {unknown}; the levers are {list(LEVERS)}")
    return np.array([levers.get(name, -1.0) for name in LEVERS], dtype=np.float32)


class NoDefence:
    """Never audits, adds no noise: the paper's defender."""

    name = "none"

    def reset(self, seed: int | None = None) -> None:
        pass

    def act(self, obs: np.ndarray) -> np.ndarray:
        return defender_action()


class RandomAudit:
    """Audits with probability ``p`` at every step (its own random stream), no noise.

    Parameters
    ----------
    p : float
        Audit probability per step, in [0, 1].
    """

    def __init__(self, p: float) -> None:
        self.p = float(p)
        if not 0.0 <= self.p <= 1.0:
            raise ParameterError(f"the audit probability p must lie in [0, 1], got {p}")
        self.name = f"audit(p={self.p:g})"
        self.rng = np.random.default_rng()

    def reset(self, seed: int | None = None) -> None:
        self.rng = np.random.default_rng(seed)

    def act(self, obs: np.ndarray) -> np.ndarray:
        return defender_action(audit=1.0 if self.rng.random() < self.p else -1.0)


class DetectorAudit:
    """Audits when its chi-squared statistic passes the threshold (an observed ratio > 1), so an
    alarm is confirmed by an audit before the attack is declared: no false alarm ends the game.

    Parameters
    ----------
    n, m : int
        The plant's sizes (the statistic is entry ``n + m`` of the defender's observation).
    """

    name = "chi2"

    def __init__(self, n: int, m: int) -> None:
        self.index = check_int("n", n, minimum=1) + check_int("m", m, minimum=1)

    def reset(self, seed: int | None = None) -> None:
        pass

    def act(self, obs: np.ndarray) -> np.ndarray:
        return defender_action(audit=1.0 if obs[self.index] > 1.0 else -1.0)


class ConstantNoise:
    """The same noise level at every step, no audits.

    Parameters
    ----------
    level : float
        The noise lever's entry, in (0, 1]: ``sigma_d2 = level * noise_max``.
    """

    def __init__(self, level: float) -> None:
        self.level = check_positive("level", level)
        if self.level > 1.0:
            raise ParameterError(f"level must lie in (0, 1], got {level}")
        self.name = f"noise({self.level:g})"

    def reset(self, seed: int | None = None) -> None:
        pass

    def act(self, obs: np.ndarray) -> np.ndarray:
        return defender_action(noise=self.level)


class RotateEvery:
    """Moves the loop to a fresh group every ``K`` steps (before the period of steps ``K - 1,
    2K - 1, ...``, as the ``"rotate"`` defender does), no audits, no noise.

    Parameters
    ----------
    K : int
        Steps per group.
    """

    def __init__(self, K: int) -> None:
        self.K = check_int("K", K, minimum=1)
        self.name = f"rotate(K={self.K})"
        self.k = 0

    def reset(self, seed: int | None = None) -> None:
        self.k = 0

    def act(self, obs: np.ndarray) -> np.ndarray:
        self.k += 1
        return defender_action(rotate=1.0 if self.k % self.K == 0 else -1.0)


class Combined:
    """Several defenders at once: each lever's entry is the largest of theirs (a lever is on if
    any of them sets it; the noise is the highest level asked for).

    Parameters
    ----------
    defenders : Player
        Two or more defenders, each seeing the same observation.
    """

    def __init__(self, *defenders: Player) -> None:
        if len(defenders) < 2:
            raise ParameterError(f"Combined needs at least two defenders, got {len(defenders)}")
        self.defenders = list(defenders)
        self.name = "+".join(d.name for d in self.defenders)

    def reset(self, seed: int | None = None) -> None:
        for d, s in zip(self.defenders, np.random.SeedSequence(seed).spawn(len(self.defenders))):
            d.reset(int(s.generate_state(1)[0]))

    def act(self, obs: np.ndarray) -> np.ndarray:
        return np.max([d.act(obs) for d in self.defenders], axis=0).astype(np.float32)


# ---------------------------------------------------------------------- attackers
class ScheduledAttacker:
    """An attacker of :mod:`encctl_gym.agents` as a game player that injects on a schedule (module docstring).

    Parameters
    ----------
    attacker : Attacker
        Computes the input from the attacker's observation (the single environment's).
    q : float
        Probability of injecting at a step (1: every step).
    period, duty : int, optional
        Timed: inject at the steps ``k`` with ``k mod period < duty`` (instead of ``q``).
    """

    def __init__(self, attacker: Attacker, q: float = 1.0, period: int | None = None, duty: int | None = None) -> None:
        self.attacker = attacker
        self.q = check_positive("q", q)
        if self.q > 1.0:
            raise ParameterError(f"q must lie in (0, 1], got {q}")
        self.period = None if period is None else check_int("period", period, minimum=1)
        if (period is None) != (duty is None):
            raise ParameterError("a timed attacker needs both period and duty")
        self.duty = None if duty is None else check_int("duty", duty, minimum=1, maximum=self.period)
        if self.period is not None:
            if q != 1.0:
                raise ParameterError("give either q (sparse) or period and duty (timed), not both")
            self.fraction = self.duty / self.period  # type: ignore[operator]
            self.name = f"{attacker.name}/timed({self.duty}:{self.period})"
        else:
            self.fraction = self.q
            self.name = attacker.name if self.q == 1.0 else f"{attacker.name}/sparse({self.q:g})"
        self.scale = 1.0 / math.sqrt(self.fraction)
        self.rng = np.random.default_rng()
        self.k = 0

    def reset(self, seed: int | None = None) -> None:
        ss = np.random.SeedSequence(seed)
        a, b = ss.spawn(2)
        self.attacker.reset(a)
        self.rng = np.random.default_rng(b)
        self.k = 0

    def act(self, obs: np.ndarray) -> np.ndarray:
        u = np.clip(self.attacker.act(obs) * self.scale, -1.0, 1.0)
        if self.period is not None:
            inject = self.k % self.period < self.duty  # type: ignore[operator]
        else:
            inject = self.q == 1.0 or self.rng.random() < self.q
        self.k += 1
        return np.r_[u, 1.0 if inject else -1.0].astype(np.float32)


class PassThrough:
    """Never injects: every period runs the encrypted controller (closed-loop data only).

    Parameters
    ----------
    m : int
        The plant's number of inputs.
    """

    name = "pass-through"

    def __init__(self, m: int) -> None:
        self.action = np.r_[np.zeros(check_int("m", m, minimum=1)), -1.0].astype(np.float32)

    def reset(self, seed: int | None = None) -> None:
        pass

    def act(self, obs: np.ndarray) -> np.ndarray:
        return self.action.copy()


class LearnedPlayer:
    """A stable-baselines3 model as a player (deterministic actions).

    Parameters
    ----------
    model : stable_baselines3 BaseAlgorithm
        PPO, :class:`~encctl_gym.agents.ars.PairedARS`, ...
    vecnorm : VecNormalize, optional
        The observation normalisation it was trained with (its statistics are used, not updated).
    name : str
    """

    def __init__(self, model: Any, vecnorm: Any = None, name: str = "learned") -> None:
        self.model, self.vecnorm, self.name = model, vecnorm, name

    def reset(self, seed: int | None = None) -> None:
        pass

    def act(self, obs: np.ndarray) -> np.ndarray:
        o = np.asarray(obs, dtype=np.float32)[None]
        if self.vecnorm is not None:
            o = self.vecnorm.normalize_obs(o)
        action, _ = self.model.predict(o, deterministic=True)
        return np.asarray(action[0], dtype=np.float32)


class Population:
    """One of ``players`` per episode, drawn uniformly at :meth:`reset`.

    Parameters
    ----------
    players : sequence of Player
    """

    def __init__(self, players: Sequence[Player]) -> None:
        self.players = list(players)
        if not self.players:
            raise ParameterError("a population needs at least one player")
        self.name = "+".join(p.name for p in self.players)
        self.current = self.players[0]

    def reset(self, seed: int | None = None) -> None:
        ss = np.random.SeedSequence(seed)
        pick, inner = ss.spawn(2)
        self.current = self.players[int(np.random.default_rng(pick).integers(len(self.players)))]
        self.current.reset(int(inner.generate_state(1)[0]))

    def act(self, obs: np.ndarray) -> np.ndarray:
        return self.current.act(obs)


# ---------------------------------------------------------------------- one side's view
class FrozenOpponent(gym.Env):
    """The game for one side, the other side's player frozen inside: a Gymnasium environment.

    Observation, action and reward are the game's for ``side``; ``info`` is that side's info of
    the game with the other side's under ``"opponent"``. The frozen player is reset with a seed
    drawn from this environment's generator, so a seeded reset replays the opponent too (paired
    episodes for :class:`~encctl_gym.agents.ars.PairedARS`).

    Parameters
    ----------
    side : {"attacker", "defender"}
        The side that learns.
    opponent : Player
        The other side's player.
    config : dict, optional
        The environment's configuration.
    rules : GameRules or dict, optional
        The game's rules.
    """

    metadata = {"render_modes": []}

    def __init__(self, side: str, opponent: Player, config: dict[str, Any] | None = None, rules: Any = None) -> None:
        if side not in AGENTS:
            raise ParameterError(f"side must be one of {list(AGENTS)}, got {side!r}")
        self.side, self.other = side, AGENTS[1 - AGENTS.index(side)]
        self.opponent = opponent
        self.game = EncryptedControlGame(config, GameRules.of(rules))
        self.params = self.game.params
        self.observation_space = self.game.observation_space(side)
        self.action_space = self.game.action_space(side)
        self._obs: dict[str, np.ndarray] = {}

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        game_seed, opponent_seed = (int(s) for s in self.np_random.integers(0, 2**31 - 1, size=2))
        self._obs, infos = self.game.reset(seed=game_seed, options=options)
        self.opponent.reset(opponent_seed)
        return self._obs[self.side], {**infos[self.side], "opponent": infos[self.other]}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        actions = {self.side: action, self.other: self.opponent.act(self._obs[self.other])}
        self._obs, rew, term, trunc, infos = self.game.step(actions)
        info = {**infos[self.side], "opponent": infos[self.other]}
        return self._obs[self.side], float(rew[self.side]), bool(term[self.side]), bool(trunc[self.side]), info


# ---------------------------------------------------------------------- playing
@dataclass(frozen=True)
class Outcome:
    """Per-episode results of one attacker against one defender (arrays of shape (E,)).

    Attributes
    ----------
    epsilon : the attacker's final error (Definition def:error)
    samples : samples collected
    detected : 1.0 if the defender detected the attack
    cost : the defender's total cost
    attacker_return, defender_return : the two sides' returns
    """

    epsilon: np.ndarray
    samples: np.ndarray
    detected: np.ndarray
    cost: np.ndarray
    attacker_return: np.ndarray
    defender_return: np.ndarray


def play(
    attacker: Player, defender: Player, config: dict[str, Any], rules: Any = None, *, episodes: int = 20, seed: int = 0
) -> Outcome:
    """Play ``episodes`` games; episode ``e`` seeds the game with ``seed + e`` (paired across
    players: the same initial states and process noise) and the players with seeds derived from
    it."""
    episodes = check_int("episodes", episodes, minimum=1)
    game = EncryptedControlGame(config, GameRules.of(rules))
    rows = []
    for e in range(episodes):
        s = seed + e
        obs, _ = game.reset(seed=s)
        a_seed, d_seed = np.random.SeedSequence([s, 1]).generate_state(2)
        attacker.reset(int(a_seed))
        defender.reset(int(d_seed))
        ra = rd = cost = 0.0
        while game.agents:
            obs, rew, _, _, info = game.step(
                {"attacker": attacker.act(obs["attacker"]), "defender": defender.act(obs["defender"])}
            )
            ra += rew["attacker"]
            rd += rew["defender"]
            cost += info["defender"]["cost"]
        att = info["attacker"]
        rows.append((att["epsilon"], att["samples_collected"], float(att["detected"]), cost, ra, rd))
    cols = np.array(rows, dtype=float).T
    return Outcome(*cols)
