"""Learning one side of the game against a frozen other, and alternating best responses.

:func:`train_side` trains the attacker or the defender of
:class:`~encctl_gym.multiagent.game.EncryptedControlGame` with stable-baselines3's PPO or the
package's :class:`~encctl_gym.agents.ars.PairedARS` on :class:`~encctl_gym.agents.game.FrozenOpponent` (the other
side's player frozen into a single-agent environment), from scratch, and returns the learned
player with its learning curve (the return of every training episode, from ``Monitor``).

:func:`alternate` runs rounds of best responses, fictitious-play style: round ``r`` trains a
defender against the attackers met so far (the starting attacker and the learned ones, one drawn
per episode, :class:`~encctl_gym.agents.game.Population`), then an attacker against the defenders learned
so far. The exploitability of a learned defender is what an attacker trained from scratch
against it alone gains over the static attackers (``experiments/game.py``).

Training is real and short (tens of thousands of steps per response on one core); the
hyperparameters are :data:`PPO_KWARGS` and :data:`ARS_KWARGS`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from encctl_gym._validation import check_int
from encctl_gym.errors import ConfigError

from .game import FrozenOpponent, LearnedPlayer, Player, Population

__all__ = ["PPO_KWARGS", "ARS_KWARGS", "Curve", "train_side", "Alternation", "alternate"]

#: PPO's settings for one best response (stable-baselines3 names).
PPO_KWARGS: dict[str, Any] = {
    "n_steps": 1024,
    "batch_size": 128,
    "n_epochs": 5,
    "gamma": 0.999,
    "gae_lambda": 0.95,
    "learning_rate": 3e-4,
    "ent_coef": 0.0,
}
#: PairedARS's settings for one best response (a linear policy).
ARS_KWARGS: dict[str, Any] = {"n_delta": 4, "n_eval_episodes": 2, "learning_rate": 0.02, "delta_std": 0.05}


@dataclass
class Curve:
    """The training returns of one best response.

    Attributes
    ----------
    label : str
        ``"{side} r{round} {algo}"``.
    side, algo : str
    timesteps : ndarray (E,)
        Training steps at the end of each training episode.
    returns : ndarray (E,)
        That episode's return (the learning side's).
    """

    label: str
    side: str
    algo: str
    timesteps: np.ndarray = field(default_factory=lambda: np.zeros(0))
    returns: np.ndarray = field(default_factory=lambda: np.zeros(0))


def train_side(
    side: str,
    opponent: Player,
    config: dict[str, Any],
    rules: Any = None,
    *,
    algo: str = "ppo",
    steps: int = 20_000,
    seed: int = 0,
    label: str | None = None,
) -> tuple[LearnedPlayer, Curve]:
    """Train ``side`` from scratch against the frozen ``opponent`` for ``steps`` environment steps.

    Returns the learned player (deterministic; with the observation normalisation it was trained
    with) and its :class:`Curve`.

    Raises
    ------
    ConfigError
        For an ``algo`` other than ``"ppo"`` or ``"ars"``.
    """
    import torch as th
    from stable_baselines3 import PPO
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    from .ars import PairedARS

    steps = check_int("steps", steps, minimum=1)
    if algo not in ("ppo", "ars"):
        raise ConfigError(f"algo must be 'ppo' or 'ars', got {algo!r}")
    th.set_num_threads(1)
    monitor = Monitor(FrozenOpponent(side, opponent, config, rules))
    venv = VecNormalize(DummyVecEnv([lambda: monitor]), norm_obs=True, norm_reward=algo == "ppo", gamma=PPO_KWARGS["gamma"])
    venv.seed(seed)
    if algo == "ppo":
        model: Any = PPO("MlpPolicy", venv, seed=seed, verbose=0, device="cpu", **PPO_KWARGS)
    else:
        model = PairedARS("LinearPolicy", venv, seed=seed, verbose=0, device="cpu", **ARS_KWARGS)
    model.learn(total_timesteps=steps)
    venv.training = False
    lengths = np.asarray(monitor.get_episode_lengths(), dtype=float)
    curve = Curve(
        label or f"{side} {algo}",
        side,
        algo,
        timesteps=np.cumsum(lengths),
        returns=np.asarray(monitor.get_episode_rewards(), dtype=float),
    )
    return LearnedPlayer(model, venv, name=f"learned {side} ({algo})"), curve


@dataclass
class Alternation:
    """The result of :func:`alternate`.

    Attributes
    ----------
    attackers, defenders : list of Player
        The starting players first, then one learned player per round.
    curves : list of Curve
        In training order (defender of round 1, attacker of round 1, ...).
    """

    attackers: list[Player]
    defenders: list[Player]
    curves: list[Curve]


def alternate(
    attacker: Player,
    defender: Player,
    config: dict[str, Any],
    rules: Any = None,
    *,
    rounds: int = 2,
    steps: int = 20_000,
    algo: str = "ppo",
    seed: int = 0,
) -> Alternation:
    """``rounds`` rounds of best responses from the starting ``attacker`` and ``defender``
    (module docstring); round ``r`` trains with seeds ``seed + 2 r`` (defender) and
    ``seed + 2 r + 1`` (attacker)."""
    rounds = check_int("rounds", rounds, minimum=1)
    attackers, defenders, curves = [attacker], [defender], []
    for r in range(1, rounds + 1):
        opp = Population(attackers) if len(attackers) > 1 else attackers[0]
        d, c = train_side(
            "defender", opp, config, rules, algo=algo, steps=steps, seed=seed + 2 * r, label=f"defender r{r} {algo}"
        )
        defenders.append(d)
        curves.append(c)
        learned = defenders[1:]
        opp = Population(learned) if len(learned) > 1 else learned[0]
        a, c = train_side(
            "attacker", opp, config, rules, algo=algo, steps=steps, seed=seed + 2 * r + 1, label=f"attacker r{r} {algo}"
        )
        attackers.append(a)
        curves.append(c)
    return Alternation(attackers, defenders, curves)
