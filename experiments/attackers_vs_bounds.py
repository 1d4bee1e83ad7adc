"""Former home of the headline experiment, now the package :mod:`experiments.compare`.

This module keeps the old import path working for one version; it re-exports the public names
from their new modules and will be removed after that. ``encctl-gym compare`` runs
:mod:`experiments.compare.cli`.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Sequence
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from agents import Attacker  # noqa: E402
from agents.runs import find_runs as _find_run_infos  # noqa: E402
from experiments.compare.attackers import ATTACKERS, learned_attackers, make_attackers  # noqa: E402
from experiments.compare.cli import QUICK_CAP, QUICK_EPISODES, QUICK_SYSTEMS, add_arguments, main, run  # noqa: E402
from experiments.compare.plots import plot  # noqa: E402
from experiments.compare.protocol import Curve, Result, compute, elgamal_check, evaluate, planned_steps  # noqa: E402
from experiments.compare.report import findings, summary_markdown  # noqa: E402
from experiments.compare.settings import DEFAULT_CAP, DEFAULT_SYSTEMS, DELAYS, Setting, length_grid, make_setting  # noqa: E402
from experiments.compare.statistics import fit_rate, samples_to_reach  # noqa: E402
from experiments.compare.tables import CURVE_COLUMNS, SECURITY_COLUMNS, bound_rows, security_row, write_csvs  # noqa: E402

warnings.warn("experiments.attackers_vs_bounds moved to experiments.compare; the old path goes away in the next version",
              DeprecationWarning, stacklevel=2)

__all__ = [
    "DEFAULT_SYSTEMS", "DELAYS", "DEFAULT_CAP", "QUICK_SYSTEMS", "QUICK_CAP", "QUICK_EPISODES", "Setting", "Curve", "Result",
    "fit_rate", "samples_to_reach", "security_row", "bound_rows", "find_runs", "attackers_for", "length_grid", "make_setting",
    "evaluate", "planned_steps", "elgamal_check", "compute", "plot", "write_csvs", "summary_markdown", "findings",
    "CURVE_COLUMNS", "SECURITY_COLUMNS", "add_arguments", "run", "main",
]


def find_runs(roots: Sequence[str | Path]) -> list[Path]:
    """Training run directories under ``roots`` (see :func:`agents.runs.find_runs`, which returns their metadata)."""
    return [r.path for r in _find_run_infos(roots)]


def attackers_for(setting: Setting, runs: Sequence[str | Path], which: str = "best") -> list[Attacker]:
    """The attackers evaluated in one setting: every registered one, then the learned ones."""
    from agents.runs import read_run

    return make_attackers(setting, tuple(ATTACKERS)) + learned_attackers(setting, [read_run(r) for r in runs], which)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
