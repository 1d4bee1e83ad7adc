"""Benchmark of the factoring breakers (Paillier keys): seconds per modulus against its bits,
and the calibration constants of their cost models as measured now.

For each size, ``--keys`` seeded Paillier moduli (a fresh modulus per key, as under rotation) are
factored by every factorer whose own cost model expects the job within ``--max-seconds``;
every factorisation is checked and every key checked by decrypting
(:func:`encctl_gym.cryptanalysis.paillier_keys.break_paillier_sequence`). The table prints the
mean and the median wall seconds per modulus (CPU seconds in brackets), then, per factorer,
the constant of its cost-model shape that the measured means give (the geometric mean over
the sizes of ``mean seconds / shape(bits)``), beside the constant in the module. The KeyGen time
per modulus length (the price of one rotation) is measured last.

Usage::

    python benchmarks/bench_factoring.py                         # 48 ... 128 bits, 6 keys
    python benchmarks/bench_factoring.py --sizes 64 96 --keys 3
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from encctl_gym.cryptanalysis import ecm, pari_factor, pollard_factor
from encctl_gym.cryptanalysis.factoring_registry import FACTORERS, get_factorer
from encctl_gym.cryptanalysis.paillier_keys import break_paillier_sequence, paillier_key_sequence
from encctl_gym.crypto import arith
from encctl_gym.crypto.paillier import measure_keygen_seconds
from encctl_gym.errors import BreakerError, BreakerLimitError, OptionalDependencyError

#: The documented constant of each factorer's cost model and its shape (seconds / constant).
CONSTANTS = {
    "rho-factor": ("RHO_SECONDS_PER_STEP", pollard_factor.RHO_SECONDS_PER_STEP),
    "ecm": ("ECM_SECONDS_CONSTANT", ecm.ECM_SECONDS_CONSTANT),
    "pari-factor": ("PARI_FACTOR_C", pari_factor.PARI_FACTOR_C),
}


def measure(sizes: list[int], keys: int, max_seconds: float, seed: int) -> list[dict]:
    """One row per (factorer, size) that ran: mean, median and CPU seconds per modulus."""
    rows = []
    for bits in sizes:
        pks = [pk for pk, _ in paillier_key_sequence(bits, keys, arith.seeded_random(seed + bits))]
        for name in FACTORERS:
            try:
                f = get_factorer(name, rng=seed, max_bits=max(bits, 16))
                f.check_time(bits, max_seconds, keys=keys)
                report = break_paillier_sequence(f, pks, rng=arith.seeded_random(seed))
            except (BreakerLimitError, OptionalDependencyError) as exc:
                rows.append({"factorer": name, "bits": bits, "skipped": str(exc).split(":")[0]})
                continue
            except BreakerError as exc:
                rows.append({"factorer": name, "bits": bits, "failed": str(exc)[:80]})
                continue
            t = report.key_seconds()
            cpu = [k.factorization.cost.cpu_seconds for k in report.keys]
            rows.append(
                {
                    "factorer": name,
                    "bits": bits,
                    "mean": float(t.mean()),
                    "median": float(statistics.median(t)),
                    "cpu": float(statistics.fmean(cpu)),
                    "expected": f.expected_seconds(bits),
                }
            )
            print(f"  {name:<12} {bits:>4} bits: mean {t.mean():.4g} s", file=sys.stderr, flush=True)
    return rows


def fitted(rows: list[dict]) -> dict[str, float]:
    """Per factorer with a constant: the geometric mean of ``constant * measured / expected``."""
    out = {}
    for name, (_, const) in CONSTANTS.items():
        logs = [
            math.log(const * r["mean"] / r["expected"]) for r in rows if r["factorer"] == name and "mean" in r and r["mean"] > 0
        ]
        if logs:
            out[name] = math.exp(statistics.fmean(logs))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[48, 64, 80, 96, 112, 128])
    ap.add_argument("--keys", type=int, default=6)
    ap.add_argument("--max-seconds", type=float, default=300.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--keygen-sizes", type=int, nargs="+", default=[1024, 2048, 3072])
    args = ap.parse_args(argv)
    rows = measure(args.sizes, args.keys, args.max_seconds, args.seed)
    print(f"| factorer | bits | mean s/modulus | median | CPU s | model s | ({args.keys} keys per size, seed {args.seed})")
    print("|---|---:|---:|---:|---:|---:|")
    for r in rows:
        if "mean" in r:
            print(
                f"| {r['factorer']} | {r['bits']} | {r['mean']:.4g} | {r['median']:.4g} | {r['cpu']:.4g} | {r['expected']:.3g} |"
            )
        else:
            print(f"| {r['factorer']} | {r['bits']} | {r.get('skipped') or r.get('failed')} | | | |")
    print()
    for name, value in fitted(rows).items():
        label, const = CONSTANTS[name]
        print(f"{name}: {label} measured now {value:.3g} (module: {const:.3g})")
    print()
    print("| modulus bits | KeyGen mean s | median s | stdev s | (10 KeyGens each: the price of one rotation)")
    print("|---:|---:|---:|---:|")
    for bits in args.keygen_sizes:
        t = measure_keygen_seconds(bits, 10, rng=args.seed)
        print(f"| {bits} | {t.mean:.4g} | {t.median:.4g} | {t.stdev:.3g} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
