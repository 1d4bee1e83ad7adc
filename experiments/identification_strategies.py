"""Identification strategies: input strategies (attackers) times estimators, against gamma(N).

For each system (default: the paper's design example, Figure 1 (c) and (g), and the ``small``
plant, which is not a multiple of the identity) and each attacker of ``agents`` (the paper's
Gaussian input, random binary, AR(1), the A-optimal design, and the learned attackers of the
training runs under ``--runs``), the attacks are played through ``EncryptedLTIAttack-v0`` (ideal
backend, ``decipher_delay = 0``): one set of ``--episodes`` episodes of exactly ``N`` samples for
every ``N`` of a log grid, with the energy budget ``m sigma_u2 N`` of that length
(:func:`agents.evaluate.budget_config`, as ``encctl-gym compare`` does), so every point compares
inputs at equal energy. From each episode the deciphered and delivered data
(``episode.delivered_data()``: states ``(K, N, n)`` and inputs ``(K, N - 1, m)`` in float64) are
identified by every estimator of ``--estimators`` (:mod:`encctl_gym.ident.registry`) on the
*same* data, and scored by Definition def:error.

The grid runs from ``n + m + 1`` (the least-squares minimum) to ``N*`` of Theorem thm:opt_sec
(eq:opt_sec for the preset's ``gamma_c``), or to ``--max-samples`` if ``N*`` is larger; it
contains the three sample sizes of the table: small (``n + m + 1``), medium (their geometric
mean) and ``N*`` (or the cap).

Security consequence. For every attacker and estimator, the sample size that reaches the
preset's ``gamma_c`` is ``floor(c / gamma_c) + 2`` for the rate ``c`` of a fit
``E[epsilon] ~ c / (N - 1)`` to the upper half of the grid
(:func:`experiments.compare.statistics.fit_rate`), flagged as inside the grid or extrapolated
(and how far), and as transient where the log-log slope there is outside [-1.1, -0.9]; where the
curve does not fall like ``1/N`` (slope above -0.8, e.g. least squares with forgetting) it is
reported as not reached. Then ``lambda = floor(log2(Upsilon tau_c / N_c)) + 1`` (Theorem thm:opt_sec) and the
key length of eq:opt_key, next to the paper's ``N*``, ``lambda*`` and ``k*``.

Heavy tails and replicates. Near ``N = n + m + 1`` the error of least squares has no mean
(:mod:`encctl_gym.ident.tails`: tail exponent ``(N - n - m) / 2``; IV with as many instruments as
unknowns has none at any N): every cell of the tables is the mean with its standard error only
where the mean exists by the tail rule (inputs with a density: the Gaussian and AR(1) attackers)
and the Hill check does not contradict it; elsewhere it is the median with the 10-90 %
quantiles and the reason. ``--replicates R`` repeats the whole experiment on disjoint
environment seeds (``seed + r * episodes``) and fresh attacker streams, and reports each
estimator's mean at ``N*`` and the samples to reach gamma_c as the spread over replicates
(mean and 95 % t interval of the replicate values).

Outputs under ``--out`` (default ``results/strategies``): ``curves.csv`` (system, attacker,
estimator, N, mean, standard error, 95 % band, median, 10 and 90 % quantiles, the status of the
mean, gamma, gamma_opt), ``episodes.csv`` (every episode's error per estimator and its
replicate), ``security.csv`` (per replicate), ``identification_strategies.png`` (mean error
against N with bands, gamma(N) and gamma_opt(N); rows systems, columns attackers),
``identification_strategies_ratio.png`` (each estimator's mean error over least squares') and
``summary.md`` (the tables and the finding in words).

Usage: ``python -m encctl_gym.experiments.identification_strategies [--quick] [--out DIR] [--seed S]
[--episodes E] [--replicates R] [--systems a,b] [--estimators ls,bayes] [--runs DIR] [--max-samples N]``; also
``encctl-gym reproduce`` (step ``strategies``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from encctl_gym.agents.runs import find_runs
from encctl_gym.experiments.common import add_common_arguments, ensure_out_dir, entry_point
from encctl_gym.experiments.compare.attackers import left_out
from encctl_gym.experiments.compare.settings import make_setting, system_entry
from encctl_gym.experiments.identification_report import CURVE_COLUMNS, SECURITY_COLUMNS, plot, summary_markdown, write_csvs
from encctl_gym.experiments.identification_results import (
    DEFAULT_CAP,
    DEFAULT_EPISODES,
    DEFAULT_ESTIMATORS,
    DEFAULT_POINTS,
    DEFAULT_SYSTEMS,
    QUICK_CAP,
    QUICK_EPISODES,
    QUICK_POINTS,
    QUICK_SYSTEMS,
    Curve,
    Result,
    attack_lengths,
    collect,
    compute,
    replicate_interval,
    security_rows,
    table_sizes,
)
from encctl_gym.ident.registry import estimator_names

__all__ = [
    "DEFAULT_SYSTEMS",
    "DEFAULT_ESTIMATORS",
    "DEFAULT_CAP",
    "CURVE_COLUMNS",
    "SECURITY_COLUMNS",
    "write_csvs",
    "Curve",
    "Result",
    "collect",
    "attack_lengths",
    "table_sizes",
    "replicate_interval",
    "compute",
    "security_rows",
    "plot",
    "summary_markdown",
    "add_arguments",
    "run",
    "main",
]


# --------------------------------------------------------------------------- command line
def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options: the common ones of the reproduction scripts plus the experiment's own."""
    add_common_arguments(parser)
    add_own_arguments(parser)


def add_own_arguments(parser: argparse.ArgumentParser) -> None:
    """The options that ``encctl-gym reproduce`` does not have (their defaults apply there)."""
    parser.add_argument(
        "--episodes",
        type=int,
        default=None,
        help=f"attacks per attacker and N (default {DEFAULT_EPISODES}; quick {QUICK_EPISODES})",
    )
    parser.add_argument("--replicates", type=int, default=1, help="independent repetitions on disjoint seeds (default 1)")
    parser.add_argument(
        "--systems",
        default=None,
        help=f"comma-separated presets or plant files (as train --system reads; default {','.join(DEFAULT_SYSTEMS)})",
    )
    parser.add_argument(
        "--estimators",
        default=None,
        help=f"comma-separated registry names (default {','.join(DEFAULT_ESTIMATORS)}; known: {', '.join(estimator_names())})",
    )
    parser.add_argument(
        "--max-samples", type=int, default=None, help=f"cap on the attack length (default {DEFAULT_CAP}; quick {QUICK_CAP})"
    )
    parser.add_argument("--points", type=int, default=None, help=f"grid points (default {DEFAULT_POINTS}; quick {QUICK_POINTS})")
    parser.add_argument(
        "--runs",
        action="append",
        default=[],
        help="training run directory or a parent of runs: its learned attackers join (repeatable; needs the [rl] extra)",
    )
    parser.add_argument("--which", choices=("best", "final"), default="best", help="learned model: best (default) or final")


def run(args: argparse.Namespace) -> int:
    """Run, write the CSVs, PNGs and ``summary.md`` under ``args.out``; print the summary."""
    quick = bool(getattr(args, "quick", False))
    systems_arg = getattr(args, "systems", None)
    systems = tuple(x.strip() for x in systems_arg.split(",")) if systems_arg else (QUICK_SYSTEMS if quick else DEFAULT_SYSTEMS)
    est_arg = getattr(args, "estimators", None)
    estimators = tuple(x.strip() for x in est_arg.split(",")) if est_arg else DEFAULT_ESTIMATORS
    episodes = getattr(args, "episodes", None) or (QUICK_EPISODES if quick else DEFAULT_EPISODES)
    cap = getattr(args, "max_samples", None) or (QUICK_CAP if quick else DEFAULT_CAP)
    points = getattr(args, "points", None) or (QUICK_POINTS if quick else DEFAULT_POINTS)
    roots = getattr(args, "runs", None) or []
    which = getattr(args, "which", "best")
    out = ensure_out_dir(getattr(args, "out", "results/strategies"))
    skipped: list[tuple[Path, str]] = []
    runs = find_runs(roots, left_out=skipped)
    if runs:  # the runs that play in none of the systems, said before the work
        entries = [system_entry(e) for e in systems]
        skipped += [
            (r.path, why) for r, why in left_out(runs, [make_setting(label, 0, cap, config=cfg) for label, cfg in entries])
        ]
    for path, why in skipped:
        print(f"identification strategies: leaving out the run {path}: {why}", file=sys.stderr)
    result = compute(
        systems,
        estimators=estimators,
        episodes=episodes,
        seed=args.seed,
        cap=cap,
        points=points,
        runs=runs,
        which=which,
        progress=not getattr(args, "no_progress", True),
        replicates=getattr(args, "replicates", 1) or 1,
    )
    files = write_csvs(result, out)
    plots = plot(result, out)
    cmd = (
        [
            "python -m encctl_gym.experiments.identification_strategies",
            f"--seed {args.seed}",
            f"--episodes {episodes}",
            f"--replicates {getattr(args, 'replicates', 1) or 1}",
            f"--systems {','.join(systems)}",
            f"--estimators {','.join(estimators)}",
            f"--max-samples {cap}",
            f"--points {points}",
        ]
        + [f"--runs {r}" for r in roots]
        + (["--quick"] if quick else [])
    )
    md = summary_markdown(result, command=" ".join(cmd), plots=[Path(p.name) for p in plots])
    (out / "summary.md").write_text(md)
    print(md)
    print("identification strategies: wrote " + ", ".join(str(p) for p in [*files, *plots, out / "summary.md"]))
    return 0


main = entry_point("identification_strategies", __doc__, add_arguments, run)


if __name__ == "__main__":
    sys.exit(main())
