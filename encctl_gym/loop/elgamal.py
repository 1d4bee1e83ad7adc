"""The ElGamal backend (``crypto="elgamal"``): real dynamic-key ElGamal ciphertexts through the loop.

Keys are updated every period, with the modified evaluation/decryption of Definition
def:modification (``scheme="modified"``), the conventional token-based dynamic key
(``"token"``) or one fixed key pair (``"static"``). One copy.

The parties hold their own randomness and nothing of each other's: the plant (keys, state
encryptions), the controller server (the token scheme's CtUpd re-randomisation), the
adversary (the randomness of its forged ciphertexts) and the adversary's key breaker (its
walks and descents, a stream of its own so that breaking changes none of the other draws). With
``crypto_seed`` the streams are derived from it independently (``numpy.random.SeedSequence``
children), so a run is reproducible and still no party can recompute another's draws from its own.

The adversary reads the state ciphertexts it paid for through a decipherer
(:mod:`encctl_gym.attacks.decipherer`): by default the plant's key of the period (the break is
simulated), with ``breaker=...`` the exponent a real discrete-logarithm attack recovers from
the period's public key.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ParameterError
from .output_feedback import controller_matrix

__all__ = ["ElGamalLoop", "party_random_sources"]

#: The parties of the loop that draw randomness, in the order their seeded streams are spawned.
PARTIES = ("plant", "server", "adversary", "breaker")


def party_random_sources(crypto_seed: int | None) -> dict[str, Any]:
    """One random source per party of :data:`PARTIES`: secure ones, or independent seeded streams.

    Parameters
    ----------
    crypto_seed : int or None
        ``None``: a cryptographically secure source each. An integer: reproducible, unsafe for
        deployment; child ``i`` of ``SeedSequence(crypto_seed)`` seeds party ``i``.
    """
    from ..crypto.arith import SecureRandom, seeded_random

    if crypto_seed is None:
        return {name: SecureRandom() for name in PARTIES}
    children = np.random.SeedSequence(crypto_seed).spawn(len(PARTIES))
    return {name: seeded_random(int(c.generate_state(1, np.uint64)[0])) for name, c in zip(PARTIES, children)}


class ElGamalLoop:
    """Real dynamic-key ElGamal ciphertexts through the loop (one copy).

    The parties come from the scheme (:data:`encctl_gym.crypto.schemes.SCHEMES`): the plant
    side (:mod:`encctl_gym.crypto.plant_side`) holds the keys, encrypts the state under
    ``pk_t``, decrypts (two-key ``Dec_bar(sk_0, sk_t, .)`` in the modified scheme, ``Dec(sk_t,
    .)`` otherwise), sums and decodes; the controller server (:mod:`encctl_gym.crypto.servers`)
    holds public keys and ciphertexts only; the forged input comes from
    :func:`encctl_gym.attacks.forgery.forge`. ``"modified"``: Phi encrypted once under ``pk_0``, keys
    updated every period, no token leaves the plant. ``"token"``: the server receives every
    update token and CtUpds Phi's ciphertexts. ``"static"``: one key pair, never updated.

    The adversary's break of a state ciphertext (paid for in time by the environment) is
    done by :attr:`decipherer`: simulated by decrypting with the plant's key of that period
    (default), or a real break of the period's public key with ``params.breaker``
    (:class:`~encctl_gym.attacks.decipherer.KeyBreaking`: then nothing of the plant's is read).

    Raises
    ------
    BreakerLimitError
        With a breaker the group is too large for, or whose expected time exceeds
        ``params.breaker_time_limit`` (before any work).
    """

    batched = False
    #: ciphertexts live in the group of the key length (generated above the shipped sizes)
    needs_key_length_group = True
    quantization = None

    def __init__(self, params: Any, group: Any) -> None:
        from ..crypto.encoding import Encoder
        from ..crypto.schemes import get_scheme

        self.params = params
        self.group = group
        self.scheme = params.scheme
        self._scheme = get_scheme(params.scheme)
        self.encoder = Encoder(group, float(params.delta))
        self.Phi = controller_matrix(params)  # -K_lqr on x, or the output controller on [x_c; y]
        self.n, self.m = self.Phi.shape[1], params.m  # n: the controller's input xi (x, y or [x_c; y])
        #: each party's random source (privileged: who holds which randomness), see :func:`party_random_sources`
        self.random_sources = party_random_sources(params.crypto_seed)
        from ..attacks.decipherer import make_decipherer

        #: how the adversary obtains the exponent of each period's key (:mod:`encctl_gym.attacks.decipherer`)
        self.decipherer = make_decipherer(params, group, lambda: self.plant.secret_key, self.random_sources["breaker"])
        self.plant: Any = None
        self.server: Any = None
        self.last_state_ciphertexts: list[Any] | None = None
        self.last_output_ciphertexts: list[list[Any]] | None = None

    def start_episode(self) -> None:
        """Fresh keys (KeyGen) and Phi encrypted under ``pk_0``; the server of the scheme is set up."""
        from ..crypto.quantized import QuantizedLinearController

        quant = QuantizedLinearController(self.Phi, self.encoder, self.params.x_bound)
        self.plant, self.server = self._scheme.parties(quant, self.random_sources["plant"], self.random_sources["server"])
        self.decipherer.start_episode()

    @staticmethod
    def _single(v: np.ndarray) -> np.ndarray:
        if v.shape[0] != 1:
            raise ParameterError(f"the elgamal backend runs one copy, got a batch of {v.shape[0]}")
        return v[0]

    def collect_state(self, x: np.ndarray) -> np.ndarray:
        """Encrypt ``x_t`` under ``pk_t`` (what the server and an eavesdropper receive) and
        return what breaking those ciphertexts reveals: ``Dcd(Dec(s_t, ct))`` with the exponent
        ``s_t`` of :attr:`decipherer`."""
        from ..crypto.elgamal import decrypt_components

        pk = self.plant.pk
        cts = self.last_state_ciphertexts = self.plant.encrypt_state(self._single(x))
        s_t = self.decipherer.secret(pk)
        return np.array([[self.encoder.decode(decrypt_components(self.group, s_t, ct.c1, ct.c2)) for ct in cts]])

    @property
    def deciphering_seconds(self) -> float:
        """Wall seconds the decipherer's breaks took this episode (0 when the break is simulated)."""
        return float(self.decipherer.seconds)

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
        from ..attacks.forgery import forge

        a0 = self._single(a)
        out = forge(self.scheme, self.plant.pk0, self.plant.pk, a0, self.encoder, self.n, self.random_sources["adversary"])
        self.last_output_ciphertexts = out
        return self.plant.decrypt_output(out)[None]

    def tick(self) -> None:
        """KeyUpd at the end of the period (none for static keys); the token scheme sends the
        token to the server, which CtUpds Phi's ciphertexts."""
        token = self.plant.update_keys()
        if self._scheme.token_to_server:
            self.server.receive_token(token)
            if self.params.adversary == "server":  # the malicious server sees what it receives
                self.decipherer.observe_token(token)
