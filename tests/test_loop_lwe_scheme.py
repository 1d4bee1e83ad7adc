"""LWE through the scheme seam (issue #32): the scheme in the loop, both backends bit for bit,
its modulus sized for the loop, its keys, its cost models and ``design --scheme lwe``."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from episodes import rollout
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.crypto import lwe
from encctl_gym.crypto.arith import seeded_random
from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv
from encctl_gym.errors import EncodingOverflowError, KeyMismatchError, ParameterError, ShapeError
from encctl_gym.loop import SCHEMES, EncryptionScheme, make_scheme
from encctl_gym.loop.lwe_scheme import LWE_MODELS, LWEDimension, LWEScheme
from encctl_gym.security.cost_models.lattice import PrimalUSVPModel, binomial_sigma, primal_usvp_estimate

BASE = {"preset": "small", "gamma_opt": False, "key_length": 48, "max_samples": 20, "warmup_steps": 2}
BASE |= {"scheme": "lwe", "crypto_seed": 3, "decipher_delay": 0}
PHI = np.array([[-0.3, 0.1], [0.05, -0.4]])


def _quantization(n: int = 16, delta: float = 64.0, x_bound: float = 5.0, u_max: float = 2.0):
    scheme = LWEScheme()
    return scheme, scheme.quantization(PHI, scheme.encoder(scheme.public_parameters(n), delta), x_bound, u_max)


# ----------------------------------------------------------------------------- crypto helpers
@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(-40, 40), min_size=3, max_size=3), st.lists(st.integers(-40, 40), min_size=3, max_size=3))
def test_adding_known_integers_decrypts_to_the_sum_and_keeps_the_noise(mu: list[int], d: list[int]) -> None:
    p = lwe.LWEParams(n=12, q=1 << 30, t=257)
    pk, sk = lwe.keygen(p, rng=np.random.default_rng(1))
    ct = lwe.encrypt(pk, np.array(mu), rng=np.random.default_rng(2))
    out = lwe.add_plaintext(ct, d)
    assert lwe.decrypt(sk, out).tolist() == [a + b for a, b in zip(mu, d)]
    assert out.noise_bound == ct.noise_bound
    assert [b - a for a, b in zip(ct.message_bound, out.message_bound)] == [abs(v) for v in d]
    assert [int(lwe.decrypt(sk, c)[0]) for c in lwe.split(ct)] == mu


def test_adding_beyond_the_plaintext_space_is_refused_before_any_arithmetic() -> None:
    p = lwe.LWEParams(n=8, q=1 << 24, t=101)
    pk, _ = lwe.keygen(p, rng=seeded_random(1))
    ct = lwe.encrypt(pk, np.array([40]), rng=seeded_random(2))
    with pytest.raises(EncodingOverflowError, match="plaintext range"):
        lwe.add_plaintext(ct, [11])  # 40 + 11 > (t - 1) / 2 = 50
    with pytest.raises(ShapeError, match="1 entries"):
        lwe.add_plaintext(ct, [1, 2])


def test_the_message_margin_widens_the_plaintext_space_by_exactly_that() -> None:
    a = lwe.controller_parameters(16, PHI, 64, 64, 5.0)
    b = lwe.controller_parameters(16, PHI, 64, 64, 5.0, message_margin=1000)
    assert b.t == a.t + 2000 and b.delta_q == a.delta_q
    with pytest.raises(ParameterError, match="message_margin"):
        lwe.controller_parameters(16, PHI, 64, 64, 5.0, message_margin=-1)


# ----------------------------------------------------------------------------- the scheme
def test_the_scheme_is_registered_and_implements_the_protocol() -> None:
    assert "lwe" in SCHEMES and isinstance(make_scheme("lwe"), EncryptionScheme)
    scheme = make_scheme({"name": "lwe", "rotation_period": 1})
    assert scheme.family == "lattice" and scheme.independent_keys("eavesdropper")
    assert not make_scheme("lwe").independent_keys("eavesdropper")
    code = "from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv as E; import numpy as np; "
    code += (
        f"e = E(config={ {**BASE, 'crypto': 'elgamal'}!r}); e.reset(seed=0); print(type(e.unwrapped.loop.encryption).__name__)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "LWEScheme"


def test_the_modulus_holds_every_honest_and_every_injected_output() -> None:
    scheme, quant = _quantization()
    p = quant.params
    row = int(np.abs(quant.phi_int).sum(axis=1).max())
    honest, injected = row * int(round(64 * 5.0)), int(round(64 * 2.0)) * 64
    assert p.max_message >= honest + injected  # room for u + a with |a| <= u_max
    assert p.max_noise >= row * p.fresh_noise_bound
    plant, server = scheme.parties(quant, np.random.default_rng(0), np.random.default_rng(1))
    x = np.array([5.0, -5.0])  # the worst state
    out = scheme.add(plant, scheme.evaluate(server, scheme.encrypt_state(plant, x)), np.array([2.0, -2.0]), None, None, None)
    expected = (quant.phi_int @ lwe.encode(x, 64.0) + np.array([128 * 64, -128 * 64])) / 64.0**2
    assert np.array_equal(scheme.decrypt_output(plant, out), expected)
    with pytest.raises(EncodingOverflowError, match="x_bound"):
        scheme.encrypt_state(plant, np.array([5.01, 0.0]))


def test_fresh_keys_every_k_steps_and_a_shared_matrix_keeps_a() -> None:
    for shared in (False, True):
        scheme = LWEScheme(rotation_period=2, shared_matrix=shared)
        _, quant = _quantization()
        plant, server = scheme.parties(quant, np.random.default_rng(0), np.random.default_rng(1))
        first = plant.pk
        scheme.update_keys(plant, server)
        assert plant.pk is first
        scheme.update_keys(plant, server)
        assert plant.pk is not first and server.pk is plant.pk and plant.keys == 2
        assert np.array_equal(plant.pk.A, first.A) == shared
        assert scheme.oracle_secret(plant) is plant.sk
        with pytest.raises(KeyMismatchError):
            scheme.oracle_secret(plant, first)
    with pytest.raises(ParameterError, match="shared_matrix needs rotation_period"):
        LWEScheme(shared_matrix=True)


@pytest.mark.parametrize("injection", ["replace", "add", "pass"])
def test_both_backends_give_the_same_lwe_episode_bit_for_bit(injection: str) -> None:
    runs = [
        rollout(EncryptedLTIAttackEnv(config={**BASE, "crypto": c, "injection": injection}), seed=4, action_seed=9)
        for c in ("elgamal", "ideal")
    ]
    assert len(runs[0]) == len(runs[1]) > 10
    assert all(np.array_equal(a, b) for a, b in zip(*runs))
    assert not all(np.array_equal(runs[0][0], r) for r in runs[0][1:])


def test_adding_a_zero_action_is_the_honest_loop() -> None:
    zero = rollout(
        EncryptedLTIAttackEnv(config={**BASE, "crypto": "elgamal", "injection": "add"}), seed=2, action_seed=0, actions="zero"
    )
    honest = rollout(
        EncryptedLTIAttackEnv(config={**BASE, "crypto": "elgamal", "injection": "pass"}), seed=2, action_seed=0, actions="zero"
    )
    assert all(np.array_equal(a, b) for a, b in zip(zero, honest))


@pytest.mark.parametrize("crypto", ["ideal", "elgamal"])
def test_a_loop_the_int64_modulus_cannot_hold_is_refused_when_the_environment_is_made(crypto: str) -> None:
    with pytest.raises(ParameterError, match="lwe scheme cannot hold this loop.*use a smaller delta"):
        EncryptedLTIAttackEnv(config={**BASE, "crypto": crypto, "key_length": 1600})


def test_the_game_runs_on_lwe_with_the_linear_check() -> None:
    from encctl_gym.multiagent.encctl_game_v0 import parallel_env

    game = parallel_env(config={**BASE, "crypto": "elgamal", "max_samples": 10})
    game.reset(seed=0)
    rng, checks = np.random.default_rng(2), 0
    while game.agents:
        acts = {a: rng.uniform(-1, 1, game.action_space(a).shape).astype(np.float32) for a in game.agents}
        acts["defender"][2], acts["defender"][3] = -1.0, 1.0  # no rotation; verify every step
        _, rewards, _, _, infos = game.step(acts)
        checks = infos["defender"]["checks"]
        assert all(np.isfinite(r) for r in rewards.values())
    assert checks >= 1


# ----------------------------------------------------------------------------- cost models
def test_the_models_price_a_dimension_at_the_int64_ceiling_modulus() -> None:
    model = LWE_MODELS.build("core-svp")
    n = 1500
    est = primal_usvp_estimate_at(n)
    assert model.security_parameter_of_key_length(n) == pytest.approx(0.5 * np.log2(1.5) * est.beta, abs=1e-9)  # log2 sqrt(3/2)
    assert model.break_cost(n).first_bits == pytest.approx(model.security_parameter_of_key_length(n), abs=1e-9)
    shared = LWE_MODELS.build("core-svp", shared_matrix=True).break_cost(n)
    assert shared.next_bits == pytest.approx(2 * np.log2(n + est.m))  # later keys: one decoding, d^2 operations
    assert shared.next_bits < shared.first_bits / 2


def primal_usvp_estimate_at(n: int):
    from encctl_gym.security.cost_models.lattice import LWEParameterSet

    sigma = binomial_sigma(2)
    return primal_usvp_estimate(LWEParameterSet("x", n, lwe.max_modulus(n, n, 2), sigma, sigma, n))


@pytest.mark.parametrize("lam", [40, 74])
def test_the_dimension_for_lambda_is_the_smallest_that_reaches_it(lam: int) -> None:
    for name in LWE_MODELS:
        model = LWE_MODELS.build(name)
        n = model.key_length_for_security_parameter(lam)
        assert model.security_parameter_of_key_length(n) >= lam > model.security_parameter_of_key_length(n - 1)
        assert model.cost_of_security_parameter(lam).key_length == n


def test_a_quantum_attacker_needs_a_larger_dimension_than_a_classical_one() -> None:
    dims = [
        LWE_MODELS.build(name).key_length_for_security_parameter(74)
        for name in ("core-svp", "core-svp-quantum", "core-svp-plausible")
    ]
    assert dims[0] < dims[1] < dims[2]


def test_a_bad_model_or_dimension_is_refused() -> None:
    with pytest.raises(ParameterError, match="core_svp"):
        PrimalUSVPModel(lambda n: 1 << 20, 1.0, core_svp="magic")
    with pytest.raises(ParameterError, match="LWE dimension"):
        LWEDimension(1)
    with pytest.raises(ParameterError, match="eta"):
        LWEScheme(eta=0)


def test_design_prints_the_dimension_per_model(capsys: pytest.CaptureFixture[str]) -> None:
    from encctl_gym.cli import main

    assert main(["design", "--preset", "paper-example", "--scheme", "lwe"]) == 0
    out = capsys.readouterr().out
    line = next(row for row in out.splitlines() if row.strip().startswith("core-svp ")).split()
    keys, k_star = int(line[1]), int(line[2])
    model = LWE_MODELS.build("core-svp")
    assert keys == 1 and model.security_parameter_of_key_length(k_star) >= model.security_parameter_of_key_length(k_star - 1)


def test_a_discrete_log_breaker_on_lwe_is_refused_by_name() -> None:
    with pytest.raises(ParameterError, match="the lwe scheme has no key breaker"):
        EncryptedLTIAttackEnv(config={**BASE, "crypto": "elgamal", "breaker": "rho"})
