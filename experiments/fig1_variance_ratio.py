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

import sys
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


from encctl_gym.experiments.common import FULL, GridConfig, Table, figure_entry_points, figure_table, panel_figure, preset_spec
from encctl_gym.sim.montecarlo import AttackSpec

__all__ = ["PANELS", "panel_systems", "compute", "plot", "add_arguments", "run", "main"]

FIGURE = "fig1"
#: Panel letters in the paper's order (row-major: rows sigma_w2, columns sigma_u2).
PANELS = tuple("abcdefghi")


def panel_systems() -> list[tuple[str, AttackSpec]]:
    """The nine systems of Figure 1, ``(letter, spec)`` in the paper's panel order (the presets
    ``fig1-a`` ... ``fig1-i`` of :mod:`encctl_gym.presets`)."""
    return [(letter, preset_spec(f"fig1-{letter}")) for letter in PANELS]


def compute(
    config: GridConfig = FULL, *, seed: int = 0, n_jobs: int = -1, scheduler: Any = None, progress: bool = False
) -> Table:
    """The data of Figure 1: errors (Definition def:error) and ``gamma(N)`` (eq:sic2), one row per
    (panel, N, run), ``bound`` empty; child 1 of ``SeedSequence(seed)`` (see
    :func:`experiments.common.figure_table`)."""
    return figure_table(FIGURE, 1, panel_systems(), config, seed=seed, n_jobs=n_jobs, scheduler=scheduler, progress=progress)


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
    runs = int(table.columns["run"].max()) + 1
    return panel_figure(
        table,
        PANELS,
        (3, 3),
        (11, 9.5),
        lambda s: (
            f"({s['panel']}) $R_\\sigma={s['r_sigma']:g}$, $\\sigma_w^2={s['sigma_w2']:g}$, $\\sigma_u^2={s['sigma_u2']:g}$"
        ),
        "Figure 1: estimation error vs. sample identifying complexity "
        f"($A=0.7071I$, $B=I$, $\\Psi_w\\approx\\Psi_u\\approx 2I$, $n=m=4$, $\\sigma_x^2=1$, {runs} runs per $N$)",
        path,
        rect=(0, 0.04, 1, 0.97),
    )


#: the command-line options (``--out --quick --seed --n-jobs --scheduler --no-progress``),
#: the run (``fig1_variance_ratio.csv`` and ``.png`` under ``--out``) and ``main``
add_arguments, run, main = figure_entry_points("fig1_variance_ratio", "Figure 1", compute, plot, __doc__)


if __name__ == "__main__":
    sys.exit(main())
