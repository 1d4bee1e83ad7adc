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

What the scheme owns besides one period (:class:`~.scheme.EncryptionScheme`): its keys for a
key length (the group, :meth:`ElGamalScheme.public_parameters`, the one place that decides it),
its deciphering-cost models (:data:`~encctl_gym.security.cost_models.DECIPHERING_MODELS`, the
paper's model as the baseline), group rotation (fresh safe-prime groups, priced by the
generation time model), its breakers (:data:`~encctl_gym.cryptanalysis.BREAKERS`) and the
additive injection: ElGamal is multiplicative, so an adversary that *adds* to the honest input
must read the products (with ``sk_t``, and ``sk_0`` for the modified scheme, whose products carry
both masks), and sends the nearest subgroup member of the product plus its addition under the
same mask (:meth:`ElGamalScheme.add`).
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache
from typing import Any

import numpy as np

from .._validation import check_bool, format_value
from ..attacks.forgery import forge_injection, forge_injection_token
from ..crypto import arith
from ..crypto.elgamal import decrypt_components
from ..crypto.encoding import Encoder, lift, nearest_member
from ..crypto.group import SHIPPED_BITS, GroupParams, shipped_group
from ..crypto.schemes import get_scheme
from ..errors import ParameterError
from ..security.cost_models import DECIPHERING_MODELS
from ..security.deciphering import independent_keys
from .injection import InjectionNeeds, added_row
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
    family = "discrete-log"
    cost_models = DECIPHERING_MODELS
    baseline_model = "paper"
    rotates = True

    def __init__(self, per_entry: bool = False) -> None:
        self.per_entry = check_bool("per_entry", per_entry)
        self._parts = get_scheme(self.name)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(per_entry={self.per_entry})"

    @property
    def breakers(self) -> Any:
        """The discrete-logarithm breakers (:data:`encctl_gym.cryptanalysis.BREAKERS`)."""
        from ..cryptanalysis import BREAKERS

        return BREAKERS

    # ------------------------------------------------------------------ keys and their costs
    def public_parameters(self, key_length: int, *, ciphertexts: bool = True) -> GroupParams:
        """The group of a key length k: the smallest shipped group of at least ``k`` bits (64 ...
        2048), a safe-prime group generated from the seed ``k`` above (the same in every run: group
        parameters are public). ``ciphertexts=False`` (a backend that needs the group only for the
        encoder's rounding pattern): the shipped group of ``min(k, 2048)`` bits, nothing generated."""
        k = int(key_length) if ciphertexts else min(int(key_length), max(SHIPPED_BITS))
        for bits in SHIPPED_BITS:
            if bits >= k:
                return shipped_group(bits)
        return _generated_group(k)

    def fresh_parameters(self, params: Any, seed: int) -> GroupParams:
        """A fresh safe-prime group of the size of ``params`` from a 256-bit seed (group rotation)."""
        from ..crypto.arith import seeded_random
        from ..crypto.group import generate_safe_prime_group

        return generate_safe_prime_group(int(params.bits), rng=seeded_random(int(seed)))

    def rotation_seconds(self, params: Any) -> float:
        """The generation time model's expected seconds for one group of that size."""
        from ..crypto.group import estimate_generation_seconds

        return float(estimate_generation_seconds(int(params.bits)))

    def check_fresh(self, params: Any, current: Any) -> GroupParams:
        """A defender's new group: a verified safe-prime group of the current size."""
        if not isinstance(params, GroupParams) or not params.is_safe_prime:
            raise ParameterError(f"DefenderAction.new_group must be a safe-prime GroupParams, got {format_value(params)}")
        if current is not None and params.bits != current.bits:
            raise ParameterError(
                f"DefenderAction.new_group must have the loop's size, {current.bits} bits, got a group of {params.bits} bits"
            )
        return params.verify()

    def provisioning_bytes(self, params: Any, encryptions: int) -> int:
        """:func:`~encctl_gym.loop.provisioning.provisioning_bytes` of the group."""
        from .provisioning import provisioning_bytes

        return provisioning_bytes(params, encryptions)

    # ------------------------------------------------------------------ the encoder
    def encoder(self, group: Any, delta: float) -> Encoder:
        return Encoder(group, float(delta))

    def nearest_plaintext(self, encoder: Any, v: int) -> int:
        """The nearest signed integer to ``v`` whose residue lies in G (the encoder's search)."""
        return nearest_member(encoder.group, int(v), int(encoder.max_shift))[0]

    def rounding(self, params: Any, limit: int) -> Any:
        """The residue table of the group (:func:`~encctl_gym.crypto.residue_table.residue_table`)."""
        from ..crypto.residue_table import residue_table

        return residue_table(params, limit)

    def quantization(self, Phi: np.ndarray, encoder: Any, x_bound: float, u_max: float = 0.0) -> Any:
        """:class:`~encctl_gym.crypto.quantized.QuantizedLinearController` of ``Phi`` on the group's encoder
        (the group's plaintext space is fixed: ``u_max`` needs no room)."""
        from ..crypto.quantized import QuantizedLinearController

        return QuantizedLinearController(Phi, encoder, x_bound)

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

    def add(self, plant: Any, out: Any, a: np.ndarray, encoder: Any, secret_of: Any, rng: Any) -> Any:
        """The honest output with ``a`` added (:func:`~encctl_gym.loop.injection.added_row`): the
        adversary strips the mask of each row's first entry with the broken keys (``c1^s_0 c2^s_t``
        for the modified scheme, ``c1^s_t`` for the others), lifts the product, and sends the nearest
        member of G to the product plus ``rint(Delta a_i) Ecd(1)`` under the same mask (one
        exponentiation per key and row; the other entries pass unchanged)."""
        grp = encoder.group
        p = grp.p
        one = encoder.encode_signed(1.0)
        s_t = int(secret_of(plant.pk))
        s_0 = int(secret_of(plant.pk0)) if self.name == "modified" else None
        rows = []
        for ai, row in zip(np.asarray(a, dtype=float).reshape(-1), out):
            c = row[0]
            if s_0 is None:
                mask = int(arith.powmod(c.c1, s_t, p))
                body = c.c2
            else:
                mask = int(arith.mulmod(arith.powmod(c.c1, s_0, p), arith.powmod(c.c2, s_t, p), p))
                body = c.c3
            product = lift(grp, int(arith.mulmod(body, arith.invert(mask, p), p)))
            w = added_row([product], float(ai), encoder.delta, one, lambda v: self.nearest_plaintext(encoder, v))[0]
            forged = int(arith.mulmod(w % p, mask, p))
            rows.append([replace(c, c2=forged) if s_0 is None else replace(c, c3=forged), *row[1:]])
        return rows

    def scale(self, plant: Any, out: Any, multipliers: Any, encoder: Any, n_cols: int, rng: Any) -> Any:
        """``injection="scale"``: the server's output with row ``i`` multiplied by ``c_i`` without
        any key (:func:`~encctl_gym.loop.injection.scale_multipliers`). ``c_i >= 2``: every summand's
        masked component (``c3`` of the modified scheme, ``c2`` of the others) times ``c_i`` mod p,
        a ciphertext of ``c_i P_ij`` (the multiplicative homomorphism; ``c_i`` lies in G,
        :func:`~encctl_gym.loop.injection.scale_gain`). ``c_i = 0``: the row of the public-key
        forgery of 0 (:meth:`forge`). ``c_i = 1``: the row unchanged."""
        p = encoder.group.p
        zero = None
        rows = []
        for i, (c, row) in enumerate(zip(multipliers, out)):
            if c == 1:
                rows.append(list(row))
            elif c == 0:
                if zero is None:
                    zero = self.forge(plant, np.zeros(len(multipliers)), encoder, n_cols, rng)
                rows.append(list(zero[i]))
            elif self.name == "modified":
                rows.append([replace(e, c3=int(arith.mulmod(e.c3, int(c) % p, p))) for e in row])
            else:
                rows.append([replace(e, c2=int(arith.mulmod(e.c2, int(c) % p, p))) for e in row])
        return rows

    def injection_needs(self, injection: str, adversary: str) -> InjectionNeeds:
        """``add`` reads the period's products: ``sk_t`` within the period, and ``sk_0`` (one more
        key) for the modified scheme, whose products carry both masks. ``scale`` injects without
        a key (reading what it caused needs ``sk_0`` once, as ``add``, but not in the period)."""
        if injection == "scale":
            return InjectionNeeds(extra_keys=1 if self.name == "modified" else 0)
        if injection != "add":
            return InjectionNeeds()
        return InjectionNeeds(extra_keys=1 if self.name == "modified" else 0, period_key=True)

    def public_key(self, plant: Any) -> Any:
        return plant.pk

    def oracle_secret(self, plant: Any, pk: Any = None) -> int:
        """The plant's secret of ``pk``: ``s_t`` by default, ``s_0`` for ``pk_0``."""
        if pk is not None and pk is plant.pk0 and pk is not plant.pk:
            return int(plant.initial_secret_key.s)
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


@lru_cache(maxsize=4)
def _generated_group(bits: int) -> GroupParams:
    from ..crypto.arith import seeded_random
    from ..crypto.group import generate_safe_prime_group

    return generate_safe_prime_group(bits, rng=seeded_random(bits))


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
