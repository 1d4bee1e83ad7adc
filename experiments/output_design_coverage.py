"""How often the output design's interval of ``N*`` covers the ``N*`` of a much larger simulation.

    python -m encctl_gym.experiments.output_design_coverage [--seeds 200] [--record]

For each case of :data:`CASES` (a plant with sensors, an estimator and the runs per ``N``),
:func:`~encctl_gym.security.output_design.output_design` is run with seeds ``0 .. seeds - 1``
and its 95 % interval of the output ``N*`` is checked against the reference: the same design
with :data:`REFERENCE_RUNS` runs and a seed no other run uses. Two intervals are scored from the
same fits: the design's, where the target (the state least-squares Markov error at the paper's
``N*``) is resampled with the output fit (``reference=`` of
:func:`~encctl_gym.security.empirical.empirical_design`), and the interval with the target fixed
at its point estimate, as the design computed it before. The binomial standard error of a
coverage near 0.95 over 200 seeds is 0.015. Writes
``results/output_identification/design_coverage.md``; ``--record`` writes it under ``docs/``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from encctl_gym.errors import EncctlError
from encctl_gym.security.empirical import empirical_design
from encctl_gym.security.output_design import output_design
from encctl_gym.security.threat import ThreatModel

from .common import ensure_out_dir, system_preset, write_recorded_table

__all__ = ["CASES", "REFERENCE_RUNS", "coverage", "main"]

#: (plant: a preset or a plant file of the clone, estimator, runs per N).
CASES: tuple[tuple[str, str, int], ...] = (
    ("small-output", "n4sid", 20),
    ("small-output", "n4sid", 80),
    ("small-output", "arx", 20),
    ("examples/plant_output.yaml", "n4sid", 20),
    ("examples/plant_output.yaml", "arx", 20),
)
#: Runs per N of the reference design.
REFERENCE_RUNS = 2000
REFERENCE_SEED = 10**6


def coverage(plant: str, estimator: str, runs: int, seeds: int) -> dict[str, float | int]:
    """The reference ``N*`` and the fraction of seeds whose interval covers it, carried and fixed."""
    p = system_preset(plant)
    threat = ThreatModel.of(p)
    ref = output_design(p.plant(), threat, estimator=estimator, runs=REFERENCE_RUNS, seed=REFERENCE_SEED, bootstrap=200)
    if ref.output_design is None:
        raise EncctlError(f"{plant}, {estimator}: the reference has no output design ({ref.note})")
    truth = ref.output_design.N_star
    carried = fixed = 0
    width = 0.0
    for seed in range(seeds):
        d = output_design(p.plant(), threat, estimator=estimator, runs=runs, seed=seed)
        if d.output_design is None:
            continue  # counted as not covering
        lo, hi = d.output_design.N_star_interval
        carried += lo <= truth <= hi
        width += (hi - lo) / truth
        flo, fhi = empirical_design(d.output_fit, threat, gamma_c=d.target).N_star_interval
        fixed += flo <= truth <= fhi
    return {"N_star": truth, "carried": carried / seeds, "fixed": fixed / seeds, "width": width / seeds}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m encctl_gym.experiments.output_design_coverage", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--seeds", type=int, default=200, help="designs per case (default 200)")
    parser.add_argument("--record", action="store_true", help="write docs/results/output_identification/design_coverage.md")
    parser.add_argument("--out", type=Path, default=Path("results/output_identification"),
                        help="directory of the page (default results/output_identification)")  # fmt: skip
    args = parser.parse_args(argv)
    if args.seeds < 1:
        print(f"output_design_coverage: --seeds must be >= 1, got {args.seeds}", file=sys.stderr)
        return 2
    rows = ["| plant | estimator | runs per N | reference N* | covered, target carried | covered, target fixed | "
            "mean width / N* |", "|---|---|---|---|---|---|---|"]  # fmt: skip
    try:
        for plant, estimator, runs in CASES:
            c = coverage(plant, estimator, runs, args.seeds)
            rows.append(f"| {plant} | {estimator} | {runs} | {c['N_star']} | {c['carried']:.3f} | {c['fixed']:.3f} | "
                        f"{c['width']:.2f} |")  # fmt: skip
            print(f"  {plant}, {estimator}, {runs} runs: {c}", file=sys.stderr)
        out = ensure_out_dir(Path("docs/results/output_identification") if args.record else args.out)
    except EncctlError as exc:
        print(f"output_design_coverage: {exc}", file=sys.stderr)
        return 2
    shown = " ".join(argv if argv is not None else sys.argv[1:])
    notes = (f" ({args.seeds} seeds per case, 95 % intervals; reference: {REFERENCE_RUNS} runs per N, seed "
             f"{REFERENCE_SEED}; binomial standard error near 0.95: {(0.95 * 0.05 / args.seeds) ** 0.5:.3f}).")  # fmt: skip
    write_recorded_table(out / "design_coverage.md", "Coverage of the output design's N* interval",
                         f"python -m encctl_gym.experiments.output_design_coverage {shown}".strip(), "\n".join(rows), notes)  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
