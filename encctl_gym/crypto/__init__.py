"""Cryptographic core of encctl-gym.

Layers, importing downward only::

    arith -> group -> checks -> encoding (+ residue_table) -> elgamal -> dyn_elgamal
          -> modified -> quantized -> servers, plant_side -> schemes -> controller

* :mod:`.arith` - the gmpy2 layer (``powmod``, ``invert``, ``is_prime``, ``jacobi``) and
  random sources (``secure_random()``; ``seeded_random(seed)``: reproducible, unsafe; the
  rules for int seeds and streams are in its docstring).
* :mod:`.group` - ``GroupParams(p, q, g)``, safe-prime generation bounded by a time estimate
  (``estimate_generation_seconds``), shipped groups.
* :mod:`.checks` - the checks shared by keys, tokens and ciphertexts (fields, types, groups).
* :mod:`.encoding` - ``Encoder(group, delta)``: Ecd/Dcd of Definition def:ec;
  :mod:`.residue_table` - the same quantisation as a table, for whole arrays.
* :mod:`.elgamal` - Example ex:elgamal: ``keygen``, ``encrypt``, ``decrypt``, ``mult``.
* :mod:`.dyn_elgamal` - Example ex:dyn_elgamal: ``key_update``, ``ciphertext_update``;
  ``recover_next_secret_key`` (Proposition prop:vulnerability).
* :mod:`.modified` - Definition def:modification: ``modified_eval``, ``modified_decrypt``.
* :mod:`.quantized` - the controller's plaintext twin with the same quantisation (eq:ec).
* :mod:`.servers` - the controller servers (modified, token, static): public keys and
  ciphertexts only; :mod:`.plant_side` - the plant party of each scheme (keys, Enc, Dec or
  Dec_bar, Sum, Dcd, KeyUpd); :mod:`.schemes` - the schemes by name, pairing the two.
* :mod:`.controller` - the encrypted linear controller of eq:ec as one object.

Forging an injected input is the adversary's: :mod:`encctl_gym.attacks.forgery`.

Keys, tokens and ciphertexts carry their group; combining objects of different groups or
steps raises :class:`~encctl_gym.errors.KeyMismatchError`.
"""

from __future__ import annotations

from .arith import RandomSource, as_random_source, as_random_stream, secure_random, seeded_random
from .controller import EncryptedLinearController, PlantCryptoSide
from .plant_side import ModifiedPlant, PlantParty, StaticPlant, TokenPlant
from .quantized import QuantizedLinearController
from .schemes import SCHEMES, Scheme, get_scheme
from .servers import ControllerServer, StaticControllerServer, TokenControllerServer
from .dyn_elgamal import UpdateToken, ciphertext_update, key_update, recover_next_secret_key
from .elgamal import Ciphertext, PublicKey, SecretKey, decrypt, encrypt, keygen, mult
from .encoding import Encoder, decode_int, encode_int
from .group import (
    DEFAULT_MAX_GENERATION_SECONDS,
    MAX_GROUP_BITS,
    MIN_GENERATE_BITS,
    SHIPPED_BITS,
    GroupParams,
    estimate_generation_seconds,
    generate_safe_prime_group,
    get_group,
    shipped_group,
)
from .modified import ModifiedCiphertext, modified_decrypt, modified_eval

__all__ = [
    "RandomSource",
    "secure_random",
    "seeded_random",
    "as_random_source",
    "as_random_stream",
    "GroupParams",
    "MIN_GENERATE_BITS",
    "MAX_GROUP_BITS",
    "SHIPPED_BITS",
    "DEFAULT_MAX_GENERATION_SECONDS",
    "estimate_generation_seconds",
    "generate_safe_prime_group",
    "shipped_group",
    "get_group",
    "Encoder",
    "encode_int",
    "decode_int",
    "PublicKey",
    "SecretKey",
    "Ciphertext",
    "keygen",
    "encrypt",
    "decrypt",
    "mult",
    "UpdateToken",
    "key_update",
    "ciphertext_update",
    "recover_next_secret_key",
    "ModifiedCiphertext",
    "modified_eval",
    "modified_decrypt",
    "ControllerServer",
    "StaticControllerServer",
    "TokenControllerServer",
    "PlantParty",
    "ModifiedPlant",
    "TokenPlant",
    "StaticPlant",
    "PlantCryptoSide",
    "Scheme",
    "SCHEMES",
    "get_scheme",
    "EncryptedLinearController",
    "QuantizedLinearController",
]
