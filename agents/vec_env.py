"""stable-baselines3's ``VecEnv`` over the native vector environment (:class:`SB3VecEnv`).

The learning algorithms (:mod:`agents.sb3`, :mod:`agents.ars`) train on it; it imports neither.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from stable_baselines3.common.vec_env import VecEnv

from encctl_gym.envs.config import AttackParams
from encctl_gym.errors import ParameterError

from .base import observation_indices
from .features import FeatureSet

__all__ = ["SB3VecEnv", "INFO_KEYS"]

#: Info keys copied into the SB3 info dicts at the end of an episode.
INFO_KEYS = ("epsilon", "gamma", "samples_delivered", "input_energy", "average_power")


class SB3VecEnv(VecEnv):
    """``num_envs`` copies of the attack environment as a stable-baselines3 ``VecEnv``.

    Parameters
    ----------
    config : dict
        Environment configuration (ideal backend).
    num_envs : int
        Number of copies.
    observation : str
        Observation mode (``"full"``, ``"no_budget"``, ``"blind"``).
    reward_scaling : {"none", "samples"}
        ``"samples"`` multiplies the reward of a step by the number of samples delivered,
        ``N_t (log eps_{t-1} - log eps_t)`` for ``reward="log_error"``: the relative error
        decrease per sample, whose scale does not shrink like ``1/N`` along the episode (the
        return is then no longer the telescoped ``log eps_0 - log eps_N``).

    All copies share the horizon, so they end together; the step that ends them returns the
    first observation of the next episodes, and every copy's info carries
    ``terminal_observation``, ``TimeLimit.truncated`` and the environment's final
    :data:`INFO_KEYS`. Other steps return empty info dicts (building K dicts per step would
    cost more than the step itself).
    """

    def __init__(
        self, config: dict[str, Any], num_envs: int, observation: str = "full", reward_scaling: str = "none", features: Any = ()
    ) -> None:
        from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv

        self.config = dict(config)
        self.venv = EncryptedLTIAttackVectorEnv(num_envs, config=config)
        self.params: AttackParams = self.venv.params
        self.observation = observation
        if reward_scaling not in ("none", "samples"):
            raise ParameterError(f"reward_scaling must be 'none' or 'samples', got {reward_scaling!r}")
        self.reward_scaling = reward_scaling
        self.obs_idx = observation_indices(self.params, observation)
        self.features = FeatureSet(features, self.params)
        self.feature_names = list(self.features.names)
        low, high = self.params.observation_bounds()
        f_low, f_high = self.features.bounds()
        obs_space = spaces.Box(
            np.concatenate([low[self.obs_idx], f_low]), np.concatenate([high[self.obs_idx], f_high]), dtype=np.float32
        )
        self.num_envs = num_envs
        self.render_mode = None
        self._actions = np.zeros((num_envs, self.params.m), dtype=np.float32)
        self._feature_rng: np.random.Generator | None = None
        super().__init__(num_envs, obs_space, self.venv.single_action_space)

    def _obs(self, obs: np.ndarray) -> np.ndarray:
        return self.features.append(obs, np.ascontiguousarray(obs[:, self.obs_idx], dtype=np.float32))

    def reset(self) -> np.ndarray:
        seeds = self._seeds
        if seeds[0] is not None:
            return self.reset_episodes([int(s) for s in seeds])  # type: ignore[arg-type]
        obs, _ = self.venv.reset()
        if self._feature_rng is None:  # never seeded: fresh entropy, kept across episodes
            self._feature_rng = np.random.default_rng()
        self.features.reset(self.num_envs, rng=self._feature_rng)
        self._reset_options()
        return self._obs(obs)

    def reset_episodes(self, seeds: list[int]) -> np.ndarray:
        """Reset every copy with its own environment seed (copies with one seed play the same
        episode, their features draw the same numbers) and return the observations.

        The seeds also seed the features' generator of the episodes that follow by autoreset.
        """
        obs, _ = self.venv.reset(seed=[int(s) for s in seeds])
        self.features.reset(self.num_envs, seeds=seeds)
        self._feature_rng = np.random.default_rng(np.random.SeedSequence([int(s) for s in seeds[:1]] + [0x7A]))
        self._reset_seeds()
        self._reset_options()
        return self._obs(obs)

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.clip(np.asarray(actions, dtype=np.float32).reshape(self.num_envs, -1), -1.0, 1.0)

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        obs, reward, terminated, truncated, info = self.venv.step(self._actions)
        dones = np.logical_or(terminated, truncated)
        if self.reward_scaling == "samples":
            reward = reward * info["samples_delivered"]
        if dones.any():
            final = self._obs(obs)
            infos = [
                {
                    "terminal_observation": final[i],
                    "TimeLimit.truncated": bool(truncated[i] and not terminated[i]),
                    **{k: float(info[k][i]) for k in INFO_KEYS},
                }
                for i in range(self.num_envs)
            ]
            obs, _ = self.venv.reset()
            self.features.reset(self.num_envs, rng=self._feature_rng)
        else:
            infos = [{} for _ in range(self.num_envs)]
        return self._obs(obs), np.asarray(reward, dtype=np.float32), dones, infos

    def close(self) -> None:
        pass

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        own = ("render_mode", "params", "observation", "config", "feature_names")
        value = getattr(self, attr_name) if attr_name in own else getattr(self.venv, attr_name)
        return [value for _ in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        raise ParameterError("SB3VecEnv copies share one batched core; attributes cannot be set per copy")

    def env_method(self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any) -> list[Any]:
        raise ParameterError(f"SB3VecEnv does not forward {method_name}() to single copies (they are one batched core)")

    def env_is_wrapped(self, wrapper_class: Any, indices: Any = None) -> list[bool]:
        return [False for _ in self._get_indices(indices)]
