"""loop.paillier_scheme standalone: a period's round trip through the scheme's methods, forge and
add from the public key alone, rotation, reveal with a broken key, the breaker it accepts."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from episodes import rollout

from encctl_gym.cryptanalysis.factoring import Factorer
from encctl_gym.cryptanalysis.paillier_keys import break_paillier_key
from encctl_gym.crypto import arith
from encctl_gym.errors import EncodingOverflowError, ParameterError
from encctl_gym.loop import SCHEMES, EncryptionScheme, make_scheme
from encctl_gym.loop.paillier_scheme import PaillierParameters, PaillierScheme

PHI = np.array([[0.5, -1.25, 0.1], [2.0, 0.0, -0.7]])
DELTA = 2.0**10


def _setup(bits: int = 96, rotation_period: int | None = None, seed: int = 1):
    scheme = PaillierScheme(rotation_period)
    params = scheme.public_parameters(bits)
    enc = scheme.encoder(params, DELTA)
    quant = SimpleNamespace(Phi=PHI, x_bound=10.0, encoder=enc)
    src = arith.seeded_random(seed)
    plant, server = scheme.parties(quant, src.spawn("plant"), src.spawn("server"))
    return scheme, params, enc, plant, server, src


def _exact(x: np.ndarray) -> np.ndarray:
    # the quantised computation in Z, decoded once with Delta^2 (independent of the scheme)
    phi = [[round(DELTA * v) for v in row] for row in PHI.tolist()]
    xb = [round(DELTA * v) for v in x.tolist()]
    return np.array([sum(a * b for a, b in zip(row, xb)) / DELTA**2 for row in phi])


def test_the_scheme_is_registered_and_built_by_name() -> None:
    s = SCHEMES.build("paillier", rotation_period=3)
    assert isinstance(s, PaillierScheme) and s.rotation_period == 3 and s.family == "factoring"
    assert isinstance(make_scheme("paillier"), EncryptionScheme)  # the runtime protocol of the seam
    assert "paper" in s.cost_models and s.baseline_model == "paper" and "ecm" in s.breakers


def test_a_period_round_trips_through_the_schemes_methods() -> None:
    scheme, _, _, plant, server, _ = _setup()
    rnd = np.random.default_rng(2)
    for _ in range(5):
        x = rnd.uniform(-10, 10, 3)
        out = scheme.evaluate(server, scheme.encrypt_state(plant, x))
        assert len(out) == 2  # one ciphertext per row: the row sum is homomorphic
        np.testing.assert_array_equal(scheme.decrypt_output(plant, out), _exact(x))
        assert scheme.update_keys(plant, server) is None


def test_forge_and_add_need_the_public_key_only() -> None:
    scheme, _, enc, plant, server, src = _setup()
    a = np.array([3.5, -1.25])
    forged = scheme.forge(plant, a, enc, 3, src)
    np.testing.assert_array_equal(scheme.decrypt_output(plant, forged), a)
    x = np.array([1.0, 2.0, -3.0])
    honest = scheme.evaluate(server, scheme.encrypt_state(plant, x))
    added = scheme.add(plant, honest, a, enc, lambda pk: pytest.fail("add must not ask for a secret"), src)
    np.testing.assert_array_equal(scheme.decrypt_output(plant, added), _exact(x) + a)


def test_rotation_every_k_steps_gives_the_server_the_fresh_key() -> None:
    scheme, _, _, plant, server, _ = _setup(rotation_period=2)
    seen = []
    for _ in range(4):
        seen.append(plant.pk.n)
        x = np.array([1.0, 0.0, -1.0])
        np.testing.assert_array_equal(
            scheme.decrypt_output(plant, scheme.evaluate(server, scheme.encrypt_state(plant, x))), _exact(x)
        )
        scheme.update_keys(plant, server)
        assert server.pk.n == plant.pk.n
    assert seen[0] == seen[1] != seen[2] == seen[3]
    assert PaillierScheme(1).independent_keys("eavesdropper") and not PaillierScheme(2).independent_keys("eavesdropper")


def test_a_broken_key_reveals_the_state() -> None:
    scheme, params, enc, plant, _, src = _setup(bits=64)
    factorer = scheme.breaker_for("ecm", "eavesdropper", arith.seeded_random(3))
    assert isinstance(factorer, Factorer)
    got = break_paillier_key(factorer, scheme.public_key(plant), rng=arith.seeded_random(4))
    x = np.array([1.5, -2.25, 7.0])
    cts = scheme.encrypt_state(plant, x)
    assert [scheme.reveal(params, got.secret, ct, enc) for ct in cts] == x.tolist()
    assert scheme.oracle_secret(plant).lam == got.secret.lam


def test_bad_input_gets_the_packages_error() -> None:
    with pytest.raises(ParameterError):
        PaillierScheme().breaker_for("index-calculus", "eavesdropper", None)
    with pytest.raises(ParameterError):
        PaillierParameters(8)
    with pytest.raises(EncodingOverflowError, match="too small"):
        _setup(bits=20)
    assert PaillierScheme().provisioning_bytes(PaillierParameters(64), 10) == 0


def test_the_environment_finds_paillier_by_name_in_a_fresh_process() -> None:
    """No import beyond the environment's own: ``scheme="paillier"`` is a row of the one registry."""
    import subprocess
    import sys

    code = (
        "from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv\n"
        "env = EncryptedLTIAttackEnv(config={'preset': 'small', 'gamma_opt': False, 'key_length': 96,"
        " 'max_samples': 5, 'warmup_steps': 1, 'scheme': 'paillier', 'crypto': 'elgamal', 'crypto_seed': 1})\n"
        "env.reset(seed=0)\n"
        "print(type(env.unwrapped.loop.encryption).__name__)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "PaillierScheme"


@pytest.mark.parametrize("injection", ["replace", "add", "pass"])
def test_both_backends_give_the_same_paillier_episode_bit_for_bit(injection: str) -> None:
    """The ciphertext backend (real Paillier, 96-bit moduli) and the exact arithmetic of the ideal
    backend agree observation for observation, so every decryption was correct."""
    from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv

    cfg = {"preset": "small", "gamma_opt": False, "key_length": 96, "max_samples": 20, "warmup_steps": 2}
    cfg |= {"scheme": "paillier", "crypto_seed": 3, "injection": injection, "decipher_delay": 0}
    runs = []
    for crypto in ("elgamal", "ideal"):
        runs.append(rollout(EncryptedLTIAttackEnv(config={**cfg, "crypto": crypto}), seed=4, action_seed=9, steps=20))
    assert len(runs[0]) == len(runs[1]) > 5
    assert all(np.array_equal(a, b) for a, b in zip(*runs))
    assert not all(np.array_equal(runs[0][0], r) for r in runs[0][1:])  # the episode moved


def test_the_game_runs_on_paillier_with_the_mac_as_its_verify_lever() -> None:
    """The attacker-defender game on real Paillier ciphertexts: noise and audits work, and the
    verify lever runs the MAC (the linear check needs ElGamal's quantised Phi): it catches the
    attacker's forged input at the first checked step."""
    from encctl_gym.multiagent.encctl_game_v0 import parallel_env

    cfg = {"preset": "small", "gamma_opt": False, "key_length": 96, "max_samples": 10, "warmup_steps": 1}
    game = parallel_env(config={**cfg, "scheme": "paillier", "crypto": "elgamal", "crypto_seed": 3})
    game.reset(seed=0)
    rng = np.random.default_rng(2)
    steps = 0
    while game.agents:
        acts = {a: rng.uniform(-1, 1, game.action_space(a).shape).astype(np.float32) for a in game.agents}
        acts["defender"][2:] = 0.0  # no rotation (no safe-prime group), no verification
        _, rewards, _, _, _ = game.step(acts)
        assert all(np.isfinite(r) for r in rewards.values())
        steps += 1
    assert steps >= 2
    game.reset(seed=1)
    acts = {a: np.zeros(game.action_space(a).shape, dtype=np.float32) for a in game.agents}
    acts["attacker"][:-1] = 0.5  # inject (flag 0 >= 0) an input that is not Phi x
    game.step(acts)
    acts["defender"][3] = 1.0
    _, _, term, _, infos = game.step(acts)
    assert infos["defender"]["verified"] and infos["defender"]["detected"] and term["defender"]


@pytest.mark.parametrize("factorer", ["rho-factor", "ecm"])
def test_the_environment_factors_every_fresh_modulus_and_sees_what_the_oracle_sees(factorer: str) -> None:
    """Real-break mode: the adversary factors each modulus it meets (a fresh one every 2 steps),
    and its observations equal those of the key oracle bit for bit."""
    from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv

    cfg = {"preset": "small", "gamma_opt": False, "key_length": 64, "max_samples": 8, "warmup_steps": 1}
    cfg |= {"scheme": {"name": "paillier", "rotation_period": 2}, "crypto": "elgamal", "crypto_seed": 3, "decipher_delay": 0}
    runs, envs = [], []
    for breaker in (factorer, None):
        env = EncryptedLTIAttackEnv(config={**cfg, "breaker": breaker})
        runs.append(rollout(env, seed=0, action_seed=5, steps=8))
        envs.append(env)
    assert len(runs[0]) == len(runs[1]) and all(np.array_equal(a, b) for a, b in zip(*runs))
    decipherer = envs[0].unwrapped.loop.decipherer
    assert len(decipherer.costs) >= 3  # one factorisation per modulus met
    assert all(method == factorer for method, _ in decipherer.costs) and decipherer.seconds > 0


def test_a_factorer_on_a_discrete_log_scheme_is_refused_by_name() -> None:
    from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv

    cfg = {"preset": "small", "gamma_opt": False, "key_length": 64, "max_samples": 8, "crypto": "elgamal", "breaker": "ecm"}
    with pytest.raises(ParameterError, match="breaker 'ecm' factors Paillier moduli; the keys of scheme 'modified'"):
        EncryptedLTIAttackEnv(config=cfg).reset(seed=0)
    with pytest.raises(ParameterError, match="unknown breaker 'gnfs'; choose one of .*rho-factor"):
        EncryptedLTIAttackEnv(config={**cfg, "breaker": "gnfs"})


def test_the_vector_environment_runs_paillier_on_its_ideal_backend() -> None:
    """The vector environment batches the ideal backend (which the test above shows equal to the
    ciphertext backend bit for bit); the Paillier rounding runs there too."""
    from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv

    cfg = {"preset": "small", "gamma_opt": False, "key_length": 96, "max_samples": 10, "warmup_steps": 1}
    vec = EncryptedLTIAttackVectorEnv(2, config={**cfg, "scheme": "paillier", "crypto": "ideal", "crypto_seed": 3})
    obs, _ = vec.reset(seed=1)
    first = obs.copy()
    for _ in range(4):
        obs, rewards, _, _, _ = vec.step(np.full(vec.action_space.shape, 0.5, dtype=np.float32))
        assert np.isfinite(rewards).all()
    assert obs.shape == first.shape and not np.array_equal(obs, first)
    with pytest.raises(ParameterError, match="ideal backend only"):
        EncryptedLTIAttackVectorEnv(2, config={**cfg, "scheme": "paillier", "crypto": "elgamal"})
