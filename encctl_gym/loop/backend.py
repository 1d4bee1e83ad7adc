"""The interface every closed-loop backend implements, and what the backends share.

A backend is the closed loop behind the plant's input, one sampling period at a time
(Definition def:adversary from the plant's side): :meth:`LoopBackend.collect_state` (the plant
encrypts ``x_t``; the adversary, having paid for it, reads ``Dcd(Ecd(x_t))``), then
:meth:`LoopBackend.control` (normal operation: the encrypted controller of eq:ec computes
``u_t = Phi x_t``) or :meth:`LoopBackend.inject` (attack: the adversary forges the input
ciphertexts and the plant decrypts them), then :meth:`LoopBackend.tick` (key update). Backends
are picked by name (``crypto="ideal"`` or ``"elgamal"``, :data:`encctl_gym.loop.BACKENDS`).

A backend whose arithmetic the environment's compiled step can run itself exposes it as
:attr:`LoopBackend.quantization` (a :class:`~encctl_gym.loop.quantize.Quantization`); the
others set it to ``None`` and are called period by period.
"""

from __future__ import annotations

import math
from typing import Protocol, runtime_checkable

import numpy as np
import scipy.linalg

from .._validation import format_value
from ..errors import ResourceLimitError
from .quantize import Quantization
from .spec import LoopSpec

__all__ = ["LoopBackend", "lqr_gain", "table_limit"]


@runtime_checkable
class LoopBackend(Protocol):
    """The closed loop behind the plant's input (one backend of ``crypto=...``).

    Arrays are batched over copies: states ``(K, n)``, inputs ``(K, m)``.

    Attributes
    ----------
    batched : bool
        True if the backend steps any number of copies at once (else exactly one).
    quantization : Quantization or None
        The fixed-point arithmetic for the environment's compiled fast path, or ``None``.
    deciphering_seconds : float
        The measured clock of ``deciphering_clock="measured"``.
    """

    batched: bool
    quantization: Quantization | None

    @property
    def deciphering_seconds(self) -> float:
        """Seconds the adversary's real key breaks took this episode (0 where the break is simulated)."""

    def start_episode(self) -> None:
        """Prepare a new episode (fresh keys and ciphertexts where there are any)."""

    def collect_state(self, x: np.ndarray) -> np.ndarray:
        """What deciphering the state ciphertexts of ``x`` reveals: ``Dcd(Ecd(x))``, shape (K, n)."""

    def control(self, x: np.ndarray) -> np.ndarray:
        """One period of normal operation (encrypted controller of eq:ec, key update): ``u``, shape (K, m)."""

    def inject(self, a: np.ndarray) -> np.ndarray:
        """The input the plant applies when the adversary forges ``a`` (Definition def:adversary), shape (K, m)."""

    def tick(self) -> None:
        """End of the period: the key update (none for static keys)."""


def lqr_gain(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Discrete-time LQR gain ``K`` (``u = -K x``, Q = I, R = I) for the warm-up controller."""
    P = scipy.linalg.solve_discrete_are(A, B, np.eye(A.shape[0]), np.eye(B.shape[1]))
    return np.linalg.solve(np.eye(B.shape[1]) + B.T @ P @ B, B.T @ P @ A)


def table_limit(params: LoopSpec, Phi: np.ndarray) -> int:
    """Largest ``|round(Delta v)|`` the loop must quantise: states, inputs, controller entries.

    Raises
    ------
    ResourceLimitError
        If ``Delta * max(x_bound, u_max, |Phi|)`` is not a finite float (nothing could quantise it).
    """
    span = max(params.x_bound, params.u_max, float(np.abs(Phi).max()) if Phi.size else 0.0, 1.0)
    scaled = float(params.delta) * span
    if not math.isfinite(scaled):
        raise ResourceLimitError(
            f"the loop would quantise values up to Delta * max(x_bound, u_max, |Phi|) = {format_value(params.delta)} * "
            f"{format_value(span)}, beyond the float range; use a smaller delta, x_bound or action_scale"
        )
    return int(math.ceil(scaled)) + 1
