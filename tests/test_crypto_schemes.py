"""Tests of ElGamal (Example ex:elgamal), dynamic-key ElGamal (Example ex:dyn_elgamal),
the token attack (Proposition prop:vulnerability) and the modified scheme
(Definition def:modification and the theorem after it)."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from encctl_gym.crypto.arith import RandomSource, powmod, seeded_random
from encctl_gym.crypto.dyn_elgamal import UpdateToken, ciphertext_update, key_update, recover_next_secret_key
from encctl_gym.crypto.elgamal import Ciphertext, PublicKey, SecretKey, decrypt, encrypt, keygen, mult
from encctl_gym.crypto.group import GroupParams, shipped_group
from encctl_gym.crypto.modified import ModifiedCiphertext, modified_decrypt, modified_eval
from encctl_gym.errors import CiphertextError, KeyMismatchError, ParameterError, PlaintextError

TOY = GroupParams(23, 11, 4)  # G = {1, 2, 3, 4, 6, 8, 9, 12, 13, 16, 18}, see test_crypto_arith_group
G64, G128 = shipped_group(64), shipped_group(128)
PROP = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


class Fixed(RandomSource):
    """Returns prescribed exponents: between(1, q) yields the next value of ``exps``."""

    def __init__(self, *exps: int) -> None:
        self.exps = list(exps)

    def below(self, n: int) -> int:
        v = self.exps.pop(0) - 1  # between(1, q) = 1 + below(q - 1)
        assert 0 <= v < n
        return v


def member(grp: GroupParams, x: int) -> int:
    """A pseudo-random element of G: a nonzero square."""
    x = x % grp.p or 1
    return x * x % grp.p


# ---------------------------------------------------------------------------- known answers
def test_elgamal_known_answers_toy_group():
    # s = 3: h = 4^3 = 64 mod 23 = 18.
    pk, sk = keygen(TOY, Fixed(3))
    assert (pk.h, sk.s, pk.t) == (18, 3, 0)
    # Enc(9; r = 5): c1 = 4^5 = 12, c2 = 9 * 18^5 = 9 * 4^15 = 9 * 4^4 = 9 * 3 = 27 = 4.
    ct1 = encrypt(pk, 9, Fixed(5))
    assert ct1 == Ciphertext(TOY, 12, 4, 0)
    # Dec: 12^-3 = 4^-15 = 4^7 = 8; 8 * 4 = 32 = 9.
    assert decrypt(sk, ct1) == 9
    # Enc(2; r = 1): (4, 2 * 18 = 36 = 13).
    ct2 = encrypt(pk, 2, Fixed(1))
    assert ct2 == Ciphertext(TOY, 4, 13, 0)
    # Eval: (12 * 4 = 48 = 2, 4 * 13 = 52 = 6); Dec: 2^-3 = 4^-18 = 4^4 = 3; 3 * 6 = 18 = 9 * 2.
    ct = mult(pk, ct1, ct2)
    assert ct == Ciphertext(TOY, 2, 6, 0)
    assert decrypt(sk, ct) == 18


def test_dyn_elgamal_known_answers_toy_group():
    pk, sk = keygen(TOY, Fixed(3))
    ct = encrypt(pk, 9, Fixed(5))  # (12, 4) as above
    # KeyUpd with s' = 7: d = 7 - 3 = 4 (mod 11), h' = 18 * 4^4 = 18 * 3 = 54 = 8 = 4^7.
    pk1, sk1, tok = key_update(pk, sk, Fixed(7))
    assert (pk1.h, pk1.t, sk1.s, sk1.t) == (8, 1, 7, 1)
    assert (tok.h, tok.d, tok.t) == (18, 4, 0)
    # CtUpd with r = 2: c1' = 12 * 4^2 = 192 = 8; c2' = 8^4 * 4 * 18^2 = 2 * 4 * 2 = 16.
    ct1 = ciphertext_update(pk, ct, tok, Fixed(2))
    assert ct1 == Ciphertext(TOY, 8, 16, 1)
    # Dec with s' = 7: 8^-7 = 4^-49 = 4^-5 = 4^6 = 2; 2 * 16 = 32 = 9.
    assert decrypt(sk1, ct1) == 9
    # Proposition prop:vulnerability: s + d = 3 + 4 = 7.
    assert recover_next_secret_key(sk, tok) == sk1


def test_modified_known_answers_toy_group():
    pk0, sk0 = keygen(TOY, Fixed(3))
    pk1, sk1, _ = key_update(pk0, sk0, Fixed(7))
    ct1 = encrypt(pk0, 9, Fixed(5))  # (12, 4), step 0
    ct2 = encrypt(pk1, 2, Fixed(1))  # (4, 2 * 8 = 16), step 1
    assert ct2 == Ciphertext(TOY, 4, 16, 1)
    # Eval_bar: (12, 4, 4 * 16 = 64 = 18).
    mct = modified_eval(pk0, ct1, ct2)
    assert mct == ModifiedCiphertext(TOY, 12, 4, 18, 0, 1)
    # c~ = 4^-7 * 18 = 4^4 * 18 = 3 * 18 = 54 = 8; m = 12^-3 * 8 = 8 * 8 = 64 = 18 = 9 * 2.
    assert modified_decrypt(sk0, sk1, mct) == 18


# ---------------------------------------------------------------------------- properties
@PROP
@given(seed=st.integers(0, 2**32), x1=st.integers(1, 2**130), x2=st.integers(1, 2**130), big=st.booleans())
def test_elgamal_correctness_and_homomorphism(seed, x1, x2, big):
    grp = G128 if big else G64
    rng = seeded_random(seed)
    pk, sk = keygen(grp, rng)
    assert pk == sk.public_key() and powmod(grp.g, sk.s, grp.p) == pk.h
    m1, m2 = member(grp, x1), member(grp, x2)
    c1, c2 = encrypt(pk, m1, rng), encrypt(pk, m2, rng)
    assert decrypt(sk, c1) == m1 and decrypt(sk, c2) == m2
    assert decrypt(sk, mult(pk, c1, c2)) == m1 * m2 % grp.p
    # Encryption is randomised: a second encryption differs (r is fresh).
    assert encrypt(pk, m1, rng) != c1


@PROP
@given(seed=st.integers(0, 2**32), x1=st.integers(1, 2**130), x2=st.integers(1, 2**130), n_updates=st.integers(1, 25))
def test_dyn_elgamal_updatable_correctness_and_homomorphism(seed, x1, x2, n_updates):
    """Definition def:upd_he: Dec(sk_t, ct_t) = m and Dec(sk_t, Eval(ct_1t, ct_2t)) = m1 m2."""
    grp = G64
    rng = seeded_random(seed)
    pk, sk = keygen(grp, rng)
    m1, m2 = member(grp, x1), member(grp, x2)
    c1, c2 = encrypt(pk, m1, rng), encrypt(pk, m2, rng)
    for t in range(1, n_updates + 1):
        pk_next, sk_next, tok = key_update(pk, sk, rng)
        assert pk_next == sk_next.public_key()  # h' = h g^d = g^s'
        assert tok.d == (sk_next.s - sk.s) % grp.q
        c1_next = ciphertext_update(pk, c1, tok, rng)
        assert c1_next.c1 != c1.c1  # re-randomised
        c1, c2 = c1_next, ciphertext_update(pk, c2, tok, rng)
        pk, sk = pk_next, sk_next
        assert (pk.t, sk.t, c1.t) == (t, t, t)
        assert decrypt(sk, c1) == m1 and decrypt(sk, c2) == m2
        assert decrypt(sk, mult(pk, c1, c2)) == m1 * m2 % grp.p
        assert decrypt(sk, encrypt(pk, m1, rng)) == m1


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32), n_updates=st.integers(1, 60), big=st.booleans())
def test_token_attack_recovers_every_next_key(seed, n_updates, big):
    """Proposition prop:vulnerability: sk_t and sigma_t give sk_{t+1} with probability 1."""
    grp = G128 if big else G64
    rng = seeded_random(seed)
    pk, sk = keygen(grp, rng)
    stolen = sk  # the adversary broke sk_0 once ...
    for _ in range(n_updates):
        pk, sk_next, tok = key_update(pk, sk, rng)
        stolen = recover_next_secret_key(stolen, tok)  # ... and sees every token
        assert stolen == sk_next
        m = member(grp, seed + sk_next.t)
        assert decrypt(stolen, encrypt(pk, m, rng)) == m
        sk = sk_next


@settings(max_examples=80, deadline=None)
@given(
    seed=st.integers(0, 2**32),
    t=st.integers(0, 5),
    k=st.integers(0, 50),
    x1=st.integers(1, 2**130),
    x2=st.integers(1, 2**130),
    big=st.booleans(),
)
def test_modified_theorem(seed, t, k, x1, x2, big):
    """Dec_bar(sk_t, sk_{t+k}, Eval_bar(pk_t, Enc(pk_t, m1), Enc(pk_{t+k}, m2))) = m1 m2 mod p."""
    grp = G128 if big else G64
    rng = seeded_random(seed)
    pk, sk = keygen(grp, rng)
    keys = [(pk, sk)]
    for _ in range(t + k):
        pk, sk, _tok = key_update(pk, sk, rng)
        keys.append((pk, sk))
    (pk_t, sk_t), (pk_tk, sk_tk) = keys[t], keys[t + k]
    m1, m2 = member(grp, x1), member(grp, x2)
    ct = modified_eval(pk_t, encrypt(pk_t, m1, rng), encrypt(pk_tk, m2, rng))
    assert (ct.t1, ct.t2) == (t, t + k)
    assert modified_decrypt(sk_t, sk_tk, ct) == m1 * m2 % grp.p
    if k > 0:
        # The original Eval has no such homomorphism across steps: mult refuses, and with
        # the step labels removed, Dec with either key gives a wrong product.
        with pytest.raises(KeyMismatchError, match="same time step"):
            mult(pk_t, encrypt(pk_t, m1, rng), encrypt(pk_tk, m2, rng))
        a, b = encrypt(pk_t, m1, rng), encrypt(pk_tk, m2, rng)
        raw = mult(pk_t, Ciphertext(grp, a.c1, a.c2), Ciphertext(grp, b.c1, b.c2))
        if sk_t.s != sk_tk.s:
            assert decrypt(SecretKey(grp, sk_tk.s), raw) != m1 * m2 % grp.p


def test_modified_theorem_at_712_bits():
    grp = shipped_group(712)
    rng = seeded_random(712)
    pk, sk = keygen(grp, rng)
    keys = [(pk, sk)]
    for _ in range(50):
        pk, sk, _ = key_update(pk, sk, rng)
        keys.append((pk, sk))
    for t, k in [(0, 1), (0, 50), (3, 17), (10, 40)]:
        (pk_t, sk_t), (pk_tk, sk_tk) = keys[t], keys[t + k]
        m1, m2 = member(grp, 10**200 + t), member(grp, 7**300 + k)
        ct = modified_eval(pk_t, encrypt(pk_t, m1, rng), encrypt(pk_tk, m2, rng))
        assert modified_decrypt(sk_t, sk_tk, ct) == m1 * m2 % grp.p


# ---------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "m, match",
    [
        (0, "m = 0 is not an element"),
        (5, "m = 5 is not in the order-q subgroup"),  # 5 is a non-residue mod 23
        (22, "m = 22 is not in the order-q subgroup"),
        (23, "m = 23 is outside"),
        (-4, "m = -4 is outside"),
        (2.0, "integer"),
        ("9", "integer"),
        (True, "integer"),
    ],
)
def test_encrypt_rejects_bad_plaintexts(m, match):
    pk, _ = keygen(TOY, 1)
    with pytest.raises(PlaintextError, match=match):
        encrypt(pk, m)


@pytest.mark.parametrize(
    "ct, match",
    [
        (Ciphertext(TOY, 0, 4), "c1 = 0 is outside"),
        (Ciphertext(TOY, 12, 23), "c2 = 23 is outside"),
        (Ciphertext(TOY, 5, 4), "c1 = 5 is not in the subgroup"),
        (Ciphertext(TOY, 12, 7), "c2 = 7 is not in the subgroup"),
        (ModifiedCiphertext(TOY, 12, 4, 18), "expected an ElGamal Ciphertext"),
        ((12, 4), "expected an ElGamal Ciphertext"),
    ],
)
def test_decrypt_rejects_bad_ciphertexts(ct, match):
    pk, sk = keygen(TOY, 1)
    with pytest.raises(CiphertextError, match=match):
        decrypt(sk, ct)
    with pytest.raises(CiphertextError):
        mult(pk, ct, Ciphertext(TOY, 12, 4))


def test_ciphertext_construction_rejects_non_integers():
    with pytest.raises(CiphertextError, match="c1 must be an integer"):
        Ciphertext(TOY, "12", 4)
    with pytest.raises(CiphertextError, match="time step"):
        Ciphertext(TOY, 12, 4, -1)
    with pytest.raises(CiphertextError, match="c3 must be an integer"):
        ModifiedCiphertext(TOY, 12, 4, 1.5)
    # The group comes first, as in PublicKey(group, h, t): the old (c1, c2, t) order is refused.
    with pytest.raises(CiphertextError, match="group must be a GroupParams"):
        Ciphertext(12, 4, 0)
    with pytest.raises(CiphertextError, match="group must be a GroupParams"):
        ModifiedCiphertext(12, 4, 18, 0, 1)


def test_modified_decrypt_rejects_two_component_ciphertext():
    _, sk = keygen(TOY, 1)
    with pytest.raises(CiphertextError, match="ModifiedCiphertext"):
        modified_decrypt(sk, sk, Ciphertext(TOY, 12, 4))
    with pytest.raises(CiphertextError, match="c3 = 5 is not in the subgroup"):
        modified_decrypt(sk, sk, ModifiedCiphertext(TOY, 12, 4, 5))


def test_wrong_time_step_is_detected():
    rng = seeded_random(3)  # one stream (an int seed would restart the stream at each call)
    pk0, sk0 = keygen(G64, rng)
    pk1, sk1, tok0 = key_update(pk0, sk0, rng)
    pk2, sk2, tok1 = key_update(pk1, sk1, rng)
    ct0 = encrypt(pk0, 4, rng)
    with pytest.raises(KeyMismatchError, match="step t = 0, secret key is of step t = 1"):
        decrypt(sk1, ct0)
    with pytest.raises(KeyMismatchError, match="same time step"):
        mult(pk0, ct0, encrypt(pk1, 4, rng))
    with pytest.raises(KeyMismatchError, match="token updates step t = 1"):
        ciphertext_update(pk1, ct0, tok1)
    with pytest.raises(KeyMismatchError, match="token is of step t = 1"):
        recover_next_secret_key(sk0, tok1)
    with pytest.raises(KeyMismatchError, match="pk is of step t = 1 but sk is of step t = 0"):
        key_update(pk1, sk0)
    mct = modified_eval(pk0, ct0, encrypt(pk2, 4, rng))
    assert modified_decrypt(sk0, sk2, mct) == 16
    with pytest.raises(KeyMismatchError, match="c2 is of step t = 2, sk2 is of step t = 1"):
        modified_decrypt(sk0, sk1, mct)
    with pytest.raises(KeyMismatchError, match="c1 is of step t = 0, sk1 is of step t = 1"):
        modified_decrypt(sk1, sk2, mct)
    # Without recorded steps nothing can be detected and Dec simply returns another element.
    bare = Ciphertext(G64, ct0.c1, ct0.c2)
    assert decrypt(sk0, bare) == 4 and decrypt(sk1, bare) != 4


def test_keys_from_another_group_are_rejected():
    pk_a, sk_a = keygen(G64, 1)
    pk_b, sk_b = keygen(G128, 1)
    with pytest.raises(KeyMismatchError, match="different groups"):
        key_update(pk_a, sk_b)
    with pytest.raises(KeyMismatchError, match="different groups"):
        modified_decrypt(sk_a, sk_b, ModifiedCiphertext(G64, 4, 4, 4))
    # A ciphertext knows its group: decrypting it under a key of another group is refused.
    ct_b = encrypt(pk_b, 2**100 % G128.p, seeded_random(1))
    with pytest.raises(KeyMismatchError, match="belongs to the group"):
        decrypt(sk_a, ct_b)
    # A public key element that is not in the group.
    with pytest.raises(KeyMismatchError, match="not an element of the group"):
        PublicKey(TOY, 5)
    with pytest.raises(KeyMismatchError, match="token h = 5"):
        UpdateToken(TOY, 5, 1)
    with pytest.raises(ParameterError, match="PublicKey"):
        encrypt(sk_a, 4)
    with pytest.raises(ParameterError, match="SecretKey"):
        decrypt(pk_a, Ciphertext(G64, 4, 4))


def test_secret_key_and_token_repr_hide_secrets():
    rng = seeded_random(9)
    pk, sk = keygen(G128, rng)
    _, _, tok = key_update(pk, sk, rng)
    assert tok.d > 10**6 and str(sk.s) not in repr(sk) and str(tok.d) not in repr(tok)
    with pytest.raises(ParameterError, match="secret exponent"):
        SecretKey(TOY, 11)


def test_int_seed_is_refused_by_encrypt_but_a_stream_is_fresh():
    # Documented rule (crypto.arith): Enc draws a fresh r at every call, so a bare int seed,
    # which would repeat r, is refused; one seeded stream gives fresh numbers at each call.
    pk, _ = keygen(G64, 1)
    with pytest.raises(ParameterError, match=r"rng=seeded_random\(5\)"):
        encrypt(pk, 4, 5)
    rng = seeded_random(5)
    assert encrypt(pk, 4, rng) != encrypt(pk, 4, rng)
    assert encrypt(pk, 4, seeded_random(5)) == encrypt(pk, 4, seeded_random(5))  # reproducible


def test_keygen_accepts_bits_and_secure_rng():
    pk, sk = keygen(64)
    assert pk.group == G64 and 1 <= sk.s < G64.q
    with pytest.raises(ParameterError):
        keygen(64.5)
    with pytest.raises(ParameterError):
        keygen("64")


# A value beyond Python's int-to-str limit (4300 digits): repr() of it raises ValueError, so a
# message that showed it with !r would itself fail; format_value shows its size instead.
HUGER = 10**5000
HUGER_SHOWN = "<integer of 16610 bits, about 5001 digits>"


def test_messages_survive_values_beyond_the_int_to_str_limit():
    from encctl_gym.crypto.arith import as_random_stream
    from encctl_gym.crypto.schemes import get_scheme
    from encctl_gym.crypto.servers import TokenControllerServer

    pk, sk = keygen(G64, 1)
    calls = [
        (lambda: encrypt(HUGER, 4, rng=seeded_random(1)), ParameterError, "pk must be a PublicKey, got int: "),
        (lambda: decrypt(sk, HUGER), CiphertextError, "expected an ElGamal Ciphertext"),
        (lambda: get_scheme(HUGER), ParameterError, "unknown scheme "),
        (lambda: seeded_random(1).spawn(HUGER), ParameterError, "purpose of a random stream must be a string, got "),
        (lambda: as_random_stream([HUGER], "encrypt"), ParameterError, "rng must be None"),
        (
            lambda: TokenControllerServer(pk, [[encrypt(pk, 4, seeded_random(2))]]).receive_token(HUGER),
            ParameterError,
            "token must be an UpdateToken, got ",
        ),
        (lambda: Ciphertext(G64, 4, 4, t=-HUGER), CiphertextError, "Ciphertext.t must be a time step >= 0, got -"),
    ]
    for call, err, start in calls:
        with pytest.raises(err) as info:
            call()
        text = str(info.value)
        assert start in text and HUGER_SHOWN in text and "\n" not in text, text


def test_server_refuses_state_ciphertexts_that_are_not_a_sequence():
    from encctl_gym.crypto.servers import ControllerServer

    pk, _ = keygen(G64, 1)
    server = ControllerServer(pk, [[encrypt(pk, 4, seeded_random(2))]])
    for bad in (42, None, 2.5):
        with pytest.raises(CiphertextError, match=r"state ciphertexts must be a sequence of 1 Ciphertext, got " + str(bad)):
            server.evaluate(bad)
