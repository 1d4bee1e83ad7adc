"""Speed of EncryptedLTIAttack-v0, measured in one run (ratios, since machines are noisy).

Prints:

1. the single environment's steps per second (ideal backend, through ``gymnasium.make``)
   against gymnasium's ``Pendulum-v1`` under the same wrappers (target: ratio >= 1);
2. the native vector environment's environment-steps per second at 1024 copies against the
   single environment's (target: >= 50x): as constructed by default (its helper thread draws
   the noise and catches up the Gram matrices while the main thread steps), with all the work
   on one thread (``helper_thread=False``), and with ``parallel=True``;
3. the ElGamal backend's time per step at 712 bits against the crypto floor: the time of one
   ``gmpy2.powmod`` with a full-size exponent at that size, measured in the same run;
4. the steps per second with each estimator other than least squares (``estimator`` key: on
   their compiled moment path, :class:`encctl_gym.ident.compiled.MomentKernels`, not fused),
   single and vector, against least squares (target: >= 0.1x single).

Usage: ``python benchmarks/bench_env.py [--quick] [--record]`` (``--record`` writes
``benchmarks/results/bench_env.json`` for the README table, :mod:`benchmarks.record`).
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


def steps_per_second(env: gym.Env, actions: np.ndarray) -> float:
    """One timed pass over ``actions`` from a fresh reset (resetting at episode ends)."""
    env.reset(seed=0)
    t0 = time.perf_counter()
    for a in actions:
        _, _, te, tr, _ = env.step(a)
        if te or tr:
            env.reset()
    return len(actions) / (time.perf_counter() - t0)


def vector_steps_per_second(venv: EncryptedLTIAttackVectorEnv, actions: np.ndarray) -> float:
    """One timed pass of ``venv`` over ``actions`` (steps, num_envs, m), after 20 start-up steps.

    The pass should be a multiple of the periodic work (noise drawn every 256 periods; Gram
    catch-up and exact refresh every 1024 columns), so that its cost is counted at its true
    average; the clock stops once the helper thread has finished what the pass gave it.
    """
    venv.reset(seed=0)
    for a in actions[:20]:  # past the start-up of the recursive least squares
        venv.step(a)
    t0 = time.perf_counter()
    for a in actions:
        venv.step(a)
    venv.episode.wait()
    return venv.num_envs * len(actions) / (time.perf_counter() - t0)


def powmod_seconds(bits: int, reps: int = 200) -> float:
    g = shipped_group(bits)
    p, base = gmpy2.mpz(g.p), gmpy2.mpz(g.g)
    e = gmpy2.mpz(g.q - 12345)
    t0 = time.perf_counter()
    for _ in range(reps):
        gmpy2.powmod(base, e, p)
    return (time.perf_counter() - t0) / reps


def elgamal_seconds_per_step(steps: int) -> float:
    env = gym.make(ENV_ID, config={**CONFIG, "crypto": "elgamal", "max_samples": max(steps + 4, 16)})
    env.reset(seed=0)
    acts = np.clip(np.random.default_rng(1).normal(0, 0.25, (steps + 2, 4)), -1, 1).astype(np.float32)
    for a in acts[:2]:  # compilation and first-use costs are not per-step costs
        env.step(a)
    t0 = time.perf_counter()
    for a in acts[2:]:
        env.step(a)
    return (time.perf_counter() - t0) / steps


def main(argv: list[str] | None = None) -> int:
    """Measure and print every figure; with ``--record`` write them for the README table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer steps (a smoke test)")
    parser.add_argument("--record", action="store_true", help="record the figures for the README table")
    args = parser.parse_args(argv)
    n_single = 2000 if args.quick else 20000
    n_vec = 64 if args.quick else 2 * 1024
    repeats = 1 if args.quick else 5
    num_envs = 1024

    best, our_acts, vec_acts = _throughput(n_single, n_vec, repeats, num_envs)
    our_sps, pend_sps, vec_sps, one_sps, par_sps = best["ours"], best["pend"], best["vec"], best["one"], best["par"]
    print(f"single env (ideal, paper-example)  : {our_sps:12,.0f} steps/s")
    print(f"Pendulum-v1 (same wrappers)         : {pend_sps:12,.0f} steps/s")
    print(f"ratio ours / Pendulum               : {our_sps / pend_sps:12.2f}   (target >= 1)")
    print(f"vector env, {num_envs} copies (default)   : {vec_sps:12,.0f} env-steps/s  ({n_vec} steps a pass)")
    print(f"ratio vector / single               : {vec_sps / our_sps:12.1f}   (target >= 50)")
    print(f"  the same on one thread            : {one_sps:12,.0f} env-steps/s  (helper_thread=False)")
    print(f"  ratio one-thread vector / single  : {one_sps / our_sps:12.1f}")
    print(f"  parallel=True (all cores)         : {par_sps:12,.0f} env-steps/s")
    print(f"  ratio parallel vector / single    : {par_sps / our_sps:12.1f}")

    est_rows = _estimator_rows(our_acts[: n_single // 4], vec_acts, num_envs, max(n_vec // 4, 16), our_sps, vec_sps)

    floor = powmod_seconds(712)
    per_step = elgamal_seconds_per_step(5 if args.quick else 30)
    print(f"elgamal backend, 712 bits           : {per_step * 1e3:12.2f} ms/step")
    print(f"one gmpy2.powmod at 712 bits        : {floor * 1e6:12.1f} us")
    print(f"step / powmod (crypto floor)        : {per_step / floor:12.1f}")
    if args.record:
        _record(best, per_step, floor, est_rows, num_envs, n_vec, argv)
    return 0


def _throughput(n_single: int, n_vec: int, repeats: int, num_envs: int) -> tuple[dict[str, float], np.ndarray, np.ndarray]:
    """Best steps per second of ``Pendulum-v1``, the single environment and the vector
    environment (helper thread, one thread, ``parallel=True``), and the actions played."""
    rng = np.random.default_rng(0)
    pend = gym.make("Pendulum-v1")
    ours = gym.make(ENV_ID, config=CONFIG)
    pend_acts = rng.uniform(-2, 2, (n_single, 1)).astype(np.float32)
    our_acts = np.clip(rng.normal(0, 0.25, (n_single, 4)), -1, 1).astype(np.float32)
    venv = EncryptedLTIAttackVectorEnv(num_envs=num_envs, config=CONFIG)
    tvenv = EncryptedLTIAttackVectorEnv(num_envs=num_envs, config=CONFIG, helper_thread=False)
    vec_acts = np.clip(rng.normal(0, 0.25, (n_vec, num_envs, 4)), -1, 1).astype(np.float32)
    steps_per_second(ours, our_acts[:50])  # warm-up (table build, compilation)
    vector_steps_per_second(venv, vec_acts[:30])
    vector_steps_per_second(tvenv, vec_acts[:30])
    # interleaved passes, best of each: every ratio compares passes taken seconds apart. The
    # parallel passes come last, so that the worker threads they start (which spin for a while
    # after each parallel region) cannot slow the one-core passes.
    best = {"pend": 0.0, "ours": 0.0, "vec": 0.0, "one": 0.0, "par": 0.0}
    for _ in range(repeats):
        best["pend"] = max(best["pend"], steps_per_second(pend, pend_acts))
        best["ours"] = max(best["ours"], steps_per_second(ours, our_acts))
        best["vec"] = max(best["vec"], vector_steps_per_second(venv, vec_acts))
        best["one"] = max(best["one"], vector_steps_per_second(tvenv, vec_acts))
    venv.close()
    tvenv.close()
    pvenv = EncryptedLTIAttackVectorEnv(num_envs=num_envs, config=CONFIG, parallel=True, helper_thread=False)
    vector_steps_per_second(pvenv, vec_acts[:30])
    for _ in range(repeats):
        best["par"] = max(best["par"], vector_steps_per_second(pvenv, vec_acts))
    return best, our_acts, vec_acts


def _estimator_rows(
    our_acts: np.ndarray, vec_acts: np.ndarray, num_envs: int, est_steps: int, our_sps: float, vec_sps: float
) -> list[tuple[str, float, float]]:
    """Steps per second of the estimators other than least squares, single and vector environment."""
    est_rows = []
    for est in ("bayes", "forgetting", "iv"):
        cfg = {**CONFIG, "estimator": est}
        single = steps_per_second(gym.make(ENV_ID, config=cfg), our_acts)
        vec = EncryptedLTIAttackVectorEnv(num_envs=num_envs, config=cfg)
        vector_steps_per_second(vec, vec_acts[:4])
        vsps = vector_steps_per_second(vec, vec_acts[:est_steps])
        vec.close()
        est_rows.append((est, single, vsps))
        print(
            f"estimator {est:<10}: single {single:10,.0f} steps/s ({single / our_sps:.2g}x ls), "
            f"vector {vsps:12,.0f} env-steps/s ({vsps / vec_sps:.2g}x ls)"
        )
    return est_rows


def _record(
    best: dict[str, float],
    per_step: float,
    floor: float,
    est_rows: list[tuple[str, float, float]],
    num_envs: int,
    n_vec: int,
    argv: list[str] | None,
) -> None:
    """Write the figures and the README rows (:func:`record.write`)."""
    our_sps, pend_sps, vec_sps, one_sps, par_sps = best["ours"], best["pend"], best["vec"], best["one"], best["par"]
    from record import write

    figures = {
        "single_sps": our_sps,
        "pendulum_sps": pend_sps,
        "vector_sps": vec_sps,
        "one_thread_sps": one_sps,
        "parallel_sps": par_sps,
        "elgamal_step_s": per_step,
        "powmod_s": floor,
    }
    write(
        "bench_env",
        figures,
        [
            (
                "environment (ideal backend) vs `Pendulum-v1`, both through `gymnasium.make`",
                f"{our_sps / pend_sps:.2f}x the steps per second ({our_sps:,.0f} steps/s)",
            ),
            (
                f"native vector environment, {num_envs} copies, vs the single environment ({n_vec}-step passes)",
                f"{vec_sps / our_sps:.1f}x as constructed (helper thread); {one_sps / our_sps:.1f}x with `helper_thread=False`; "
                f"{par_sps / our_sps:.1f}x with `parallel=True`",
            ),
            (
                "environment step through real ElGamal at 712 bits",
                f"{per_step * 1e3:.2f} ms = {per_step / floor:.1f} powmod times",
            ),
            (
                "estimators other than least squares: steps per second, single env / vector env (their share of least squares')",
                "; ".join(f"`{e}` {s1:,.0f} ({s1 / our_sps:.2g}x) / {v:,.0f} ({v / vec_sps:.2g}x)" for e, s1, v in est_rows),
            ),
        ],
        argv,
    )


if __name__ == "__main__":
    raise SystemExit(main())
