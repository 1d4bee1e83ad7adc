"""The attacker's deciphering clock in the game: charged per group the defender moves to.

The single environment prices a rotation schedule fixed in advance (``rotate_group_every``:
:func:`~encctl_gym.security.rotation.rotated_affordable_samples` sets the horizon when it is
made). In the game the defender rotates when it decides to, so the episode's horizon (one group)
does not see its rotations: :class:`GroupClock` charges them as they happen. Every cost model
prices the keys of one group (:class:`~encctl_gym.security.cost_models.KeyBreakCost`: ``first``
for its first key, which carries any precomputation, ``next`` for each further key), so ``N``
samples in ``G`` groups cost (Definition def:sdt charged per group, as
:mod:`encctl_gym.security.rotation` charges ``ceil(N / K)`` groups)

* ``G (first - next) + N next`` operations with independent keys (under the precomputation model
  ``G C_pre + N C_key``; under the paper's model, ``first = next``, rotation changes nothing);
* ``G first`` when one break reveals every sample of a group.

A sample is collected only if its cost, with the group it lies in, stays within
``Upsilon tau_c`` (exact rational arithmetic, as the horizon's); the game ends the attack at the
step whose sample the budget cannot pay (terminated, as a deciphering budget ends it). Under the
measured clock (``deciphering_clock="measured"``) the breaker's own seconds already pay each
group's precomputation, and the clock is off; so it is where every key costs the same (the
paper's model with independent keys).
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

from ..security.exact import decimal_fraction

__all__ = ["GroupClock"]


class GroupClock:
    """Deciphering work of the samples collected, charged per group (module docstring).

    Parameters
    ----------
    params : AttackParams
        The game's resolved parameters (cost model, ``upsilon``, ``tau_c``, the key exposure).

    Attributes
    ----------
    active : bool
        False under the measured clock (the breaker charges the groups itself) and where every
        key costs the same with independent keys (rotation changes nothing: the episode's own
        table is exact).
    samples, groups : int
        Samples collected this episode and the groups they lie in.
    """

    def __init__(self, params: Any) -> None:
        self.first, self.next = Fraction(params.cost.first), Fraction(params.cost.next)
        self.independent = bool(params.independent_keys)
        # a group costs more than its keys only with a precomputation, or when one break reveals it
        self.active = params.deciphering_clock == "model" and (self.first != self.next or not self.independent)
        self.upsilon = decimal_fraction("upsilon", params.upsilon)
        self.budget = self.upsilon * decimal_fraction("tau_c", params.tau_c)
        self.reset(1)

    def reset(self, samples: int) -> None:
        """Start an episode whose first ``samples`` samples lie in the first group."""
        self.samples, self.groups = int(samples), 1
        self.pending = False  # the loop moved to a group no sample lies in yet

    def work(self, samples: int, groups: int) -> Fraction:
        """Operations to decipher ``samples`` samples lying in ``groups`` groups."""
        if samples == 0:
            return Fraction(0)
        if self.independent:
            return groups * (self.first - self.next) + samples * self.next
        return groups * self.first

    @property
    def rotated(self) -> bool:
        """The loop has left the first group this episode (before that the episode's own
        deciphering-time table is exact and the clock leaves it alone)."""
        return self.groups > 1 or self.pending

    def affords(self, new_group: bool) -> bool:
        """Whether the budget pays for one more sample, lying in a new group if ``new_group``
        (or if the loop moved since the last sample)."""
        fresh = new_group or self.pending
        return self.work(self.samples + 1, self.groups + int(fresh)) <= self.budget

    def advance(self, collected: int, rotated: bool) -> None:
        """After a step: ``collected`` samples in all, the loop moved before its period if
        ``rotated`` (the step's sample, if any, lies in the new group)."""
        self.pending = self.pending or rotated
        if collected > self.samples and self.pending:
            self.groups += 1
            self.pending = False
        self.samples = int(collected)

    @property
    def seconds(self) -> float:
        """tau of the samples collected, charged per group (seconds)."""
        return float(self.work(self.samples, self.groups) / self.upsilon)

    @property
    def fraction(self) -> float:
        """The fraction of the budget ``Upsilon tau_c`` spent."""
        return float(self.work(self.samples, self.groups) / self.budget)
