"""The scheme seam: the encryption scheme the loop runs, as one object (Definitions def:ec, def:sdt, eq:opt_key).

An :class:`EncryptionScheme` holds every fact of one scheme that the loop, the adversary, the
deciphering budget and the security design need, so that a new scheme (an additive one, a
lattice one) is one module and one row of :data:`SCHEMES`, with no edit of the episode, the
backends, the budget or the design:

================================  =================================================================
what                              members
================================  =================================================================
its keys for a security level     :attr:`~EncryptionScheme.family`, :meth:`~EncryptionScheme.public_parameters`
(eq:opt_key)                      ``(key_length, ciphertexts)`` (a group, a modulus size, a lattice),
                                  :attr:`~EncryptionScheme.cost_models` (its deciphering-cost models,
                                  :class:`~encctl_gym.security.cost_models.CostModel` classes by name)
                                  and :attr:`~EncryptionScheme.baseline_model` (the paper's model of
                                  the family: lambda <-> key length)
its keys' rotation and price      :attr:`~EncryptionScheme.rotates`, :meth:`~EncryptionScheme.fresh_parameters`,
                                  :meth:`~EncryptionScheme.rotation_seconds`, :meth:`~EncryptionScheme.check_fresh`,
                                  :meth:`~EncryptionScheme.provisioning_bytes`
its breakers                      :attr:`~EncryptionScheme.breakers` (names -> breaker classes),
                                  :meth:`~EncryptionScheme.breaker_for`
its encoder (def:ec) and the      :meth:`~EncryptionScheme.encoder` ``(params, delta)``,
ideal backend's rounding          :meth:`~EncryptionScheme.rounding` ``(params, limit)``,
                                  :meth:`~EncryptionScheme.nearest_plaintext`
KeyGen, ``Enc(pk_0, Phi)``, the   :meth:`~EncryptionScheme.quantization` ``(Phi, encoder, x_bound, u_max)``,
server set-up                     :meth:`~EncryptionScheme.parties` ``(quantization, plant_rng, server_rng)``
one period of eq:ec               :meth:`~EncryptionScheme.encrypt_state`, :meth:`~EncryptionScheme.evaluate`,
                                  :meth:`~EncryptionScheme.decrypt_output`, :meth:`~EncryptionScheme.update_keys`
the adversary's injection         :meth:`~EncryptionScheme.forge` (replace, from public keys only),
(def:adversary, the injection     :meth:`~EncryptionScheme.add` (the honest output plus ``a``),
seam)                             :meth:`~EncryptionScheme.injection_needs` (what each mode must break)
what the adversary must break     :meth:`~EncryptionScheme.public_key`, :meth:`~EncryptionScheme.independent_keys`
and how the decipherer reads it   :meth:`~EncryptionScheme.oracle_secret`, :meth:`~EncryptionScheme.reveal`
================================  =================================================================

:class:`SchemeBase` gives the members a scheme without rotation, breakers or key needs may leave
out (a toy scheme written in the test suite subclasses it). The three ElGamal variants
(``"modified"``, ``"token"``, ``"static"``) are implementations
(:mod:`encctl_gym.loop.elgamal_scheme`); the environment's ``scheme`` key names a row of
:data:`SCHEMES` (or passes an object), and ``encctl-gym design --scheme NAME`` designs its key.
The plant and the server are whatever :meth:`~EncryptionScheme.parties` returns: the loop only
hands them back to the scheme's methods.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, Protocol, runtime_checkable

import numpy as np

from .._validation import format_value
from ..errors import ParameterError
from ..registry import Registry
from .injection import InjectionNeeds

__all__ = ["EncryptionScheme", "MalleableScheme", "SchemeBase", "ExactRounding", "SCHEMES", "make_scheme", "scheme_name"]


@runtime_checkable
class EncryptionScheme(Protocol):
    """The encryption scheme of the encrypted controller, as the loop runs it (one copy).

    Attributes
    ----------
    name : str
        The scheme's name (the environment's ``scheme``; its row of :data:`SCHEMES`).
    family : str
        The hard problem its keys rest on (``"discrete-log"``, ``"factoring"``, ``"lattice"``, ...).
    cost_models : Registry
        Its deciphering-cost models by name (classes of
        :class:`~encctl_gym.security.cost_models.CostModel`; the environment's
        ``deciphering_model`` and ``design --cost-model`` pick from them).
    baseline_model : str
        The name of the paper's model of the family (eq:opt_key: lambda <-> key length).
    breakers : Mapping
        Its real key breakers by name (the environment's ``breaker``).
    rotates : bool
        Whether its public parameters can be rotated (``rotate_group_every``, the rotate lever).
    """

    name: str
    family: str
    cost_models: Registry[Any]
    baseline_model: str
    breakers: Mapping[str, Any]
    rotates: bool

    # ------------------------------------------------------------------ keys and their costs
    def public_parameters(self, key_length: int, *, ciphertexts: bool = True) -> Any:
        """The public parameters of a key length (ElGamal: the group). ``ciphertexts=False``: a
        backend without ciphertexts asks, so parameters that serve the rounding alone do."""

    def fresh_parameters(self, params: Any, seed: int) -> Any:
        """New public parameters of the size of ``params`` from a 256-bit ``seed`` (rotation)."""

    def rotation_seconds(self, params: Any) -> float:
        """The time model's expected seconds of one :meth:`fresh_parameters` of that size."""

    def check_fresh(self, params: Any, current: Any) -> Any:
        """A defender's new parameters, checked against the loop's current ones; returned."""

    def provisioning_bytes(self, params: Any, encryptions: int) -> int:
        """Bytes the plant sends to provision the server with ``encryptions`` ciphertexts."""

    def breaker_for(self, breaker: Any, adversary: str, rng: Any) -> Any:
        """The breaker the decipherer runs on :meth:`public_key` (e.g. wrapped in the token
        chain for a malicious server that receives tokens); :class:`ParameterError` if the
        scheme's keys cannot be broken by it."""

    # ------------------------------------------------------------------ the encoder and the loop
    def encoder(self, params: Any, delta: float) -> Any:
        """The encoder ``Ecd``/``Dcd`` at scale ``delta`` (Definition def:ec): an object with
        ``decode`` and ``encode_signed`` like :class:`~encctl_gym.crypto.encoding.Encoder`."""

    def nearest_plaintext(self, encoder: Any, v: int) -> int:
        """The plaintext (a signed integer) nearest to the signed integer ``v``: what an adversary
        adding to a product sends (:func:`~encctl_gym.loop.injection.added_row`)."""

    def rounding(self, params: Any, limit: int) -> Any:
        """The encoder's rounding of ``round(Delta v)`` for ``|round(Delta v)| <= limit``, as the
        ideal backend tabulates it: an object with ``offsets``, ``limit``, ``nearest`` and
        ``max_shift`` (:class:`~encctl_gym.crypto.residue_table.ResidueTable`, :class:`ExactRounding`)."""

    def quantization(self, Phi: np.ndarray, encoder: Any, x_bound: float, u_max: float) -> Any:
        """The plant's quantised controller (``Phi`` on the encoder's scale, checked against the
        plaintext space for states up to ``x_bound``) that :meth:`parties` is built from;
        ``u_max`` bounds what an injection puts on an input (a scheme that sizes its plaintext
        space per loop, like LWE, reserves room for it)."""

    def parties(self, quantization: Any, plant_rng: Any, server_rng: Any) -> tuple[Any, Any]:
        """KeyGen and the parameter ciphertexts: a new plant party (fresh keys) and its server,
        each with its own randomness."""

    def encrypt_state(self, plant: Any, x: np.ndarray) -> list[Any]:
        """The state ciphertexts of ``x`` (shape (n,)) under the period's key."""

    def evaluate(self, server: Any, cts: list[Any]) -> Any:
        """The server's evaluation of the controller on the state ciphertexts (eq:ec)."""

    def decrypt_output(self, plant: Any, out: Any) -> np.ndarray:
        """Dec, Sum and Dcd of the server's output (or a falsified one): the input, shape (m,)."""

    def update_keys(self, plant: Any, server: Any) -> Any:
        """KeyUpd at the end of the period; the token the server receives (``None``: it receives none)."""

    # ------------------------------------------------------------------ the adversary
    def forge(self, plant: Any, a: np.ndarray, encoder: Any, n_cols: int, rng: Any) -> Any:
        """``injection="replace"``: output ciphertexts that the plant decodes to ``a``, from the
        plant's public keys only (Definition def:adversary, step 1)."""

    def add(self, plant: Any, out: Any, a: np.ndarray, encoder: Any, secret_of: Callable[[Any], Any], rng: Any) -> Any:
        """``injection="add"``: the server's output ``out`` falsified so that the plant decodes
        the honest input plus ``a`` (:func:`~encctl_gym.loop.injection.added_row`);
        ``secret_of(pk)`` gives the secret of a key the adversary has broken (the decipherer's)."""

    def injection_needs(self, injection: str, adversary: str) -> InjectionNeeds:
        """What the injection mode needs the adversary to have broken (extra keys, the period's key)."""

    def public_key(self, plant: Any) -> Any:
        """The key of the period the adversary must break to read the state ciphertexts."""

    def oracle_secret(self, plant: Any, pk: Any = None) -> Any:
        """The plant's secret of ``pk`` (default: the period's key); the simulated break reads it (privileged)."""

    def reveal(self, params: Any, secret: Any, ct: Any, encoder: Any) -> float:
        """What one state ciphertext reveals under ``secret``: ``Dcd(Dec(secret, ct))``."""

    def independent_keys(self, adversary: str) -> bool:
        """Whether every sample is under its own key for this adversary (else one break reveals
        every sample; Definition def:sdt)."""


@runtime_checkable
class MalleableScheme(Protocol):
    """A scheme whose output ciphertexts a server can scale without any key (``injection="scale"``:
    the multiplicative homomorphism of the ElGamal variants)."""

    def scale(self, plant: Any, out: Any, multipliers: Any, encoder: Any, n_cols: int, rng: Any) -> Any:
        """The output ``out`` with row ``i`` multiplied by ``multipliers[i]`` (:func:`~encctl_gym.loop.injection.scale_multipliers`)."""


class ExactRounding:
    """The rounding of an encoder whose plaintexts are all integers (an additive or a lattice
    scheme): ``Ecd(v) = round(Delta v)``, every offset 0 (:meth:`EncryptionScheme.rounding`)."""

    max_shift = 0

    def __init__(self, limit: int) -> None:
        self.limit = int(limit)
        self.offsets = np.zeros(2 * self.limit + 1, dtype=np.int16)

    def nearest(self, v: Any) -> np.ndarray:
        """``v`` itself (every integer is a plaintext)."""
        return np.asarray(v, dtype=np.int64)


class SchemeBase:
    """Defaults of :class:`EncryptionScheme` for a scheme without rotation, real breakers or key
    needs: a subclass gives ``name``, ``family``, ``cost_models``, ``baseline_model`` and the
    methods of one period (keys, encryption, evaluation, decryption, forgery, addition)."""

    name = "scheme"
    family = "unspecified"
    baseline_model = "paper"
    breakers: Mapping[str, Any] = {}
    rotates = False

    def fresh_parameters(self, params: Any, seed: int) -> Any:
        raise ParameterError(f"the {self.name} scheme's public parameters cannot be rotated")

    def rotation_seconds(self, params: Any) -> float:
        return 0.0

    def check_fresh(self, params: Any, current: Any) -> Any:
        raise ParameterError(f"the {self.name} scheme's public parameters cannot be rotated")

    def provisioning_bytes(self, params: Any, encryptions: int) -> int:
        return 0

    def breaker_for(self, breaker: Any, adversary: str, rng: Any) -> Any:
        raise ParameterError(f"the {self.name} scheme has no key breaker ({format_value(breaker)})")

    def rounding(self, params: Any, limit: int) -> Any:
        return ExactRounding(limit)

    def nearest_plaintext(self, encoder: Any, v: int) -> int:
        return int(v)

    def injection_needs(self, injection: str, adversary: str) -> InjectionNeeds:
        return InjectionNeeds()

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


#: The schemes by name (classes whose constructor takes the scheme's options): the one registry.
SCHEMES: Registry[Any] = Registry("scheme")


def make_scheme(spec: Any) -> EncryptionScheme:
    """A scheme from a name of :data:`SCHEMES`, a mapping ``{"name": ..., **options}``, or an
    object implementing :class:`EncryptionScheme`.

    Raises
    ------
    ParameterError
        For an unknown name or option (the registered ones are listed) or an object that is no scheme.
    """
    if isinstance(spec, str):
        return SCHEMES.build(spec)
    if isinstance(spec, Mapping):
        options = dict(spec)
        name = options.pop("name", None)
        if not isinstance(name, str):
            raise ParameterError(f"a scheme given as a mapping needs a 'name' ({', '.join(SCHEMES)}), got {format_value(spec)}")
        return SCHEMES.build(name, **options)
    if isinstance(spec, type) or not isinstance(spec, EncryptionScheme):
        raise ParameterError(
            f"scheme must be a name ({', '.join(SCHEMES)}), a mapping with a name, or an object implementing "
            f"EncryptionScheme, got {format_value(spec)}"
        )
    return spec


def scheme_name(spec: Any) -> str:
    """The name of a scheme given by name, mapping or object (checked by :func:`make_scheme`)."""
    return make_scheme(spec).name
