"""The attackers of a comparison, chosen by name from one registry, and the learned ones.

:data:`ATTACKERS` maps a name to a factory of the attacker for a :class:`Setting` (the
baselines of :mod:`agents.baselines` and the optimal-design oracle of :mod:`agents.optimal`);
``compare`` plays all of them, ``evaluate`` the ones it names, and a new baseline is one row.
Learned attackers come from training runs (:mod:`agents.runs`): a run plays in a setting of its
own system, in the environment it was trained in (rebuilt from its ``run.json``), a policy that
reads states only where states are delivered (an integer delay), a ``blind`` policy in every
setting (:func:`run_setting`).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from encctl_gym._validation import format_value
from encctl_gym.agents import Attacker, ColoredGaussianAttacker, GaussianAttacker, OptimalDesignAttacker, PRBSAttacker
from encctl_gym.agents.evaluate import budget_config
from encctl_gym.agents.runs import RUN_FILE, RunInfo
from encctl_gym.agents.stealth import AdditiveAttacker, SparseAttacker
from encctl_gym.envs.config import AttackParams, resolve_params
from encctl_gym.errors import ConfigError, EncctlError
from encctl_gym.registry import Registry

from .settings import Setting

__all__ = [
    "ATTACKERS",
    "DEFAULT_ATTACKERS",
    "make_attackers",
    "system_config",
    "run_setting",
    "run_applies",
    "left_out",
    "learned_players",
]

#: Baseline and oracle attackers by name -> factory for a setting.
ATTACKERS: Registry[Callable[[Setting], Attacker]] = Registry(
    "attacker",
    {
        "gaussian": lambda s: GaussianAttacker(s.params),
        "prbs": lambda s: PRBSAttacker(s.params),
        "colored": lambda s: ColoredGaussianAttacker(s.params, rho=0.5),
        "optimal": lambda s: OptimalDesignAttacker(s.params, design=s.design, feedback=s.params.decipher_delay is not None),
        # the stealthy attackers of agents.stealth (replaying Phi x under the settings' replace
        # injection; they read delivered states, so they play at integer delays only)
        "additive": lambda s: AdditiveAttacker(s.params),
        "sparse": lambda s: SparseAttacker(s.params),
    },
    error=ConfigError,
)
#: The attackers ``compare`` plays when none are named (every setting, ``"end"`` included).
DEFAULT_ATTACKERS: tuple[str, ...] = ("gaussian", "prbs", "colored", "optimal")


def make_attackers(setting: Setting, names: Sequence[str]) -> list[Attacker]:
    """The registered attackers ``names`` (keys of :data:`ATTACKERS`) built for ``setting``."""
    factories = [ATTACKERS.lookup(n) for n in names]  # every name is checked before any is built
    return [make(setting) for make in factories]


#: Environment keys that define the system and its budget (not carried to another system).
SYSTEM_KEYS = frozenset({"preset", "A", "B", "sigma_w2", "sigma_x2", "sigma_u2", "upsilon", "gamma_c"})
#: Keys that set the attack length or the backend of the training episodes (dropped: an
#: evaluation sets its own length).
LENGTH_KEYS = frozenset({"tau_c", "max_samples", "security_parameter", "key_length", "crypto", "crypto_seed", "gamma_opt"})
#: Of those, the ones that define the system's own key and defense period when the training
#: configuration gave them (``config.env`` of ``run.json``, before ``horizon`` shortened tau_c).
_OWN_KEYS = ("tau_c", "security_parameter", "key_length")
#: What must agree between the environment a run was trained in and a setting it plays in: the
#: system, its key and budget, and how the error is measured.
_SAME_SYSTEM = (
    "sigma_w2",
    "sigma_x2",
    "sigma_u2",
    "upsilon",
    "tau_c",
    "gamma_c",
    "security_parameter",
    "key_length",
    "deciphering_model",
    "scheme",
    "adversary",
    "estimator",
    "warmup_steps",
)


def system_config(run: RunInfo, system: str | None = None, config: dict[str, Any] | None = None) -> dict[str, Any]:
    """The environment configuration a run plays in, rebuilt from its ``run.json``.

    On its own system (``system`` None or the run's label) this is the training environment
    (observation layout, reward, encoder, estimator, every value it was trained with) with the
    system's own defense period and key (before the training's ``horizon`` shortened it). On
    another system (a preset name, or a label with its environment ``config``) the run's
    settings other than the system's are carried over.
    """
    rest = {k: v for k, v in run.env.items() if k not in LENGTH_KEYS}
    if system is None or system == run.system:
        own = (run.meta.get("config") or {}).get("env") or {}
        rest.update({k: own[k] for k in _OWN_KEYS if own.get(k) is not None})
        return rest
    other = dict(config) if config is not None else {"preset": system}
    return {**{k: v for k, v in rest.items() if k not in SYSTEM_KEYS}, **other}


def _mismatch(run: RunInfo, base: AttackParams, params: AttackParams, setting: Setting) -> str | None:
    """How the run's environment differs from the setting's system, or None."""
    if base.A.shape != setting.base.A.shape or base.B.shape != setting.base.B.shape:
        return f"its plant has A {base.A.shape}, B {base.B.shape}; {setting.system}'s has A {setting.base.A.shape}, B {setting.base.B.shape}"
    if not (np.array_equal(base.A, setting.base.A) and np.array_equal(base.B, setting.base.B)):
        return f"its plant matrices A, B are not {setting.system}'s"
    for key in _SAME_SYSTEM:
        mine, theirs = getattr(base, key), getattr(setting.base, key)
        if mine != theirs:
            return f"it was trained with {key} = {format_value(mine)}, {setting.system} has {format_value(theirs)}"
    if params.horizon != setting.params.horizon:  # pragma: no cover - the same system and budget give the same length
        return f"its attack length would be N = {params.horizon}, the setting's is {setting.params.horizon}"
    return None


def run_setting(run: RunInfo, setting: Setting) -> Setting | str:
    """The setting in which a training run plays ``setting``, or the reason it does not.

    The run plays in the environment it was trained in (:func:`system_config`: its observation
    layout, such as ``input_history``, its reward, encoder and estimator) at the setting's
    decipher delay and attack length; the system, its budget and the measurement must be the
    setting's (the same A and B, variances, key, defense period, Upsilon, gamma_c and estimator),
    and a policy that reads states plays only where states are delivered (an integer delay).

    Returns
    -------
    Setting or str
        ``setting`` with the run's environment, or a sentence saying why the run does not play.
    """
    if run.system != setting.system:
        return f"it was trained on {run.system!r}, not {setting.system!r}"
    if run.observation != "blind" and setting.params.decipher_delay is None:
        return f"its {run.observation!r} policy reads delivered states, which decipher_delay 'end' does not deliver"
    cfg = {**system_config(run), "decipher_delay": setting.delay, "gamma_opt": False}
    try:
        base = resolve_params(cfg)
        if setting.capped:  # the setting's length, through the same budget rule
            cfg = budget_config(cfg, int(setting.params.horizon))
        params = resolve_params(cfg)
    except EncctlError as exc:
        raise ConfigError(f"the environment of the run {run.path} ({RUN_FILE}) cannot be rebuilt: {exc}") from None
    why = _mismatch(run, base, params, setting)
    return why if why is not None else replace(setting, config=cfg, params=params, base=base)


def run_applies(run: RunInfo, setting: Setting) -> bool:
    """Whether a training run plays in ``setting`` (:func:`run_setting`)."""
    return isinstance(run_setting(run, setting), Setting)


def left_out(runs: Sequence[RunInfo], settings: Sequence[Setting]) -> list[tuple[RunInfo, str]]:
    """The runs that play in none of ``settings``, each with the reason (:func:`run_setting`;
    the distinct reasons over the settings, joined)."""
    out = []
    for run in runs:
        reasons = [run_setting(run, s) for s in settings]
        if reasons and all(isinstance(r, str) for r in reasons):
            out.append((run, "; ".join(dict.fromkeys(str(r) for r in reasons))))
    return out


def learned_players(
    setting: Setting, runs: Sequence[RunInfo], which: str = "best", *, deterministic: bool = False
) -> list[tuple[Attacker, Setting]]:
    """The learned attackers of the runs that play in ``setting``, each with the setting it plays
    in: ``setting`` in the environment the run was trained in (:func:`run_setting`).

    Each is named by its algorithm (``-blind`` for a blind policy); when two runs would share a
    name, each is named by its run directory. ``which="best"`` falls back to the final model
    for a run without ``best_model.zip``.
    """
    chosen = [(r, s) for r in runs for s in [run_setting(r, setting)] if isinstance(s, Setting)]
    if not chosen:
        return []
    try:
        from encctl_gym.agents.sb3 import load_attacker
    except ModuleNotFoundError as exc:
        raise EncctlError(
            f"learned attackers need stable-baselines3 (module {exc.name!r} is missing); "
            "install the extra: pip install 'encctl-gym[rl]'"
        ) from exc
    names = [r.algo + ("-blind" if r.observation == "blind" else "") for r, _ in chosen]
    count = Counter(names)
    out: list[tuple[Attacker, Setting]] = []
    for (run, play), name in zip(chosen, names):
        label = name if count[name] == 1 else f"{name} ({run.path.name})"
        w = which if which == "final" or (run.path / "best_model.zip").exists() else "final"
        out.append((load_attacker(run.path, which=w, params=play.params, name=label, deterministic=deterministic), play))
    return out
