"""Public parameters (p, q, g) of ElGamal encryption (Example ex:elgamal).

p and q are primes with p = n q + 1 (n is the *cofactor*); g generates the subgroup
G = {g^i mod p | i in Z_q} of order q, which is both the plaintext space and the space of
ciphertext components. The generator :func:`generate_safe_prime_group` produces safe-prime
groups (n = 2, p = 2q + 1), in which G is the group of quadratic residues modulo p, so
membership is a Jacobi symbol; groups with another cofactor can be loaded and verified.

The *bit length* of a group (``GroupParams.bits``) is the bit length of p.

Degenerate parameters are refused: q = 2 (G = {1, p - 1}, whose only secret key s = 1 is
public), g = 1, q not dividing p - 1, composite p or q, g of another order than q
(:meth:`GroupParams.verify`). Keys are only made over verified groups.

Generating a group of a size that is not shipped is bounded in time: before the search starts,
:func:`estimate_generation_seconds` gives the expected time of the search and
:func:`generate_safe_prime_group` refuses (:class:`~encctl_gym.errors.ResourceLimitError`)
sizes whose estimate exceeds ``max_seconds`` (default
:data:`DEFAULT_MAX_GENERATION_SECONDS`).

Pre-generated groups for :data:`SHIPPED_BITS` are stored in ``crypto/data/groups.json``
(made with :func:`generate_safe_prime_group`); :func:`shipped_group` verifies them once per
process (primality of p and q, order of g) and caches the result.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import sys
import time
from collections.abc import Mapping
from functools import cache, cached_property, lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import check_bool, check_int, check_positive, format_value
from ..errors import ConfigError, GroupError, ParameterError, ResourceLimitError
from . import arith
from .arith import RngLike
from .arith import format_int as fmt

__all__ = [
    "GroupParams",
    "MIN_GENERATE_BITS",
    "MAX_GROUP_BITS",
    "MAX_GROUP_FILE_BYTES",
    "MAX_SIEVE_WINDOW",
    "MAX_SIEVE_LIMIT",
    "SHIPPED_BITS",
    "DEFAULT_MAX_GENERATION_SECONDS",
    "estimate_generation_seconds",
    "generate_safe_prime_group",
    "sieve_window",
    "shipped_group",
    "get_group",
    "as_group",
]

#: Smallest bit length accepted by :func:`generate_safe_prime_group` (and :func:`get_group`).
#: Such groups are insecure; they exist for fast tests. :class:`GroupParams` itself has no
#: minimum, so hand-checked toy groups such as (p, q, g) = (23, 11, 4) can be loaded for
#: known-answer tests.
MIN_GENERATE_BITS = 16

#: Largest bit length of p accepted by :class:`GroupParams`: above it a single verification or
#: exponentiation takes from seconds to hours (NIST SP 800-57 asks 15360 bits of p for the
#: highest, 256-bit, security level of finite-field discrete logarithms).
MAX_GROUP_BITS = 16384

#: Largest group file :meth:`GroupParams.load` reads, in bytes.
MAX_GROUP_FILE_BYTES = 1 << 20

#: Largest number of candidates sieved at once (:func:`sieve_window`, the ``window`` of
#: :func:`generate_safe_prime_group`): one byte each.
MAX_SIEVE_WINDOW = 1 << 24

#: Largest bound of the sieving primes of :func:`sieve_window` (the search itself uses at most
#: 2**20): the sieve of Eratosthenes below it takes one byte per integer.
MAX_SIEVE_LIMIT = 1 << 24

#: Bit lengths of the groups shipped in ``crypto/data/groups.json``.
SHIPPED_BITS: tuple[int, ...] = (64, 128, 256, 512, 712, 1024, 2048)

_DATA_FILE = Path(__file__).with_name("data") / "groups.json"

_MPZ = type(arith.mpz(0))

# (p, q, g) triples that passed GroupParams.verify() in this process.
_VERIFIED: set[tuple[int, int, int]] = set()


def _as_int(name: str, value: Any) -> int:
    if isinstance(value, str):
        try:
            return int(value, 0)
        except ValueError as exc:
            shown = value if len(value) <= 60 else f"{value[:40]}... ({len(value)} characters)"
            raise GroupError(f"{name} must be an integer (decimal or 0x hex), got {shown!r}: {exc}") from None
    if type(value).__name__ == "mpz":
        return int(value)
    try:
        return check_int(name, value)
    except ParameterError as exc:
        raise GroupError(str(exc)) from exc


def _as_path(path: Any) -> Path:
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"path must be a str or a path, got {format_value(path)}")
    return Path(path)


@dataclasses.dataclass(frozen=True)
class GroupParams:
    """Group parameters (p, q, g) of Example ex:elgamal.

    Construction performs the cheap structural checks (integers, p >= 5 of at most
    :data:`MAX_GROUP_BITS` bits, q >= 3, q | p - 1, 1 < g < p); :meth:`verify` performs the expensive ones (primality of p and q,
    g^q = 1 mod p) and is cached per process. No minimum size is enforced here (see
    :data:`MIN_GENERATE_BITS`).

    Parameters
    ----------
    p : int
        The prime modulus, p = n q + 1.
    q : int
        The odd prime order of the subgroup G generated by g (q = 2 is refused: the only
        secret exponent in {1, ..., q - 1} would be s = 1).
    g : int
        A generator of G (g != 1, g^q = 1 mod p).

    Attributes
    ----------
    bits : int
        The bit length of p (the key length of the paper).
    cofactor : int
        n = (p - 1) / q; 2 for the safe-prime groups this package generates.

    Raises
    ------
    GroupError
        If a value is not an integer, p < 5 or p has more than :data:`MAX_GROUP_BITS` bits,
        q < 3, q does not divide p - 1, or g is not in (1, p).
    """

    p: int
    q: int
    g: int

    def __post_init__(self) -> None:
        p, q, g = _as_int("p", self.p), _as_int("q", self.q), _as_int("g", self.g)
        if p < 5:
            raise GroupError(f"p must be a prime >= 5, got p = {fmt(p)}")
        if p.bit_length() > MAX_GROUP_BITS:
            raise GroupError(
                f"p has {p.bit_length()} bits, more than MAX_GROUP_BITS = {MAX_GROUP_BITS} (every "
                "verification and exponentiation would take from seconds to hours)"
            )
        if q < 3:
            raise GroupError(
                f"q must be an odd prime >= 3, got q = {fmt(q)} (for q = 2 the group is {{1, p - 1}} "
                "and the only secret key s = 1 is public)"
            )
        if (p - 1) % q != 0:
            raise GroupError(f"q = {fmt(q)} does not divide p - 1 = {fmt(p - 1)} (need p = n q + 1)")
        if not 1 < g < p:
            raise GroupError(f"g must satisfy 1 < g < p = {fmt(p)}, got g = {fmt(g)}")
        object.__setattr__(self, "p", p)
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "g", g)

    # ------------------------------------------------------------------ properties
    @property
    def bits(self) -> int:
        """Bit length of p (the paper's key length k; ``GroupParams.bits`` convention)."""
        return self.p.bit_length()

    @cached_property
    def cofactor(self) -> int:
        """The cofactor n with p = n q + 1 (2 for safe-prime groups)."""
        return (self.p - 1) // self.q

    @property
    def is_safe_prime(self) -> bool:
        """True if p = 2q + 1, so that G is the set of quadratic residues modulo p."""
        return self.cofactor == 2

    @cached_property
    def half(self) -> int:
        """(p - 1) // 2: signed plaintexts are lifted to the interval [-half, half]."""
        return (self.p - 1) // 2

    # ------------------------------------------------------------------ membership
    def contains(self, m: int) -> bool:
        """True if ``m`` is an element of G (1 <= m < p and m^q = 1 mod p).

        For safe-prime groups this is one Jacobi symbol (no modular exponentiation); for
        another cofactor it is ``pow(m, q, p) == 1`` (one exponentiation).

        Raises
        ------
        ParameterError
            If ``m`` is not an integer (a float or a string is not "not a member": it is no
            residue at all).
        """
        if type(m) is not int and type(m) is not _MPZ:
            m = arith.check_integer("m", m)
        if not 0 < m < self.p:
            return False
        if self.is_safe_prime:
            return arith.jacobi(m, self.p) == 1
        return arith.powmod(m, self.q, self.p) == 1

    def verify(self, recheck: bool = False) -> GroupParams:
        """Check that p and q are prime, q | p - 1, g != 1 and g^q = 1 mod p (g has order q).

        The result is cached per process, so verifying a group again is free.

        Parameters
        ----------
        recheck : bool, default False
            Run the checks even if they already succeeded in this process (for benchmarks).

        Returns
        -------
        GroupParams
            ``self``, for chaining.

        Raises
        ------
        GroupError
            Naming the failed condition and the offending value.
        ParameterError
            If ``recheck`` is not a bool.
        """
        if recheck is not False:
            recheck = check_bool("recheck", recheck)
        key = (self.p, self.q, self.g)
        if key in _VERIFIED and not recheck:
            return self
        if not arith.is_prime(self.q):
            raise GroupError(f"q is not prime: q = {fmt(self.q)}")
        if not arith.is_prime(self.p):
            raise GroupError(f"p is not prime: p = {fmt(self.p)}")
        if self.g == 1 or arith.powmod(self.g, self.q, self.p) != 1:
            raise GroupError(f"g = {fmt(self.g)} does not have order q = {fmt(self.q)} modulo p = {fmt(self.p)} (g^q != 1)")
        _VERIFIED.add(key)
        return self

    @property
    def verified(self) -> bool:
        """True if :meth:`verify` already succeeded for these parameters in this process."""
        return (self.p, self.q, self.g) in _VERIFIED

    # ------------------------------------------------------------------ serialisation
    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict; integers are hexadecimal strings (exact in every JSON parser)."""
        return {"bits": self.bits, "cofactor": self.cofactor, "p": hex(self.p), "q": hex(self.q), "g": hex(self.g)}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> GroupParams:
        """Inverse of :meth:`to_dict` (also accepts plain integers); does not :meth:`verify`.

        Raises
        ------
        GroupError
            If a field is missing or the declared ``bits``/``cofactor`` do not match.
        """
        if not isinstance(data, Mapping):
            raise GroupError(f"group data must be a mapping with fields p, q, g, got {format_value(data)}")
        try:
            group = cls(data["p"], data["q"], data["g"])
        except (KeyError, TypeError) as exc:
            raise GroupError(
                f"group data must be a mapping with fields p, q, g, got {type(data).__name__} "
                f"with fields {sorted(map(str, data)) if isinstance(data, Mapping) else None}"
            ) from exc
        for name in ("bits", "cofactor"):
            if name in data and _as_int(name, data[name]) != getattr(group, name):
                raise GroupError(
                    f"declared {name} = {fmt(data[name])} does not match the parameters ({name} = {getattr(group, name)})"
                )
        return group

    def to_json(self) -> str:
        """Serialise to a JSON string (see :meth:`to_dict`)."""
        return json.dumps(self.to_dict(), indent=1)

    @classmethod
    def from_json(cls, text: str | bytes) -> GroupParams:
        """Parse :meth:`to_json` output.

        Raises
        ------
        GroupError
            If ``text`` is not text (``str`` or UTF-8 ``bytes``), is malformed or too deeply
            nested JSON, or does not describe a group (:meth:`from_dict`).
        """
        if not isinstance(text, (str, bytes, bytearray)):
            raise GroupError(f"group JSON must be a str or bytes, got {format_value(text)}")
        try:
            data = json.loads(text)
        except RecursionError:
            raise GroupError("invalid group JSON: nested too deeply (a group is one flat object)") from None
        except ValueError as exc:  # malformed, not UTF-8, or a decimal number beyond the int-to-str limit
            raise GroupError(f"invalid group JSON: {exc}") from None
        if not isinstance(data, dict):
            raise GroupError(f"group JSON must be an object, got a {type(data).__name__}")
        return cls.from_dict(data)

    def save(self, path: str | Path) -> None:
        """Write :meth:`to_json` to ``path``.

        Raises
        ------
        ParameterError
            If ``path`` is not a str or a path.
        ConfigError
            If the file cannot be written (a directory, a missing parent, no permission, ...).
        """
        target = _as_path(path)
        try:
            target.write_text(self.to_json() + "\n", encoding="utf-8")
        except OSError as exc:
            raise ConfigError(f"cannot write the group file {format_value(str(target))}: {exc.strerror or exc}") from None

    @classmethod
    def load(cls, path: str | Path, verify: bool = True) -> GroupParams:
        """Read a group written by :meth:`save` (verified unless ``verify=False``).

        At most :data:`MAX_GROUP_FILE_BYTES` are read (a group of :data:`MAX_GROUP_BITS` bits
        takes about 13 kB).

        Raises
        ------
        ParameterError
            If ``path`` is not a str or a path, or ``verify`` is not a bool.
        ConfigError
            If the file cannot be read, is larger than :data:`MAX_GROUP_FILE_BYTES` or is not
            UTF-8 text.
        GroupError
            If its content is not a valid group (:meth:`from_json`, :meth:`verify`).
        """
        source = _as_path(path)
        if verify is not True:
            verify = check_bool("verify", verify)
        shown = format_value(str(source))
        try:
            with source.open("rb") as f:
                raw = f.read(MAX_GROUP_FILE_BYTES + 1)
        except OSError as exc:
            raise ConfigError(f"cannot read the group file {shown}: {exc.strerror or exc}") from None
        if len(raw) > MAX_GROUP_FILE_BYTES:
            raise ConfigError(
                f"the group file {shown} is larger than MAX_GROUP_FILE_BYTES = {MAX_GROUP_FILE_BYTES} bytes "
                "(a group file is a few kilobytes)"
            )
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise ConfigError(f"the group file {shown} is not UTF-8 text: {exc.reason} at byte {exc.start}") from None
        group = cls.from_json(text)
        return group.verify() if verify else group

    def __repr__(self) -> str:
        return f"GroupParams(bits={self.bits}, cofactor={fmt(self.cofactor)}, p={fmt(self.p)}, g={fmt(self.g)})"


# ---------------------------------------------------------------------- generation
@cache
def _small_primes(limit: int) -> tuple[int, ...]:
    """Odd primes below ``limit`` (sieve of Eratosthenes)."""
    sieve = np.ones(limit, dtype=bool)
    sieve[:2] = False
    for i in range(2, int(limit**0.5) + 1):
        if sieve[i]:
            sieve[i * i :: i] = False
    return tuple(int(x) for x in np.flatnonzero(sieve) if x != 2)


def sieve_window(q0: int, n_cand: int, limit: int) -> np.ndarray:
    """Indices k of the candidates ``q = q0 + 2k`` (k < ``n_cand``) that survive the sieve.

    A candidate is struck out when q or 2q + 1 is divisible by an odd prime l < ``limit``:
    ``q0 + 2k = 0 (mod l)`` iff ``k = -q0 / 2``, and ``2(q0 + 2k) + 1 = 0 (mod l)`` iff
    ``k = (-1/2 - q0) / 2`` (mod l). ``q0`` must be odd and, so that a prime q is not struck
    out by itself, at least ``limit`` (larger than every sieving prime).

    Parameters
    ----------
    q0 : int
        The first candidate, odd and >= ``limit``.
    n_cand : int
        Number of candidates, in ``[0, MAX_SIEVE_WINDOW]``.
    limit : int
        Bound of the sieving primes, in ``[3, MAX_SIEVE_LIMIT]``.

    Returns
    -------
    numpy.ndarray
        The surviving indices k, ascending.

    Raises
    ------
    ParameterError
        If an argument is not an integer or is outside its range (the message names it).
    """
    q0 = arith.check_integer("q0", q0)
    n_cand = check_int("n_cand", n_cand, minimum=0, maximum=MAX_SIEVE_WINDOW)
    limit = check_int("limit", limit, minimum=3, maximum=MAX_SIEVE_LIMIT)
    if q0 % 2 == 0 or q0 < limit:
        raise ParameterError(
            f"q0 must be odd and >= limit = {limit} (a prime q below the sieve bound would strike itself out), got {fmt(q0)}"
        )
    primes = _small_primes(limit)
    inv2 = _inverses_of_two(limit)
    sieve = np.ones(n_cand, dtype=bool)
    for ell, i2 in zip(primes, inv2):
        r = q0 % ell
        sieve[(-r * i2) % ell :: ell] = False
        sieve[((-i2 - r) * i2) % ell :: ell] = False
    return np.flatnonzero(sieve)


@cache
def _inverses_of_two(limit: int) -> tuple[int, ...]:
    return tuple(pow(2, -1, ell) for ell in _small_primes(limit))


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


# ---------------------------------------------------------------------- shipped groups
@lru_cache(maxsize=1)
def _shipped_data() -> dict[int, dict[str, Any]]:
    try:
        data = json.loads(_DATA_FILE.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise GroupError(f"cannot read the shipped groups from {_DATA_FILE}: {exc}") from exc
    return {int(entry["bits"]): entry for entry in data["groups"]}


def shipped_group(bits: int) -> GroupParams:
    """Return the pre-generated safe-prime group of ``bits`` bits (verified once per process).

    Parameters
    ----------
    bits : int
        One of :data:`SHIPPED_BITS`.

    Raises
    ------
    ParameterError
        If no group of that size is shipped.
    GroupError
        If the stored group fails verification.
    """
    bits = check_int("bits", bits)
    data = _shipped_data()
    if bits not in data:
        raise ParameterError(f"no shipped group of {bits} bits; shipped sizes: {sorted(data)}")
    group = GroupParams.from_dict(data[bits])
    if group.bits != bits:
        raise GroupError(f"shipped group labelled {bits} bits has {group.bits} bits")
    return group.verify()


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


if __name__ == "__main__":  # pragma: no cover
    write_shipped_groups()
