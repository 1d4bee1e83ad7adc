"""The key-handling schemes of the encrypted controller, by name: which plant party, which server.

==============  ===================  =========================  ==============================
scheme          plant party          server                     keys
==============  ===================  =========================  ==============================
``modified``    :class:`ModifiedPlant` :class:`ControllerServer`  updated every period; no token
                                                                 leaves the plant (Definition
                                                                 def:modification, eq:ec)
``token``       :class:`TokenPlant`  :class:`TokenControllerServer` updated every period; the
                                                                 server receives every token
                                                                 (Definition def:ec, Example
                                                                 ex:dyn_elgamal)
``static``      :class:`StaticPlant` :class:`StaticControllerServer` one fixed key pair
==============  ===================  =========================  ==============================

These are the ElGamal variants' parties: the encrypted controller
(:class:`~encctl_gym.crypto.controller.EncryptedLinearController`) pairs them here, and the
loop's scheme seam (:class:`encctl_gym.loop.scheme.EncryptionScheme`, the ElGamal variants in
:mod:`encctl_gym.loop.elgamal_scheme`) takes them from here; a new scheme is a class of that
seam and a row of :data:`encctl_gym.loop.scheme.SCHEMES`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .._validation import format_value
from ..errors import ParameterError
from .arith import RandomSource
from .plant_side import ModifiedPlant, PlantParty, StaticPlant, TokenPlant
from .quantized import QuantizedLinearController
from .servers import ControllerServer, StaticControllerServer, TokenControllerServer

__all__ = ["Scheme", "SCHEMES", "get_scheme"]


@dataclass(frozen=True)
class Scheme:
    """One key-handling scheme: its plant party and the server that goes with it.

    Attributes
    ----------
    name : str
        The scheme's name (the ``scheme`` of the environment and of the controller).
    plant : type
        The plant party (:mod:`.plant_side`).
    make_server : callable
        ``(plant, ct_phi, rng) -> server``: the server for that plant's parameter ciphertexts,
        with its own randomness ``rng`` where it needs any.
    token_to_server : bool
        The plant sends every update token to the server (the server then CtUpds Phi).
    """

    name: str
    plant: type[PlantParty]
    make_server: Callable[[PlantParty, Any, RandomSource], Any]
    token_to_server: bool

    def parties(self, quantization: QuantizedLinearController, plant_rng: Any, server_rng: Any) -> tuple[PlantParty, Any]:
        """A new plant party (fresh keys) and its server, each with its own randomness."""
        plant = self.plant(quantization, plant_rng)
        return plant, self.make_server(plant, plant.encrypt_parameter(), server_rng)


#: The schemes by name.
SCHEMES: dict[str, Scheme] = {
    "modified": Scheme("modified", ModifiedPlant, lambda plant, ct, rng: ControllerServer(plant.pk0, ct), False),
    "token": Scheme("token", TokenPlant, lambda plant, ct, rng: TokenControllerServer(plant.pk0, ct, rng), True),
    "static": Scheme("static", StaticPlant, lambda plant, ct, rng: StaticControllerServer(plant.pk0, ct), False),
}


def get_scheme(name: Any) -> Scheme:
    """The scheme ``name`` of :data:`SCHEMES`; an unknown name raises :class:`ParameterError`."""
    if not isinstance(name, str) or name not in SCHEMES:
        raise ParameterError(f"unknown scheme {format_value(name)}; choose one of {', '.join(SCHEMES)}")
    return SCHEMES[name]
