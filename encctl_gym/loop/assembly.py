"""The defender of a loop: the policy its ``LoopSpec`` names, with the configured levers added.

The configuration names a policy (``defender``) and may add levers beside it: audits at a rate
(``audit_probability``), input noise (``defense_noise_sigma2``) and group rotation every K steps
(``rotate_group_every``). :func:`defender_for` assembles them, in one place, from the loop's
value object (:class:`~encctl_gym.loop.spec.LoopSpec`).
"""

from __future__ import annotations

from .._validation import format_value
from ..errors import ParameterError
from .defender import DefenderPolicy, make_defender
from .defenses import AuditDefender, CombinedDefender, NoiseDefender
from .rotation import RotatingDefender
from .spec import LoopSpec

__all__ = ["defender_for"]


def defender_for(params: LoopSpec) -> DefenderPolicy:
    """The defender of an environment's parameters: the policy ``params.defender`` names, with an
    :class:`~encctl_gym.loop.defenses.AuditDefender` for ``params.audit_probability`` and a
    :class:`~encctl_gym.loop.defenses.NoiseDefender` for ``params.defense_noise_sigma2`` added
    (a :class:`~encctl_gym.loop.defenses.CombinedDefender` when there is more than one), wrapped in
    a :class:`~encctl_gym.loop.rotation.RotatingDefender` when ``params.rotate_group_every`` is set.

    Raises
    ------
    ParameterError
        For ``rotate_group_every`` together with a defender that rotates already.
    """
    policy: DefenderPolicy = make_defender(params.defender)
    levers: list[DefenderPolicy] = []
    audit_p = params.audit_probability
    if audit_p is not None:
        levers.append(AuditDefender(rate=audit_p))
    noise_d2 = params.defense_noise_sigma2
    if noise_d2 is not None:
        levers.append(NoiseDefender(sigma_d2=noise_d2))
    if levers:
        keep = [] if policy.name == "fixed" else [policy]
        policy = levers[0] if len(keep + levers) == 1 else CombinedDefender(keep + levers)
    every = params.rotate_group_every
    if every is None:
        return policy
    if policy.rotates:
        raise ParameterError(
            f"rotate_group_every = {format_value(every)} and the defender {format_value(policy)}, which rotates "
            "already: give one of them"
        )
    return RotatingDefender(every, inner=policy)
