"""ElGamal encryption (Example ex:elgamal): KeyGen, Enc, Dec and the multiplicative Eval.

Keys and ciphertexts are small frozen dataclasses over plain functions, as in ECLib and
python-paillier. Keys carry the time step ``t`` of the dynamic-key scheme
(:mod:`.dyn_elgamal`; 0 for a fresh key) and a ciphertext may record the step of the key it
was made under, so that decrypting with the key of another step raises
:class:`~encctl_gym.errors.KeyMismatchError` instead of returning garbage.

Randomness: ``s`` and ``r`` are drawn uniformly from ``{1, ..., q - 1}`` (the paper's Z_q
without 0, which would make ``h = 1`` or leave ``m`` in the clear).
"""

from __future__ import annotations

import dataclasses
import numbers
from typing import Any, Optional, Union

import numpy as np

from ..errors import CiphertextError, KeyMismatchError, ParameterError, PlaintextError
from . import arith
from .arith import RngLike
from .group import GroupParams, as_group

__all__ = [
    "PublicKey",
    "SecretKey",
    "Ciphertext",
    "keygen",
    "encrypt",
    "decrypt",
    "mult",
    "check_plaintext",
    "check_ciphertext",
    "check_same_group",
]


_MPZ = type(arith.mpz(0))


def _int_field(obj: Any, name: str, err: type) -> None:
    value = getattr(obj, name)
    if type(value) is int:  # fast path (hot in the control loop)
        return
    if type(value) is _MPZ:
        object.__setattr__(obj, name, int(value))
        return
    if isinstance(value, bool) or not (
        isinstance(value, (numbers.Integral, np.integer)) or type(value).__name__ == "mpz"
    ):
        raise err(f"{type(obj).__name__}.{name} must be an integer, got {value!r}")
    object.__setattr__(obj, name, int(value))


def _step_field(obj: Any, name: str, err: type, optional: bool) -> None:
    value = getattr(obj, name)
    if value is None and optional:
        return
    if type(value) is int and value >= 0:  # fast path
        return
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, np.integer)) or value < 0:
        raise err(f"{type(obj).__name__}.{name} must be a time step >= 0, got {value!r}")
    object.__setattr__(obj, name, int(value))


@dataclasses.dataclass(frozen=True, slots=True)
class PublicKey:
    """Public key pk = (p, q, g, h) of Example ex:elgamal, at time step ``t``.

    Attributes
    ----------
    group : GroupParams
        (p, q, g).
    h : int
        g^s mod p.
    t : int
        Time step of the dynamic-key scheme (0 after :func:`keygen`).
    """

    group: GroupParams
    h: int
    t: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.group, GroupParams):
            raise ParameterError(f"PublicKey.group must be a GroupParams, got {self.group!r}")
        _int_field(self, "h", ParameterError)
        _step_field(self, "t", ParameterError, optional=False)
        if not self.group.contains(self.h):
            raise KeyMismatchError(f"public key h = {self.h} is not an element of the group")


@dataclasses.dataclass(frozen=True, slots=True)
class SecretKey:
    """Secret key sk = s of Example ex:elgamal (with its group), at time step ``t``.

    ``s`` is hidden from ``repr``.
    """

    group: GroupParams
    s: int = dataclasses.field(repr=False)
    t: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.group, GroupParams):
            raise ParameterError(f"SecretKey.group must be a GroupParams, got {self.group!r}")
        _int_field(self, "s", ParameterError)
        _step_field(self, "t", ParameterError, optional=False)
        if not 0 <= self.s < self.group.q:
            raise ParameterError(f"secret exponent must lie in [0, q), got s outside (t = {self.t})")

    def public_key(self) -> PublicKey:
        """The matching public key ``(p, q, g, g^s mod p)`` at the same step (one exponentiation)."""
        grp = self.group
        return PublicKey(grp, int(arith.powmod(grp.g, self.s, grp.p)), self.t)


@dataclasses.dataclass(frozen=True, slots=True)
class Ciphertext:
    """Ciphertext ct = (c1, c2) = (g^r, m h^r) mod p of Example ex:elgamal.

    ``t`` optionally records the time step of the public key used (``None``: unknown, no
    check); :func:`decrypt` compares it with the secret key's step.
    """

    c1: int
    c2: int
    t: Optional[int] = None

    def __post_init__(self) -> None:
        _int_field(self, "c1", CiphertextError)
        _int_field(self, "c2", CiphertextError)
        _step_field(self, "t", CiphertextError, optional=True)


# ---------------------------------------------------------------------- checks
def check_same_group(a: Any, b: Any, what: str = "keys") -> GroupParams:
    """Return the common group of two keys, raising :class:`KeyMismatchError` if they differ."""
    if a.group != b.group:
        raise KeyMismatchError(
            f"{what} belong to different groups: {a.group!r} and {b.group!r}"
        )
    return a.group


def _check_key(key: Any, cls: type, name: str) -> None:
    if not isinstance(key, cls):
        raise ParameterError(f"{name} must be a {cls.__name__}, got {type(key).__name__}: {key!r}")


def check_plaintext(group: GroupParams, m: Any) -> int:
    """Return ``m`` as an int after checking that it lies in the message space G.

    Raises
    ------
    PlaintextError
        If ``m`` is not an integer, is 0, lies outside [1, p) or outside the order-q subgroup.
    """
    if type(m) is not int:
        if isinstance(m, bool) or not (
            isinstance(m, (numbers.Integral, np.integer)) or type(m) is _MPZ
        ):
            raise PlaintextError(f"plaintext must be an integer element of G, got {m!r}")
        m = int(m)
    if m == 0:
        raise PlaintextError("plaintext m = 0 is not an element of G (0 has no order)")
    if not 0 < m < group.p:
        raise PlaintextError(f"plaintext m = {m} is outside [1, p) for p = {group.p}")
    if not group.contains(m):
        raise PlaintextError(f"plaintext m = {m} is not in the order-q subgroup G")
    return m


def _check_component(group: GroupParams, c: int, name: str) -> None:
    if not 0 < c < group.p:
        raise CiphertextError(f"ciphertext component {name} = {c} is outside [1, p)")
    if not group.contains(c):
        raise CiphertextError(f"ciphertext component {name} = {c} is not in the subgroup G")


def check_ciphertext(group: GroupParams, ct: Any) -> "Ciphertext":
    """Check that ``ct`` is a :class:`Ciphertext` whose components lie in G.

    Raises
    ------
    CiphertextError
        For another type (e.g. a three-component ciphertext) or a component outside G.
    """
    if not isinstance(ct, Ciphertext):
        raise CiphertextError(f"expected an ElGamal Ciphertext (c1, c2), got {ct!r}")
    _check_component(group, ct.c1, "c1")
    _check_component(group, ct.c2, "c2")
    return ct


# ---------------------------------------------------------------------- algorithms
def keygen(
    group_or_bits: Union[GroupParams, int], rng: RngLike = None
) -> tuple[PublicKey, SecretKey]:
    """KeyGen of Example ex:elgamal: ``s`` uniform in {1, ..., q-1}, ``pk = (p, q, g, g^s mod p)``.

    Parameters
    ----------
    group_or_bits : GroupParams or int
        A group (verified, cached) or a bit length (:func:`~.group.get_group`: the shipped
        group if there is one, else a freshly generated safe-prime group).
    rng : None, int, RandomSource or numpy.random.Generator
        Randomness (``None``: secure; a seed is reproducible and unsafe for deployment).

    Returns
    -------
    (PublicKey, SecretKey)
        The key pair at time step 0.
    """
    group = as_group(group_or_bits, rng=rng)
    src = arith.as_random_source(rng)
    s = src.between(1, group.q)
    sk = SecretKey(group, s, 0)
    return sk.public_key(), sk


def encrypt(pk: PublicKey, m: int, rng: RngLike = None) -> Ciphertext:
    """Enc of Example ex:elgamal: ``(g^r mod p, m h^r mod p)`` with ``r`` uniform in {1, ..., q-1}.

    Parameters
    ----------
    pk : PublicKey
        The public key; the ciphertext records ``pk.t``.
    m : int
        A plaintext in G (see :class:`~.encoding.Encoder` for real numbers).
    rng : None, int, RandomSource or numpy.random.Generator

    Raises
    ------
    PlaintextError
        If ``m`` is 0 or not in G.
    """
    _check_key(pk, PublicKey, "pk")
    return _encrypt_member(pk, check_plaintext(pk.group, m), arith.as_random_source(rng))


def _encrypt_member(pk: PublicKey, m: int, src: arith.RandomSource) -> Ciphertext:
    # Enc for a plaintext already known to lie in G (e.g. produced by the encoder).
    grp = pk.group
    r = src.between(1, grp.q)
    c1 = arith.powmod(grp.g, r, grp.p)
    c2 = arith.mulmod(m, arith.powmod(pk.h, r, grp.p), grp.p)
    return Ciphertext(int(c1), int(c2), pk.t)


def _dec(grp: GroupParams, s: int, c1: int, c2: int) -> int:
    # c1 is in G (checked), so c1^(-s) = c1^(q - s): no inversion needed.
    return int(arith.mulmod(arith.powmod(c1, grp.q - s, grp.p), c2, grp.p))


def decrypt(sk: SecretKey, ct: Ciphertext) -> int:
    """Dec of Example ex:elgamal: ``m = c1^(-s) c2 mod p``.

    Raises
    ------
    CiphertextError
        If ``ct`` is not a two-component ciphertext with components in G.
    KeyMismatchError
        If ``ct`` records a time step different from ``sk.t``.
    """
    _check_key(sk, SecretKey, "sk")
    check_ciphertext(sk.group, ct)
    if ct.t is not None and ct.t != sk.t:
        raise KeyMismatchError(
            f"ciphertext was made under the key of step t = {ct.t}, secret key is of step t = {sk.t}"
        )
    return _dec(sk.group, sk.s, ct.c1, ct.c2)


def mult(pk: PublicKey, ct1: Ciphertext, ct2: Ciphertext) -> Ciphertext:
    """Eval of Example ex:elgamal: ``(c11 c21 mod p, c12 c22 mod p)``, an encryption of ``m1 m2``.

    Raises
    ------
    CiphertextError
        If a ciphertext is malformed.
    KeyMismatchError
        If the two ciphertexts record different time steps (the homomorphism of
        Example ex:dyn_elgamal holds only for ciphertexts of the same step; see
        :func:`~.modified.modified_eval` for the cross-step version).
    """
    _check_key(pk, PublicKey, "pk")
    grp = pk.group
    check_ciphertext(grp, ct1)
    check_ciphertext(grp, ct2)
    if ct1.t is not None and ct2.t is not None and ct1.t != ct2.t:
        raise KeyMismatchError(
            f"Eval needs ciphertexts of the same time step, got t = {ct1.t} and t = {ct2.t}"
        )
    t = ct1.t if ct1.t is not None else ct2.t
    p = grp.p
    return Ciphertext(int(arith.mulmod(ct1.c1, ct2.c1, p)), int(arith.mulmod(ct1.c2, ct2.c2, p)), t)
