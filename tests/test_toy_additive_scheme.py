"""The scheme seam from the test suite alone (issue 29): a toy additive scheme, a one-time pad
modulo M = 2^k with a made-up cost model, is registered here with no file of the package edited;
it runs episodes through the ciphertext backend (bit-identical to the ideal backend's exact
arithmetic, under every injection mode), the environment's budget comes from its cost model, and
``encctl-gym design --scheme toy-otp`` prints its key size.

The pad is no cipher (the forger reads the pads): it exercises the seam.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import numpy as np
import pytest
from episodes import rollout

from encctl_gym.cli import main
from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv
from encctl_gym.errors import EncodingOverflowError, ModelRangeError
from encctl_gym.loop.scheme import SCHEMES, SchemeBase
from encctl_gym.registry import Registry
from encctl_gym.security.cost_models import CostModel, KeyBreakCost
from encctl_gym.security.exact import pow2

TOY_SECURITY = 0.25  # the made-up model: a k-bit pad costs 2^(k/4) operations per key


class QuarterBits(CostModel):
    """Made up: breaking one k-bit pad costs ``2^(k/4)`` operations, every key alike."""

    name = "quarter-bits"
    key_length_range = (16, 8192)

    def security_parameter_of_key_length(self, key_length: int) -> float:
        return TOY_SECURITY * int(key_length)

    def break_cost(self, key_length: int) -> KeyBreakCost:
        c = pow2(Fraction(int(key_length), 4))
        return KeyBreakCost(
            self.name, c, c, key_length=int(key_length), security_parameter=self.security_parameter_of_key_length(key_length)
        )

    def cost_of_security_parameter(self, lam: Any) -> KeyBreakCost:
        c = pow2(lam)
        return KeyBreakCost(self.name, c, c, security_parameter=lam)

    def key_length_for_security_parameter(self, lam: Any) -> int:
        return max(self.key_length_range[0], math.ceil(float(lam) / TOY_SECURITY))

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, "formula": "2^(k/4) per key", "source": "made up for the test"}


TOY_MODELS: Registry[type[CostModel]] = Registry("toy cost model", [QuarterBits])


class Modulus:
    """The toy's public parameters: M = 2^bits."""

    def __init__(self, bits: int) -> None:
        self.bits, self.M = int(bits), 1 << int(bits)

    def lift(self, v: int) -> int:
        v %= self.M
        return v - self.M if v >= self.M // 2 else v


class ScaleEncoder:
    """``Ecd(v) = rint(Delta v)`` as a signed integer (every integer is a plaintext mod M)."""

    def __init__(self, modulus: Modulus, delta: float) -> None:
        self.modulus, self.delta = modulus, float(delta)

    def encode_signed(self, v: float) -> int:
        return int(np.rint(float(v) * self.delta))


class Quantized:
    """Phi on the encoder's scale; states up to x_bound; row sums decoded by Delta^2."""

    def __init__(self, Phi: np.ndarray, encoder: ScaleEncoder, x_bound: float) -> None:
        self.encoder, self.x_bound = encoder, float(x_bound)
        self.phi_int = [[encoder.encode_signed(v) for v in row] for row in np.asarray(Phi)]
        worst = max(sum(abs(w) for w in row) for row in self.phi_int) * encoder.encode_signed(self.x_bound)
        if worst >= encoder.modulus.M // 2:
            raise EncodingOverflowError(f"M = 2^{encoder.modulus.bits} is too small for |Phi x| up to {worst}")

    def encode_state(self, x: np.ndarray) -> list[int]:
        if not (np.abs(x) <= self.x_bound).all():
            raise EncodingOverflowError(f"state {np.asarray(x).tolist()} leaves |x| <= {self.x_bound}")
        return [self.encoder.encode_signed(v) for v in np.asarray(x).reshape(-1)]


class PadPlant:
    def __init__(self, quant: Quantized, rng: Any) -> None:
        self.quant, self.rng = quant, rng
        self.M = quant.encoder.modulus.M
        self.pad = self._draw()

    def _draw(self) -> int:
        return self.rng.between(0, self.M - 1)


class PadServer:
    def __init__(self, phi_int: list[list[int]], M: int) -> None:
        self.phi_int, self.M = phi_int, M  # additive: the server holds Phi in plaintext


class OneTimePad(SchemeBase):
    """``ct_j = Ecd(x_j) + k mod M`` with a fresh pad ``k`` every period; the server returns the
    summands ``Phi_ij ct_j mod M``, the plant subtracts ``Phi_ij k`` and sums."""

    name = "toy-otp"
    family = "toy"
    cost_models = TOY_MODELS
    baseline_model = "quarter-bits"

    def public_parameters(self, key_length: int, *, ciphertexts: bool = True) -> Modulus:
        return Modulus(key_length)

    def encoder(self, params: Modulus, delta: float) -> ScaleEncoder:
        return ScaleEncoder(params, delta)

    def quantization(self, Phi: np.ndarray, encoder: ScaleEncoder, x_bound: float, u_max: float) -> Quantized:
        return Quantized(Phi, encoder, x_bound)

    def parties(self, quantization: Quantized, plant_rng: Any, server_rng: Any) -> tuple[PadPlant, PadServer]:
        plant = PadPlant(quantization, plant_rng)
        return plant, PadServer(quantization.phi_int, plant.M)

    def encrypt_state(self, plant: PadPlant, x: np.ndarray) -> list[int]:
        return [(w + plant.pad) % plant.M for w in plant.quant.encode_state(x)]

    def evaluate(self, server: PadServer, cts: list[int]) -> list[list[int]]:
        return [[f * c % server.M for f, c in zip(row, cts)] for row in server.phi_int]

    def _unpad(self, plant: PadPlant, out: list[list[int]]) -> list[list[int]]:
        mod = plant.quant.encoder.modulus
        return [[mod.lift(c - f * plant.pad) for c, f in zip(row, phi)] for row, phi in zip(out, plant.quant.phi_int)]

    def decrypt_output(self, plant: PadPlant, out: list[list[int]]) -> np.ndarray:
        d2 = plant.quant.encoder.delta**2
        return np.array([sum(row) / d2 for row in self._unpad(plant, out)])

    def update_keys(self, plant: PadPlant, server: PadServer) -> None:
        plant.pad = plant._draw()

    def _pad(self, plant: PadPlant, rows: list[list[int]]) -> list[list[int]]:
        return [[(w + f * plant.pad) % plant.M for w, f in zip(row, phi)] for row, phi in zip(rows, plant.quant.phi_int)]

    def forge(self, plant: PadPlant, a: np.ndarray, encoder: ScaleEncoder, n_cols: int, rng: Any) -> list[list[int]]:
        one = encoder.encode_signed(1.0)
        return self._pad(plant, [[encoder.encode_signed(v) * one] + [0] * (n_cols - 1) for v in np.asarray(a).reshape(-1)])

    def add(self, plant: PadPlant, out: list[list[int]], a: np.ndarray, encoder: ScaleEncoder, secret_of: Any, rng: Any) -> Any:
        one = encoder.encode_signed(1.0)
        return [[(row[0] + encoder.encode_signed(v) * one) % plant.M, *row[1:]] for row, v in zip(out, np.asarray(a).reshape(-1))]

    def public_key(self, plant: PadPlant) -> int:
        return 0

    def oracle_secret(self, plant: PadPlant, pk: Any = None) -> int:
        return plant.pad

    def reveal(self, params: Modulus, secret: int, ct: int, encoder: ScaleEncoder) -> float:
        return params.lift(ct - secret) / encoder.delta

    def independent_keys(self, adversary: str) -> bool:
        return True


if OneTimePad.name not in SCHEMES:
    SCHEMES.register(OneTimePad)

BASE = {
    "preset": "small",
    "gamma_opt": False,
    "key_length": 64,
    "max_samples": 30,
    "warmup_steps": 3,
    "crypto_seed": 11,
    "decipher_delay": 0,
    "scheme": "toy-otp",
}


def _play(config: dict[str, Any], seed: int = 5) -> np.ndarray:
    return np.array(rollout(EncryptedLTIAttackEnv(config=config), seed=seed, action_seed=2))


@pytest.mark.parametrize("injection", ["replace", "add", "pass"])
def test_the_toy_runs_episodes_on_both_backends_bit_for_bit(injection: str) -> None:
    cipher = _play({**BASE, "crypto": "elgamal", "injection": injection})
    ideal = _play({**BASE, "crypto": "ideal", "injection": injection})
    assert cipher.shape == ideal.shape == (31, ideal.shape[1])
    np.testing.assert_array_equal(cipher, ideal)


def test_the_toy_sends_padded_states_and_decrypts_the_exact_controller() -> None:
    env = EncryptedLTIAttackEnv(config={**BASE, "crypto": "elgamal", "injection": "pass"})
    env.reset(seed=1)
    loop = env.loop
    x = np.array([0.5, -1.25, 2.0])[: loop.n]
    scheme, plant = loop.encryption, loop.plant
    cts = scheme.encrypt_state(plant, x)
    assert cts != plant.quant.encode_state(x)  # padded
    u = scheme.decrypt_output(plant, scheme.evaluate(loop.server, cts))
    exact = np.array(plant.quant.phi_int) @ np.array(plant.quant.encode_state(x)) / loop.encoder.delta**2
    np.testing.assert_array_equal(u, exact)


def test_the_budget_comes_from_the_toys_cost_model() -> None:
    # 2^(64/4) = 2^16 operations per key: at Upsilon = 2^16 / s and tau_c = 40 s the budget buys 40 keys
    params = EncryptedLTIAttackEnv(config={**BASE, "max_samples": None, "upsilon": 2.0**16, "tau_c": 40.0}).params
    assert params.deciphering_model == "quarter-bits"
    assert params.security_parameter == 16.0
    assert params.horizon == 40
    with pytest.raises(Exception, match="deciphering_model"):
        EncryptedLTIAttackEnv(config={**BASE, "deciphering_model": "paper"})  # ElGamal's model is not the toy's


def test_design_prints_the_toys_key_size(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["design", "--preset", "paper-example", "--scheme", "toy-otp"]) == 0
    out = capsys.readouterr().out
    line = next(row for row in out.splitlines() if row.strip().startswith("quarter-bits"))
    keys, k_star = int(line.split()[1]), int(line.split()[2])
    # independently: the smallest k with N* 2^(k/4) > Upsilon tau_c, N* from the paper's table
    n_star = int(next(row for row in out.splitlines() if "Scheme toy-otp" in row).split("N* = ")[1].split()[0])
    budget = 442e15 * 31536e4
    expected = next(k for k in range(16, 8192) if n_star * 2.0 ** (k / 4) > budget)
    assert keys == n_star and k_star == expected
    assert "Scheme toy-otp (toy)" in out


def test_the_toy_refuses_a_design_outside_its_models_range() -> None:
    with pytest.raises(ModelRangeError):
        QuarterBits().minimum_key_length(1, Fraction(2) ** 9000)
