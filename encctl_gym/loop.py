"""The closed loop behind the plant's input: encrypted controller, or an adversary's injection.

Two interchangeable backends with one interface, used by the attack environment:

* :class:`IdealLoop` (``crypto="ideal"``): the exact encode / quantise / multiply / sum /
  decode arithmetic of the encrypted controller (Definition def:ec, eq:ec), without big
  integers. Quantisation uses the same group and the same nearest-member rule as the encoder
  (through :class:`~encctl_gym.crypto.residue_table.ResidueTable`), so it is bit-identical to
  decrypting real ciphertexts. Batched over any number of copies.
* :class:`ElGamalLoop` (``crypto="elgamal"``): real dynamic-key ElGamal ciphertexts, keys
  updated every period, with the modified evaluation/decryption of Definition def:modification
  (``scheme="modified"``), the conventional token-based dynamic key (``"token"``) or one fixed
  key pair (``"static"``). One copy.

Per sampling period: :meth:`collect_state` (the plant encrypts ``x_t``; the adversary breaks the
ciphertext and reads ``Dcd(Ecd(x_t))``), then :meth:`control` (warm-up: the encrypted
controller computes ``u_t = Phi x_t``) or :meth:`inject` (attack: the adversary forges the input
ciphertext from public keys only and the plant decrypts it), then :meth:`tick` (key update).

The forged input. The plant decrypts an ``m x n`` matrix of product ciphertexts, sums each row
and decodes with ``Delta^2`` (eq:ec). To make row ``i`` read ``a_i``, the adversary puts the
product ``Ecd(1) Ecd(a_i)`` in column 0 and ``Ecd(0) Ecd(0)`` in the others; the plant
then applies ``u_i = (Ecd(a_i) Ecd(1) + (n - 1) Ecd(0)^2) / Delta^2``, i.e. ``a_i`` quantised
at ``1/Delta`` plus a known offset of ``(n - 1)/Delta^2`` (0 is not in the group; its nearest
member is 1).
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np
import scipy.linalg

from .errors import EncodingOverflowError, ParameterError

__all__ = ["lqr_gain", "IdealLoop", "ElGamalLoop", "make_loop", "loop_group", "table_limit"]


def lqr_gain(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Discrete-time LQR gain ``K`` (``u = -K x``, Q = I, R = I) for the warm-up controller."""
    P = scipy.linalg.solve_discrete_are(A, B, np.eye(A.shape[0]), np.eye(B.shape[1]))
    return np.linalg.solve(np.eye(B.shape[1]) + B.T @ P @ B, B.T @ P @ A)


def table_limit(params: Any, Phi: np.ndarray) -> int:
    """Largest ``|round(Delta v)|`` the loop must quantise: states, inputs, controller entries."""
    span = max(params.x_bound, params.u_max, float(np.abs(Phi).max()) if Phi.size else 0.0, 1.0)
    return int(math.ceil(params.delta * span)) + 1


class IdealLoop:
    """Exact fixed-point arithmetic of the encrypted loop without ciphertexts (batched)."""

    def __init__(self, params: Any, group: Any) -> None:
        from .crypto.residue_table import residue_table

        self.delta = float(params.delta)
        self.x_bound = float(params.x_bound)
        self.n, self.m = params.n, params.m
        self.Phi = -lqr_gain(params.A, params.B)
        self.table = residue_table(int(group.p), table_limit(params, self.Phi))
        self.Phi_int = self.encode_int(self.Phi)
        self._one = int(self.encode_int(np.array(1.0)))
        self._zero2 = int(self.encode_int(np.array(0.0))) ** 2
        #: what the fused compiled step needs (encctl_gym.envs._kernels.step_ideal)
        self.fused_parameters = (
            self.delta, self.table.offsets, self.table.limit, self._one, self._zero2, self.n, self.x_bound,
        )

    def encode_int(self, v: np.ndarray) -> np.ndarray:
        """Signed integer of the subgroup element that encodes ``v`` (Definition def:ec).

        Raises EncodingOverflowError for a value outside the declared range."""
        return self.table.nearest(np.rint(np.asarray(v, dtype=np.float64) * self.delta).astype(np.int64))

    def _encode_in_range(self, v: np.ndarray) -> np.ndarray:
        # for values already bounded by construction (clipped actions): no range check
        i = np.rint(v * self.delta).astype(np.int64)
        return i + self.table.offset_at(i)

    def start_episode(self) -> None:
        pass

    def _encode_state(self, x: np.ndarray) -> np.ndarray:
        if not (np.abs(x) <= self.x_bound).all():  # the encoder's declared range (crypto raises alike)
            raise EncodingOverflowError(f"state {x.tolist()} leaves the declared range |x| <= {self.x_bound} (x_bound)")
        return self.encode_int(x)

    def collect_state(self, x: np.ndarray) -> np.ndarray:
        return self._encode_state(x) / self.delta

    def control(self, x: np.ndarray) -> np.ndarray:
        xi = self._encode_state(x)  # (K, n)
        return (self.Phi_int[None] * xi[:, None, :]).sum(-1) / (self.delta * self.delta)

    def inject(self, a: np.ndarray) -> np.ndarray:
        # |a| <= u_max by the actuator bound, inside the table range (table_limit)
        return (self._encode_in_range(a) * self._one + (self.n - 1) * self._zero2) / (self.delta * self.delta)

    def tick(self) -> None:
        pass


def loop_group(key_length: int) -> Any:
    """The group both backends use for a key length k (same group: same quantisation).

    The smallest shipped group with at least ``k`` bits (``p`` of 64, 128, 256, 512, 712, 1024 or
    2048 bits), so that the loop is set up instantly and every run uses the same public
    parameters; beyond 2048 bits a safe-prime group generated from the seed ``k``, so it too is
    the same in every run (group parameters are public: a fixed seed costs no security).
    """
    from .crypto.group import SHIPPED_BITS, shipped_group

    for bits in SHIPPED_BITS:
        if bits >= key_length:
            return shipped_group(bits)
    return _generated_group(int(key_length))


@lru_cache(maxsize=4)
def _generated_group(bits: int) -> Any:
    from .crypto.arith import seeded_random
    from .crypto.group import generate_safe_prime_group

    return generate_safe_prime_group(bits, rng=seeded_random(bits))


def make_loop(params: Any) -> Any:
    """The loop backend selected by ``params.crypto``, on the group of :func:`loop_group`."""
    group = loop_group(params.key_length)
    if params.crypto == "ideal":
        return IdealLoop(params, group)
    if params.crypto == "elgamal":
        return ElGamalLoop(params, group)
    raise ParameterError(f"unknown crypto backend {params.crypto!r}")


class ElGamalLoop:
    """Real dynamic-key ElGamal ciphertexts through the loop (one copy).

    The plant side (:class:`~encctl_gym.crypto.controller.PlantCryptoSide`) holds the keys,
    encrypts the state under ``pk_t``, decrypts (two-key ``Dec_bar(sk_0, sk_t, .)`` in the
    modified scheme, ``Dec(sk_t, .)`` otherwise), sums and decodes; the controller server holds
    public keys and ciphertexts only. ``"modified"``: Phi encrypted once under ``pk_0``, keys
    updated every period, no token leaves the plant. ``"token"``: the server receives every
    update token and CtUpds Phi's ciphertexts. ``"static"``: one key pair, never updated.

    The adversary's break of a state ciphertext (paid for in time by the environment) is
    simulated by decrypting with the plant's key of that period.
    """

    def __init__(self, params: Any, group: Any) -> None:
        from .crypto.arith import as_random_source
        from .crypto.encoding import Encoder

        self.params = params
        self.group = group
        self.n, self.m = params.n, params.m
        self.scheme = params.scheme
        self.encoder = Encoder(group, float(params.delta))
        self.Phi = -lqr_gain(params.A, params.B)
        self._rng = as_random_source(params.crypto_seed)
        self.plant: Any = None
        self.server: Any = None
        self.last_state_ciphertexts: list[Any] | None = None
        self.last_output_ciphertexts: list[list[Any]] | None = None

    def start_episode(self) -> None:
        """Fresh keys (KeyGen) and Phi encrypted under ``pk_0``; the server is set up."""
        from .crypto.controller import ControllerServer, PlantCryptoSide, QuantizedLinearController, TokenControllerServer

        quant = QuantizedLinearController(self.Phi, self.encoder, self.params.x_bound)
        self.plant = PlantCryptoSide(quant, "modified" if self.scheme == "modified" else "token", self._rng)
        ct_phi = self.plant.encrypt_parameter()
        if self.scheme == "modified":
            self.server = ControllerServer(self.plant.pk0, ct_phi)
        else:
            self.server = TokenControllerServer(self.plant.pk0, ct_phi, self._rng)

    @staticmethod
    def _single(v: np.ndarray) -> np.ndarray:
        if v.shape[0] != 1:
            raise ParameterError(f"the elgamal backend runs one copy, got a batch of {v.shape[0]}")
        return v[0]

    def collect_state(self, x: np.ndarray) -> np.ndarray:
        """Encrypt ``x_t`` under ``pk_t`` (what the server and an eavesdropper receive) and
        return what breaking those ciphertexts reveals: ``Dcd(Dec(sk_t, ct))``."""
        from .crypto.elgamal import decrypt

        self.last_state_ciphertexts = self.plant.encrypt_state(self._single(x))
        sk_t = self.plant.secret_key
        return np.array([[self.encoder.decode(decrypt(sk_t, ct)) for ct in self.last_state_ciphertexts]])

    def control(self, x: np.ndarray) -> np.ndarray:
        """A full period of normal operation: encrypt, server evaluation (eq:ec), decrypt, Sum,
        decode, key update."""
        ct_x = self.plant.encrypt_state(self._single(x))
        out = self.server.evaluate(ct_x)
        u = self.plant.decrypt_output(out)
        self.tick()
        return u[None]

    def inject(self, a: np.ndarray) -> np.ndarray:
        """The adversary forges the input ciphertexts from public keys only; the plant decrypts."""
        from .crypto.controller import forge_injection, forge_injection_token

        a0 = self._single(a)
        if self.scheme == "modified":
            out = forge_injection(self.plant.pk0, self.plant.pk, a0, self.encoder, self.n, self._rng)
        else:
            out = forge_injection_token(self.plant.pk, a0, self.encoder, self.n, self._rng)
        self.last_output_ciphertexts = out
        return self.plant.decrypt_output(out)[None]

    def tick(self) -> None:
        """KeyUpd at the end of the period (none for static keys); the token scheme sends the
        token to the server, which CtUpds Phi's ciphertexts."""
        if self.scheme == "static":
            return
        token = self.plant.update_keys()
        if self.scheme == "token":
            self.server.receive_token(token)
