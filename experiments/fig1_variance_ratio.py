"""Figure 1 (fig:variance_ratio): estimation error against the sample identifying complexity.

The system of Section "Numerical Simulation": ``m = n = 4``, ``sigma_x2 = 1``,
``A = 0.7071 I``, ``B = I`` (so ``Psi_w ~= Psi_u ~= 2I``), for the nine combinations
``sigma_w2, sigma_u2 in {0.1, 1, 10}``. Rows are ``sigma_w2``, columns ``sigma_u2``, as in the
paper: (a) ``sigma_w2 = 0.1, sigma_u2 = 0.1`` (``R_sigma = 1``), (b) ``0.1, 1``, (c) ``0.1, 10``,
(d) ``1, 0.1``, ... (i) ``10, 10``.

For every panel, 50 identifications (eq:estimate) per sample size: each run is one trajectory of
the i.i.d. Gaussian attack of Theorem thm:sic of length ``N_max = 10^4``, identified on every
prefix ``N`` of a log grid (Definition def:error). Gray dots: each run's error; solid: the mean;
dashed: ``gamma(N)`` of eq:sic2 (from :mod:`encctl_gym.security.complexity`).

Usage: ``python experiments/fig1_variance_ratio.py [--quick] [--out DIR] [--seed S]
[--n-jobs J] [--scheduler local|tcp://host:port]`` (also ``encctl-gym reproduce``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any, Sequence

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np

from encctl_gym.presets import get_preset
from encctl_gym.security.complexity import sample_identifying_complexity_asymptotic
from encctl_gym.security.gramians import controllability_gramian
from encctl_gym.sim.montecarlo import AttackSpec, sweep_gaussian_attack
from experiments.common import (
    FULL,
    GridConfig,
    Table,
    add_common_arguments,
    figure_seed,
    plot_panel,
    run_figure,
    script_main,
)

__all__ = ["PANELS", "panel_systems", "compute", "plot", "add_arguments", "run", "main"]

FIGURE = "fig1"
#: Panel letters in the paper's order (row-major: rows sigma_w2, columns sigma_u2).
PANELS = tuple("abcdefghi")


def panel_systems() -> list[tuple[str, AttackSpec]]:
    """The nine systems of Figure 1, ``(letter, spec)`` in the paper's panel order.

    Returns
    -------
    list of (str, AttackSpec)
        From the presets ``fig1-a`` ... ``fig1-i`` of :mod:`encctl_gym.presets`.
    """
    out = []
    for letter in PANELS:
        p = get_preset(f"fig1-{letter}")
        out.append((letter, AttackSpec(p.A, p.B, sigma_w2=p.sigma_w2, sigma_u2=p.sigma_u2, sigma_x2=p.sigma_x2)))
    return out


def compute(
    config: GridConfig = FULL,
    *,
    seed: int = 0,
    n_jobs: int = -1,
    scheduler: Any = None,
    progress: bool = False,
) -> Table:
    """The data of Figure 1: errors (Definition def:error) and ``gamma(N)`` (eq:sic2).

    Parameters
    ----------
    config
        Grid of sample sizes and number of runs (:data:`experiments.common.FULL` is the paper's).
    seed
        Master seed; the figure uses child 1 of ``SeedSequence(seed)`` and panel ``k`` its child
        ``k``, so a panel does not depend on the others or on the workers.
    n_jobs, scheduler, progress
        Parallel execution (see :func:`encctl_gym.parallel.run_tasks`).
    Returns
    -------
    Table
        One row per (panel, N, run), ``bound`` empty.
    """
    systems = panel_systems()
    grid = config.grid(4, 4)
    errors_all = sweep_gaussian_attack(
        [spec for _, spec in systems], sample_sizes=grid, runs=config.runs, seed=figure_seed(seed, 1),
        n_jobs=n_jobs, scheduler=scheduler, progress=progress, desc="Figure 1",
    )
    parts = []
    for (letter, spec), errors in zip(systems, errors_all):
        r_sigma = spec.sigma_u2 / spec.sigma_w2
        gamma = sample_identifying_complexity_asymptotic(grid, spec.A, spec.B, r_sigma=r_sigma)
        psi_u = float(np.trace(controllability_gramian(spec.A, spec.B))) / spec.A.shape[0]
        parts.append(Table.from_errors(
            figure=FIGURE, panel=letter, grid=grid, errors=errors, gamma=gamma,
            sigma_w2=spec.sigma_w2, sigma_u2=spec.sigma_u2, psi_u=psi_u,
        ))
    return Table.concat(parts)


def plot(table: Table, path: str | Path) -> Path:
    """Draw Figure 1 (3 x 3 log-log panels) from a table of :func:`compute` and save it.

    Parameters
    ----------
    table
        Output of :func:`compute`.
    path
        PNG file to write.

    Returns
    -------
    pathlib.Path
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 3, figsize=(11, 9.5), sharex=True, sharey=True)
    for ax, letter in zip(axes.ravel(), PANELS):
        s = table.summary(letter)
        plot_panel(ax, s, f"({letter}) $R_\\sigma={s['r_sigma']:g}$, $\\sigma_w^2={s['sigma_w2']:g}$, "
                          f"$\\sigma_u^2={s['sigma_u2']:g}$")
    for ax in axes[-1]:
        ax.set_xlabel("sample size $N$")
    for ax in axes[:, 0]:
        ax.set_ylabel(r"estimation error $\epsilon(N)$")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, frameon=False)
    runs = int(table.columns["run"].max()) + 1
    fig.suptitle(
        "Figure 1: estimation error vs. sample identifying complexity "
        f"($A=0.7071I$, $B=I$, $\\Psi_w\\approx\\Psi_u\\approx 2I$, $n=m=4$, $\\sigma_x^2=1$, {runs} runs per $N$)",
        fontsize=10,
    )
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    path = Path(path)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Command-line options (``--out --quick --seed --n-jobs --scheduler --no-progress``)."""
    add_common_arguments(parser)


def run(args: argparse.Namespace) -> int:
    """Compute, save ``fig1_variance_ratio.csv`` and ``.png`` under ``args.out``; print the paths."""
    return run_figure(args, compute, plot, "fig1_variance_ratio", "Figure 1")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``python experiments/fig1_variance_ratio.py``."""
    return script_main("fig1_variance_ratio", __doc__, add_arguments, run, argv)


if __name__ == "__main__":
    sys.exit(main())
