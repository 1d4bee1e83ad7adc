"""The attackers of a comparison, chosen by name from one registry, and the learned ones.

:data:`ATTACKERS` maps a name to a factory of the attacker for a :class:`Setting` (the
baselines of :mod:`agents.baselines` and the optimal-design oracle of :mod:`agents.optimal`);
``compare`` plays all of them, ``evaluate`` the ones it names, and a new baseline is one row.
Learned attackers come from training runs (:mod:`agents.runs`): a run plays in a setting of its
own system, a policy that reads states only where states are delivered (an integer delay),
a ``blind`` policy in every setting.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Sequence

import numpy as np

from agents import Attacker, ColoredGaussianAttacker, GaussianAttacker, OptimalDesignAttacker, PRBSAttacker
from agents.runs import RunInfo
from encctl_gym.errors import ConfigError, EncctlError
from encctl_gym.registry import Registry

from .settings import Setting

__all__ = ["ATTACKERS", "make_attackers", "run_applies", "learned_attackers"]

#: Baseline and oracle attackers by name -> factory for a setting.
ATTACKERS: Registry[Callable[[Setting], Attacker]] = Registry(
    "attacker",
    {
        "gaussian": lambda s: GaussianAttacker(s.params),
        "prbs": lambda s: PRBSAttacker(s.params),
        "colored": lambda s: ColoredGaussianAttacker(s.params, rho=0.5),
        "optimal": lambda s: OptimalDesignAttacker(s.params, design=s.design, feedback=s.params.decipher_delay is not None),
    },
    error=ConfigError,
)


def make_attackers(setting: Setting, names: Sequence[str]) -> list[Attacker]:
    """The registered attackers ``names`` (keys of :data:`ATTACKERS`) built for ``setting``."""
    factories = [ATTACKERS.lookup(n) for n in names]  # every name is checked before any is built
    return [make(setting) for make in factories]


def run_applies(run: RunInfo, setting: Setting) -> bool:
    """Whether a training run plays in ``setting``: same system (and, for a plant given by its
    matrices, the same A and B), and states delivered if the policy reads them."""
    if run.system != setting.system:
        return False
    if run.custom_plant:
        A, B = np.asarray(run.env.get("A"), dtype=float), np.asarray(run.env.get("B"), dtype=float)
        if A.shape != setting.params.A.shape or B.shape != setting.params.B.shape:
            return False
        if not (np.array_equal(A, setting.params.A) and np.array_equal(B, setting.params.B)):
            return False
    return run.observation == "blind" or setting.params.decipher_delay is not None


def learned_attackers(setting: Setting, runs: Sequence[RunInfo], which: str = "best", *, deterministic: bool = False) -> list[Attacker]:
    """The learned attackers of the runs that apply to ``setting`` (:func:`run_applies`).

    Each is named by its algorithm (``-blind`` for a blind policy); when two runs would share a
    name, each is named by its run directory. ``which="best"`` falls back to the final model
    for a run without ``best_model.zip``.
    """
    chosen = [r for r in runs if run_applies(r, setting)]
    if not chosen:
        return []
    try:
        from agents.sb3 import load_attacker
    except ModuleNotFoundError as exc:
        raise EncctlError(f"learned attackers need stable-baselines3 (module {exc.name!r} is missing); "
                          "install the extra: pip install 'encctl-gym[rl]'") from exc
    names = [r.algo + ("-blind" if r.observation == "blind" else "") for r in chosen]
    count = Counter(names)
    out: list[Attacker] = []
    for run, name in zip(chosen, names):
        label = name if count[name] == 1 else f"{name} ({run.path.name})"
        w = which if which == "final" or (run.path / "best_model.zip").exists() else "final"
        out.append(load_attacker(run.path, which=w, params=setting.params, name=label, deterministic=deterministic))
    return out
