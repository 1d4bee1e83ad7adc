"""Big-integer arithmetic and randomness: the only module of :mod:`encctl_gym.crypto` that
talks to gmpy2 directly (as ``phe.util`` does in python-paillier).

Everything above this layer (groups, ElGamal, the encrypted controller) calls
:func:`powmod`, :func:`mulmod`, :func:`invert`, :func:`is_prime`, :func:`jacobi`,
:func:`legendre` and a :class:`RandomSource`, never gmpy2 or :func:`pow` itself. That keeps
the fast backend swappable and lets :func:`powmod` count its calls (the benchmark reports the
number of modular exponentiations per control step, see :class:`PowmodCounter`).

Randomness
----------
The exponents of Example ex:elgamal and ex:dyn_elgamal (the secret key s, the encryption
randomness r, the updated key s', the re-randomisation r of CtUpd) and the starting point of
the safe-prime search are drawn from a :class:`RandomSource`. Every function that needs random
numbers takes ``rng``:

* ``None``: a cryptographically secure source (:func:`secure_random`, ``secrets``);
* a :class:`RandomSource` *stream* (e.g. ``seeded_random(seed)``), used as is: every draw
  continues the stream, so passing one stream to many calls gives fresh numbers each time;
* a :class:`numpy.random.Generator`: a seeded stream whose 256-bit key is drawn from the
  generator at each call (reproducible when the generator is);
* an ``int`` seed, only where the call is made once per object or per experiment (key and
  group generation, the parties of the encrypted controller): it becomes the stream
  ``seeded_random(seed, purpose)``, *keyed by the purpose of the call* (``"group"`` for the
  prime search, ``"keygen"`` for s, ...), so one seed never feeds two purposes with the same
  numbers (a secret key that followed from the public prime by a short scan was the result of
  that mistake).

Functions that draw fresh randomness on every call (Enc, KeyUpd, CtUpd, the forging of an
injected input) refuse a bare int seed (:func:`as_random_stream`): the same int would repeat
r on every call (``c1`` would equal ``h`` after ``keygen(..., rng=5)``, and the quotient of two
ciphertexts would reveal the quotient of their plaintexts). Pass one stream instead.

Seeded streams are UNSAFE for deployment (whoever knows or guesses the seed recomputes every
key); they exist for reproducible experiments and tests. A stream is SHAKE-256 in counter mode
under a key derived from (seed, purpose); :meth:`RandomSource.spawn` derives independent child
streams, one way (a child cannot recompute its parent's draws), so that the parties of a
protocol can each hold their own.
"""

from __future__ import annotations

import hashlib
import numbers
import secrets
from typing import Any

import gmpy2
import numpy as np

from .._validation import check_int, format_value
from ..errors import ParameterError

__all__ = [
    "mpz",
    "check_integer",
    "MAX_PRIMALITY_REPS",
    "powmod",
    "mulmod",
    "invert",
    "gcd",
    "is_prime",
    "jacobi",
    "legendre",
    "format_int",
    "PowmodCounter",
    "powmod_count",
    "RandomSource",
    "SecureRandom",
    "SeededRandom",
    "secure_random",
    "seeded_random",
    "as_random_source",
    "as_random_stream",
    "check_rng",
    "RngLike",
]

mpz = gmpy2.mpz

# Number of calls of :func:`powmod` in this process (read via :func:`powmod_count`).
_POWMOD_CALLS = 0


_MPZ = type(gmpy2.mpz(0))
_INT_TYPES = (int, _MPZ)

#: Largest number of Miller-Rabin repetitions :func:`is_prime` accepts (GMP's own default is 25).
MAX_PRIMALITY_REPS = 1000


def check_integer(name: str, value: Any) -> int:
    """``value`` as an integer for the big-integer arithmetic, by the package's one rule
    (:func:`encctl_gym._validation.check_int`: exact integers, and integral floats up to 2^53;
    no bool, no string), else a :class:`ParameterError` naming it.

    An ``int`` or a ``gmpy2.mpz`` is returned as it is (the fast path of every exponentiation);
    anything else accepted is returned as a Python int.
    """
    if type(value) is int or type(value) is _MPZ:  # fast path (hot in every exponentiation)
        return value
    return check_int(name, value)


def _check_modulus(name: str, mod: Any) -> int:
    mod = check_integer(name, mod)
    if mod <= 1:
        raise ParameterError(f"{name} must be an integer > 1, got {format_int(mod)}")
    return mod


def powmod(base: int, exp: int, mod: int) -> int:
    """Return ``base ** exp mod mod`` (gmpy2; a negative ``exp`` uses the modular inverse).

    The single modular-exponentiation primitive of the package (Example ex:elgamal and all
    schemes above it); every call is counted, see :class:`PowmodCounter`.

    Parameters
    ----------
    base, exp, mod : int
        Integers (Python ``int``, ``gmpy2.mpz`` or a NumPy integer); ``mod`` > 1.

    Returns
    -------
    gmpy2.mpz
        The residue in ``[0, mod)``.

    Raises
    ------
    ParameterError
        If an argument is not an integer, ``mod <= 1`` (a negative modulus would give a
        residue in ``(mod, 0]``), or ``exp < 0`` and ``base`` has no inverse modulo ``mod``.
    """
    global _POWMOD_CALLS
    if not (type(base) in _INT_TYPES and type(exp) in _INT_TYPES and type(mod) in _INT_TYPES and mod > 1):
        base, exp = check_integer("base", base), check_integer("exp", exp)
        mod = _check_modulus("mod", mod)
    _POWMOD_CALLS += 1
    try:
        return gmpy2.powmod(base, exp, mod)
    except (ValueError, ZeroDivisionError) as exc:  # e.g. no inverse for a negative exponent
        raise ParameterError(f"powmod({format_int(base)}, {format_int(exp)}, {format_int(mod)}) is undefined: {exc}") from exc


def powmod_count() -> int:
    """Return the number of :func:`powmod` calls made so far in this process."""
    return _POWMOD_CALLS


class PowmodCounter:
    """Context manager counting the modular exponentiations made inside a ``with`` block.

    Examples
    --------
    >>> with PowmodCounter() as c:
    ...     _ = powmod(3, 5, 7)
    >>> c.count
    1
    """

    def __init__(self) -> None:
        self.start = 0
        self.count = 0

    def __enter__(self) -> PowmodCounter:
        self.start = _POWMOD_CALLS
        self.count = 0
        return self

    def __exit__(self, *exc: Any) -> None:
        self.count = _POWMOD_CALLS - self.start


def mulmod(a: int, b: int, mod: int) -> int:
    """Return ``a * b mod mod`` with gmpy2 integers (the Eval of Example ex:elgamal).

    Raises
    ------
    ParameterError
        If an argument is not an integer or ``mod <= 1`` (as :func:`powmod`).
    """
    if not (type(a) in _INT_TYPES and type(b) in _INT_TYPES and type(mod) in _INT_TYPES and mod > 1):
        a, b = check_integer("a", a), check_integer("b", b)
        mod = _check_modulus("mod", mod)
    return gmpy2.f_mod(gmpy2.mul(a, b), mod)


def invert(a: int, mod: int) -> int:
    """Return the inverse of ``a`` modulo ``mod`` (in ``[1, mod)``).

    Raises
    ------
    ParameterError
        If ``a`` or ``mod`` is not an integer, ``mod <= 1`` (modulo 1 every number is 0, and a
        negative modulus is not a residue class), or ``a`` has no inverse modulo ``mod``
        (``gcd(a, mod) != 1``).
    """
    a = check_integer("a", a)
    mod = _check_modulus("mod", mod)
    try:
        return gmpy2.invert(a, mod)
    except ZeroDivisionError as exc:
        raise ParameterError(f"{format_int(a)} has no inverse modulo {format_int(mod)}") from exc


def gcd(a: int, b: int) -> int:
    """Return ``gcd(a, b) >= 0`` (gmpy2; the Paillier checks of ``Z_n^*`` and the factoring breakers).

    Raises
    ------
    ParameterError
        If an argument is not an integer.
    """
    if not (type(a) in _INT_TYPES and type(b) in _INT_TYPES):
        a, b = check_integer("a", a), check_integer("b", b)
    return gmpy2.gcd(a, b)


def is_prime(n: int, reps: int = 25) -> bool:
    """Probabilistic primality test (gmpy2/GMP: trial division, BPSW, then Miller-Rabin).

    With GMP >= 6.2 this is a Baillie-PSW test plus ``reps - 24`` Miller-Rabin rounds; no
    BPSW pseudoprime is known. Used for the primes p and q of Example ex:elgamal.

    Parameters
    ----------
    n : int
        The number to test; values < 2 are not prime.
    reps : int, default 25
        Repetitions passed to ``gmpy2.is_prime``, in ``[1, MAX_PRIMALITY_REPS]``.

    Raises
    ------
    ParameterError
        If ``n`` is not an integer or ``reps`` is not an integer in range.
    """
    n = check_integer("n", n)
    if type(reps) is not int or not 1 <= reps <= MAX_PRIMALITY_REPS:
        reps = check_int("reps", reps, minimum=1, maximum=MAX_PRIMALITY_REPS)
    if n < 2:
        return False
    return bool(gmpy2.is_prime(n, reps))


def jacobi(a: int, n: int) -> int:
    """Jacobi symbol (a/n) for odd n > 0; equals the Legendre symbol when n is prime.

    For a safe prime p = 2q + 1, ``jacobi(m, p) == 1`` iff m is a quadratic residue, i.e.
    iff m lies in the order-q subgroup of Example ex:elgamal. One call costs about as much
    as a few multiplications, far less than a modular exponentiation.

    Raises
    ------
    ParameterError
        If ``a`` or ``n`` is not an integer, or ``n`` is not odd and positive (the symbol is
        undefined there).
    """
    if not (type(a) in _INT_TYPES and type(n) in _INT_TYPES and n > 0):
        a, n = check_integer("a", a), check_integer("n", n)
        if n <= 0:  # gmpy2 would return a symbol for a negative odd n
            raise ParameterError(f"the Jacobi symbol (a/n) needs an odd n > 0, got n = {format_int(n)}")
    try:
        return int(gmpy2.jacobi(a, n))
    except ValueError:  # gmpy2 refuses an even n
        raise ParameterError(f"the Jacobi symbol (a/n) needs an odd n > 0, got n = {format_int(n)}") from None


def legendre(a: int, p: int) -> int:
    """Legendre symbol (a/p) for an odd prime p (see :func:`jacobi`).

    Raises
    ------
    ParameterError
        If ``a`` or ``p`` is not an integer, or ``p`` is not an odd prime (for a composite p
        the value would be the Jacobi symbol, which does not tell quadratic residues; callers
        that already know p is prime use :func:`jacobi`, which skips the primality test).
    """
    a, p = check_integer("a", a), check_integer("p", p)
    if p < 3 or p % 2 == 0 or not is_prime(p):
        raise ParameterError(f"the Legendre symbol (a/p) needs an odd prime p, got p = {format_int(p)}")
    return int(gmpy2.legendre(a, p))


def format_int(n: Any) -> str:
    """An integer for an error message or a repr: decimal up to 256 bits, else abbreviated hex.

    Python refuses to convert integers of more than 4300 decimal digits to text, so a message
    that printed such a number in decimal would itself raise; ``0x1234abcd...89ef (N bits)``
    always works and still tells numbers apart.
    """
    try:
        v = int(n)
    except (TypeError, ValueError):
        return repr(n)
    if abs(v).bit_length() <= 256:
        return str(v)
    h = hex(v)
    return f"{h[:14]}...{h[-8:]} ({abs(v).bit_length()} bits)"


# --------------------------------------------------------------------------- randomness
class RandomSource:
    """Source of uniform random integers for the cryptographic algorithms.

    Subclasses implement :meth:`below`. ``secure`` tells whether the source is suitable for
    deployment (only :class:`SecureRandom` is).
    """

    secure: bool = False

    def below(self, n: int) -> int:
        """Return an integer uniform in ``[0, n)``; ``n`` must be >= 1."""
        raise NotImplementedError

    def between(self, low: int, high: int) -> int:
        """Return an integer uniform in ``[low, high)``; requires integers ``low < high``.

        Raises
        ------
        ParameterError
            If a bound is not an integer, or the range is empty.
        """
        if not (type(low) in _INT_TYPES and type(high) in _INT_TYPES):
            low, high = check_integer("low", low), check_integer("high", high)
        if not high > low:
            raise ParameterError(f"empty range [{format_int(low)}, {format_int(high)})")
        return low + self.below(high - low)

    def spawn(self, purpose: str) -> RandomSource:
        """An independent child stream for another party or purpose.

        The child is keyed by 256 bits drawn from this source and by ``purpose``; knowing the
        child's key does not reveal this source's draws. :class:`SecureRandom` returns a new
        secure source.
        """
        return SeededRandom(self.below(1 << 256), _check_purpose(purpose))

    @staticmethod
    def _check_n(n: int) -> int:
        if type(n) is int and n >= 1:  # fast path
            return n
        if isinstance(n, bool) or not isinstance(n, (numbers.Integral, type(mpz(0)))):
            raise ParameterError(f"the bound n must be an integer, got {format_value(n)}")
        if n < 1:
            raise ParameterError(f"the bound n must be >= 1, got {format_int(n)}")
        return n


class SecureRandom(RandomSource):
    """Cryptographically secure randomness from the operating system (``secrets``)."""

    secure = True

    def below(self, n: int) -> int:
        n = self._check_n(n)
        return secrets.randbelow(int(n))

    def spawn(self, purpose: str) -> SecureRandom:
        _check_purpose(purpose)
        return SecureRandom()

    def __repr__(self) -> str:
        return "SecureRandom()"


def _length_prefixed(data: bytes) -> bytes:
    return len(data).to_bytes(8, "big") + data


def _check_purpose(purpose: Any) -> str:
    if not isinstance(purpose, str):
        raise ParameterError(f"the purpose of a random stream must be a string, got {format_value(purpose)}")
    return purpose


class SeededRandom(RandomSource):
    """Reproducible randomness: SHAKE-256 in counter mode under a key derived from (seed, purpose).

    Draw j of the stream is ``SHAKE-256("draw" || key || j)`` cut to the bit length of the
    bound, with rejection of values >= n (exactly uniform). Streams of different seeds or
    different purposes are independent; so are the children of :meth:`spawn`.

    .. warning:: UNSAFE for deployment: anybody who knows or guesses the seed can recompute
       every key and every encryption randomness. Use only for reproducible experiments
       and tests.

    Parameters
    ----------
    seed : int
        A non-negative integer.
    purpose : str, default ""
        What the stream is for (see the module docstring): the same seed with another purpose
        gives an unrelated stream.
    """

    secure = False

    def __init__(self, seed: int, purpose: str = "") -> None:
        self.seed = check_int("seed", seed, minimum=0)
        self.purpose = _check_purpose(purpose)
        seed_bytes = self.seed.to_bytes((self.seed.bit_length() + 7) // 8, "big")
        material = _length_prefixed(seed_bytes) + _length_prefixed(self.purpose.encode("utf-8"))
        self._key = hashlib.shake_256(b"encctl-gym seed\0" + material).digest(32)
        self._draws = 0
        self._spawned = 0

    def below(self, n: int) -> int:
        n = self._check_n(n)
        bits = (n - 1).bit_length()
        if bits == 0:
            return 0
        nbytes = (bits + 7) >> 3
        drop = 8 * nbytes - bits
        while True:
            block = hashlib.shake_256(b"encctl-gym draw\0" + self._key + self._draws.to_bytes(8, "big")).digest(nbytes)
            self._draws += 1
            v = int.from_bytes(block, "big") >> drop
            if v < n:
                return v

    def spawn(self, purpose: str) -> SeededRandom:
        """An independent child stream keyed by this stream's key, a spawn counter and ``purpose``.

        Spawning does not consume draws of this stream; spawning twice with the same purpose
        gives two different children.
        """
        child = SeededRandom.__new__(SeededRandom)
        child.seed = self.seed
        child.purpose = f"{self.purpose}/{_check_purpose(purpose)}"
        child._key = hashlib.shake_256(
            b"encctl-gym spawn\0" + self._key + self._spawned.to_bytes(8, "big") + _length_prefixed(purpose.encode("utf-8"))
        ).digest(32)
        child._draws = 0
        child._spawned = 0
        self._spawned += 1
        return child

    def __repr__(self) -> str:
        return f"SeededRandom(seed={format_int(self.seed)}, purpose={self.purpose!r})"


def secure_random() -> SecureRandom:
    """Return the default, cryptographically secure :class:`RandomSource`."""
    return SecureRandom()


def seeded_random(seed: int, purpose: str = "") -> SeededRandom:
    """Return a reproducible stream from a non-negative integer seed (and a purpose).

    UNSAFE for deployment (see :class:`SeededRandom`); for reproducible experiments only.
    Pass the returned object to every call that should continue the stream.
    """
    return SeededRandom(seed, purpose)


RngLike = None | int | RandomSource | np.random.Generator


def _generator_seed(gen: np.random.Generator) -> int:
    # 256 bits of key material from the generator (four 64-bit words).
    words = gen.integers(0, 2**64, size=4, dtype=np.uint64)
    return int.from_bytes(words.astype(">u8").tobytes(), "big")


def as_random_source(rng: RngLike, purpose: str = "") -> RandomSource:
    """Normalise the ``rng`` argument of calls made once per object (keys, groups, parties).

    Parameters
    ----------
    rng : None, int, numpy.random.Generator or RandomSource
        ``None`` gives :func:`secure_random`; an int seed gives ``seeded_random(seed,
        purpose)``; a NumPy generator gives a seeded stream keyed by 256 bits drawn from it
        (reproducible, unsafe for deployment); a :class:`RandomSource` is returned unchanged.
    purpose : str, default ""
        The purpose an int seed (or a generator's draw) is keyed by (module docstring).

    Raises
    ------
    ParameterError
        For any other type, or a negative seed.
    """
    rng = check_rng(rng)
    if rng is None:
        return SecureRandom()
    if isinstance(rng, RandomSource):
        return rng
    if isinstance(rng, np.random.Generator):
        return SeededRandom(_generator_seed(rng), purpose)
    return SeededRandom(int(rng), purpose)


def check_rng(rng: Any, name: str = "rng") -> RngLike:
    """Check the type of an ``rng`` argument without drawing from it; return it unchanged.

    For calls that take ``rng`` but may not need it (a shipped group is not generated): a bad
    value is refused all the same, and a generator or stream is left untouched.

    Raises
    ------
    ParameterError
        Unless ``rng`` is None, an int seed >= 0, a numpy Generator or a :class:`RandomSource`.
    """
    if rng is None or isinstance(rng, (RandomSource, np.random.Generator)):
        return rng
    if isinstance(rng, bool) or not isinstance(rng, (numbers.Integral, np.integer)):
        raise ParameterError(f"{name} must be None, an int seed, a numpy Generator or a RandomSource, got {format_value(rng)}")
    return check_int(f"the seed {name}", rng, minimum=0)


def as_random_stream(rng: RngLike, caller: str) -> RandomSource:
    """Normalise ``rng`` for a call that needs fresh randomness every time (Enc, KeyUpd, CtUpd, ...).

    As :func:`as_random_source`, except that a bare int seed is refused: it would restart the
    same stream at every call and repeat the randomness (module docstring).

    Parameters
    ----------
    rng : None, numpy.random.Generator or RandomSource
    caller : str
        The name of the calling function, for the error message.

    Raises
    ------
    ParameterError
        For an int seed (naming it and the stream to pass instead) or another bad type.
    """
    if rng is None:
        return SecureRandom()
    if isinstance(rng, RandomSource):
        return rng
    if isinstance(rng, (numbers.Integral, np.integer)) and not isinstance(rng, bool):
        raise ParameterError(
            f"{caller} draws fresh randomness at every call, so the int seed rng={format_int(rng)} "
            f"would repeat it; pass one stream and reuse it, e.g. rng=seeded_random({format_int(rng)})"
        )
    return as_random_source(rng, caller)
