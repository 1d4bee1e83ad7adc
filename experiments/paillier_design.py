"""The design example of Section "Numerical Simulation" with Paillier keys: the modulus length
k* per factoring cost model, beside ElGamal's key length, with a fresh modulus every K steps,
and the defender's measured cost per step at each k*.

The budget is the paper's, ``Upsilon tau_c = 442e15 FLOPS x 31536e4 s``, and the sample size its
``N* = 13159``. With rotation every K steps the eavesdropper's N* samples lie under
``ceil(N*/K)`` moduli, each of which must be factored (nothing is shared between moduli except
through the factory's and batch NFS's amortisation, which the models carry). The defender's cost
per step is measured here: one step of :class:`~encctl_gym.crypto.paillier_controller.PaillierLinearController`
(a 4 x 4 controller: 4 encryptions, the server's products, 4 decryptions) plus one KeyGen every
K steps (:func:`~encctl_gym.crypto.paillier.measure_keygen_seconds`, off the control path).

Usage: ``python experiments/paillier_design.py [--steps S] [--repeats R]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from encctl_gym.crypto.paillier import measure_keygen_seconds
from encctl_gym.crypto.paillier_controller import PaillierLinearController
from encctl_gym.security.cost_models import FACTORING_MODELS, GUILLEVIC_CORRECTION, deciphering_model, design_modulus_lengths

N_STAR = 13159
BUDGET = Fraction(442 * 10**15 * 31536 * 10**4)
PERIODS = (1, 10, 100, N_STAR)


def step_seconds(bits: int, steps: int) -> float:
    """Mean wall seconds of one control step at ``bits`` bits (4 x 4 controller, no rotation)."""
    ctl = PaillierLinearController(np.eye(4) * 0.5, bits, 2.0**16, 10.0, rng=1)
    x = np.array([1.0, -2.0, 0.5, 3.0])
    ctl.step(x)
    t0 = time.perf_counter()
    for _ in range(steps):
        ctl.step(x)
    return (time.perf_counter() - t0) / steps


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    print(f"budget Upsilon tau_c = 2^{math.log2(BUDGET):.3f} operations, N* = {N_STAR}")
    print("| rotation K | moduli ceil(N*/K) | " + " | ".join(FACTORING_MODELS) + " | (k*, bits; GNFS correction 0 / 11.91)")
    print("|---:|---:|" + "---:|" * len(FACTORING_MODELS))
    sizes: set[Any] = set()
    for K in PERIODS:
        keys = -(-N_STAR // K)
        k0 = design_modulus_lengths(keys, BUDGET)
        k1 = design_modulus_lengths(keys, BUDGET, gnfs_correction=GUILLEVIC_CORRECTION)
        sizes.update(k0.values())
        print(f"| {K} | {keys} | " + " | ".join(f"{k0[m]} / {k1[m]}" for m in FACTORING_MODELS) + " |")
    eg = {m: deciphering_model(m).minimum_key_length(N_STAR, BUDGET) for m in ("paper", "precomputation")}
    print(f"ElGamal (dynamic keys, one group): paper {eg['paper']}, precomputation {eg['precomputation']} bits")
    print()
    print("| k bits | step s (4x4) | KeyGen s (mean) | step + KeyGen/K for K = 1, 10, 100 |")
    print("|---:|---:|---:|---|")
    for bits in sorted(sizes):
        s = step_seconds(bits, args.steps)
        g = measure_keygen_seconds(bits, args.repeats, rng=bits).mean
        print(f"| {bits} | {s:.4g} | {g:.4g} | " + ", ".join(f"{s + g / K:.4g}" for K in (1, 10, 100)) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
