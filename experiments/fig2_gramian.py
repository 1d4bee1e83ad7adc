"""Figure 2 (fig:gramian): the complexity approaches the bound eq:bound as tr(Psi_u) decreases.

``m = n = 4``, ``sigma_x2 = 1``, ``Psi_w = 2I``, ``R_sigma = 100`` and
``Psi_u in {2, 1, 0.5, 0.3, 0.2, 0.1} I``. The paper gives only the Gramians; we realise them
with ``A = sqrt(1/2) I`` (so ``Psi_w = I / (1 - 1/2) = 2I``) and ``B = b I`` with
``b = sqrt(psi_u (1 - 1/2))``, since ``Psi_u = b^2 / (1 - a^2) I`` for ``A = a I, B = b I``.
The paper fixes only the ratio ``R_sigma``; we take ``sigma_w2 = 0.1`` and ``sigma_u2 = 10``
(the variances of Figure 1 (c), which has the same ratio; presets ``fig2-psi<v>``).

Per panel: gray dots each run's error (Definition def:error), solid the mean over 50 runs,
dashed ``gamma(N)`` of eq:sic2 and dotted the upper bound ``(m+n) / ((N-1) m R_sigma)`` of
eq:bound (both from :mod:`encctl_gym.security.complexity`).

Usage: ``python experiments/fig2_gramian.py [--quick] [--out DIR] [--seed S] [--n-jobs J]
[--scheduler local|tcp://host:port]`` (also ``encctl-gym reproduce``).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


from encctl_gym.experiments.common import FULL, GridConfig, Table, figure_entry_points, figure_table, panel_figure, preset_spec
from encctl_gym.sim.montecarlo import AttackSpec

__all__ = ["PSI_U", "PANELS", "panel_systems", "compute", "plot", "add_arguments", "run", "main"]

FIGURE = "fig2"
#: The scalar psi_u of Psi_u = psi_u I, in the paper's panel order (a)..(f).
PSI_U = (2.0, 1.0, 0.5, 0.3, 0.2, 0.1)
PANELS = tuple("abcdef")


def panel_systems() -> list[tuple[str, float, AttackSpec]]:
    """The six systems of Figure 2, ``(letter, psi_u, spec)``: ``A = I / sqrt(2)``,
    ``B = sqrt(psi_u / 2) I``, ``sigma_w2 = 0.1``, ``sigma_u2 = 10`` (the presets ``fig2-psi<v>``
    of :mod:`encctl_gym.presets`)."""
    return [(letter, psi, preset_spec(f"fig2-psi{psi:g}")) for letter, psi in zip(PANELS, PSI_U)]


def compute(
    config: GridConfig = FULL, *, seed: int = 0, n_jobs: int = -1, scheduler: Any = None, progress: bool = False
) -> Table:
    """The data of Figure 2: errors (Definition def:error), ``gamma(N)`` (eq:sic2) and the bound
    (eq:bound), one row per (panel, N, run); ``psi_u`` is computed from ``(A, B)``. Child 2 of
    ``SeedSequence(seed)`` (see :func:`experiments.common.figure_table`)."""
    panels = [(letter, spec) for letter, _, spec in panel_systems()]
    return figure_table(FIGURE, 2, panels, config, seed=seed, n_jobs=n_jobs, scheduler=scheduler, progress=progress, bound=True)


def plot(table: Table, path: str | Path) -> Path:
    """Draw Figure 2 (2 x 3 log-log panels) from a table of :func:`compute` and save it to
    ``path`` (PNG); returns the path, as :func:`experiments.fig1_variance_ratio.plot`."""
    s0 = table.summary(PANELS[0])
    runs = s0["errors"].shape[0]
    return panel_figure(
        table,
        PANELS,
        (2, 3),
        (11, 7),
        lambda s: f"({s['panel']}) $\\Psi_u = {s['psi_u']:.3g}I$",
        "Figure 2: varying $\\Psi_u$ with $\\Psi_w = 2I$, $R_\\sigma = 100$ "
        f"($\\sigma_w^2={s0['sigma_w2']:g}$, $\\sigma_u^2={s0['sigma_u2']:g}$, {runs} runs per $N$)\n"
        "realised by $A = I/\\sqrt{2}$, $B = bI$, $b = \\sqrt{\\psi_u(1-1/2)}$, "
        "i.e. $\\Psi_u = b^2/(1-a^2)\\,I$",
        path,
        bound=True,
    )


#: the command-line options (``--out --quick --seed --n-jobs --scheduler --no-progress``),
#: the run (``fig2_gramian.csv`` and ``.png`` under ``--out``) and ``main``
add_arguments, run, main = figure_entry_points("fig2_gramian", "Figure 2", compute, plot, __doc__)


if __name__ == "__main__":
    sys.exit(main())
