"""The closed loop behind the plant's input: encrypted controller, or an adversary's injection.

Backends implement :class:`~encctl_gym.loop.backend.LoopBackend` and are picked by name
(:data:`BACKENDS`, the environment's ``crypto`` key):

* ``"ideal"`` (:class:`~encctl_gym.loop.ideal.IdealLoop`): the exact encode / quantise /
  multiply / sum / decode arithmetic of the encrypted controller without big integers, batched,
  with the compiled stages of :mod:`encctl_gym.loop.quantize`;
* ``"elgamal"`` (:class:`~encctl_gym.loop.elgamal.ElGamalLoop`): real dynamic-key ElGamal
  ciphertexts, one copy.

The encryption scheme the ElGamal backend runs is an
:class:`~encctl_gym.loop.scheme.EncryptionScheme` of :data:`SCHEMES` (the three ElGamal variants
of :mod:`encctl_gym.loop.elgamal_scheme`, or a new one: a class and a row).

The defender policies with real levers (input noise, audits, a chi-squared detector) are in
:mod:`encctl_gym.loop.defenses`; group rotation (a fresh group every K steps) in
:mod:`encctl_gym.loop.rotation`.

Both use the group the defender picks (:mod:`encctl_gym.loop.defender`; by default that of
:func:`~encctl_gym.loop.backend.loop_group` for the key length), so their trajectories agree
bit for bit up to the largest shipped group (2048 bits). Above it, with the default defender,
the ElGamal backend generates a safe-prime group of the key length (minutes at 2500 bits), while
the ideal backend, which needs the group only for the residue pattern of its quantisation, stays
on the 2048-bit group: it generates nothing, and its trajectories then differ from ElGamal's in
the rounding pattern only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..crypto.group import SHIPPED_BITS
from ..errors import ParameterError
from .backend import LoopBackend, loop_group, lqr_gain, table_limit
from .defender import DEFENDERS, DefenderAction, DefenderPolicy, FixedDefender, PlantView, make_defender
from .defenses import AuditDefender, CusumDefender, DetectorDefender, NoiseDefender  # registers "noise", "audit", "chi2", "cusum"
from .elgamal import ElGamalLoop
from .elgamal_scheme import ElGamalScheme  # registers "modified", "token", "static"
from .ideal import IdealLoop
from .quantize import Quantization
from .rotation import RotatingDefender, defender_for  # registers "rotate"
from .scheme import SCHEMES, EncryptionScheme, make_scheme
from .spec import LoopSpec

if TYPE_CHECKING:
    from ..envs.config import AttackParams

__all__ = [
    "LoopBackend",
    "BACKENDS",
    "make_loop",
    "IdealLoop",
    "ElGamalLoop",
    "Quantization",
    "EncryptionScheme",
    "ElGamalScheme",
    "SCHEMES",
    "make_scheme",
    "LoopSpec",
    "loop_group",
    "lqr_gain",
    "table_limit",
    "DEFENDERS",
    "DefenderAction",
    "DefenderPolicy",
    "FixedDefender",
    "NoiseDefender",
    "AuditDefender",
    "CusumDefender",
    "DetectorDefender",
    "PlantView",
    "make_defender",
    "RotatingDefender",
    "defender_for",
]

#: Backends by the name the environment's ``crypto`` key gives.
BACKENDS: dict[str, type] = {"ideal": IdealLoop, "elgamal": ElGamalLoop}


def make_loop(params: AttackParams, defender: DefenderPolicy | None = None) -> LoopBackend:
    """The backend selected by ``params.crypto``, on the group the defender picks
    (``defender``, else the policy of ``params.defender``; by default :func:`loop_group` of the
    key length).

    With the default defender, a backend without ciphertexts (``needs_key_length_group = False``:
    the ideal one) gets the group of ``min(key_length, max(SHIPPED_BITS))`` bits, so it never
    generates a group."""
    try:
        backend = BACKENDS[params.crypto]
    except KeyError:
        raise ParameterError(f"unknown crypto backend {params.crypto!r}; choose one of {', '.join(BACKENDS)}") from None
    policy = defender if defender is not None else make_defender(params.defender)
    if not getattr(backend, "needs_key_length_group", True) and isinstance(policy, FixedDefender):
        return backend(params, loop_group(min(params.key_length, max(SHIPPED_BITS))))
    return backend(params, policy.group(params))
