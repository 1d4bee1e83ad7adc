"""Time of the lattice attacks on LWE (encctl_gym.cryptanalysis.lattice_lwe) against the dimension.

For each dimension n (q = 3329, eta = 2, m = n) it breaks a few seeded keys sharing one public
matrix with each attack (every secret checked), prints the cost model's block size beside the
measured one, the precomputation, the first key and a later key, fits ``log2 T = a + b n`` to the
primal attack's time per key and to the BDD attack's precomputation, and prints the calibration
constants ``LLL_SECONDS`` and ``BKZ_SECONDS`` of the breakers' time estimate as measured now,
beside the documented ones. The rows are the table of ``docs/lwe.md``.

Usage::

    python benchmarks/bench_lattice_lwe.py                      # n = 30 ... 100, 3 keys
    python benchmarks/bench_lattice_lwe.py --dimensions 30 40 --keys 2
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from encctl_gym.cryptanalysis import lattice_lwe as L  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dimensions", type=int, nargs="+", default=[30, 40, 50, 60, 70, 80, 90, 100])
    parser.add_argument("--attacks", nargs="+", default=["primal", "bdd"], choices=list(L.LWE_BREAKERS))
    parser.add_argument("--keys", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    rows: list[L.AttackTiming] = []
    print("| attack | n | model beta | measured beta | precomputation (s) | first key (s) | later key (s) |")
    print("|---|---|---|---|---|---|---|")
    for n in args.dimensions:
        for attack in args.attacks:
            r = L.time_attack(attack, n, keys=args.keys, seed=args.seed + n)
            rows.append(r)
            print(
                f"| {r.attack} | {r.n} | {r.model_beta} | {r.measured_beta} | {r.precomputation_seconds:.3g} | "
                f"{r.first_key_seconds:.3g} | {r.mean_later_seconds:.3g} |",
                flush=True,
            )
    primal = [r for r in rows if r.attack == "primal"]
    if len(primal) >= 2:
        a, b = L.fit_exponential([r.n for r in primal], [(r.first_key_seconds + r.mean_later_seconds) / 2 for r in primal])
        print(f"primal, time per key: log2 T = {a:.2f} + {b:.4f} n (doubles every {1 / b:.1f} dimensions)")
    bdd = [r for r in rows if r.attack == "bdd"]
    if len(bdd) >= 2:
        a, b = L.fit_exponential([r.n for r in bdd], [r.first_total for r in bdd])
        print(f"bdd, precomputation + first key: log2 T = {a:.2f} + {b:.4f} n (doubles every {1 / b:.1f} dimensions)")
        print(f"bdd, later key: median {statistics.median(r.mean_later_seconds for r in bdd):.3g} s")
    # calibration of the estimate LLL_SECONDS d^4 + BKZ_SECONDS d^3 2^(0.2 beta), on the primal rows
    lll = [(r.first_key_seconds + r.mean_later_seconds) / 2 / (2 * r.n + 1) ** 4 for r in primal if r.model_beta == 2]
    if lll:
        c_lll = statistics.median(lll)
        bkz = [
            ((r.first_key_seconds + r.mean_later_seconds) / 2 - c_lll * (2 * r.n + 1) ** 4)
            / ((2 * r.n + 1) ** 3 * 2 ** (0.2 * r.model_beta))
            for r in primal
            if r.model_beta > 2
        ]
        print(f"LLL_SECONDS measured {c_lll:.3g} (documented {L.LLL_SECONDS:g})")
        if bkz:
            print(f"BKZ_SECONDS measured {statistics.median(bkz):.3g} (documented {L.BKZ_SECONDS:g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
