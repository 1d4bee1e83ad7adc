"""``encctl-gym compare``: every attacker against gamma(N) and gamma_opt(N).

For each system (default: the paper's design example and Figure 1 (c) and (g)) and both
observation settings (``decipher_delay = 0`` and ``"end"``), every attacker of the registry
(:data:`~experiments.compare.attackers.ATTACKERS`: Gaussian = the paper's, random binary, AR(1),
the A-optimal design as an oracle) and the learned attackers of the training runs found under
``--runs`` play ``--episodes`` episodes of ``EncryptedLTIAttack-v0`` (ideal backend) per attack
length, with the same environment seeds and the same energy budget ``m sigma_u2 N``
(:mod:`~experiments.compare.protocol`). By default a run's best model of the training's
evaluation callback plays (selected on the callback's own episodes, so the comparison here, on
other seeds, is not biased by the selection).

Outputs under ``--out`` (default ``results/compare``): ``curves.csv``, ``episodes.csv``,
``security.csv``, ``elgamal.csv`` (:mod:`~experiments.compare.tables`), one PNG per system
(:mod:`~experiments.compare.plots`) and ``summary.md`` (:mod:`~experiments.compare.report`),
which is also printed.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from encctl_gym._validation import format_value
from encctl_gym.agents.runs import MODEL_FILES, check_output_dir, find_runs
from encctl_gym.errors import ConfigError

from .attackers import ATTACKERS, DEFAULT_ATTACKERS, left_out
from .plots import plot
from .protocol import compute
from .records import Result
from .report import summary_markdown
from .settings import DEFAULT_CAP, DEFAULT_SYSTEMS, DELAYS, make_setting, parse_delays, system_entry
from .tables import write_csvs

__all__ = [
    "QUICK_SYSTEMS",
    "QUICK_CAP",
    "QUICK_EPISODES",
    "MAX_COUNT",
    "add_arguments",
    "run",
    "main",
    "write_outputs",
    "positive",
    "names",
]

QUICK_SYSTEMS = ("paper-example",)
QUICK_CAP = 60
QUICK_EPISODES = 4
QUICK_POINTS = 4
FULL_EPISODES = 50
FULL_POINTS = 10


#: Largest count on the command line: attack lengths, episodes and grid sizes are int64 arrays.
MAX_COUNT = 2**63 - 1


def positive(name: str, value: int | None, minimum: int = 1, maximum: int = MAX_COUNT) -> int | None:
    """A command-line count checked against its range (``None`` passes: the default applies)."""
    if value is not None and value < minimum:
        raise ConfigError(f"--{name} must be >= {minimum}, got {format_value(value)}")
    if value is not None and value > maximum:
        raise ConfigError(f"--{name} must be <= {maximum}, got {format_value(value)}")
    return value


def names(text: str, what: str) -> tuple[str, ...]:
    """A comma-separated list of names (``--systems a,b``), without empty entries or repeats."""
    out = tuple(dict.fromkeys(v.strip() for v in text.split(",") if v.strip()))
    if not out:
        raise ConfigError(f"no {what} in {text!r}")
    return out


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``encctl-gym compare``."""
    parser.add_argument("--out", default="results/compare", help="output directory (default results/compare)")
    parser.add_argument(
        "--quick",
        action="store_true",
        help=f"small smoke test ({QUICK_SYSTEMS[0]}, N <= {QUICK_CAP}, {QUICK_EPISODES} episodes, {QUICK_POINTS} lengths)",
    )
    parser.add_argument("--seed", type=int, default=0, help="environment seeds seed, seed + 1, ... (default 0)")
    parser.add_argument(
        "--episodes", type=int, default=None, help=f"episodes per attacker, setting and attack length (default {FULL_EPISODES})"
    )
    parser.add_argument(
        "--systems",
        default=None,
        help=f"comma-separated presets or plant files (as train --system reads; default {','.join(DEFAULT_SYSTEMS)})",
    )
    parser.add_argument("--delays", default=None, help="comma-separated decipher delays: integers >= 0 or end (default 0,end)")
    parser.add_argument(
        "--attackers",
        default=None,
        help=f"comma-separated registered attackers ({','.join(ATTACKERS)}; default {','.join(DEFAULT_ATTACKERS)}); learned ones come from --runs",
    )
    parser.add_argument("--max-samples", type=int, default=None, help=f"evaluation cap on N (default {DEFAULT_CAP})")
    parser.add_argument(
        "--points",
        type=int,
        default=None,
        help=f"attack lengths N on the log grid of every curve, in every setting, at most --max-samples "
        f"(default {FULL_POINTS}; quick {QUICK_POINTS})",
    )
    parser.add_argument(
        "--runs",
        action="append",
        default=[],
        help="training run directory or a parent of runs (repeatable; default results/train if it exists, left out with --quick)",
    )
    parser.add_argument(
        "--which",
        choices=("best", "final"),
        default="best",
        help="learned model: the best of the training's evaluation callback (default) or the final one",
    )
    parser.add_argument(
        "--elgamal-episodes",
        type=int,
        default=1,
        help="episodes of each attacker through real ElGamal ciphertexts (64-bit key, N = 40; default 1, 0: none)",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def write_outputs(result: Result, out: Path, *, command: str, title: str | None = None) -> tuple[str, list[Path]]:
    """CSV files, PNGs and ``summary.md`` under ``out``; returns the summary and every path written."""
    out.mkdir(parents=True, exist_ok=True)
    files = write_csvs(result, out)
    plots = plot(result, out)
    kw = {"title": title} if title else {}
    md = summary_markdown(result, command=command, plots=plots, **kw)
    (out / "summary.md").write_text(md)
    return md, [*files, *plots, out / "summary.md"]


def run_roots(runs: Sequence[str] | None, quick: bool, default: str = "results/train") -> tuple[list[str], str]:
    """The run folders whose learned attackers play, and a note when the default folder exists
    but is left out: ``--runs`` as given; else ``default`` if it exists, except with ``--quick``
    (a smoke test of the scripted attackers), which says that it leaves it out."""
    if runs:
        return list(runs), ""
    if not Path(default).exists():
        return [], ""
    if quick:
        return (
            [],
            f"--quick leaves out the trained runs in {default} (it plays the scripted attackers only); give --runs {default} to add them",
        )
    return [default], ""


def run(args: argparse.Namespace) -> int:
    """Run, write CSV, PNG and summary.md; print the summary."""
    quick = args.quick
    # an empty list given on the command line is an error, not the default
    systems = names(args.systems, "systems") if args.systems is not None else (QUICK_SYSTEMS if quick else DEFAULT_SYSTEMS)
    delays = parse_delays(args.delays) if args.delays is not None else DELAYS
    attackers = names(args.attackers, "attackers") if args.attackers is not None else DEFAULT_ATTACKERS
    episodes = positive("episodes", args.episodes) or (QUICK_EPISODES if quick else FULL_EPISODES)
    cap = positive("max-samples", args.max_samples, 2) or (QUICK_CAP if quick else DEFAULT_CAP)
    points = positive("points", args.points, 1, cap) or (QUICK_POINTS if quick else FULL_POINTS)
    positive("elgamal-episodes", args.elgamal_episodes, 0)
    check_output_dir(args.out)  # before the work, not after it
    roots, note = run_roots(args.runs, quick)
    if note:
        print(f"encctl-gym compare: {note}", file=sys.stderr)
    skipped: list[tuple[Path, str]] = []
    runs = find_runs(roots, left_out=skipped)
    for r in runs:  # every model that may play is a readable archive, checked before the work
        r.model_path(args.which if args.which == "final" or (r.path / MODEL_FILES["best"]).exists() else "final")
    configs = dict(system_entry(s) for s in systems)  # presets and plant files, by label
    settings = [make_setting(label, d, cap, config=cfg) for label, cfg in configs.items() for d in delays]
    skipped += [(r.path, why) for r, why in left_out(runs, settings)]
    for path, why in skipped:
        print(f"encctl-gym compare: leaving out the run {path}: {why}", file=sys.stderr)
    result = compute(
        settings=settings,
        episodes=episodes,
        seed=args.seed,
        points=points,
        runs=runs,
        which=args.which,
        elgamal_episodes=args.elgamal_episodes,
        elgamal_N=min(40, cap),
        progress=not args.no_progress,
        attackers=attackers,
    )
    cmd = (
        [
            "encctl-gym compare",
            f"--seed {args.seed}",
            f"--episodes {episodes}",
            f"--systems {','.join(systems)}",
            f"--delays {','.join(str(d) for d in delays)}",
            f"--max-samples {cap}",
            f"--points {points}",
            f"--which {args.which}",
        ]
        + [f"--runs {r}" for r in roots]
        + (["--quick"] if quick else [])
    )
    if args.attackers:
        cmd.append(f"--attackers {','.join(attackers)}")
    md, paths = write_outputs(result, Path(args.out), command=" ".join(cmd))
    print(md)
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run as a script (``python -m encctl_gym.experiments.compare.cli``)."""
    from encctl_gym.cli import main as cli_main

    return cli_main(["compare", *(sys.argv[1:] if argv is None else argv)])


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
