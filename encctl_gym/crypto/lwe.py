"""Public-key LWE encryption with worst-case noise tracking, and the encrypted linear controller on it.

The scheme is Regev's public-key LWE encryption in the small-secret form of Lindner and Peikert
(R. Lindner, C. Peikert, "Better key sizes (and attacks) for LWE-based encryption", CT-RSA 2011,
Section 3; the same structure as Kyber's CPA scheme without modules or compression):

* **KeyGen**: ``A`` uniform in ``Z_q^{m x n}``, secret ``s`` and error ``e`` from the centred
  binomial distribution ``B_eta`` (``sum_{i<eta} (a_i - b_i)`` of fair bits: mean 0, variance
  ``eta / 2``, support ``[-eta, eta]``); public key ``(A, b = A s + e mod q)``, secret key ``s``.
* **Enc** of an integer ``mu`` with ``|mu| <= (t - 1) / 2``: ``r <- B_eta^m``, ``e1 <- B_eta^n``,
  ``e2 <- B_eta``; ``c1 = A^T r + e1``, ``c2 = b^T r + e2 + Delta_q mu`` (mod q), with the
  scale ``Delta_q = floor(q / t)``.
* **Dec**: ``v = c2 - <c1, s> mod q``, lifted to ``(-q/2, q/2]``, then ``mu = round(v / Delta_q)``.
* **Eval**: addition of ciphertexts and multiplication by integers (mod q, componentwise), so an
  integer matrix ``K`` maps a vector of ciphertexts to ``K ct``, which decrypts to ``K mu``.

**Noise bound** (deterministic, since ``B_eta`` is bounded). For a fresh ciphertext
``v - Delta_q mu = e^T r + e2 - e1^T s``, so ``|v - Delta_q mu| <= B_fresh = eta^2 (m + n) + eta``.
A combination ``sum_j K_ij ct_j`` has noise at most ``sum_j |K_ij| B_j``. Decryption is correct
whenever the noise ``E`` and the message ``M`` satisfy ``2 |E| < Delta_q`` and
``|M| <= (t - 1) / 2`` (then ``|v| < Delta_q t / 2 <= q / 2``, no wrap). Every ciphertext carries
its bound, every operation computes the new one and refuses (before any arithmetic) a result
whose noise bound or message bound could break decryption: a wrong control input is never
produced silently.

**Machine arithmetic**: ciphertexts are numpy ``int64`` arrays with entries in ``[0, q)``. The
largest intermediate value of KeyGen, Enc and Dec is a dot product of ``L = max(m, n)`` terms
``|x| |y| <= (q - 1) eta``, so ``q`` is refused unless ``L eta (q - 1) + q <= 2^63 - 1``
(:func:`max_modulus`); an integer combination ``K ct`` is one int64 product while
``cols(K) max|K| (q - 1) + q <= 2^63 - 1``, and split-word arithmetic beyond (:func:`matmul_mod`:
``K`` in base ``2^w`` digits, Horner's rule modulo q). Overflow is impossible by construction.

**The encrypted controller** ``u = Phi x`` (eq:ec of the paper, with LWE in place of ElGamal):
the plant encodes ``x_int = round(Delta_x x)`` and sends ``Enc(x_int)``; the server holds the
integer matrix ``Phi_int = round(Delta_Phi Phi)`` *in plaintext* (LWE multiplies a ciphertext by
an integer, not by another ciphertext: unlike the paper's ElGamal controller, ``Phi`` is not
hidden from the server) and returns ``Phi_int Enc(x_int)``; the plant decrypts
``Phi_int x_int`` exactly and decodes ``u = Phi_int x_int / (Delta_Phi Delta_x)``, within
:func:`quantization_error_bound` of ``Phi x``.

Randomness: bulk draws for numpy come from a :class:`ByteStream` over a
:class:`~encctl_gym.crypto.arith.RandomSource`: the operating system's generator for a secure
source, SHAKE-256 in counter mode under a key drawn from the source for a seeded one.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import secrets
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_positive, format_value
from ..errors import CiphertextError, EncodingOverflowError, KeyMismatchError, ParameterError, ShapeError
from . import arith
from .arith import RngLike

__all__ = [
    "INT64_MAX",
    "max_modulus",
    "LWEParams",
    "ByteStream",
    "LWEPublicKey",
    "LWESecretKey",
    "LWECiphertext",
    "keygen",
    "keygen_shared",
    "split",
    "add_plaintext",
    "encrypt",
    "decrypt",
    "decryption_noise",
    "add",
    "mult",
    "linear_combination",
    "concatenate",
    "matmul_mod",
    "encode",
    "quantization_error_bound",
    "controller_parameters",
    "LWEController",
]

#: Largest value of a numpy int64.
INT64_MAX = int(np.iinfo(np.int64).max)


def max_modulus(n: int, m: int, eta: int) -> int:
    """The largest modulus ``q`` whose KeyGen, Enc and Dec cannot overflow int64.

    The largest intermediate is a dot product of ``L = max(m, n)`` terms of magnitude at most
    ``(q - 1) eta`` plus one value below ``q``: ``L eta (q - 1) + q <= 2^63 - 1``.
    """
    n, m, eta = check_int("n", n, minimum=1), check_int("m", m, minimum=1), check_int("eta", eta, minimum=1)
    L = max(n, m)
    # L eta (q - 1) + q <= INT64_MAX  <=>  q <= (INT64_MAX + L eta) / (L eta + 1)
    return (INT64_MAX + L * eta) // (L * eta + 1)


@dataclasses.dataclass(frozen=True)
class LWEParams:
    """Parameters of the LWE scheme (module docstring), checked once.

    Attributes
    ----------
    n : int
        Dimension of the secret (the security parameter's main part).
    q : int
        Ciphertext modulus, ``2 <= q <= max_modulus(n, m, eta)``.
    t : int
        Plaintext modulus: messages are integers with ``|mu| <= (t - 1) / 2``; ``2 <= t <= q``.
    eta : int
        Parameter of the centred binomial distribution of ``s``, ``e``, ``r``, ``e1``, ``e2``
        (standard deviation ``sqrt(eta / 2)``, support ``[-eta, eta]``).
    m : int
        Rows of the public matrix ``A`` (samples of the public key); default ``n``.

    Raises
    ------
    ParameterError
        For a non-integer or out-of-range field; ``q`` above :func:`max_modulus` (the int64
        limit is named); a fresh noise bound that already breaks decryption
        (``2 B_fresh >= Delta_q``: the noise is too large for the modulus and plaintext space).
    """

    n: int
    q: int
    t: int
    eta: int = 2
    m: int = 0

    def __post_init__(self) -> None:
        n = check_int("n", self.n, minimum=1)
        eta = check_int("eta", self.eta, minimum=1)
        m = n if self.m in (0, None) else check_int("m", self.m, minimum=1)
        limit = max_modulus(n, m, eta)
        q = check_int("q", self.q, minimum=2)
        if q > limit:
            raise ParameterError(
                f"q = {q} is beyond the int64 arithmetic: with n = {n}, m = {m}, eta = {eta} the largest modulus "
                f"is {limit} (max(m, n) eta (q - 1) + q <= 2^63 - 1)"
            )
        t = check_int("t", self.t, minimum=2, maximum=q)
        for name, value in (("n", n), ("q", q), ("t", t), ("eta", eta), ("m", m)):
            object.__setattr__(self, name, value)
        if 2 * self.fresh_noise_bound >= self.delta_q:
            raise ParameterError(
                f"noise too large for correct decryption: a fresh ciphertext's noise bound eta^2 (m + n) + eta = "
                f"{self.fresh_noise_bound} must be below Delta_q / 2 = floor(q / t) / 2 = {self.delta_q / 2:g} "
                f"(q = {q}, t = {t}); use a larger q, a smaller t or a smaller eta"
            )

    @property
    def delta_q(self) -> int:
        """The message scale ``Delta_q = floor(q / t)``."""
        return self.q // self.t

    @property
    def sigma(self) -> float:
        """Standard deviation ``sqrt(eta / 2)`` of the error distribution."""
        return math.sqrt(self.eta / 2)

    @property
    def fresh_noise_bound(self) -> int:
        """``B_fresh = eta^2 (m + n) + eta``: the largest noise of a fresh ciphertext."""
        return self.eta * self.eta * (self.m + self.n) + self.eta

    @property
    def max_noise(self) -> int:
        """Largest noise decryption tolerates: ``E`` with ``2 E < Delta_q``."""
        return (self.delta_q - 1) // 2

    @property
    def max_message(self) -> int:
        """Largest message magnitude ``(t - 1) // 2``."""
        return (self.t - 1) // 2


class ByteStream:
    """Bulk random bytes and the numpy samples of the scheme from a :class:`RandomSource`.

    A secure source gives the operating system's bytes (``secrets.token_bytes``); any other
    source keys SHAKE-256 in counter mode with 256 bits drawn from it once (reproducible).
    """

    def __init__(self, rng: RngLike = None, purpose: str = "lwe") -> None:
        src = arith.as_random_source(rng, purpose)
        self.secure = bool(src.secure)
        self._key = None if self.secure else src.below(1 << 256).to_bytes(32, "big")
        self._counter = 0

    def bytes(self, k: int) -> bytes:
        """``k`` random bytes."""
        if self._key is None:
            return secrets.token_bytes(k)
        block = hashlib.shake_256(self._key + self._counter.to_bytes(8, "big")).digest(k)
        self._counter += 1
        return block

    def uniform(self, q: int, shape: tuple[int, ...]) -> np.ndarray:
        """Integers uniform in ``[0, q)`` (rejection sampling of ``bits(q - 1)``-bit words), int64."""
        size = int(np.prod(shape, dtype=np.int64))
        bits = max((q - 1).bit_length(), 1)
        mask = np.uint64((1 << bits) - 1)
        out = np.empty(0, dtype=np.int64)
        while out.size < size:
            need = size - out.size
            words = np.frombuffer(self.bytes(8 * (need + need // 2 + 8)), dtype="<u8") & mask
            out = np.concatenate([out, words[words < np.uint64(q)].astype(np.int64)])
        return out[:size].reshape(shape)

    def binomial(self, eta: int, shape: tuple[int, ...]) -> np.ndarray:
        """Samples of the centred binomial distribution ``B_eta`` (int64)."""
        size = int(np.prod(shape, dtype=np.int64))
        nbits = 2 * eta * size
        bits = np.unpackbits(np.frombuffer(self.bytes((nbits + 7) // 8), dtype=np.uint8))[:nbits]
        pairs = bits.reshape(size, 2, eta).astype(np.int64).sum(axis=2)
        return (pairs[:, 0] - pairs[:, 1]).reshape(shape)


@dataclasses.dataclass(frozen=True, eq=False)
class LWEPublicKey:
    """``(A, b = A s + e mod q)``: ``A`` of shape (m, n), ``b`` of shape (m,), int64 in ``[0, q)``."""

    params: LWEParams
    A: np.ndarray = dataclasses.field(repr=False)
    b: np.ndarray = dataclasses.field(repr=False)


@dataclasses.dataclass(frozen=True, eq=False)
class LWESecretKey:
    """The secret ``s`` (shape (n,), entries in ``[-eta, eta]``) and its public key."""

    params: LWEParams
    s: np.ndarray = dataclasses.field(repr=False)
    public: LWEPublicKey = dataclasses.field(repr=False)


@dataclasses.dataclass(frozen=True, eq=False)
class LWECiphertext:
    """A vector of ``k`` ciphertexts: ``c1`` of shape (k, n), ``c2`` of shape (k,), int64 in
    ``[0, q)``, with the worst-case bounds of their noise and of their messages (Python ints).

    ``public`` identifies the key: operations refuse ciphertexts of different keys.
    """

    public: LWEPublicKey = dataclasses.field(repr=False)
    c1: np.ndarray = dataclasses.field(repr=False)
    c2: np.ndarray = dataclasses.field(repr=False)
    noise_bound: tuple[int, ...]
    message_bound: tuple[int, ...]

    def __len__(self) -> int:
        return int(self.c2.shape[0])

    @property
    def params(self) -> LWEParams:
        return self.public.params


def _stream(rng: RngLike | ByteStream, caller: str) -> ByteStream:
    if isinstance(rng, ByteStream):
        return rng
    return ByteStream(arith.as_random_stream(rng, caller))


def keygen(params: LWEParams, rng: RngLike | ByteStream = None) -> tuple[LWEPublicKey, LWESecretKey]:
    """KeyGen: ``A`` uniform, ``s, e <- B_eta``, ``b = A s + e mod q`` (module docstring).

    A matrix ``A`` shared between keys: :func:`keygen_shared`."""
    if not isinstance(params, LWEParams):
        raise ParameterError(f"params must be LWEParams, got {format_value(params)}")
    stream = rng if isinstance(rng, ByteStream) else ByteStream(rng, "lwe keygen")
    A = stream.uniform(params.q, (params.m, params.n))
    return keygen_shared(params, A, stream)


def keygen_shared(params: LWEParams, A: np.ndarray, rng: RngLike | ByteStream = None) -> tuple[LWEPublicKey, LWESecretKey]:
    """KeyGen with a given public matrix ``A`` (a matrix shared across keys, as under key rotation
    with a common reference matrix): fresh ``s, e``, ``b = A s + e mod q``.

    Raises
    ------
    ShapeError
        If ``A`` is not an int64-convertible (m, n) matrix with entries in ``[0, q)``.
    """
    A = np.asarray(A)
    if A.shape != (params.m, params.n) or A.dtype.kind not in "iu" or (A.size and (A.min() < 0 or A.max() >= params.q)):
        raise ShapeError(f"A must be an integer ({params.m}, {params.n}) matrix with entries in [0, q), got {format_value(A)}")
    A = A.astype(np.int64)
    stream = rng if isinstance(rng, ByteStream) else ByteStream(rng, "lwe keygen")
    s = stream.binomial(params.eta, (params.n,))
    e = stream.binomial(params.eta, (params.m,))
    b = (A @ s + e) % params.q
    A.setflags(write=False)
    b.setflags(write=False)
    s.setflags(write=False)
    pk = LWEPublicKey(params, A, b)
    return pk, LWESecretKey(params, s, pk)


def _check_messages(params: LWEParams, mu: Any) -> np.ndarray:
    arr = np.asarray(mu)
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1 or arr.dtype.kind not in "iu" and not (arr.dtype == object):
        raise ParameterError(f"messages must be a 1-D array of integers, got {format_value(mu)}")
    values = [int(v) for v in arr]
    worst = max((abs(v) for v in values), default=0)
    if worst > params.max_message:
        raise EncodingOverflowError(
            f"message {worst} is outside the plaintext range |mu| <= (t - 1) / 2 = {params.max_message} (t = {params.t})"
        )
    return np.array(values, dtype=np.int64)


def encrypt(pk: LWEPublicKey, mu: Any, rng: RngLike | ByteStream = None) -> LWECiphertext:
    """Enc of each integer of ``mu`` (shape (k,)) under ``pk``, vectorised over the k messages.

    Parameters
    ----------
    pk : LWEPublicKey
    mu : array of int
        Messages with ``|mu| <= (t - 1) / 2``.
    rng : RandomSource, numpy Generator, ByteStream or None
        Encryption randomness (a bare int seed is refused: it would repeat ``r``).

    Raises
    ------
    EncodingOverflowError
        For a message outside the plaintext range.
    """
    if not isinstance(pk, LWEPublicKey):
        raise KeyMismatchError(f"pk must be an LWEPublicKey, got {format_value(pk)}")
    p = pk.params
    msg = _check_messages(p, mu)
    stream = _stream(rng, "lwe.encrypt")
    k = msg.shape[0]
    r = stream.binomial(p.eta, (k, p.m))
    e1 = stream.binomial(p.eta, (k, p.n))
    e2 = stream.binomial(p.eta, (k,))
    c1 = (r @ pk.A + e1) % p.q
    c2 = (r @ pk.b + e2 + p.delta_q * msg) % p.q
    worst = tuple(abs(int(v)) for v in msg)
    return LWECiphertext(pk, c1, c2, (p.fresh_noise_bound,) * k, worst)


def _check_ct(ct: Any, what: str = "ct") -> LWECiphertext:
    if not isinstance(ct, LWECiphertext):
        raise CiphertextError(f"{what} must be an LWECiphertext, got {format_value(ct)}")
    return ct


def decryption_noise(sk: LWESecretKey, ct: LWECiphertext) -> tuple[np.ndarray, np.ndarray]:
    """Dec with the noise: ``(mu, v - Delta_q mu)`` for each ciphertext (int64 arrays).

    Raises
    ------
    KeyMismatchError
        For a ciphertext of another key.
    """
    ct = _check_ct(ct)
    if ct.public is not sk.public:
        raise KeyMismatchError("the ciphertext was made under another public key")
    p = sk.params
    v = (ct.c2 - ct.c1 @ sk.s) % p.q
    v = np.where(v > p.q // 2, v - p.q, v)  # centred lift to (-q/2, q/2]
    d = p.delta_q
    mu = np.floor_divide(2 * v + d, 2 * d)  # round(v / d), ties up: |v| < q/2 keeps 2 v + d in int64
    return mu, v - d * mu


def decrypt(sk: LWESecretKey, ct: LWECiphertext) -> np.ndarray:
    """Dec: the messages of ``ct`` (int64 array of shape (k,))."""
    return decryption_noise(sk, ct)[0]


def _same_key(a: LWECiphertext, b: LWECiphertext) -> None:
    if a.public is not b.public:
        raise KeyMismatchError("the ciphertexts were made under different public keys")


def _checked_bounds(p: LWEParams, noise: list[int], message: list[int]) -> tuple[tuple[int, ...], tuple[int, ...]]:
    worst_noise, worst_msg = max(noise, default=0), max(message, default=0)
    if worst_noise > p.max_noise:
        raise EncodingOverflowError(
            f"the result's noise bound {worst_noise} would exceed the decryptable noise (Delta_q - 1) / 2 = {p.max_noise}: "
            "decryption could be wrong; use a larger q or smaller integers"
        )
    if worst_msg > p.max_message:
        raise EncodingOverflowError(
            f"the result's message bound {worst_msg} would exceed the plaintext range (t - 1) / 2 = {p.max_message}: "
            "the sum could wrap modulo t; use a larger t or smaller integers"
        )
    return tuple(noise), tuple(message)


def add(a: LWECiphertext, b: LWECiphertext) -> LWECiphertext:
    """Eval of addition: ``Enc(mu_a) + Enc(mu_b)`` decrypts to ``mu_a + mu_b`` (same shape)."""
    a, b = _check_ct(a, "a"), _check_ct(b, "b")
    _same_key(a, b)
    if len(a) != len(b):
        raise ShapeError(f"cannot add {len(a)} ciphertexts to {len(b)}")
    p = a.params
    noise, msg = _checked_bounds(
        p, [x + y for x, y in zip(a.noise_bound, b.noise_bound)], [x + y for x, y in zip(a.message_bound, b.message_bound)]
    )
    return LWECiphertext(a.public, (a.c1 + b.c1) % p.q, (a.c2 + b.c2) % p.q, noise, msg)


def mult(k: int, ct: LWECiphertext) -> LWECiphertext:
    """Eval of multiplication by the integer ``k``: decrypts to ``k mu``."""
    k = check_int("k", k)
    size = len(_check_ct(ct))
    return linear_combination([[k if i == j else 0 for j in range(size)] for i in range(size)], ct)


def matmul_mod(K: np.ndarray, C: np.ndarray, q: int) -> np.ndarray:
    """``K C mod q`` exactly in int64 for an integer matrix ``K`` (r, k) of any magnitude and
    ``C`` (k, ...) with entries in ``[0, q)``: split-word arithmetic.

    ``|K|`` is written in base ``2^w`` with the largest ``w`` such that ``k 2^w (q - 1) + q <= 2^63 - 1``
    (one digit times ``C`` cannot overflow), and the digits are combined by Horner's rule,
    multiplying by ``2^w`` modulo q as ``w`` doublings (each below ``2 q``). One digit (the usual
    case: small ``K``) is a single matrix product.

    Raises
    ------
    ParameterError
        If even ``w = 1`` overflows (``2 k (q - 1) + q > 2^63 - 1``).
    """
    K = np.asarray(K, dtype=object)
    cols = K.shape[1]
    w = (INT64_MAX - q) // (cols * (q - 1)) if cols else 1
    w = w.bit_length() - 1 if w >= 1 else -1
    if w < 1:
        raise ParameterError(f"a product of {cols} ciphertexts mod q = {q} cannot be computed in int64 even one bit at a time")
    base = 1 << w
    mags = np.vectorize(abs, otypes=[object])(K) if K.size else K
    signs = np.where(K < 0, -1, 1).astype(np.int64) if K.size else np.zeros(K.shape, dtype=np.int64)
    top = max((int(v) for v in mags.ravel()), default=0).bit_length()
    ndigits = max(1, -(-top // w))
    acc = None
    for d in reversed(range(ndigits)):
        digit = np.vectorize(lambda v, d=d: (int(v) >> (w * d)) & (base - 1), otypes=[np.int64])(mags) if K.size else mags
        term = ((signs * digit).astype(np.int64) @ C) % q
        if acc is None:
            acc = term
            continue
        for _ in range(w):
            acc = (2 * acc) % q
        acc = (acc + term) % q
    assert acc is not None
    return acc


def linear_combination(K: Any, ct: LWECiphertext) -> LWECiphertext:
    """Eval of ``K ct`` for an integer matrix ``K`` of shape (r, k): ``r`` ciphertexts, the i-th
    of ``sum_j K_ij Enc(mu_j)``, decrypting to ``(K mu)_i`` (the server's step of eq:ec).

    Raises
    ------
    ShapeError
        If ``K`` is not an integer matrix with ``len(ct)`` columns.
    EncodingOverflowError
        If the result's noise or message bound could break decryption.

    The products are exact for integers of any size (:func:`matmul_mod`).
    """
    ct = _check_ct(ct)
    Kobj = np.asarray(K, dtype=object)
    if Kobj.ndim != 2 or Kobj.shape[1] != len(ct):
        raise ShapeError(f"K must be a matrix with {len(ct)} columns, got {format_value(K)}")
    try:
        Kint = [[check_int("K entry", v) for v in row] for row in Kobj]
    except ParameterError as exc:
        raise ShapeError(f"K must be an integer matrix, got {format_value(K)}") from exc
    p = ct.params
    noise = [sum(abs(v) * bnd for v, bnd in zip(row, ct.noise_bound)) for row in Kint]
    msg = [sum(abs(v) * bnd for v, bnd in zip(row, ct.message_bound)) for row in Kint]
    noise_t, msg_t = _checked_bounds(p, noise, msg)
    Kexact = np.array(Kint, dtype=object).reshape(Kobj.shape)
    kmax = max((abs(v) for row in Kint for v in row), default=0)
    if Kobj.shape[1] * kmax * (p.q - 1) + p.q <= INT64_MAX:  # one word: the direct product
        K64 = Kexact.astype(np.int64)
        return LWECiphertext(ct.public, (K64 @ ct.c1) % p.q, (K64 @ ct.c2) % p.q, noise_t, msg_t)
    return LWECiphertext(ct.public, matmul_mod(Kexact, ct.c1, p.q), matmul_mod(Kexact, ct.c2, p.q), noise_t, msg_t)


def concatenate(*cts: LWECiphertext) -> LWECiphertext:
    """The ciphertext vectors ``cts`` (same key) as one vector, in order."""
    if not cts:
        raise ParameterError("concatenate needs at least one ciphertext vector")
    first = _check_ct(cts[0])
    for ct in cts[1:]:
        _same_key(first, _check_ct(ct))
    return LWECiphertext(
        first.public,
        np.concatenate([ct.c1 for ct in cts]),
        np.concatenate([ct.c2 for ct in cts]),
        tuple(b for ct in cts for b in ct.noise_bound),
        tuple(b for ct in cts for b in ct.message_bound),
    )


def split(ct: LWECiphertext) -> list[LWECiphertext]:
    """The ``k`` ciphertexts of ``ct`` one by one (the inverse of :func:`concatenate`)."""
    ct = _check_ct(ct)
    return [
        LWECiphertext(ct.public, ct.c1[i : i + 1], ct.c2[i : i + 1], (ct.noise_bound[i],), (ct.message_bound[i],))
        for i in range(len(ct))
    ]


def add_plaintext(ct: LWECiphertext, d: Any) -> LWECiphertext:
    """Eval of adding known integers ``d`` (shape (k,)): ``c2 + Delta_q d mod q`` decrypts to
    ``mu + d``; the noise is unchanged, the message bound grows by ``|d|`` (checked first, so
    ``|Delta_q d| <= q / 2`` and the int64 arithmetic is exact). No key is needed.

    Raises
    ------
    ShapeError
        If ``d`` has not one integer per ciphertext.
    EncodingOverflowError
        If a message bound would leave the plaintext space.
    """
    ct = _check_ct(ct)
    vals = [check_int("d", v) for v in np.asarray(d, dtype=object).reshape(-1).tolist()]
    if len(vals) != len(ct):
        raise ShapeError(f"d must have {len(ct)} entries, got {len(vals)}")
    p = ct.params
    noise, msg = _checked_bounds(p, list(ct.noise_bound), [b + abs(v) for b, v in zip(ct.message_bound, vals)])
    shift = np.array([p.delta_q * v for v in vals], dtype=np.int64)
    return LWECiphertext(ct.public, ct.c1, (ct.c2 + shift) % p.q, noise, msg)


def encode(x: Any, scale: float) -> np.ndarray:
    """Ecd of Definition def:ec for LWE: ``round(scale x)`` as int64 (round half to even).

    Raises
    ------
    EncodingOverflowError
        If ``|scale x|`` is beyond 2^53 (no exact integer).
    """
    scale = check_positive("scale", scale)
    arr = as_finite_array("x", x)
    y = np.rint(scale * arr)
    if y.size and float(np.abs(y).max()) > 2.0**53:
        raise EncodingOverflowError(f"scale * x reaches {float(np.abs(y).max()):.3g}, beyond the exact integers of a float")
    return y.astype(np.int64)


def quantization_error_bound(Phi: Any, x: Any, delta_x: float, delta_phi: float) -> np.ndarray:
    """Bound on ``|Phi_int x_int / (Delta_Phi Delta_x) - Phi x|`` per input (shape (m,)).

    With ``Phi_int = Phi Delta_Phi + a``, ``x_int = x Delta_x + c``, ``|a|, |c| <= 1/2``:
    ``|error_i| <= sum_j (|Phi_ij| / (2 Delta_x) + |x_j| / (2 Delta_Phi) + 1 / (4 Delta_Phi Delta_x))``.
    """
    Phi = as_finite_array("Phi", Phi, ndim=2)
    x = as_finite_array("x", x, ndim=1)
    dx, dp = check_positive("delta_x", delta_x), check_positive("delta_phi", delta_phi)
    return np.abs(Phi).sum(axis=1) / (2 * dx) + np.abs(x).sum() / (2 * dp) + Phi.shape[1] / (4 * dp * dx)


def controller_parameters(
    n: int, Phi: Any, delta_x: float, delta_phi: float, x_bound: float, eta: int = 2, *, message_margin: int = 0
) -> LWEParams:
    """The smallest parameters of dimension ``n`` (m = n) on which :class:`LWEController` runs
    ``u = Phi x`` for every ``|x_j| <= x_bound``: ``t = 2 M + 1`` with the message bound
    ``M = max_i ||Phi_int,i||_1 round(Delta_x x_bound) + message_margin``, and ``q = t (2 N + 1)``
    with the noise bound ``N = max_i ||Phi_int,i||_1 B_fresh`` (then ``floor(q / t) = 2 N + 1``,
    ``2 N < Delta_q``). ``message_margin`` reserves room for an integer added to an output
    (:func:`add_plaintext`, the loop's additive injection) or sent in its place.

    Raises
    ------
    ParameterError
        If that ``q`` is beyond :func:`max_modulus` (the int64 arithmetic), naming both.
    """
    n, eta = check_int("n", n, minimum=1), check_int("eta", eta, minimum=1)
    row = int(np.abs(encode(as_finite_array("Phi", Phi, ndim=2), delta_phi)).sum(axis=1).max())
    x_int = int(round(check_positive("delta_x", delta_x) * check_positive("x_bound", x_bound)))
    margin = check_int("message_margin", message_margin, minimum=0)
    t = 2 * max(row * x_int + margin, 1) + 1
    noise = max(row, 1) * (eta * eta * 2 * n + eta)
    return LWEParams(n=n, q=t * (2 * noise + 1), t=t, eta=eta)


class LWEController:
    """The encrypted linear state feedback ``u = Phi x`` over LWE (module docstring).

    The plant side calls :meth:`encrypt_state` and :meth:`decrypt_input`; the server side calls
    :meth:`evaluate` (it needs only ``Phi_int``, public). One check at construction makes every
    step safe: for states with ``|x_j| <= x_bound`` the noise and message bounds of
    ``Phi_int Enc(x_int)`` fit the parameters (else :class:`EncodingOverflowError` names the limit).

    Parameters
    ----------
    params : LWEParams
    Phi : array (m_u, n_x)
        Controller gain.
    delta_x, delta_phi : float
        Scales of the state and of the gain (``x_int = round(Delta_x x)``, ``Phi_int = round(Delta_Phi Phi)``).
    x_bound : float
        Largest ``|x_j|`` the plant encrypts; larger states raise :class:`EncodingOverflowError`.
    rng : RandomSource, numpy Generator or None
        The plant's randomness (keys and encryption).
    """

    def __init__(
        self, params: LWEParams, Phi: Any, delta_x: float, delta_phi: float, x_bound: float, rng: RngLike = None
    ) -> None:
        self.params = params
        self.Phi = as_finite_array("Phi", Phi, ndim=2)
        self.delta_x, self.delta_phi = check_positive("delta_x", delta_x), check_positive("delta_phi", delta_phi)
        self.x_bound = check_positive("x_bound", x_bound)
        self.Phi_int = encode(self.Phi, self.delta_phi)
        self._stream = ByteStream(rng, "lwe controller")
        self.pk, self._sk = keygen(params, self._stream)
        x_int_max = int(round(self.delta_x * self.x_bound))
        # the worst case of one step, checked once (linear_combination re-checks the actual bounds)
        row = np.abs(self.Phi_int).sum(axis=1)
        _checked_bounds(params, [int(v) * params.fresh_noise_bound for v in row], [int(v) * x_int_max for v in row])
        self._x_int_max = x_int_max

    def encrypt_state(self, x: Any) -> LWECiphertext:
        """Plant: ``Enc(round(Delta_x x))`` of the state (shape (n_x,))."""
        x = as_finite_array("x", x, ndim=1)
        if x.shape[0] != self.Phi.shape[1]:
            raise ShapeError(f"x must have {self.Phi.shape[1]} entries, got {x.shape[0]}")
        if float(np.abs(x).max(initial=0.0)) > self.x_bound:
            raise EncodingOverflowError(f"state {format_value(x)} is outside |x_j| <= x_bound = {self.x_bound:g}")
        return encrypt(self.pk, encode(x, self.delta_x), self._stream)

    def evaluate(self, ct_x: LWECiphertext) -> LWECiphertext:
        """Server: ``Phi_int Enc(x_int)``."""
        return linear_combination(self.Phi_int, ct_x)

    def decrypt_input(self, ct_u: LWECiphertext) -> np.ndarray:
        """Plant: ``u = Dec(ct_u) / (Delta_Phi Delta_x)``."""
        return decrypt(self._sk, ct_u).astype(np.float64) / (self.delta_phi * self.delta_x)

    def step(self, x: Any) -> np.ndarray:
        """One period: encrypt, evaluate, decrypt."""
        return self.decrypt_input(self.evaluate(self.encrypt_state(x)))
