"""What group rotation charges the attacker: the sample deciphering time and the budget per group.

The plant side moves to a fresh safe-prime group every ``K`` attack steps (``rotate_group_every``,
:mod:`encctl_gym.loop.rotation`), so the ``N`` samples an attacker collects lie in
``ceil(N / K)`` groups (:func:`~encctl_gym.security.defenses.rotation_precomputations`). Every
cost model prices the keys of one group (:class:`~encctl_gym.security.cost_models.KeyBreakCost`:
``first`` for the first key, which carries any precomputation, ``next`` for each further key), and
rotation charges it per group:

* with independent keys (every sample under its own key, Definition def:sdt) the work is
  ``ceil(N / K) (first - next) + N next``, which under the precomputation model
  (``first = C_pre + C_key``, ``next = C_key``) is ``tau(N) Upsilon = ceil(N / K) C_pre + N C_key``
  (:func:`~encctl_gym.security.defenses.rotated_deciphering_operations`, the one home of that
  formula); under the paper's model and the generic one (``first = next``) it is ``N 2^lambda``,
  unchanged;
* when one break reveals every sample of a group (static keys; the token scheme against a
  malicious server), one key per group: ``ceil(N / K) first``.

:func:`rotated_deciphering_time` is ``tau(N)`` (seconds), :func:`rotated_affordable_samples` the
largest ``N`` with ``tau(N) <= tau_c``, exactly (rational arithmetic, as
:func:`~encctl_gym.security.deciphering.max_affordable_samples`), and
:func:`rotated_minimum_key_length` the smallest key length whose ``N*`` samples cost more than
``Upsilon tau_c`` under rotation (eq:opt_key charged per group).
"""

from __future__ import annotations

import math
from dataclasses import replace
from fractions import Fraction
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, format_value
from ..errors import ParameterError
from .cost_models import CostModel, KeyBreakCost, PaperModel
from .deciphering import KeyExposure, independent_keys, sample_deciphering_time
from .defenses import rotated_deciphering_operations, rotation_precomputations
from .exact import decimal_fraction

__all__ = [
    "check_rotation_period",
    "rotated_operations",
    "rotated_deciphering_time",
    "rotated_affordable_samples",
    "rotated_minimum_key_length",
]


def check_rotation_period(every: Any, name: str = "rotate_group_every") -> int:
    """``K`` as an int >= 1 (``ParameterError`` naming the value for 0, negatives, non-integers, bools)."""
    return check_int(name, every, minimum=1)


def rotated_operations(
    N: Any, cost: KeyBreakCost, every: Any, *, scheme: str | KeyExposure = "modified", adversary: str = "eavesdropper"
) -> float:
    """The attacker's work for ``N`` samples when the group rotates every ``every`` steps (module
    docstring), in operations: :func:`~encctl_gym.security.defenses.rotated_deciphering_operations`
    with ``C_pre = first - next`` and ``C_key = next`` for independent keys, ``ceil(N / K) first``
    otherwise. ``N = 0`` costs nothing."""
    N = check_int("N", N, minimum=0)
    K = check_rotation_period(every)
    if N == 0:
        return 0.0
    if independent_keys(scheme, adversary):
        return rotated_deciphering_operations(N, K, float(cost.first - cost.next), float(cost.next))
    return rotation_precomputations(N, K) * float(cost.first)


def rotated_deciphering_time(
    N: Any, cost: KeyBreakCost, upsilon: Any, every: Any, *, scheme: str | KeyExposure = "modified", adversary: str = "eavesdropper"
) -> float | np.ndarray:
    """``tau(N)`` in seconds under rotation every ``every`` steps (module docstring).

    A scalar ``N`` is :func:`rotated_operations` over ``Upsilon``; an array is the same sum in
    float64 (``ceil(N / K) t_pre + N t_key``; the tests check it against the scalar form at every
    ``N``). Where every key costs the same (``first == next``: the paper's model, the generic one)
    and keys are independent, rotation changes nothing and this is
    :func:`~encctl_gym.security.deciphering.sample_deciphering_time`, bit for bit.
    """
    K = check_rotation_period(every)
    independent = independent_keys(scheme, adversary)
    if independent and cost.first == cost.next:
        return sample_deciphering_time(N, cost, upsilon, scheme=scheme, adversary=adversary)
    ups = decimal_fraction("upsilon", upsilon)
    if np.ndim(N) == 0:
        ops = rotated_operations(N.item() if isinstance(N, np.ndarray) else N, cost, K, scheme=scheme, adversary=adversary)
        return ops / float(ups)
    arr = as_finite_array("N", N)
    if not np.all(arr == np.round(arr)) or np.any(arr < 0):
        raise ParameterError(f"N must contain integers >= 0, got {format_value(np.asarray(N))}")
    groups = np.ceil(arr / K)
    with np.errstate(over="ignore", invalid="ignore"):
        if independent:
            return groups * float((cost.first - cost.next) / ups) + arr * float(cost.next / ups)
        return groups * float(cost.first / ups)


def rotated_affordable_samples(
    tau_c: Any, cost: KeyBreakCost, upsilon: Any, every: Any, *, scheme: str | KeyExposure = "modified", adversary: str = "eavesdropper"
) -> int:
    """The largest ``N`` with ``tau(N) <= tau_c`` under rotation every ``K = every`` steps, exactly.

    With ``B = Upsilon tau_c``: a full group of ``K`` independent keys costs ``first + (K - 1) next``,
    so ``q = floor(B / (first + (K - 1) next))`` groups fit, and the rest ``r`` of the budget buys
    ``0`` further samples if ``r < first``, else ``1 + floor((r - first) / next)`` (fewer than ``K``).
    When one break reveals a whole group, ``floor(B / first)`` groups of ``K`` samples. Finite in
    both cases: rotation bounds even the attack that one break would otherwise finish.
    """
    K = check_rotation_period(every)
    budget = decimal_fraction("upsilon", upsilon) * decimal_fraction("tau_c", tau_c)
    first, nxt = Fraction(cost.first), Fraction(cost.next)
    if not independent_keys(scheme, adversary):
        return math.floor(budget / first) * K
    block = first + (K - 1) * nxt
    q = math.floor(budget / block)
    rest = budget - q * block
    r = 0 if rest < first else 1 + math.floor((rest - first) / nxt)
    return q * K + r


class _GroupCharged(CostModel):
    """``base`` with the work of ``groups`` groups carried by the first key, so that the shared
    key-length search of :class:`CostModel` sees, exactly (rational), ``operations(keys) =
    groups (first - next) + keys next`` (independent keys) or ``operations(1) = groups first``
    (one break per group, ``whole_groups``)."""

    def __init__(self, base: CostModel, groups: int, whole_groups: bool) -> None:
        self.base, self.groups, self.whole_groups = base, groups, whole_groups
        self.name, self.key_length_range = base.name, base.key_length_range

    def break_cost(self, key_length: int) -> KeyBreakCost:
        c = self.base.break_cost(key_length)
        first = self.groups * c.first if self.whole_groups else c.first + (self.groups - 1) * (c.first - c.next)
        return replace(c, first=first)

    def describe(self) -> dict[str, Any]:
        return {**self.base.describe(), "groups": self.groups}


def rotated_minimum_key_length(
    model: CostModel, N_star: Any, every: Any, budget: Fraction, *, scheme: str | KeyExposure = "modified", adversary: str = "eavesdropper"
) -> int:
    """The smallest key length ``k`` whose ``N*`` samples, in groups of ``K = every``, cost more than
    ``budget`` (``Upsilon tau_c``) operations under ``model`` (eq:opt_key with the work of the
    module docstring).

    The paper's model charges every key alike, so rotation leaves its design with independent
    keys (the integer ``lambda*`` of Theorem thm:opt_sec, then eq:opt_key) unchanged; every other
    model is searched with its first key carrying the ``ceil(N* / K) - 1`` further
    precomputations (exact, in fractions). With one break per group (static keys; the token
    scheme against a malicious server) the ``ceil(N* / K)`` groups cost one first key each.

    Raises
    ------
    ModelRangeError
        If the answer lies outside the model's key-length range.
    """
    N_star = check_int("N_star", N_star, minimum=1)
    groups = rotation_precomputations(N_star, check_rotation_period(every))
    whole = not independent_keys(scheme, adversary)
    if isinstance(model, PaperModel):  # every key 2^lambda: the paper's two steps for the keys to break
        return model.minimum_key_length(groups if whole else N_star, budget)
    return _GroupCharged(model, groups, whole).minimum_key_length(1 if whole else N_star, budget)
