"""Subspace identification on a batch of runs: encctl_gym.ident.subspace against nfoursid.

Both run the same N4SID (PO-MOESP instruments, oblique projection, state sequence, least squares)
on the same 100 runs of a 3-state, 2-input, 2-output plant; the script prints the largest relative
difference of their Markov parameters (the same estimate to rounding) and the ratio of their
times, measured in this one run (paired, alternating, best of three each).

    python benchmarks/bench_subspace.py [--runs 100] [--samples 1000]

Needs nfoursid (pip install nfoursid).
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def simulate(R: int, N: int, seed: int = 1) -> tuple[tuple[np.ndarray, ...], np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    A = np.array([[0.7, 0.2, 0.0], [0.0, 0.5, 0.1], [0.0, 0.0, -0.4]])
    B = np.array([[1.0, 0.0], [0.0, 1.0], [0.5, 0.5]])
    C = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 1.0]])
    D = np.zeros((2, 2))
    u = rng.normal(size=(R, N, 2))
    x = np.zeros((R, 3))
    y = np.empty((R, N, 2))
    for t in range(N):
        y[:, t] = x @ C.T + 0.1 * rng.normal(size=(R, 2))
        x = x @ A.T + u[:, t] @ B.T + 0.1 * rng.normal(size=(R, 3))
    return (A, B, C, D), u, y


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=100)
    parser.add_argument("--samples", type=int, default=1000)
    args = parser.parse_args()
    import pandas as pd
    from nfoursid.nfoursid import NFourSID

    from encctl_gym.ident.subspace import markov_parameters, n4sid

    _, u, y = simulate(args.runs, args.samples)
    cols = ["u0", "u1", "y0", "y1"]

    def ours():
        return n4sid(u, y, order=3, block_rows=5)

    def theirs():
        out = []
        for r in range(u.shape[0]):
            m = NFourSID(
                pd.DataFrame(np.hstack([u[r], y[r]]), columns=cols),
                output_columns=cols[2:],
                input_columns=cols[:2],
                num_block_rows=5,
            )
            m.subspace_identification()
            out.append(m.system_identification(rank=3)[0])
        return out

    t_ours, t_theirs = [], []
    for _ in range(3):
        t0 = time.perf_counter()
        est = ours()
        t_ours.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        ref = theirs()
        t_theirs.append(time.perf_counter() - t0)
    diff = max(
        float(
            np.abs(
                markov_parameters(s.a, s.b, s.c, s.d, 10) - markov_parameters(est.A[r], est.B[r], est.C[r], est.D[r], 10)
            ).max()
            / np.abs(markov_parameters(s.a, s.b, s.c, s.d, 10)).max()
        )
        for r, s in enumerate(ref)
    )
    print(
        f"{args.runs} runs of N = {args.samples}: encctl_gym n4sid {min(t_ours):.3f} s, nfoursid {min(t_theirs):.3f} s, "
        f"ratio {min(t_theirs) / min(t_ours):.1f}x; largest relative Markov-parameter difference {diff:.1e}"
    )


if __name__ == "__main__":
    main()
