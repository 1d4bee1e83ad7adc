"""Speed of EncryptedLTIAttack-v0, measured in one run (ratios, since machines are noisy).

Prints:

1. the single environment's steps per second (ideal backend, through ``gymnasium.make``)
   against gymnasium's ``Pendulum-v1`` under the same wrappers (target: ratio >= 1);
2. the native vector environment's environment-steps per second at 1024 copies against the
   single environment's (target: >= 50x), on one core and with ``parallel=True`` (all cores);
3. the ElGamal backend's time per step at 712 bits against the crypto floor: the time of one
   ``gmpy2.powmod`` with a full-size exponent at that size, measured in the same run.

Usage: ``python benchmarks/bench_env.py [--quick]``.
"""

from __future__ import annotations

import argparse
import time

import gmpy2
import gymnasium as gym
import numpy as np

import encctl_gym  # noqa: F401  (registers the environment)
from encctl_gym.crypto.group import shipped_group
from encctl_gym.envs import ENV_ID
from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv

CONFIG = {"preset": "paper-example", "gamma_opt": False}


def steps_per_second(env: gym.Env, actions: np.ndarray, repeats: int) -> float:
    """Best of ``repeats`` timed passes over ``actions`` (resetting at episode ends)."""
    best = 0.0
    for _ in range(repeats):
        env.reset(seed=0)
        t0 = time.perf_counter()
        for a in actions:
            _, _, te, tr, _ = env.step(a)
            if te or tr:
                env.reset()
        best = max(best, len(actions) / (time.perf_counter() - t0))
    return best


def vector_steps_per_second(num_envs: int, steps: int, repeats: int, parallel: bool = False) -> float:
    venv = EncryptedLTIAttackVectorEnv(num_envs=num_envs, config=CONFIG, parallel=parallel)
    rng = np.random.default_rng(0)
    acts = np.clip(rng.normal(0, 0.25, (steps, num_envs, venv.params.m)), -1, 1).astype(np.float32)
    best = 0.0
    for _ in range(repeats):
        venv.reset(seed=0)
        for a in acts[:20]:  # past the start-up of the recursive least squares
            venv.step(a)
        t0 = time.perf_counter()
        for a in acts:
            venv.step(a)
        best = max(best, num_envs * steps / (time.perf_counter() - t0))
    return best


def powmod_seconds(bits: int, reps: int = 200) -> float:
    g = shipped_group(bits)
    p, base = gmpy2.mpz(g.p), gmpy2.mpz(g.g)
    e = gmpy2.mpz(g.q - 12345)
    t0 = time.perf_counter()
    for _ in range(reps):
        gmpy2.powmod(base, e, p)
    return (time.perf_counter() - t0) / reps


def elgamal_seconds_per_step(steps: int) -> float:
    env = gym.make(ENV_ID, config={**CONFIG, "crypto": "elgamal", "max_samples": max(steps + 1, 16)})
    env.reset(seed=0)
    acts = np.clip(np.random.default_rng(1).normal(0, 0.25, (steps, 4)), -1, 1).astype(np.float32)
    t0 = time.perf_counter()
    for a in acts:
        env.step(a)
    return (time.perf_counter() - t0) / steps


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer steps (a smoke test)")
    args = parser.parse_args(argv)
    n_single = 2000 if args.quick else 20000
    n_vec = 20 if args.quick else 200
    repeats = 1 if args.quick else 3

    rng = np.random.default_rng(0)
    pend = gym.make("Pendulum-v1")
    ours = gym.make(ENV_ID, config=CONFIG)
    pend_acts = rng.uniform(-2, 2, (n_single, 1)).astype(np.float32)
    our_acts = np.clip(rng.normal(0, 0.25, (n_single, 4)), -1, 1).astype(np.float32)
    steps_per_second(ours, our_acts[:50], 1)  # warm-up (table build, compilation)
    pend_sps = steps_per_second(pend, pend_acts, repeats)
    our_sps = steps_per_second(ours, our_acts, repeats)
    print(f"single env (ideal, paper-example)  : {our_sps:12,.0f} steps/s")
    print(f"Pendulum-v1 (same wrappers)         : {pend_sps:12,.0f} steps/s")
    print(f"ratio ours / Pendulum               : {our_sps / pend_sps:12.2f}   (target >= 1)")

    vec_sps = vector_steps_per_second(1024, n_vec, repeats)
    print(f"vector env, 1024 copies (1 core)    : {vec_sps:12,.0f} env-steps/s")
    print(f"ratio vector / single               : {vec_sps / our_sps:12.1f}   (target >= 50)")
    par_sps = vector_steps_per_second(1024, n_vec, repeats, parallel=True)
    print(f"vector env, 1024 copies, parallel   : {par_sps:12,.0f} env-steps/s  (all cores)")
    print(f"ratio parallel vector / single      : {par_sps / our_sps:12.1f}")

    floor = powmod_seconds(712)
    per_step = elgamal_seconds_per_step(5 if args.quick else 30)
    print(f"elgamal backend, 712 bits           : {per_step * 1e3:12.2f} ms/step")
    print(f"one gmpy2.powmod at 712 bits        : {floor * 1e6:12.1f} us")
    print(f"step / powmod (crypto floor)        : {per_step / floor:12.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
