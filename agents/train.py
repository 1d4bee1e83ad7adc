"""Train a learned attacker with stable-baselines3 (the ``train`` subcommand).

A run is configured by one mapping (:mod:`agents.config`): the default of its algorithm
(``agents/configs/defaults/{algo}.yaml``), a system's tuned file when one exists
(``agents/configs/{algo}_{preset}.yaml``) or ``--config FILE``, the system (``--preset NAME``
or a plant file ``--system FILE``), a ``quick:`` section for smoke tests (``--quick``) and
``--set key.sub=value`` overrides, every entry checked before anything is built. Training steps
the native vector environment through :class:`agents.sb3.SB3VecEnv` on the fast ideal backend.

A run directory (:mod:`agents.runs`) holds ``model.zip`` (final), ``best_model.zip`` (best
evaluation), ``vecnormalize.npz`` (when observations are normalised), ``learning_curve.npz``
and ``learning_curve.png`` (evaluation ``E[epsilon] / gamma_opt(N)`` against training steps,
:mod:`agents.curves`), ``evaluations.npz``, TensorBoard logs under ``tb/`` and ``run.json``
(configuration, timing, and the final evaluation: the learned policy against the Gaussian
attacker on the same seeds on the ideal backend, and a few episodes through real ElGamal
ciphertexts). A run never replaces an earlier one silently: an existing name gets a numbered
sibling (``...-2``) unless ``--overwrite`` is given. Load a run with
:func:`agents.sb3.load_attacker`; compare it with ``encctl-gym evaluate RUN_DIR``.

Example::

    encctl-gym train --algo ppo --preset paper-example --seed 0
    encctl-gym train --algo sac --preset fig1-c --quick --out /tmp/runs
    encctl-gym train --algo ppo --system plant.json --set env.sigma_w2=0.5
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym._validation import format_count, format_value
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ConfigError
from encctl_gym.resources import check_memory

from .config import CONFIG_DIR, apply_override, env_config, load_config, run_name, validate_config
from .curves import CURVE_FILE, curve_for, plot_learning_curves
from .hyperparams import make_schedules, network_bytes, policy_kwargs
from .runs import RUN_FILE, new_run_dir, read_run
from .sb3 import ALGORITHMS, VECNORMALIZE_FILE, SB3VecEnv, algorithm_class, load_attacker, save_vecnormalize

__all__ = ["CONFIG_DIR", "load_config", "apply_override", "train", "final_evaluation", "add_arguments", "run"]


def _make_env(cfg: dict[str, Any], env_cfg: dict[str, Any], num_envs: int, reward_scaling: str) -> Any:
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    venv: Any = VecMonitor(SB3VecEnv(env_cfg, num_envs, cfg["observation"], reward_scaling, features=cfg.get("features") or ()))
    norm = cfg.get("normalize") or {}
    if norm.get("norm_obs") or norm.get("norm_reward"):
        venv = VecNormalize(
            venv,
            norm_obs=bool(norm.get("norm_obs", True)),
            norm_reward=bool(norm.get("norm_reward", False)),
            gamma=float(cfg["hyperparams"].get("gamma", 0.99)),
        )
    return venv


def _write_meta(run_dir: Path, meta: dict[str, Any]) -> None:
    (run_dir / RUN_FILE).write_text(json.dumps(meta, indent=2, default=str))


def train(
    cfg: dict[str, Any],
    *,
    out: str | Path = "results/train",
    seed: int | None = None,
    progress: bool = True,
    tensorboard: bool = True,
    verbose: int = 0,
    name: str | None = None,
    overwrite: bool = False,
    on_evaluation: Callable[[Any], bool] | None = None,
) -> Path:
    """Train one attacker as configured; return the run directory (model saved, run.json written).

    Parameters
    ----------
    cfg : dict
        From :func:`agents.config.load_config` (checked again here).
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
        Run directory name (default :func:`agents.config.run_name`).
    overwrite : bool
        Replace an earlier run of the same name; otherwise a new ``{name}-{i}`` directory is used
        (:func:`agents.runs.new_run_dir`).
    on_evaluation : callable, optional
        Called with the :class:`agents.curves.LearningCurve` after every evaluation; returning
        False stops training there (the tuner's pruning). The run is then recorded with
        ``status: "stopped"``.

    Raises
    ------
    ConfigError
        A configuration entry rejected by the checks or by the algorithm's constructor, or
        networks PyTorch cannot allocate.
    ResourceLimitError
        Policy networks estimated above :data:`encctl_gym.resources.MEMORY_LIMIT`
        (:func:`agents.hyperparams.network_bytes`), refused before they are built.
    """
    import torch
    from stable_baselines3.common.callbacks import CallbackList

    cfg = copy.deepcopy(cfg)
    if seed is not None:
        cfg["seed"] = seed
    validate_config(cfg)
    seed = int(cfg["seed"])
    algo_cls = algorithm_class(cfg["algo"])
    hp = make_schedules(cfg["hyperparams"])
    hp["policy_kwargs"] = policy_kwargs(algo_cls, cfg["policy"], hp.get("policy_kwargs"))
    torch.set_num_threads(1)
    env_cfg = env_config(cfg)
    params = resolve_params(env_cfg)
    env = _make_env(cfg, env_cfg, int(cfg["n_envs"]), cfg["reward_scaling"])
    ev = cfg["eval"]
    n_eval = int(ev["episodes"])
    eval_env = _make_eval_env(cfg, env_cfg, n_eval)
    model = _build_model(cfg, algo_cls, hp, env, seed, verbose)
    run_dir = new_run_dir(out, name or run_name(cfg, seed), overwrite=overwrite)
    model.tensorboard_log = str(run_dir / "tb") if tensorboard else None
    meta = _initial_meta(cfg, env_cfg, seed)
    _write_meta(run_dir, meta)
    curve = curve_for(params, cfg["observation"], algo=cfg["algo"], system=cfg["system"], seed=seed)
    total, budget = training_budget(cfg, curve)
    meta["n_timesteps"] = total
    meta["budget"] = budget
    stopper = _oracle_stopper(cfg, params, env_cfg, n_eval, int(ev["seed"]), log=print if progress else None)
    callbacks = _callbacks(cfg, eval_env, curve, run_dir, verbose=verbose, on_evaluation=_both(stopper, on_evaluation))
    if progress:
        callbacks.append(_progress_bar(total, budget, run_dir.name, stopper))
    t0 = time.perf_counter()
    model.learn(total_timesteps=total, callback=CallbackList(callbacks), tb_log_name="run")
    seconds = time.perf_counter() - t0
    _save_model(model, env, curve, run_dir)
    stopped = int(model.num_timesteps) < total
    meta.update(
        status="stopped" if stopped else "finished",
        timesteps_done=int(model.num_timesteps),
        train_seconds=round(seconds, 1),
        steps_per_second=round(model.num_timesteps / seconds, 1),
        torch_threads=torch.get_num_threads(),
        learning_curve=_curve_summary(curve),
    )
    if stopper is not None:
        meta["stopping"] = _stopping_summary(cfg, stopper)
    _write_meta(run_dir, meta)
    env.close()
    return run_dir


def _progress_bar(total: int, budget: dict[str, Any], label: str, stopper: Any) -> Any:
    """The training's progress bar; with a stopping rule, first one line saying that the bar
    counts to the budget, a ceiling the rule may stop before."""
    from .callbacks import ProgressCallback

    if stopper is not None:
        print(
            f"{budget.get('text', f'budget {total} steps')}; the bar counts to it, and the stopping rule (oracle) may stop before "
            "(its state follows the bar's counts)",
            flush=True,
        )
    return ProgressCallback(total, label, status=None if stopper is None else stopper.status)


def _make_eval_env(cfg: dict[str, Any], env_cfg: dict[str, Any], n_eval: int) -> Any:
    """The evaluation copies: unscaled rewards (the true ``log eps_0 - log eps_N``) and, when
    observations are normalised, statistics frozen."""
    eval_env = _make_env(cfg, env_cfg, n_eval, "none")
    if hasattr(eval_env, "training"):
        eval_env.training = False
        eval_env.norm_reward = False
    return eval_env


def _save_model(model: Any, env: Any, curve: Any, run_dir: Path) -> None:
    """Write ``model.zip``, ``vecnormalize.npz`` (when observations are normalised) and the
    learning-curve figure (when there was an evaluation)."""
    model.save(str(run_dir / "model.zip"))
    if hasattr(env, "obs_rms"):
        save_vecnormalize(env, run_dir / VECNORMALIZE_FILE)
    if len(curve.timesteps):
        plot_learning_curves([curve], run_dir / "learning_curve.png", title=f"{run_dir.name}: evaluation error over the optimum")


def _initial_meta(cfg: dict[str, Any], env_cfg: dict[str, Any], seed: int) -> dict[str, Any]:
    """The ``run.json`` written before training starts (``status: "training"``)."""
    return {
        "status": "training",
        "algo": cfg["algo"],
        "observation": cfg["observation"],
        "system": cfg["system"],
        "env": env_cfg,
        "seed": seed,
        "n_timesteps": int(cfg["n_timesteps"]),
        "n_envs": int(cfg["n_envs"]),
        "config": cfg,
    }


def _build_model(cfg: dict[str, Any], algo_cls: Any, hp: dict[str, Any], env: Any, seed: int, verbose: int) -> Any:
    """The algorithm's model on ``env`` with the hyperparameters ``hp``: policy networks checked
    against the memory limit first, the algorithm's and PyTorch's refusals turned into
    :class:`ConfigError`."""
    n_in = int(np.prod(env.observation_space.shape))
    n_out = int(np.prod(env.action_space.shape))
    net_arch = (cfg["hyperparams"].get("policy_kwargs") or {}).get("net_arch")
    check_memory(
        f"training the policy networks of net_arch = {format_value(net_arch)} ({n_in} inputs, {n_out} outputs)",
        network_bytes(net_arch, n_in, n_out),
        advice="use smaller layers (hyperparams.policy_kwargs.net_arch)",
    )
    try:
        return algo_cls(cfg["policy"], env, seed=seed, verbose=verbose, device="cpu", **hp)
    except (AssertionError, ValueError, TypeError) as exc:  # stable-baselines3's own checks of the values
        raise ConfigError(f"{cfg['algo']} rejected the hyperparameters {format_value(cfg['hyperparams'])}: {exc}") from exc
    except (RuntimeError, MemoryError) as exc:  # PyTorch could not allocate the networks
        first = str(exc).strip().splitlines()
        raise ConfigError(
            f"{cfg['algo']} could not build its model with the hyperparameters {format_value(cfg['hyperparams'])}: "
            f"{type(exc).__name__}: {format_value(first[0] if first else '')}"
        ) from None


def _callbacks(
    cfg: dict[str, Any], eval_env: Any, curve: Any, run_dir: Path, *, verbose: int, on_evaluation: Callable[[Any], bool] | None
) -> list[Any]:
    """The training callbacks: attack metrics, and the learning curve's periodic evaluation."""
    from .callbacks import AttackMetricsCallback, LearningCurveCallback

    ev = cfg["eval"]
    n_eval = int(ev["episodes"])
    return [
        AttackMetricsCallback(),
        LearningCurveCallback(
            eval_env,
            curve=curve,
            curve_path=run_dir / CURVE_FILE,
            eval_seed=int(ev["seed"]),
            n_eval_episodes=n_eval,
            eval_freq=max(int(ev["freq"]) // int(cfg["n_envs"]), 1),
            log_path=str(run_dir),
            best_model_save_path=str(run_dir),
            deterministic=False,
            verbose=verbose,
            on_evaluation=on_evaluation,
        ),
    ]


def _curve_summary(curve: Any) -> dict[str, Any]:
    """The ``learning_curve`` entry of ``run.json``."""
    return {
        "N": curve.N,
        "gamma": curve.gamma,
        "gamma_gauss": curve.gamma_gauss,
        "gamma_opt": curve.gamma_opt,
        "design": curve.design_kind,
        "evaluations": int(len(curve.timesteps)),
        "last_ratio_to_gamma_opt": float(curve.ratio()[0][-1]) if len(curve.timesteps) else None,
    }


def _stopping_summary(cfg: dict[str, Any], stopper: Any) -> dict[str, Any]:
    """The ``stopping`` entry of ``run.json``: the rule, the oracle and every decision."""
    final = stopper.final()
    return {
        "rule": dict(cfg["stopping"]),
        "oracle": stopper.oracle_name,
        "oracle_mean_epsilon": float(np.mean(stopper.oracle_epsilon)),
        "decision": final.as_dict() if final is not None else None,
        "curve": [
            {"timestep": d.timestep, "ratio": d.ratio, "low": d.low, "high": d.high, "reason": d.reason}
            for d in stopper.decisions
        ],
    }


def steps_per_iteration(cfg: dict[str, Any], horizon: int) -> int:
    """Environment steps of one update of the algorithm: ARS plays ``2 n_delta + 1`` policies on
    ``n_eval_episodes`` episodes of ``horizon`` steps (:class:`agents.ars.PairedARS`); an
    on-policy algorithm collects ``n_steps`` per copy; any other steps once per copy."""
    hp = cfg["hyperparams"]
    if cfg["algo"] == "ars":
        return (2 * int(hp.get("n_delta", 8)) + 1) * int(hp.get("n_eval_episodes", 1)) * int(horizon)
    return int(hp.get("n_steps", 1)) * int(cfg["n_envs"])


def training_budget(cfg: dict[str, Any], curve: Any) -> tuple[int, dict[str, Any]]:
    """The run's budget in environment steps and how it was set (``stopping.budget``).

    ``fixed``: ``n_timesteps``. ``plant``: :func:`agents.stopping.plant_budget` of the curve's
    references ``gamma_gauss(N) / gamma_opt(N)``, :func:`steps_per_iteration` and
    ``stopping.iterations_per_gain``, at most ``n_timesteps``.
    """
    from .stopping import plant_budget

    cap = int(cfg["n_timesteps"])
    st = cfg["stopping"]
    if st["budget"] != "plant":
        return cap, {"how": "fixed", "n_timesteps": cap}
    per = steps_per_iteration(cfg, curve.N)
    total = plant_budget(
        curve.gamma_gauss, curve.gamma_opt, iterations_per_gain=float(st["iterations_per_gain"]), steps_per_iteration=per, cap=cap
    )
    gain = math.log(curve.gamma_gauss / curve.gamma_opt)
    ipg = float(st["iterations_per_gain"])
    if gain > 0:
        text = f"budget scaled to the plant: {ipg:g} / log(gamma_gauss / gamma_opt) = {ipg:g} / {gain:.4f} = " + (
            f"{math.ceil(ipg / gain)} iterations of {per} steps"
            + (f": at the ceiling n_timesteps = {cap}" if total == cap else f" = {total} steps (ceiling {cap})")
        )
    else:
        text = f"budget scaled to the plant: the optimal design gains nothing over the Gaussian attack; the ceiling {cap}"
    return total, {
        "how": "plant",
        "n_timesteps": total,
        "ceiling": cap,
        "steps_per_iteration": per,
        "log_gain_over_gaussian": gain,
        "iterations_per_gain": float(st["iterations_per_gain"]),
        "text": text,
    }


def _oracle_stopper(cfg: dict[str, Any], params: Any, env_cfg: dict[str, Any], episodes: int, seed: int, *, log: Any) -> Any:
    """The :class:`agents.stopping.OracleStopper` of ``stopping.rule = oracle`` (None for ``none``):
    the oracle of the policy's class played once on the evaluation seeds."""
    from .curves import reference_designs
    from .evaluate import rollout
    from .optimal import OptimalDesignAttacker
    from .stopping import OracleStopper, StoppingRule

    st = cfg["stopping"]
    if st["rule"] == "none":
        return None
    if episodes < 2:
        raise ConfigError(f"stopping.rule = oracle needs eval.episodes >= 2 (paired ratios), got {episodes}")
    rule = StoppingRule(
        tolerance=float(st["tolerance"]),
        window=int(st["window"]),
        plateau_gain=float(st["plateau_gain"]),
        min_evaluations=int(st["min_evaluations"]),
    )
    design, _ = reference_designs(params, cfg["observation"])
    oracle = OptimalDesignAttacker(params, design=design, feedback=design.kind == "closed_loop")
    finals = rollout(oracle, env_cfg, episodes=episodes, seed=seed, record=False).final_epsilon
    return OracleStopper(rule, finals, log=log, oracle_name=oracle.name)


def _both(first: Any, second: Any) -> Callable[[Any], bool] | None:
    """One ``on_evaluation`` hook calling both (either may be None); False if either says stop."""
    hooks = [h for h in (first, second) if h is not None]
    if not hooks:
        return None

    def hook(curve: Any) -> bool:
        return all([h(curve) is not False for h in hooks])  # a list: every hook sees every evaluation

    return hook


# --------------------------------------------------------------------------- final evaluation
def final_evaluation(run_dir: str | Path, *, seed: int = 10_000) -> dict[str, Any]:
    """Evaluate a finished run and record the result in its ``run.json``.

    The final and the best model each play ``eval.final_episodes`` episodes on the ideal backend
    (at the training episode length, or ``eval.final_horizon``) against the Gaussian attacker
    on the same environment seeds; then the final model plays ``eval.elgamal.episodes`` short
    episodes through real ElGamal ciphertexts (a small key). For the full comparison with
    confidence intervals use ``encctl-gym evaluate``.

    Returns
    -------
    dict
        The ``final_evaluation`` entry written to ``run.json``.
    """
    from .baselines import GaussianAttacker
    from .evaluate import budget_config, elgamal_config, rollout

    run = read_run(run_dir)
    meta = run.meta
    ev = meta["config"]["eval"]
    env_cfg = dict(run.env)
    if ev.get("final_horizon"):
        env_cfg = budget_config(env_cfg, int(ev["final_horizon"]))
    params = resolve_params(env_cfg)
    episodes = int(ev["final_episodes"])
    out: dict[str, Any] = {"episodes": episodes, "seed": seed, "N": params.horizon, "env": env_cfg}
    gauss = rollout(GaussianAttacker(params), env_cfg, episodes=episodes, seed=seed, record=False)
    out["gaussian"] = _summary(gauss)
    out["gaussian_design_rate"] = _gauss_rate(params)
    for which in ("final", "best"):
        if not (run.path / ("model.zip" if which == "final" else "best_model.zip")).exists():
            continue
        att = load_attacker(run.path, which=which, params=params)
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
        el_cfg = elgamal_config(run.env, int(el["max_samples"]), key_length=int(el["key_length"]), crypto_seed=seed)
        el_params = resolve_params(el_cfg)
        att = load_attacker(run.path, which="final", params=el_params)
        r = rollout(att, el_cfg, episodes=int(el["episodes"]), seed=seed, record=False)
        out["elgamal"] = {
            **_summary(r),
            "key_length": el_params.key_length,
            "N": el_params.horizon,
            "seconds_per_step": r.seconds / (r.episodes * max(el_params.horizon - 1, 1)),
        }
    meta["final_evaluation"] = out
    _write_meta(run.path, meta)
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
def system_summary(cfg: dict[str, Any], plant: str | Path) -> str:
    """The line ``train --system FILE`` prints: the plant's values and the system's own defense
    period ``tau_c``, then the training attack length and the shortened defense period that sets
    it (``horizon``, :func:`agents.evaluate.budget_config`), which is not the system's."""
    p = resolve_params({**cfg["env"], "gamma_opt": False})
    text = (
        f"plant A ({p.n} x {p.n}), B ({p.n} x {p.m}) from {plant}; sigma_w2 = {p.sigma_w2:g}, sigma_u2 = {p.sigma_u2:g}, "
        f"sigma_x2 = {p.sigma_x2:g}, gamma_c = {p.gamma_c:g}, defense period tau_c = {p.tau_c:g} s, Upsilon = {p.upsilon:g} "
        f"(the values the file does not give are preset {cfg['env'].get('preset')}'s unless set with --set env.KEY=VALUE)"
    )
    t = resolve_params(env_config(cfg))
    if t.horizon != p.horizon:
        text += (
            f"; training attacks of N = {t.horizon} samples (horizon), through a defense period shortened to "
            f"{t.tau_c:g} s at lambda = {t.security_parameter:g} (the system's tau_c allows N = {p.horizon})"
        )
    return text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``encctl-gym train``."""
    parser.add_argument("--algo", required=True, choices=list(ALGORITHMS), help="learning algorithm")
    parser.add_argument(
        "--preset",
        default=None,
        help="system preset (default: the config's, else paper-example); its tuned config "
        "agents/configs/{algo}_{preset}.yaml is merged over the algorithm's default when it exists",
    )
    parser.add_argument(
        "--system",
        default=None,
        metavar="FILE",
        help="plant file (JSON/YAML {A: ..., B: ...} or NPZ, as `design` reads) replacing the preset's A and B; "
        "the values the file does not give (noise variances, gamma_c, tau_c, Upsilon) come from the config's env.preset "
        "(default paper-example; env.preset=null: the file must give them), as for the environment's "
        "config={'A': A, 'B': B}; --set env.KEY=VALUE overrides any",
    )
    parser.add_argument(
        "--config",
        default=None,
        metavar="FILE",
        help="config file merged over the algorithm's default (instead of the preset's tuned file)",
    )
    parser.add_argument("--quick", action="store_true", help="smoke test: the configs' quick sections (a few thousand steps)")
    parser.add_argument("--seed", type=int, default=None, help="seed (default: the config's)")
    parser.add_argument("--n-timesteps", type=int, default=None, help="override the training budget (environment steps)")
    parser.add_argument("--n-envs", type=int, default=None, help="override the number of parallel copies")
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a config entry: dotted keys, YAML values (e.g. env.max_samples=512, "
        "hyperparams.gamma=0.99); checked like the files; repeatable",
    )
    parser.add_argument("--out", default="results/train", help="parent directory of the run (default results/train)")
    parser.add_argument("--name", default=None, help="run directory name (default {algo}_{system}_d{delay}_{obs}_s{seed})")
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace an earlier run of the same name (default: a new directory NAME-2, NAME-3, ...)",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--no-tensorboard", action="store_true", help="no TensorBoard logs")
    parser.add_argument("--no-final-eval", action="store_true", help="skip the final evaluation (ideal and ElGamal)")
    parser.add_argument("--verbose", type=int, default=0, choices=(0, 1, 2), help="stable-baselines3 verbosity (0, 1, 2)")


def run(args: argparse.Namespace) -> int:
    """Train, save, evaluate; print a one-paragraph summary."""
    cfg = load_config(args.algo, args.preset, path=args.config, system=args.system, quick=args.quick)
    if args.n_timesteps is not None:  # an explicit budget is used as given (the stopping rule still applies)
        apply_override(cfg, f"n_timesteps={args.n_timesteps}")
        apply_override(cfg, "stopping.budget=fixed")
    if args.n_envs is not None:
        apply_override(cfg, f"n_envs={args.n_envs}")
    for item in args.overrides:
        apply_override(cfg, item)
    if args.system is not None:
        print(system_summary(cfg, args.system))
    run_dir = train(
        cfg,
        out=args.out,
        seed=args.seed,
        progress=not args.no_progress,
        tensorboard=not args.no_tensorboard,
        verbose=args.verbose,
        name=args.name,
        overwrite=args.overwrite,
    )
    meta = read_run(run_dir).meta
    print(
        f"trained {cfg['algo']} for {meta['timesteps_done']} steps in {meta['train_seconds']} s "
        f"({meta['steps_per_second']} steps/s); saved to {run_dir}"
    )
    if meta.get("budget", {}).get("how") == "plant":
        print(meta["budget"]["text"])
    stop = (meta.get("stopping") or {}).get("decision")
    if stop is not None:
        print(f"stopping rule ({cfg['stopping']['rule']}): {stop['reason']}: {stop['message']}")
    lc = meta["learning_curve"]
    if lc["last_ratio_to_gamma_opt"] is not None:
        print(
            f"learning curve ({lc['evaluations']} evaluations, N = {lc['N']}): last E[eps] / gamma_opt(N) = "
            f"{lc['last_ratio_to_gamma_opt']:.3f} (Gaussian attack {lc['gamma_gauss'] / lc['gamma_opt']:.3f}, "
            f"paper's gamma {lc['gamma'] / lc['gamma_opt']:.3f}); "
            f"{run_dir / 'learning_curve.png'}"
        )
    if not args.no_final_eval:
        ev = final_evaluation(run_dir)
        g = ev["gaussian"]
        print(
            f"evaluation ({format_count(ev['episodes'], 'episode')}, N = {ev['N']}): gaussian mean epsilon {g['mean_epsilon']:.4g} "
            f"(power {g['mean_average_power']:.3g})"
        )
        for which in ("final", "best"):
            if which in ev:
                s = ev[which]
                print(
                    f"  {which:5s} model: mean epsilon {s['mean_epsilon']:.4g} +- {s['se_epsilon']:.2g}, "
                    f"ratio to gaussian {s['ratio_to_gaussian']:.3f} (paired log ratio {s['mean_log_ratio']:+.3f} "
                    f"+- {s['se_log_ratio']:.3f}), power {s['mean_average_power']:.3g}"
                )
        el = ev.get("elgamal")
        if el:
            print(
                f"  elgamal ({format_count(el['episodes'], 'episode')}, N = {el['N']}, {el['key_length']}-bit key): mean epsilon "
                f"{el['mean_epsilon']:.4g}, {1000 * el['seconds_per_step']:.1f} ms/step"
            )
    return 0
