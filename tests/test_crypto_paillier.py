"""Paillier encryption (crypto.paillier) and the encrypted linear controller over it
(crypto.paillier_controller): properties with hypothesis, python-paillier (phe) from outside,
the error bound against exact rational arithmetic, and the package's errors on bad input."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.crypto import arith
from encctl_gym.crypto import paillier as P
from encctl_gym.crypto.paillier_controller import (
    PaillierControllerServer,
    PaillierEncoder,
    PaillierLinearController,
    controller_error_bound,
    to_signed,
)
from encctl_gym.errors import CiphertextError, EncodingOverflowError, KeyMismatchError, ParameterError, PlaintextError

PK, SK = P.keygen(256, rng=11)
PK2, SK2 = P.keygen(256, rng=12)
SRC = arith.seeded_random(5, "tests")
N = PK.n
SET = settings(max_examples=40, deadline=None)


# ----------------------------------------------------------------------------- KeyGen
@pytest.mark.parametrize("bits", [16, 17, 33, 64, 255, 256, 1024])
def test_keygen_gives_a_modulus_of_exactly_k_bits_from_two_distinct_primes(bits: int) -> None:
    pk, sk = P.keygen(bits, rng=bits)
    assert pk.bits == bits and pk.n == sk.p * sk.q and sk.p != sk.q
    assert arith.is_prime(sk.p) and arith.is_prime(sk.q)
    assert math.gcd(pk.n, (sk.p - 1) * (sk.q - 1)) == 1
    # lambda and mu as written in Scheme 1, recomputed independently here
    lam = math.lcm(sk.p - 1, sk.q - 1)
    assert sk.lam == lam
    L = (pow(pk.n + 1, lam, pk.n**2) - 1) // pk.n
    assert sk.mu == pow(L, -1, pk.n)


def test_keygen_is_reproducible_for_a_seed_and_differs_between_seeds() -> None:
    assert P.keygen(128, rng=3)[0].n == P.keygen(128, rng=3)[0].n
    assert P.keygen(128, rng=3)[0].n != P.keygen(128, rng=4)[0].n


@pytest.mark.parametrize("bits", [15, 0, 8193, 12.5, "64", True])
def test_keygen_refuses_bad_bit_lengths(bits: object) -> None:
    with pytest.raises(ParameterError):
        P.keygen(bits, rng=1)  # type: ignore[arg-type]


def test_secret_key_refuses_wrong_factors() -> None:
    with pytest.raises(ParameterError):
        P.secret_key_from_factors(PK, SK.p, SK.q + 2)
    assert P.secret_key_from_factors(PK, SK.q, SK.p).lam == SK.lam
    assert "p=" not in repr(SK) and str(SK.p) not in repr(SK)


# ----------------------------------------------------------------------------- Enc / Dec / Eval
@SET
@given(st.integers(0, N - 1))
def test_decrypt_inverts_encrypt_and_the_crt_equals_the_textbook_formula(m: int) -> None:
    ct = P.encrypt(PK, m, SRC)
    assert P.decrypt(SK, ct) == m == P.decrypt_textbook(SK, ct)


@SET
@given(st.integers(0, N - 1), st.integers(0, N - 1))
def test_the_product_of_ciphertexts_decrypts_to_the_sum_mod_n(a: int, b: int) -> None:
    ca, cb = P.encrypt(PK, a, SRC), P.encrypt(PK, b, SRC)
    assert P.decrypt(SK, ca + cb) == (a + b) % N == P.decrypt(SK, P.add(ca, cb))
    assert P.decrypt(SK, ca + b) == (a + b) % N  # add_plain: Enc(a) g^b


@SET
@given(st.integers(0, N - 1), st.integers(-(2**80), 2**80))
def test_a_power_of_a_ciphertext_decrypts_to_the_plaintext_multiple(m: int, k: int) -> None:
    assert P.decrypt(SK, P.encrypt(PK, m, SRC) * k) == (k * m) % N


@SET
@given(st.integers(-(N - 1) // 2, (N - 1) // 2))
def test_signed_values_round_trip_through_their_residue(v: int) -> None:
    assert to_signed(P.decrypt(SK, P.encrypt(PK, v % N, SRC)), N) == v


@SET
@given(st.integers(0, N - 1), st.integers(0, 2**32))
def test_the_owners_crt_encryption_is_bit_identical_to_encrypt_for_one_seed(m: int, seed: int) -> None:
    a = P.encrypt(PK, m, arith.seeded_random(seed))
    b = P.encrypt_with_secret(SK, m, arith.seeded_random(seed))
    assert a.c == b.c and P.decrypt(SK, b) == m


def test_encryption_is_randomised() -> None:
    assert P.encrypt(PK, 7, SRC).c != P.encrypt(PK, 7, SRC).c


@pytest.mark.parametrize("m", [1.5, 2.0, "3", None, True, -1, N])
def test_a_plaintext_that_is_not_an_integer_of_z_n_is_refused(m: object) -> None:
    with pytest.raises(PlaintextError):
        P.encrypt(PK, m, SRC)


@pytest.mark.parametrize("c", [0, N * N, N * N + 5, -3, N, 3 * SK.p, 2.0])
def test_a_ciphertext_outside_z_n2_star_is_refused(c: object) -> None:
    with pytest.raises(CiphertextError):
        P.decrypt(SK, P.PaillierCiphertext(PK, c))  # type: ignore[arg-type]


def test_objects_of_different_moduli_are_not_combined() -> None:
    a, b = P.encrypt(PK, 1, SRC), P.encrypt(PK2, 1, SRC)
    with pytest.raises(KeyMismatchError):
        P.add(a, b)
    with pytest.raises(KeyMismatchError):
        P.decrypt(SK2, a)
    with pytest.raises(CiphertextError):
        P.decrypt(SK, 5)


def test_encrypt_refuses_a_bare_int_seed() -> None:
    with pytest.raises(ParameterError, match="seeded_random"):
        P.encrypt(PK, 1, 5)


def test_measured_keygen_seconds_are_positive_and_one_per_repeat() -> None:
    t = P.measure_keygen_seconds(128, 3, rng=1)
    assert len(t.samples) == 3 and all(s > 0 for s in t.samples) and t.mean > 0
    assert t.to_dict()["bits"] == 128


# ----------------------------------------------------------------------------- python-paillier
def _cases(n: int, count: int) -> list[int]:
    rnd = arith.seeded_random(9, "phe-cases")
    half = (n - 1) // 2
    edge = [0, 1, -1, half, -half, 2, -2]
    return edge + [rnd.between(-half, half + 1) for _ in range(count - len(edge))]


def test_interoperates_with_python_paillier_in_both_directions() -> None:
    phe = pytest.importorskip("phe")
    pub = phe.PaillierPublicKey(N)
    priv = phe.PaillierPrivateKey(pub, SK.p, SK.q)
    assert pub.g == PK.g
    rnd = arith.seeded_random(10, "phe-r")
    for v in _cases(N, 200):
        m = v % N
        ours = P.encrypt(PK, m, SRC)
        assert to_signed(priv.raw_decrypt(ours.c), N) == v  # ours -> phe
        theirs = pub.raw_encrypt(m, r_value=rnd.between(1, N))
        assert to_signed(P.decrypt(SK, P.PaillierCiphertext(PK, theirs)), N) == v  # phe -> ours
        assert priv.raw_decrypt((ours + P.PaillierCiphertext(PK, theirs)).c) == (2 * m) % N


# ----------------------------------------------------------------------------- encoder
@SET
@given(st.floats(-1e6, 1e6, allow_nan=False))
def test_the_encoder_round_trip_is_within_half_a_step(x: float) -> None:
    enc = PaillierEncoder(PK, 2.0**20)
    assert abs(enc.decode(enc.encode(x)) - x) <= enc.error_bound() * (1 + 1e-12)


def test_the_encoder_refuses_what_it_cannot_represent() -> None:
    enc = PaillierEncoder(P.keygen(32, rng=1)[0], 2.0**10, x_bound=100.0)
    with pytest.raises(EncodingOverflowError):
        enc.encode(100.5)
    with pytest.raises(ParameterError):
        enc.encode(float("nan"))
    with pytest.raises(EncodingOverflowError):
        PaillierEncoder(P.keygen(32, rng=1)[0], 2.0**30, x_bound=100.0)


# ----------------------------------------------------------------------------- the controller
PHI = np.array([[0.5, -1.25, 0.1], [2.0, 0.0, -0.7]])


def test_the_encrypted_controller_equals_its_quantised_twin_bit_for_bit_and_meets_the_bound() -> None:
    ctl = PaillierLinearController(PHI, 128, 2.0**12, 10.0, rng=3)
    rnd = np.random.default_rng(4)
    for _ in range(20):
        x = rnd.uniform(-10, 10, size=3)
        u = ctl.step(x)
        np.testing.assert_array_equal(u, ctl.reference(x))
        bound = ctl.error_bound(x)
        for i in range(2):
            exact = sum(Fraction(float(a)) * Fraction(float(b)) for a, b in zip(PHI[i], x))
            assert abs(Fraction(float(u[i])) - exact) <= Fraction(float(bound[i])) + Fraction(abs(float(u[i]))) * 2**-52


def test_the_error_bound_formula() -> None:
    # sum_j (|Phi_ij| + |x_j|) / (2 Delta) + beta / (4 Delta^2), by hand for Delta = 4
    b = controller_error_bound([[1.0, -2.0]], [0.5, -3.0], 4.0)
    assert b[0] == pytest.approx((1.0 + 0.5 + 2.0 + 3.0) / 8 + 2 / 64, rel=1e-15)


def test_a_malicious_server_adds_an_offset_with_the_public_key_alone() -> None:
    ctl = PaillierLinearController(PHI, 128, 2.0**12, 10.0, rng=3)
    x = np.array([1.0, -2.0, 3.0])
    honest = ctl.reference(x)
    d = [3 * 2**24, -(2**24)]  # +3 and -1 after Dcd with Delta^2 = 2^24
    u = ctl.step(x, offset=d)
    np.testing.assert_array_equal(u, honest + np.array([3.0, -1.0]))


def test_rotation_draws_a_fresh_modulus_every_k_steps_and_the_server_follows() -> None:
    ctl = PaillierLinearController(PHI, 96, 2.0**8, 10.0, rotation_period=2, rng=3)
    moduli = []
    for _ in range(6):
        moduli.append(ctl.plant.pk.n)
        ctl.step(np.zeros(3))
        assert ctl.server.pk.n == ctl.plant.pk.n
    assert moduli[0] == moduli[1] != moduli[2] == moduli[3] != moduli[4]
    assert len(ctl.plant.keygen_seconds) == 4  # the first key and three rotations


def test_a_modulus_too_small_for_the_encoders_range_is_refused() -> None:
    with pytest.raises(EncodingOverflowError, match="too small for the encoder's range"):
        PaillierLinearController(PHI, 32, 2.0**16, 10.0, rng=1)


def test_the_server_refuses_a_wrong_number_of_state_ciphertexts() -> None:
    server = PaillierControllerServer(PK, [[1, 2]])
    with pytest.raises(ParameterError):
        server.evaluate([P.encrypt(PK, 1, SRC)])
