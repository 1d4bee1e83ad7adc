"""Benchmark of the key breakers (encctl_gym.cryptanalysis) against PARI's znlog.

For each size it breaks the same dynamic-key sequence with every breaker and prints the
first-key time ``T_first`` (precomputation + first key) and the mean time of a later key
``T_1``, each as a ratio to PARI's at the same size, measured in this one run (CPU time of this
process, which other jobs on a shared machine do not inflate). It also prints the calibration
constants of the breakers' cost models as measured now (seconds per walk step,
per baby step, per index-calculus smoothness trial), beside the documented values in the
modules, so the constants can be checked on another machine.

Usage::

    python benchmarks/bench_cryptanalysis.py            # 32 ... 80 bits, 8 keys per size
    python benchmarks/bench_cryptanalysis.py --quick    # 32 and 48 bits, 4 keys
    python benchmarks/bench_cryptanalysis.py --record   # also write benchmarks/results/ for the README table
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from encctl_gym.crypto import arith
from encctl_gym.crypto.group import generate_safe_prime_group
from encctl_gym.cryptanalysis import bsgs, index_calculus, pari_available, rho
from encctl_gym.cryptanalysis.keys import key_sequence
from encctl_gym.cryptanalysis.registry import get_breaker
from encctl_gym.cryptanalysis.sequence import break_sequence

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
    print(f"bsgs: {per_baby * 1e9:.0f} ns per baby step (documented bsgs.SECONDS_PER_STEP = "
          f"{bsgs.SECONDS_PER_STEP * 1e9:.0f} ns)")
    for bits in (64, 80):
        grp = generate_safe_prime_group(bits, rng=1)
        ic = get_breaker("index-calculus", rng=1)
        pre = ic.precompute(grp)
        bound = pre.bound
        model = index_calculus.cost_model(bits, bound)
        phases = pre.phase_cpu_seconds
        trial = phases["relations"] / pre.cost.operations["smoothness_tests"]
        documented = index_calculus.TRIAL_BASE + index_calculus.TRIAL_PER_BIT * bits + index_calculus.TRIAL_PER_BOUND * bound
        print(f"index-calculus {bits} bits (B = {bound}): {trial * 1e6:.2f} us per smoothness trial (model "
              f"{documented * 1e6:.2f} us); relations {phases['relations']:.2f} s (model "
              f"{model['relations']:.2f} s), linear algebra {phases['linear_algebra']:.2f} s (model "
              f"{model['linear_algebra']:.2f} s)")


def bench(sizes: list[int], keys: int) -> list[dict]:
    """Each breaker's first-key and per-key CPU time on the same keys, against the reference
    (PARI if installed); printed, and returned as rows."""
    breakers = ["pari"] if pari_available() else []
    breakers += ["index-calculus", "token-chain", *GENERIC]
    if not pari_available():
        print("cypari is not installed: ratios are against the index calculus instead of PARI "
              "(pip install 'encctl-gym[cryptanalysis]')")
    reference = breakers[0]
    rows = []
    print(f"{'bits':>5} {'breaker':<15} {'T_first (s)':>12} {'T_1 (s)':>12} {'T_first/ref':>12} {'T_1/ref':>10}"
          f"   (ref = {reference}, same keys, this run)")
    for bits in sizes:
        grp = generate_safe_prime_group(bits, rng=bits)
        hs, secrets, tokens = key_sequence(grp, keys, arith.seeded_random(bits + 1))
        ref = None
        for name in breakers:
            if name in GENERIC and bits > 44:
                continue
            kwargs = {"inner": "index-calculus"} if name == "token-chain" else {}
            report = break_sequence(get_breaker(name, rng=2, **kwargs), grp, hs,
                                    tokens=tokens if name == "token-chain" else None)
            assert report.secrets == secrets
            t = report.key_seconds("cpu")
            first, later = report.precomputation.cpu_seconds + t[0], float(t[1:].mean())
            if ref is None:
                ref = (first, later)
            print(f"{bits:>5} {name:<15} {first:12.4g} {later:12.4g} {first / ref[0]:12.3g} {later / ref[1]:10.3g}")
            rows.append({"bits": bits, "breaker": name, "reference": reference, "first_s": first, "per_key_s": later,
                         "first_ratio": first / ref[0], "per_key_ratio": later / ref[1]})
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="two sizes, 4 keys")
    parser.add_argument("--record", action="store_true", help="record the figures for the README table")
    args = parser.parse_args()
    t0 = time.perf_counter()
    calibrate()
    rows = bench([32, 48] if args.quick else [32, 40, 48, 64, 80], 4 if args.quick else 8)
    print(f"done in {time.perf_counter() - t0:.1f} s")
    if args.record:
        from record import write

        largest = max(r["bits"] for r in rows)
        ic = next(r for r in rows if r["bits"] == largest and r["breaker"] == "index-calculus")
        write("bench_cryptanalysis", {"rows": rows}, [
            (f"index calculus vs {ic['reference']} at {largest} bits (same keys, CPU time)",
             f"first key {ic['first_s']:.3g} s ({ic['first_ratio']:.2g}x), each further key {ic['per_key_s'] * 1e3:.3g} ms "
             f"({ic['per_key_ratio']:.2g}x)"),
        ], sys.argv[1:])
    return 0


if __name__ == "__main__":
    sys.exit(main())
