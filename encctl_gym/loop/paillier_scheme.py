"""Paillier's scheme as an implementation of the scheme seam (:class:`~.scheme.EncryptionScheme`):
the encrypted controller of :mod:`encctl_gym.crypto.paillier_controller` in the loop.

What differs from the ElGamal variants (:mod:`.elgamal_scheme`):

* **family** ``"factoring"``: a key is broken by factoring its modulus; the cost models are
  :data:`~encctl_gym.security.cost_models.FACTORING_MODELS` (baseline ``paper``), the breakers
  :data:`~encctl_gym.cryptanalysis.factoring_registry.FACTORERS`.
* **the server holds Phi in plaintext** (``Phi_bar``, signed integers): no ``Enc(pk_0, Phi)``;
  the server's output is one ciphertext per row (the row sum is homomorphic).
* **public parameters** are a modulus length (:class:`PaillierParameters`): every KeyGen draws its
  own modulus, so there is no group to share; ``rotation_period = K`` makes the plant draw a fresh
  modulus after every K steps (:class:`~encctl_gym.crypto.paillier_controller.PaillierPlant`), and
  the server receives the new public key, not a token.
* **injection needs no key**: :meth:`PaillierScheme.forge` (replace) encrypts the chosen rows under
  the public key, and :meth:`PaillierScheme.add` multiplies the honest rows by ``g^(round(Delta^2 a))``.
* **independent keys**: every sample is under its own key only when ``rotation_period == 1``.

The class subclasses :class:`~.scheme.SchemeBase`, which supplies ``injection_needs`` (no key is
needed by either injection mode) and ``rounding`` (exact: every residue is a plaintext).

The quantization handed to :meth:`PaillierScheme.parties` is any object with ``Phi`` (or the
signed integers ``phi_int``), ``x_bound`` and ``encoder`` (a
:class:`~encctl_gym.crypto.paillier_controller.PaillierEncoder` of the modulus length, from
:meth:`PaillierScheme.encoder`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np

from .._validation import check_int, format_value
from ..cryptanalysis.factoring import Factorer
from ..cryptanalysis.factoring_registry import FACTORERS, get_factorer
from ..crypto.paillier import MAX_MODULUS_BITS, MIN_MODULUS_BITS, PaillierCiphertext, decrypt, encrypt
from ..crypto.paillier_controller import PaillierControllerServer, PaillierEncoder, PaillierPlant, check_row_sums, to_signed
from ..errors import KeyMismatchError, ParameterError
from ..security.cost_models.factoring import FACTORING_MODELS
from .injection import addition
from .scheme import SCHEMES, SchemeBase

__all__ = ["PaillierParameters", "PaillierQuantization", "PaillierScheme"]


@dataclasses.dataclass(frozen=True)
class PaillierQuantization:
    """What :meth:`PaillierScheme.parties` builds the plant and the server from."""

    Phi: np.ndarray
    encoder: Any
    x_bound: float


@dataclasses.dataclass(frozen=True)
class PaillierParameters:
    """The public parameters of the loop under Paillier: the modulus length k (bits)."""

    key_length: int

    def __post_init__(self) -> None:
        object.__setattr__(self, "key_length", check_int("key_length", self.key_length, MIN_MODULUS_BITS, MAX_MODULUS_BITS))


class PaillierScheme(SchemeBase):
    """Paillier encryption in the loop (module docstring).

    Parameters
    ----------
    rotation_period : int, optional
        K: a fresh modulus after every K steps (``None``: one key for the whole run).
    """

    name = "paillier"
    family = "factoring"
    cost_models = FACTORING_MODELS
    baseline_model = "paper"
    breakers = FACTORERS
    rotates = False

    def __init__(self, rotation_period: int | None = None) -> None:
        self.rotation_period = None if rotation_period is None else check_int("rotation_period", rotation_period, 1)

    def __repr__(self) -> str:
        return f"PaillierScheme(rotation_period={self.rotation_period})"

    # ------------------------------------------------------------------ keys and the encoder
    def public_parameters(self, key_length: int, *, ciphertexts: bool = True) -> PaillierParameters:
        return PaillierParameters(key_length)

    def encoder(self, params: Any, delta: float) -> PaillierEncoder:
        """The encoder of every modulus of ``params.key_length`` bits: its range is that of the
        smallest such modulus, ``2^(k-1) + 1``; decoding of a residue lifts by the key's own n
        (:meth:`reveal`, the plant)."""
        k = params.key_length if isinstance(params, PaillierParameters) else PaillierParameters(params).key_length
        return PaillierEncoder((1 << (k - 1)) + 1, float(delta))

    def quantization(self, Phi: np.ndarray, encoder: Any, x_bound: float, u_max: float = 0.0) -> PaillierQuantization:
        """Phi, the encoder and the state bound, as :meth:`parties` takes them (Phi is quantised there,
        with the plant's encoder, and its row sums checked against the modulus; the modulus dwarfs
        ``u_max``)."""
        return PaillierQuantization(np.asarray(Phi, dtype=float), encoder, float(x_bound))

    def parties(self, quantization: Any, plant_rng: Any, server_rng: Any) -> tuple[PaillierPlant, PaillierControllerServer]:
        """KeyGen (the plant's first modulus) and the server with ``pk`` and Phi in plaintext.

        Raises
        ------
        EncodingOverflowError
            If the modulus is too small for the encoder's range.
        """
        enc = quantization.encoder
        if not isinstance(enc, PaillierEncoder):
            raise ParameterError(f"the paillier scheme needs its own encoder (PaillierScheme.encoder), got {format_value(enc)}")
        bits, x_bound = enc.n.bit_length(), float(quantization.x_bound)
        plant = PaillierPlant(bits, enc.delta, x_bound, self.rotation_period, plant_rng)
        phi_int = getattr(quantization, "phi_int", None)
        if phi_int is None:
            phi_int = [[plant.encoder.quantize(v) for v in row] for row in np.asarray(quantization.Phi, dtype=float).tolist()]
        phi_bar = [[int(v) for v in row] for row in phi_int]
        check_row_sums(phi_bar, plant.encoder.quantize(x_bound), plant.pk.n)
        return plant, PaillierControllerServer(plant.pk, phi_bar)

    def fresh_parameters(self, params: Any, seed: int) -> Any:
        raise ParameterError("the paillier scheme rotates its modulus with rotation_period, not by fresh public parameters")

    def rotation_seconds(self, params: Any) -> float:
        return 0.0

    def check_fresh(self, params: Any, current: Any) -> Any:
        raise ParameterError("the paillier scheme rotates its modulus with rotation_period, not by fresh public parameters")

    def provisioning_bytes(self, params: Any, encryptions: int) -> int:
        """No ciphertexts are provisioned: the server receives Phi in plaintext."""
        return 0

    def nearest_plaintext(self, encoder: Any, v: int) -> int:
        """``v`` itself: every integer is a plaintext (modulo n)."""
        return int(v)

    # ------------------------------------------------------------------ one period
    def encrypt_state(self, plant: PaillierPlant, x: np.ndarray) -> list[PaillierCiphertext]:
        return plant.encrypt_state(x)

    def evaluate(self, server: PaillierControllerServer, cts: list[Any]) -> list[PaillierCiphertext]:
        return server.evaluate(cts)

    def decrypt_output(self, plant: PaillierPlant, out: Any) -> np.ndarray:
        return plant.decrypt_output(out)

    def update_keys(self, plant: PaillierPlant, server: PaillierControllerServer) -> None:
        """The end of a period: a fresh modulus after every K steps; the server receives the new
        public key (no token: nothing the server learns helps it decrypt)."""
        fresh = plant.update_keys()
        if fresh is not None:
            server.receive_key(fresh)
        return None

    # ------------------------------------------------------------------ the adversary
    def forge(self, plant: PaillierPlant, a: np.ndarray, encoder: Any, n_cols: int, rng: Any) -> list[PaillierCiphertext]:
        """Rows ``Enc(pk_t, Ecd(a_i) Ecd(1) mod n)``, the forgery of def:adversary (:func:`~.injection.addition`):
        the plant decodes ``a`` on the grid of ``1/Delta``, as the ideal backend computes it; from the
        public key alone (``n_cols`` is not used: one ciphertext per row)."""
        pk, delta = plant.pk, plant.encoder.delta
        one = plant.encoder.quantize(1.0)
        return [encrypt(pk, addition(v, delta, one) % pk.n, rng) for v in np.asarray(a, dtype=float).ravel().tolist()]

    def add(
        self, plant: PaillierPlant, out: Any, a: np.ndarray, encoder: Any, secret_of: Callable[[Any], Any], rng: Any
    ) -> list[PaillierCiphertext]:
        """The honest rows times ``g^d`` with ``d = Ecd(a_i) Ecd(1)`` (:func:`~.injection.addition`):
        the plant decodes ``u + a``; no secret is used."""
        delta, one = plant.encoder.delta, plant.encoder.quantize(1.0)
        rows = list(out)
        vals = np.asarray(a, dtype=float).ravel().tolist()
        if len(vals) != len(rows):
            raise ParameterError(f"a must have {len(rows)} entries, got {len(vals)}")
        return [ct + addition(v, delta, one) for ct, v in zip(rows, vals)]

    def public_key(self, plant: PaillierPlant) -> Any:
        return plant.pk

    def oracle_secret(self, plant: PaillierPlant, pk: Any = None) -> Any:
        """The plant's current secret key (of ``pk`` if given: it must be the current key)."""
        if pk is not None and pk.n != plant.pk.n:
            raise KeyMismatchError("the plant keeps only its current Paillier key; this public key is of another period")
        return plant.sk

    def reveal(self, params: Any, secret: Any, ct: Any, encoder: Any) -> float:
        """``Dcd(Dec(sk, ct))`` of one state ciphertext, lifted by the key's own modulus."""
        return float(encoder.decode_signed(to_signed(decrypt(secret, ct), secret.public.n)))

    def independent_keys(self, adversary: str) -> bool:
        return self.rotation_period == 1

    def breaker_for(self, breaker: Any, adversary: str, rng: Any) -> Factorer:
        """A factorer (by name of :data:`FACTORERS` or an instance); a discrete-log breaker is refused."""
        if isinstance(breaker, Factorer):
            return breaker
        if isinstance(breaker, str) and breaker in FACTORERS:
            return get_factorer(breaker, rng=rng)
        raise ParameterError(
            f"the paillier scheme's keys are broken by factoring ({', '.join(FACTORERS)}), not {format_value(breaker)}"
        )


SCHEMES.register(PaillierScheme)
