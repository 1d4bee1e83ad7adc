"""The table of factoring breakers (Paillier keys): a registry name -> factorer class.

=================  ================================================  ==========================
name               class                                             per modulus (balanced, k bits)
=================  ================================================  ==========================
``rho-factor``     :class:`~.pollard_factor.PollardRhoFactorer`      about 2^(k/4) steps
``p-1``            :class:`~.pollard_factor.PollardPMinusOne`        fixed bounds; needs smooth p-1
``ecm``            :class:`~.ecm.EllipticCurveMethod`                L_p[1/2, sqrt 2], p = 2^(k/2)
``pari-factor``    :class:`~.pari_factor.PariFactor` (extra)         PARI's MPQS, L_n[1/2, 1]
=================  ================================================  ==========================
"""

from __future__ import annotations

from typing import Any

from ..registry import Registry
from .ecm import EllipticCurveMethod
from .factoring import Factorer
from .pari_factor import PariFactor
from .pollard_factor import PollardPMinusOne, PollardRhoFactorer

__all__ = ["FACTORERS", "get_factorer"]

#: Registry name -> factorer class (:class:`~encctl_gym.registry.Registry`).
FACTORERS: Registry[type[Factorer]] = Registry(
    "factoring breaker", [PollardRhoFactorer, PollardPMinusOne, EllipticCurveMethod, PariFactor]
)


def get_factorer(name: str | Factorer, **kwargs: Any) -> Factorer:
    """Build the factorer registered as ``name`` (an instance is returned as is).

    Raises
    ------
    ParameterError
        For an unknown name (the message lists the registered ones) or an unknown option.
    """
    if isinstance(name, Factorer):
        return name
    return FACTORERS.build(name, **kwargs)
