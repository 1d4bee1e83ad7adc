"""How the adversary reads the state ciphertexts it has paid for (Definition def:sdt, in the loop).

The environment charges the adversary the deciphering time of every sample it collects
(Definition def:sdt, under the configured cost model). A *decipherer* is what then turns the
period's state ciphertexts ``ct_x_t`` (encrypted under ``pk_t = g^{s_t}``) into numbers, by
supplying the exponent ``s_t`` to decrypt them with:

* :class:`KeyOracle` (the environment's default, ``breaker=None``): the break is simulated and
  the plant's key of the period is read; the charged time stands for the work;
* :class:`KeyBreaking` (``breaker="index-calculus"`` and the other names of
  :data:`encctl_gym.cryptanalysis.BREAKERS`): ``pk_t`` is broken for real and the ciphertexts
  are decrypted with the recovered exponent only; nothing of the plant's is read. The breaker's
  precomputation runs once per group, on the first key met, and is kept for every later key
  and episode (dynamic-key ElGamal never changes the group); keys already recovered in an
  episode (the static scheme's one key) are not broken again; the malicious server of the token
  scheme derives every later key from the tokens it receives (Proposition prop:vulnerability),
  so its breaker is wrapped in the token chain.

:attr:`Decipherer.seconds` is the wall time the episode's breaks took on this machine (0 for the
oracle): the environment's ``deciphering_clock="measured"`` charges it instead of the model's
``tau(N)``. A precomputation is measured once and charged to every episode, as to an attack
from scratch.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

from ..errors import ParameterError

__all__ = [
    "BreakableScheme",
    "Decipherer",
    "KeyOracle",
    "KeyBreaking",
    "KeyFactoring",
    "make_decipherer",
    "DEFAULT_BREAKER_TIME_LIMIT",
]


@runtime_checkable
class BreakableScheme(Protocol):
    """What the decipherer asks of the loop's scheme (the part of
    :class:`encctl_gym.loop.scheme.EncryptionScheme` it uses; the loop's layer stands above this one)."""

    def breaker_for(self, breaker: Any, adversary: str, rng: Any) -> Any:
        """The breaker that reads this scheme's keys for ``adversary``."""
        ...


#: Seconds a breaker may take for its precomputation and for each key, by default: a breaker
#: whose expected first-key time is longer is refused before any work.
DEFAULT_BREAKER_TIME_LIMIT = 60.0


@runtime_checkable
class Decipherer(Protocol):
    """Supplies the exponent that decrypts the state ciphertexts of the current period.

    Attributes
    ----------
    seconds : float
        Wall seconds the breaks of the current episode took (0 where nothing is broken).
    """

    seconds: float

    def start_episode(self) -> None:
        """A new episode: fresh keys, nothing recovered yet, ``seconds = 0``."""

    def secret(self, pk: Any) -> Any:
        """The secret of the period's public key ``pk`` (ElGamal: the exponent ``s_t``, ``pk.h = g^{s_t}``)."""

    def observe_token(self, token: Any) -> None:
        """An update token the adversary sees (the token scheme's controller server)."""


class KeyOracle:
    """The simulated break: the plant's secret key of the period (a privileged read).

    Parameters
    ----------
    read_key : callable
        ``read_key(pk)`` returns the plant's secret of the public key ``pk`` (the scheme's
        ``oracle_secret``: for ElGamal the exponent ``s_t`` of the period's key, ``s_0`` of ``pk_0``).
    """

    def __init__(self, read_key: Callable[[Any], Any]) -> None:
        self._read_key = read_key
        self.seconds = 0.0

    def start_episode(self) -> None:
        self.seconds = 0.0

    def secret(self, pk: Any) -> Any:
        return self._read_key(pk)

    def observe_token(self, token: Any) -> None:
        return None


class KeyBreaking:
    """Breaks every period's public key with a breaker of :mod:`encctl_gym.cryptanalysis`.

    Parameters
    ----------
    breaker : str
        A name of :data:`encctl_gym.cryptanalysis.BREAKERS`.
    group : GroupParams
        The loop's group (every key is in it).
    scheme : EncryptionScheme
        The loop's scheme (:class:`encctl_gym.loop.scheme.EncryptionScheme`): its
        ``breaker_for(breaker, adversary, rng)`` wraps the breaker as the adversary uses it (the
        token scheme against a malicious server: the token chain, which breaks one key and
        derives the others).
    adversary : str
        The adversary (``"eavesdropper"`` or ``"server"``).
    time_limit : float
        Seconds allowed for the precomputation and for each key. A breaker whose expected
        first-key time exceeds it is refused here; a break that overruns it raises
        :class:`~encctl_gym.errors.BreakerTimeoutError`.
    rng
        The breaker's random source (its walks, its randomised descents).
    precomputation : str, optional
        A precomputation file the breaker loads (``breaker_precomputation``; the index calculus),
        checked against ``group`` here.

    Raises
    ------
    BreakerLimitError
        The group is larger than the breaker's ``max_bits``, or its expected time exceeds
        ``time_limit`` (the message gives both).
    OptionalDependencyError
        ``breaker="pari"`` without the ``cryptanalysis`` extra.
    """

    def __init__(
        self,
        breaker: str,
        group: Any,
        *,
        scheme: BreakableScheme,
        adversary: str,
        time_limit: float = DEFAULT_BREAKER_TIME_LIMIT,
        rng: Any = None,
        precomputation: Any = None,
    ) -> None:
        from ..cryptanalysis import TokenChain, get_breaker

        found = get_breaker(breaker, rng=rng, **({} if precomputation is None else {"precomputation": precomputation}))
        b = scheme.breaker_for(found, adversary, rng)
        b.check_time(
            group,
            time_limit,
            limit_name="breaker_time_limit",
            advice="use a shorter key_length, another breaker or a longer breaker_time_limit",
        )
        self.breaker = b
        self.group = group
        self.time_limit = float(time_limit)
        self._rng = rng
        self._token_chain = isinstance(b, TokenChain)
        self._pre: Any = None  # the precomputation, once per group
        self._state: Any = None  # this episode's: the precomputation, or a fresh token chain over it
        self._known: dict[int, int] = {}
        self._tokens: list[Any] = []  # tokens seen before this episode's first break
        #: the cost records of this episode: the precomputation (if it was charged) and every key broken
        self.costs: list[tuple[str, Any]] = []
        self.seconds = 0.0

    def start_episode(self) -> None:
        self._state = None
        self._known = {}
        self._tokens = []
        self.costs = []
        self.seconds = 0.0

    def _episode_state(self) -> Any:
        if self._pre is None:
            self._pre = self.breaker.precompute(self.group, time_limit=self.time_limit)
        if self._state is None:
            self.costs.append(("precomputation", self._pre.cost))
            self.seconds += self._pre.cost.seconds
            if self._token_chain:
                from ..cryptanalysis.token_chain import TokenChainState

                self._state = TokenChainState(self._pre.inner, self._rng)
                self._state.add_tokens(self._tokens)
                self._tokens = []
            else:
                self._state = self._pre
        return self._state

    def secret(self, pk: Any) -> int:
        h = int(pk.h)
        if h in self._known:
            return self._known[h]
        state = self._episode_state()
        key = state.break_key(h, time_limit=self.time_limit)
        self.costs.append((key.method, key.cost))
        self.seconds += key.cost.seconds
        self._known[h] = key.s
        return key.s

    def observe_token(self, token: Any) -> None:
        if not self._token_chain:
            return
        if self._state is None:
            self._tokens.append(token)
        else:
            self._state.add_tokens([token])


class KeyFactoring:
    """The adversary that factors each Paillier modulus it meets (:mod:`encctl_gym.cryptanalysis.factoring`):
    a new key is a new modulus, so nothing is precomputed or shared between keys; each recovered
    key is checked by decrypting (:func:`~encctl_gym.cryptanalysis.paillier_keys.break_paillier_key`).

    Raises
    ------
    BreakerLimitError
        At construction, if one modulus of the parameters' size would take longer than ``time_limit``.
    """

    def __init__(self, factorer: Any, params: Any, *, time_limit: float = DEFAULT_BREAKER_TIME_LIMIT, rng: Any = None) -> None:
        factorer.check_time(
            int(params.key_length),
            time_limit,
            limit_name="breaker_time_limit",
            advice="use a shorter key_length, another breaker or a longer breaker_time_limit",
        )
        self.breaker, self.group, self.time_limit, self._rng = factorer, params, float(time_limit), rng
        self._known: dict[int, Any] = {}
        self.costs: list[tuple[str, Any]] = []
        self.seconds = 0.0

    def start_episode(self) -> None:
        self._known, self.costs, self.seconds = {}, [], 0.0

    def secret(self, pk: Any) -> Any:
        from ..cryptanalysis.paillier_keys import break_paillier_key

        n = int(pk.n)
        if n not in self._known:
            key = break_paillier_key(self.breaker, pk, time_limit=self.time_limit, rng=self._rng)
            self.costs.append((key.factorization.method, key.factorization.cost))
            self.seconds += key.seconds
            self._known[n] = key.secret
        return self._known[n]

    def observe_token(self, token: Any) -> None:
        return None  # Paillier has no update token


def make_decipherer(
    breaker: str | None,
    group: Any,
    read_key: Callable[[Any], Any],
    *,
    scheme: BreakableScheme,
    adversary: str,
    time_limit: float = DEFAULT_BREAKER_TIME_LIMIT,
    rng: Any = None,
    precomputation: Any = None,
) -> Decipherer:
    """The decipherer of a loop: :class:`KeyBreaking` with a ``breaker`` name, else the
    :class:`KeyOracle` over ``read_key`` (the scheme's ``oracle_secret`` of the plant).
    ``precomputation``: a file the breaker loads (``breaker_precomputation``).

    Raises
    ------
    ParameterError
        For a breaker that is not a name.
    """
    if breaker is None:
        return KeyOracle(read_key)
    if not isinstance(breaker, str):
        raise ParameterError(f"breaker must be a breaker name, got {breaker!r}")
    from ..cryptanalysis.factoring_registry import FACTORERS

    if breaker in FACTORERS:
        from ..cryptanalysis.factoring import Factorer

        factorer = scheme.breaker_for(breaker, adversary, rng)
        if not isinstance(factorer, Factorer):
            raise ParameterError(
                f"breaker {breaker!r} factors Paillier moduli; the keys of scheme "
                f"{getattr(scheme, 'name', type(scheme).__name__)!r} are discrete logarithms (a breaker of "
                "encctl_gym.cryptanalysis.BREAKERS)"
            )
        return KeyFactoring(factorer, group, time_limit=time_limit, rng=rng)
    return KeyBreaking(
        breaker, group, scheme=scheme, adversary=adversary, time_limit=time_limit, rng=rng, precomputation=precomputation
    )
