"""stable-baselines3 glue: a VecEnv over the native vector environment, and learned attackers.

* :class:`~agents.vec_env.SB3VecEnv` (its own module, re-exported here) adapts :class:`~encctl_gym.envs.vector.EncryptedLTIAttackVectorEnv` (K
  copies stepped at once) to stable-baselines3's ``VecEnv`` API: same-step autoreset
  with ``info["terminal_observation"]`` and ``info["TimeLimit.truncated"]``, seeding through
  ``VecEnv.seed``, and an observation *mode* (:func:`agents.base.observation_indices`) that
  selects the columns the policy sees, followed by the columns of its *features*
  (:mod:`agents.features`). It is several times faster than a ``DummyVecEnv`` over single
  environments.
* :class:`SB3Attacker` wraps a trained model (PPO, SAC, RecurrentPPO; with its
  ``VecNormalize`` statistics) as an :class:`~agents.base.Attacker`.
* :func:`load_attacker` loads a training run written by :mod:`agents.train`.
* :data:`ALGORITHMS`: the learning algorithms by name (one table for training, loading and the
  command line).
"""

from __future__ import annotations

import pickle
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
from sb3_contrib import RecurrentPPO
from stable_baselines3 import PPO, SAC
from stable_baselines3.common.base_class import BaseAlgorithm

from encctl_gym.envs.config import AttackParams, resolve_params
from encctl_gym.errors import ConfigError, ParameterError
from encctl_gym.registry import Registry

from .ars import PairedARS
from .base import Attacker, observation_indices
from .features import FeatureSet
from .vec_env import INFO_KEYS, SB3VecEnv

__all__ = ["SB3VecEnv", "SB3Attacker", "load_attacker", "ALGORITHMS", "algorithm_class", "INFO_KEYS"]

#: The learning algorithms by name: ``train``, :func:`load_attacker` and the command line's
#: choices all read this one table (a new algorithm is a row here and a default config in
#: ``agents/configs/defaults/{name}.yaml``).
_CLASSES: dict[str, type[BaseAlgorithm]] = {"ppo": PPO, "sac": SAC, "recurrent_ppo": RecurrentPPO, "ars": PairedARS}
ALGORITHMS: Registry[type[BaseAlgorithm]] = Registry("algorithm", _CLASSES, error=ConfigError)


def algorithm_class(algo: str) -> type[BaseAlgorithm]:
    """The stable-baselines3 (or sb3-contrib) class registered as ``algo`` in :data:`ALGORITHMS`."""
    return ALGORITHMS.lookup(algo)


class SB3Attacker(Attacker):
    """A trained stable-baselines3 policy as an :class:`~agents.base.Attacker`.

    Parameters
    ----------
    model : BaseAlgorithm
        PPO, SAC or RecurrentPPO (recurrent state handled per copy, reset with the episode).
    vecnormalize : VecNormalize, optional
        Observation statistics saved with the model (applied in evaluation mode).
    deterministic : bool, default False
        Use the policy's mean action. Off by default, on purpose: identification needs
        excitation, and a stochastic policy's noise *is* its excitation; the mean of a policy
        that feeds back the state (``u = mu(x)``) leaves the regressor ``[x; u]`` nearly
        rank-deficient.
    params : AttackParams, optional
        Parameters of the environment it will run in (for the observation layout); without
        them only ``observation="full"`` is possible and the layout is not checked.
    observation : str
        The observation mode the model was trained with.
    features : sequence of str
        The features (:mod:`agents.features`) the model was trained with; their columns are
        computed here from the observations and the attacker's own generator (seeded by
        :meth:`reset`), as in training. Features need ``params``.
    name : str, optional
        Label (default: the algorithm's name).
    """

    def __init__(
        self,
        model: Any,
        vecnormalize: Any = None,
        deterministic: bool = False,
        *,
        params: AttackParams | None = None,
        observation: str = "full",
        features: Any = (),
        name: str | None = None,
    ) -> None:
        if params is None and features:
            raise ParameterError("an SB3Attacker with features needs the environment's params")
        if params is None:
            if observation != "full":
                raise ParameterError("an SB3Attacker with observation mode other than 'full' needs the environment's params")
            dim = int(np.prod(model.observation_space.shape))
            self.params = None  # type: ignore[assignment]
            self._obs_idx = np.arange(dim)
            self._dim = dim
        else:
            super().__init__(params)
            self._obs_idx = observation_indices(params, observation)
            self._dim = self.layout.dim
        self._features = FeatureSet(features, params) if params is not None else FeatureSet((), None)
        if len(self._obs_idx) + self._features.dim != int(np.prod(model.observation_space.shape)):
            raise ParameterError(
                f"the model expects {model.observation_space.shape} observations, the {observation!r} mode"
                f"{' with features ' + ','.join(self._features.names) if self._features else ''} gives "
                f"{len(self._obs_idx) + self._features.dim}"
            )
        self.model = model
        self.vecnormalize = vecnormalize
        if vecnormalize is not None:
            vecnormalize.training = False
            vecnormalize.norm_reward = False
        self.deterministic = bool(deterministic)
        self.observation = observation
        self.needs_states = observation in ("full", "no_budget")
        self.recurrent = hasattr(model.policy, "lstm_actor")
        self.name = name or type(model).__name__.lower()
        self.rng = np.random.default_rng()
        self._batch = None
        self._state: Any = None
        self._episode_start: np.ndarray | None = None

    @classmethod
    def from_env(cls, env: Any, **kwargs: Any) -> SB3Attacker:
        from .base import params_of

        return cls(params=params_of(env), **kwargs)

    def reset(self, seed: Any = None) -> None:
        super().reset(seed)
        if seed is not None:  # the policy samples from torch's generator
            import torch

            ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
            torch.manual_seed(int(ss.generate_state(1)[0]))
        self._state = None

    def act(self, obs: Any) -> np.ndarray:
        if self.params is not None:
            return super().act(obs)
        o = np.asarray(obs, dtype=np.float64)
        single = o.ndim == 1
        o2 = o[None] if single else o
        if self._batch is None:
            self._batch = o2.shape[0]
            self._start(self._batch)
        a = np.clip(self._act(o2), -1.0, 1.0).astype(np.float32)
        return a[0] if single else a

    def _start(self, K: int) -> None:
        self._state = None
        self._episode_start = np.ones(K, dtype=bool)
        self._features.reset(K, rng=self.rng)

    def _act(self, obs: np.ndarray) -> np.ndarray:
        o = self._features.append(obs, obs[:, self._obs_idx].astype(np.float32))
        if self.vecnormalize is not None:
            o = self.vecnormalize.normalize_obs(o)
        if self.recurrent:
            a, self._state = self.model.predict(o, state=self._state, episode_start=self._episode_start, deterministic=self.deterministic)
            self._episode_start = np.zeros(obs.shape[0], dtype=bool)
        else:
            a, _ = self.model.predict(o, deterministic=self.deterministic)
        return np.asarray(a, dtype=np.float64).reshape(obs.shape[0], -1)


def load_attacker(
    run_dir: str | Path,
    *,
    which: str = "final",
    params: AttackParams | None = None,
    deterministic: bool = False,
    name: str | None = None,
    torch_threads: int | None = 1,
) -> SB3Attacker:
    """Load a training run written by :mod:`agents.train` as an attacker.

    Parameters
    ----------
    run_dir : path
        The run's directory (:mod:`agents.runs`: ``run.json``, ``model.zip``,
        ``best_model.zip`` and, when the observations were normalised, ``vecnormalize.pkl``).
        Loading unpickles these files: load only runs you trust.
    which : {"final", "best"}
        The model at the end of training or the best one of the evaluation callback.
    params : AttackParams, optional
        Parameters of the environment to run in (default: the training environment's).
    deterministic : bool
        See :class:`SB3Attacker`.
    name : str, optional
        Label (default: the run's algorithm name).
    torch_threads : int, optional
        Sets torch's (process-wide) number of threads, 1 by default: the policies are small,
        and on a shared 2-core machine a second thread made one RecurrentPPO step 4 to 40 times
        slower (1.1 ms on one thread). ``None`` leaves it as it is.

    Raises
    ------
    ConfigError
        A broken ``run.json``, an unknown algorithm, a missing, corrupt or incompatible model
        or normalisation file.
    """
    from .runs import read_run

    run = read_run(run_dir)
    cls = algorithm_class(run.algo)
    if torch_threads is not None:
        import torch

        torch.set_num_threads(int(torch_threads))
    model_path = run.model_path(which)
    try:
        model = cls.load(str(model_path), device="cpu")
    except (zipfile.BadZipFile, EOFError, OSError, ValueError, KeyError, RuntimeError, pickle.UnpicklingError) as exc:
        raise ConfigError(f"cannot load {model_path} as a {run.algo} model: {type(exc).__name__}: {_first_line(exc)}") from exc
    env_cfg = dict(run.env)
    env_cfg["gamma_opt"] = False
    if params is None:
        params = resolve_params(env_cfg)
    vecnorm = None
    vn_path = run.path / "vecnormalize.pkl"
    if vn_path.exists():
        from stable_baselines3.common.vec_env import VecNormalize

        try:
            vecnorm = VecNormalize.load(str(vn_path), SB3VecEnv(env_cfg, 1, run.observation, features=run.features))
        except (EOFError, OSError, ValueError, KeyError, AttributeError, pickle.UnpicklingError) as exc:
            raise ConfigError(f"cannot load {vn_path}: {type(exc).__name__}: {_first_line(exc)}") from exc
    return SB3Attacker(
        model, vecnorm, deterministic, params=params, observation=run.observation, features=run.features,
        name=name or run.algo,
    )


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else ""
