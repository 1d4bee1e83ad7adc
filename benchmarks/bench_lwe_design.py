"""The LWE scheme for the paper's design example: the smallest dimension that meets lambda*.

For the design example (A = I/sqrt 2, B = I/2, n = m = 4, LQR gain Phi with Q = R = I), the
encoder scales Delta_x = 4096 and Delta_Phi = 256 and states within |x_j| <= 10, the modulus of
the LWE state feedback follows from its worst-case noise bound
(:func:`encctl_gym.crypto.lwe.controller_parameters`); this script finds, for each core-SVP
model, the smallest dimension n whose primal uSVP cost (m = n samples) reaches lambda* = 74 bits
(the paper's figure, PAPER_REPORTED) with
:func:`encctl_gym.security.cost_models.lattice.smallest_secure_dimension`, and times the plant's
and the server's work of one control step at that dimension (this machine).

Usage::

    python benchmarks/bench_lwe_design.py [--bits 74] [--steps 50]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402
import scipy.linalg  # noqa: E402

from encctl_gym.crypto import lwe  # noqa: E402
from encctl_gym.presets import PAPER_REPORTED  # noqa: E402
from encctl_gym.security.cost_models import lattice as L  # noqa: E402

DELTA_X, DELTA_PHI, X_BOUND, ETA = 4096, 256, 10.0, 2


def design_gain() -> np.ndarray:
    A, B = np.eye(4) * math.sqrt(0.5), 0.5 * np.eye(4)
    P = scipy.linalg.solve_discrete_are(A, B, np.eye(4), np.eye(4))
    return -np.linalg.solve(np.eye(4) + B.T @ P @ B, B.T @ P @ A)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bits", type=float, default=float(PAPER_REPORTED["lam_star"]))
    parser.add_argument("--steps", type=int, default=50)
    args = parser.parse_args(argv)
    Phi = design_gain()

    def modulus(n: int) -> int:
        return lwe.controller_parameters(n, Phi, DELTA_X, DELTA_PHI, X_BOUND, ETA).q

    print("| core-SVP model | n | log2 q | t | beta | bits | seconds per control step |")
    print("|---|---|---|---|---|---|---|")
    for model in L.CORE_SVP_EXPONENTS:
        n, est = L.smallest_secure_dimension(modulus, L.binomial_sigma(ETA), args.bits, model=model)
        p = lwe.controller_parameters(n, Phi, DELTA_X, DELTA_PHI, X_BOUND, ETA)
        ctl = lwe.LWEController(p, Phi, DELTA_X, DELTA_PHI, X_BOUND, rng=1)
        x = np.array([0.3, -1.2, 2.0, 0.01])
        ctl.step(x)
        t0 = time.perf_counter()
        for _ in range(args.steps):
            ctl.step(x)
        per_step = (time.perf_counter() - t0) / args.steps
        print(f"| {model} | {n} | {math.log2(p.q):.2f} | {p.t} | {est.beta} | {est.bits(model):.1f} | {per_step:.3g} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
