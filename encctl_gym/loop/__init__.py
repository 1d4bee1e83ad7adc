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

Both take the loop's own value object, :class:`~encctl_gym.loop.spec.LoopSpec` (nothing here
knows the environment's configuration), and run on the group the defender picks
(:mod:`encctl_gym.loop.defender`; by default :meth:`LoopSpec.group`, the scheme's public
parameters for the key length: the one place that decides them), so their trajectories agree
bit for bit up to the largest shipped group (2048 bits). Above it the ElGamal backend generates a
safe-prime group of the key length (minutes at 2500 bits), while the ideal backend, which needs
the group only for the residue pattern of its quantisation (``LoopSpec.ciphertexts`` False), stays
on the 2048-bit group: it generates nothing, and its trajectories then differ from ElGamal's in
the rounding pattern only.
"""

from __future__ import annotations

from ..errors import ParameterError
from .assembly import defender_for
from .backend import LoopBackend, lqr_gain, table_limit
from .defender import DEFENDERS, DefenderAction, DefenderBase, DefenderPolicy, FixedDefender, PlantView, make_defender
from .defenses import AuditDefender, CusumDefender, DetectorDefender, NoiseDefender  # registers "noise", "audit", "chi2", "cusum"
from .elgamal import ElGamalLoop
from .elgamal_scheme import ElGamalScheme  # registers "modified", "token", "static"
from .ideal import IdealLoop
from .lwe_scheme import LWEScheme  # registers "lwe"
from .paillier_scheme import PaillierScheme  # registers "paillier"
from .quantize import Quantization
from .rotation import RotatingDefender  # registers "rotate"
from .scheme import SCHEMES, EncryptionScheme, make_scheme
from .spec import LoopSpec
from .verification import LinearCheckDefender  # registers "linear-check"

__all__ = [
    "LoopBackend",
    "BACKENDS",
    "make_loop",
    "IdealLoop",
    "ElGamalLoop",
    "Quantization",
    "EncryptionScheme",
    "ElGamalScheme",
    "PaillierScheme",
    "LWEScheme",
    "SCHEMES",
    "make_scheme",
    "LoopSpec",
    "lqr_gain",
    "table_limit",
    "DEFENDERS",
    "DefenderAction",
    "DefenderPolicy",
    "DefenderBase",
    "FixedDefender",
    "NoiseDefender",
    "AuditDefender",
    "CusumDefender",
    "DetectorDefender",
    "PlantView",
    "make_defender",
    "RotatingDefender",
    "defender_for",
    "LinearCheckDefender",
]

#: Backends by the name the environment's ``crypto`` key gives.
BACKENDS: dict[str, type] = {"ideal": IdealLoop, "elgamal": ElGamalLoop}


def make_loop(spec: LoopSpec, defender: DefenderPolicy | None = None) -> LoopBackend:
    """The backend selected by ``spec.crypto``, on the group the defender picks (``defender``,
    else the policy of ``spec.defender``; by default :meth:`LoopSpec.group`).

    Raises
    ------
    ParameterError
        For an unknown backend or something that is not a :class:`LoopSpec`.
    """
    if not isinstance(spec, LoopSpec):
        raise ParameterError(f"make_loop takes a LoopSpec (AttackParams.loop), got {type(spec).__name__}")
    try:
        backend = BACKENDS[spec.crypto]
    except KeyError:
        raise ParameterError(f"unknown crypto backend {spec.crypto!r}; choose one of {', '.join(BACKENDS)}") from None
    policy = defender if defender is not None else make_defender(spec.defender)
    return backend(spec, policy.group(spec))
