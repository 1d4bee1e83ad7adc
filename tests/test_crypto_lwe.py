"""LWE encryption (encctl_gym.crypto.lwe): correctness against an independent decryption written
here with Python integers, homomorphic properties, the worst-case noise bound, the int64 limit
at the largest allowed modulus, refusals, and the encrypted state feedback on the design example."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.crypto import lwe
from encctl_gym.crypto.arith import seeded_random
from encctl_gym.errors import EncodingOverflowError, KeyMismatchError, ParameterError, ShapeError


def reference_decrypt(q: int, delta: int, s: np.ndarray, c1: np.ndarray, c2: np.ndarray) -> tuple[list[int], list[int]]:
    """Dec with Python integers (no numpy arithmetic): messages and noises."""
    out, noise = [], []
    sv = [int(v) for v in s]
    for row, last in zip(c1.tolist(), c2.tolist()):
        v = (int(last) - sum(int(a) * b for a, b in zip(row, sv))) % q
        if v > q // 2:
            v -= q
        mu = (2 * v + delta) // (2 * delta)
        out.append(mu)
        noise.append(v - delta * mu)
    return out, noise


def small_params(n: int, eta: int = 2, t: int = 2**10) -> lwe.LWEParams:
    # q just above what the fresh noise bound needs, so that the tests exercise tight margins
    bound = eta * eta * 2 * n + eta
    return lwe.LWEParams(n=n, q=t * (2 * bound + 1) * 8 + 3, t=t, eta=eta)


def key_error(pk: lwe.LWEPublicKey, sk: lwe.LWESecretKey) -> list[int]:
    """``b - A s mod q``, centred, with Python integers."""
    q = pk.params.q
    out = []
    for row, b in zip(pk.A.tolist(), pk.b.tolist()):
        e = (b - sum(a * s for a, s in zip(row, sk.s.tolist()))) % q
        out.append(e - q if e > q // 2 else e)
    return out


@settings(max_examples=25, deadline=None)
@given(n=st.integers(1, 24), eta=st.integers(1, 4), seed=st.integers(0, 2**32), data=st.data())
def test_round_trip_and_noise_within_bound(n: int, eta: int, seed: int, data: st.DataObject) -> None:
    p = small_params(n, eta)
    pk, sk = lwe.keygen(p, seed)
    assert all(abs(e) <= eta for e in key_error(pk, sk))
    assert np.abs(sk.s).max() <= eta
    mu = data.draw(st.lists(st.integers(-p.max_message, p.max_message), min_size=1, max_size=6))
    ct = lwe.encrypt(pk, mu, seeded_random(seed, "enc"))
    got, noise = lwe.decryption_noise(sk, ct)
    ref, ref_noise = reference_decrypt(p.q, p.delta_q, sk.s, ct.c1, ct.c2)
    assert got.tolist() == mu == ref
    assert noise.tolist() == ref_noise
    assert max(abs(v) for v in ref_noise) <= p.fresh_noise_bound


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32), data=st.data())
def test_linear_combination_decrypts_to_the_integer_product(seed: int, data: st.DataObject) -> None:
    p = lwe.LWEParams(n=16, q=2**40 + 15, t=2**16, eta=2)
    pk, sk = lwe.keygen(p, seed)
    k = data.draw(st.integers(1, 5))
    # |sum_j K_ij mu_j| <= 5 * 40 * 160 = 32000 <= (t - 1) / 2 = 32767: every draw is decryptable
    mu = data.draw(st.lists(st.integers(-160, 160), min_size=k, max_size=k))
    K = data.draw(st.lists(st.lists(st.integers(-40, 40), min_size=k, max_size=k), min_size=1, max_size=4))
    stream = lwe.ByteStream(seeded_random(seed, "enc"))
    ct = lwe.encrypt(pk, mu, stream)
    out = lwe.linear_combination(K, ct)
    expected = [sum(a * b for a, b in zip(row, mu)) for row in K]
    got, noise = lwe.decryption_noise(sk, out)
    assert got.tolist() == expected
    assert all(abs(int(e)) <= b for e, b in zip(noise, out.noise_bound))
    assert list(out.message_bound) == [sum(abs(a) * abs(b) for a, b in zip(row, mu)) for row in K]
    # addition and scalar multiplication agree with the combination
    assert lwe.decrypt(sk, lwe.add(ct, ct)).tolist() == [2 * v for v in mu]
    assert lwe.decrypt(sk, lwe.mult(-3, ct)).tolist() == [-3 * v for v in mu]


def test_largest_allowed_modulus_does_not_overflow() -> None:
    n, eta = 64, 3
    q = lwe.max_modulus(n, n, eta)
    assert n * eta * (q - 1) + q <= lwe.INT64_MAX < n * eta * q + q + 1  # the limit is tight
    with pytest.raises(ParameterError, match=str(q)):
        lwe.LWEParams(n=n, q=q + 1, t=2**20, eta=eta)
    p = lwe.LWEParams(n=n, q=q, t=2**20, eta=eta)
    pk, sk = lwe.keygen(p, 7)
    assert all(abs(e) <= eta for e in key_error(pk, sk))  # A s + e computed without wrap
    mu = [p.max_message, -p.max_message, 0, 12345]
    ct = lwe.encrypt(pk, mu, seeded_random(7, "enc"))
    ref, ref_noise = reference_decrypt(q, p.delta_q, sk.s, ct.c1, ct.c2)
    assert lwe.decrypt(sk, ct).tolist() == ref == mu
    # the largest integer matrix the int64 check admits: numpy and Python integers agree
    kmax = lwe.INT64_MAX // (4 * (q - 1))
    K = np.array([[kmax, -kmax, kmax, -kmax]], dtype=np.int64)
    zero = lwe.encrypt(pk, [0, 0, 0, 0], seeded_random(8, "enc"))
    out = lwe.linear_combination(K, zero)  # admitted: 4 kmax (q - 1) <= 2^63 - 1
    exact = [sum(int(k) * int(c) for k, c in zip(K[0], col)) % q for col in zero.c1.T.tolist()]
    assert out.c1[0].tolist() == exact
    assert lwe.decrypt(sk, out).tolist() == [0]
    # beyond one int64 word the product is split (matmul_mod) and still exact
    big = [[kmax + 1, -(2**20) - 3, 7, -kmax]]
    out = lwe.linear_combination(big, zero)
    exact = [sum(k * int(c) for k, c in zip(big[0], col)) % q for col in zero.c1.T.tolist()]
    assert out.c1[0].tolist() == exact
    assert out.c2.tolist() == [sum(k * int(c) for k, c in zip(big[0], zero.c2.tolist())) % q]


@settings(max_examples=30, deadline=None)
@given(q=st.integers(2, 2**58), data=st.data())
def test_matmul_mod_is_exact_for_any_integers(q: int, data: st.DataObject) -> None:
    k = data.draw(st.integers(1, 6))
    K = data.draw(st.lists(st.lists(st.integers(-(2**70), 2**70), min_size=k, max_size=k), min_size=1, max_size=3))
    C = np.array(data.draw(st.lists(st.integers(0, q - 1), min_size=k, max_size=k)), dtype=np.int64).reshape(k, 1)
    got = lwe.matmul_mod(np.array(K, dtype=object), C, q)
    assert got[:, 0].tolist() == [sum(a * int(c) for a, c in zip(row, C[:, 0])) % q for row in K]


def test_refusals_name_the_limit() -> None:
    with pytest.raises(ParameterError, match="noise too large"):
        lwe.LWEParams(n=64, q=2**14, t=16, eta=2)
    with pytest.raises(ParameterError, match="t must be"):
        lwe.LWEParams(n=8, q=2**20, t=2**21)
    p = lwe.LWEParams(n=8, q=2**30, t=2**8)
    pk, sk = lwe.keygen(p, 1)
    with pytest.raises(EncodingOverflowError, match="plaintext range"):
        lwe.encrypt(pk, [128], seeded_random(1, "e"))
    ct = lwe.encrypt(pk, [100, 100], seeded_random(1, "e"))
    with pytest.raises(EncodingOverflowError, match="wrap modulo t"):
        lwe.add(ct, ct)
    with pytest.raises(ParameterError, match="int seed"):
        lwe.encrypt(pk, [1], 5)
    pk2, sk2 = lwe.keygen(p, 2)
    with pytest.raises(KeyMismatchError):
        lwe.decrypt(sk2, ct)
    with pytest.raises(KeyMismatchError):
        lwe.add(ct, lwe.encrypt(pk2, [1, 1], seeded_random(3, "e")))
    with pytest.raises(ShapeError):
        lwe.linear_combination([[1, 2, 3]], ct)
    with pytest.raises(ShapeError):
        lwe.linear_combination([[1.5, 2]], ct)


def test_byte_stream_distributions_and_reproducibility() -> None:
    a = lwe.ByteStream(seeded_random(11))
    b = lwe.ByteStream(seeded_random(11))
    x, y = a.binomial(3, (20000,)), b.binomial(3, (20000,))
    assert np.array_equal(x, y)
    assert x.min() >= -3 and x.max() <= 3
    # mean 0, variance eta/2 = 1.5: the sample moments of 20000 draws within 5 standard errors
    assert abs(x.mean()) < 5 * np.sqrt(1.5 / 20000)
    assert abs(x.var() - 1.5) < 5 * np.sqrt(2 * 1.5**2 / 20000) * 1.5
    u = a.uniform(1000003, (50000,))
    assert u.min() >= 0 and u.max() < 1000003
    assert abs(u.mean() - 500001) < 5 * 1000003 / np.sqrt(12 * 50000)
    assert not lwe.ByteStream(None).bytes(16) == lwe.ByteStream(None).bytes(16)


def design_example_gain() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The paper's design example (Psi_u = 0.5 I: A = I/sqrt 2, B = I/2, n = m = 4) with an LQR
    gain (Q = R = I) computed here from the Riccati equation."""
    A, B = np.eye(4) * np.sqrt(0.5), 0.5 * np.eye(4)
    P = scipy.linalg.solve_discrete_are(A, B, np.eye(4), np.eye(4))
    K = np.linalg.solve(np.eye(4) + B.T @ P @ B, B.T @ P @ A)
    return A, B, -K


def run_loop(steps: int, seed: int) -> float:
    """Closed loop with the LWE controller; every input checked against the exact integer product
    and against the stated quantisation bound. Returns the largest decoding error seen."""
    A, B, Phi = design_example_gain()
    params = lwe.LWEParams(n=256, q=2**44, t=2**25, eta=2)
    ctl = lwe.LWEController(params, Phi, delta_x=4096, delta_phi=256, x_bound=10.0, rng=seed)
    rng = np.random.default_rng(seed)
    x = rng.normal(0.0, 1.0, 4)
    worst = 0.0
    for _ in range(steps):
        ct_u = ctl.evaluate(ctl.encrypt_state(x))
        u = ctl.decrypt_input(ct_u)
        exact = ctl.Phi_int @ lwe.encode(x, 4096)
        assert np.array_equal(np.rint(u * 4096 * 256).astype(np.int64), exact)
        err = np.abs(u - Phi @ x)
        assert np.all(err <= lwe.quantization_error_bound(Phi, x, 4096, 256))
        worst = max(worst, float(err.max()))
        x = A @ x + B @ u + rng.normal(0.0, np.sqrt(0.1), 4)
    return worst


def test_encrypted_state_feedback_on_the_design_example() -> None:
    assert run_loop(300, seed=5) > 0.0


@pytest.mark.slow
def test_encrypted_state_feedback_for_1e5_steps() -> None:
    run_loop(100_000, seed=6)


def test_controller_refuses_parameters_that_could_fail() -> None:
    _, _, Phi = design_example_gain()
    with pytest.raises(EncodingOverflowError, match="plaintext range"):
        lwe.LWEController(lwe.LWEParams(n=64, q=2**44, t=2**20), Phi, 4096, 256, 10.0, rng=1)
    with pytest.raises(EncodingOverflowError, match="noise"):
        lwe.LWEController(lwe.LWEParams(n=64, q=2**40, t=2**25), Phi, 4096, 256, 10.0, rng=1)
    ctl = lwe.LWEController(lwe.LWEParams(n=64, q=2**44, t=2**25), Phi, 4096, 256, 10.0, rng=1)
    with pytest.raises(EncodingOverflowError, match="x_bound"):
        ctl.encrypt_state([11.0, 0, 0, 0])


def test_controller_parameters_are_the_smallest_that_run() -> None:
    _, _, Phi = design_example_gain()
    p = lwe.controller_parameters(128, Phi, 4096, 256, 10.0)
    lwe.LWEController(p, Phi, 4096, 256, 10.0, rng=1)  # accepted
    with pytest.raises(EncodingOverflowError):
        lwe.LWEController(lwe.LWEParams(n=128, q=p.q, t=p.t - 2, eta=2), Phi, 4096, 256, 10.0, rng=1)
    with pytest.raises(EncodingOverflowError):
        lwe.LWEController(lwe.LWEParams(n=128, q=p.q - p.t, t=p.t, eta=2), Phi, 4096, 256, 10.0, rng=1)
