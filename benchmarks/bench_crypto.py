"""Benchmark of the cryptographic core (encctl_gym.crypto).

For each key length it prints the time of: safe-prime group generation + KeyGen (fresh) and
KeyGen with the shipped group, the verification of the shipped group from scratch, Enc, Dec,
Eval, Eval_bar/Dec_bar, KeyUpd, CtUpd, and one full encrypted control step of each scheme
(n = m = 4), with the step time divided by the time of one gmpy2.powmod at that size
(full-size exponent) measured in the same run, and the number of modular exponentiations per
step (counted by crypto.arith.powmod).

Then the mean time of repeated safe-prime searches against
crypto.group.estimate_generation_seconds (the estimate that decides, before a search starts,
whether it is refused), and the build time and peak memory (tracemalloc) of the residue table
of the environment's default range against crypto.residue_table.residue_table_bytes.

Usage::

    python benchmarks/bench_crypto.py            # full run (2048-bit generation with timeout)
    python benchmarks/bench_crypto.py --quick    # fewer repetitions, no fresh 2048-bit group
    python benchmarks/bench_crypto.py --record   # also write benchmarks/results/bench_crypto.json
                                                 # for the README table (benchmarks/record.py)
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import statistics
import sys
import time
import tracemalloc
from collections.abc import Callable

import gmpy2
import numpy as np

from encctl_gym.crypto import arith
from encctl_gym.crypto.controller import EncryptedLinearController
from encctl_gym.crypto.dyn_elgamal import ciphertext_update, key_update
from encctl_gym.crypto.elgamal import decrypt, encrypt, keygen, mult
from encctl_gym.crypto.group import estimate_generation_seconds, generate_safe_prime_group, shipped_group
from encctl_gym.crypto.modified import modified_decrypt, modified_eval
from encctl_gym.crypto.residue_table import ResidueTable, residue_table_bytes

PHI = np.array([[0.5, -1.2, 0.3, 0.0], [1.0, 2.0, -3.0, 0.25], [0.1, 0.2, 0.3, 0.4], [-1.0, -1.0, -1.0, -1.0]])


def timeit(fn: Callable[[], object], reps: int) -> float:
    """Best (minimum) wall time of ``fn`` in seconds over ``reps`` calls, after one warm-up call.

    The minimum is the least disturbed by other processes on a shared machine.
    """
    fn()
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def _generate(bits: int, queue: mp.Queue[float]) -> None:
    t0 = time.perf_counter()
    grp = generate_safe_prime_group(bits)
    keygen(grp)
    queue.put(time.perf_counter() - t0)


def fresh_keygen(bits: int, samples: int, timeout: float) -> str:
    """Time of generate_safe_prime_group + keygen, each sample in a child process with a timeout."""
    times = []
    ctx = mp.get_context("spawn" if sys.platform == "win32" else "fork")
    for _ in range(samples):
        queue: mp.Queue[float] = ctx.Queue()
        proc = ctx.Process(target=_generate, args=(bits, queue), daemon=True)
        proc.start()
        proc.join(timeout)
        if proc.is_alive():
            proc.terminate()
            proc.join()
            return f"> {timeout:.0f} s (timeout)"
        times.append(queue.get())
    if len(times) == 1:
        return f"{times[0]:.2f} s"
    return f"{statistics.median(times):.2f} s (median of {len(times)}, {min(times):.2f}-{max(times):.2f})"


def bench_size(bits: int, reps: int, fresh_samples: int, fresh_timeout: float, skip_fresh: bool) -> dict:
    """Time the operations and the control steps at one key length; print them and return the figures."""
    grp = shipped_group(bits)
    rng = arith.seeded_random(bits)
    p = grp.p
    base = gmpy2.mpz(rng.between(2, p))
    exp = gmpy2.mpz(rng.between(p // 2, p))  # full-size exponent (bit length of p)
    t_pow = timeit(lambda: gmpy2.powmod(base, exp, p), max(reps, 20))
    t_pow_py = timeit(lambda: pow(int(base), int(exp), int(p)), max(3, reps // 4))

    pk, sk = keygen(grp, rng)
    m1, m2 = 4, 9
    ct1, ct2 = encrypt(pk, m1, rng), encrypt(pk, m2, rng)
    pk1, sk1, tok = key_update(pk, sk, rng)
    ct2_next = encrypt(pk1, m2, rng)
    mct = modified_eval(pk, ct1, ct2_next)

    fresh = "skipped" if skip_fresh else fresh_keygen(bits, fresh_samples, fresh_timeout)
    ops = {
        "verify shipped group from scratch": timeit(lambda: grp.verify(recheck=True), max(1, reps // 4)),
        "keygen, shipped group": timeit(lambda: keygen(grp), reps),
        "encrypt": timeit(lambda: encrypt(pk, m1), reps),
        "decrypt": timeit(lambda: decrypt(sk, ct1), reps),
        "eval (mult)": timeit(lambda: mult(pk, ct1, ct2), reps),
        "modified_eval": timeit(lambda: modified_eval(pk, ct1, ct2_next), reps),
        "modified_decrypt": timeit(lambda: modified_decrypt(sk, sk1, mct), reps),
        "key_update": timeit(lambda: key_update(pk, sk), reps),
        "ciphertext_update": timeit(lambda: ciphertext_update(pk, ct1, tok), reps),
    }
    steps = {}
    for scheme in ("modified", "token"):
        ctrl = EncryptedLinearController(PHI, grp, 2.0**16, 10.0, scheme=scheme)
        xs = np.random.default_rng(0).uniform(-10, 10, (reps + 1, 4))
        it = iter(xs)
        t_step = timeit(lambda ctrl=ctrl, it=it: ctrl.step(next(it)), reps)
        with arith.PowmodCounter() as c:
            ctrl.step(xs[0])
        steps[scheme] = (t_step, c.count)
    # Measure the reference exponentiation again and keep the better value, so that a burst
    # of load from other processes during one measurement does not skew the ratios.
    t_pow = min(t_pow, timeit(lambda: gmpy2.powmod(base, exp, p), max(reps, 20)))

    print(f"\n== {bits}-bit group (p = 2q + 1) ==")
    print(f"  {'gmpy2.powmod (full exponent)':<34s} {t_pow * 1e3:9.3f} ms")
    print(f"  {'Python pow (same)':<34s} {t_pow_py * 1e3:9.3f} ms  ({t_pow_py / t_pow:.1f}x gmpy2)")
    print(f"  {'keygen, fresh safe prime':<34s} {fresh}")
    for name, t in ops.items():
        print(f"  {name:<34s} {t * 1e3:9.3f} ms")
    for scheme, (t_step, count) in steps.items():
        print(
            f"  {'control step, ' + scheme + ' (n=m=4)':<34s} {t_step * 1e3:9.3f} ms  "
            f"= {t_step / t_pow:6.1f} powmod times; {count} powmods counted"
        )
    return {
        "bits": bits,
        "powmod_s": t_pow,
        "python_pow_s": t_pow_py,
        "fresh_keygen": fresh,
        **{f"step_{k}_s": v[0] for k, v in steps.items()},
        **{f"step_{k}_powmods": v[1] for k, v in steps.items()},
    }


def bench_generation(sizes: list[tuple[int, int]]) -> None:
    """Mean time of ``samples`` searches per size against estimate_generation_seconds.

    Wall time and the process's CPU time: on a machine shared with other jobs the wall time
    grows with the load, the CPU time is what the estimate models.
    """
    print("\n== safe-prime generation: mean of n searches (seeded streams 0..n-1) vs the estimate ==")
    print(
        f"  {'bits':>5s} {'n':>3s} {'estimate':>9s} {'wall mean':>10s} {'ratio':>6s} {'cpu mean':>9s} {'ratio':>6s} {'sem':>5s}"
    )
    for bits, samples in sizes:
        wall, cpu = [], []
        for i in range(samples):
            t0, c0 = time.perf_counter(), time.process_time()
            generate_safe_prime_group(bits, rng=arith.seeded_random(i, "bench"))
            wall.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        est, w, c = estimate_generation_seconds(bits), statistics.mean(wall), statistics.mean(cpu)
        sem = statistics.stdev(cpu) / samples**0.5 / c if samples > 1 else float("nan")
        print(f"  {bits:5d} {samples:3d} {est:8.3f}s {w:9.3f}s {w / est:6.2f} {c:8.3f}s {c / est:6.2f} {sem:5.2f}")


def bench_residue_table(limit: int) -> None:
    """Build time and tracemalloc peak of a residue table against residue_table_bytes."""
    grp = shipped_group(712)
    tracemalloc.start()
    t0 = time.perf_counter()
    ResidueTable(grp, limit)
    dt = time.perf_counter() - t0
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    est = residue_table_bytes(limit)
    print(f"\n== residue table, limit {limit} (712-bit group) ==")
    print(
        f"  build {dt:.2f} s (under tracemalloc); peak {peak / 2**20:.1f} MiB; "
        f"estimate {est / 2**20:.1f} MiB ({est / peak:.2f}x the peak)"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bits", type=int, nargs="+", default=[256, 712, 1024, 2048])
    parser.add_argument("--quick", action="store_true", help="fewer repetitions; no fresh 2048-bit group")
    parser.add_argument("--reps", type=int, default=None, help="repetitions per timing (default 30, quick 8)")
    parser.add_argument("--skip-fresh-2048", action="store_true", help="skip fresh 2048-bit group generation")
    parser.add_argument("--fresh-timeout", type=float, default=120.0, help="timeout (s) per fresh generation")
    parser.add_argument("--record", action="store_true", help="record the 712-bit figures for the README table")
    args = parser.parse_args(argv)
    reps = args.reps or (8 if args.quick else 30)
    fresh_samples = 1 if args.quick else 3
    print(
        f"gmpy2 {gmpy2.version()}, {gmpy2.mp_version()}; reps = {reps}; times are the best of reps (fresh keygen: median of samples)"
    )
    sizes = {}
    for bits in args.bits:
        skip = bits >= 2048 and (args.quick or args.skip_fresh_2048)
        sizes[bits] = bench_size(bits, reps, 1 if bits >= 2048 else fresh_samples, args.fresh_timeout, skip)
    if args.quick:
        bench_generation([(256, 20), (512, 10), (712, 8), (1024, 4)])
    else:
        bench_generation([(256, 80), (512, 40), (712, 30), (1024, 16), (1536, 6), (2048, 3)])
    # The environment's default range: Delta = 4096 times x_bound = 256 (plus one).
    bench_residue_table(4096 * 256 + 1)
    if args.record:
        if 712 not in sizes:
            raise SystemExit("--record needs 712 among --bits")
        f = sizes[712]
        from record import write

        write(
            "bench_crypto",
            {str(b): v for b, v in sizes.items()},
            [
                (
                    "encrypted control step, modified scheme, n = m = 4, 712 bits",
                    f"{f['step_modified_s'] * 1e3:.2f} ms = {f['step_modified_s'] / f['powmod_s']:.1f} powmod times "
                    f"({f['step_modified_powmods']} modular exponentiations counted); token scheme {f['step_token_powmods']}",
                ),
                ("gmpy2 vs Python `pow` at 712 bits", f"{f['python_pow_s'] / f['powmod_s']:.1f}x faster"),
                ("fresh 712-bit safe-prime group and KeyGen", f"{f['fresh_keygen']} (shipped groups: instant)"),
            ],
            argv,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
