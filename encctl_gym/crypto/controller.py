"""The encrypted linear controller psi = Phi xi of eq:ec, as one object: ``step(x) -> u``.

:class:`EncryptedLinearController` runs the whole loop with the parties of a scheme
(:mod:`.schemes`): the plant side (:mod:`.plant_side`: keys, state encryption, decryption,
``Sum``, decoding, key update) and the controller server (:mod:`.servers`: public keys and
ciphertexts only). :class:`~.quantized.QuantizedLinearController` computes the *same* numbers
without ciphertexts, bit for bit.

The plant party of a scheme by name is ``get_scheme(name).plant(quantization, rng)``
(:mod:`.schemes`); forging injected inputs is the adversary's (:mod:`encctl_gym.attacks.forgery`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from . import arith
from .arith import RngLike
from .checks import check_ciphertext_matrix
from .elgamal import Ciphertext, PublicKey
from .encoding import Encoder
from .group import GroupParams, as_group
from .quantized import QuantizedLinearController
from .schemes import get_scheme

__all__ = ["EncryptedLinearController"]


class EncryptedLinearController:
    """Closed-loop encrypted linear controller u = Phi x of eq:ec (``step(x) -> u``).

    Each :meth:`step`: the plant encrypts x under ``pk_t``; the server evaluates (modified
    scheme: ``Eval_bar`` with Phi under ``pk_0``; token and static schemes: ``Eval`` with Phi
    under ``pk_t``); the plant decrypts (``Dec_bar(sk_0, sk_t, .)`` or ``Dec(sk_t, .)``), sums
    each row in Z, decodes with ``Delta**2`` and updates the keys (the token scheme sends
    sigma_t to the server, which CtUpds Phi's ciphertexts; static keys are never updated). The
    parties come from :data:`~.schemes.ELGAMAL_VARIANTS`. The result equals
    :meth:`QuantizedLinearController.compute` bit for bit.

    Parameters
    ----------
    Phi : array_like, shape (alpha, beta)
        Controller parameter.
    group : GroupParams or int
        The group, or a bit length (:func:`~.group.get_group`).
    delta : float
        Scaling factor Delta > 0 of Definition def:ec.
    x_bound : float
        Declared bound ``|x_j| <= x_bound`` on the controller input.
    scheme : {"modified", "token", "static"}, default "modified"
    rng : None, int, RandomSource or numpy.random.Generator
        Randomness (``None``: secure; a seed makes runs reproducible, unsafe for deployment).
        The plant and the server each get a stream of their own spawned from it.
    max_shift : int, optional
        Passed to :class:`~.encoding.Encoder`.

    Attributes
    ----------
    server : ControllerServer, TokenControllerServer or StaticControllerServer
    plant : ModifiedPlant, TokenPlant or StaticPlant
    quantized : QuantizedLinearController
        The plaintext reference with the same quantisation.
    last_state_ciphertexts : list of Ciphertext or None
        ``ct_{x,t}`` of the last step (what an eavesdropper sees).
    last_output_ciphertexts : matrix or None
        The output matrix the plant decrypted in the last step (possibly injected).

    Raises
    ------
    EncodingOverflowError
        If some ``|x_j| <= x_bound`` could make a product or row sum wrap modulo p.
    """

    def __init__(
        self,
        Phi: Any,
        group: GroupParams | int,
        delta: float,
        x_bound: float,
        scheme: str = "modified",
        rng: RngLike = None,
        max_shift: int | None = None,
    ) -> None:
        self.scheme_parts = get_scheme(scheme)
        src = arith.as_random_source(rng, "controller")
        self.group = as_group(group, rng=src)
        self.scheme = scheme
        self.encoder = Encoder(self.group, delta, max_shift=max_shift)
        self.quantized = QuantizedLinearController(Phi, self.encoder, x_bound)
        self.alpha, self.beta = self.quantized.alpha, self.quantized.beta
        self.x_bound = self.quantized.x_bound
        self.plant, self.server = self.scheme_parts.parties(self.quantized, src.spawn("plant"), src.spawn("server"))
        self.last_state_ciphertexts: list[Ciphertext] | None = None
        self.last_output_ciphertexts: list[list[Any]] | None = None

    @property
    def pk(self) -> PublicKey:
        """The current public key ``pk_t``."""
        return self.plant.pk

    @property
    def pk0(self) -> PublicKey:
        """The initial public key ``pk_0``."""
        return self.plant.pk0

    @property
    def t(self) -> int:
        """The current time step (number of completed steps)."""
        return self.plant.t

    def step(self, x: Any, inject: Sequence[Sequence[Any]] | None = None) -> np.ndarray:
        """One control step: encrypt x, evaluate on the server, decrypt, Sum, decode, update keys.

        Parameters
        ----------
        x : array_like, shape (beta,)
            Controller input with ``|x_j| <= x_bound``.
        inject : matrix of ModifiedCiphertext (or Ciphertext for the token scheme), optional
            Replaces the server's output (a man-in-the-middle or malicious server, e.g.
            from :func:`encctl_gym.attacks.forgery.forge_injection`); the server still sees the
            state ciphertexts.

        Returns
        -------
        numpy.ndarray, shape (alpha,)
            The decoded control input.

        Raises
        ------
        ParameterError
            If x has the wrong size or non-finite entries.
        EncodingOverflowError
            If ``|x_j| > x_bound``.
        CiphertextError, KeyMismatchError
            If an injected output is not an alpha x beta matrix of the ciphertexts the plant
            decrypts, is malformed, or is of another group or step.
        """
        if inject is not None:  # refused before anything is encrypted or evaluated
            shape = (self.alpha, self.beta)
            inject = check_ciphertext_matrix("inject", inject, self.plant.output_type, shape)
        ct_x = self.plant.encrypt_state(x)
        out = self.server.evaluate(ct_x)
        if inject is not None:
            out = inject
        u = self.plant.decrypt_output(out)
        token = self.plant.update_keys()
        if self.scheme_parts.token_to_server:
            self.server.receive_token(token)
        self.last_state_ciphertexts = ct_x
        self.last_output_ciphertexts = out
        return u

    def reference(self, x: Any) -> np.ndarray:
        """The plaintext computation with the same quantisation (no ciphertexts, no key update)."""
        return self.quantized.compute(x)

    def __repr__(self) -> str:
        return (
            f"EncryptedLinearController(scheme={self.scheme!r}, shape=({self.alpha}, {self.beta}), "
            f"bits={self.group.bits}, delta={self.encoder.delta!r}, x_bound={self.x_bound!r}, t={self.t})"
        )
