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
* :func:`save_vecnormalize` / :func:`load_vecnormalize` store the ``VecNormalize`` statistics
  as plain arrays (``vecnormalize.npz``, loaded without pickles); an older run's
  ``vecnormalize.pkl`` is unpickled only when the caller opts in (``allow_pickle=True``).
* :data:`ALGORITHMS`: the learning algorithms by name (one table for training, loading and the
  command line).
"""

from __future__ import annotations

import inspect
import pickle
import warnings
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
from sb3_contrib import RecurrentPPO
from stable_baselines3 import PPO, SAC
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.vec_env import VecEnv

from encctl_gym.envs.config import AttackParams, resolve_params
from encctl_gym.errors import ConfigError, EncctlError, ParameterError
from encctl_gym.registry import Registry

from .ars import PairedARS
from .base import Attacker, observation_indices
from .features import FeatureSet
from .vec_env import INFO_KEYS, SB3VecEnv

__all__ = [
    "SB3VecEnv",
    "SB3Attacker",
    "load_attacker",
    "save_vecnormalize",
    "load_vecnormalize",
    "VECNORMALIZE_FILE",
    "ALGORITHMS",
    "algorithm_class",
    "INFO_KEYS",
]

#: The run file of the observation statistics (arrays only, no pickles).
VECNORMALIZE_FILE = "vecnormalize.npz"
#: The pickle older runs hold instead (unpickled only with ``allow_pickle=True``).
VECNORMALIZE_PICKLE = "vecnormalize.pkl"

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
            a, self._state = self.model.predict(
                o, state=self._state, episode_start=self._episode_start, deterministic=self.deterministic
            )
            self._episode_start = np.zeros(obs.shape[0], dtype=bool)
        else:
            a, _ = self.model.predict(o, deterministic=self.deterministic)
        return np.asarray(a, dtype=np.float64).reshape(obs.shape[0], -1)


def save_vecnormalize(vecnorm: Any, path: str | Path) -> Path:
    """Write a ``VecNormalize``'s statistics and settings as arrays (``numpy.savez``, no pickles).

    Stored: ``obs_rms`` and ``ret_rms`` (mean, var, count), ``clip_obs``, ``clip_reward``,
    ``gamma``, ``epsilon``, ``norm_obs`` and ``norm_reward``; :func:`load_vecnormalize` reads them.
    """
    path = Path(path)
    arrays = {
        "obs_mean": vecnorm.obs_rms.mean, "obs_var": vecnorm.obs_rms.var, "obs_count": vecnorm.obs_rms.count,
        "ret_mean": vecnorm.ret_rms.mean, "ret_var": vecnorm.ret_rms.var, "ret_count": vecnorm.ret_rms.count,
        "clip_obs": vecnorm.clip_obs, "clip_reward": vecnorm.clip_reward, "gamma": vecnorm.gamma,
        "epsilon": vecnorm.epsilon, "norm_obs": vecnorm.norm_obs, "norm_reward": vecnorm.norm_reward,
    }  # fmt: skip
    values: dict[str, Any] = {k: np.asarray(v, dtype=np.float64) for k, v in arrays.items()}
    with path.open("wb") as fh:
        np.savez(fh, **values)
    return path


def load_vecnormalize(path: str | Path, venv: VecEnv) -> Any:
    """A ``VecNormalize`` over ``venv`` with the statistics of :func:`save_vecnormalize` (no pickles).

    Raises
    ------
    ConfigError
        If the file cannot be read as such arrays, or its observation statistics do not have
        the shape of ``venv``'s observations.
    """
    from stable_baselines3.common.vec_env import VecNormalize

    path = Path(path)
    keys = ("obs_mean", "obs_var", "obs_count", "ret_mean", "ret_var", "ret_count",
            "clip_obs", "clip_reward", "gamma", "epsilon", "norm_obs", "norm_reward")  # fmt: skip
    try:
        with np.load(path, allow_pickle=False) as z:
            v = {k: np.array(z[k], dtype=np.float64) for k in keys}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        raise ConfigError(f"cannot load {path} as VecNormalize statistics: {type(exc).__name__}: {_first_line(exc)}") from None
    shape = venv.observation_space.shape
    if v["obs_mean"].shape != shape or v["obs_var"].shape != shape or not all(np.isfinite(a).all() for a in v.values()):
        raise ConfigError(
            f"{path}: observation statistics of shape {v['obs_mean'].shape} (finite: "
            f"{all(np.isfinite(a).all() for a in v.values())}) do not fit the run's observations of shape {shape}"
        )
    vecnorm = VecNormalize(
        venv, training=False, norm_obs=bool(v["norm_obs"]), norm_reward=bool(v["norm_reward"]),
        clip_obs=float(v["clip_obs"]), clip_reward=float(v["clip_reward"]), gamma=float(v["gamma"]),
        epsilon=float(v["epsilon"]),
    )  # fmt: skip
    obs_rms: Any = vecnorm.obs_rms  # one RunningMeanStd: the observations are a Box
    obs_rms.mean, obs_rms.var, obs_rms.count = v["obs_mean"], v["obs_var"], float(v["obs_count"])
    vecnorm.ret_rms.mean, vecnorm.ret_rms.var, vecnorm.ret_rms.count = v["ret_mean"], v["ret_var"], float(v["ret_count"])
    return vecnorm


#: Replay buffer of a model rebuilt only to predict (SAC would otherwise allocate its training buffer).
_PREDICT_BUFFER = 1


def _load_weights_only(run: Any, cls: type[BaseAlgorithm], model_path: Path) -> BaseAlgorithm:
    """The run's model without unpickling anything: rebuilt from its ``run.json`` config as
    :mod:`agents.train` builds it, then given the archive's weights by ``set_parameters``
    (stable-baselines3 reads only the ``.pth`` entries there, with ``torch.load(...,
    weights_only=True)``; the ``data`` entry, whose objects are cloudpickled, is not read).

    Raises
    ------
    ConfigError
        If the config does not rebuild the model or the weights do not fit it exactly.
    """
    from .hyperparams import make_schedules, policy_kwargs

    cfg = run.meta.get("config")
    if not isinstance(cfg, dict) or not isinstance(cfg.get("hyperparams"), dict) or "policy" not in cfg:
        raise ConfigError(
            f"cannot load {model_path} without unpickling: {run.path / 'run.json'} has no training config to rebuild the model from"
        )
    try:
        hp = make_schedules(cfg["hyperparams"])
        hp["policy_kwargs"] = policy_kwargs(cls, cfg["policy"], hp.get("policy_kwargs"))
        if "buffer_size" in inspect.signature(cls.__init__).parameters:
            hp["buffer_size"] = _PREDICT_BUFFER
        try:  # a bad env is the run.json's fault, not the model's
            env = SB3VecEnv(dict(run.env), 1, run.observation, features=run.features)
        except EncctlError as exc:
            raise ConfigError(f"{run.path / 'run.json'}: its env does not make an environment: {exc}") from exc
        with warnings.catch_warnings():  # the training-time advice (PPO's mini-batch size for one copy) does not apply
            warnings.simplefilter("ignore", UserWarning)
            model = cls(cfg["policy"], env, verbose=0, device="cpu", **hp)
        model.set_parameters(str(model_path), exact_match=True, device="cpu")
    except ConfigError:
        raise
    except EncctlError as exc:
        raise ConfigError(f"cannot rebuild the {run.algo} model of {run.path}: {exc}") from exc
    except (
        zipfile.BadZipFile,
        EOFError,
        OSError,
        ValueError,
        KeyError,
        TypeError,
        AssertionError,
        RuntimeError,
        pickle.UnpicklingError,
    ) as exc:
        raise ConfigError(
            f"cannot load the weights of {model_path} into a {run.algo} model: {type(exc).__name__}: {_first_line(exc)}"
        ) from exc
    return model


def _load_model(run: Any, cls: type[BaseAlgorithm], model_path: Path, allow_pickle: bool) -> BaseAlgorithm:
    """The model by :func:`_load_weights_only`; stable-baselines3's own loader (which unpickles)
    only if that fails and the caller allows pickles."""
    try:
        return _load_weights_only(run, cls, model_path)
    except ConfigError as exc:
        if not allow_pickle:
            raise ConfigError(
                f"{exc}; loading {model_path} as stable-baselines3 saved it unpickles its 'data' entry, which can run any code: "
                "do it only for a run you trust, with allow_pickle=True (encctl-gym evaluate --allow-pickle)"
            ) from exc
    try:
        return cls.load(str(model_path), device="cpu")
    except (zipfile.BadZipFile, EOFError, OSError, ValueError, KeyError, RuntimeError, pickle.UnpicklingError) as exc:
        raise ConfigError(f"cannot load {model_path} as a {run.algo} model: {type(exc).__name__}: {_first_line(exc)}") from exc


def load_attacker(
    run_dir: str | Path,
    *,
    which: str = "final",
    params: AttackParams | None = None,
    deterministic: bool = False,
    name: str | None = None,
    torch_threads: int | None = 1,
    allow_pickle: bool = False,
) -> SB3Attacker:
    """Load a training run written by :mod:`agents.train` as an attacker.

    Parameters
    ----------
    run_dir : path
        The run's directory (:mod:`agents.runs`: ``run.json``, ``model.zip``,
        ``best_model.zip`` and, when the observations were normalised, ``vecnormalize.npz``).
        The model is rebuilt from the run's config and given the archive's weights only
        (nothing is unpickled, :func:`_load_weights_only`).
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
    allow_pickle : bool, default False
        Allow every pickle a run may need (a pickle can run any code when loaded): a
        ``vecnormalize.pkl`` (written by older versions), and stable-baselines3's own loader
        (which unpickles the archive's ``data`` entry) for a model the run's config cannot
        rebuild. Without it such a run is refused, saying how to opt in.

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
    model = _load_model(run, cls, run.model_path(which), allow_pickle)
    env_cfg = dict(run.env)
    env_cfg["gamma_opt"] = False
    if params is None:
        params = resolve_params(env_cfg)
    vecnorm = None
    vn_path, pkl_path = run.path / VECNORMALIZE_FILE, run.path / VECNORMALIZE_PICKLE
    if vn_path.exists() or pkl_path.exists():
        try:  # a bad env is the run.json's fault, not the statistics'
            venv = SB3VecEnv(env_cfg, 1, run.observation, features=run.features)
        except EncctlError as exc:
            raise ConfigError(f"{run.path / 'run.json'}: its env does not make an environment: {exc}") from exc
        if vn_path.exists():
            vecnorm = load_vecnormalize(vn_path, venv)
        elif not allow_pickle:
            raise ConfigError(
                f"{pkl_path} is a pickle, and unpickling can run any code; load it only from a run you trust, with "
                f"allow_pickle=True (encctl-gym evaluate --allow-pickle); runs written now store {VECNORMALIZE_FILE} instead"
            )
        else:
            from stable_baselines3.common.vec_env import VecNormalize

            try:
                vecnorm = VecNormalize.load(str(pkl_path), venv)
            except (EOFError, OSError, ValueError, KeyError, AttributeError, pickle.UnpicklingError) as exc:
                raise ConfigError(f"cannot load {pkl_path}: {type(exc).__name__}: {_first_line(exc)}") from exc
    try:
        return SB3Attacker(
            model,
            vecnorm,
            deterministic,
            params=params,
            observation=run.observation,
            features=run.features,
            name=name or run.algo,
        )
    except ParameterError as exc:  # an environment other than the run's: name the run and the difference
        trained = resolve_params(env_cfg)
        diff = [
            f"{k} = {getattr(trained, k)} in training, {getattr(params, k)} here"
            for k in ("n", "m", "input_history")
            if getattr(trained, k) != getattr(params, k)
        ]
        raise ConfigError(
            f"the run {run.path} cannot play in this environment: {exc}" + (f" ({'; '.join(diff)})" if diff else "")
        ) from None


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else ""
