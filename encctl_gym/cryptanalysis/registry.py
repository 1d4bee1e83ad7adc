"""The table of key breakers: a registry name -> breaker class (a new breaker is a row).

==================  ===========================================  ==============================
name                class                                        per key after precomputation
==================  ===========================================  ==============================
``bsgs``            :class:`~.bsgs.BabyStepGiantStep`            about sqrt(q) / 2 steps
``rho``             :class:`~.rho.PollardRho`                    about sqrt(pi q / 2) steps
``rho-multi``       :class:`~.rho.MultiLogRho`                   falls with every key broken
``pari``            :class:`~.pari.PariZnlog` (extra)            one ``znlog`` call
``index-calculus``  :class:`~.index_calculus.IndexCalculus`      one descent
``token-chain``     :class:`~.token_chain.TokenChain`            one exponentiation
==================  ===========================================  ==============================
"""

from __future__ import annotations

from typing import Any

from ..errors import ParameterError
from .base import Breaker
from .bsgs import BabyStepGiantStep
from .index_calculus import IndexCalculus
from .pari import PariZnlog
from .rho import MultiLogRho, PollardRho
from .token_chain import TokenChain

__all__ = ["BREAKERS", "get_breaker"]

#: Registry name -> breaker class.
BREAKERS: dict[str, type[Breaker]] = {
    cls.name: cls for cls in (BabyStepGiantStep, PollardRho, MultiLogRho, PariZnlog, IndexCalculus, TokenChain)
}


def get_breaker(name: str | Breaker, **kwargs: Any) -> Breaker:
    """Build the breaker registered as ``name`` with keyword arguments ``kwargs`` (a
    :class:`~.base.Breaker` instance is returned as is).

    Raises
    ------
    ParameterError
        For an unknown name (the message lists the registered ones).
    """
    if isinstance(name, Breaker):
        return name
    try:
        cls = BREAKERS[name]
    except (KeyError, TypeError):
        raise ParameterError(f"unknown breaker {name!r}; registered: {', '.join(BREAKERS)}") from None
    return cls(**kwargs)
