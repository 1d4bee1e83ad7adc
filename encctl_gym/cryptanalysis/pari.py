"""PARI/GP's ``znlog`` through the ``cypari`` binding (registry name ``"pari"``; optional extra).

``znlog(h, g, o)`` is PARI's discrete logarithm in ``(Z/pZ)^*``: given the order ``o = q`` of g
with its factorisation, it runs Pohlig-Hellman (trivial here: q is prime) and, for the prime
order q, picks baby-step giant-step, Pollard rho or its linear-sieve index calculus by size.
It is one call per key: whatever PARI computes for the group is recomputed for every key, so
the precomputation phase of this breaker only prepares the PARI objects; the measurements of
``experiments/deciphering_time.py`` show how much PARI reuses between calls.

Binding: ``cypari`` (``pip install 'encctl-gym[cryptanalysis]'``), chosen because it installs
from a self-contained manylinux wheel for current Pythons (it bundles PARI 2.15); ``cypari2``
publishes a cp311 wheel only for its old release 2.2.0 and falls back to a source build, which
needs a system PARI, for newer ones. PARI runs only in the main thread of a process (its stack
is per thread): this breaker refuses to run in another thread instead of crashing.

A PARI error inside ``znlog`` (PARI gives up: "too many iterations", its stack) is a one-line
:class:`~encctl_gym.errors.BreakerError`. Known limitation of the binding (cypari with PARI
2.15, reproduced without this package): once an ``alarm`` (the ``time_limit``) has interrupted
a ``znlog``, the next PARI *error* in the same process crashes it with a segmentation fault;
calls that succeed are unaffected. Run PARI attacks that may time out in their own process.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Mapping
from typing import Any, ClassVar

from .._validation import format_value
from ..crypto.arith import RandomSource, format_int
from ..crypto.group import GroupParams
from ..errors import BreakerError, OptionalDependencyError
from .base import Breaker, Deadline, Precomputation

__all__ = ["PariZnlog", "pari_available", "PARI_STACK_MAX"]

#: Cost model: seconds per key ~ PARI_C exp(PARI_A sqrt(ln p ln ln p)) (the L_p[1/2] shape of an
#: index calculus), fitted to ``znlog`` on this machine at 64-110 bits (0.11 s at 64 bits,
#: 0.56 s at 80, 2.6 s at 96, 8.6 s at 110).
PARI_C = 2.15e-6
PARI_A = 0.836
#: Largest PARI stack allowed (bytes); PARI doubles its stack as needed up to this size.
PARI_STACK_MAX = 1 << 30

_INSTALL = "pip install 'encctl-gym[cryptanalysis]'"
_PARI: Any = None
_ZNLOG_ALARM: Any = None


def pari_available() -> bool:
    """True if the ``cypari`` binding can be imported."""
    try:
        _pari()
    except OptionalDependencyError:
        return False
    return True


def _pari() -> Any:
    global _PARI, _ZNLOG_ALARM
    if _PARI is None:
        try:
            from cypari import pari
        except ImportError as exc:
            raise OptionalDependencyError(
                f"the 'pari' breaker needs the cypari binding of PARI/GP; install it with: {_INSTALL}"
            ) from exc
        pari.allocatemem(1 << 26, PARI_STACK_MAX, silent=True)
        pari.default("debugmem", 0)  # no "increasing stack size" warnings on stderr
        _ZNLOG_ALARM = pari("(h, g, o, t) -> alarm(t, znlog(h, g, o))")
        _PARI = pari
    return _PARI


class PariContext(Precomputation):
    """The group as PARI objects: ``Mod(g, p)`` and the order ``[q, [q, 1]]`` (rebuilt lazily, so
    that the context pickles)."""

    def __init__(self, group: GroupParams, rng: RandomSource | None) -> None:
        super().__init__(PariZnlog.name, group, rng)
        self._objects: tuple[Any, Any] | None = None

    def __getstate__(self) -> dict:
        state = super().__getstate__()
        state["_objects"] = None
        return state

    def _pari_objects(self) -> tuple[Any, Any]:
        if self._objects is None:
            pari = _pari()
            grp = self.group
            order = pari([grp.q, pari.matrix(1, 2, [grp.q, 1])])  # o = [q, factor(q)]
            self._objects = (pari.Mod(grp.g, grp.p), order)
        return self._objects

    def _solve(self, h: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int], str]:
        if threading.current_thread() is not threading.main_thread():
            raise BreakerError(
                "breaker 'pari' runs only in the main thread of a process (PARI's stack is per thread); "
                "break these keys without a thread-based scheduler"
            )
        pari = _pari()
        import cypari._pari as cp

        g, order = self._pari_objects()
        target = pari.Mod(h, self.group.p)
        try:
            if deadline.limit is None:
                result = pari.znlog(target, g, order)
            else:
                seconds = max(1, math.ceil(deadline.remaining))
                result = _ZNLOG_ALARM(target, g, order, seconds)
        except KeyboardInterrupt as exc:
            # PARI's alarm arrives as cypari's AlarmInterrupt, or as cysignals' one once fpylll (the
            # lattice extra) has imported cysignals and taken over SIGALRM: both are the time limit
            if type(exc).__name__ == "AlarmInterrupt":  # cypari.AlarmInterrupt or cysignals.signals.AlarmInterrupt
                raise deadline.error() from None
            raise
        except cp.PariError as exc:  # PARI gives up (an algorithm it lacks, its stack): one line, ours
            said = " ".join(str(exc).split())
            raise BreakerError(f"pari: znlog failed for h = {format_int(h)}: {format_value(said, 200)}") from None
        if result.type() != "t_INT":
            raise BreakerError(f"pari: znlog found no logarithm of h = {format_int(h)} (result {format_value(str(result))})")
        return int(result), {}, ""


class PariZnlog(Breaker):
    """PARI/GP's ``znlog``, one call per key (see the module docstring).

    Parameters
    ----------
    max_bits : int, optional
        Size limit (default 160 bits: about 5 minutes per key on this machine).
    rng
        Unused (PARI draws its own randomness); accepted for the common interface.
    """

    name: ClassVar[str] = "pari"
    DEFAULT_MAX_BITS: ClassVar[int] = 160
    MAIN_THREAD_ONLY: ClassVar[bool] = True

    def expected_seconds(self, group: GroupParams) -> tuple[float, float]:
        """``PARI_C exp(PARI_A sqrt(ln p ln ln p))`` for the first key and for each later one."""
        lnp = group.p.bit_length() * math.log(2)
        per_key = PARI_C * math.exp(PARI_A * math.sqrt(lnp * math.log(max(lnp, 2.0))))
        return per_key, per_key

    def check_feasible(self, group: GroupParams) -> None:
        """The size limit, and the binding: a missing ``cypari`` is refused here, before any work
        (:class:`~encctl_gym.errors.OptionalDependencyError`, one line naming the extra)."""
        super().check_feasible(group)
        _pari()

    def _precompute(self, group: GroupParams, deadline: Deadline) -> tuple[PariContext, Mapping[str, int]]:
        _pari()
        ctx = PariContext(group, self.rng)
        ctx._pari_objects()
        return ctx, {}
