"""Subspace identification on a batch of runs: encctl_gym.ident.subspace against nfoursid.

Both run the same N4SID (PO-MOESP instruments, oblique projection, state sequence, least squares)
on the same 100 runs of a 3-state, 2-input, 2-output plant; the script prints the largest relative
difference of their Markov parameters (the same estimate to rounding) and the ratio of their
times, measured in this one run (paired, alternating, best of three each).

    python benchmarks/bench_subspace.py [--runs 100] [--samples 1000] [--sippy]

Needs nfoursid (pip install nfoursid). With ``--sippy`` (pip install sippy-unipi) it also prints
the median Markov-parameter error of SIPPY's N4SID, MOESP and CVA (a different, weighted
algorithm) against this package's N4SID and PO-MOESP on 10 runs of N = 2000 (order 3, 10 block
rows), where both are not the same algorithm and only their accuracy can be compared.
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
    parser.add_argument("--sippy", action="store_true", help="also compare accuracy with SIPPY's methods")
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
    if args.sippy:
        compare_sippy()


def compare_sippy() -> None:
    """Median Markov error of SIPPY's methods and of this package's on the same 10 runs."""
    import warnings

    from sippy_unipi import system_identification

    from encctl_gym.ident.subspace import markov_error, moesp, n4sid

    true, u, y = simulate(10, 2000)
    rows = {
        "n4sid (this package)": markov_error(true, n4sid(u, y, order=3, block_rows=10)),
        "moesp (this package, PO-MOESP)": markov_error(true, moesp(u, y, order=3, block_rows=10)),
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for method in ("N4SID", "MOESP", "CVA"):
            errs = []
            for r in range(u.shape[0]):
                s = system_identification(y[r].T, u[r].T, method, SS_fixed_order=3, SS_f=10, SS_p=10)
                errs.append(markov_error(true, (s.A, s.B, s.C, s.D)))
            rows[f"{method} (SIPPY)"] = np.asarray(errs)
    for name, e in rows.items():
        print(f"  {name:32s} median Markov error {float(np.median(e)):.3g}")


if __name__ == "__main__":
    main()
