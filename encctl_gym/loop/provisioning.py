"""Moving the loop to another group: what the plant side sends, and the adversary's decipherer per group.

The job of group rotation (:mod:`encctl_gym.loop.rotation`) that the backends do: a backend's
``rotate_group(group)`` runs KeyGen in the new group and re-provisions the server with
``Enc(pk_0', Ecd(Phi))`` (``n m`` encryptions), and returns a :class:`ProvisioningCost`; the
episode sums them in a :class:`RotationRecord`. In the ElGamal loop the adversary's decipherer
becomes a :class:`GroupDecipherers`: a breaker meets each new group unprepared and redoes its
precomputation there.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..crypto.group import GroupParams

__all__ = ["ProvisioningCost", "RotationRecord", "GroupDecipherers", "provisioning_bytes", "rotate_elgamal_loop"]


def provisioning_bytes(group: GroupParams, encryptions: int) -> int:
    """Bytes the plant side sends to provision the server in ``group``: ``encryptions``
    ciphertexts ``(c1, c2)``, the public key ``h_0'`` and the prime ``p`` (``q = (p - 1) / 2`` and
    ``g = 4`` follow), each element in the fixed width ``ceil(bits(p) / 8)``."""
    width = (int(group.p).bit_length() + 7) // 8
    return (2 * int(encryptions) + 2) * width


@dataclass(frozen=True)
class ProvisioningCost:
    """What one move to a new group costs the plant side.

    Attributes
    ----------
    encryptions : int
        Encryptions of ``Ecd(Phi)`` under ``pk_0'`` (``n m``).
    bytes_sent : int
        :func:`provisioning_bytes` of those ciphertexts.
    keygens : int
        Key generations (1).
    seconds : float
        Wall seconds the backend took to move (KeyGen and encryptions; the ideal backend's
        quantisation table).
    """

    encryptions: int
    bytes_sent: int
    keygens: int = 1
    seconds: float = 0.0


@dataclass
class RotationRecord:
    """The rotations of one episode, summed (``EpisodeCore.rotation``)."""

    rotations: int = 0
    encryptions: int = 0
    bytes_sent: int = 0
    keygens: int = 0
    provisioning_seconds: float = 0.0

    def add(self, cost: ProvisioningCost) -> None:
        """Count one move to a new group."""
        self.rotations += 1
        self.encryptions += int(cost.encryptions)
        self.bytes_sent += int(cost.bytes_sent)
        self.keygens += int(cost.keygens)
        self.provisioning_seconds += float(cost.seconds)


class GroupDecipherers:
    """The adversary's decipherer in a rotating loop: one per group, the measured seconds summed.

    Implements :class:`~encctl_gym.attacks.decipherer.Decipherer`. On :meth:`move_to` a new group
    gets a fresh decipherer from ``make`` (with a breaker, a new
    :class:`~encctl_gym.attacks.decipherer.KeyBreaking`: its precomputation runs again, on the
    first key met in that group); the first group's decipherer is kept, with its precomputation,
    for the start of every episode.
    """

    def __init__(self, initial: Any, initial_group: GroupParams, make: Callable[[GroupParams], Any]) -> None:
        self._initial, self._initial_group, self._make = initial, initial_group, make
        self.current = initial
        self._past_seconds = 0.0
        self._past_costs: list[tuple[str, Any]] = []

    @property
    def seconds(self) -> float:
        """Wall seconds of this episode's breaks, over every group met."""
        return self._past_seconds + float(self.current.seconds)

    @property
    def costs(self) -> list[tuple[str, Any]]:
        """The cost records of this episode's breaks, over every group met (empty for the oracle)."""
        return self._past_costs + list(getattr(self.current, "costs", []))

    @property
    def precomputations(self) -> int:
        """Precomputations charged this episode (one per group met, with a breaker)."""
        return sum(1 for method, _ in self.costs if method == "precomputation")

    def start_episode(self) -> None:
        self._past_seconds, self._past_costs = 0.0, []
        self.current.start_episode()

    def move_to(self, group: GroupParams) -> None:
        """The loop moved to ``group``: keep what the last group's breaks cost, decipher with a new one."""
        self._past_seconds += float(self.current.seconds)
        self._past_costs += list(getattr(self.current, "costs", []))
        self.current = self._initial if group is self._initial_group else self._make(group)
        self.current.start_episode()

    def secret(self, pk: Any) -> int:
        return int(self.current.secret(pk))

    def observe_token(self, token: Any) -> None:
        self.current.observe_token(token)


def rotate_elgamal_loop(loop: Any, group: GroupParams) -> ProvisioningCost:
    """Move an :class:`~encctl_gym.loop.elgamal.ElGamalLoop` to ``group``: a new encoder, the
    adversary's decipherer for the group, KeyGen and ``Enc(pk_0', Ecd(Phi))`` to a new server
    (``loop.provision()``); returns what was sent, counted on the server's ciphertexts."""
    t0 = time.perf_counter()
    if not isinstance(loop.decipherer, GroupDecipherers):
        loop.decipherer = GroupDecipherers(
            loop.decipherer,
            loop.group,
            lambda g: loop.decipherer_for(
                g
            ),  # a saved precomputation belongs to the first group: a new group is precomputed afresh
        )
    loop.group = group
    loop.encoder = loop.encryption.encoder(group, float(loop.params.delta))
    loop.decipherer.move_to(group)
    loop.provision()
    encryptions = sum(len(row) for row in loop.server.ct_phi)
    return ProvisioningCost(encryptions, provisioning_bytes(group, encryptions), 1, time.perf_counter() - t0)
