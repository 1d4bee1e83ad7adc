"""Cryptographic core of encctl-gym (issue 2).

Layers, importing downward only::

    arith -> group -> encoding -> elgamal -> dyn_elgamal -> modified -> controller

* :mod:`.arith` - the gmpy2 layer (``powmod``, ``invert``, ``is_prime``, ``jacobi``) and
  random sources (``secure_random()``, ``seeded_random(seed)``: reproducible, unsafe).
* :mod:`.group` - ``GroupParams(p, q, g)``, safe-prime generation, shipped groups.
* :mod:`.encoding` - ``Encoder(group, delta)``: Ecd/Dcd of Definition def:ec.
* :mod:`.elgamal` - Example ex:elgamal: ``keygen``, ``encrypt``, ``decrypt``, ``mult``.
* :mod:`.dyn_elgamal` - Example ex:dyn_elgamal: ``key_update``, ``ciphertext_update``;
  ``recover_next_secret_key`` (Proposition prop:vulnerability).
* :mod:`.modified` - Definition def:modification: ``modified_eval``, ``modified_decrypt``.
* :mod:`.controller` - the encrypted linear controller of eq:ec, its plaintext twin and
  injection forging.
"""

from __future__ import annotations

from .arith import RandomSource, secure_random, seeded_random
from .controller import (
    ControllerServer,
    EncryptedLinearController,
    PlantCryptoSide,
    QuantizedLinearController,
    TokenControllerServer,
    forge_injection,
    forge_injection_token,
    injection_value,
)
from .dyn_elgamal import UpdateToken, ciphertext_update, key_update, recover_next_secret_key
from .elgamal import Ciphertext, PublicKey, SecretKey, decrypt, encrypt, keygen, mult
from .encoding import Encoder, decode_int, encode_int
from .group import (
    MIN_GENERATE_BITS,
    SHIPPED_BITS,
    GroupParams,
    generate_safe_prime_group,
    get_group,
    shipped_group,
)
from .modified import ModifiedCiphertext, modified_decrypt, modified_eval

__all__ = [
    "RandomSource",
    "secure_random",
    "seeded_random",
    "GroupParams",
    "MIN_GENERATE_BITS",
    "SHIPPED_BITS",
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
    "TokenControllerServer",
    "PlantCryptoSide",
    "EncryptedLinearController",
    "QuantizedLinearController",
    "forge_injection",
    "forge_injection_token",
    "injection_value",
]
