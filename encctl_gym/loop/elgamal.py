"""The ElGamal backend (``crypto="elgamal"``): real ciphertexts of the configured scheme through the loop.

The scheme is an :class:`~encctl_gym.loop.scheme.EncryptionScheme` (the environment's ``scheme``):
by default dynamic-key ElGamal with keys updated every period, with the modified
evaluation/decryption of Definition def:modification (``scheme="modified"``), the conventional
token-based dynamic key (``"token"``) or one fixed key pair (``"static"``); any scheme of
:data:`~encctl_gym.loop.scheme.SCHEMES` (or object implementing the protocol) runs the same way.
One copy.

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

from typing import Any, cast

import numpy as np

from ..errors import ParameterError
from .injection import ADD, REPLACE, SCALE, scale_gain, scale_multipliers
from .output_feedback import controller_matrix
from .scheme import EncryptionScheme, MalleableScheme, make_scheme
from .spec import LoopSpec

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
    """Real ciphertexts of the configured scheme through the loop (one copy).

    Every step of the scheme is the scheme object's (:attr:`encryption`, an
    :class:`~encctl_gym.loop.scheme.EncryptionScheme`): the plant side holds the keys, encrypts
    the state under the period's key, decrypts, sums and decodes; the controller server holds
    public keys and ciphertexts only; the forged input comes from the scheme's ``forge`` (public
    keys only). For the ElGamal variants (:mod:`encctl_gym.loop.elgamal_scheme`):
    ``"modified"``: Phi encrypted once under ``pk_0``, keys updated every period, no token leaves
    the plant. ``"token"``: the server receives every update token and CtUpds Phi's
    ciphertexts. ``"static"``: one key pair, never updated.

    The adversary's break of a state ciphertext (paid for in time by the environment) is
    done by :attr:`decipherer`: simulated by reading the plant's secret of that period
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

    def __init__(self, params: LoopSpec, group: Any) -> None:
        self.params = params
        self.group = group
        #: the scheme's object (:class:`~encctl_gym.loop.scheme.EncryptionScheme`)
        self.encryption: EncryptionScheme = make_scheme(params.scheme)
        #: the scheme's name
        self.scheme = self.encryption.name
        self.encoder = self.encryption.encoder(group, float(params.delta))
        self.Phi = controller_matrix(params)  # -K_lqr on x, or the output controller on [x_c; y]
        self.n, self.m = self.Phi.shape[1], params.m  # n: the controller's input xi (x, y or [x_c; y])
        # the scheme refuses a loop its plaintext space cannot hold now, not at the first reset (as the ideal backend)
        self.encryption.quantization(self.Phi, self.encoder, params.x_bound, params.u_max)
        #: each party's random source (privileged: who holds which randomness), see :func:`party_random_sources`
        self.random_sources = party_random_sources(params.crypto_seed)
        #: how the adversary obtains the secret of each period's key (:mod:`encctl_gym.attacks.decipherer`)
        self.decipherer = self.decipherer_for(group, params.breaker_precomputation)
        self.plant: Any = None
        self.server: Any = None
        self.last_state_ciphertexts: list[Any] | None = None
        self.last_output_ciphertexts: Any = None

    def decipherer_for(self, group: Any, precomputation: Any = None) -> Any:
        """The adversary's decipherer in ``group`` (:func:`~encctl_gym.attacks.decipherer.make_decipherer`):
        the configured breaker, or the oracle reading the plant's secret of each public key."""
        from ..attacks.decipherer import make_decipherer

        p = self.params
        return make_decipherer(
            p.breaker,
            group,
            lambda pk: self.encryption.oracle_secret(self.plant, pk),
            scheme=self.encryption,
            adversary=p.adversary,
            time_limit=p.breaker_time_limit,
            rng=self.random_sources["breaker"],
            precomputation=precomputation,
        )

    def start_episode(self) -> None:
        """Fresh keys (KeyGen) and Phi encrypted under ``pk_0``; the server of the scheme is set up."""
        self.provision()
        self.decipherer.start_episode()

    def provision(self) -> None:
        """KeyGen in the loop's group and the server of the scheme set up with ``Enc(pk_0, Ecd(Phi))``."""
        quant = self.encryption.quantization(self.Phi, self.encoder, self.params.x_bound, self.params.u_max)
        self.plant, self.server = self.encryption.parties(quant, self.random_sources["plant"], self.random_sources["server"])

    def rotate_group(self, group: Any) -> Any:
        """Move to a fresh ``group`` (group rotation): KeyGen in it, the server re-provisioned, the
        adversary's breaker on the new group; returns the
        :class:`~encctl_gym.loop.provisioning.ProvisioningCost` (:func:`~encctl_gym.loop.provisioning.rotate_elgamal_loop`)."""
        from .provisioning import rotate_elgamal_loop

        return rotate_elgamal_loop(self, group)

    @staticmethod
    def _single(v: np.ndarray) -> np.ndarray:
        if v.shape[0] != 1:
            raise ParameterError(f"the elgamal backend runs one copy, got a batch of {v.shape[0]}")
        return v[0]

    def collect_state(self, x: np.ndarray) -> np.ndarray:
        """Encrypt ``x_t`` under the period's key (what the server and an eavesdropper receive)
        and return what breaking those ciphertexts reveals: the scheme's ``reveal`` with the
        secret of :attr:`decipherer` (``Dcd(Dec(s_t, ct))`` for ElGamal)."""
        scheme = self.encryption
        cts = self.last_state_ciphertexts = scheme.encrypt_state(self.plant, self._single(x))
        secret = self.decipherer.secret(scheme.public_key(self.plant))
        return np.array([[scheme.reveal(self.group, secret, ct, self.encoder) for ct in cts]])

    @property
    def deciphering_seconds(self) -> float:
        """Wall seconds the decipherer's breaks took this episode (0 when the break is simulated)."""
        return float(self.decipherer.seconds)

    def control(self, x: np.ndarray) -> np.ndarray:
        """A full period of normal operation: encrypt, server evaluation (eq:ec), decrypt, Sum,
        decode, key update."""
        scheme = self.encryption
        ct_x = scheme.encrypt_state(self.plant, self._single(x))
        u = scheme.decrypt_output(self.plant, scheme.evaluate(self.server, ct_x))
        self.tick()
        return np.asarray(u)[None]

    def inject(self, a: np.ndarray) -> np.ndarray:
        """The adversary forges the input ciphertexts from public keys only; the plant decrypts."""
        return self.period_input(a, None, REPLACE)

    def period_input(self, a: np.ndarray, x: np.ndarray | None, injection: int) -> np.ndarray:
        """The input the plant decrypts this period under the injection mode (:mod:`~.injection`):
        the scheme's forgery of ``a`` (``REPLACE``, from public keys only), or the server's
        evaluation of ``Enc(x)`` (eq:ec) with ``a`` added by the scheme's :meth:`add` (``ADD``, with
        the keys the decipherer has broken), its rows scaled by the scheme's :meth:`scale` (``SCALE``,
        no key) or passed on (``PASS``). No key update (:meth:`tick`)."""
        scheme = self.encryption
        if injection == REPLACE:
            out = scheme.forge(self.plant, self._single(a), self.encoder, self.n, self.random_sources["adversary"])
        else:
            if x is None:
                raise ParameterError("the honest evaluation of this period needs the plant's state x")
            out = scheme.evaluate(self.server, scheme.encrypt_state(self.plant, self._single(x)))
            if injection == ADD:
                out = scheme.add(
                    self.plant, out, self._single(a), self.encoder, self.decipherer.secret, self.random_sources["adversary"]
                )
            elif injection == SCALE:  # no key: the multiplicative homomorphism on the output
                c = scale_multipliers(self._single(a).tolist(), scale_gain(self.group))
                out = cast(MalleableScheme, scheme).scale(
                    self.plant, out, c, self.encoder, self.n, self.random_sources["adversary"]
                )
        self.last_output_ciphertexts = out
        return np.asarray(scheme.decrypt_output(self.plant, out))[None]

    def tick(self) -> None:
        """The scheme's key update at the end of the period (none for static keys); a token the
        server receives is seen by a malicious server."""
        token = self.encryption.update_keys(self.plant, self.server)
        if token is not None and self.params.adversary == "server":  # the malicious server sees what it receives
            self.decipherer.observe_token(token)
