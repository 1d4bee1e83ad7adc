"""Paired speed of the environment against another revision of the package (a regression check).

The package at ``--base`` (a git revision, checked out into a temporary worktree) and the working
tree are run in turn, A B A B ..., each in a fresh process, for ``--pairs`` pairs. Each run
prints the single environment's steps per second (ideal backend, the design example, through
``gymnasium.make``) and the native vector environment's environment-steps per second at 1024
copies, both timed inside the process (imports and the numba compilation are not counted; a
first full-size run per side, not counted, warms the compiled kernels' cache). The ratio working tree / base is taken
pair by pair, so a drift of the machine's speed between pairs cancels; the median over the
pairs and its range are printed.

Usage: ``python benchmarks/bench_regression.py [--base REV] [--pairs 7] [--quick]``. The default
base is ``HEAD~1``. A ratio below 1 is a slowdown of the working tree.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: The measurement each run performs (imports only ``encctl_gym``: any revision runs it).
PROBE = """
import sys, time
import numpy as np, gymnasium as gym
import encctl_gym  # noqa: F401
from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv
steps, vec_steps = int(sys.argv[1]), int(sys.argv[2])
rng = np.random.default_rng(0)
cfg = {"preset": "paper-example", "gamma_opt": False}
env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config=cfg)
acts = rng.uniform(-1, 1, (steps,) + env.action_space.shape).astype(np.float32)
env.reset(seed=0)
t = time.perf_counter()
for a in acts:
    _, _, term, trunc, _ = env.step(a)
    if term or trunc:
        env.reset()
single = steps / (time.perf_counter() - t)
venv = EncryptedLTIAttackVectorEnv(num_envs=1024, config=cfg)
venv.reset(seed=0)
va = rng.uniform(-1, 1, (vec_steps, 1024, venv.params.m)).astype(np.float32)
t = time.perf_counter()
for a in va:
    venv.step(a)
vector = vec_steps * 1024 / (time.perf_counter() - t)
venv.close()
print(single, vector)
"""


def run_probe(tree: Path, steps: int, vec_steps: int) -> tuple[float, float]:
    """One fresh process importing the package of ``tree``: (single steps/s, vector steps/s)."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    out = subprocess.run(
        [sys.executable, "-c", PROBE, str(steps), str(vec_steps)],
        env=env,
        capture_output=True,
        text=True,
        cwd=tempfile.gettempdir(),
    )
    if out.returncode != 0:
        raise SystemExit(f"bench_regression: the probe failed in {tree}:\n{out.stderr.strip().splitlines()[-1]}")
    single, vector = out.stdout.split()
    return float(single), float(vector)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python benchmarks/bench_regression.py", description=__doc__.splitlines()[0])
    parser.add_argument("--base", default="HEAD~1", help="the git revision to compare against (default HEAD~1)")
    parser.add_argument("--pairs", type=int, default=7, help="A B pairs (default 7)")
    parser.add_argument("--quick", action="store_true", help="short runs (a smoke test)")
    args = parser.parse_args(argv)
    if args.pairs < 1:
        print(f"bench_regression: --pairs must be >= 1, got {args.pairs}", file=sys.stderr)
        return 2
    steps, vec_steps = (2000, 20) if args.quick else (200_000, 1000)
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp) / "base"
        made = subprocess.run(
            ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(base), args.base], capture_output=True, text=True
        )
        if made.returncode != 0:
            print(f"bench_regression: cannot check out --base {args.base!r}: {made.stderr.strip()}", file=sys.stderr)
            return 2
        try:
            for tree in (ROOT, base):  # warm each side's compiled-kernel cache (every path a full run takes)
                run_probe(tree, steps, vec_steps)
            pairs = []
            for i in range(args.pairs):
                a, b = run_probe(ROOT, steps, vec_steps), run_probe(base, steps, vec_steps)
                pairs.append((a[0] / b[0], a[1] / b[1]))
                print(f"pair {i + 1}: single {a[0]:.0f} vs {b[0]:.0f} steps/s, vector {a[1]:.0f} vs {b[1]:.0f}", flush=True)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(base)], capture_output=True)
    for name, k in (("single env", 0), ("vector env (1024 copies)", 1)):
        r = [p[k] for p in pairs]
        print(
            f"{name}: working tree / {args.base} = {statistics.median(r):.3f} (median of {len(r)} pairs; min {min(r):.3f}, max {max(r):.3f})"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
