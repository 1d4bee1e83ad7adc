"""The scheme seam: the encryption scheme the loop runs, as one object (Definitions def:ec, def:sdt).

An :class:`EncryptionScheme` holds every fact of one scheme that the loop, the adversary and the
budget need, so that a new scheme is one module (a class) and one row of :data:`SCHEMES`:

============================  ======================================================================
what                          method
============================  ======================================================================
its encoder (Definition        :meth:`~EncryptionScheme.encoder` ``(group, delta)``
def:ec)
KeyGen, ``Enc(pk_0, Phi)``,    :meth:`~EncryptionScheme.parties` ``(quantization, plant_rng,
the server set-up              server_rng) -> (plant, server)``
Enc of the state               :meth:`~EncryptionScheme.encrypt_state` ``(plant, x)``
Eval (eq:ec)                   :meth:`~EncryptionScheme.evaluate` ``(server, cts)``
Dec, Sum, Dcd                  :meth:`~EncryptionScheme.decrypt_output` ``(plant, out)``
KeyUpd (and what the server    :meth:`~EncryptionScheme.update_keys` ``(plant, server)`` returns the
receives)                      token the server saw, or ``None``
the forged input (def:         :meth:`~EncryptionScheme.forge` ``(plant, a, encoder, n_cols, rng)``
adversary, from public keys)
what the adversary must break  :meth:`~EncryptionScheme.public_key` ``(plant)`` (the period's key),
                               :meth:`~EncryptionScheme.independent_keys` ``(adversary)`` (def:sdt:
                               every sample its own key, or one break reveals all)
how the decipherer charges it  :meth:`~EncryptionScheme.oracle_secret` ``(plant)`` (the simulated
                               break's privileged read), :meth:`~EncryptionScheme.reveal`
                               ``(group, secret, ct, encoder)`` (Dec and Dcd with the recovered
                               secret), :meth:`~EncryptionScheme.breaker_for` ``(breaker,
                               adversary, rng)`` (the real breaker, wrapped as the adversary uses it)
============================  ======================================================================

The three ElGamal variants (``"modified"``, ``"token"``, ``"static"``) are implementations
(:mod:`encctl_gym.loop.elgamal_scheme`); the environment's ``scheme`` key names a row of
:data:`SCHEMES` (or passes an object) and the ElGamal backend (``crypto="elgamal"``) runs it.
The plant and the server are whatever the scheme's :meth:`~EncryptionScheme.parties` returns:
the loop only hands them back to the scheme's methods.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np

from .._validation import format_value
from ..errors import ParameterError
from ..registry import Registry

__all__ = ["EncryptionScheme", "SCHEMES", "make_scheme", "scheme_name"]


@runtime_checkable
class EncryptionScheme(Protocol):
    """The encryption scheme of the encrypted controller, as the loop runs it (one copy).

    Attributes
    ----------
    name : str
        The scheme's name (the environment's ``scheme``; its row of :data:`SCHEMES`).
    """

    name: str

    def encoder(self, group: Any, delta: float) -> Any:
        """The encoder ``Ecd``/``Dcd`` at scale ``delta`` (Definition def:ec): an object with
        ``decode``, ``encode_signed`` and ``group`` like :class:`~encctl_gym.crypto.encoding.Encoder`."""

    def parties(self, quantization: Any, plant_rng: Any, server_rng: Any) -> tuple[Any, Any]:
        """KeyGen and the parameter ciphertexts: a new plant party (fresh keys) and its server,
        each with its own randomness."""

    def encrypt_state(self, plant: Any, x: np.ndarray) -> list[Any]:
        """The state ciphertexts of ``x`` (shape (n,)) under the period's key."""

    def evaluate(self, server: Any, cts: list[Any]) -> Any:
        """The server's evaluation of the controller on the state ciphertexts (eq:ec)."""

    def decrypt_output(self, plant: Any, out: Any) -> np.ndarray:
        """Dec, Sum and Dcd of the server's output (or a forged one): the input, shape (m,)."""

    def update_keys(self, plant: Any, server: Any) -> Any:
        """KeyUpd at the end of the period; the token the server receives (``None``: it receives none)."""

    def forge(self, plant: Any, a: np.ndarray, encoder: Any, n_cols: int, rng: Any) -> Any:
        """The adversary's output ciphertexts that the plant decodes to ``a``, from the plant's
        public keys only (Definition def:adversary, step 1)."""

    def public_key(self, plant: Any) -> Any:
        """The key of the period the adversary must break to read the state ciphertexts."""

    def oracle_secret(self, plant: Any) -> Any:
        """The plant's secret of the period (the simulated break reads it; privileged)."""

    def reveal(self, group: Any, secret: Any, ct: Any, encoder: Any) -> float:
        """What one state ciphertext reveals under ``secret``: ``Dcd(Dec(secret, ct))``."""

    def independent_keys(self, adversary: str) -> bool:
        """Whether every sample is under its own key for this adversary (else one break reveals
        every sample; Definition def:sdt)."""

    def breaker_for(self, breaker: Any, adversary: str, rng: Any) -> Any:
        """The breaker the decipherer runs on :meth:`public_key` (e.g. wrapped in the token
        chain for a malicious server that receives tokens); :class:`ParameterError` if the
        scheme's keys cannot be broken by it."""


#: The schemes by name (classes whose constructor takes the scheme's options).
SCHEMES: Registry[Any] = Registry("scheme")


def make_scheme(spec: Any) -> EncryptionScheme:
    """A scheme from a name of :data:`SCHEMES` or an object implementing :class:`EncryptionScheme`.

    Raises
    ------
    ParameterError
        For an unknown name (the registered ones are listed) or an object that is no scheme.
    """
    if isinstance(spec, str):
        return SCHEMES.build(spec)
    if isinstance(spec, type) or not isinstance(spec, EncryptionScheme):
        raise ParameterError(
            f"scheme must be a name ({', '.join(SCHEMES)}) or an object implementing EncryptionScheme, got {format_value(spec)}"
        )
    return spec


def scheme_name(spec: Any) -> str:
    """The name of a scheme given by name or as an object (checked by :func:`make_scheme`)."""
    return make_scheme(spec).name
