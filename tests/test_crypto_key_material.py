"""Key material and group membership (security): degenerate keys and groups are
refused, and every operation that combines keys, tokens and ciphertexts detects objects of
another group or another time step (KeyMismatchError) instead of returning garbage."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from encctl_gym.attacks.forgery import forge_injection
from encctl_gym.crypto.arith import RandomSource, seeded_random
from encctl_gym.crypto.controller import EncryptedLinearController
from encctl_gym.crypto.dyn_elgamal import UpdateToken, ciphertext_update, key_update, recover_next_secret_key
from encctl_gym.crypto.elgamal import Ciphertext, PublicKey, SecretKey, decrypt, encrypt, keygen, mult
from encctl_gym.crypto.encoding import Encoder
from encctl_gym.crypto.group import GroupParams, generate_safe_prime_group, shipped_group
from encctl_gym.crypto.modified import modified_decrypt, modified_eval
from encctl_gym.errors import GroupError, KeyMismatchError, ParameterError

TOY = GroupParams(23, 11, 4)  # G = {1, 2, 3, 4, 6, 8, 9, 12, 13, 16, 18}
G64 = shipped_group(64)
OTHER64 = generate_safe_prime_group(64, rng=64)  # another 64-bit group: same sizes, other p
PROP = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


class Fixed(RandomSource):
    """Returns prescribed exponents: between(1, q) yields the next value of ``exps``."""

    def __init__(self, *exps: int) -> None:
        self.exps = list(exps)

    def below(self, n: int) -> int:
        return self.exps.pop(0) - 1


def _square(grp: GroupParams, x: int) -> int:
    x = x % grp.p or 1
    return x * x % grp.p


# ---------------------------------------------------------------------------- degenerate keys and groups
def test_degenerate_keys_are_refused():
    with pytest.raises(ParameterError, match=r"secret exponent must lie in \[1, q\)"):
        SecretKey(TOY, 0)  # h = g^0 = 1
    with pytest.raises(ParameterError, match="secret exponent"):
        SecretKey(TOY, 11)
    with pytest.raises(KeyMismatchError, match="h = 1 is degenerate"):
        PublicKey(TOY, 1)  # Enc would output (g^r, m): the message in the clear
    with pytest.raises(KeyMismatchError, match="token h = 1"):
        UpdateToken(TOY, 1, 3)
    with pytest.raises(KeyMismatchError, match="d is outside"):
        UpdateToken(TOY, 4, 11)
    with pytest.raises(ParameterError, match="group must be a GroupParams"):
        PublicKey(23, 4)


@pytest.mark.parametrize("p, q, g", [(27, 13, 4), (23, 11, 5), (2 * 1000003 + 1, 1000003, 4)])
def test_keys_are_never_made_over_unverified_groups(p, q, g):
    grp = GroupParams(p, q, g)
    for make in (lambda: PublicKey(grp, 4), lambda: SecretKey(grp, 3), lambda: keygen(grp, 1)):
        with pytest.raises(GroupError):
            make()


def test_order_two_group_is_refused_although_it_would_verify():
    # (p, 2, p - 1): g = -1 has order 2 and p, 2 are prime, but the only key s = 1 is public.
    for p in (5, 23, G64.p):
        with pytest.raises(GroupError, match="q must be an odd prime"):
            GroupParams(p, 2, p - 1)


def test_ciphertext_update_never_outputs_the_plaintext():
    """CtUpd draws r again when c1 g^r = 1 (the second component would be the plaintext)."""
    pk, sk = keygen(TOY, Fixed(3))
    ct = encrypt(pk, 9, Fixed(5))  # c1 = 4^5 = 12
    _, sk1, tok = key_update(pk, sk, Fixed(7))
    # r = 6 gives c1 g^r = 4^11 = 1: refused, r = 2 is used (the known answer (8, 16)).
    out = ciphertext_update(pk, ct, tok, Fixed(6, 2))
    assert out == Ciphertext(TOY, 8, 16, 1) and decrypt(sk1, out) == 9


# ---------------------------------------------------------------------------- another group
def test_decrypting_under_another_group_was_garbage_and_is_now_refused():
    """40 tries of the probe: a ciphertext of one 64-bit group under the key of another."""
    rng = seeded_random(40)
    refused = 0
    for i in range(40):
        pk_a, _ = keygen(G64, rng)
        _, sk_b = keygen(OTHER64, rng)
        ct = encrypt(pk_a, _square(G64, i + 2), rng)
        with pytest.raises(KeyMismatchError, match="belongs to the group"):
            decrypt(sk_b, ct)
        refused += 1
    assert refused == 40


@PROP
@given(seed=st.integers(0, 2**64), x1=st.integers(1, 2**70), x2=st.integers(1, 2**70))
def test_every_combining_operation_detects_another_group(seed, x1, x2):
    rng = seeded_random(seed)
    pk, sk = keygen(G64, rng)
    pk_o, sk_o = keygen(OTHER64, rng)
    ct = encrypt(pk, _square(G64, x1), rng)
    ct_o = encrypt(pk_o, _square(OTHER64, x2), rng)
    pk1, sk1, tok = key_update(pk, sk, rng)
    _, _, tok_o = key_update(pk_o, sk_o, rng)
    mct = modified_eval(pk, ct, encrypt(pk1, _square(G64, x2), rng))
    mct_o = modified_eval(pk_o, ct_o, ct_o)
    checks = [
        lambda: decrypt(sk_o, ct),
        lambda: mult(pk, ct, ct_o),
        lambda: mult(pk_o, ct, ct),
        lambda: modified_eval(pk, ct, ct_o),
        lambda: modified_eval(pk_o, ct, ct),
        lambda: modified_decrypt(sk_o, sk_o, mct),
        lambda: modified_decrypt(sk, sk1, mct_o),
        lambda: modified_decrypt(sk, sk_o, mct),
        lambda: key_update(pk, sk_o, rng),
        lambda: ciphertext_update(pk, ct_o, tok, rng),
        lambda: ciphertext_update(pk, ct, tok_o, rng),
        lambda: recover_next_secret_key(sk, tok_o),
    ]
    for check in checks:
        with pytest.raises(KeyMismatchError):
            check()
    # ... while the same operations within one group work.
    assert decrypt(sk, ct) == _square(G64, x1)
    assert modified_decrypt(sk, sk1, mct) == _square(G64, x1) * _square(G64, x2) % G64.p


def test_the_encrypted_controller_refuses_ciphertexts_of_another_group():
    phi = np.array([[0.5, -1.0], [2.0, 0.25]])
    ctrl = EncryptedLinearController(phi, G64, 2.0**8, 10.0, rng=1)
    other = EncryptedLinearController(phi, OTHER64, 2.0**8, 10.0, rng=1)
    x = np.array([1.0, -2.0])
    with pytest.raises(KeyMismatchError, match="belongs to the group"):
        ctrl.server.evaluate(other.plant.encrypt_state(x))
    forged = forge_injection(other.pk0, other.pk, [1.0, 2.0], Encoder(OTHER64, 2.0**8), 2, seeded_random(2))
    with pytest.raises(KeyMismatchError, match="belongs to the group"):
        ctrl.step(x, inject=forged)
    tok = EncryptedLinearController(phi, G64, 2.0**8, 10.0, scheme="token", rng=1)
    other_tok = EncryptedLinearController(phi, OTHER64, 2.0**8, 10.0, scheme="token", rng=1)
    with pytest.raises(KeyMismatchError, match="belongs to the group"):
        tok.server.evaluate(other_tok.plant.encrypt_state(x))
    _, _, foreign_token = key_update(*keygen(OTHER64, 3), seeded_random(3))
    with pytest.raises(KeyMismatchError):
        tok.server.receive_token(foreign_token)
    assert np.array_equal(ctrl.step(x), ctrl.reference(x))  # nothing was corrupted


# ---------------------------------------------------------------------------- another step
@PROP
@given(seed=st.integers(0, 2**64), t=st.integers(0, 6), k=st.integers(1, 6), x=st.integers(1, 2**70))
def test_every_combining_operation_detects_another_step(seed, t, k, x):
    rng = seeded_random(seed)
    keys = [keygen(G64, rng)]
    for _ in range(t + k):
        pk, sk, _ = key_update(*keys[-1], rng)
        keys.append((pk, sk))
    (pk_t, sk_t), (pk_tk, sk_tk) = keys[t], keys[t + k]
    m = _square(G64, x)
    ct_t, ct_tk = encrypt(pk_t, m, rng), encrypt(pk_tk, m, rng)
    with pytest.raises(KeyMismatchError, match="step"):
        decrypt(sk_tk, ct_t)
    with pytest.raises(KeyMismatchError, match="same time step"):
        mult(pk_t, ct_t, ct_tk)
    mct = modified_eval(pk_t, ct_t, ct_tk)
    with pytest.raises(KeyMismatchError, match="step"):
        modified_decrypt(sk_tk, sk_tk, mct)
    with pytest.raises(KeyMismatchError, match="step"):
        modified_decrypt(sk_t, sk_t, mct)
    _, _, tok_t = key_update(pk_t, sk_t, rng)
    with pytest.raises(KeyMismatchError, match="step"):
        ciphertext_update(pk_t, ct_tk, tok_t, rng)
    assert modified_decrypt(sk_t, sk_tk, mct) == m * m % G64.p
