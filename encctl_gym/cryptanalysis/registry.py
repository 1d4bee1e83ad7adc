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

import inspect
from typing import Any

from .._validation import format_value
from ..errors import ParameterError
from .base import Breaker
from .bsgs import BabyStepGiantStep
from .index_calculus import IndexCalculus
from .pari import PariZnlog
from .rho import MultiLogRho, PollardRho
from .token_chain import TokenChain

__all__ = ["BREAKERS", "get_breaker", "breaker_options"]

#: Registry name -> breaker class.
BREAKERS: dict[str, type[Breaker]] = {
    cls.name: cls for cls in (BabyStepGiantStep, PollardRho, MultiLogRho, PariZnlog, IndexCalculus, TokenChain)
}


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
    try:
        cls = BREAKERS[name]
    except (KeyError, TypeError):
        raise ParameterError(f"unknown breaker {format_value(name)}; registered: {', '.join(BREAKERS)}") from None
    options = breaker_options(cls)
    unknown = [k for k in kwargs if k not in options]
    if unknown:
        raise ParameterError(
            f"breaker {cls.name!r} has no option {', '.join(format_value(k) for k in unknown)}; its options: {', '.join(options)}"
        )
    wraps = cls.WRAPS_OPTION
    if wraps is not None and isinstance(kwargs.get(wraps), str):
        inner = kwargs[wraps]
        if inner == cls.name:
            raise ParameterError(f"the breaker {cls.name!r} cannot wrap itself")
        inner_kwargs = {k: kwargs.pop(k) for k in ("max_bits",) if k in kwargs}
        kwargs[wraps] = get_breaker(inner, **inner_kwargs, rng=kwargs.get("rng"))
    return cls(**kwargs)


def breaker_options(cls: type[Breaker]) -> tuple[str, ...]:
    """The keyword options of a breaker class (the parameters of its constructor)."""
    params = list(inspect.signature(cls.__init__).parameters.values())[1:]
    return tuple(p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY))
