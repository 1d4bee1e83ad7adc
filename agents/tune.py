"""Hyperparameter search with Optuna (the ``tune`` subcommand; extra ``[optuna]``).

A *trial* is one training run (:func:`agents.train.train`) of the configuration
(:func:`agents.config.load_config`: the algorithm's default, the system's tuned file, ``--set``
overrides) with entries drawn from the algorithm's search space (:data:`SEARCH_SPACES`, dotted
keys as ``--set`` takes them). Its value is the paired error ratio of the trained policy to the
optimal-design oracle at the training attack length: the geometric mean over ``episodes``
environment seeds of ``epsilon_policy / epsilon_oracle`` (both attackers on the same seeds;
:class:`agents.optimal.OptimalDesignAttacker` closed loop for a policy that reads delivered
states, open loop for a blind one), minimised. The seeds (``30000, 30001, ...`` by default)
differ from those of the training's evaluations and of ``encctl-gym evaluate`` (20000, ...), so
the reported results are not the ones the search selected on.

Pruning: after every evaluation of the training's learning curve (:mod:`agents.curves`), the
trial reports ``E[epsilon] / gamma_opt(N)`` to Optuna's median pruner and stops when it is
worse than the median of earlier trials at the same step.

Storage: a SQLite file ``study.db`` in the output directory by default, so an interrupted study
resumes when the command is run again; ``--storage URL`` (any database URL Optuna accepts, e.g.
``postgresql://...``) shares one study between machines, each running ``encctl-gym tune`` with
the same ``--study-name``. The best trial's configuration is written as an rl-zoo3-style YAML
file, ``{algo}_{system}.yaml`` in the output directory (``--save-config``: also
``agents/configs/{algo}_{preset}.yaml``, the tuned file ``train --preset`` then merges).

Example::

    encctl-gym tune --algo ars --preset paper-example --trials 20 --n-timesteps 20000000
"""

from __future__ import annotations

import argparse
import copy
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from encctl_gym._validation import format_value
from encctl_gym.errors import ConfigError, EncctlError

from .config import CONFIG_DIR, MAX_STEPS, apply_override, load_config
from .runs import check_output_dir
from .sb3 import ALGORITHMS  # the [rl] extra: without it the CLI says which extra to install

__all__ = ["SEARCH_SPACES", "TUNED_KEYS", "objective_ratio", "tuned_config", "tune", "add_arguments", "run"]

#: Environment seeds of the trials' objective (seed, seed + 1, ...).
OBJECTIVE_SEED = 30_000


def _ppo_space(trial: Any) -> dict[str, Any]:
    arch = trial.suggest_categorical("policy", ["linear", "mlp64"])
    return {
        "env.reward": trial.suggest_categorical("reward", ["a_optimality", "log_error"]),
        "reward_scaling": trial.suggest_categorical("reward_scaling", ["none", "samples"]),
        "hyperparams.learning_rate": trial.suggest_float("learning_rate", 1e-5, 1e-3, log=True),
        "hyperparams.n_steps": trial.suggest_categorical("n_steps", [256, 512, 1024]),
        "hyperparams.batch_size": trial.suggest_categorical("batch_size", [512, 1024, 4096]),
        "hyperparams.n_epochs": trial.suggest_categorical("n_epochs", [5, 10, 20]),
        "hyperparams.gamma": trial.suggest_categorical("gamma", [0.95, 0.99, 0.999]),
        "hyperparams.gae_lambda": trial.suggest_categorical("gae_lambda", [0.9, 0.95, 0.99]),
        "hyperparams.policy_kwargs.net_arch": {"pi": [], "vf": [64, 64]} if arch == "linear" else [64, 64],
    }


def _ars_space(trial: Any) -> dict[str, Any]:
    return {
        "hyperparams.learning_rate": trial.suggest_float("learning_rate", 1e-3, 5e-2, log=True),
        "hyperparams.delta_std": trial.suggest_float("delta_std", 3e-3, 1e-1, log=True),
        "hyperparams.n_delta": trial.suggest_categorical("n_delta", [8, 16, 32, 64]),
        "hyperparams.n_eval_episodes": trial.suggest_categorical("n_eval_episodes", [4, 8, 16]),
        "hyperparams.step_rule": trial.suggest_categorical("step_rule", ["adam", "ars"]),
    }


def _sac_space(trial: Any) -> dict[str, Any]:
    return {
        "env.reward": trial.suggest_categorical("reward", ["a_optimality", "log_error"]),
        "hyperparams.learning_rate": trial.suggest_float("learning_rate", 1e-5, 1e-3, log=True),
        "hyperparams.batch_size": trial.suggest_categorical("batch_size", [256, 512, 1024]),
        "hyperparams.gamma": trial.suggest_categorical("gamma", [0.95, 0.99, 0.999]),
        "hyperparams.tau": trial.suggest_categorical("tau", [0.005, 0.01, 0.02]),
    }


def _recurrent_ppo_space(trial: Any) -> dict[str, Any]:
    return {
        "env.reward": trial.suggest_categorical("reward", ["a_optimality", "log_error"]),
        "hyperparams.learning_rate": trial.suggest_float("learning_rate", 1e-5, 1e-3, log=True),
        "hyperparams.gamma": trial.suggest_categorical("gamma", [0.95, 0.99, 0.999]),
        "hyperparams.n_epochs": trial.suggest_categorical("n_epochs", [5, 10]),
        "hyperparams.policy_kwargs.lstm_hidden_size": trial.suggest_categorical("lstm_hidden_size", [16, 32, 64]),
    }


#: Search space per algorithm: a function of an Optuna trial returning ``{dotted key: value}``
#: overrides (a new algorithm's space is a row here).
SEARCH_SPACES: dict[str, Callable[[Any], dict[str, Any]]] = {
    "ppo": _ppo_space,
    "ars": _ars_space,
    "sac": _sac_space,
    "recurrent_ppo": _recurrent_ppo_space,
}

#: Top-level entries of a configuration that a tuned file may carry (the rest is the system's or
#: the run's own).
TUNED_KEYS = (
    "env",
    "horizon",
    "observation",
    "features",
    "reward_scaling",
    "n_envs",
    "n_timesteps",
    "normalize",
    "policy",
    "hyperparams",
)


def _set(cfg: dict[str, Any], key: str, value: Any) -> None:
    """Apply one dotted override with a Python value (checked like ``--set``)."""
    apply_override(cfg, f"{key}={yaml.safe_dump(value, default_flow_style=True).strip()}")


def objective_ratio(
    run_dir: str | Path, *, episodes: int, seed: int = OBJECTIVE_SEED, which: str = "best"
) -> tuple[float, float]:
    """Paired error ratio of a run's policy to the oracle at the training attack length.

    Returns
    -------
    (float, float)
        ``exp(mean(log eps_policy - log eps_oracle))`` over ``episodes`` seeds and the standard
        error of the mean log ratio.
    """
    from encctl_gym.envs.config import resolve_params

    from .evaluate import rollout
    from .optimal import OptimalDesignAttacker
    from .runs import read_run
    from .sb3 import load_attacker

    run = read_run(run_dir)
    cfg = {**run.env, "gamma_opt": False}
    params = resolve_params(cfg)
    w = which if (run.path / "best_model.zip").exists() else "final"
    att = load_attacker(run.path, which=w, params=params)
    feedback = params.decipher_delay is not None and run.observation != "blind"
    oracle = OptimalDesignAttacker(params, feedback=feedback)
    d = np.log(rollout(att, cfg, episodes=episodes, seed=seed, record=False).final_epsilon) - np.log(
        rollout(oracle, cfg, episodes=episodes, seed=seed, record=False).final_epsilon
    )
    se = float(d.std(ddof=1) / math.sqrt(d.size)) if d.size > 1 else float("nan")
    return float(math.exp(d.mean())), se


def tuned_config(cfg: dict[str, Any]) -> dict[str, Any]:
    """The best trial's configuration as a tuned file (a mapping of :data:`TUNED_KEYS`)."""
    out: dict[str, Any] = {"algo": cfg["algo"]}
    for key in TUNED_KEYS:
        if key in cfg:
            out[key] = copy.deepcopy(cfg[key])
    env = out.get("env", {})
    if cfg.get("system") == env.get("preset"):  # a preset's file: keep its name, drop derived entries
        out["env"] = {k: v for k, v in env.items() if k not in ("A", "B")}
    return out


def _yaml_text(tuned: dict[str, Any], header: list[str]) -> str:
    body = yaml.safe_dump(tuned, sort_keys=False, default_flow_style=None)
    return "".join(f"# {line}\n" for line in header) + body


def tune(
    cfg: dict[str, Any],
    *,
    trials: int,
    out: str | Path = "results/tune",
    storage: str | None = None,
    study_name: str | None = None,
    episodes: int = 100,
    sampler_seed: int = 0,
    prune: bool = True,
    progress: bool = False,
) -> tuple[Any, Path]:
    """Run (or resume) a study of ``trials`` more trials; return the study and the best config file.

    Parameters
    ----------
    cfg : dict
        The base configuration (:func:`agents.config.load_config`).
    trials : int
        Trials to run in this call (a resumed study keeps its earlier ones).
    out : path
        Output directory: ``study.db`` (default storage), ``trials/`` (one run per trial) and
        the best configuration ``{algo}_{system}.yaml``.
    storage : str, optional
        An Optuna storage URL (default ``sqlite:///{out}/study.db``).
    study_name : str, optional
        Default ``{algo}_{system}``.
    episodes : int
        Environment seeds of each trial's objective (:func:`objective_ratio`).
    sampler_seed : int
        Seed of the TPE sampler (trial ``i`` also trains with seed ``cfg["seed"] + i``).
    prune : bool
        Stop trials whose learning curve is worse than the median (Optuna's ``MedianPruner``).

    Raises
    ------
    EncctlError
        Optuna is not installed (the extra ``[optuna]``).
    ConfigError
        An algorithm without a search space, or a drawn configuration the checks reject.
    """
    try:
        import optuna
    except ModuleNotFoundError as exc:
        raise EncctlError("encctl-gym tune needs Optuna; install the extra: pip install 'encctl-gym[optuna]'") from exc
    from .train import train  # before the study exists: a missing [rl] extra fails here

    algo = cfg["algo"]
    if algo not in SEARCH_SPACES:
        raise ConfigError(f"no search space for algorithm {algo!r}; tunable: {', '.join(SEARCH_SPACES)}")
    out = check_output_dir(out, "the tuning directory (--out)")
    name = study_name or f"{algo}_{cfg['system']}"
    url = storage or f"sqlite:///{(out / 'study.db').resolve()}"
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    pruner = optuna.pruners.MedianPruner(n_startup_trials=3, n_warmup_steps=1) if prune else optuna.pruners.NopPruner()
    study = optuna.create_study(
        study_name=name,
        storage=url,
        load_if_exists=True,
        direction="minimize",
        sampler=optuna.samplers.TPESampler(seed=sampler_seed),
        pruner=pruner,
    )
    study.optimize(_objective(optuna, train, cfg, out, episodes=episodes, progress=progress), n_trials=trials, catch=())
    return study, _write_best(optuna, study, cfg, name, out, episodes=episodes)


def _objective(
    optuna: Any, train: Callable[..., Path], cfg: dict[str, Any], out: Path, *, episodes: int, progress: bool
) -> Callable[[Any], float]:
    """The study's objective: ``train`` (:func:`agents.train.train`) the trial's drawn
    configuration (pruned by its learning curve) and return its paired error ratio to the
    oracle (:func:`objective_ratio`)."""
    from .runs import read_run

    algo = cfg["algo"]

    def objective(trial: Any) -> float:
        trial_cfg = copy.deepcopy(cfg)
        for key, value in SEARCH_SPACES[algo](trial).items():
            _set(trial_cfg, key, value)

        def report(curve: Any) -> bool:
            step = len(curve.timesteps) - 1
            trial.report(float(curve.ratio()[0][-1]), step)
            return not trial.should_prune()

        run_dir = train(
            trial_cfg,
            out=out / "trials",
            seed=int(cfg["seed"]) + trial.number,
            progress=progress,
            tensorboard=False,
            name=f"trial_{trial.number:04d}",
            overwrite=True,
            on_evaluation=report,
        )
        trial.set_user_attr("run_dir", str(run_dir))
        trial.set_user_attr("config", {k: trial_cfg[k] for k in TUNED_KEYS if k in trial_cfg})
        if read_run(run_dir).meta.get("status") == "stopped":
            raise optuna.TrialPruned()
        ratio, se = objective_ratio(run_dir, episodes=episodes)
        trial.set_user_attr("ratio_se_log", se)
        return ratio

    return objective


def _write_best(optuna: Any, study: Any, cfg: dict[str, Any], name: str, out: Path, *, episodes: int) -> Path:
    """Write the best completed trial's configuration as ``{out}/{algo}_{system}.yaml`` with a
    header saying how it was found; return its path."""
    algo = cfg["algo"]
    done = [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    if not done:
        raise ConfigError(f"study {name!r} has no completed trial (all pruned or failed)")
    best = study.best_trial
    best_cfg = {**copy.deepcopy(cfg), **best.user_attrs["config"]}
    tuned = tuned_config(best_cfg)
    header = [
        f"Tuned by `encctl-gym tune` (study {name!r}, {len(done)} completed of {len(study.trials)} trials):",
        f"best trial {best.number}: paired error ratio to the oracle {best.value:.4f} at N = "
        f"{cfg.get('horizon') or 'the preset budget'} on {episodes} seeds from {OBJECTIVE_SEED}.",
        f"Merged over agents/configs/defaults/{algo}.yaml (see agents/config.py for every key); n_timesteps is the",
        "trials' training budget.",
    ]
    path = out / f"{algo}_{cfg['system']}.yaml"
    path.write_text(_yaml_text(tuned, header))
    return path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``encctl-gym tune``."""
    parser.add_argument("--algo", required=True, choices=list(ALGORITHMS), help="learning algorithm")
    parser.add_argument("--preset", default=None, help="system preset (default: the config's, else paper-example)")
    parser.add_argument("--system", default=None, metavar="FILE", help="plant file (as train --system)")
    parser.add_argument("--config", default=None, metavar="FILE", help="base config file (as train --config)")
    parser.add_argument("--quick", action="store_true", help="the configs' quick sections (a smoke test)")
    parser.add_argument(
        "--trials", type=int, default=20, help="trials to run now (default 20; a resumed study keeps its earlier ones)"
    )
    parser.add_argument("--n-timesteps", type=int, default=None, help="training steps of every trial")
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a config entry of every trial (as train --set); repeatable",
    )
    parser.add_argument(
        "--episodes", type=int, default=100, help="seeds of each trial's paired ratio to the oracle (default 100)"
    )
    parser.add_argument("--out", default="results/tune", help="output directory (default results/tune)")
    parser.add_argument(
        "--storage",
        default=None,
        metavar="URL",
        help="Optuna storage URL shared by several machines (default: sqlite file OUT/study.db)",
    )
    parser.add_argument("--study-name", default=None, help="study name (default {algo}_{system})")
    parser.add_argument("--seed", type=int, default=0, help="sampler seed; trial i trains with seed + i (default 0)")
    parser.add_argument("--no-prune", action="store_true", help="run every trial to its end")
    parser.add_argument(
        "--save-config",
        action="store_true",
        help="also write the best configuration to agents/configs/{algo}_{preset}.yaml (needs --preset)",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    """Tune; print the best trial and where its configuration went."""
    for flag, value, minimum in (("trials", args.trials, 1), ("episodes", args.episodes, 2)):
        if value < minimum:
            raise ConfigError(f"--{flag} must be >= {minimum}, got {format_value(value)}")
        if value > MAX_STEPS:
            raise ConfigError(f"--{flag} must be <= {MAX_STEPS}, got {format_value(value)}")
    if args.save_config and not args.preset:
        raise ConfigError("--save-config writes agents/configs/{algo}_{preset}.yaml and needs --preset")
    cfg = load_config(args.algo, args.preset, path=args.config, system=args.system, quick=args.quick)
    apply_override(cfg, f"seed={args.seed}")  # checked like any seed (0 <= seed <= MAX_SEED)
    if args.n_timesteps is not None:
        apply_override(cfg, f"n_timesteps={args.n_timesteps}")
    for item in args.overrides:
        apply_override(cfg, item)
    study, path = tune(
        cfg,
        trials=args.trials,
        out=args.out,
        storage=args.storage,
        study_name=args.study_name,
        episodes=args.episodes,
        sampler_seed=args.seed,
        prune=not args.no_prune,
        progress=not args.no_progress,
    )
    best = study.best_trial
    print(
        f"study {study.study_name}: {len(study.trials)} trials; best trial {best.number}: paired error ratio to the oracle "
        f"{best.value:.4f} (run {best.user_attrs['run_dir']})"
    )
    for k, v in best.params.items():
        print(f"  {k} = {v}")
    print(f"best configuration: {path}")
    if args.save_config:
        target = CONFIG_DIR / f"{args.algo}_{args.preset}.yaml"
        target.write_text(path.read_text())
        print(f"saved as {target}")
    return 0
