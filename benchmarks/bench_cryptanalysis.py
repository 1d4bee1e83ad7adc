"""Benchmark of the key breakers (encctl_gym.cryptanalysis) against PARI's znlog.

For each size it breaks the same dynamic-key sequence with every breaker and prints the
first-key time ``T_first`` (precomputation + first key) and the mean time of a later key
``T_1``, each as a ratio to PARI's at the same size, measured in this one run (CPU time of this
process, which other jobs on a shared machine inflate less than wall time). With
``--repeats N`` each size is run N times on N fresh groups, the breakers interleaved within a
repeat, and the ratios are taken within each repeat (paired): the table shows the median ratio
and, in brackets, the smallest and largest, so the noise of a shared machine is visible. It
also prints the calibration constants of the breakers' cost models as measured now (seconds per
walk step, per baby step, per sieved cell of the index calculus), beside the documented values
in the modules, so the constants can be checked on another machine.

Usage::

    python benchmarks/bench_cryptanalysis.py                  # 32 ... 96 bits, 8 keys per size
    python benchmarks/bench_cryptanalysis.py --quick          # 32 and 48 bits, 4 keys
    python benchmarks/bench_cryptanalysis.py --sizes 64 80 96 --repeats 3 --breakers pari index-calculus
    python benchmarks/bench_cryptanalysis.py --record         # also write benchmarks/results/ for the README table
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from encctl_gym.cryptanalysis import bsgs, index_calculus, pari_available, rho
from encctl_gym.cryptanalysis.keys import key_sequence
from encctl_gym.cryptanalysis.registry import get_breaker
from encctl_gym.cryptanalysis.sequence import break_sequence
from encctl_gym.crypto import arith
from encctl_gym.crypto.group import generate_safe_prime_group

GENERIC = ("bsgs", "rho", "rho-multi")


def calibrate() -> None:
    """Measure the cost-model constants now and print them beside the documented ones."""
    grp = generate_safe_prime_group(40, rng=1)
    hs, _, _ = key_sequence(grp, 2, 1)
    pre = get_breaker("rho", rng=1).precompute(grp)
    key = pre.break_key(hs[0])
    step = key.cost.cpu_seconds / key.cost.operations["group_operations"]
    print(f"rho: {step * 1e9:.0f} ns per walk step (documented rho.SECONDS_PER_STEP = {rho.SECONDS_PER_STEP * 1e9:.0f} ns)")
    table = get_breaker("bsgs").precompute(grp)
    per_baby = table.cost.cpu_seconds / table.m
    print(
        f"bsgs: {per_baby * 1e9:.0f} ns per baby step (documented bsgs.SECONDS_PER_STEP = {bsgs.SECONDS_PER_STEP * 1e9:.0f} ns)"
    )
    get_breaker("index-calculus", rng=1).precompute(generate_safe_prime_group(40, rng=1))  # load the compiled sieve
    for bits in (64, 80):
        grp = generate_safe_prime_group(bits, rng=1)
        ic = get_breaker("index-calculus", rng=1)
        pre = ic.precompute(grp)
        bound = pre.bound
        model = index_calculus.cost_model(bits, bound)
        phases = pre.phase_cpu_seconds
        rows, half = index_calculus.sieve_region(bits)
        cell = phases["relations"] / (pre.cost.operations["sieved_lattices"] * 2 * rows * half)
        print(
            f"index-calculus {bits} bits (B = {bound}): {cell * 1e9:.2f} ns per sieved cell (documented "
            f"CELL_SECONDS = {index_calculus.CELL_SECONDS * 1e9:.2f} ns); relations {phases['relations']:.2f} s (model "
            f"{model['relations']:.2f} s), linear algebra {phases['linear_algebra']:.2f} s (model "
            f"{model['linear_algebra']:.2f} s)"
        )


def _med(values: list[float]) -> float:
    return float(statistics.median(values))


def _span(values: list[float]) -> str:
    return f"{_med(values):.3g} [{min(values):.3g}, {max(values):.3g}]"


def bench(sizes: list[int], keys: int, repeats: int = 1, only: list[str] | None = None) -> list[dict]:
    """Each breaker's first-key and per-key CPU time on the same keys, against the reference
    (PARI if installed), ``repeats`` times per size on fresh groups with the breakers interleaved;
    printed (median ratio and range), and returned as rows (one per breaker and size, with the
    per-repeat figures)."""
    breakers = ["pari"] if pari_available() else []
    breakers += ["index-calculus", "token-chain", *GENERIC]
    if only:
        breakers = [b for b in breakers if b in only]
    if not pari_available():
        print(
            "cypari is not installed: ratios are against the index calculus instead of PARI "
            "(pip install 'encctl-gym[cryptanalysis]')"
        )
    reference = breakers[0]
    rows = []
    print(
        f"{'bits':>5} {'breaker':<15} {'T_first (s)':>12} {'T_1 (s)':>12} {'T_first/ref':>22} {'T_1/ref':>22}"
        f"   (ref = {reference}, same keys, paired within each of {repeats} repeat(s); median [min, max])"
    )
    for bits in sizes:
        runs: dict[str, list[tuple[float, float]]] = {}
        for rep in range(repeats):
            grp = generate_safe_prime_group(bits, rng=bits if rep == 0 else 1000 * bits + rep)
            hs, secrets, tokens = key_sequence(grp, keys, arith.seeded_random(bits + 1 + rep))
            for name in breakers:
                if name in GENERIC and bits > 44:
                    continue
                kwargs = {"inner": "index-calculus"} if name == "token-chain" else {}
                report = break_sequence(
                    get_breaker(name, rng=2 + rep, **kwargs), grp, hs, tokens=tokens if name == "token-chain" else None
                )
                assert report.secrets == secrets  # every key recovered and checked (g^s = h)
                t = report.key_seconds("cpu")
                runs.setdefault(name, []).append((report.precomputation.cpu_seconds + t[0], float(t[1:].mean())))
        ref = runs[reference]
        for name, times in runs.items():
            first = [f / r[0] for (f, _), r in zip(times, ref)]
            later = [k / r[1] for (_, k), r in zip(times, ref)]
            print(
                f"{bits:>5} {name:<15} {_med([t[0] for t in times]):12.4g} {_med([t[1] for t in times]):12.4g} "
                f"{_span(first):>22} {_span(later):>22}"
            )
            rows.append(
                {
                    "bits": bits,
                    "breaker": name,
                    "reference": reference,
                    "first_s": _med([t[0] for t in times]),
                    "per_key_s": _med([t[1] for t in times]),
                    "first_ratio": _med(first),
                    "per_key_ratio": _med(later),
                    "first_ratios": first,
                    "per_key_ratios": later,
                    "repeats": repeats,
                }
            )
        sys.stdout.flush()
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="two sizes, 4 keys")
    parser.add_argument("--record", action="store_true", help="record the figures for the README table")
    parser.add_argument("--sizes", type=int, nargs="+", help="bit lengths of p (default 32 40 48 64 80 96)")
    parser.add_argument("--keys", type=int, help="keys per sequence (default 8, --quick 4)")
    parser.add_argument("--repeats", type=int, default=1, help="fresh groups per size, breakers interleaved (default 1)")
    parser.add_argument("--breakers", nargs="+", help="only these breakers (the first is the reference)")
    parser.add_argument("--no-calibrate", dest="calibrate", action="store_false", help="skip the calibration lines")
    args = parser.parse_args()
    if args.repeats < 1 or (args.keys is not None and args.keys < 2):
        parser.error("--repeats must be >= 1 and --keys >= 2")
    t0 = time.perf_counter()
    if args.calibrate:
        calibrate()
    sizes = args.sizes or ([32, 48] if args.quick else [32, 40, 48, 64, 80, 96])
    rows = bench(sizes, args.keys or (4 if args.quick else 8), args.repeats, args.breakers)
    print(f"done in {time.perf_counter() - t0:.1f} s")
    if args.record:
        from record import write

        largest = max(r["bits"] for r in rows)
        ic = next(r for r in rows if r["bits"] == largest and r["breaker"] == "index-calculus")
        write(
            "bench_cryptanalysis",
            {"rows": rows},
            [
                (
                    f"index calculus vs {ic['reference']} at {largest} bits (same keys, CPU time)",
                    f"first key {ic['first_s']:.3g} s ({ic['first_ratio']:.2g}x), each further key {ic['per_key_s'] * 1e3:.3g} ms "
                    f"({ic['per_key_ratio']:.2g}x)",
                )
            ],
            sys.argv[1:],
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
