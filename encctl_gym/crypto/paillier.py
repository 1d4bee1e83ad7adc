"""Paillier encryption: KeyGen, Enc, Dec and the additive Eval (P. Paillier, "Public-Key
Cryptosystems Based on Composite Degree Residuosity Classes", EUROCRYPT 1999, LNCS 1592,
Scheme 1, with the generator ``g = n + 1`` as in python-paillier and ECLib's ``paillier``).

KeyGen(k)
    two random primes ``p != q`` of ``ceil(k/2)`` and ``floor(k/2)`` bits, each with its two top
    bits set, so that ``n = p q`` has exactly ``k`` bits; ``gcd(n, (p-1)(q-1)) = 1`` is checked.
    ``pk = n`` (and ``g = n + 1``), ``sk = (lambda, mu)`` with ``lambda = lcm(p-1, q-1)`` and
    ``mu = L(g^lambda mod n^2)^-1 mod n = lambda^-1 mod n`` (``L(u) = (u - 1)/n``).
Enc(pk, m)
    ``c = g^m r^n = (1 + m n) r^n mod n^2`` for ``m`` in ``Z_n`` and ``r`` uniform in ``Z_n^*``.
Dec(sk, c)
    ``m = L(c^lambda mod n^2) mu mod n``; computed with the Chinese remainder theorem modulo p^2
    and q^2 (Paillier 1999, Section 7), which gives the same m about four times faster;
    :func:`decrypt_textbook` is the formula as written (the tests compare the two).
Eval (additive homomorphism)
    ``Dec(c1 c2 mod n^2) = m1 + m2 mod n`` (:func:`add`), ``Dec(c^k mod n^2) = k m mod n``
    for any integer k (:func:`scalar_mult`; a negative k uses the inverse of c), and
    ``Dec(c g^a) = m + a`` (:func:`add_plain`). Only additions and plaintext multiples: the
    server of the encrypted controller must hold Phi in plaintext
    (:mod:`.paillier_controller`).

Objects are small frozen dataclasses over plain functions (as in python-paillier). A
ciphertext carries its public key; combining objects of different moduli raises
:class:`~encctl_gym.errors.KeyMismatchError`. A plaintext is an integer of ``[0, n)``
(:class:`~encctl_gym.errors.PlaintextError` otherwise); signed values are the encoder's
(:mod:`.paillier_controller`). A ciphertext is an integer of ``[1, n^2)`` prime to n
(:class:`~encctl_gym.errors.CiphertextError` otherwise).

Key rotation is a fresh modulus (a new KeyGen); :func:`measure_keygen_seconds` measures what it
costs, off the control path. Randomness follows :mod:`.arith`: :func:`keygen` accepts an int
seed (keyed by the purpose ``"paillier-keygen"``), :func:`encrypt` draws a fresh r at every call
and refuses a bare int seed.
"""

from __future__ import annotations

import dataclasses
import math
import statistics
import time
from typing import Any

from .._validation import check_int, format_value
from ..errors import CiphertextError, KeyMismatchError, ParameterError, PlaintextError
from . import arith
from .arith import RngLike
from .arith import format_int as fmt

__all__ = [
    "MIN_MODULUS_BITS",
    "MAX_MODULUS_BITS",
    "PaillierPublicKey",
    "PaillierSecretKey",
    "PaillierCiphertext",
    "KeygenTiming",
    "keygen",
    "random_prime",
    "secret_key_from_factors",
    "encrypt",
    "encrypt_with_secret",
    "decrypt",
    "decrypt_textbook",
    "add",
    "add_plain",
    "scalar_mult",
    "check_plaintext",
    "check_ciphertext",
    "measure_keygen_seconds",
]

#: Smallest modulus length of :func:`keygen` (two primes of 8 bits: a toy for the breakers' tests).
MIN_MODULUS_BITS = 16
#: Largest modulus length of :func:`keygen` (twice NIST's 3072-bit level and more; a bound before work).
MAX_MODULUS_BITS = 8192


def _check_bits(bits: Any) -> int:
    return check_int("modulus bits k", bits, MIN_MODULUS_BITS, MAX_MODULUS_BITS)


@dataclasses.dataclass(frozen=True, slots=True, repr=False)
class PaillierPublicKey:
    """Public key ``n = p q`` of Paillier's Scheme 1 with ``g = n + 1``.

    Attributes
    ----------
    n : int
        The modulus (odd, at least :data:`MIN_MODULUS_BITS` bits).

    Raises
    ------
    ParameterError
        If ``n`` is not an odd integer of at least :data:`MIN_MODULUS_BITS` bits.
    """

    n: int

    def __post_init__(self) -> None:
        n = self.n
        if isinstance(n, bool) or not isinstance(n, int) and type(n).__name__ != "mpz":
            n = check_int("modulus n", n)
        n = int(n)
        if n.bit_length() < MIN_MODULUS_BITS or n % 2 == 0:
            raise ParameterError(f"a Paillier modulus n must be odd with at least {MIN_MODULUS_BITS} bits, got n = {fmt(n)}")
        object.__setattr__(self, "n", n)

    @property
    def n2(self) -> int:
        """``n^2``, the ciphertext modulus."""
        return self.n * self.n

    @property
    def g(self) -> int:
        """The generator ``g = n + 1``."""
        return self.n + 1

    @property
    def bits(self) -> int:
        """Bit length k of n."""
        return self.n.bit_length()

    def __repr__(self) -> str:
        return f"PaillierPublicKey(bits={self.bits}, n={fmt(self.n)})"


@dataclasses.dataclass(frozen=True, repr=False)
class PaillierSecretKey:
    """Secret key of Paillier's Scheme 1: the factors ``p, q`` of n, and ``(lambda, mu)``.

    ``lambda = lcm(p-1, q-1)``, ``mu = lambda^-1 mod n`` (``g = n + 1``), and the CRT constants of
    Section 7 are computed once here; the factors are hidden from ``repr``.

    Raises
    ------
    ParameterError
        If ``p q != n``, ``p = q``, a factor is not prime, or ``gcd(n, (p-1)(q-1)) != 1``.
    """

    public: PaillierPublicKey
    p: int = dataclasses.field(repr=False)
    q: int = dataclasses.field(repr=False)
    lam: int = dataclasses.field(init=False, repr=False)
    mu: int = dataclasses.field(init=False, repr=False)
    _crt: tuple[int, ...] = dataclasses.field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.public, PaillierPublicKey):
            raise ParameterError(f"public must be a PaillierPublicKey, got {format_value(self.public)}")
        p, q = int(check_int("p", self.p)), int(check_int("q", self.q))
        n = self.public.n
        if p * q != n or p == q or not (arith.is_prime(p) and arith.is_prime(q)):
            raise ParameterError(f"p and q must be two distinct primes with p q = n = {fmt(n)}")
        if arith.gcd(n, (p - 1) * (q - 1)) != 1:
            raise ParameterError(f"gcd(n, (p-1)(q-1)) must be 1 for the modulus n = {fmt(n)}")
        lam = (p - 1) * (q - 1) // arith.gcd(p - 1, q - 1)
        p2, q2 = p * p, q * q
        # Section 7: h_p = L_p(g^(p-1) mod p^2)^-1 mod p, and the same for q; L_p(u) = (u - 1)/p.
        hp = arith.invert((int(arith.powmod(n + 1, p - 1, p2)) - 1) // p, p)
        hq = arith.invert((int(arith.powmod(n + 1, q - 1, q2)) - 1) // q, q)
        for name, value in (("p", p), ("q", q), ("lam", lam), ("mu", int(arith.invert(lam, n)))):
            object.__setattr__(self, name, value)
        crt = (p2, q2, int(hp), int(hq), int(arith.invert(p, q)), int(arith.invert(p2, q2)))
        object.__setattr__(self, "_crt", crt)

    def __repr__(self) -> str:
        return f"PaillierSecretKey(bits={self.public.bits})"


@dataclasses.dataclass(frozen=True, slots=True, repr=False)
class PaillierCiphertext:
    """A ciphertext ``c`` in ``Z_{n^2}^*`` under ``pk``; ``+`` is :func:`add` (or :func:`add_plain`
    with an int), ``*`` by an int is :func:`scalar_mult`."""

    pk: PaillierPublicKey
    c: int

    def __add__(self, other: Any) -> PaillierCiphertext:
        if isinstance(other, PaillierCiphertext):
            return add(self, other)
        return add_plain(self, other)

    __radd__ = __add__

    def __mul__(self, k: Any) -> PaillierCiphertext:
        return scalar_mult(self, k)

    __rmul__ = __mul__

    def __repr__(self) -> str:
        return f"PaillierCiphertext(bits={self.pk.bits}, c={fmt(self.c)})"


def random_prime(bits: int, rng: arith.RandomSource) -> int:
    """A uniformly random prime of exactly ``bits`` bits with its two top bits set (rejection
    sampling of odd candidates; :func:`~.arith.is_prime`)."""
    bits = check_int("prime bits", bits, 3)
    low = (1 << (bits - 1)) | (1 << (bits - 2))
    while True:
        cand = low + rng.below(1 << (bits - 2)) | 1
        if arith.is_prime(cand):
            return cand


def keygen(bits: int, rng: RngLike = None) -> tuple[PaillierPublicKey, PaillierSecretKey]:
    """KeyGen: a ``bits``-bit modulus ``n = p q`` and its keys (module docstring).

    Parameters
    ----------
    bits : int
        Bit length k of n, in ``[MIN_MODULUS_BITS, MAX_MODULUS_BITS]``.
    rng : None, int, RandomSource or numpy.random.Generator
        ``None``: secure; an int seed is keyed by the purpose ``"paillier-keygen"`` (reproducible,
        unsafe for deployment).

    Returns
    -------
    (PaillierPublicKey, PaillierSecretKey)

    Raises
    ------
    ParameterError
        For a bit length outside the range or a bad ``rng``.
    """
    bits = _check_bits(bits)
    src = arith.as_random_source(rng, "paillier-keygen")
    while True:
        p = random_prime((bits + 1) // 2, src)
        q = random_prime(bits // 2, src)
        n = p * q
        if p != q and arith.gcd(n, (p - 1) * (q - 1)) == 1:
            pk = PaillierPublicKey(n)
            return pk, PaillierSecretKey(pk, p, q)


def secret_key_from_factors(pk: PaillierPublicKey, p: int, q: int) -> PaillierSecretKey:
    """The secret key of ``pk`` from a factorisation ``n = p q`` (what a factoring breaker
    recovers); :class:`ParameterError` if ``p q != n`` or a factor is not prime."""
    if not isinstance(pk, PaillierPublicKey):
        raise ParameterError(f"pk must be a PaillierPublicKey, got {format_value(pk)}")
    p, q = sorted((int(p), int(q)))
    return PaillierSecretKey(pk, p, q)


def check_plaintext(pk: PaillierPublicKey, m: Any) -> int:
    """``m`` as an int after checking it is an integer of ``[0, n)``.

    Raises
    ------
    PlaintextError
        For a non-integer (a float, a string, a bool) or an integer outside ``[0, n)``.
    """
    if type(m) is not int:
        if isinstance(m, bool) or not (isinstance(m, int) or type(m).__name__ in ("mpz", "int64", "int32", "uint64")):
            raise PlaintextError(f"a Paillier plaintext must be an integer of [0, n), got {format_value(m)}")
        m = int(m)
    if not 0 <= m < pk.n:
        raise PlaintextError(f"a Paillier plaintext must lie in [0, n) for the {pk.bits}-bit modulus, got {fmt(m)}")
    return m


def check_ciphertext(pk: PaillierPublicKey, ct: Any) -> PaillierCiphertext:
    """``ct`` after checking it is a :class:`PaillierCiphertext` of ``pk`` with ``c`` in ``Z_{n^2}^*``.

    Raises
    ------
    CiphertextError
        For another type, or ``c`` outside ``[1, n^2)`` or not prime to n.
    KeyMismatchError
        For a ciphertext of another modulus.
    """
    if not isinstance(ct, PaillierCiphertext):
        raise CiphertextError(f"expected a PaillierCiphertext, got {format_value(ct)}")
    if ct.pk.n != pk.n:
        raise KeyMismatchError(f"a ciphertext of the modulus {fmt(ct.pk.n)} used with the key of {fmt(pk.n)}")
    c = ct.c
    if isinstance(c, bool) or not (isinstance(c, int) or type(c).__name__ == "mpz"):
        raise CiphertextError(f"a Paillier ciphertext must be an integer of Z_(n^2)^*, got {format_value(c)}")
    if not 0 < c < pk.n2 or arith.gcd(c, pk.n) != 1:
        raise CiphertextError(f"a Paillier ciphertext must lie in Z_(n^2)^* (in [1, n^2), prime to n), got c = {fmt(c)}")
    return ct


def encrypt(pk: PaillierPublicKey, m: Any, rng: RngLike = None) -> PaillierCiphertext:
    """Enc: ``c = (1 + m n) r^n mod n^2``, r uniform in ``Z_n^*`` (fresh at every call).

    Raises
    ------
    PlaintextError
        If ``m`` is not an integer of ``[0, n)``.
    ParameterError
        For a bare int seed as ``rng`` (it would repeat r; see :mod:`.arith`).
    """
    m = check_plaintext(pk, m)
    src = arith.as_random_stream(rng, "paillier.encrypt")
    n, n2 = pk.n, pk.n2
    r = _draw_r(n, src)
    return PaillierCiphertext(pk, int(arith.mulmod(1 + m * n, arith.powmod(r, n, n2), n2)))


def _draw_r(n: int, src: arith.RandomSource) -> int:
    while True:
        r = src.between(1, n)
        if arith.gcd(r, n) == 1:
            return r


def encrypt_with_secret(sk: PaillierSecretKey, m: Any, rng: RngLike = None) -> PaillierCiphertext:
    """Enc by the key's owner (the plant): the same ciphertext as :func:`encrypt` for the same
    r, with ``r^n mod n^2`` computed by the CRT modulo ``p^2`` and ``q^2`` (exponents reduced
    modulo ``p(p-1)`` and ``q(q-1)``), about three times faster.

    Raises
    ------
    PlaintextError, ParameterError
        As :func:`encrypt`.
    """
    pk = sk.public
    m = check_plaintext(pk, m)
    src = arith.as_random_stream(rng, "paillier.encrypt_with_secret")
    n, n2 = pk.n, pk.n2
    r = _draw_r(n, src)
    p2, q2 = sk._crt[0], sk._crt[1]
    rp = int(arith.powmod(r % p2, n % (p2 - sk.p), p2))
    rq = int(arith.powmod(r % q2, n % (q2 - sk.q), q2))
    rn = rp + (rq - rp) * sk._crt[5] % q2 * p2
    return PaillierCiphertext(pk, int(arith.mulmod(1 + m * n, rn, n2)))


def decrypt(sk: PaillierSecretKey, ct: Any) -> int:
    """Dec: ``m = L(c^lambda mod n^2) mu mod n``, by the CRT of Paillier 1999, Section 7.

    Returns
    -------
    int
        The plaintext in ``[0, n)``.

    Raises
    ------
    CiphertextError, KeyMismatchError
        As :func:`check_ciphertext`.
    """
    pk = sk.public
    c = check_ciphertext(pk, ct).c
    p, q = sk.p, sk.q
    p2, q2, hp, hq, p_inv_q, _ = sk._crt
    mp = (int(arith.powmod(c % p2, p - 1, p2)) - 1) // p * hp % p
    mq = (int(arith.powmod(c % q2, q - 1, q2)) - 1) // q * hq % q
    return mp + (mq - mp) * p_inv_q % q * p


def decrypt_textbook(sk: PaillierSecretKey, ct: Any) -> int:
    """Dec as written in Scheme 1: ``L(c^lambda mod n^2) mu mod n`` (no CRT)."""
    pk = sk.public
    c = check_ciphertext(pk, ct).c
    return (int(arith.powmod(c, sk.lam, pk.n2)) - 1) // pk.n * sk.mu % pk.n


def add(a: PaillierCiphertext, b: PaillierCiphertext) -> PaillierCiphertext:
    """Eval: ``Enc(m1) Enc(m2) mod n^2``, a ciphertext of ``m1 + m2 mod n``.

    Raises
    ------
    CiphertextError, KeyMismatchError
        For a non-ciphertext or ciphertexts of different moduli.
    """
    if not isinstance(a, PaillierCiphertext) or not isinstance(b, PaillierCiphertext):
        raise CiphertextError(f"add needs two PaillierCiphertext, got {format_value(a)} and {format_value(b)}")
    if a.pk.n != b.pk.n:
        raise KeyMismatchError(f"ciphertexts of different moduli: {fmt(a.pk.n)} and {fmt(b.pk.n)}")
    return PaillierCiphertext(a.pk, int(arith.mulmod(a.c, b.c, a.pk.n2)))


def add_plain(ct: PaillierCiphertext, a: Any) -> PaillierCiphertext:
    """``Enc(m) g^a = Enc(m) (1 + a n) mod n^2``, a ciphertext of ``m + a mod n`` (any integer
    ``a``; no randomness: the result is as random as ``ct``)."""
    if not isinstance(ct, PaillierCiphertext):
        raise CiphertextError(f"add_plain needs a PaillierCiphertext, got {format_value(ct)}")
    if isinstance(a, bool) or not (isinstance(a, int) or type(a).__name__ in ("mpz", "int64", "int32")):
        raise PlaintextError(f"a plaintext to add must be an integer, got {format_value(a)}")
    n, n2 = ct.pk.n, ct.pk.n2
    return PaillierCiphertext(ct.pk, int(arith.mulmod(ct.c, 1 + int(a) % n * n, n2)))


def scalar_mult(ct: PaillierCiphertext, k: Any) -> PaillierCiphertext:
    """``Enc(m)^k mod n^2``, a ciphertext of ``k m mod n`` (any integer k; a negative k raises the
    inverse of c to ``|k|``, which keeps the exponent short for a small signed k).

    Raises
    ------
    PlaintextError
        If ``k`` is not an integer.
    """
    if not isinstance(ct, PaillierCiphertext):
        raise CiphertextError(f"scalar_mult needs a PaillierCiphertext, got {format_value(ct)}")
    if type(k) is not int:
        if isinstance(k, bool) or not (isinstance(k, int) or type(k).__name__ in ("mpz", "int64", "int32")):
            raise PlaintextError(f"a plaintext multiple must be an integer, got {format_value(k)}")
        k = int(k)
    return PaillierCiphertext(ct.pk, int(arith.powmod(ct.c, k, ct.pk.n2)))


@dataclasses.dataclass(frozen=True)
class KeygenTiming:
    """Measured seconds of :func:`keygen` at one modulus length (wall time, this machine).

    Attributes
    ----------
    bits : int
    samples : tuple of float
        Seconds of each KeyGen.
    """

    bits: int
    samples: tuple[float, ...]

    @property
    def mean(self) -> float:
        """Mean seconds of one KeyGen."""
        return statistics.fmean(self.samples)

    @property
    def median(self) -> float:
        """Median seconds of one KeyGen."""
        return statistics.median(self.samples)

    @property
    def stdev(self) -> float:
        """Sample standard deviation (0 for one sample): prime search times vary widely."""
        return statistics.stdev(self.samples) if len(self.samples) > 1 else 0.0

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {"bits": self.bits, "mean": self.mean, "median": self.median, "stdev": self.stdev, "samples": list(self.samples)}


def measure_keygen_seconds(bits: int, repeats: int = 5, rng: RngLike = None) -> KeygenTiming:
    """Run :func:`keygen` ``repeats`` times at ``bits`` bits and record each wall time: the price
    of one rotation (a fresh modulus), paid off the control path.

    Raises
    ------
    ParameterError
        For a bit length outside the range or ``repeats`` outside ``[1, 1000]``.
    """
    bits = _check_bits(bits)
    repeats = check_int("repeats", repeats, 1, 1000)
    src = arith.as_random_source(rng, "paillier-keygen-timing")
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        keygen(bits, src)
        samples.append(time.perf_counter() - t0)
    if not all(math.isfinite(s) for s in samples):  # pragma: no cover - a clock failure
        raise ParameterError("keygen timing gave a non-finite time")
    return KeygenTiming(bits, tuple(samples))
