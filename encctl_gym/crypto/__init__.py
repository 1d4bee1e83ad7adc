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

import sys

from .arith import *  # noqa: F403
from .checks import *  # noqa: F403
from .controller import *  # noqa: F403
from .dyn_elgamal import *  # noqa: F403
from .elgamal import *  # noqa: F403
from .encoding import *  # noqa: F403
from .group import *  # noqa: F403
from .modified import *  # noqa: F403
from .plant_side import *  # noqa: F403
from .quantized import *  # noqa: F403
from .schemes import *  # noqa: F403
from .servers import *  # noqa: F403

#: The public names of the modules above, in their order (each module's ``__all__``).
__all__ = list(
    dict.fromkeys(
        name
        for module in (
            "arith",
            "group",
            "checks",
            "encoding",
            "elgamal",
            "dyn_elgamal",
            "modified",
            "quantized",
            "servers",
            "plant_side",
            "schemes",
            "controller",
        )
        for name in sys.modules[f"{__name__}.{module}"].__all__
    )
)
