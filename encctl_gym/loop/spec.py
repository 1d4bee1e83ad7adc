"""The loop as a value object: what the environment's closed loop is made of (Definitions def:ec, def:sdt).

A :class:`LoopSpec` gathers the loop's choices that :class:`~encctl_gym.envs.config.AttackParams`
carries among its fields: the backend (``crypto``), the encryption scheme
(:mod:`encctl_gym.loop.scheme`), the key length and the group it picks, the encoder's scale
``Delta`` and state bound, the adversary's key breaker and the defender. It is built from
checked values (``AttackParams.loop``) and checks nothing again; :meth:`LoopSpec.encryption` and
:meth:`LoopSpec.group` give the objects the names stand for.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .backend import loop_group
from .scheme import EncryptionScheme, make_scheme

__all__ = ["LoopSpec"]


@dataclass(frozen=True)
class LoopSpec:
    """The closed loop behind the plant's input.

    Attributes
    ----------
    crypto : str
        The backend (``"ideal"`` or ``"elgamal"``, :data:`encctl_gym.loop.BACKENDS`).
    scheme : str
        The encryption scheme, a name of :data:`encctl_gym.loop.scheme.SCHEMES`.
    key_length : int
        k, the bit length of p (eq:opt_key).
    delta : int
        The encoder's scale Delta (Definition def:ec).
    x_bound : float
        The largest state entry the encoder takes.
    u_max : float
        The actuator bound (an action of 1).
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
    breaker_precomputation : str or None
        A precomputation file the breaker loads (the index calculus), checked against the group.
    observe : str
        What the plant sends: ``"state"`` (``x``) or ``"output"`` (``y = C x + v``).
    controller : str
        The loop's controller on outputs (:data:`encctl_gym.loop.output_feedback.CONTROLLERS`).
    """

    crypto: str
    scheme: str
    key_length: int
    delta: int
    x_bound: float
    u_max: float
    breaker: str | None
    breaker_time_limit: float
    crypto_seed: int | None
    defender: Any = "fixed"
    rotate_group_every: int | None = None
    breaker_precomputation: str | None = None
    observe: str = "state"
    controller: str = "static"

    def encryption(self) -> EncryptionScheme:
        """The scheme object (:func:`~encctl_gym.loop.scheme.make_scheme`)."""
        return make_scheme(self.scheme)

    def group(self) -> Any:
        """The group of the key length with the default defender (:func:`~encctl_gym.loop.backend.loop_group`)."""
        return loop_group(self.key_length)
