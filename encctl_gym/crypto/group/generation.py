"""Safe-prime groups p = 2q + 1 made on demand, and the group of a size: shipped or generated.

Generating a group of a size that is not shipped is bounded in time: before the search starts,
:func:`estimate_generation_seconds` gives the expected time of the search and
:func:`generate_safe_prime_group` refuses (:class:`~encctl_gym.errors.ResourceLimitError`)
sizes whose estimate exceeds ``max_seconds`` (default
:data:`DEFAULT_MAX_GENERATION_SECONDS`).

:func:`get_group` returns the shipped group of a size when there is one (:mod:`.shipped`) and
generates one otherwise; :func:`as_group` also accepts a :class:`~.params.GroupParams`.
"""

from __future__ import annotations

import json
import math
import sys
import time
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from ..._validation import check_bool, check_int, check_positive, format_value
from ...errors import ParameterError, ResourceLimitError
from .. import arith
from ..arith import RngLike
from ..arith import format_int as fmt
from .params import GroupParams
from .shipped import _DATA_FILE, SHIPPED_BITS, shipped_group
from .sieve import MAX_SIEVE_WINDOW, _small_primes, sieve_window

__all__ = [
    "MIN_GENERATE_BITS",
    "DEFAULT_MAX_GENERATION_SECONDS",
    "estimate_generation_seconds",
    "modular_exponentiation_seconds",
    "generate_safe_prime_group",
    "get_group",
    "as_group",
    "write_shipped_groups",
]

#: Smallest bit length accepted by :func:`generate_safe_prime_group` (and :func:`get_group`).
#: Such groups are insecure; they exist for fast tests. :class:`GroupParams` itself has no
#: minimum, so hand-checked toy groups such as (p, q, g) = (23, 11, 4) can be loaded for
#: known-answer tests.
MIN_GENERATE_BITS = 16


def _check_bits(bits: Any) -> int:
    if isinstance(bits, bool) or not isinstance(bits, (int, np.integer)):
        raise ParameterError(f"bits must be an integer, got {format_value(bits)}")
    bits = int(bits)
    if bits < MIN_GENERATE_BITS:
        raise ParameterError(
            f"bits must be >= {MIN_GENERATE_BITS} (MIN_GENERATE_BITS), got {bits}; toy groups "
            "can still be built directly with GroupParams(p, q, g)"
        )
    return bits


#: Default limit, in seconds, on the *estimated* time of a safe-prime search
#: (:func:`estimate_generation_seconds`); about 3000 bits on the reference machine.
DEFAULT_MAX_GENERATION_SECONDS = 60.0

# Cost model of the search (estimate_generation_seconds), measured on the reference machine
# (gmpy2 2.3.2, GMP 6.3.0; benchmarks/bench_crypto.py prints estimate / measured):
# best time of gmpy2.powmod(2, n - 1, n) for n of the given bit length, in seconds ...
_POWMOD_SECONDS = (
    (128, 2.0e-6),
    (256, 1.21e-5),
    (512, 5.32e-5),
    (712, 1.25e-4),
    (1024, 2.96e-4),
    (1536, 9.08e-4),
    (2048, 2.07e-3),
    (3072, 6.38e-3),
    (4096, 1.50e-2),
    (8192, 8.64e-2),
    (16384, 0.492),
)
# ... and the time per sieving prime per window (two strided assignments and a reduction).
_SIEVE_SECONDS_PER_PRIME = 7.5e-7
# Hardy-Littlewood twin-prime constant C2: the density of Sophie Germain primes q (q and
# 2q + 1 prime) among the odd integers near x is 4 C2 / (ln x ln 2x).
_TWIN_PRIME_CONSTANT = 0.6601618158468696


def _search_plan(bits: int, window: int | None = None) -> tuple[int, int]:
    """(window, sieve limit) of the safe-prime search for ``bits`` (shared with the estimate)."""
    large = bits >= 1536
    default = 1 << 16 if large else 1 << 14
    window = check_int("window", default if window is None else window, minimum=16, maximum=MAX_SIEVE_WINDOW)
    cap = 1 << (20 if large else 16)
    # Sieve only with primes below q_low = 2^(bits - 2), so that a prime q is never struck out
    # by itself (q_low is not built for huge bits: it exceeds the cap from 23 bits on).
    limit = cap if bits - 2 > 21 else min(cap, max(3, 1 << (bits - 2)))
    return window, limit


def _powmod_seconds(bits: float) -> float:
    """Log-log interpolation of the measured powmod times (last slope beyond the table)."""
    table = _POWMOD_SECONDS
    if bits <= table[0][0]:
        return table[0][1] * bits / table[0][0]
    for (b0, t0), (b1, t1) in zip(table, table[1:]):
        if bits <= b1 or (b1, t1) == table[-1]:
            slope = math.log(t1 / t0) / math.log(b1 / b0)
            try:
                return t0 * math.exp(slope * (math.log(bits) - math.log(b0)))
            except OverflowError:
                return math.inf
    raise AssertionError("unreachable")  # pragma: no cover


def modular_exponentiation_seconds(bits: Any) -> float:
    """Time of one modular exponentiation with a full-size exponent modulo a ``bits``-bit p on the
    reference machine: the measured table of the safe-prime search's time model, interpolated in
    log-log scale (the per-size model every cost per step of the package is built on).

    Raises
    ------
    ParameterError
        If ``bits`` is not an integer >= 1.
    """
    return _powmod_seconds(float(check_int("bits", bits, minimum=1)))


@cache
def _sieve_survival(limit: int) -> tuple[float, float, int]:
    """(prod (1 - 2/l), prod (1 - 1/l), number of primes) over the sieving primes below ``limit``."""
    primes = np.array(_small_primes(limit), dtype=np.float64)
    return (float(np.exp(np.log1p(-2.0 / primes).sum())), float(np.exp(np.log1p(-1.0 / primes).sum())), len(primes))


def estimate_generation_seconds(bits: int, window: int | None = None) -> float:
    """Expected time of :func:`generate_safe_prime_group` for ``bits``, before it starts.

    Model: a safe prime p = 2q + 1 is a Sophie Germain prime q, whose density among odd
    integers near q is ``4 C2 / (ln q ln p)`` (Hardy-Littlewood), so about
    ``ln q ln p / (4 C2)`` odd candidates are scanned. The sieve keeps the fraction
    ``prod_l (1 - 2/l)`` of them (both q and 2q + 1 free of the sieving primes l); each
    survivor costs one base-2 Fermat test on q (one modular exponentiation of ``bits`` bits),
    plus one on p when q passes; each window of candidates costs one pass over the sieving
    primes. The powmod and sieve times are measurements on the reference machine (gmpy2 2.3.2,
    GMP 6.3.0), interpolated in log-log scale; beyond 16384 bits the last slope is used.

    The number of candidates is geometric, so the time of one search scatters around this
    mean (about 5% of searches take more than 3 times it); on a loaded or slower machine every
    search takes longer.

    Parameters
    ----------
    bits : int
        Bit length of p (>= :data:`MIN_GENERATE_BITS`); any size, it is not generated.
    window : int, optional
        As for :func:`generate_safe_prime_group`.

    Returns
    -------
    float
        The expected time in seconds.

    Raises
    ------
    ParameterError
        If ``bits`` is not an integer >= :data:`MIN_GENERATE_BITS`.
    """
    bits = _check_bits(bits)
    window, limit = _search_plan(bits, window)
    if bits > 1 << 60:  # beyond any float model (and any memory)
        return math.inf
    ln_q = (bits - 1.5) * math.log(2.0)  # q uniform in [2^(bits-2), 2^(bits-1))
    ln_p = ln_q + math.log(2.0)
    candidates = ln_q * ln_p / (4.0 * _TWIN_PRIME_CONSTANT)
    keep2, keep1, n_primes = _sieve_survival(limit)
    tests = candidates * keep2
    q_passes = min(1.0, 2.0 / (ln_q * keep1))  # P(q prime | q has no small factor)
    t_pow = _powmod_seconds(bits)
    windows = max(1.0, candidates / window)
    # + the final BPSW / Miller-Rabin tests of q and p (about ten exponentiations)
    return tests * (1.0 + q_passes) * t_pow + windows * n_primes * _SIEVE_SECONDS_PER_PRIME + 10 * t_pow


def generate_safe_prime_group(
    bits: int,
    rng: RngLike = None,
    progress: bool = False,
    window: int | None = None,
    max_seconds: float = DEFAULT_MAX_GENERATION_SECONDS,
) -> GroupParams:
    """Generate a safe-prime group p = 2q + 1 with p of exactly ``bits`` bits (Example ex:elgamal).

    Candidates q of ``bits - 1`` bits are scanned in windows q0, q0 + 2, ..., and a sieve
    with the small odd primes removes every q for which q or 2q + 1 has a small factor. The
    survivors get a base-2 Fermat test on q and on p = 2q + 1, then the BPSW/Miller-Rabin
    test of :func:`arith.is_prime` on both. g = 4 = 2^2 is a quadratic residue different
    from 1, hence generates the order-q subgroup. (Scanning forward from a random start is
    the standard incremental search; it slightly favours primes after long gaps, which is
    irrelevant for discrete-log security.)

    Parameters
    ----------
    bits : int
        Bit length of p, >= :data:`MIN_GENERATE_BITS`.
    rng : None, int, RandomSource or numpy.random.Generator
        Randomness for the starting points (``None``: secure; an int seed is reproducible and
        keyed by the purpose ``"group"``, see :mod:`.arith`).
    progress : bool, default False
        Print the number of tested candidates on stderr while searching.
    window : int, optional
        Number of candidates sieved at once (default 2**14, or 2**16 from 1536 bits on, where
        the sieve also uses more primes because each primality test is expensive); at most
        :data:`MAX_SIEVE_WINDOW`.
    max_seconds : float, default :data:`DEFAULT_MAX_GENERATION_SECONDS`
        Limit on :func:`estimate_generation_seconds`, checked before the search starts.

    Returns
    -------
    GroupParams
        A verified safe-prime group.

    Raises
    ------
    ParameterError
        If ``bits`` is not an integer or is below :data:`MIN_GENERATE_BITS`, ``max_seconds``
        is not finite and > 0, ``progress`` is not a bool, or ``window`` is not an integer in
        ``[16, MAX_SIEVE_WINDOW]``.
    ResourceLimitError
        If the estimated time exceeds ``max_seconds`` (the message gives both).
    """
    bits = _check_bits(bits)
    max_seconds = check_positive("max_seconds", max_seconds)
    if progress is not False:
        progress = check_bool("progress", progress)
    window, limit = _search_plan(bits, window)
    estimate = estimate_generation_seconds(bits, window)
    if estimate > max_seconds:
        raise ResourceLimitError(
            f"generating a {fmt(bits)}-bit safe-prime group is estimated to take {estimate:.3g} s, "
            f"more than max_seconds = {max_seconds:g} s; use a shipped size {SHIPPED_BITS}, load "
            "a group made elsewhere (GroupParams.load), or raise max_seconds"
        )
    src = arith.as_random_source(rng, purpose="group")
    qbits = bits - 1
    q_low, q_high = 1 << (qbits - 1), 1 << qbits  # q in [q_low, q_high) => p has `bits` bits
    tested = 0
    t0 = time.monotonic()
    while True:
        q0 = src.between(q_low, q_high) | 1
        while q0 < q_high:
            n_cand = min(window, (q_high - q0 + 1) // 2)
            q0m = arith.mpz(q0)
            for k in sieve_window(q0, n_cand, limit):
                q = q0m + 2 * int(k)
                p = 2 * q + 1
                tested += 1
                if progress and tested % 200 == 0:
                    print(
                        f"\rgenerating {bits}-bit safe prime: {tested} candidates tested, "
                        f"{time.monotonic() - t0:.1f} s (expected {estimate:.1f} s)",
                        end="",
                        file=sys.stderr,
                        flush=True,
                    )
                if arith.powmod(2, q - 1, q) != 1 or arith.powmod(2, p - 1, p) != 1:
                    continue
                if arith.is_prime(q) and arith.is_prime(p):
                    if progress:
                        print(
                            f"\rgenerated {bits}-bit safe prime after {tested} candidates in {time.monotonic() - t0:.1f} s",
                            file=sys.stderr,
                            flush=True,
                        )
                    return GroupParams(int(p), int(q), 4).verify()
            q0 += 2 * n_cand


def get_group(
    bits: int, rng: RngLike = None, progress: bool = False, max_seconds: float = DEFAULT_MAX_GENERATION_SECONDS
) -> GroupParams:
    """The shipped group of ``bits`` bits if there is one, else a freshly generated one.

    Parameters
    ----------
    bits : int
        Bit length of p (>= :data:`MIN_GENERATE_BITS`).
    rng, progress, max_seconds
        Passed to :func:`generate_safe_prime_group` when generating.

    Raises
    ------
    ResourceLimitError
        If a group must be generated and its estimated time exceeds ``max_seconds``.
    """
    bits = _check_bits(bits)
    arith.check_rng(rng)  # refused even where it is not needed (a shipped size)
    if bits in SHIPPED_BITS:
        return shipped_group(bits)
    return generate_safe_prime_group(bits, rng=rng, progress=progress, max_seconds=max_seconds)


def as_group(group_or_bits: GroupParams | int, rng: RngLike = None) -> GroupParams:
    """Accept a :class:`GroupParams` (verified here) or a bit length (:func:`get_group`, with
    the default time limit; call :func:`get_group` with ``max_seconds`` for larger sizes)."""
    if isinstance(group_or_bits, GroupParams):
        arith.check_rng(rng)
        return group_or_bits.verify()
    return get_group(group_or_bits, rng=rng)


def write_shipped_groups(path: str | Path = _DATA_FILE, bits: tuple[int, ...] = SHIPPED_BITS, rng: RngLike = None) -> None:
    """Regenerate the shipped-group file (``python -m encctl_gym.crypto.group``).

    Each group is made by :func:`generate_safe_prime_group` with secure randomness unless an
    ``rng`` is given.
    """
    groups = []
    for b in bits:
        group = generate_safe_prime_group(b, rng=rng, progress=True, max_seconds=3600.0)
        groups.append(group.to_dict())
    doc = {
        "description": "Safe-prime groups p = 2q + 1, g = 4 (order q), made by "
        "encctl_gym.crypto.group.generate_safe_prime_group; verified when loaded.",
        "groups": groups,
    }
    Path(path).write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
