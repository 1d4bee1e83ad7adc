"""Tests of the encrypted linear controller of eq:ec (crypto.controller and its parties:
crypto.quantized, crypto.servers, crypto.plant_side, crypto.schemes) and of the forging of
injected inputs (attacks.forgery, through each scheme's ``forge`` of loop.scheme)."""

from __future__ import annotations

import gc
import types

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from encctl_gym.attacks.forgery import forge_injection, forge_injection_token, injection_value
from encctl_gym.crypto.arith import PowmodCounter, RandomSource, seeded_random
from encctl_gym.crypto.controller import EncryptedLinearController
from encctl_gym.crypto.dyn_elgamal import UpdateToken, recover_next_secret_key
from encctl_gym.crypto.elgamal import Ciphertext, SecretKey, decrypt, keygen
from encctl_gym.crypto.encoding import Encoder
from encctl_gym.crypto.group import shipped_group
from encctl_gym.crypto.modified import ModifiedCiphertext, modified_decrypt, modified_eval
from encctl_gym.crypto.plant_side import PlantParty, StaticPlant
from encctl_gym.crypto.quantized import QuantizedLinearController
from encctl_gym.crypto.schemes import ELGAMAL_VARIANTS
from encctl_gym.crypto.servers import ControllerServer, StaticControllerServer
from encctl_gym.errors import CiphertextError, EncodingOverflowError, KeyMismatchError, ParameterError
from encctl_gym.loop.scheme import SCHEMES as LOOP_SCHEMES

G64, G128 = shipped_group(64), shipped_group(128)
PHI = np.array([[0.5, -1.2, 0.3, 0.0], [1.0, 2.0, -3.0, 0.25], [0.1, 0.2, 0.3, 0.4], [-1.0, -1.0, -1.0, -1.0]])


def _x(seed: int, n: int = 4, bound: float = 10.0) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-bound, bound, n)


# ---------------------------------------------------------------------------- correctness
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    phi=hnp.arrays(np.float64, st.tuples(st.integers(1, 3), st.integers(1, 4)), elements=st.floats(-5, 5, allow_nan=False)),
    seed=st.integers(0, 2**32),
    log_delta=st.integers(4, 16),
    scheme=st.sampled_from(["modified", "token"]),
    big=st.booleans(),
)
def test_encrypted_equals_quantized_bit_for_bit(phi, seed, log_delta, scheme, big):
    grp = G128 if big else G64
    delta, x_bound = 2.0**log_delta, 8.0
    ctrl = EncryptedLinearController(phi, grp, delta, x_bound, scheme=scheme, rng=seed)
    ref = QuantizedLinearController(phi, Encoder(grp, delta), x_bound)
    rng = np.random.default_rng(seed)
    for t in range(4):
        x = rng.uniform(-x_bound, x_bound, phi.shape[1])
        if t == 3:
            x = x_bound * np.sign(x)  # the declared extremes
        u = ctrl.step(x)
        assert u.shape == (phi.shape[0],) and u.dtype == np.float64
        assert np.array_equal(u, ref.compute(x))  # bit-identical
        assert np.array_equal(u, ctrl.reference(x))
        # Quantisation error: |u - Phi x| <= sum_j |Phi_ij| e_x + |x_j| e_Phi + e_Phi e_x.
        e = ctrl.encoder.error_bound()
        bound = (np.abs(phi) * e + np.abs(x) * e + e * e).sum(axis=1)
        assert np.all(np.abs(u - phi @ x) <= bound * (1 + 1e-9))
        assert ctrl.t == t + 1


def test_two_key_decryption_matches_modified_decrypt():
    ctrl = EncryptedLinearController(PHI, G128, 2.0**12, 10.0, rng=1)
    sk0 = ctrl.plant.initial_secret_key
    for t in range(3):
        x = _x(t)
        sk_t = ctrl.plant.secret_key
        ct_x = ctrl.plant.encrypt_state(x)
        out = ctrl.server.evaluate(ct_x)
        fast = ctrl.plant.decrypt_products(out)
        for i, row in enumerate(out):
            for j, c in enumerate(row):
                assert c == modified_eval(ctrl.pk0, ctrl.server.ct_phi[i][j], ct_x[j])
                m = modified_decrypt(sk0, sk_t, c)
                assert fast[i][j] == (m if m <= G128.half else m - G128.p)
                assert fast[i][j] == ctrl.quantized.phi_int[i, j] * ctrl.quantized.encode_state(x)[j]
        ctrl.plant.update_keys()


def test_powmod_count_per_step():
    """n = m = 4: 8 (encrypt) + 1 (key update) + 4 (column parts) = 13; the server does none."""
    grp = shipped_group(256)
    ctrl = EncryptedLinearController(PHI, grp, 2.0**16, 10.0, rng=2)
    for t in range(3):
        with PowmodCounter() as c:
            ctrl.step(_x(t))
        assert c.count == 13
    with PowmodCounter() as c:
        ctrl.server.evaluate(ctrl.plant.encrypt_state(_x(9)))
    assert c.count == 8  # only the 8 of the plant's encryption
    tok = EncryptedLinearController(PHI, grp, 2.0**16, 10.0, scheme="token", rng=2)
    with PowmodCounter() as c:
        tok.step(_x(0))
    # 8 + 1 + 16 decryptions + 16 * 3 for CtUpd on the server.
    assert c.count == 8 + 1 + 16 + 48


def test_keys_advance_and_eavesdropper_view():
    ctrl = EncryptedLinearController(PHI, G64, 2.0**10, 10.0, rng=3)
    assert ctrl.t == 0 and ctrl.pk == ctrl.pk0 and ctrl.last_state_ciphertexts is None
    pks = [ctrl.pk]
    for t in range(3):
        ctrl.step(_x(t))
        pks.append(ctrl.pk)
        assert [c.t for c in ctrl.last_state_ciphertexts] == [t] * 4
        assert all(
            isinstance(c, ModifiedCiphertext) and (c.t1, c.t2) == (0, t) for row in ctrl.last_output_ciphertexts for c in row
        )
    assert [pk.t for pk in pks] == [0, 1, 2, 3] and len({pk.h for pk in pks}) == 4
    assert ctrl.server.pk0 == ctrl.pk0  # the server never sees later keys


# ---------------------------------------------------------------------------- no secrets on the server
_SECRET_TYPES = (SecretKey, UpdateToken, RandomSource, PlantParty, EncryptedLinearController)


def _reachable(root):
    """Every object reachable from ``root`` (gc referents), not descending into types/modules/code."""
    seen, stack, out = set(), [root], []
    while stack:
        obj = stack.pop()
        if id(obj) in seen or isinstance(
            obj, (type, types.ModuleType, types.FunctionType, types.BuiltinFunctionType, types.CodeType)
        ):
            continue
        seen.add(id(obj))
        out.append(obj)
        stack.extend(gc.get_referents(obj))
    return out


def _secrets_reachable(server, secret_ints):
    found = []
    for obj in _reachable(server):
        if isinstance(obj, _SECRET_TYPES):
            found.append(obj)
        elif isinstance(obj, int) and not isinstance(obj, bool) and obj in secret_ints:
            found.append(obj)
    return found


@pytest.mark.parametrize("scheme", ["modified", "token"])
def test_server_holds_no_secret_key_or_token(scheme):
    ctrl = EncryptedLinearController(PHI, G128, 2.0**12, 10.0, scheme=scheme, rng=4)
    plant = ctrl.plant
    secret_ints = {plant.initial_secret_key.s}
    tokens = []
    original = plant.update_keys

    def recording_update():
        tok = original()
        tokens.append(tok)
        secret_ints.update({plant.secret_key.s, tok.d})
        return tok

    plant.update_keys = recording_update
    for t in range(5):
        ctrl.step(_x(t))
    assert len(secret_ints) == 11
    found = _secrets_reachable(ctrl.server, secret_ints)
    if scheme == "modified":
        assert type(ctrl.server) is ControllerServer
        assert not hasattr(ctrl.server, "__dict__")  # __slots__ only: nothing can be attached
        assert found == []
        # ... while the walker does reach the public material it should.
        reach = _reachable(ctrl.server)
        assert any(o is ctrl.pk0 for o in reach) and ctrl.pk0.h in {o for o in reach if isinstance(o, int)}
    else:
        # Negative control: the conventional server keeps a token, and the walker finds it.
        assert any(isinstance(o, UpdateToken) for o in found) and tokens[-1].d in found


def test_token_scheme_malicious_server_reads_all_later_states():
    """Proposition prop:vulnerability end to end: one broken key + tokens = every later state."""
    ctrl = EncryptedLinearController(PHI, G128, 2.0**12, 10.0, scheme="token", rng=5)
    stolen = ctrl.plant.secret_key  # the server breaks sk_0 once
    for t in range(6):
        x = _x(t)
        ctrl.step(x)
        expected = ctrl.quantized.encode_state(x)
        got = [decrypt(stolen, c) for c in ctrl.last_state_ciphertexts]
        assert [m if m <= G128.half else m - G128.p for m in got] == expected
        stolen = recover_next_secret_key(stolen, ctrl.server.last_token)
    assert stolen == ctrl.plant.secret_key


# ---------------------------------------------------------------------------- overflow and bad input
def test_overflow_checked_at_construction():
    # 64-bit group: (p-1)/2 ~ 6.9e18. Delta = 2^20: products ~ Delta^2 |Phi| |x| ~ 1.1e12 |Phi x|.
    ok = EncryptedLinearController(PHI, G64, 2.0**20, 1000.0, rng=6)
    x = 1000.0 * np.sign(PHI[1])  # worst case of row 1
    assert np.array_equal(ok.step(x), ok.reference(x))
    assert abs(ok.step(x)[1] - PHI[1] @ x) < 1e-2
    with pytest.raises(EncodingOverflowError, match="row 1 of Phi can overflow"):
        EncryptedLinearController(PHI, G64, 2.0**20, 2.0e6, rng=6)
    with pytest.raises(EncodingOverflowError, match="row 0 of Phi can overflow"):
        QuantizedLinearController(PHI, Encoder(G64, 2.0**30), 10.0)
    # A value just beyond the declared bound is rejected at step time, naming it.
    with pytest.raises(EncodingOverflowError, match="x = 1000.5 is outside"):
        ok.step([0.0, 1000.5, 0.0, 0.0])


def test_overflow_check_is_tight_enough_to_matter():
    """Without the check, the worst case really wraps: the integer row sum exceeds (p-1)/2."""
    enc = Encoder(G64, 2.0**20)
    with pytest.raises(EncodingOverflowError):
        QuantizedLinearController(PHI, enc, 2.0e6)
    w_phi = enc.encode_signed_array(PHI)
    w_x = enc.encode_signed_array(2.0e6 * np.sign(PHI[1]))
    assert abs(sum(int(a) * int(b) for a, b in zip(w_phi[1], w_x))) > G64.half


@pytest.mark.parametrize(
    "x, err, match",
    [
        ([1.0, 2.0, 3.0], ParameterError, "4 entries"),
        ([1.0, 2.0, 3.0, float("nan")], ParameterError, "finite"),
        ([1.0, 2.0, 3.0, float("inf")], ParameterError, "finite"),
        ([1.0, 2.0, 3.0, 11.0], EncodingOverflowError, "x = 11.0 is outside"),
        ("abcd", ParameterError, "numeric"),
    ],
)
def test_step_bad_input(x, err, match):
    ctrl = EncryptedLinearController(PHI, G64, 2.0**10, 10.0, rng=7)
    with pytest.raises(err, match=match):
        ctrl.step(x)
    assert ctrl.t == 0  # nothing advanced


def test_constructor_bad_input():
    with pytest.raises(ParameterError, match="scheme"):
        EncryptedLinearController(PHI, G64, 2.0**10, 10.0, scheme="rsa")
    with pytest.raises(ParameterError, match="delta"):
        EncryptedLinearController(PHI, G64, 0.0, 10.0)
    with pytest.raises(ParameterError, match="x_bound"):
        EncryptedLinearController(PHI, G64, 2.0**10, -1.0)
    with pytest.raises(ParameterError, match="Phi"):
        EncryptedLinearController([[1.0, np.nan]], G64, 2.0**10, 1.0)
    with pytest.raises(ParameterError, match="Phi"):
        EncryptedLinearController(np.ones((2, 2, 2)), G64, 2.0**10, 1.0)
    with pytest.raises(ParameterError, match="bits"):
        EncryptedLinearController(PHI, 8, 2.0**10, 1.0)
    with pytest.raises(ParameterError, match="encoder"):
        QuantizedLinearController(PHI, G64, 1.0)


def test_server_rejects_bad_state_ciphertexts():
    ctrl = EncryptedLinearController(PHI, G64, 2.0**10, 10.0, rng=8)
    cts = ctrl.plant.encrypt_state(_x(0))
    with pytest.raises(CiphertextError, match="expected 4 state ciphertexts, got 3"):
        ctrl.server.evaluate(cts[:3])
    with pytest.raises(CiphertextError, match="expected an ElGamal Ciphertext"):
        ctrl.server.evaluate(cts[:3] + [ModifiedCiphertext(G64, 4, 4, 4)])
    with pytest.raises(CiphertextError, match="outside"):
        ctrl.server.evaluate(cts[:3] + [Ciphertext(G64, G64.p + 1, 4)])
    with pytest.raises(CiphertextError, match="rectangular"):
        ControllerServer(ctrl.pk0, [[cts[0]], [cts[0], cts[1]]])
    with pytest.raises(CiphertextError, match="matrix"):
        ControllerServer(ctrl.pk0, 5)
    token = EncryptedLinearController(PHI, G64, 2.0**10, 10.0, scheme="token", rng=8)
    with pytest.raises(KeyMismatchError, match="token is for step t = 5"):
        token.server.receive_token(UpdateToken(G64, 4, 1, 5))
    old = token.plant.encrypt_state(_x(1))
    token.step(_x(1))
    with pytest.raises(KeyMismatchError, match="state ciphertext is of step t = 0"):
        token.server.evaluate(old)


# ---------------------------------------------------------------------------- injection
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    a=hnp.arrays(np.float64, 4, elements=st.floats(-50, 50, allow_nan=False)),
    seed=st.integers(0, 2**32),
    steps_before=st.integers(0, 3),
    scheme=st.sampled_from(["modified", "token"]),
)
def test_injection_from_public_keys_is_decoded_exactly(a, seed, steps_before, scheme):
    ctrl = EncryptedLinearController(PHI, G128, 2.0**12, 10.0, scheme=scheme, rng=seed)
    for t in range(steps_before):
        ctrl.step(_x(t))
    adversary_rng = seeded_random(seed + 1)
    if scheme == "modified":
        forged = forge_injection(ctrl.pk0, ctrl.pk, a, ctrl.encoder, ctrl.beta, adversary_rng)
    else:
        forged = forge_injection_token(ctrl.pk, a, ctrl.encoder, ctrl.beta, adversary_rng)
    u = ctrl.step(_x(99), inject=forged)
    expected = injection_value(a, ctrl.encoder, ctrl.beta)
    assert np.array_equal(u, expected)  # bit for bit
    # Delta = 2^12 is a perfect square, so Ecd(1) = Delta: a quantised at 1/Delta plus 3 Ecd(0)^2/Delta^2
    enc = ctrl.encoder
    assert enc.encode_signed(1.0) == enc.delta
    assert np.all(np.abs(u - a) <= (0.5 + enc.max_shift) / enc.delta + 3 / enc.delta**2)
    assert ctrl.last_output_ciphertexts == forged
    # The loop carries on normally afterwards.
    x = _x(5)
    assert np.array_equal(ctrl.step(x), ctrl.reference(x))


def test_injection_known_answer_small_case():
    enc = Encoder(G64, 4.0)
    # Delta = 4 = 2^2 is a square, so Ecd(1) = 4; Ecd(0) = 1 (0 is not in G, 1 is its nearest member).
    # a = 1.3: round(5.2) = 5 -> w = nearest member of G to 5; value (4 w + 3 * 1^2) / 16.
    assert enc.encode_signed(1.0) == 4 and enc.encode_signed(0.0) == 1
    w = enc.encode_signed(1.3)
    val = injection_value([1.3], enc, 4)
    assert val[0] == (4 * w + 3) / 16
    assert abs(val[0] - 1.3) <= (0.5 + enc.max_shift) / 4 + 3 / 16


def test_injection_bad_input():
    ctrl = EncryptedLinearController(PHI, G64, 2.0**10, 10.0, rng=9)
    other_pk, _ = keygen(G128, 1)
    with pytest.raises(KeyMismatchError, match="different groups"):
        forge_injection(ctrl.pk0, other_pk, np.ones(4), ctrl.encoder, 4)
    with pytest.raises(EncodingOverflowError, match="a = 1e\\+20 is not representable"):
        forge_injection(ctrl.pk0, ctrl.pk, [1e20, 0, 0, 0], ctrl.encoder, 4)
    with pytest.raises(ParameterError, match="finite"):
        injection_value([np.nan], ctrl.encoder, 4)
    with pytest.raises(ParameterError, match="n_cols"):
        injection_value([1.0], ctrl.encoder, 0)
    # Forged with a stale public key: the plant detects the wrong step.
    ctrl.step(_x(0))
    stale = forge_injection(ctrl.pk0, ctrl.pk0, np.ones(4), ctrl.encoder, 4, seeded_random(1))
    with pytest.raises(KeyMismatchError, match=r"\(t1, t2\) = \(0, 0\)"):
        ctrl.step(_x(1), inject=stale)
    # Wrong shape or type.
    good = forge_injection(ctrl.pk0, ctrl.pk, np.ones(4), ctrl.encoder, 4, seeded_random(1))
    with pytest.raises(CiphertextError, match="shape"):
        ctrl.step(_x(1), inject=[row[:3] for row in good])
    with pytest.raises(CiphertextError, match="ModifiedCiphertext"):
        ctrl.step(_x(1), inject=[[Ciphertext(G64, 4, 4)] * 4] * 4)
    bad = [list(r) for r in good]
    bad[2][1] = ModifiedCiphertext(G64, good[2][1].c1, good[2][1].c2, 0, 0, ctrl.t)
    with pytest.raises(CiphertextError, match="c3 = 0"):
        ctrl.step(_x(1), inject=bad)


@pytest.mark.parametrize(
    "inject, match",
    [
        (42, "inject must be a matrix of ModifiedCiphertext, got int"),
        ("abcd", "inject must have shape \\(4, 4\\), got \\(4, 1\\)"),
        ([], "inject must be a non-empty rectangular matrix"),
        ([[None] * 4] * 4, "inject must contain ModifiedCiphertext entries, got NoneType"),
    ],
    ids=["int", "str", "empty", "None-entries"],
)
def test_injection_must_be_a_matrix_of_the_plants_ciphertexts(inject, match):
    ctrl = EncryptedLinearController(PHI, G64, 2.0**10, 10.0, rng=9)
    with pytest.raises(CiphertextError, match=match):
        ctrl.step(_x(1), inject=inject)
    # the refused injection changed nothing: a valid one still decodes exactly after it
    a = np.array([0.5, -0.25, 1.0, 0.0])
    forged = forge_injection(ctrl.pk0, ctrl.pk, a, ctrl.encoder, 4, seeded_random(2))
    assert np.array_equal(ctrl.step(_x(2), inject=forged), injection_value(a, ctrl.encoder, 4))


# ---------------------------------------------------------------------------- quantized twin
def test_every_scheme_pairs_its_plant_and_server_and_forgery():
    """The registry's parties run the loop for every scheme; static keys never change and the
    forged output of each scheme decodes to injection_value."""
    assert set(ELGAMAL_VARIANTS) == {"modified", "token", "static"}
    a = np.array([0.5, -1.0, 2.0, 0.0])
    for name, scheme in ELGAMAL_VARIANTS.items():
        ctrl = EncryptedLinearController(PHI, G128, 2.0**12, 10.0, scheme=name, rng=3)
        assert isinstance(ctrl.plant, scheme.plant)
        pk0 = ctrl.pk0
        for t in range(3):
            assert np.array_equal(ctrl.step(_x(t)), ctrl.reference(_x(t)))
        assert (ctrl.pk == pk0) == (name == "static") and (ctrl.t == 0) == (name == "static")
        forged = LOOP_SCHEMES.build(name).forge(ctrl.plant, a, ctrl.encoder, 4, seeded_random(2))
        assert np.array_equal(ctrl.step(_x(5), inject=forged), injection_value(a, ctrl.encoder, 4))
    static = EncryptedLinearController(PHI, G128, 2.0**12, 10.0, scheme="static", rng=3)
    assert type(static.server) is StaticControllerServer and isinstance(static.plant, StaticPlant)
    assert static.plant.update_keys() is None


@pytest.mark.parametrize("scheme", ["modified", "token"])
def test_per_entry_forgery_hides_the_input_and_decodes_the_same(scheme):
    """With one randomness per matrix the entries that encrypt Ecd(0)^2 = 1 carry the mask, so
    an onlooker divides it out and reads Ecd(a_i) Ecd(1); with per_entry=True the masks differ."""
    ctrl = EncryptedLinearController(PHI, G128, 2.0**12, 10.0, scheme=scheme, rng=5)
    a = np.array([1.25, -0.5, 0.0, 3.0])
    p = G128.p
    last = (lambda c: c.c3) if scheme == "modified" else (lambda c: c.c2)
    for per_entry in (False, True):
        out = LOOP_SCHEMES.build(scheme, per_entry=per_entry).forge(ctrl.plant, a, ctrl.encoder, 4, seeded_random(7))
        masks = {last(c) for row in out for c in row[1:]}  # entries that encrypt the known 1
        read = [last(row[0]) * pow(last(row[1]), -1, p) % p for row in out]
        truth = [w % p for w in (ctrl.encoder.encode_signed(float(ai)) * ctrl.encoder.encode_signed(1.0) for ai in a)]
        assert (read == truth) == (not per_entry)
        assert (len(masks) == 1) == (not per_entry)
        assert np.array_equal(ctrl.step(_x(per_entry), inject=out), injection_value(a, ctrl.encoder, 4))


@pytest.mark.parametrize("bits", [712])
def test_encrypted_controller_at_712_bits(bits):
    grp = shipped_group(bits)
    for scheme in ("modified", "token"):
        ctrl = EncryptedLinearController(PHI, grp, 2.0**24, 100.0, scheme=scheme, rng=10)
        for t in range(3):
            x = _x(t, bound=100.0)
            assert np.array_equal(ctrl.step(x), ctrl.reference(x))
        a = np.array([1.5, -2.25, 0.0, 7.0])
        forged = (
            forge_injection(ctrl.pk0, ctrl.pk, a, ctrl.encoder, 4, seeded_random(1))
            if scheme == "modified"
            else forge_injection_token(ctrl.pk, a, ctrl.encoder, 4, seeded_random(1))
        )
        assert np.array_equal(ctrl.step(_x(9), inject=forged), injection_value(a, ctrl.encoder, 4))
