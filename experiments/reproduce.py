"""Reproduce the paper's Figures 1 and 2, its design example and the measurements beyond it (PNG, CSV, tables).

The ``reproduce`` subcommand of ``encctl-gym`` (``add_arguments`` / ``run``); also
``python -m encctl_gym.experiments.reproduce``. Runs :mod:`experiments.fig1_variance_ratio`
(fig:variance_ratio), :mod:`experiments.fig2_gramian` (fig:gramian),
:mod:`experiments.design_example` (Theorem thm:opt_sec, eq:opt_key) and
:mod:`experiments.identification_strategies` (attackers times estimators against gamma(N)) and
:mod:`experiments.deciphering_time` (measured deciphering time of real discrete-logarithm
attacks against Definition def:sdt) with the same options.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import time
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from encctl_gym.experiments.common import add_common_arguments, entry_point

__all__ = ["STEPS", "add_arguments", "run", "main"]

#: (name, module) in the order they run.
STEPS = (
    ("fig1", "encctl_gym.experiments.fig1_variance_ratio"),
    ("fig2", "encctl_gym.experiments.fig2_gramian"),
    ("design", "encctl_gym.experiments.design_example"),
    ("strategies", "encctl_gym.experiments.identification_strategies"),
    ("deciphering", "encctl_gym.experiments.deciphering_time"),
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options: ``--out --quick --seed --n-jobs --scheduler --no-progress --only``."""
    add_common_arguments(parser)
    parser.add_argument(
        "--only", action="append", choices=[name for name, _ in STEPS], help="run only this part (repeatable; default: all)"
    )


def run(args: argparse.Namespace) -> int:
    """Run every step (or those of ``--only``); print where the outputs are and the wall time."""
    t0 = time.perf_counter()
    chosen = args.only or [name for name, _ in STEPS]
    for name, module_name in STEPS:
        if name not in chosen:
            continue
        module = importlib.import_module(module_name)
        rc = module.run(args)
        if rc:
            return rc
    print(f"reproduce: done in {time.perf_counter() - t0:.1f} s (outputs in {args.out})")
    return 0


main = entry_point("reproduce", __doc__, add_arguments, run)


if __name__ == "__main__":
    sys.exit(main())
