"""The plant's side of the encrypted linear controller (eq:ec), one party per key-handling scheme.

The plant holds the keys, encrypts the state under the current key, decrypts the server's
output matrix, sums each row in Z (``Sum`` of eq:ec: every decrypted product is lifted to a
signed integer first, so a row sum never wraps modulo p), decodes with ``Delta**2`` and updates
the keys. What differs between the schemes is the decryption and the key update:

================  =====================================================  =====================
party             decryption of the output                               key update
================  =====================================================  =====================
ModifiedPlant     ``Dec_bar(sk_0, sk_t, .)`` (Definition def:modification) KeyUpd; the token
                                                                         never leaves the plant
TokenPlant        ``Dec(sk_t, .)`` (Example ex:dyn_elgamal)               KeyUpd; the token goes
                                                                         to the server
StaticPlant       ``Dec(sk, .)`` with one fixed key (Example ex:elgamal)  none
================  =====================================================  =====================

Cost of one step of the modified scheme, alpha = beta = 4: 8 exponentiations to encrypt the
state, 1 for the key update, 4 for the column parts ``c2^(-s_t)`` (one per column: the state
ciphertext's first component is shared by the whole column); the parts ``c1^(-s_0)`` of Phi's
fixed first components are computed once at set-up. Total: 13 exponentiations per step.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import KeyMismatchError
from . import arith
from .arith import RngLike
from .checks import check_ciphertext_matrix, check_group_of
from .dyn_elgamal import UpdateToken, key_update
from .elgamal import Ciphertext, SecretKey, check_ciphertext, encrypt, encrypt_member, keygen
from .encoding import lift
from .modified import ModifiedCiphertext, check_modified_ciphertext
from .quantized import QuantizedLinearController

__all__ = ["PlantParty", "ModifiedPlant", "TokenPlant", "StaticPlant"]


class PlantParty:
    """What every plant party does: keys, state encryption, Sum and decoding (eq:ec).

    Parameters
    ----------
    quantization : QuantizedLinearController
        Encoding of Phi and of the state (shared with the plaintext twin).
    rng : None, int, RandomSource or numpy.random.Generator
        The plant's randomness for keys and encryptions (an int seed is keyed by the purpose
        ``"plant"``).

    Attributes
    ----------
    pk0 : PublicKey
        The initial public key.
    pk : PublicKey
        The current public key of step ``t``.
    """

    #: the class of the ciphertexts of the server's output that this party decrypts
    output_type: type = Ciphertext

    def __init__(self, quantization: QuantizedLinearController, rng: RngLike = None) -> None:
        self.quantization = quantization
        self.group = quantization.group
        self._rng = arith.as_random_source(rng, "plant")
        self.pk0, self._sk0 = keygen(self.group, self._rng)
        self.pk, self._sk = self.pk0, self._sk0

    @property
    def t(self) -> int:
        """The current time step."""
        return self._sk.t

    @property
    def secret_key(self) -> SecretKey:
        """The current secret key ``sk_t`` (the plant's own; privileged)."""
        return self._sk

    @property
    def initial_secret_key(self) -> SecretKey:
        """The secret key ``sk_0`` of step 0 (the plant's own; privileged)."""
        return self._sk0

    def encrypt_parameter(self) -> list[list[Ciphertext]]:
        """``Enc(pk_0, Ecd(Phi_ij; Delta))`` for every entry of Phi (the server's parameter)."""
        p = self.group.p
        return [[encrypt(self.pk0, int(w) % p, self._rng) for w in row] for row in self.quantization.phi_int]

    def encrypt_state(self, x: Any) -> list[Ciphertext]:
        """``Enc(pk_t, Ecd(x_j; Delta))`` for j = 1..beta (checks the range ``|x_j| <= x_bound``)."""
        p = self.group.p
        # The encoder only returns members of G, so the plaintext check can be skipped.
        return [encrypt_member(self.pk, w % p, self._rng) for w in self.quantization.encode_state(x)]

    def _output(self, out: Sequence[Sequence[Any]]) -> list[list[Any]]:
        shape = (self.quantization.alpha, self.quantization.beta)
        return check_ciphertext_matrix("server output", out, self.output_type, shape)

    def decrypt_products(self, out: Sequence[Sequence[Any]]) -> list[list[int]]:
        """Decrypt the server's alpha x beta output; every product lifted to a signed integer.

        Raises
        ------
        CiphertextError
            If the output has the wrong shape or malformed entries.
        KeyMismatchError
            If an entry belongs to another group or records other steps than the keys it needs.
        """
        rows = self._output(out)
        cache: dict[tuple[str, int], Any] = {}  # the parts c^(-s) computed this step, by key and component
        grp = self.group
        return [[lift(grp, self._decrypt_entry(c, cache)) for c in row] for row in rows]

    def _decrypt_entry(self, c: Any, cache: dict[tuple[str, int], Any]) -> int:
        """The plaintext of one entry of the output (the scheme's decryption), checks included."""
        raise NotImplementedError

    def decrypt_output(self, out: Sequence[Sequence[Any]]) -> np.ndarray:
        """``Dcd(Sum(Dec(.)); Delta^2)``: the control input, shape (alpha,)."""
        products = self.decrypt_products(out)
        return self.quantization.decode_row_sums([sum(r) for r in products])

    def update_keys(self) -> UpdateToken | None:
        """KeyUpd (Example ex:dyn_elgamal): move to step t + 1 and return sigma_t (``None``: no update)."""
        self.pk, self._sk, token = key_update(self.pk, self._sk, self._rng)
        return token

    def __repr__(self) -> str:
        return f"{type(self).__name__}(t={self.t}, bits={self.group.bits})"


class ModifiedPlant(PlantParty):
    """The plant of the proposed scheme: ``Dec_bar(sk_0, sk_t, .)`` of the server's ``Eval_bar``
    output (Definition def:modification); keys updated every period, no token ever sent.

    ``c1^(-s_0)`` of Phi's ciphertexts (fixed for ever) is computed once, when they are made;
    ``c2^(-s_t)`` once per distinct state ciphertext (per column).
    """

    output_type = ModifiedCiphertext

    def __init__(self, quantization: QuantizedLinearController, rng: RngLike = None) -> None:
        super().__init__(quantization, rng)
        self._mask0: dict[int, Any] = {}

    def encrypt_parameter(self) -> list[list[Ciphertext]]:
        ct = super().encrypt_parameter()
        p, q, s0 = self.group.p, self.group.q, self._sk0.s
        for row in ct:
            for c in row:
                self._mask0[c.c1] = arith.powmod(c.c1, q - s0, p)
        return ct

    def _decrypt_entry(self, c: Any, cache: dict[tuple[str, int], Any]) -> int:
        """``Dec_bar(sk_0, sk_t, c)``: ``c1^(-s_0)`` from the set-up (Phi's entries) or computed once
        per distinct c1 (e.g. injected ones), ``c2^(-s_t)`` once per distinct c2 (per column)."""
        grp = self.group
        p, q = grp.p, grp.q
        check_group_of(c, grp)
        if not (0 < c.c1 < p and 0 < c.c2 < p and grp.contains(c.c3)):
            check_modified_ciphertext(grp, c)  # raises, naming the component
        t0, t = self._sk0.t, self._sk.t
        if (c.t1 is not None and c.t1 != t0) or (c.t2 is not None and c.t2 != t):
            raise KeyMismatchError(
                f"output ciphertext records steps (t1, t2) = ({c.t1}, {c.t2}), "
                f"the plant decrypts with the keys of steps ({t0}, {t})"
            )
        # c1 and c2 are checked for membership when first seen (the cached c1 of Phi's ciphertexts
        # were made by the plant itself).
        a = self._mask0.get(c.c1)
        if a is None:
            a = cache.get(("c1", c.c1))
        if a is None:  # not one of Phi's ciphertexts (e.g. an injected one)
            if not grp.contains(c.c1):
                check_modified_ciphertext(grp, c)  # raises, naming c1
            a = cache["c1", c.c1] = arith.powmod(c.c1, q - self._sk0.s, p)
        b = cache.get(("c2", c.c2))
        if b is None:
            if not grp.contains(c.c2):
                check_modified_ciphertext(grp, c)  # raises, naming c2
            b = cache["c2", c.c2] = arith.powmod(c.c2, q - self._sk.s, p)
        return int(arith.mulmod(arith.mulmod(a, b, p), c.c3, p))


class TokenPlant(PlantParty):
    """The plant of the conventional dynamic key: ``Dec(sk_t, .)`` of the server's ``Eval``
    output; each key update returns the token the server needs (Definition def:ec)."""

    def _decrypt_entry(self, c: Any, cache: dict[tuple[str, int], Any]) -> int:
        """``Dec(sk_t, c)`` with one ``c1^(-s_t)`` per distinct c1."""
        grp = self.group
        check_ciphertext(grp, c)
        t = self._sk.t
        if c.t is not None and c.t != t:
            raise KeyMismatchError(f"output ciphertext is of step t = {c.t}, the plant's key of step t = {t}")
        a = cache.get(("c1", c.c1))
        if a is None:
            a = cache["c1", c.c1] = arith.powmod(c.c1, grp.q - self._sk.s, grp.p)
        return int(arith.mulmod(a, c.c2, grp.p))


class StaticPlant(TokenPlant):
    """One fixed key pair (no dynamic keys): ``Dec(sk, .)`` of the server's ``Eval`` output,
    and no key update (Remark after Definition def:security: one break reveals every sample)."""

    def update_keys(self) -> None:
        """No update: the key pair of step 0 is kept for ever."""
        return None
