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

__all__ = ["Scheme", "ELGAMAL_VARIANTS", "get_scheme"]


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


def _controller_server(plant: PlantParty, ct: Any, rng: RandomSource) -> ControllerServer:
    return ControllerServer(plant.pk0, ct)


def _token_server(plant: PlantParty, ct: Any, rng: RandomSource) -> TokenControllerServer:
    return TokenControllerServer(plant.pk0, ct, rng)


def _static_server(plant: PlantParty, ct: Any, rng: RandomSource) -> StaticControllerServer:
    return StaticControllerServer(plant.pk0, ct)


#: The parties of the three ElGamal variants by name (the loop's one scheme registry,
#: :data:`encctl_gym.loop.scheme.SCHEMES`, holds the schemes; these are their parts).
ELGAMAL_VARIANTS: dict[str, Scheme] = {
    "modified": Scheme("modified", ModifiedPlant, _controller_server, False),
    "token": Scheme("token", TokenPlant, _token_server, True),
    "static": Scheme("static", StaticPlant, _static_server, False),
}


def get_scheme(name: Any) -> Scheme:
    """The variant ``name`` of :data:`ELGAMAL_VARIANTS`; an unknown name raises :class:`ParameterError`."""
    if not isinstance(name, str) or name not in ELGAMAL_VARIANTS:
        raise ParameterError(f"unknown scheme {format_value(name)}; choose one of {', '.join(ELGAMAL_VARIANTS)}")
    return ELGAMAL_VARIANTS[name]
