"""The malicious server's token chain (Proposition prop:vulnerability), as a breaker strategy.

In the conventional token scheme of Example ex:dyn_elgamal the controller server receives every
update token ``sigma_t = (h_t, d_t)`` with ``d_t = s_{t+1} - s_t mod q``. Once it has broken one
key ``s_t`` with any breaker, it derives ``s_{t+1} = s_t + d_t mod q`` and so every later key,
at the cost of one exponentiation each (the check g^s = h that every breaker performs). So the
deciphering time of N samples is that of *one* key, whatever N.

:class:`TokenChain` (registry name ``"token-chain"``) wraps another breaker: keys that a known
key and a token reach are derived, any other key is broken by the inner breaker. Tokens are
objects with attributes ``h`` and ``d`` (``crypto.dyn_elgamal.UpdateToken``) or pairs
``(h, d)``, given to the precomputation with :meth:`TokenChainState.add_tokens` (or to
:func:`~encctl_gym.cryptanalysis.sequence.break_sequence`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any, ClassVar

import gmpy2

from .._validation import check_int, format_value
from ..crypto.arith import RandomSource, RngLike, format_int
from ..crypto.group import GroupParams
from ..errors import KeyMismatchError, ParameterError
from .base import Breaker, Deadline, Precomputation, RecoveredKey, as_list, check_element
from .index_calculus import IndexCalculus

__all__ = ["TokenChain", "TokenChainState", "as_token"]


def as_token(group: GroupParams, token: Any) -> tuple[int, int]:
    """``(h, d)`` of an update token (an object with ``h`` and ``d``, or a pair), checked.

    Raises
    ------
    KeyMismatchError
        If ``h`` is not in G of the group or ``d`` is outside ``[0, q)``.
    """
    if hasattr(token, "h") and hasattr(token, "d"):
        h, d = token.h, token.d
    else:
        try:
            h, d = token
        except (TypeError, ValueError) as exc:
            raise ParameterError(
                f"an update token must have fields h and d, or be a pair (h, d); got {format_value(token)}"
            ) from exc
    h = check_element(group, h)
    d = check_int("token d", d)
    if not 0 <= d < group.q:
        raise KeyMismatchError(f"update token d is outside [0, q) for this group (token of h = {format_int(h)})")
    return h, d


class TokenChainState(Precomputation):
    """The inner breaker's precomputation, the tokens seen and the keys known so far.

    Attributes
    ----------
    inner : Precomputation
        The wrapped breaker's precomputation.
    tokens : dict
        ``h_t -> d_t``.
    known : dict
        ``h -> s`` of every key broken or derived.
    reachable : dict
        ``h_{t+1} -> s_{t+1}`` for keys that a known key and its token determine.
    """

    def __init__(self, inner: Precomputation, rng: RandomSource | None) -> None:
        super().__init__(TokenChain.name, inner.group, rng)
        self.inner = inner
        self.tokens: dict[int, int] = {}
        self.known: dict[int, int] = {}
        self.reachable: dict[int, int] = {}

    def add_tokens(self, tokens: Iterable[Any]) -> None:
        """Record update tokens ``sigma_t = (h_t, d_t)`` (any order).

        Raises
        ------
        ParameterError
            If ``tokens`` is not an iterable of tokens.
        """
        for token in as_list("tokens", tokens, "update tokens"):
            h, d = as_token(self.group, token)
            self.tokens[h] = d
            if h in self.known:
                self._extend(h, self.known[h])

    def _extend(self, h: int, s: int) -> None:
        # Proposition prop:vulnerability: s_{t+1} = s_t + d_t, h_{t+1} = h_t g^(d_t).
        d = self.tokens[h]
        grp = self.group
        h_next = int(gmpy2.mpz(h) * gmpy2.powmod(grp.g, d, grp.p) % grp.p)
        self.reachable[h_next] = (s + d) % grp.q

    def break_key(self, h: Any, *, time_limit: float | None = None, rng: RngLike = None) -> RecoveredKey:
        key = super().break_key(h, time_limit=time_limit, rng=rng)
        self.known[key.h] = key.s
        if key.h in self.tokens:
            self._extend(key.h, key.s)
        return key

    def _solve(self, h: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int], str]:
        if h in self.known:
            return self.known[h], {"exponentiations": 0}, "known"
        if h in self.reachable:
            return self.reachable[h], {"exponentiations": 1}, "token"
        limit = None if deadline.limit is None else max(deadline.remaining, 1e-3)
        key = self.inner.break_key(h, time_limit=limit, rng=src)
        return key.s, key.cost.operations, key.method


class TokenChain(Breaker):
    """Break one key with an inner breaker, derive the later ones from the update tokens.

    Parameters
    ----------
    inner : Breaker, optional
        The breaker of the first key (default: :class:`~.index_calculus.IndexCalculus` built
        with ``max_bits`` and ``rng``). By name through the registry:
        ``get_breaker("token-chain", inner="rho")``.
    max_bits : int, optional
        Passed to the default inner breaker (its limit is the limit); refused with an
        instance, whose own ``max_bits`` holds.
    rng
        See :class:`~encctl_gym.cryptanalysis.base.Breaker`.
    """

    name: ClassVar[str] = "token-chain"
    DEFAULT_MAX_BITS: ClassVar[int] = 2048
    WRAPS_OPTION: ClassVar[str | None] = "inner"

    def __init__(self, inner: Breaker | None = None, *, max_bits: int | None = None, rng: RngLike = None) -> None:
        if isinstance(inner, Breaker):
            if max_bits is not None:
                raise ParameterError(
                    f"max_bits applies to an inner breaker built by name; set it on the instance {format_value(inner)} instead"
                )
            if isinstance(inner, TokenChain):
                raise ParameterError("the token chain cannot wrap itself")
            self.inner = inner
        elif inner is None:
            self.inner = IndexCalculus(max_bits=max_bits, rng=rng)
        else:
            raise ParameterError(
                f"inner must be a Breaker instance, got {format_value(inner)}; "
                "to name it, build the chain with get_breaker('token-chain', inner=NAME)"
            )
        super().__init__(max_bits=self.inner.max_bits, rng=rng)

    def __repr__(self) -> str:
        return f"TokenChain(inner={self.inner!r})"

    def expected_seconds(self, group: GroupParams) -> tuple[float, float]:
        """The inner breaker's first key; each later key one exponentiation (about 1e-5 s)."""
        first, _ = self.inner.expected_seconds(group)
        return first, 1e-5

    def check_feasible(self, group: GroupParams) -> None:
        """The inner breaker's limits (it must break the first key)."""
        self.inner.check_feasible(group)

    def _precompute(self, group: GroupParams, deadline: Deadline) -> tuple[TokenChainState, Mapping[str, int]]:
        inner = self.inner.precompute(group, time_limit=deadline.limit, progress=deadline.progress)
        return TokenChainState(inner, self.rng), dict(inner.cost.operations)
