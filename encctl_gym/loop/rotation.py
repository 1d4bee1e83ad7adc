"""Group rotation: every ``K`` attack steps the plant side moves the loop to a fresh safe-prime group.

Dynamic-key ElGamal changes the secret key every period but never the group, so an attacker
pays the discrete-logarithm precomputation (index calculus, the GNFS) once and every later key
almost for free. Rotation takes that away: with ``rotate_group_every=K`` (or the defender
``{"name": "rotate", "every": K}``) the plant side, before the period of every ``K``-th attack
step,

1. takes a fresh group of the same size from a :class:`GroupPool` (generated ahead, off the
   control path, on a worker thread; seeded from the plant's own crypto stream, a child of
   ``party_random_sources(crypto_seed)["plant"]`` that leaves the plant's draws unchanged);
2. runs KeyGen in it and re-provisions the server with ``Enc(pk_0', Ecd(Phi))``: ``n m``
   encryptions, and the ciphertexts, ``pk_0'`` and ``p`` sent (:class:`~encctl_gym.loop.provisioning.ProvisioningCost`).

The samples ``x_0 .. x_{K-1}`` are then under the first group, ``x_K .. x_{2K-1}`` under the
second, and so on: ``N`` samples lie in ``ceil(N / K)`` groups, and every cost model charges the
attacker per group (:mod:`encctl_gym.security.rotation`). With a real breaker
(``breaker=...``) the breaker meets every new group unprepared and redoes its precomputation
(:class:`~encctl_gym.loop.provisioning.GroupDecipherers`; counted in ``info["breaker_precomputations"]``).

The seam: a :class:`~encctl_gym.loop.defender.DefenderAction` with ``new_group`` set asks the
episode to move the loop; the episode calls the backend's ``rotate_group(group)``, which returns
the :class:`~encctl_gym.loop.provisioning.ProvisioningCost`, and sums them per episode in a
:class:`~encctl_gym.loop.provisioning.RotationRecord`
(``EpisodeCore.rotation``; the info fields of :func:`rotation_info`). Both backends rotate (the
ideal one rebuilds its quantisation table for the new group, the ElGamal one its keys and
ciphertexts), so their trajectories stay bit-identical for one seed. Every episode starts on the
loop's first group again. With ``crypto_seed`` set every episode meets the same sequence of groups
(the pool keeps them by index); with ``crypto_seed=None`` the groups follow the episode's seed
(:class:`RotationGroups`), so one seed gives one episode in any instance.
"""

from __future__ import annotations

import time
from collections import OrderedDict
from collections.abc import Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._validation import check_int, format_value
from ..crypto.group import GroupParams, estimate_generation_seconds, generate_safe_prime_group
from ..crypto.group.generation import DEFAULT_MAX_GENERATION_SECONDS
from ..errors import ParameterError, ResourceLimitError
from ..security.rotation import check_rotation_period
from .defender import DEFENDERS, DefenderAction, DefenderBase, DefenderPolicy, PlantView, make_defender
from .provisioning import GroupDecipherers, RotationRecord

__all__ = [
    "GroupPool",
    "RotationGroups",
    "GenerationTally",
    "RotatingDefender",
    "move_loop",
    "rotation_info",
    "MAX_AHEAD",
    "check_ahead",
]

#: Most groups a :class:`GroupPool` generates ahead. The worker makes one group at a time and the
#: episode takes one every ``K`` steps, so a deeper pool only starts sooner: 16 covers a rotation
#: at every step for 16 steps of generation lag. Each prefetched group draws a seed and queues a
#: generation at ``reset`` (1000 ahead: a 3.4 s reset at 64 bits; 10**400 never returned).
MAX_AHEAD = 16


def check_ahead(name: str, ahead: Any) -> int:
    """``ahead`` as an int in ``[0, MAX_AHEAD]``, else a :class:`ParameterError` naming it."""
    try:
        return check_int(name, ahead, minimum=0, maximum=MAX_AHEAD)
    except ParameterError as exc:
        raise ParameterError(f"{exc} (groups generated ahead of the one taken: MAX_AHEAD)") from None


def _generate(bits: int, seed: int, max_seconds: float) -> tuple[GroupParams, float]:
    t0 = time.perf_counter()
    group = generate_safe_prime_group(bits, rng=seed, max_seconds=max_seconds)
    return group, time.perf_counter() - t0


class GroupPool:
    """Fresh safe-prime groups of one size, generated ahead on a worker thread, kept by index.

    Group ``i >= 1`` (the loop's own group is group 0) is generated from the ``i``-th 256-bit seed
    drawn from ``source``; seeds are drawn in index order on the caller's thread, so the groups are
    the same however far ahead the worker runs. :meth:`get` waits only when the worker is behind.

    Parameters
    ----------
    bits : int
        Bit length of every group.
    source : RandomSource
        Where the seeds come from (the plant's group stream, :class:`RotatingDefender`).
    ahead : int, default 2
        Groups generated ahead of the one taken (0: generate when asked, on the caller's thread's
        time), at most :data:`MAX_AHEAD`.
    max_seconds : float
        Limit on the expected generation time of one group
        (:func:`~encctl_gym.crypto.group.estimate_generation_seconds`, the package's time model).

    Attributes
    ----------
    model_seconds : float
        The time model's expected seconds for one group of ``bits``.
    seconds : dict[int, float]
        Measured wall seconds of the generation of each group (on the worker).

    Raises
    ------
    ParameterError
        If ``ahead`` is not an integer in ``[0, MAX_AHEAD]``.
    ResourceLimitError
        If the time model expects a group of ``bits`` to take more than ``max_seconds``.
    """

    def __init__(self, bits: int, source: Any, ahead: int = 2, max_seconds: float = DEFAULT_MAX_GENERATION_SECONDS) -> None:
        self.bits = check_int("bits", bits, minimum=16)
        self.ahead = check_ahead("ahead", ahead)
        self.max_seconds = float(max_seconds)
        self.model_seconds = estimate_generation_seconds(self.bits)
        if self.model_seconds > self.max_seconds:
            raise ResourceLimitError(
                f"group rotation at {self.bits} bits needs a fresh safe-prime group per rotation, estimated at "
                f"{self.model_seconds:.3g} s each, more than max_seconds = {self.max_seconds:g} s"
            )
        self._source = source
        self._seeds: list[int] = []
        self._groups: dict[int, GroupParams] = {}
        self.seconds: dict[int, float] = {}
        self._futures: dict[int, Future] = {}
        self._executor: ThreadPoolExecutor | None = None

    def _seed(self, i: int) -> int:
        while len(self._seeds) < i:
            self._seeds.append(int(self._source.below(1 << 256)))
        return self._seeds[i - 1]

    def _submit(self, i: int) -> None:
        if i in self._groups or i in self._futures:
            return
        seed = self._seed(i)
        if self._executor is None:
            self._executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="encctl-gym-groups")
        self._futures[i] = self._executor.submit(_generate, self.bits, seed, self.max_seconds)

    def prefetch(self, first: int) -> None:
        """Start generating groups ``first .. first + ahead - 1`` (those not made yet)."""
        first = check_int("first", first, minimum=1)
        for i in range(first, first + self.ahead):
            self._submit(i)

    def get(self, i: int) -> tuple[GroupParams, float]:
        """Group ``i`` (>= 1) and the seconds the caller waited for it; starts the next ones ahead."""
        i = check_int("i", i, minimum=1)
        waited = 0.0
        if i not in self._groups:
            self._submit(i)
            t0 = time.perf_counter()
            group, seconds = self._futures.pop(i).result()  # re-raises what the worker raised
            waited = time.perf_counter() - t0
            self._groups[i], self.seconds[i] = group, seconds
        self.prefetch(i + 1)
        return self._groups[i], waited

    def close(self) -> None:
        """Stop the worker (groups already made are kept)."""
        executor, self._executor = self._executor, None
        if executor is not None:
            executor.shutdown(wait=False, cancel_futures=True)
        self._futures = {}

    def __getstate__(self) -> dict[str, Any]:
        """Copies get the groups made so far and no worker (a thread cannot be copied)."""
        state = self.__dict__.copy()
        for i, future in sorted(self._futures.items()):
            state["_groups"] = dict(state["_groups"])
            group, seconds = future.result()
            state["_groups"][i] = group
            state["seconds"] = {**state["seconds"], i: seconds}
        state["_futures"] = {}
        state["_executor"] = None
        return state

    def __del__(self) -> None:
        executor = getattr(self, "_executor", None)
        if executor is not None:
            executor.shutdown(wait=False, cancel_futures=True)

    def __repr__(self) -> str:
        return f"GroupPool(bits={self.bits}, ahead={self.ahead}, made={len(self._groups)})"


class RotationGroups:
    """Where a rotating defender's groups come from, episode by episode (one home for the
    :class:`RotatingDefender` and the game's rotate lever).

    * ``crypto_seed`` an integer: one :class:`GroupPool` seeded from the plant's group stream, a
      child of ``party_random_sources(crypto_seed)["plant"]``; every episode meets the same groups.
    * ``crypto_seed`` ``None``: the keys come from the secure source, but the groups (public
      parameters, sent to the server at every move) follow the episode's seed, so that two
      instances reset with the same seed meet the same groups and run the same episode (the
      quantisation depends on the group). The pool of an episode is keyed by 256 bits drawn from a
      child spawned off the defender's stream of copy 0 (``rngs[0]``; spawning leaves that stream's
      draws unchanged): ``reset(seed=s)`` meets the groups of ``s``, a reset without a seed meets
      new ones. The last :attr:`MAX_POOLS` pools are kept, so re-seeding does not regenerate.
      In a batch all copies share the loop's group, so copy 0's seed decides.

    Raises
    ------
    ResourceLimitError
        If the time model expects a group of ``bits`` to take more than the pool's limit.
    """

    #: Pools kept for re-seeded episodes (``crypto_seed=None``); an evicted pool's worker stops.
    MAX_POOLS = 4

    def __init__(self, bits: int, crypto_seed: int | None, ahead: int) -> None:
        from .elgamal import party_random_sources

        self.crypto_seed = crypto_seed
        self.ahead = check_ahead("ahead", ahead)
        self.fixed = GroupPool(bits, party_random_sources(crypto_seed)["plant"].spawn("group-rotation"), ahead)
        self.bits = self.fixed.bits
        self._pools: OrderedDict[int, GroupPool] = OrderedDict()

    def for_episode(self, rng: np.random.Generator) -> GroupPool:
        """The pool of the episode whose defender stream (copy 0) is ``rng``."""
        if self.crypto_seed is not None:
            return self.fixed
        from ..crypto.arith import seeded_random

        words = rng.spawn(1)[0].integers(0, 2**64, size=4, dtype=np.uint64)
        key = int.from_bytes(words.astype(">u8").tobytes(), "big")
        pool = self._pools.pop(key, None)
        if pool is None:
            pool = GroupPool(self.bits, seeded_random(key, "group-rotation"), self.ahead, self.fixed.max_seconds)
        self._pools[key] = pool  # most recent last
        while len(self._pools) > self.MAX_POOLS:
            self._pools.popitem(last=False)[1].close()
        return pool

    def close(self) -> None:
        """Stop every pool's worker (groups already made are kept)."""
        self.fixed.close()
        for pool in self._pools.values():
            pool.close()

    def __repr__(self) -> str:
        return f"RotationGroups(bits={self.bits}, crypto_seed={self.crypto_seed!r}, pools={len(self._pools)})"


@dataclass
class GenerationTally:
    """The groups a :class:`RotatingDefender` took in one episode."""

    groups: int = 0
    seconds: float = 0.0  # measured generation time of those groups (on the worker)
    model_seconds: float = 0.0  # the time model's expectation for them
    waited: float = 0.0  # seconds the control path waited for the pool
    indices: list[int] = field(default_factory=list)


class RotatingDefender(DefenderBase):
    """Moves the loop to a fresh group every ``every`` attack steps (registry name ``"rotate"``).

    Parameters
    ----------
    every : int
        ``K >= 1``: the rotation happens before the period of attack steps ``K - 1, 2K - 1, ...``,
        so samples ``x_{jK} .. x_{(j+1)K - 1}`` lie in group ``j``.
    inner : defender spec, optional
        Another policy composed with the rotation (its noise and alarm pass through; it picks
        the first group, and its ``on_new_group(group)`` is called at every move):
        a name of ``DEFENDERS``, a mapping or a policy object. Default ``"fixed"``.
    ahead : int, default 2
        Groups the pool generates ahead, at most :data:`MAX_AHEAD`.
    """

    name = "rotate"
    rotates = True

    def __init__(self, every: int = 10, inner: Any = None, ahead: int = 2) -> None:
        self.every = check_rotation_period(every, "every")
        self.inner: DefenderPolicy = make_defender(inner)
        if getattr(self.inner, "rotates", False):  # given as an object, a name or a dict spec alike
            raise ParameterError(f"a rotating defender cannot wrap another rotating defender (inner={format_value(inner)})")
        self.ahead = check_ahead("ahead", ahead)
        self.groups: RotationGroups | None = None
        self.pool: GroupPool | None = None  # the episode's (RotationGroups.for_episode)
        self.initial_group: GroupParams | None = None
        self.tally = GenerationTally()
        self._next = 1

    def group(self, params: Any) -> Any:
        """The inner policy's group; the fresh groups of its size (:class:`RotationGroups`)."""
        group = self.inner.group(params)
        if not (isinstance(group, GroupParams) and group.is_safe_prime):
            raise ParameterError(f"group rotation needs a safe-prime group to start from, got {format_value(group)}")
        self.initial_group = group
        self.horizon = int(params.horizon)
        self.groups = RotationGroups(group.bits, params.crypto_seed, self.ahead)
        self.pool = self.groups.fixed
        return group

    def reset(self, K: int, n: int, m: int, rngs: Sequence[np.random.Generator]) -> None:
        self.inner.reset(K, n, m, rngs)
        if self.groups is None:
            raise ParameterError("the rotating defender's group() must pick the loop's group before an episode")
        self.pool = self.groups.for_episode(rngs[0])
        self._next = 1
        self.tally = GenerationTally()
        self.pool.prefetch(1)

    def act(self, view: PlantView) -> DefenderAction | None:
        action = self.inner.act(view)
        step = view.step
        if (step + 1) % self.every or step + 1 >= self.horizon:  # no group for a sample never collected
            return action
        assert self.pool is not None
        group, waited = self.pool.get(self._next)
        t = self.tally
        t.groups += 1
        t.indices.append(self._next)
        t.seconds += self.pool.seconds[self._next]
        t.model_seconds += self.pool.model_seconds
        t.waited += waited
        self._next += 1
        self.inner.on_new_group(group)  # e.g. the audit's error bound follows the new group's encoding
        if action is None:
            return DefenderAction(new_group=group)
        return DefenderAction(input_noise=action.input_noise, end=action.end, new_group=group)

    def close(self) -> None:
        """Stop the pools' workers (the environment's ``close``); the inner policy's too."""
        if self.groups is not None:
            self.groups.close()
        self.inner.close()

    def __repr__(self) -> str:
        return f"RotatingDefender(every={self.every!r}, inner={self.inner!r})"


DEFENDERS["rotate"] = RotatingDefender


def move_loop(loop: Any, stepper: Any, group: Any) -> Any:
    """The episode's move of ``loop`` to ``group`` (its ``rotate_group``; returns the
    :class:`~encctl_gym.loop.provisioning.ProvisioningCost`); a compiled ``stepper`` takes the new
    quantisation.

    Raises
    ------
    ParameterError
        For a backend without ``rotate_group``.
    """
    rotate = getattr(loop, "rotate_group", None)
    if rotate is None:
        raise ParameterError(f"the {type(loop).__name__} backend cannot move to another group (it has no rotate_group)")
    cost = rotate(group)
    if hasattr(stepper, "quant") and loop.quantization is not None:
        stepper.quant = tuple(loop.quantization)
    return cost


def rotation_info(record: RotationRecord, defender: Any, loop: Any, breaker: bool) -> dict[str, Any]:
    """The info fields of group rotation (empty unless the defender rotates or the loop was moved).

    ``groups`` (groups the loop has used this episode), ``group_rotations``,
    ``provisioning_encryptions`` and ``provisioning_bytes`` (:class:`RotationRecord`),
    ``group_generation_seconds`` (measured, on the pool's worker), ``group_generation_model_seconds``
    (the time model's), ``group_wait_seconds`` (what the control path waited for the pool) and,
    with a breaker, ``breaker_precomputations`` (the precomputations it ran this episode).
    """
    if not (defender.rotates or record.rotations):
        return {}
    tally = defender.tally
    info: dict[str, Any] = {
        "groups": record.rotations + 1,
        "group_rotations": record.rotations,
        "provisioning_encryptions": record.encryptions,
        "provisioning_bytes": record.bytes_sent,
        "group_generation_seconds": float(tally.seconds) if tally is not None else 0.0,
        "group_generation_model_seconds": float(tally.model_seconds) if tally is not None else 0.0,
        "group_wait_seconds": float(tally.waited) if tally is not None else 0.0,
    }
    if breaker:
        dec = getattr(loop, "decipherer", None)
        if isinstance(dec, GroupDecipherers):
            info["breaker_precomputations"] = dec.precomputations
        else:
            info["breaker_precomputations"] = sum(1 for method, _ in getattr(dec, "costs", []) if method == "precomputation")
    return info
