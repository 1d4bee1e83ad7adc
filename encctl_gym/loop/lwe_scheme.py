"""LWE as an implementation of the scheme seam (:class:`~.scheme.EncryptionScheme`): the encrypted
state feedback of :mod:`encctl_gym.crypto.lwe` (eq:ec with LWE in place of ElGamal) in the loop.

What differs from the ElGamal variants (:mod:`.elgamal_scheme`):

* **family** ``"lattice"``; the **key length is the dimension** ``n`` of the secret. The modulus
  follows from the loop: the plaintext space holds every honest product sum
  ``max_i ||Phi_int,i||_1 round(Delta x_bound)`` plus the largest injected integer
  ``round(Delta u_max) Ecd(1)``, and ``q = t (2 N + 1)`` with the worst-case noise ``N`` of one
  evaluation (:func:`~encctl_gym.crypto.lwe.controller_parameters`), so decryption is exact at every
  step by construction; both scales are the loop's ``Delta`` (``Delta_x = Delta_Phi = Delta``), so
  the plant decodes the same integers as the ideal backend (:class:`~.scheme.ExactRounding`).
* **cost models** (:data:`LWE_MODELS`): the primal uSVP attack in core-SVP operations,
  :class:`~encctl_gym.security.cost_models.lattice.PrimalUSVPModel`, classical (the baseline),
  quantum and "plausible" exponents. The design cannot know a loop's modulus, so the models price
  dimension ``n`` at the **largest modulus the int64 arithmetic allows**
  (:func:`~encctl_gym.crypto.lwe.max_modulus`): a larger modulus only helps the attacker, so the
  dimension they give is secure for every loop the scheme can run (a lower bound on its cost;
  ``bench_lwe_design.py`` prints the smaller dimension of the design example's own modulus).
* **the server holds Phi in plaintext** (``Phi_int``; LWE multiplies a ciphertext by integers, not
  by another ciphertext) and returns ``Phi_int Enc(x_int)``: one ciphertext per input.
* **keys**: one key pair for the run, or a fresh KeyGen after every ``rotation_period`` steps
  (the server receives the new public key, no token); with ``shared_matrix`` the fresh keys keep
  the first public matrix ``A`` (only ``s`` and ``e`` change), which the cost models charge as
  one reduction and a cheap decoding per later key.
* **injection needs no key**: :meth:`LWEScheme.forge` encrypts the chosen integers under the
  public key, :meth:`LWEScheme.add` adds them to the honest outputs (``c2 + Delta_q d``,
  :func:`~encctl_gym.crypto.lwe.add_plaintext`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np

from .._validation import check_bool, check_int, format_value
from ..crypto import lwe
from ..errors import EncodingOverflowError, KeyMismatchError, ParameterError, ShapeError
from ..registry import Registry
from ..security.cost_models.lattice import PrimalUSVPModel, binomial_sigma
from .injection import addition
from .scheme import SCHEMES, SchemeBase

__all__ = ["LWEDimension", "LWEEncoder", "LWEQuantization", "LWEPlant", "LWEServer", "LWEScheme", "LWE_MODELS"]

#: Widths of the centred binomial distribution the scheme accepts.
ETA_RANGE = (1, 16)


@dataclasses.dataclass(frozen=True)
class LWEDimension:
    """The public parameters a key length fixes: the dimension ``n`` and the error width ``eta``
    (the modulus is the loop's, :class:`LWEQuantization`)."""

    n: int
    eta: int = 2

    def __post_init__(self) -> None:
        object.__setattr__(self, "n", check_int("key_length (the LWE dimension n)", self.n, 2, 4096))
        object.__setattr__(self, "eta", check_int("eta", self.eta, *ETA_RANGE))


class LWEEncoder:
    """``Ecd(v) = round(Delta v)`` (every integer of the plaintext space is a plaintext), for the
    keys of one dimension."""

    def __init__(self, delta: float, dimension: LWEDimension) -> None:
        self.delta, self.dimension = float(delta), dimension

    def encode_signed(self, v: float) -> int:
        return int(np.rint(float(v) * self.delta))

    def decode(self, v: int) -> float:
        return float(v) / self.delta

    def __repr__(self) -> str:
        return f"LWEEncoder(delta={self.delta:g}, n={self.dimension.n})"


@dataclasses.dataclass(frozen=True)
class LWEQuantization:
    """What :meth:`LWEScheme.parties` builds the plant and the server from: ``Phi_int``, the
    parameters sized for the loop, the scale and the state bound."""

    dimension: LWEDimension
    params: lwe.LWEParams
    phi_int: np.ndarray
    delta: float
    x_bound: float

    def encode_state(self, x: np.ndarray) -> list[int]:
        """``round(Delta x)`` as the plant encrypts it (what the linear check recomputes from);
        :class:`EncodingOverflowError` outside ``|x| <= x_bound``."""
        x = np.asarray(x, dtype=np.float64).reshape(-1)
        if not (np.abs(x) <= self.x_bound).all():
            raise EncodingOverflowError(f"state {x.tolist()} leaves the declared range |x| <= {self.x_bound} (x_bound)")
        return [int(v) for v in lwe.encode(x, self.delta)]


def _modulus_ceiling(eta: int) -> Callable[[int], int]:
    return lambda n: lwe.max_modulus(n, n, eta)


class _LWEModel(PrimalUSVPModel):
    CORE = "classical"

    def __init__(self, eta: int = 2, shared_matrix: bool = False) -> None:
        eta = check_int("eta", eta, *ETA_RANGE)
        super().__init__(_modulus_ceiling(eta), binomial_sigma(eta), self.CORE, shared_matrix=shared_matrix)


class CoreSVPClassical(_LWEModel):
    """Primal uSVP, classical sieving ``2^(0.292 beta)`` (Becker-Ducas-Gama-Laarhoven 2016)."""

    name = "core-svp"
    CORE = "classical"


class CoreSVPQuantum(_LWEModel):
    """Primal uSVP, quantum sieving ``2^(0.265 beta)`` (Laarhoven 2015)."""

    name = "core-svp-quantum"
    CORE = "quantum"


class CoreSVPPlausible(_LWEModel):
    """Primal uSVP at ADPS16's "best plausible" ``2^(0.2075 beta)``."""

    name = "core-svp-plausible"
    CORE = "plausible"


#: The LWE scheme's deciphering-cost models (the key length is the dimension n).
LWE_MODELS: Registry[type[PrimalUSVPModel]] = Registry("LWE cost model", [CoreSVPClassical, CoreSVPQuantum, CoreSVPPlausible])


class LWEPlant:
    """The plant side: the keys, the state encryption, the decryption of the inputs."""

    def __init__(self, quant: LWEQuantization, rotation_period: int | None, shared_matrix: bool, rng: Any) -> None:
        self.quant, self.params = quant, quant.params
        self.rotation_period, self.shared_matrix = rotation_period, shared_matrix
        self._stream = lwe.ByteStream(rng, "lwe plant")
        self.pk, self.sk = lwe.keygen(self.params, self._stream)
        self.steps = 0
        self.keys = 1

    def encrypt_state(self, x: np.ndarray) -> list[lwe.LWECiphertext]:
        ints = np.array(self.quant.encode_state(x), dtype=np.int64)
        return lwe.split(lwe.encrypt(self.pk, ints, self._stream))

    def decrypt_output(self, out: lwe.LWECiphertext) -> np.ndarray:
        if out.public is not self.pk:
            raise KeyMismatchError("the output is not under the plant's current LWE key")
        return lwe.decrypt(self.sk, out) / (self.quant.delta * self.quant.delta)

    def update_keys(self) -> lwe.LWEPublicKey | None:
        """A fresh key pair after every ``rotation_period`` steps (the first matrix kept with
        ``shared_matrix``); returns the new public key, or ``None``."""
        self.steps += 1
        if self.rotation_period is None or self.steps % self.rotation_period:
            return None
        if self.shared_matrix:
            self.pk, self.sk = lwe.keygen_shared(self.params, np.array(self.pk.A), self._stream)
        else:
            self.pk, self.sk = lwe.keygen(self.params, self._stream)
        self.keys += 1
        return self.pk


class LWEServer:
    """The controller server: the public key and ``Phi_int`` in plaintext."""

    def __init__(self, pk: lwe.LWEPublicKey, phi_int: np.ndarray) -> None:
        self.pk, self.phi_int = pk, phi_int

    def evaluate(self, cts: list[lwe.LWECiphertext]) -> lwe.LWECiphertext:
        return lwe.linear_combination(self.phi_int, lwe.concatenate(*cts))


class LWEScheme(SchemeBase):
    """Regev/Lindner-Peikert LWE in the loop (module docstring).

    Parameters
    ----------
    eta : int, default 2
        Width of the centred binomial secret and errors.
    rotation_period : int, optional
        K: a fresh key pair after every K steps (``None``: one key for the run).
    shared_matrix : bool, default False
        Fresh keys keep the first public matrix (only with ``rotation_period``).
    """

    name = "lwe"
    family = "lattice"
    cost_models = LWE_MODELS
    baseline_model = "core-svp"
    rotates = False

    def __init__(self, eta: int = 2, rotation_period: int | None = None, shared_matrix: bool = False) -> None:
        self.eta = check_int("eta", eta, *ETA_RANGE)
        self.rotation_period = None if rotation_period is None else check_int("rotation_period", rotation_period, 1)
        self.shared_matrix = check_bool("shared_matrix", shared_matrix)
        if self.shared_matrix and self.rotation_period is None:
            raise ParameterError("shared_matrix needs rotation_period: with one key there is no matrix to share")

    def __repr__(self) -> str:
        return f"LWEScheme(eta={self.eta}, rotation_period={self.rotation_period}, shared_matrix={self.shared_matrix})"

    # ------------------------------------------------------------------ keys and the encoder
    def public_parameters(self, key_length: int, *, ciphertexts: bool = True) -> LWEDimension:
        return LWEDimension(key_length, self.eta)

    def encoder(self, params: Any, delta: float) -> LWEEncoder:
        dim = params if isinstance(params, LWEDimension) else self.public_parameters(params)
        return LWEEncoder(delta, dim)

    def quantization(self, Phi: np.ndarray, encoder: Any, x_bound: float, u_max: float) -> LWEQuantization:
        """``Phi_int = round(Delta Phi)`` and the smallest LWE parameters of the dimension that hold
        every honest output and every injected one exactly (module docstring).

        Raises
        ------
        ParameterError
            If the modulus needed is beyond the int64 arithmetic (the limit is named).
        """
        if not isinstance(encoder, LWEEncoder):
            raise ParameterError(f"the lwe scheme needs its own encoder (LWEScheme.encoder), got {format_value(encoder)}")
        dim, delta = encoder.dimension, encoder.delta
        margin = abs(addition(float(u_max), delta, encoder.encode_signed(1.0)))
        try:
            params = lwe.controller_parameters(dim.n, Phi, delta, delta, x_bound, dim.eta, message_margin=margin)
        except ParameterError as exc:
            raise ParameterError(
                f"the lwe scheme cannot hold this loop exactly at dimension n = {dim.n}: {exc}. The modulus grows with "
                f"Delta^2 x_bound ||Phi||_1 and Delta^2 u_max (Delta = {delta:g}, x_bound = {x_bound:g}, u_max = "
                f"{u_max:.4g}): use a smaller delta or x_bound"
            ) from None
        phi_int = lwe.encode(np.asarray(Phi, dtype=float), delta)
        return LWEQuantization(dim, params, phi_int, delta, float(x_bound))

    def parties(self, quantization: Any, plant_rng: Any, server_rng: Any) -> tuple[LWEPlant, LWEServer]:
        """KeyGen (the plant's first key pair) and the server with ``pk`` and ``Phi_int``."""
        if not isinstance(quantization, LWEQuantization):
            raise ParameterError(f"the lwe scheme needs its own quantization, got {format_value(quantization)}")
        plant = LWEPlant(quantization, self.rotation_period, self.shared_matrix, plant_rng)
        return plant, LWEServer(plant.pk, quantization.phi_int)

    # ------------------------------------------------------------------ one period
    def encrypt_state(self, plant: LWEPlant, x: np.ndarray) -> list[lwe.LWECiphertext]:
        return plant.encrypt_state(x)

    def evaluate(self, server: LWEServer, cts: list[Any]) -> lwe.LWECiphertext:
        return server.evaluate(cts)

    def decrypt_output(self, plant: LWEPlant, out: Any) -> np.ndarray:
        return plant.decrypt_output(out)

    def update_keys(self, plant: LWEPlant, server: LWEServer) -> None:
        """A fresh key pair after every K steps; the server receives the new public key."""
        fresh = plant.update_keys()
        if fresh is not None:
            server.pk = fresh
        return None

    # ------------------------------------------------------------------ the adversary
    def _injected(self, plant: LWEPlant, a: np.ndarray) -> list[int]:
        delta = plant.quant.delta
        one = int(np.rint(delta))
        return [addition(v, delta, one) for v in np.asarray(a, dtype=float).ravel().tolist()]

    def forge(self, plant: LWEPlant, a: np.ndarray, encoder: Any, n_cols: int, rng: Any) -> lwe.LWECiphertext:
        """``Enc(pk, round(Delta a_i) Ecd(1))`` per input (def:adversary's forgery, public key only):
        the plant decodes ``a`` on the grid of ``1/Delta``, as the ideal backend computes it."""
        return lwe.encrypt(plant.pk, np.array(self._injected(plant, a), dtype=np.int64), lwe.ByteStream(rng, "lwe forgery"))

    def add(self, plant: LWEPlant, out: Any, a: np.ndarray, encoder: Any, secret_of: Callable[[Any], Any], rng: Any) -> Any:
        """The honest outputs plus ``round(Delta a_i) Ecd(1)`` (no key: ``c2 + Delta_q d``)."""
        d = self._injected(plant, a)
        if len(d) != len(out):
            raise ShapeError(f"a must have {len(out)} entries, got {len(d)}")
        return lwe.add_plaintext(out, d)

    def public_key(self, plant: LWEPlant) -> lwe.LWEPublicKey:
        return plant.pk

    def oracle_secret(self, plant: LWEPlant, pk: Any = None) -> lwe.LWESecretKey:
        """The plant's current secret key (of ``pk`` if given: it must be the current key)."""
        if pk is not None and pk is not plant.pk:
            raise KeyMismatchError("the plant keeps only its current LWE key; this public key is of another period")
        return plant.sk

    def reveal(self, params: Any, secret: Any, ct: Any, encoder: Any) -> float:
        """``Dcd(Dec(s, ct))`` of one state ciphertext."""
        return float(lwe.decrypt(secret, ct)[0]) / float(encoder.delta)

    def independent_keys(self, adversary: str) -> bool:
        return self.rotation_period == 1


SCHEMES.register(LWEScheme)
