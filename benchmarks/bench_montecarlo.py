"""Benchmark: the batched Monte Carlo engine against a straightforward loop.

Workload (reduced, the same for both): one Figure 1 panel (``A = 0.7071 I``, ``B = I``,
``sigma_w2 = 0.1``, ``sigma_u2 = 10``), ``RUNS`` runs, the error ``epsilon(N)`` (Definition
def:error) on a log grid of ``N`` up to ``N_MAX``.

* batched: :func:`encctl_gym.sim.montecarlo.gaussian_attack_errors` (all runs simulated at once,
  errors on the whole grid from running Gram matrices / QR, one pass over the data);
* loop: one run at a time, the plant stepped with ``LinearPlant.next_state``, and one
  ``numpy.linalg.lstsq`` per ``N`` on the prefix (eq:estimate from scratch).

Both draw the same random numbers (the loop re-uses the per-run streams of
``simulate_gaussian_attack``), so their errors must agree; the script checks that and prints
both times and their ratio, measured in this one run.

Usage: ``python benchmarks/bench_montecarlo.py [--runs R] [--n-max N] [--points K] [--record]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

if __package__ in (None, ""):
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np

from encctl_gym.parallel import as_seed_sequence
from encctl_gym.sim.montecarlo import gaussian_attack_errors, log_grid
from encctl_gym.sim.plant import LinearPlant


def loop_errors(plant: LinearPlant, grid: np.ndarray, runs: int, sigma_u2: float, seed: int) -> np.ndarray:
    """The straightforward computation: per run, step the plant, then one lstsq per N."""
    n, m = plant.n, plant.m
    N_max = int(grid[-1])
    truth = np.concatenate([plant.A, plant.B], axis=1)
    out = np.empty((runs, grid.size))
    for r, child in enumerate(as_seed_sequence(seed).spawn(runs)):
        g_x, g_w, g_u = (np.random.default_rng(s) for s in child.spawn(3))
        x = np.empty((N_max, n))
        x[0] = np.sqrt(plant.sigma_x2) * g_x.standard_normal(n)
        w = np.sqrt(plant.sigma_w2) * g_w.standard_normal((N_max - 1, n))
        u = np.sqrt(sigma_u2) * g_u.standard_normal((N_max, m))
        for t in range(N_max - 1):
            x[t + 1] = plant.next_state(x[t], u[t], w[t])
        for k, N in enumerate(grid):
            D = np.concatenate([x[: N - 1], u[: N - 1]], axis=1)
            theta = np.linalg.lstsq(D, x[1:N], rcond=None)[0].T
            out[r, k] = np.sum((truth - theta) ** 2) / (n * (n + m))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().splitlines()[0])
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--n-max", type=int, default=5000)
    parser.add_argument("--points", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--record", action="store_true", help="record the figures for the README table")
    args = parser.parse_args(argv)
    plant = LinearPlant(0.7071 * np.eye(4), np.eye(4), sigma_w2=0.1)
    grid = log_grid(plant.n + plant.m + 1, args.n_max, args.points)
    print(f"workload: n = m = 4, {args.runs} runs, {grid.size} sample sizes N in [{grid[0]}, {grid[-1]}]")

    gaussian_attack_errors(plant, sample_sizes=grid[:3], runs=2, sigma_u2=10.0, seed=args.seed)  # warm-up
    t0 = time.perf_counter()
    batched = gaussian_attack_errors(plant, sample_sizes=grid, runs=args.runs, sigma_u2=10.0, seed=args.seed)
    t_batched = time.perf_counter() - t0

    t0 = time.perf_counter()
    looped = loop_errors(plant, grid, args.runs, 10.0, args.seed)
    t_loop = time.perf_counter() - t0

    dev = float(np.max(np.abs(batched - looped) / looped))
    print(f"batched engine : {t_batched:8.3f} s")
    print(f"straight loop  : {t_loop:8.3f} s")
    print(f"speed-up       : {t_loop / t_batched:8.1f} x")
    print(f"max relative difference of the errors: {dev:.1e}")
    if not dev < 1e-6:
        print("MISMATCH between the batched engine and the loop", file=sys.stderr)
        return 1
    if args.record:
        from record import write

        write(
            "bench_montecarlo",
            {"batched_s": t_batched, "loop_s": t_loop, "max_relative_difference": dev},
            [
                (
                    f"batched Monte Carlo engine vs a one-`lstsq`-per-N loop ({args.runs} runs, {grid.size} sample sizes up to {grid[-1]})",
                    f"{t_loop / t_batched:.1f}x (same errors to {dev:.0e})",
                )
            ],
            argv,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
