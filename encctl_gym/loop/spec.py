"""The loop as a value object: everything the closed loop behind the plant's input is made of
(Definitions def:ec, def:adversary, def:sdt).

A :class:`LoopSpec` is what the loop layer takes: the backends (:mod:`encctl_gym.loop.ideal`,
:mod:`encctl_gym.loop.elgamal`), the defenders (:mod:`encctl_gym.loop.defender`), group rotation
and the controller design all read their parameters from it, and nothing under ``loop/`` knows
the environment's configuration. It holds the plant (a :class:`~encctl_gym.plant.Plant`, with
its outputs when the plant sends them), the process noise, the adversary, the backend
(``crypto``), the encryption scheme, the key length, the encoder's scale ``Delta`` and bounds, the
attack length, how the adversary injects (:data:`INJECTIONS`), its key breaker and the
defender's policy. It is built from checked values (the environment builds it once,
``AttackParams.loop``) and checks nothing again; :meth:`LoopSpec.encryption` and
:meth:`LoopSpec.group` give the objects the names stand for, and :meth:`LoopSpec.group` is the
one place that decides the group of a key length.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..plant import Plant
from .injection import INJECTIONS
from .scheme import EncryptionScheme, make_scheme

__all__ = ["LoopSpec", "INJECTIONS"]


@dataclass(frozen=True)
class LoopSpec:
    """The closed loop behind the plant's input.

    Attributes
    ----------
    plant : Plant
        ``(A, B)`` of eq:system, with ``C`` and ``sigma_v2`` when the plant sends outputs.
    sigma_w2 : float
        The process noise variance (the controller design and the plant side's detectors use it).
    adversary : str
        ``"eavesdropper"`` or ``"server"`` (Definition def:adversary).
    crypto : str
        The backend (``"ideal"`` or ``"elgamal"``, :data:`encctl_gym.loop.BACKENDS`).
    scheme : str or EncryptionScheme
        The encryption scheme: a name of :data:`encctl_gym.loop.scheme.SCHEMES` or an object.
    key_length : int
        k, the bit length of p (eq:opt_key).
    delta : int
        The encoder's scale Delta (Definition def:ec).
    x_bound : float
        The largest state entry the encoder takes.
    u_max : float
        The actuator bound (an action of 1).
    horizon : int
        N, the attack length in samples.
    breaker : str or None
        The adversary's key breaker (:data:`encctl_gym.cryptanalysis.BREAKERS`); ``None``: the
        break is simulated.
    breaker_time_limit : float
        Seconds a break may take.
    crypto_seed : int or None
        Seed of the parties' random streams (``None``: secure sources).
    defender : object
        The defender policy specification (a name of :data:`encctl_gym.loop.DEFENDERS`, a
        mapping, or a policy object).
    rotate_group_every : int or None
        Group rotation: a fresh safe-prime group every ``K`` attack steps (``None``: one group;
        :mod:`encctl_gym.loop.rotation`).
    audit_probability : float or None
        Audits per step added to the defender (``None``: none).
    defense_noise_sigma2 : float or None
        Input noise added to the defender (``None``: none).
    breaker_precomputation : str or None
        A precomputation file the breaker loads (the index calculus), checked against the group.
    observe : str
        What the plant sends: ``"state"`` (``x``) or ``"output"`` (``y = C x + v``).
    controller : str
        The loop's controller on outputs (:data:`encctl_gym.loop.output_feedback.CONTROLLERS`).
    injection : str
        How the adversary's action enters the loop (:data:`INJECTIONS`): ``"replace"`` (the
        forgery of Definition def:adversary), ``"add"`` (the server's honest output plus the
        action) or ``"pass"`` (the honest loop).
    ciphertexts : bool
        Whether the backend runs real ciphertexts (its ``needs_key_length_group``): the ideal
        backend needs the group only for the encoder's rounding pattern.
    """

    plant: Plant
    sigma_w2: float
    adversary: str
    crypto: str
    scheme: Any
    key_length: int
    delta: int
    x_bound: float
    u_max: float
    horizon: int
    breaker: str | None = None
    breaker_time_limit: float = float("inf")
    crypto_seed: int | None = None
    defender: Any = "fixed"
    rotate_group_every: int | None = None
    audit_probability: float | None = None
    defense_noise_sigma2: float | None = None
    breaker_precomputation: str | None = None
    observe: str = "state"
    controller: str = "static"
    injection: str = "replace"
    ciphertexts: bool = True

    # ----------------------------------------------------------------- the plant's matrices
    @property
    def A(self) -> np.ndarray:
        """The plant's ``A`` (eq:system)."""
        return self.plant.A

    @property
    def B(self) -> np.ndarray:
        """The plant's ``B`` (eq:system)."""
        return self.plant.B

    @property
    def C(self) -> np.ndarray | None:
        """The sensors when the plant sends outputs, else ``None``."""
        return self.plant.C

    @property
    def sigma_v2(self) -> float:
        """The measurement noise variance (0 when the state is sent)."""
        return self.plant.sigma_v2

    @property
    def n(self) -> int:
        return self.plant.n

    @property
    def m(self) -> int:
        return self.plant.m

    # ----------------------------------------------------------------- what the names stand for
    def encryption(self) -> EncryptionScheme:
        """The scheme object (:func:`~encctl_gym.loop.scheme.make_scheme`)."""
        return make_scheme(self.scheme)

    @property
    def scheme_name(self) -> str:
        """The scheme's name (its row of :data:`~encctl_gym.loop.scheme.SCHEMES`)."""
        return self.encryption().name

    def group(self) -> Any:
        """The group of the key length: the one place that decides it.

        The scheme's public parameters for ``key_length`` (:meth:`EncryptionScheme.public_parameters`:
        for ElGamal the smallest shipped safe-prime group of at least ``k`` bits, a seeded
        generated one above 2048 bits). A backend without ciphertexts (the ideal one) needs the
        group only for the encoder's rounding pattern, so it gets the shipped group of at most
        2048 bits and never waits for a generated one.
        """
        return self.encryption().public_parameters(self.key_length, ciphertexts=self.ciphertexts)
