"""Train a learned attacker with stable-baselines3 (the ``train`` subcommand).

One YAML file per algorithm and system in ``agents/configs/`` (``{algo}_{preset}.yaml``, in the
spirit of rl-zoo3) holds everything a run needs: the environment configuration, the observation
mode, the number of parallel copies, the budget, the policy and its hyperparameters, the
normalisation, the evaluation. A ``quick:`` section overrides it for a smoke test
(``--quick``). Training steps the native vector environment through :class:`agents.sb3.SB3VecEnv`
on the fast ideal backend.

A run directory holds ``model.zip`` (final), ``best_model.zip`` (best evaluation),
``vecnormalize.pkl`` (when observations are normalised), ``evaluations.npz``, TensorBoard logs
under ``tb/`` and ``run.json`` (configuration, timing, and the final evaluation: the learned
policy against the Gaussian attacker on the same seeds, on the ideal backend, and a few episodes
through real ElGamal ciphertexts). Load it with :func:`agents.sb3.load_attacker`.

Example::

    encctl-gym train --algo ppo --preset paper-example --seed 0
    encctl-gym train --algo ppo --preset small --quick --out /tmp/runs
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ParameterError

__all__ = ["CONFIG_DIR", "load_config", "train", "final_evaluation", "add_arguments", "run"]

CONFIG_DIR = Path(__file__).resolve().parent / "configs"

_ACTIVATIONS = {"tanh": "Tanh", "relu": "ReLU", "elu": "ELU", "leaky_relu": "LeakyReLU"}


# --------------------------------------------------------------------------- configuration
def _merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    out = copy.deepcopy(base)
    for k, v in (over or {}).items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


DEFAULTS: dict[str, Any] = {
    "env": {"reward": "log_error", "decipher_delay": 0},
    "horizon": None,  # attack length of the training episodes, set through the budget (budget_config)
    "observation": "full",
    "reward_scaling": "none",
    "n_envs": 16,
    "n_timesteps": 100_000,
    "seed": 0,
    "normalize": {"norm_obs": True, "norm_reward": False},
    "policy": "MlpPolicy",
    "hyperparams": {},
    "eval": {
        "freq": 50_000,  # environment steps between evaluations
        "episodes": 16,
        "final_episodes": 50,
        "final_horizon": None,  # None: the training episode length
        "elgamal": {"episodes": 2, "max_samples": 40, "key_length": 64},
    },
}


def load_config(algo: str, preset: str | None = None, *, path: str | Path | None = None, quick: bool = False) -> dict[str, Any]:
    """Read ``agents/configs/{algo}_{preset}.yaml`` (or ``path``), merged over the defaults.

    Parameters
    ----------
    algo : str
        ``ppo``, ``sac`` or ``recurrent_ppo``.
    preset : str, optional
        The environment preset naming the file (ignored when ``path`` is given).
    path : path, optional
        An explicit YAML file.
    quick : bool
        Apply the file's ``quick:`` section (a smoke test of a few thousand steps).

    Returns
    -------
    dict
        The resolved configuration (``algo`` included).
    """
    from .sb3 import ALGORITHMS

    if algo not in ALGORITHMS:
        raise ParameterError(f"unknown algorithm {algo!r}; choose one of {', '.join(ALGORITHMS)}")
    if path is None:
        if preset is None:
            raise ParameterError("give a preset or a config file")
        path = CONFIG_DIR / f"{algo}_{preset}.yaml"
        if not path.exists():
            known = sorted(p.stem for p in CONFIG_DIR.glob(f"{algo}_*.yaml"))
            raise ParameterError(f"no config {path.name} in {CONFIG_DIR}; available for {algo}: {', '.join(known) or 'none'}")
    path = Path(path)
    if not path.exists():
        raise ParameterError(f"config file {path} does not exist")
    raw = yaml.safe_load(path.read_text()) or {}
    if raw.get("algo", algo) != algo:
        raise ParameterError(f"{path.name} is a config for {raw['algo']!r}, not {algo!r}")
    quick_over = raw.pop("quick", {}) or {}
    cfg = _merge(DEFAULTS, raw)
    if quick:
        cfg = _merge(cfg, quick_over)
    cfg["algo"] = algo
    cfg["config_file"] = str(path)
    cfg["quick"] = bool(quick)
    resolve_params(_env_cfg(cfg))  # fail early on a bad environment configuration
    return cfg


def _yaml_value(text: str) -> Any:
    """A YAML scalar, with ``1e-3``-style floats (strings to YAML 1.1) read as floats."""
    v = yaml.safe_load(text)
    if isinstance(v, str):
        try:
            return float(v)
        except ValueError:
            return v
    return v


def apply_override(cfg: dict[str, Any], item: str) -> None:
    """Apply one ``key.sub=value`` override (value parsed as YAML) to ``cfg`` in place."""
    if "=" not in item:
        raise ParameterError(f"override {item!r} is not KEY=VALUE")
    key, value = item.split("=", 1)
    parts = key.strip().split(".")
    node = cfg
    for p in parts[:-1]:
        if not isinstance(node.get(p), dict):
            node[p] = {}
        node = node[p]
    node[parts[-1]] = _yaml_value(value)
    if parts[0] == "env":
        resolve_params(_env_cfg(cfg))


def _env_cfg(cfg: dict[str, Any], **over: Any) -> dict[str, Any]:
    """The training environment's configuration (``horizon`` applied through the budget)."""
    from .evaluate import budget_config

    env = {"gamma_opt": False, **cfg["env"]}
    env.update(over)
    if cfg.get("horizon"):
        env = budget_config(env, int(cfg["horizon"]))
    return env


def _policy_kwargs(pk: dict[str, Any] | None) -> dict[str, Any]:
    import torch.nn as nn

    pk = dict(pk or {})
    act = pk.get("activation_fn")
    if isinstance(act, str):
        name = _ACTIVATIONS.get(act.lower())
        if name is None:
            raise ParameterError(f"unknown activation_fn {act!r}; choose one of {', '.join(_ACTIVATIONS)}")
        pk["activation_fn"] = getattr(nn, name)
    return pk


# --------------------------------------------------------------------------- callbacks
def _callbacks() -> tuple[type, type]:
    from stable_baselines3.common.callbacks import BaseCallback

    class AttackMetricsCallback(BaseCallback):
        """Logs the attack's outcome at every episode end: final epsilon, (N - 1) epsilon
        (comparable with the design rates), epsilon / gamma(N), and the average input power."""

        def _on_step(self) -> bool:
            for info in self.locals.get("infos", ()):
                if "epsilon" in info and "terminal_observation" in info:
                    eps, N = info["epsilon"], info["samples_delivered"]
                    self.logger.record_mean("attack/final_log10_epsilon", math.log10(eps))
                    self.logger.record_mean("attack/final_epsilon_x_N-1", eps * (N - 1))
                    self.logger.record_mean("attack/epsilon_over_gamma", eps / info["gamma"])
                    self.logger.record_mean("attack/average_power", info["average_power"])
            return True

    class TqdmCallback(BaseCallback):
        """A tqdm progress bar over environment steps; without a TTY it prints a line every
        30 s instead of redrawing."""

        def __init__(self, total: int, desc: str) -> None:
            super().__init__()
            self.total, self.desc = total, desc
            self.bar: Any = None

        def _on_training_start(self) -> None:
            from tqdm import tqdm

            tty = sys.stderr.isatty()
            self.bar = tqdm(total=self.total, desc=self.desc, unit="step", mininterval=0.5 if tty else 30.0,
                            dynamic_ncols=tty, file=sys.stderr, ascii=not tty)

        def _on_step(self) -> bool:
            self.bar.update(self.training_env.num_envs)
            return True

        def _on_training_end(self) -> None:
            if self.bar is not None:
                self.bar.close()

    return AttackMetricsCallback, TqdmCallback


# --------------------------------------------------------------------------- training
def _make_env(cfg: dict[str, Any], env_cfg: dict[str, Any], num_envs: int, reward_scaling: str) -> Any:
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from .sb3 import SB3VecEnv

    venv: Any = VecMonitor(SB3VecEnv(env_cfg, num_envs, cfg["observation"], reward_scaling))
    norm = cfg.get("normalize") or {}
    if norm and (norm.get("norm_obs") or norm.get("norm_reward")):
        venv = VecNormalize(venv, norm_obs=bool(norm.get("norm_obs", True)), norm_reward=bool(norm.get("norm_reward", False)),
                            gamma=float(cfg["hyperparams"].get("gamma", 0.99)))
    return venv


def run_name(cfg: dict[str, Any], seed: int) -> str:
    """``{algo}_{preset}_d{delay}_{observation}_s{seed}`` (``-quick`` for smoke tests)."""
    delay = cfg["env"].get("decipher_delay", 0)
    name = f"{cfg['algo']}_{cfg['env'].get('preset', 'custom')}_d{delay}_{cfg['observation']}_s{seed}"
    return name + ("-quick" if cfg.get("quick") else "")


def train(
    cfg: dict[str, Any],
    *,
    out: str | Path = "results/train",
    seed: int | None = None,
    progress: bool = True,
    tensorboard: bool = True,
    verbose: int = 0,
    name: str | None = None,
) -> Path:
    """Train one attacker as configured; return the run directory (model saved, run.json written).

    Parameters
    ----------
    cfg : dict
        From :func:`load_config`.
    out : path
        Parent directory of the run directory.
    seed : int, optional
        Overrides ``cfg["seed"]``.
    progress : bool
        Show a progress bar (works without a TTY).
    tensorboard : bool
        Write TensorBoard logs under ``<run>/tb``.
    verbose : int
        stable-baselines3 verbosity.
    name : str, optional
        Run directory name (default :func:`run_name`).
    """
    import torch
    from stable_baselines3.common.callbacks import CallbackList, EvalCallback

    from .sb3 import algorithm_class

    torch.set_num_threads(1)
    seed = int(cfg["seed"] if seed is None else seed)
    cfg = copy.deepcopy(cfg)
    cfg["seed"] = seed
    run_dir = Path(out) / (name or run_name(cfg, seed))
    run_dir.mkdir(parents=True, exist_ok=True)
    n_envs = int(cfg["n_envs"])
    env_cfg = _env_cfg(cfg)
    env = _make_env(cfg, env_cfg, n_envs, cfg.get("reward_scaling", "none"))
    ev = cfg["eval"]
    n_eval = int(ev["episodes"])
    eval_env = _make_env(cfg, env_cfg, n_eval, "none")  # eval returns are the true log eps_0 - log eps_N
    if hasattr(eval_env, "training"):
        eval_env.training = False
        eval_env.norm_reward = False

    hp = dict(cfg["hyperparams"])
    hp["policy_kwargs"] = _policy_kwargs(hp.get("policy_kwargs"))
    algo_cls = algorithm_class(cfg["algo"])
    model = algo_cls(
        cfg["policy"], env, seed=seed, verbose=verbose, device="cpu",
        tensorboard_log=str(run_dir / "tb") if tensorboard else None, **hp,
    )
    Metrics, Tqdm = _callbacks()
    callbacks: list[Any] = [
        Metrics(),
        EvalCallback(
            eval_env, n_eval_episodes=n_eval, eval_freq=max(int(ev["freq"]) // n_envs, 1),
            log_path=str(run_dir), best_model_save_path=str(run_dir), deterministic=False, verbose=verbose,
        ),
    ]
    total = int(cfg["n_timesteps"])
    if progress:
        callbacks.append(Tqdm(total, run_dir.name))
    t0 = time.perf_counter()
    model.learn(total_timesteps=total, callback=CallbackList(callbacks), tb_log_name="run")
    seconds = time.perf_counter() - t0
    model.save(str(run_dir / "model.zip"))
    if hasattr(env, "obs_rms"):
        env.save(str(run_dir / "vecnormalize.pkl"))
    meta = {
        "algo": cfg["algo"],
        "observation": cfg["observation"],
        "env": env_cfg,
        "seed": seed,
        "n_timesteps": total,
        "n_envs": n_envs,
        "train_seconds": round(seconds, 1),
        "steps_per_second": round(total / seconds, 1),
        "config": cfg,
        "torch_threads": torch.get_num_threads(),
    }
    (run_dir / "run.json").write_text(json.dumps(meta, indent=2, default=str))
    env.close()
    return run_dir


# --------------------------------------------------------------------------- final evaluation
def final_evaluation(run_dir: str | Path, *, seed: int = 10_000, progress: bool = False) -> dict[str, Any]:
    """Evaluate a finished run and record the result in its ``run.json``.

    The final and the best model each play ``eval.final_episodes`` episodes on the ideal backend
    (at the training episode length, or ``eval.final_horizon``) against the Gaussian
    attacker on the same environment seeds; then the final model plays ``eval.elgamal.episodes``
    short episodes through real ElGamal ciphertexts (a small key). If the ElGamal backend is
    unavailable the reason is recorded instead.

    Returns
    -------
    dict
        The ``final_evaluation`` entry written to ``run.json``.
    """
    from .baselines import GaussianAttacker
    from .evaluate import rollout
    from .sb3 import load_attacker

    run_dir = Path(run_dir)
    meta = json.loads((run_dir / "run.json").read_text())
    from .evaluate import budget_config, elgamal_config

    ev = meta["config"]["eval"]
    env_cfg = dict(meta["env"])
    if ev.get("final_horizon"):
        env_cfg = budget_config(env_cfg, int(ev["final_horizon"]))
    params = resolve_params(env_cfg)
    episodes = int(ev["final_episodes"])
    out: dict[str, Any] = {"episodes": episodes, "seed": seed, "N": params.horizon, "env": env_cfg}
    gauss = rollout(GaussianAttacker(params), env_cfg, episodes=episodes, seed=seed, record=False)
    out["gaussian"] = _summary(gauss)
    rate = _gauss_rate(params)
    out["gaussian_design_rate"] = rate
    for which in ("final", "best"):
        if not (run_dir / ("model.zip" if which == "final" else "best_model.zip")).exists():
            continue
        att = load_attacker(run_dir, which=which, params=params)
        r = rollout(att, env_cfg, episodes=episodes, seed=seed, record=False)
        s = _summary(r)
        s["ratio_to_gaussian"] = s["mean_epsilon"] / out["gaussian"]["mean_epsilon"]
        # paired comparison on the same seeds: mean and standard error of the log ratio
        d = np.log(r.final_epsilon) - np.log(gauss.final_epsilon)
        s["mean_log_ratio"] = float(d.mean())
        s["se_log_ratio"] = float(d.std(ddof=1) / math.sqrt(d.size)) if d.size > 1 else float("nan")
        out[which] = s
    el = ev.get("elgamal") or {}
    if el.get("episodes", 0) > 0:
        # a small key for speed; short attacks whose budget fractions mean what they meant in training
        el_cfg = elgamal_config(meta["env"], int(el.get("max_samples", 40)), key_length=int(el.get("key_length", 64)), crypto_seed=seed)
        try:
            el_params = resolve_params(el_cfg)
            att = load_attacker(run_dir, which="final", params=el_params)
            r = rollout(att, el_cfg, episodes=int(el["episodes"]), seed=seed, record=False)
            out["elgamal"] = {**_summary(r), "key_length": el_params.key_length, "N": el_params.horizon,
                              "seconds_per_step": r.seconds / (r.episodes * max(el_params.horizon - 1, 1))}
        except Exception as exc:  # noqa: BLE001 - recorded, not hidden: the backend may be unfinished
            out["elgamal"] = {"unavailable": f"{type(exc).__name__}: {exc}"}
    meta["final_evaluation"] = out
    (run_dir / "run.json").write_text(json.dumps(meta, indent=2, default=str))
    return out


def _gauss_rate(params: Any) -> float:
    from encctl_gym.security.attack_design import gaussian_attack_design

    return float(gaussian_attack_design(params.A, params.B, sigma_u2=params.sigma_u2, sigma_w2=params.sigma_w2).rate)


def _summary(r: Any) -> dict[str, Any]:
    return {
        "mean_epsilon": r.mean_final(),
        "se_epsilon": r.se_final(),
        "mean_average_power": float(r.average_power.mean()),
        "episodes": r.episodes,
        "seconds": round(r.seconds, 2),
    }


# --------------------------------------------------------------------------- command line
def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``encctl-gym train``."""
    from .sb3 import ALGORITHMS

    parser.add_argument("--algo", required=True, choices=ALGORITHMS, help="learning algorithm")
    parser.add_argument("--preset", default="paper-example", help="system preset naming the config agents/configs/{algo}_{preset}.yaml")
    parser.add_argument("--config", default=None, help="explicit YAML config file (overrides --preset's)")
    parser.add_argument("--quick", action="store_true", help="smoke test: the config's quick section (a few thousand steps)")
    parser.add_argument("--seed", type=int, default=None, help="seed (default: the config's)")
    parser.add_argument("--n-timesteps", type=int, default=None, help="override the training budget")
    parser.add_argument("--n-envs", type=int, default=None, help="override the number of parallel copies")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override a config entry, dotted keys, YAML values (e.g. env.max_samples=512, "
                        "hyperparams.gamma=0.99); repeatable")
    parser.add_argument("--out", default="results/train", help="parent directory of the run (default results/train)")
    parser.add_argument("--name", default=None, help="run directory name (default {algo}_{preset}_d{delay}_{obs}_s{seed})")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--no-tensorboard", action="store_true", help="no TensorBoard logs")
    parser.add_argument("--no-final-eval", action="store_true", help="skip the final evaluation (ideal and ElGamal)")
    parser.add_argument("--verbose", type=int, default=0, help="stable-baselines3 verbosity (0, 1, 2)")


def run(args: argparse.Namespace) -> int:
    """Train, save, evaluate; print a one-paragraph summary."""
    cfg = load_config(args.algo, args.preset, path=args.config, quick=args.quick)
    if args.n_timesteps is not None:
        cfg["n_timesteps"] = int(args.n_timesteps)
    if args.n_envs is not None:
        cfg["n_envs"] = int(args.n_envs)
    for item in args.overrides:
        apply_override(cfg, item)
    run_dir = train(cfg, out=args.out, seed=args.seed, progress=not args.no_progress,
                    tensorboard=not args.no_tensorboard, verbose=args.verbose, name=args.name)
    meta = json.loads((run_dir / "run.json").read_text())
    print(f"trained {cfg['algo']} for {meta['n_timesteps']} steps in {meta['train_seconds']} s "
          f"({meta['steps_per_second']} steps/s); saved to {run_dir}")
    if not args.no_final_eval:
        ev = final_evaluation(run_dir)
        g = ev["gaussian"]
        print(f"evaluation ({ev['episodes']} episodes, N = {ev['N']}): gaussian mean epsilon {g['mean_epsilon']:.4g} "
              f"(power {g['mean_average_power']:.3g})")
        for which in ("final", "best"):
            if which in ev:
                s = ev[which]
                print(f"  {which:5s} model: mean epsilon {s['mean_epsilon']:.4g} +- {s['se_epsilon']:.2g}, "
                      f"ratio to gaussian {s['ratio_to_gaussian']:.3f} (paired log ratio {s['mean_log_ratio']:+.3f} "
                      f"+- {s['se_log_ratio']:.3f}), power {s['mean_average_power']:.3g}")
        el = ev.get("elgamal", {})
        if "unavailable" in el:
            print(f"  elgamal: unavailable ({el['unavailable']})")
        elif el:
            print(f"  elgamal ({el['episodes']} episodes, N = {el['N']}, {el['key_length']}-bit key): mean epsilon "
                  f"{el['mean_epsilon']:.4g}, {1000 * el['seconds_per_step']:.1f} ms/step")
    return 0
