"""The three ElGamal variants as implementations of the scheme seam (:class:`~.scheme.EncryptionScheme`).

==============  ===========================================  ======================================
scheme          parties (:data:`encctl_gym.crypto.schemes    keys the adversary breaks (def:sdt,
                .SCHEMES`)                                   :mod:`encctl_gym.security.deciphering`)
==============  ===========================================  ======================================
``modified``    ``Eval_bar``/``Dec_bar`` (def:modification)  one per sample, either adversary
``token``       ``Eval``/``Dec``, CtUpd with every token      one per sample against an
                (Example ex:dyn_elgamal)                     eavesdropper; one against the server,
                                                             which chains the tokens
                                                             (Proposition prop:vulnerability)
``static``      ``Eval``/``Dec``, one key pair               one
==============  ===========================================  ======================================

The modified scheme's forged output has two masks (``h_0^r h_t^r'``, :func:`forge_injection`),
the others one (``Enc(pk_t, .)``, :func:`forge_injection_token`). Option ``per_entry`` (default
False): fresh forging randomness for every entry (see :mod:`encctl_gym.attacks.forgery`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import check_bool
from ..attacks.forgery import forge_injection, forge_injection_token
from ..crypto.elgamal import decrypt_components
from ..crypto.encoding import Encoder
from ..crypto.schemes import get_scheme
from ..security.deciphering import independent_keys
from .scheme import SCHEMES

__all__ = ["ElGamalScheme", "ModifiedElGamal", "TokenElGamal", "StaticElGamal"]


class ElGamalScheme:
    """Dynamic-key ElGamal over the loop's group (Examples ex:elgamal, ex:dyn_elgamal).

    Subclasses set :attr:`name`; the parties, the token routing and the keys to break follow
    from it (one home each: :mod:`encctl_gym.crypto.schemes` and
    :func:`encctl_gym.security.deciphering.independent_keys`).

    Parameters
    ----------
    per_entry : bool, default False
        Forge with fresh randomness for every entry (see :func:`forge_injection`).
    """

    name = "modified"

    def __init__(self, per_entry: bool = False) -> None:
        self.per_entry = check_bool("per_entry", per_entry)
        self._parts = get_scheme(self.name)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(per_entry={self.per_entry})"

    def encoder(self, group: Any, delta: float) -> Encoder:
        return Encoder(group, float(delta))

    def parties(self, quantization: Any, plant_rng: Any, server_rng: Any) -> tuple[Any, Any]:
        return self._parts.parties(quantization, plant_rng, server_rng)

    def encrypt_state(self, plant: Any, x: np.ndarray) -> list[Any]:
        return plant.encrypt_state(x)

    def evaluate(self, server: Any, cts: list[Any]) -> Any:
        return server.evaluate(cts)

    def decrypt_output(self, plant: Any, out: Any) -> np.ndarray:
        return plant.decrypt_output(out)

    def update_keys(self, plant: Any, server: Any) -> Any:
        """KeyUpd (none for static keys); the token scheme's server CtUpds with the token it receives."""
        token = plant.update_keys()
        if self._parts.token_to_server:
            server.receive_token(token)
            return token
        return None

    def forge(self, plant: Any, a: np.ndarray, encoder: Any, n_cols: int, rng: Any) -> Any:
        if self.name == "modified":
            return forge_injection(plant.pk0, plant.pk, a, encoder, n_cols, rng, per_entry=self.per_entry)
        return forge_injection_token(plant.pk, a, encoder, n_cols, rng, per_entry=self.per_entry)

    def public_key(self, plant: Any) -> Any:
        return plant.pk

    def oracle_secret(self, plant: Any) -> int:
        return int(plant.secret_key.s)

    def reveal(self, group: Any, secret: Any, ct: Any, encoder: Any) -> float:
        """``Dcd(Dec(s_t, ct))`` of one state ciphertext (``Enc(pk_t, .)`` in every variant)."""
        return float(encoder.decode(decrypt_components(group, int(secret), ct.c1, ct.c2)))

    def independent_keys(self, adversary: str) -> bool:
        return independent_keys(self.name, adversary)

    def breaker_for(self, breaker: Any, adversary: str, rng: Any) -> Any:
        """The breaker itself, or (token scheme, malicious server) the token chain over it."""
        from ..cryptanalysis import TokenChain

        if self._parts.token_to_server and adversary == "server" and not isinstance(breaker, TokenChain):
            return TokenChain(breaker, rng=rng)
        return breaker


@SCHEMES.register
class ModifiedElGamal(ElGamalScheme):
    """The proposed scheme (Definition def:modification): keys updated every period, no token sent."""

    name = "modified"


@SCHEMES.register
class TokenElGamal(ElGamalScheme):
    """The conventional dynamic key (Definition def:ec): the server receives every token."""

    name = "token"


@SCHEMES.register
class StaticElGamal(ElGamalScheme):
    """One fixed key pair (Example ex:elgamal)."""

    name = "static"
