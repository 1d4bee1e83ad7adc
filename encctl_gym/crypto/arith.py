"""Big-integer arithmetic and randomness: the only module of :mod:`encctl_gym.crypto` that
talks to gmpy2 directly (as ``phe.util`` does in python-paillier).

Everything above this layer (groups, ElGamal, the encrypted controller) calls
:func:`powmod`, :func:`mulmod`, :func:`invert`, :func:`is_prime`, :func:`jacobi` and a
:class:`RandomSource`, never gmpy2 or :func:`pow` itself. That keeps the fast backend
swappable and lets :func:`powmod` count its calls (the benchmark reports the number of
modular exponentiations per control step, see :class:`PowmodCounter`).

Randomness
----------
Every function of the package that needs random numbers takes ``rng``:

* ``None``: a cryptographically secure source (:func:`secure_random`, ``secrets``/``os.urandom``);
* an ``int`` seed, or a :class:`numpy.random.Generator`: a *seeded, reproducible and
  therefore UNSAFE* source (:func:`seeded_random`), meant for reproducible experiments only;
* a :class:`RandomSource` instance, used as is.
"""

from __future__ import annotations

import numbers
import secrets
from typing import Any, Union

import gmpy2
import numpy as np

from .._validation import check_int
from ..errors import ParameterError

__all__ = [
    "mpz",
    "powmod",
    "mulmod",
    "invert",
    "is_prime",
    "jacobi",
    "legendre",
    "bit_length",
    "PowmodCounter",
    "powmod_count",
    "RandomSource",
    "SecureRandom",
    "SeededRandom",
    "secure_random",
    "seeded_random",
    "as_random_source",
    "RngLike",
]

mpz = gmpy2.mpz

# Number of calls of :func:`powmod` in this process (read via :func:`powmod_count`).
_POWMOD_CALLS = 0


def powmod(base: int, exp: int, mod: int) -> int:
    """Return ``base ** exp mod mod`` (gmpy2; a negative ``exp`` uses the modular inverse).

    The single modular-exponentiation primitive of the package (Example ex:elgamal and all
    schemes above it); every call is counted, see :class:`PowmodCounter`.

    Parameters
    ----------
    base, exp, mod : int
        Integers (Python ``int`` or ``gmpy2.mpz``); ``mod`` > 1.

    Returns
    -------
    gmpy2.mpz
        The residue in ``[0, mod)``.
    """
    global _POWMOD_CALLS
    _POWMOD_CALLS += 1
    try:
        return gmpy2.powmod(base, exp, mod)
    except (ValueError, ZeroDivisionError) as exc:  # e.g. no inverse for a negative exponent
        raise ParameterError(f"powmod({base!r}, {exp!r}, {mod!r}) is undefined: {exc}") from exc


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

    def __enter__(self) -> "PowmodCounter":
        self.start = _POWMOD_CALLS
        self.count = 0
        return self

    def __exit__(self, *exc: Any) -> None:
        self.count = _POWMOD_CALLS - self.start


def mulmod(a: int, b: int, mod: int) -> int:
    """Return ``a * b mod mod`` with gmpy2 integers (the Eval of Example ex:elgamal)."""
    return gmpy2.f_mod(gmpy2.mul(a, b), mod)


def invert(a: int, mod: int) -> int:
    """Return the inverse of ``a`` modulo ``mod``.

    Raises
    ------
    ParameterError
        If ``a`` has no inverse modulo ``mod`` (``gcd(a, mod) != 1``).
    """
    try:
        return gmpy2.invert(a, mod)
    except ZeroDivisionError as exc:
        raise ParameterError(f"{a} has no inverse modulo {mod}") from exc


def is_prime(n: int, reps: int = 25) -> bool:
    """Probabilistic primality test (gmpy2/GMP: trial division, BPSW, then Miller-Rabin).

    With GMP >= 6.2 this is a Baillie-PSW test plus ``reps - 24`` Miller-Rabin rounds; no
    BPSW pseudoprime is known. Used for the primes p and q of Example ex:elgamal.

    Parameters
    ----------
    n : int
        The number to test; values < 2 are not prime.
    reps : int, default 25
        Repetitions passed to ``gmpy2.is_prime``.
    """
    if n < 2:
        return False
    return bool(gmpy2.is_prime(n, reps))


def jacobi(a: int, n: int) -> int:
    """Jacobi symbol (a/n) for odd n > 0; equals the Legendre symbol when n is prime.

    For a safe prime p = 2q + 1, ``jacobi(m, p) == 1`` iff m is a quadratic residue, i.e.
    iff m lies in the order-q subgroup of Example ex:elgamal. One call costs about as much
    as a few multiplications, far less than a modular exponentiation.
    """
    return int(gmpy2.jacobi(a, n))


def legendre(a: int, p: int) -> int:
    """Legendre symbol (a/p) for an odd prime p (see :func:`jacobi`)."""
    return int(gmpy2.legendre(a, p))


def bit_length(n: int) -> int:
    """Number of bits of ``|n|`` (0 for 0); the bit length of p is the group's ``bits``."""
    return int(gmpy2.mpz(n).bit_length())


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
        """Return an integer uniform in ``[low, high)``; requires ``low < high``."""
        if not high > low:
            raise ParameterError(f"empty range [{low}, {high})")
        return low + self.below(high - low)

    def randbits(self, k: int) -> int:
        """Return an integer uniform in ``[0, 2**k)``."""
        return self.below(1 << k)

    @staticmethod
    def _check_n(n: int) -> int:
        if type(n) is int and n >= 1:  # fast path
            return n
        if isinstance(n, bool) or not isinstance(n, (numbers.Integral, type(mpz(0)))):
            raise ParameterError(f"the bound n must be an integer, got {n!r}")
        if n < 1:
            raise ParameterError(f"the bound n must be >= 1, got {n}")
        return n


class SecureRandom(RandomSource):
    """Cryptographically secure randomness from the operating system (``secrets``)."""

    secure = True

    def below(self, n: int) -> int:
        n = self._check_n(n)
        return secrets.randbelow(int(n))

    def __repr__(self) -> str:
        return "SecureRandom()"


class SeededRandom(RandomSource):
    """Reproducible randomness from a seed (GMP's Mersenne Twister via ``gmpy2.random_state``).

    .. warning:: UNSAFE for deployment: anybody who knows or guesses the seed can recompute
       every key and every encryption randomness. Use only for reproducible experiments
       and tests.
    """

    secure = False

    def __init__(self, seed: int) -> None:
        self.seed = check_int("seed", seed, minimum=0)
        self._state = gmpy2.random_state(self.seed)

    def below(self, n: int) -> int:
        n = self._check_n(n)
        return int(gmpy2.mpz_random(self._state, n))

    def __repr__(self) -> str:
        return f"SeededRandom(seed={self.seed})"


def secure_random() -> SecureRandom:
    """Return the default, cryptographically secure :class:`RandomSource`."""
    return SecureRandom()


def seeded_random(seed: int) -> SeededRandom:
    """Return a reproducible :class:`RandomSource` from a non-negative integer seed.

    UNSAFE for deployment (see :class:`SeededRandom`); for reproducible experiments only.
    """
    return SeededRandom(seed)


RngLike = Union[None, int, RandomSource, np.random.Generator]


def as_random_source(rng: RngLike) -> RandomSource:
    """Normalise the ``rng`` argument accepted throughout :mod:`encctl_gym.crypto`.

    Parameters
    ----------
    rng : None, int, numpy.random.Generator or RandomSource
        ``None`` gives :func:`secure_random`; an int seed gives :func:`seeded_random`; a
        NumPy generator gives a seeded source whose seed is drawn from it (reproducible,
        unsafe for deployment); a :class:`RandomSource` is returned unchanged.

    Raises
    ------
    ParameterError
        For any other type, or a negative seed.
    """
    if rng is None:
        return SecureRandom()
    if isinstance(rng, RandomSource):
        return rng
    if isinstance(rng, np.random.Generator):
        return SeededRandom(int(rng.integers(0, 2**63 - 1)))
    if isinstance(rng, bool) or not isinstance(rng, (numbers.Integral, np.integer)):
        raise ParameterError(
            f"rng must be None, an int seed, a numpy Generator or a RandomSource, got {rng!r}"
        )
    return SeededRandom(int(rng))
