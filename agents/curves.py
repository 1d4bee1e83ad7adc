"""Learning curves of training runs: evaluation error against training steps, and their plots.

During training the evaluation callback (:class:`agents.callbacks.LearningCurveCallback`) plays
the current policy on the same environment seeds every ``eval.freq`` steps and records the final
identification error ``epsilon`` (Definition def:error) of each episode, at the training attack
length ``N``. A :class:`LearningCurve` holds that record with three references at the same
``N``: ``gamma(N)`` of eq:sic (the paper's sample identifying complexity), the exact
large-N error of the i.i.d. Gaussian attack, and ``gamma_opt(N)`` of the A-optimal attack design
at equal input power (both from :mod:`encctl_gym.security.attack_design`; closed loop when the
policy reads delivered states, open loop for a blind policy). The curve is drawn as
``E[epsilon] / gamma_opt(N)``: 1 is the optimum an attacker of that class can reach (for large
N); the two other references are horizontal lines.

:func:`plot_learning_curves` draws several runs in one figure (one colour per algorithm and
system, one line per seed).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym._validation import format_count
from encctl_gym.errors import ConfigError
from encctl_gym.plotting import save_figure

__all__ = [
    "CURVE_FILE",
    "LearningCurve",
    "reference_designs",
    "curve_for",
    "load_learning_curve",
    "plot_learning_curves",
    "curve_table",
]

#: File name of a run's learning curve (and ``.png`` for its plot).
CURVE_FILE = "learning_curve.npz"
#: z value of a two-sided 95 % normal interval.
Z95 = 1.959963984540054


@dataclass
class LearningCurve:
    """Evaluation errors of one training run against its training steps.

    Attributes
    ----------
    label : str
        ``{algo} {system} s{seed}``.
    algo, system : str
        Algorithm and system label.
    seed : int
        Training seed.
    N : int
        Attack length of the evaluation episodes.
    gamma, gamma_gauss, gamma_opt : float
        ``gamma(N)`` (eq:sic), the Gaussian attack's exact rate over ``N - 1``, and
        ``gamma_opt(N)`` (the optimal design of ``design_kind``).
    design_kind : str
        ``closed_loop`` or ``open_loop``.
    timesteps : ndarray (E,)
        Training steps at each evaluation.
    epsilon : ndarray (E, K)
        Final error of each of the K evaluation episodes (the same seeds at every evaluation).
    """

    label: str
    algo: str
    system: str
    seed: int
    N: int
    gamma: float
    gamma_gauss: float
    gamma_opt: float
    design_kind: str
    timesteps: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    epsilon: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))

    def append(self, timestep: int, finals: np.ndarray) -> None:
        """Add one evaluation (``finals``: the K episodes' final errors)."""
        finals = np.asarray(finals, dtype=float).reshape(1, -1)
        if self.epsilon.size and finals.shape[1] != self.epsilon.shape[1]:
            raise ConfigError(f"an evaluation of {finals.shape[1]} episodes does not fit a curve of {self.epsilon.shape[1]}")
        self.timesteps = np.append(self.timesteps, int(timestep))
        self.epsilon = finals if not self.epsilon.size else np.vstack([self.epsilon, finals])

    @property
    def mean(self) -> np.ndarray:
        """``E[epsilon]`` at each evaluation (mean over its episodes)."""
        return self.epsilon.mean(axis=1)

    @property
    def se(self) -> np.ndarray:
        """Standard error of :attr:`mean` (``nan`` for a single episode)."""
        K = self.epsilon.shape[1]
        return self.epsilon.std(axis=1, ddof=1) / math.sqrt(K) if K > 1 else np.full(len(self.timesteps), np.nan)

    def ratio(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``E[epsilon] / gamma_opt(N)`` at each evaluation with its 95 % band (low, high)."""
        r = self.mean / self.gamma_opt
        half = Z95 * self.se / self.gamma_opt
        return r, r - half, r + half

    def save(self, path: str | Path) -> Path:
        """Write the curve as ``.npz`` (read back with :func:`load_learning_curve`)."""
        path = Path(path)
        np.savez(
            path,
            label=self.label,
            algo=self.algo,
            system=self.system,
            seed=self.seed,
            N=self.N,
            gamma=self.gamma,
            gamma_gauss=self.gamma_gauss,
            gamma_opt=self.gamma_opt,
            design_kind=self.design_kind,
            timesteps=self.timesteps,
            epsilon=self.epsilon,
        )
        return path


def reference_designs(params: Any, observation: str) -> tuple[Any, Any]:
    """The optimal attack design a policy is measured against (closed loop if it reads delivered
    states in time, open loop if it is blind or nothing is delivered before the end) and the
    i.i.d. Gaussian attack's design, both at the environment's input power."""
    from encctl_gym.security.attack_design import gaussian_attack_design, optimal_attack_design

    feedback = params.decipher_delay is not None and observation != "blind"
    kw = {"sigma_u2": params.sigma_u2, "sigma_w2": params.sigma_w2}
    return optimal_attack_design(params.A, params.B, feedback=feedback, **kw), gaussian_attack_design(params.A, params.B, **kw)


def curve_for(params: Any, observation: str, *, algo: str, system: str, seed: int) -> LearningCurve:
    """An empty :class:`LearningCurve` with the references of an environment at its horizon."""
    design, gauss = reference_designs(params, observation)
    N = params.horizon
    return LearningCurve(
        label=f"{algo} {system} s{seed}",
        algo=algo,
        system=system,
        seed=seed,
        N=N,
        gamma=float(params.gamma(N)),
        gamma_gauss=float(gauss.gamma(N)),
        gamma_opt=float(design.gamma(N)),
        design_kind=design.kind,
    )


def load_learning_curve(path: str | Path) -> LearningCurve:
    """Read a curve written by :meth:`LearningCurve.save` (a run directory or the ``.npz`` file).

    Raises
    ------
    ConfigError
        A missing or unreadable file, or one without the curve's fields.
    """
    path = Path(path)
    if path.is_dir():
        path = path / CURVE_FILE
    if not path.is_file():
        raise ConfigError(f"no learning curve at {str(path)!r}")
    try:
        with np.load(path, allow_pickle=False) as z:
            return LearningCurve(
                label=str(z["label"]),
                algo=str(z["algo"]),
                system=str(z["system"]),
                seed=int(z["seed"]),
                N=int(z["N"]),
                gamma=float(z["gamma"]),
                gamma_gauss=float(z["gamma_gauss"]),
                gamma_opt=float(z["gamma_opt"]),
                design_kind=str(z["design_kind"]),
                timesteps=np.asarray(z["timesteps"], dtype=np.int64),
                epsilon=np.asarray(z["epsilon"], dtype=float),
            )
    except (OSError, ValueError, KeyError, EOFError) as exc:
        raise ConfigError(f"cannot read learning curve {str(path)!r}: {type(exc).__name__}: {exc}") from exc


def plot_learning_curves(curves: Sequence[LearningCurve | str | Path], path: str | Path, *, title: str | None = None) -> Path:
    """Draw one or more learning curves in one figure and write it as PNG.

    Each curve is ``E[epsilon] / gamma_opt(N)`` against training steps with its 95 % band; runs
    of the same algorithm and system share a colour (one line per seed); the paper's
    ``gamma(N)`` (dashed) and the Gaussian attack's exact error (dash-dotted) of each system
    are horizontal lines, over the same ``gamma_opt(N)``; 1 is the optimal design.

    Parameters
    ----------
    curves : sequence
        :class:`LearningCurve` objects, run directories or ``.npz`` files.
    path : path
        Output PNG.
    title : str, optional
        Figure title.

    Returns
    -------
    Path
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cs = [c if isinstance(c, LearningCurve) else load_learning_curve(c) for c in curves]
    # a run given by its directory (or its .npz) is named by the directory: two runs of one
    # algorithm, system and seed (other settings) stay apart in the legend
    names = [
        None if isinstance(c, LearningCurve) else (Path(c).parent if Path(c).suffix == ".npz" else Path(c)).name for c in curves
    ]
    if not cs:
        raise ConfigError("no learning curve to plot")
    fig, ax = plt.subplots(figsize=(11.5, 4.8))
    _draw_curves(ax, cs, names, plt.rcParams["axes.prop_cycle"].by_key()["color"])
    _draw_references(ax, cs)
    ax.set_xlabel("training steps")
    _set_ratio_limits(ax, cs)
    ax.set_ylabel("E[eps(N)] / gamma_opt(N)  (evaluation episodes)")
    ax.set_title(title or "Learning curves: evaluation error over the optimum", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.tight_layout()
    path = Path(path)
    save_figure(fig, path, dpi=110, tight=True)
    plt.close(fig)
    return path


def _draw_curves(ax: Any, cs: Sequence[LearningCurve], names: Sequence[str | None], colors: Sequence[str]) -> None:
    """One line (with its 95 % band) per curve: a colour per algorithm, system and design, a line
    style per run within it."""
    groups = list(dict.fromkeys((c.algo, c.system, c.design_kind) for c in cs))
    styles = ("-", "--", "-.", ":")
    for i, (c, name) in enumerate(zip(cs, names)):
        key = (c.algo, c.system, c.design_kind)
        g = groups.index(key)
        within = [j for j, d in enumerate(cs) if (d.algo, d.system, d.design_kind) == key].index(i)
        r, lo, hi = c.ratio()
        col = colors[g % len(colors)]
        ax.plot(
            c.timesteps,
            r,
            color=col,
            ls=styles[within % len(styles)],
            marker="o",
            ms=3,
            lw=1.4,
            label=(f"{name}: " if name else "") + f"{c.algo}, {c.system}, {c.design_kind}, seed {c.seed} "
            f"(N = {c.N}, {format_count(c.epsilon.shape[1], 'episode')})",
        )
        if np.all(np.isfinite(lo)):
            ax.fill_between(c.timesteps, lo, hi, color=col, alpha=0.15, lw=0)


def _draw_references(ax: Any, cs: Sequence[LearningCurve]) -> None:
    """The horizontal references of each system: the paper's ``gamma(N)``, the Gaussian attack's
    exact error, and 1 (the optimal design), all over ``gamma_opt(N)``."""
    for system in dict.fromkeys((c.system, c.design_kind, c.N) for c in cs):
        ref = next(c for c in cs if (c.system, c.design_kind, c.N) == system)
        ax.axhline(
            ref.gamma / ref.gamma_opt,
            color="0.35",
            ls="--",
            lw=1.0,
            label=f"{ref.system}, {ref.design_kind}: paper's gamma(N) (eq:sic) / gamma_opt(N)",
        )
        ax.axhline(
            ref.gamma_gauss / ref.gamma_opt,
            color="0.35",
            ls="-.",
            lw=1.0,
            label=f"{ref.system}, {ref.design_kind}: Gaussian attack, exact rate / gamma_opt(N)",
        )
    ax.axhline(1.0, color="k", lw=1.0, label="1: the optimal design (gamma_opt, same power)")


def _set_ratio_limits(ax: Any, cs: Sequence[LearningCurve]) -> None:
    """The y range: near 1 with early evaluations far above it cut (said in the plot), or a log axis when
    a curve's last evaluation would be cut away."""
    # the interesting range is near 1: a policy that starts at zero input (ARS) has an error many
    # orders above the optimum at first, and those points are cut at the top (said in the plot)
    refs = [c.gamma_gauss / c.gamma_opt for c in cs] + [c.gamma / c.gamma_opt for c in cs]
    top = max(2.0, 1.3 * max(refs))
    peak = max(float(np.nanmax(c.ratio()[0])) for c in cs)
    low = min(0.9, min(float(np.nanmin(c.ratio()[0])) for c in cs) * 0.97)
    # every curve keeps at least its last evaluation in view: a short (quick) run that never came
    # near the optimum is drawn on a log axis instead of being cut away
    last_below_cut = all(float(c.ratio()[0][np.isfinite(c.ratio()[0])][-1]) <= top for c in cs)
    if peak > top and last_below_cut:
        ax.set_ylim(low, top)
        ax.text(
            0.5,
            0.98,
            f"y axis cut at a ratio of {top:.2g} to the optimum: early evaluations reach {peak:.3g}",
            transform=ax.transAxes,
            fontsize=7,
            va="top",
            ha="center",
        )
    elif peak > top:
        ax.set_yscale("log")
        ax.set_ylim(low, 1.5 * peak)


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m encctl_gym.agents.curves RUN_DIR ... --out FILE``: several runs' learning curves in one figure."""
    import argparse
    import sys

    parser = argparse.ArgumentParser(prog="python -m encctl_gym.agents.curves", description=main.__doc__)
    parser.add_argument("runs", nargs="+", metavar="RUN_DIR", help="training run directories (or learning_curve.npz files)")
    parser.add_argument("--out", required=True, help="output PNG")
    parser.add_argument("--title", default=None, help="figure title")
    args = parser.parse_args(argv)
    try:
        path = plot_learning_curves(args.runs, args.out, title=args.title)
    except ConfigError as exc:
        print(f"python -m encctl_gym.agents.curves: error: {exc}", file=sys.stderr)
        return 2
    print(curve_table(args.runs))
    print(f"wrote {path}")
    return 0


def curve_table(curves: Sequence[LearningCurve | str | Path]) -> str:
    """A markdown table of learning curves: per run its steps, evaluations and ``E[eps] /
    gamma_opt(N)`` at the first, the best (with its step) and the last evaluation."""
    rows = ["| run | N | steps | evaluations | first | best (step) | last |", "|---|---|---|---|---|---|---|"]
    for c in curves:
        curve = c if isinstance(c, LearningCurve) else load_learning_curve(c)
        name = curve.label if isinstance(c, LearningCurve) else Path(c).name
        if not len(curve.timesteps):
            rows.append(f"| {name} | {curve.N} | 0 | 0 | | | |")
            continue
        r = curve.ratio()[0]
        i = int(np.argmin(r))
        rows.append(
            f"| {name} | {curve.N} | {int(curve.timesteps[-1])} | {len(r)} | {r[0]:.3f} | {r[i]:.3f} ({int(curve.timesteps[i])}) "
            f"| {r[-1]:.3f} |"
        )
    return "\n".join(rows)


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
