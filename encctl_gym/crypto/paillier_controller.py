"""The encrypted linear controller ``u = Phi x`` over Paillier encryption (Definition def:ec and
eq:ec, with an additive scheme in place of ElGamal), its encoder and its error bound.

Encoder (:class:`PaillierEncoder`)
    ``Ecd(x; Delta) = round(Delta x) mod n`` (IEEE double product, round half to even): every
    residue of ``Z_n`` is a plaintext, so there is no shift (``max_shift = 0``, unlike the
    order-q subgroup of ElGamal). ``Dcd(m; Delta)`` lifts m to the signed representative in
    ``(-n/2, n/2]`` and divides by ``Delta`` (or ``Delta^2`` for a product), exactly rounded
    once (:func:`~.encoding.decode_scaled`, the same rule as the ElGamal encoder). Round trip:
    ``|Dcd(Ecd(x)) - x| <= 1 / (2 Delta)``.

Who holds what
    The plant holds the secret key and encrypts ``x``; the server holds ``pk`` and **Phi in
    plaintext** (``Phi_bar = round(Delta Phi)``, signed integers): Paillier's Eval adds
    ciphertexts and raises them to plaintext powers, never multiplies two ciphertexts, so
    ``Enc(Phi) * Enc(x)`` has no meaning here. The server computes, per row,
    ``c_i = prod_j Enc(x_bar_j)^(Phi_bar_ij) mod n^2 = Enc(sum_j Phi_bar_ij x_bar_j)`` (the row
    sum is homomorphic, so one ciphertext per row reaches the plant, not one per entry); the
    plant decrypts and decodes with ``Delta^2``. Confidentiality of the controller is gone,
    and a malicious server adds ``Enc(d)`` to a row with the public key alone
    (:meth:`PaillierControllerServer.evaluate`'s ``offset``).

Error bound (:func:`controller_error_bound`)
    With ``|Phi_bar_ij / Delta - Phi_ij| <= 1/(2 Delta)`` and ``|x_bar_j / Delta - x_j| <=
    1/(2 Delta)``, row i of the decoded input differs from ``(Phi x)_i`` by at most
    ``sum_j (|Phi_ij| + |x_j|) / (2 Delta) + beta / (4 Delta^2)`` before the final rounding to a
    double (at most half an ulp of the result).

No silent wrap: the constructor refuses a modulus too small for the encoder's range (some row
sum over ``|x_j| <= x_bound`` could exceed ``(n - 1)/2``) with
:class:`~encctl_gym.errors.EncodingOverflowError`.

Key rotation (:class:`PaillierPlant`): with ``rotation_period = K`` the plant draws a fresh
modulus after every K steps (KeyGen, off the control path: after the input of the step is
applied) and the server receives the new public key; Phi needs no re-encryption, since the
server holds it in plaintext. Each KeyGen's wall time is recorded (``keygen_seconds``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_nonnegative, check_positive, format_value
from ..errors import EncodingOverflowError, ParameterError
from . import arith
from .arith import RandomSource, RngLike
from .arith import format_int as fmt
from .encoding import decode_scaled
from .paillier import (
    PaillierCiphertext,
    PaillierPublicKey,
    PaillierSecretKey,
    add_plain,
    check_ciphertext,
    decrypt,
    encrypt_with_secret,
    keygen,
)

__all__ = [
    "PaillierEncoder",
    "to_signed",
    "controller_error_bound",
    "check_row_sums",
    "PaillierControllerServer",
    "PaillierPlant",
    "PaillierLinearController",
]


def to_signed(m: int, n: int) -> int:
    """The signed representative of ``m mod n`` in ``(-n/2, n/2]``."""
    m = int(m) % n
    return m - n if m > n // 2 else m


def _modulus(n_or_pk: Any) -> int:
    if isinstance(n_or_pk, PaillierPublicKey):
        return n_or_pk.n
    return PaillierPublicKey(n_or_pk).n


class PaillierEncoder:
    """``Ecd(.; Delta)`` and ``Dcd(.; Delta)`` over ``Z_n`` (module docstring).

    Parameters
    ----------
    modulus : PaillierPublicKey or int
        The public key (or its modulus n).
    delta : float
        The scaling factor Delta > 0.
    x_bound : float, optional
        Declared input range ``|x| <= x_bound`` (default: every representable value,
        ``|round(Delta x)| <= (n - 1)/2``).

    Raises
    ------
    ParameterError
        For a bad modulus, ``delta`` or ``x_bound``.
    EncodingOverflowError
        If ``x_bound`` itself is not representable.
    """

    max_shift = 0

    def __init__(self, modulus: PaillierPublicKey | int, delta: float, x_bound: float | None = None) -> None:
        self.n = _modulus(modulus)
        self.half = (self.n - 1) // 2
        self.delta = check_positive("delta", delta)
        self.delta_ratio: tuple[int, int] = self.delta.as_integer_ratio()
        self.x_bound: float | None = None
        if x_bound is not None:
            xb = check_nonnegative("x_bound", x_bound)
            self.quantize(xb)
            self.x_bound = xb

    def quantize(self, x: Any) -> int:
        """``v = round(Delta x)`` after the finiteness and range checks (a signed integer).

        Raises
        ------
        ParameterError
            For a non-number, NaN or infinity.
        EncodingOverflowError
            If ``|x| > x_bound`` or ``|v| > (n - 1)/2``.
        """
        if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
            raise ParameterError(f"x must be a real number, got {format_value(x)}")
        xf = float(x)
        if not math.isfinite(xf):
            raise ParameterError(f"x must be finite, got {format_value(x)}")
        if self.x_bound is not None and abs(xf) > self.x_bound:
            raise EncodingOverflowError(f"x = {xf!r} is outside the declared input range |x| <= {self.x_bound!r}")
        y = self.delta * xf
        if not math.isfinite(y) or abs(y) > self.half:
            raise EncodingOverflowError(
                f"x = {xf!r} is not representable: |round(Delta x)| > (n-1)/2 for the {self.n.bit_length()}-bit modulus "
                f"and Delta = {self.delta!r}"
            )
        return int(round(y))

    def encode_signed(self, x: Any) -> int:
        """The signed integer ``round(Delta x)`` whose residue is ``Ecd(x)``."""
        return self.quantize(x)

    def encode(self, x: Any) -> int:
        """``Ecd(x)``: the plaintext ``round(Delta x) mod n``, an int of ``[0, n)``."""
        return self.quantize(x) % self.n

    def quantize_array(self, x: Any) -> list[int]:
        """:meth:`quantize` of every entry of a 1-D or 2-D array, flattened row by row."""
        arr = as_finite_array("x", x, allow_empty=True, overflow_error=EncodingOverflowError)
        return [self.quantize(v) for v in arr.ravel().tolist()]

    def decode(self, m: Any, power: int = 1) -> float:
        """``Dcd(m)``: lift ``m`` to ``(-n/2, n/2]`` and divide by ``Delta**power`` (power 1 or 2)."""
        return decode_scaled(to_signed(check_int("m", m), self.n), self.delta_ratio, power)

    def decode_signed(self, w: Any, power: int = 1) -> float:
        """Decode an already lifted signed integer."""
        return decode_scaled(check_int("w", w), self.delta_ratio, power)

    def error_bound(self) -> float:
        """Round-trip bound ``1 / (2 Delta)`` (no shift: every residue is a plaintext)."""
        return 0.5 / self.delta

    def __repr__(self) -> str:
        return f"PaillierEncoder(bits={self.n.bit_length()}, delta={self.delta!r}, x_bound={self.x_bound!r})"


def controller_error_bound(Phi: Any, x: Any, delta: float) -> np.ndarray:
    """The bound ``sum_j (|Phi_ij| + |x_j|) / (2 Delta) + beta / (4 Delta^2)`` on each row's
    error of the decoded input (module docstring), before the final rounding to a double.

    Parameters
    ----------
    Phi : array_like, shape (alpha, beta)
    x : array_like, shape (beta,)
        The input, or a bound on ``|x_j|`` (a scalar broadcasts).
    delta : float
    """
    P = as_finite_array("Phi", Phi, ndim=2)
    xv = np.broadcast_to(np.abs(as_finite_array("x", x)), (P.shape[1],))
    d = check_positive("delta", delta)
    rows = []
    for row in np.abs(P):
        total = sum((Fraction(float(a)) + Fraction(float(b)) for a, b in zip(row, xv)), Fraction(0))
        rows.append(float(total / (2 * Fraction(d)) + Fraction(P.shape[1]) / (4 * Fraction(d) ** 2)))
    return np.array(rows)


class PaillierControllerServer:
    """The controller server: the public key and Phi in plaintext (``Phi_bar``, signed integers).

    Parameters
    ----------
    pk : PaillierPublicKey
    Phi_bar : sequence of sequences of int
        ``round(Delta Phi)``, shape (alpha, beta).
    """

    def __init__(self, pk: PaillierPublicKey, Phi_bar: Sequence[Sequence[int]]) -> None:
        if not isinstance(pk, PaillierPublicKey):
            raise ParameterError(f"pk must be a PaillierPublicKey, got {format_value(pk)}")
        self.pk = pk
        self.Phi_bar = [[int(v) for v in row] for row in Phi_bar]
        self.alpha, self.beta = len(self.Phi_bar), len(self.Phi_bar[0])

    def receive_key(self, pk: PaillierPublicKey) -> None:
        """A rotation: the plant's fresh public key replaces the old one."""
        if not isinstance(pk, PaillierPublicKey):
            raise ParameterError(f"pk must be a PaillierPublicKey, got {format_value(pk)}")
        self.pk = pk

    def evaluate(self, cts: Sequence[PaillierCiphertext], offset: Sequence[int] | None = None) -> list[PaillierCiphertext]:
        """Row i: ``prod_j ct_j^(Phi_bar_ij) mod n^2`` (negative entries through one inverse per row).

        ``offset`` (a malicious server): signed integers ``d_i`` added to each row,
        ``c_i g^(d_i)`` (:func:`~.paillier.add_plain`), so the plant decodes ``u_i + d_i /
        Delta^2``; it needs no key.

        Raises
        ------
        CiphertextError, KeyMismatchError
            For a list that is not beta ciphertexts of the server's key.
        """
        cts = list(cts)
        if len(cts) != self.beta:
            raise ParameterError(f"the server expects {self.beta} state ciphertexts, got {len(cts)}")
        cs = [check_ciphertext(self.pk, ct).c for ct in cts]
        n2 = self.pk.n2
        out = []
        for row in self.Phi_bar:
            pos, neg = 1, 1
            for c, k in zip(cs, row):
                if k > 0:
                    pos = arith.mulmod(pos, arith.powmod(c, k, n2), n2)
                elif k < 0:
                    neg = arith.mulmod(neg, arith.powmod(c, -k, n2), n2)
            out.append(PaillierCiphertext(self.pk, int(arith.mulmod(pos, arith.invert(neg, n2), n2))))
        if offset is not None:
            offs = [check_int("offset", d) for d in offset]
            if len(offs) != self.alpha:
                raise ParameterError(f"offset must have {self.alpha} entries, got {len(offs)}")
            out = [add_plain(c, d) for c, d in zip(out, offs)]
        return out


class PaillierPlant:
    """The plant party: the secret key, the encoder, the time step and the rotation.

    Parameters
    ----------
    bits : int
        Modulus length k.
    delta : float
    x_bound : float
    rotation_period : int or None
        K: a fresh modulus after every K steps (``None``: one key for the whole run).
    rng : RandomSource
        The plant's randomness (KeyGen and Enc).
    """

    def __init__(self, bits: int, delta: float, x_bound: float, rotation_period: int | None, rng: RandomSource) -> None:
        self.bits = bits
        self.delta = delta
        self.x_bound = x_bound
        self.rotation_period = None if rotation_period is None else check_int("rotation_period", rotation_period, 1)
        self.rng = rng
        self.t = 0
        self.keygen_seconds: list[float] = []
        self.pk, self.sk = self._keygen()
        self.encoder = PaillierEncoder(self.pk, delta, x_bound)

    def _keygen(self) -> tuple[PaillierPublicKey, PaillierSecretKey]:
        t0 = time.perf_counter()
        keys = keygen(self.bits, self.rng)
        self.keygen_seconds.append(time.perf_counter() - t0)
        return keys

    def encrypt_state(self, x: Any) -> list[PaillierCiphertext]:
        """``Enc(pk_t, Ecd(x_j))`` for every entry of ``x`` (shape (beta,)), by the key's owner
        (:func:`~.paillier.encrypt_with_secret`: the CRT, the same ciphertexts as ``encrypt``)."""
        return [encrypt_with_secret(self.sk, self.encoder.encode(v), self.rng) for v in as_finite_array("x", x, ndim=1).tolist()]

    def decrypt_output(self, out: Sequence[PaillierCiphertext]) -> np.ndarray:
        """Dec and Dcd (with ``Delta^2``) of each row's ciphertext: the control input."""
        return np.array([self.encoder.decode(decrypt(self.sk, ct), 2) for ct in out], dtype=np.float64)

    def update_keys(self) -> PaillierPublicKey | None:
        """End of a step: after every K steps a fresh modulus; returns the new public key (for
        the server) or ``None`` when the key stays."""
        self.t += 1
        if self.rotation_period is None or self.t % self.rotation_period:
            return None
        self.pk, self.sk = self._keygen()
        self.encoder = PaillierEncoder(self.pk, self.delta, self.x_bound)
        return self.pk


def check_row_sums(Phi_bar: list[list[int]], v_max: int, n: int) -> None:
    """Raise :class:`EncodingOverflowError` unless every row sum ``sum_j Phi_bar_ij x_bar_j`` with
    ``|x_bar_j| <= v_max`` stays within ``(n - 1)/2`` (no wrap modulo n)."""
    half = (n - 1) // 2
    for i, row in enumerate(Phi_bar):
        worst = sum(abs(k) for k in row) * v_max
        if worst > half:
            raise EncodingOverflowError(
                f"the {n.bit_length()}-bit modulus is too small for the encoder's range: row {i} of Phi x can reach "
                f"|sum_j Phi_bar_ij x_bar_j| = {fmt(worst)} > (n-1)/2 for |x_j| <= x_bound; use a longer modulus, "
                "a smaller Delta or a smaller x_bound"
            )


class PaillierLinearController:
    """``u = Phi x`` over Paillier encryption, one object: ``step(x) -> u`` (module docstring).

    Parameters
    ----------
    Phi : array_like, shape (alpha, beta)
    bits : int
        Modulus length k.
    delta : float
        Scale Delta > 0.
    x_bound : float
        Declared bound ``|x_j| <= x_bound``.
    rotation_period : int, optional
        K: a fresh modulus after every K steps.
    rng : None, int, RandomSource or numpy.random.Generator
        The plant and the server get streams of their own spawned from it.

    Raises
    ------
    EncodingOverflowError
        If the modulus is too small for the encoder's range (a row sum could wrap).
    """

    def __init__(
        self, Phi: Any, bits: int, delta: float, x_bound: float, rotation_period: int | None = None, rng: RngLike = None
    ) -> None:
        P = as_finite_array("Phi", Phi, ndim=2)
        src = arith.as_random_source(rng, "paillier-controller")
        self.plant = PaillierPlant(bits, delta, x_bound, rotation_period, src.spawn("plant"))
        enc = self.plant.encoder
        self.Phi = P
        self.Phi_bar = [[enc.quantize(v) for v in row] for row in P.tolist()]
        check_row_sums(self.Phi_bar, enc.quantize(x_bound), enc.n)
        self.server = PaillierControllerServer(self.plant.pk, self.Phi_bar)
        self.last_state_ciphertexts: list[PaillierCiphertext] | None = None

    def reference(self, x: Any) -> np.ndarray:
        """The same quantised computation in Z, without ciphertexts (equal to :meth:`step` bit for bit)."""
        enc = self.plant.encoder
        xb = [enc.quantize(v) for v in as_finite_array("x", x, ndim=1).tolist()]
        return np.array([enc.decode_signed(sum(k * v for k, v in zip(row, xb)), 2) for row in self.Phi_bar])

    def error_bound(self, x: Any) -> np.ndarray:
        """:func:`controller_error_bound` of this controller at ``x``."""
        return controller_error_bound(self.Phi, x, self.plant.delta)

    def step(self, x: Any, offset: Sequence[int] | None = None) -> np.ndarray:
        """Encrypt x, evaluate on the server (plus a malicious ``offset``), decrypt, decode, rotate."""
        cts = self.plant.encrypt_state(x)
        u = self.plant.decrypt_output(self.server.evaluate(cts, offset))
        fresh = self.plant.update_keys()
        if fresh is not None:
            self.server.receive_key(fresh)
        self.last_state_ciphertexts = cts
        return u

    def __repr__(self) -> str:
        return (
            f"PaillierLinearController(shape=({self.server.alpha}, {self.server.beta}), bits={self.plant.bits}, "
            f"delta={self.plant.delta!r}, rotation_period={self.plant.rotation_period}, t={self.plant.t})"
        )
