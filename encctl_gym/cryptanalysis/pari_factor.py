"""PARI/GP's ``factor`` through the ``cypari`` binding: the independent reference factorer
(registry name ``"pari-factor"``; optional extra ``cryptanalysis``), as ``znlog`` is for the
discrete logarithms (:mod:`.pari`).

For the moduli of this package PARI's ``factor`` runs trial division, Pollard rho, SQUFOF, its
ECM and, beyond them, its self-initialising multiple-polynomial quadratic sieve (MPQS), whose
running time has the ``L_n[1/2, 1]`` shape. The cost model is that shape with two constants
fitted on this machine (:data:`PARI_FACTOR_C`, :data:`PARI_FACTOR_A`). Every result is checked as
for every factorer (``p q = n``), and a result that is not two factors raises
:class:`~encctl_gym.errors.BreakerError`. The binding is loaded through :func:`.pari._pari`, so
a missing ``cypari`` is the same one-line :class:`~encctl_gym.errors.OptionalDependencyError`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import ClassVar

from .._validation import format_value
from ..crypto.arith import RandomSource
from ..errors import BreakerError
from .base import Deadline
from .factoring import Factorer
from .pari import _pari

__all__ = ["PariFactor", "PARI_FACTOR_C", "PARI_FACTOR_A"]

#: seconds ~ PARI_FACTOR_C exp(PARI_FACTOR_A sqrt(ln n ln ln n)), fitted to ``factor`` on this
#: machine at 96 bits (2.8 ms), 128 bits (35 ms) and 192 bits (1.9 s) (``python benchmarks/bench_factoring.py``).
PARI_FACTOR_C = 4.0e-9
PARI_FACTOR_A = 0.804


class PariFactor(Factorer):
    """PARI's ``factor(n)``, one call per modulus. Default limit 256 bits."""

    name: ClassVar[str] = "pari-factor"
    DEFAULT_MAX_BITS: ClassVar[int] = 256
    MAIN_THREAD_ONLY: ClassVar[bool] = True

    def expected_seconds(self, bits: int) -> float:
        """``PARI_FACTOR_C exp(PARI_FACTOR_A sqrt(ln n ln ln n))``."""
        ln_n = max(bits, 8) * math.log(2.0)
        return PARI_FACTOR_C * math.exp(PARI_FACTOR_A * math.sqrt(ln_n * math.log(ln_n)))

    def check_feasible(self, bits: int) -> None:
        """The limits, and the binding (a missing ``cypari`` is refused here, before any work)."""
        super().check_feasible(bits)
        _pari()

    def _find_factor(self, n: int, deadline: Deadline, src: RandomSource) -> tuple[int, Mapping[str, int]]:
        pari = _pari()
        import cypari._pari as cp

        try:
            fac = pari.factor(n)
        except cp.PariError as exc:  # PARI gives up (its stack): one line, ours
            raise BreakerError(f"pari-factor: factor failed: {format_value(' '.join(str(exc).split()), 200)}") from None
        primes = [int(p) for p in fac[0]]
        exponents = [int(e) for e in fac[1]]
        if len(primes) < 2 and exponents[0] < 2:
            raise BreakerError(f"pari-factor: factor returned {format_value(str(fac))}, not a composite's factors")
        return primes[0], {"prime_factors": sum(exponents)}
