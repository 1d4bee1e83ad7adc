"""The LWE scheme in the environment: the design example's dimension, its modulus, and the
time of one environment step on the ciphertext backend against the ideal backend.

The environment is the design example (preset ``paper-example``) with ``scheme="lwe"``; the key
length (the dimension n) is the one the environment designs for lambda* under the scheme's
baseline cost model (``core-svp``, priced at the int64 ceiling modulus). The loop's Delta must be
small enough for the modulus to fit the int64 arithmetic: the script reports the largest
power-of-two Delta that is accepted, then times ``--steps`` steps of both backends (same seed;
their observations are compared bit for bit).

Usage::

    python benchmarks/bench_lwe_loop.py [--steps 200]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv  # noqa: E402
from encctl_gym.errors import ParameterError  # noqa: E402


def _env(delta: int, crypto: str, steps: int) -> EncryptedLTIAttackEnv:
    return EncryptedLTIAttackEnv(
        config={
            "preset": "paper-example",
            "scheme": "lwe",
            "crypto": crypto,
            "crypto_seed": 1,
            "delta": delta,
            "max_samples": steps,
        }
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200, help="environment steps timed per backend (default 200)")
    args = parser.parse_args(argv)
    if args.steps < 1:
        print(f"bench_lwe_loop: --steps must be >= 1, got {args.steps}", file=sys.stderr)
        return 2
    delta, refused = 4096, []
    while True:
        try:
            _env(delta, "ideal", args.steps)
            break
        except ParameterError as exc:
            refused.append((delta, str(exc).split(":")[1].strip() if ":" in str(exc) else str(exc)))
            delta //= 2
    for d, why in refused:
        print(f"Delta = {d}: refused ({why})")
    runs, seconds = {}, {}
    for crypto in ("ideal", "elgamal"):
        env = _env(delta, crypto, args.steps)
        obs, _ = env.reset(seed=0)
        rng, rows = np.random.default_rng(0), [obs]
        t0 = time.perf_counter()
        for _ in range(args.steps):
            obs, _, term, trunc, _ = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
            rows.append(obs)
            if term or trunc:
                break
        seconds[crypto] = (time.perf_counter() - t0) / (len(rows) - 1)
        runs[crypto] = rows
        if crypto == "elgamal":
            p = env.unwrapped.loop.plant.params
            print(
                f"Delta = {delta}: n = {p.n}, log2 q = {math.log2(p.q):.2f}, t = {p.t}, lambda = {env.unwrapped.params.security_parameter}"
            )
    same = len(runs["ideal"]) == len(runs["elgamal"]) and all(
        np.array_equal(a, b) for a, b in zip(runs["ideal"], runs["elgamal"])
    )
    print(f"steps: {len(runs['elgamal']) - 1}; observations bit-identical: {same}")
    print(
        f"seconds per step: ciphertext backend {seconds['elgamal']:.4g}, ideal {seconds['ideal']:.4g}, ratio {seconds['elgamal'] / seconds['ideal']:.1f}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
