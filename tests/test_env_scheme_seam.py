"""The scheme seam (loop.scheme): a scheme written in the test suite alone, with no edit of the
package, runs an episode through the ElGamal backend and decrypts correctly; the ElGamal variants
are implementations of the same protocol."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from episodes import rollout

from encctl_gym.attacks.forgery import injection_integers
from encctl_gym.crypto.encoding import Encoder, lift
from encctl_gym.envs.config import resolve_params
from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv
from encctl_gym.errors import ParameterError
from encctl_gym.loop import SCHEMES, ElGamalScheme, EncryptionScheme, LoopSpec, make_scheme
from encctl_gym.loop.scheme import SchemeBase
from encctl_gym.plant import Plant
from encctl_gym.security.cost_models import DECIPHERING_MODELS
from encctl_gym.security.deciphering import independent_keys
from encctl_gym.security.threat import ThreatModel

SMALL = {"preset": "small", "gamma_opt": False, "key_length": 64, "max_samples": 25, "warmup_steps": 3}


class PadPlant:
    """The plant of the toy: a fresh multiplicative pad ``k_t = g^r`` of the group every period."""

    def __init__(self, quantization: Any, rng: Any) -> None:
        self.quantization, self.group, self.rng = quantization, quantization.group, rng
        self.pad0 = self._draw()
        self.pad = self._draw()
        self.t = 0

    def _draw(self) -> int:
        g = self.group
        return pow(g.g, self.rng.between(1, g.q), g.p)


class PadServer:
    def __init__(self, ct_phi: list[list[int]], p: int) -> None:
        self.ct_phi, self.p = ct_phi, p


class MultiplicativePad(SchemeBase):
    """A toy multiplicatively homomorphic scheme: ``ct = m k mod p`` with a pad ``k`` in G.

    Phi is padded once with ``k_0``, each state with the period's ``k_t``; the server's products
    carry ``k_0 k_t``, which the plant divides out. The pads are public in this toy (the forger
    pads its plaintexts with them): it exercises the seam, it is no cipher.
    """

    name = "toy-pad"
    family = "discrete-log"
    cost_models = DECIPHERING_MODELS

    def public_parameters(self, key_length: int, *, ciphertexts: bool = True) -> Any:
        return make_scheme("modified").public_parameters(key_length, ciphertexts=ciphertexts)

    def nearest_plaintext(self, encoder: Any, v: int) -> int:
        return make_scheme("modified").nearest_plaintext(encoder, v)

    def rounding(self, params: Any, limit: int) -> Any:
        return make_scheme("modified").rounding(params, limit)

    def quantization(self, Phi: Any, encoder: Any, x_bound: float, u_max: float) -> Any:
        return make_scheme("modified").quantization(Phi, encoder, x_bound, u_max)

    def add(self, plant: Any, out: Any, a: np.ndarray, encoder: Any, secret_of: Any, rng: Any) -> Any:
        raise ParameterError("the toy pad has no addition")

    def encoder(self, group: Any, delta: float) -> Encoder:
        return Encoder(group, float(delta))

    def parties(self, quantization: Any, plant_rng: Any, server_rng: Any) -> tuple[PadPlant, PadServer]:
        plant = PadPlant(quantization, plant_rng)
        p = plant.group.p
        ct_phi = [[int(w) % p * plant.pad0 % p for w in row] for row in quantization.phi_int]
        return plant, PadServer(ct_phi, p)

    def encrypt_state(self, plant: PadPlant, x: np.ndarray) -> list[int]:
        p = plant.group.p
        return [w % p * plant.pad % p for w in plant.quantization.encode_state(x)]

    def evaluate(self, server: PadServer, cts: list[int]) -> list[list[int]]:
        return [[a * b % server.p for a, b in zip(row, cts)] for row in server.ct_phi]

    def decrypt_output(self, plant: PadPlant, out: list[list[int]]) -> np.ndarray:
        p = plant.group.p
        unpad = pow(plant.pad0 * plant.pad % p, -1, p)
        sums = [sum(lift(plant.group, c * unpad % p) for c in row) for row in out]
        return plant.quantization.decode_row_sums(sums)

    def update_keys(self, plant: PadPlant, server: PadServer) -> None:
        plant.pad, plant.t = plant._draw(), plant.t + 1
        return None

    def forge(self, plant: PadPlant, a: np.ndarray, encoder: Encoder, n_cols: int, rng: Any) -> list[list[int]]:
        p = plant.group.p
        pads = plant.pad0 * plant.pad % p
        return [[w % p * pads % p for w in row] for row in injection_integers(a, encoder, n_cols)]

    def public_key(self, plant: PadPlant) -> int:
        return plant.pad

    def oracle_secret(self, plant: PadPlant, pk: Any = None) -> int:
        return plant.pad

    def reveal(self, group: Any, secret: int, ct: int, encoder: Encoder) -> float:
        return float(encoder.decode(ct * pow(secret, -1, group.p) % group.p))

    def independent_keys(self, adversary: str) -> bool:
        return True  # a fresh pad every period, whoever the adversary is

    def breaker_for(self, breaker: Any, adversary: str, rng: Any) -> Any:
        raise ParameterError("no discrete-logarithm breaker applies to the toy pad")


if MultiplicativePad.name not in SCHEMES:
    SCHEMES.register(MultiplicativePad)  # the scheme's row: all the package needs


def _trajectory(config: dict[str, Any], steps: int, seed: int = 4) -> tuple[list[np.ndarray], EncryptedLTIAttackEnv]:
    env = EncryptedLTIAttackEnv(config=config)
    return rollout(env, seed=seed, action_seed=9, steps=steps), env


def test_the_toy_scheme_implements_the_protocol_and_the_elgamal_variants_too():
    assert isinstance(MultiplicativePad(), EncryptionScheme)
    for name in ("modified", "token", "static"):
        scheme = make_scheme(name)
        assert isinstance(scheme, ElGamalScheme) and isinstance(scheme, EncryptionScheme) and scheme.name == name
    # what the adversary must break is the scheme's own answer (Definition def:sdt)
    assert independent_keys(MultiplicativePad(), "server") is True
    assert [make_scheme(s).independent_keys("server") for s in ("modified", "token", "static")] == [True, False, False]


def test_a_scheme_from_the_test_suite_runs_an_episode_and_decrypts_correctly():
    """The toy's episode through the ciphertext backend equals the exact arithmetic of the ideal
    backend bit for bit (so every decryption, the forged inputs' included, was correct), and the
    state ciphertexts it sent decrypt to the encoded state."""
    cfg = {**SMALL, "scheme": "toy-pad", "crypto_seed": 3}
    toy, env = _trajectory({**cfg, "crypto": "elgamal"}, 25)
    ideal, _ = _trajectory({**cfg, "crypto": "ideal"}, 25)
    assert len(toy) == len(ideal) == 26
    assert all(np.array_equal(a, b) for a, b in zip(toy, ideal))
    loop = env.unwrapped.loop
    assert loop.scheme == "toy-pad" and isinstance(loop.encryption, MultiplicativePad)
    plant, p, scheme = loop.plant, loop.group.p, loop.encryption
    assert len(loop.last_state_ciphertexts) == loop.n
    x0 = np.array([0.75, -2.5, 1.0])[: loop.n]
    cts = scheme.encrypt_state(plant, x0)
    assert cts != [w % p for w in plant.quantization.encode_state(x0)]  # padded, not the plaintexts
    revealed = [scheme.reveal(loop.group, loop.decipherer.secret(scheme.public_key(plant)), c, loop.encoder) for c in cts]
    assert revealed == [loop.encoder.decode(w % p) for w in plant.quantization.encode_state(x0)]


def test_the_toy_scheme_charges_the_budget_of_independent_keys():
    """The budget follows the scheme's own independent_keys: like the modified scheme's, not the
    static one's (which needs max_samples)."""
    cfg = {
        **SMALL,
        "max_samples": None,
        "key_length": None,
        "scheme": "toy-pad",
        "security_parameter": 40,
        "tau_c": 1.0,
        "upsilon": 2.0**40 * 30,
    }
    env = EncryptedLTIAttackEnv(config=cfg)
    params = env.unwrapped.params
    assert params.independent_keys and params.horizon == 30 and params.budget_limited
    with pytest.raises(ParameterError, match="max_samples"):
        EncryptedLTIAttackEnv(config={**cfg, "scheme": "static"})


def test_a_breaker_on_a_scheme_without_breakable_keys_is_refused():
    with pytest.raises(ParameterError, match="toy pad"):
        EncryptedLTIAttackEnv(config={**SMALL, "scheme": "toy-pad", "crypto": "elgamal", "breaker": "bsgs"}).reset(seed=0)


def test_an_unknown_scheme_names_the_registered_ones():
    with pytest.raises(ParameterError, match="modified, token, static"):
        make_scheme("rsa")
    with pytest.raises(ParameterError, match="EncryptionScheme"):
        make_scheme(object())


def test_the_parameters_compose_a_plant_a_threat_model_and_a_loop():
    p = resolve_params({**SMALL, "scheme": "token", "adversary": "server", "deciphering_model": "precomputation"})
    assert isinstance(p.plant, Plant) and np.array_equal(p.plant.A, p.A) and (p.plant.n, p.plant.m) == (p.n, p.m)
    assert isinstance(p.threat, ThreatModel)
    assert (p.threat.tau_c, p.threat.upsilon, p.threat.gamma_c, p.threat.adversary) == (p.tau_c, p.upsilon, p.gamma_c, "server")
    assert p.threat.model.name == "precomputation"
    assert isinstance(p.loop, LoopSpec)
    assert (p.loop.scheme, p.loop.key_length, p.loop.delta, p.loop.crypto) == ("token", 64, p.delta, "ideal")
    assert p.loop.encryption().independent_keys(p.adversary) is p.independent_keys is False
    assert p.loop.group().bits == 64
