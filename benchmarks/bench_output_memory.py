"""Peak memory of the output design with the estimators streamed over chunks of runs, against
the same design with every run in one batch (as before the streaming), measured in one run.

Each variant runs :func:`~encctl_gym.security.output_design.output_design` in a fresh Python
process (so one's peak cannot hide the other's) on ``examples/plant_output.yaml`` with
``gamma_c = 1e-6`` and the given ``sigma_u2`` (a smaller one makes the attacks longer), and
prints its peak resident memory (``ru_maxrss``), its wall time and whether the two designs agree
to the last digit. The batch variant sets :data:`encctl_gym.sim.output.STREAM_BYTES` beyond any
run, so every run enters the estimator at once.

Usage::

    python benchmarks/bench_output_memory.py                     # sigma_u2 = 1 (N up to 259 840), n4sid and arx
    python benchmarks/bench_output_memory.py --sigma-u2 0.3      # N up to 654 182: about 6 GB for the batch ARX
    python benchmarks/bench_output_memory.py --record
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

CHILD = """
import dataclasses, json, resource, sys, time
import encctl_gym.sim.output as so
from encctl_gym.plant_file import load_plant_file
from encctl_gym.security.output_design import output_design
from encctl_gym.security.threat import ThreatModel
estimator, sigma_u2, batch = sys.argv[1], float(sys.argv[2]), sys.argv[3] == "batch"
if batch:
    so.STREAM_BYTES = 2**62
p = dataclasses.replace(load_plant_file(sys.argv[4]).preset, sigma_u2=sigma_u2, gamma_c=1e-6)
t0 = time.perf_counter()
d = output_design(p.plant(), ThreatModel.of(p), estimator=estimator, memory_limit=2**40)
print(json.dumps({"seconds": time.perf_counter() - t0, "maxrss_kib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
                  "N_max": int(d.state_fit.N[-1]), "design": d.to_dict()}))
"""


def _run(estimator: str, sigma_u2: float, variant: str) -> dict:
    out = subprocess.run(
        [sys.executable, "-c", CHILD, estimator, str(sigma_u2), variant, str(ROOT / "examples" / "plant_output.yaml")],
        capture_output=True, text=True, check=True, cwd=ROOT,
    )  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sigma-u2", type=float, default=1.0, help="attack input power (default 1)")
    parser.add_argument("--estimators", nargs="+", default=["n4sid", "arx"])
    parser.add_argument("--record", action="store_true", help="record the figures for the docs' benchmark table")
    args = parser.parse_args(argv)
    figures: dict = {}
    rows = []
    for est in args.estimators:
        streamed, batch = _run(est, args.sigma_u2, "streamed"), _run(est, args.sigma_u2, "batch")
        same = streamed["design"] == batch["design"]
        s_gb, b_gb = streamed["maxrss_kib"] / 2**20, batch["maxrss_kib"] / 2**20
        print(
            f"{est:6s} N up to {streamed['N_max']}: peak {s_gb:.2f} GiB streamed, {b_gb:.2f} GiB in one batch "
            f"(ratio {s_gb / b_gb:.2f}); {streamed['seconds']:.1f} s against {batch['seconds']:.1f} s; same design: {same}"
        )
        figures[est] = {"streamed_gib": s_gb, "batch_gib": b_gb, "streamed_s": streamed["seconds"],
                        "batch_s": batch["seconds"], "same_design": same, "N_max": streamed["N_max"]}  # fmt: skip
        rows.append((
            f"output design peak memory, {est}, examples/plant_output.yaml, sigma_u2 = {args.sigma_u2:g}, N up to "
            f"{streamed['N_max']}: streamed / one batch",
            f"{s_gb:.2f} / {b_gb:.2f} GiB = {s_gb / b_gb:.2f} (same design: {same})",
        ))  # fmt: skip
    if args.record:
        from record import write

        print(f"  wrote {write('bench_output_memory', figures, rows, argv)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
