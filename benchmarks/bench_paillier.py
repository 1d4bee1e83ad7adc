"""One control step of the encrypted controller ``u = Phi x`` over Paillier, side by side: this
package (``crypto.paillier_controller``), python-paillier (``phe``) and ECLib's ``paillier``.

A step is what the plant and the server do per sampling period for a 4 x 4 controller: the
plant encrypts the 4 entries of x, the server evaluates ``Phi x`` on the ciphertexts with Phi in
plaintext (ECLib's ``int_mult``; phe's ``EncryptedNumber * int`` and ``+``; here one product
per row with short signed exponents), the plant decrypts and decodes the 4 rows. All three use
the same scale (``Delta = 2^16``, ECLib's quantisation step ``1/Delta``) and modulus length k
(ECLib's ``keygen(k/2)`` draws two primes of k/2 bits). Each decoded input is checked against
the plaintext ``Phi x`` within the encoder's bound. KeyGen is outside the step.

ECLib is not a dependency: pass ``--eclib PATH`` (its wheel, from ``pip download eclib``, or an
unpacked copy); without it, or without phe, those columns are skipped.

Usage::

    python benchmarks/bench_paillier.py --eclib /tmp/eclib-1.5.4-py3-none-any.whl [--sizes 1024 2048 3072] [--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from encctl_gym.crypto.paillier_controller import PaillierLinearController

PHI = np.array([[0.5, -0.25, 0.1, 0.0], [-1.0, 0.3, 0.0, 0.7], [0.2, 0.2, -0.6, 0.1], [0.0, -0.9, 0.4, 0.05]])
X = np.array([1.5, -2.0, 0.25, 3.0])
DELTA = 2.0**16


def timed(step, repeats: int) -> float:
    """Median wall seconds of ``step()`` over ``repeats`` runs (after one warm-up run)."""
    step()
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        step()
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples)


def ours(bits: int):
    ctl = PaillierLinearController(PHI, bits, DELTA, 10.0, rng=1)

    def step() -> None:
        u = ctl.step(X)
        assert np.all(np.abs(u - PHI @ X) <= ctl.error_bound(X) + 1e-12)

    return step


def python_paillier(bits: int):
    import phe

    pub, priv = phe.generate_paillier_keypair(n_length=bits)
    phi = [[int(round(DELTA * v)) for v in row] for row in PHI.tolist()]

    def step() -> None:
        cts = [pub.encrypt(int(round(DELTA * v))) for v in X.tolist()]
        rows = [sum((c * k for c, k in zip(cts, row) if k), pub.encrypt(0)) for row in phi]
        u = np.array([priv.decrypt(r) / DELTA**2 for r in rows])
        assert np.allclose(u, PHI @ X, atol=1e-3)

    return step


def eclib(bits: int, path: str):
    sys.path.insert(0, path)
    from eclib import paillier as ec

    params, pk, sk = ec.keygen(bits // 2)
    phi = ec.encode(params, PHI, 1 / DELTA)

    def step() -> None:
        c = ec.enc(params, pk, X, 1 / DELTA)
        y = ec.int_mult(params, phi, c)
        u = np.array(ec.dec(params, sk, y, 1 / DELTA**2), dtype=float)
        assert np.allclose(u, PHI @ X, atol=1e-3)

    return step


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1024, 2048, 3072])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--eclib", default=None, help="path of ECLib's wheel or unpacked package")
    args = ap.parse_args(argv)
    print("| k bits | encctl-gym s/step | phe s/step | ECLib s/step | ECLib / encctl-gym | phe / encctl-gym |")
    print("|---:|---:|---:|---:|---:|---:|")
    for bits in args.sizes:
        t_ours = timed(ours(bits), args.repeats)
        try:
            t_phe = timed(python_paillier(bits), args.repeats)
        except ImportError:
            t_phe = float("nan")
        t_ec = timed(eclib(bits, args.eclib), args.repeats) if args.eclib else float("nan")
        print(f"| {bits} | {t_ours:.4g} | {t_phe:.4g} | {t_ec:.4g} | {t_ec / t_ours:.3g} | {t_phe / t_ours:.3g} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
