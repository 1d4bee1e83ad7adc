"""ElGamal encryption (Example ex:elgamal): KeyGen, Enc, Dec and the multiplicative Eval.

Keys and ciphertexts are small frozen dataclasses over plain functions, as in ECLib and
python-paillier. Each carries its group (p, q, g): an algorithm that combines a key with a
ciphertext (or two ciphertexts) of different groups raises
:class:`~encctl_gym.errors.KeyMismatchError` instead of returning garbage. Keys carry the
time step ``t`` of the dynamic-key scheme (:mod:`.dyn_elgamal`; 0 for a fresh key) and a
ciphertext may record the step of the key it was made under, so that decrypting with the key
of another step raises :class:`~encctl_gym.errors.KeyMismatchError` too.

Keys are made only over verified groups (:meth:`~.group.GroupParams.verify`), and the
degenerate keys are refused: ``s = 0`` (then ``h = 1``) and ``h = 1``, under which Enc leaves
the message in the clear (``c2 = m h^r = m``).

Randomness: ``s`` and ``r`` are drawn uniformly from ``{1, ..., q - 1}`` (the paper's Z_q
without 0, which would make ``h = 1`` or leave ``m`` in the clear). :func:`keygen` accepts an
int seed (keyed by the purpose ``"keygen"``); :func:`encrypt` draws a fresh r at every call
and refuses one (see :mod:`.arith`).
"""

from __future__ import annotations

import dataclasses
import numbers
from typing import Any

import numpy as np

from .._validation import format_value
from ..errors import CiphertextError, KeyMismatchError, ParameterError, PlaintextError
from . import arith
from .arith import RngLike
from .arith import format_int as fmt
from .checks import check_ciphertext_of, check_instance, check_same_group, group_field, integer_field, step_field
from .group import GroupParams, as_group

__all__ = [
    "PublicKey",
    "SecretKey",
    "Ciphertext",
    "keygen",
    "encrypt",
    "encrypt_member",
    "decrypt",
    "decrypt_components",
    "mult",
    "mult_members",
    "check_plaintext",
    "check_ciphertext",
    "check_same_group",
]


@dataclasses.dataclass(frozen=True, slots=True, repr=False)
class PublicKey:
    """Public key pk = (p, q, g, h) of Example ex:elgamal, at time step ``t``.

    Attributes
    ----------
    group : GroupParams
        (p, q, g), verified.
    h : int
        g^s mod p, an element of G other than 1.
    t : int
        Time step of the dynamic-key scheme (0 after :func:`keygen`).

    Raises
    ------
    GroupError
        If the group does not verify.
    KeyMismatchError
        If ``h`` is not an element of G, or ``h = 1`` (Enc would leave messages in the clear).
    """

    group: GroupParams
    h: int
    t: int = 0

    def __post_init__(self) -> None:
        group_field(self, ParameterError).verify()
        integer_field(self, "h", ParameterError)
        step_field(self, "t", ParameterError, optional=False)
        if self.h == 1:
            raise KeyMismatchError("public key h = 1 is degenerate: Enc would output c2 = m, the message in the clear")
        if not self.group.contains(self.h):
            raise KeyMismatchError(f"public key h = {fmt(self.h)} is not an element of the group")

    def __repr__(self) -> str:
        return f"PublicKey(bits={self.group.bits}, h={fmt(self.h)}, t={self.t})"


@dataclasses.dataclass(frozen=True, slots=True, repr=False)
class SecretKey:
    """Secret key sk = s of Example ex:elgamal (with its group), at time step ``t``.

    ``s`` lies in {1, ..., q - 1} (``s = 0`` would give ``h = 1``) and is hidden from ``repr``.

    Raises
    ------
    GroupError
        If the group does not verify.
    ParameterError
        If ``s`` is not an integer in [1, q) (the message does not show ``s``).
    """

    group: GroupParams
    s: int = dataclasses.field(repr=False)
    t: int = 0

    def __post_init__(self) -> None:
        group_field(self, ParameterError).verify()
        integer_field(self, "s", ParameterError)
        step_field(self, "t", ParameterError, optional=False)
        if not 0 < self.s < self.group.q:
            raise ParameterError(
                f"secret exponent must lie in [1, q), got s outside (t = {self.t}; s = 0 would give the public key h = 1)"
            )

    def __repr__(self) -> str:
        return f"SecretKey(bits={self.group.bits}, t={self.t})"

    def public_key(self) -> PublicKey:
        """The matching public key ``(p, q, g, g^s mod p)`` at the same step (one exponentiation)."""
        grp = self.group
        return PublicKey(grp, int(arith.powmod(grp.g, self.s, grp.p)), self.t)


@dataclasses.dataclass(frozen=True, slots=True, repr=False)
class Ciphertext:
    """Ciphertext ct = (c1, c2) = (g^r, m h^r) mod p of Example ex:elgamal, in ``group``.

    ``t`` optionally records the time step of the public key used (``None``: unknown, no
    check); :func:`decrypt` compares it with the secret key's step, and the group with the
    key's group.
    """

    group: GroupParams
    c1: int
    c2: int
    t: int | None = None

    def __post_init__(self) -> None:
        group_field(self, CiphertextError)
        integer_field(self, "c1", CiphertextError)
        integer_field(self, "c2", CiphertextError)
        step_field(self, "t", CiphertextError, optional=True)

    def __repr__(self) -> str:
        return f"Ciphertext(bits={self.group.bits}, c1={fmt(self.c1)}, c2={fmt(self.c2)}, t={self.t})"


# ---------------------------------------------------------------------- checks
_MPZ = type(arith.mpz(0))


def check_plaintext(group: GroupParams, m: Any) -> int:
    """Return ``m`` as an int after checking that it lies in the message space G.

    Raises
    ------
    PlaintextError
        If ``m`` is not an integer, is 0, lies outside [1, p) or outside the order-q subgroup.
    """
    if type(m) is not int:
        if isinstance(m, bool) or not (isinstance(m, (numbers.Integral, np.integer)) or type(m) is _MPZ):
            raise PlaintextError(f"plaintext must be an integer element of G, got {format_value(m)}")
        m = int(m)
    if m == 0:
        raise PlaintextError("plaintext m = 0 is not an element of G (0 has no order)")
    if not 0 < m < group.p:
        raise PlaintextError(f"plaintext m = {fmt(m)} is outside [1, p) for p = {fmt(group.p)}")
    if not group.contains(m):
        raise PlaintextError(f"plaintext m = {fmt(m)} is not in the order-q subgroup G")
    return m


def check_ciphertext(group: GroupParams, ct: Any) -> Ciphertext:
    """Check that ``ct`` is a :class:`Ciphertext` of ``group`` whose components lie in G.

    Raises
    ------
    CiphertextError
        For another type (e.g. a three-component ciphertext) or a component outside G.
    KeyMismatchError
        If ``ct`` belongs to another group.
    """
    return check_ciphertext_of(group, ct, Ciphertext, ("c1", "c2"), "an ElGamal Ciphertext (c1, c2)")


# ---------------------------------------------------------------------- algorithms
def keygen(group_or_bits: GroupParams | int, rng: RngLike = None) -> tuple[PublicKey, SecretKey]:
    """KeyGen of Example ex:elgamal: ``s`` uniform in {1, ..., q-1}, ``pk = (p, q, g, g^s mod p)``.

    Parameters
    ----------
    group_or_bits : GroupParams or int
        A group (verified, cached) or a bit length (:func:`~.group.get_group`: the shipped
        group if there is one, else a freshly generated safe-prime group, within the default
        time limit of :func:`~.group.generate_safe_prime_group`).
    rng : None, int, RandomSource or numpy.random.Generator
        Randomness (``None``: secure). An int seed is reproducible and unsafe for deployment;
        the prime search (purpose ``"group"``) and s (purpose ``"keygen"``) get independent
        streams of it. A stream is used as is, first for the prime search, then for s.

    Returns
    -------
    (PublicKey, SecretKey)
        The key pair at time step 0.
    """
    group = as_group(group_or_bits, rng=rng)
    src = arith.as_random_source(rng, purpose="keygen")
    s = src.between(1, group.q)
    sk = SecretKey(group, s, 0)
    return sk.public_key(), sk


def encrypt(pk: PublicKey, m: int, rng: RngLike = None) -> Ciphertext:
    """Enc of Example ex:elgamal: ``(g^r mod p, m h^r mod p)`` with ``r`` uniform in {1, ..., q-1}.

    Parameters
    ----------
    pk : PublicKey
        The public key; the ciphertext records ``pk.t`` and ``pk.group``.
    m : int
        A plaintext in G (see :class:`~.encoding.Encoder` for real numbers).
    rng : None, RandomSource or numpy.random.Generator
        A stream (an int seed is refused: it would repeat r at every call, see :mod:`.arith`).

    Raises
    ------
    PlaintextError
        If ``m`` is 0 or not in G.
    ParameterError
        If ``pk`` is not a :class:`PublicKey` or ``rng`` is an int.
    """
    check_instance(pk, PublicKey, "pk")
    return encrypt_member(pk, check_plaintext(pk.group, m), arith.as_random_stream(rng, "encrypt"))


def encrypt_member(pk: PublicKey, m: int, src: arith.RandomSource) -> Ciphertext:
    """Enc of Example ex:elgamal for a plaintext already known to lie in G (no checks).

    The raw algorithm under :func:`encrypt`, for callers whose plaintexts come from the
    encoder (which returns members of G only) and who hold a :class:`~.arith.RandomSource`.
    Two exponentiations.
    """
    grp = pk.group
    r = src.between(1, grp.q)
    c1 = arith.powmod(grp.g, r, grp.p)
    c2 = arith.mulmod(m, arith.powmod(pk.h, r, grp.p), grp.p)
    return Ciphertext(grp, int(c1), int(c2), pk.t)


def decrypt_components(group: GroupParams, s: int, c1: int, c2: int) -> int:
    """Dec of Example ex:elgamal on raw components: ``c1^(-s) c2 mod p`` (no checks).

    ``c1`` must lie in G (the callers check it), so ``c1^(-s) = c1^(q - s)``: one
    exponentiation, no inversion. :func:`decrypt` and :func:`~.modified.modified_decrypt`
    are built on it.
    """
    return int(arith.mulmod(arith.powmod(c1, group.q - s, group.p), c2, group.p))


def decrypt(sk: SecretKey, ct: Ciphertext) -> int:
    """Dec of Example ex:elgamal: ``m = c1^(-s) c2 mod p``.

    Raises
    ------
    CiphertextError
        If ``ct`` is not a two-component ciphertext with components in G.
    KeyMismatchError
        If ``ct`` belongs to another group or records a time step different from ``sk.t``.
    """
    check_instance(sk, SecretKey, "sk")
    check_ciphertext(sk.group, ct)
    if ct.t is not None and ct.t != sk.t:
        raise KeyMismatchError(f"ciphertext was made under the key of step t = {ct.t}, secret key is of step t = {sk.t}")
    return decrypt_components(sk.group, sk.s, ct.c1, ct.c2)


def mult(pk: PublicKey, ct1: Ciphertext, ct2: Ciphertext) -> Ciphertext:
    """Eval of Example ex:elgamal: ``(c11 c21 mod p, c12 c22 mod p)``, an encryption of ``m1 m2``.

    Raises
    ------
    CiphertextError
        If a ciphertext is malformed.
    KeyMismatchError
        If a ciphertext belongs to another group than ``pk``, or the two ciphertexts record
        different time steps (the homomorphism of Example ex:dyn_elgamal holds only for
        ciphertexts of the same step; see :func:`~.modified.modified_eval` for the
        cross-step version).
    """
    check_instance(pk, PublicKey, "pk")
    grp = pk.group
    check_ciphertext(grp, ct1)
    check_ciphertext(grp, ct2)
    if ct1.t is not None and ct2.t is not None and ct1.t != ct2.t:
        raise KeyMismatchError(f"Eval needs ciphertexts of the same time step, got t = {ct1.t} and t = {ct2.t}")
    return mult_members(grp, ct1, ct2, ct1.t if ct1.t is not None else ct2.t)


def mult_members(group: GroupParams, ct1: Ciphertext, ct2: Ciphertext, t: int | None) -> Ciphertext:
    """Eval of Example ex:elgamal on ciphertexts already checked to belong to ``group`` (no checks).

    The raw algorithm under :func:`mult`, for a caller that checks its inputs once (the
    conventional controller server). Two modular multiplications; the result records step ``t``.
    """
    p = group.p
    return Ciphertext(group, int(arith.mulmod(ct1.c1, ct2.c1, p)), int(arith.mulmod(ct1.c2, ct2.c2, p)), t)
