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

from .._validation import format_value
from ..errors import ParameterError
from ..registry import Registry
from .base import Breaker
from .bsgs import BabyStepGiantStep
from .index_calculus import IndexCalculus
from .pari import PariZnlog
from .rho import MultiLogRho, PollardRho
from .token_chain import TokenChain

__all__ = ["BREAKERS", "get_breaker"]

#: Registry name -> breaker class (:class:`~encctl_gym.registry.Registry`).
BREAKERS: Registry[type[Breaker]] = Registry(
    "breaker", [BabyStepGiantStep, PollardRho, MultiLogRho, PariZnlog, IndexCalculus, TokenChain]
)


def get_breaker(name: str | Breaker, **kwargs: Any) -> Breaker:
    """Build the breaker registered as ``name`` with keyword arguments ``kwargs`` (a
    :class:`~.base.Breaker` instance is returned as is, and takes no ``kwargs``).

    A breaker that wraps another (:attr:`~.base.Breaker.WRAPS_OPTION`, the token chain's
    ``inner``) may be given it by name: that one is built first, with ``max_bits`` and ``rng``.

    Raises
    ------
    ParameterError
        For an unknown name (the message lists the registered ones), an option the breaker
        does not have (the message lists its options), or options given with an instance.
    """
    if isinstance(name, Breaker):
        if kwargs:
            raise ParameterError(
                f"options {', '.join(format_value(k) for k in kwargs)} apply to a breaker built by name; "
                f"set them on the instance {format_value(name)} instead"
            )
        return name
    cls = BREAKERS.lookup(name)
    BREAKERS.check_options(name, kwargs)
    wraps = cls.WRAPS_OPTION
    if wraps is not None and isinstance(kwargs.get(wraps), str):
        inner = kwargs[wraps]
        if inner == cls.name:
            raise ParameterError(f"the breaker {cls.name!r} cannot wrap itself")
        inner_kwargs = {k: kwargs.pop(k) for k in ("max_bits",) if k in kwargs}
        kwargs[wraps] = get_breaker(inner, **inner_kwargs, rng=kwargs.get("rng"))
    return cls(**kwargs)
