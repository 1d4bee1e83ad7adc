"""Dynamic-key ElGamal encryption (Example ex:dyn_elgamal): KeyUpd and CtUpd.

KeyGen, Enc, Dec and Eval are those of :mod:`.elgamal`. The key update draws a fresh
``s'`` and publishes ``h' = h g^d`` with ``d = s' - s mod q`` (the paper writes ``mod p``,
a typo: exponents live modulo the group order q). The update token ``sigma_t = (h, d)``
lets anybody holding it move ciphertexts to the next key (:func:`ciphertext_update`), and
also, by Proposition prop:vulnerability, recover ``sk_{t+1}`` from ``sk_t``
(:func:`recover_next_secret_key`): this is why the modified scheme (:mod:`.modified`) never
sends tokens to the controller server.
"""

from __future__ import annotations

import dataclasses

from ..errors import KeyMismatchError, ParameterError
from . import arith
from .arith import RngLike
from .checks import check_group_of, check_instance, check_same_group, group_field, integer_field, step_field
from .elgamal import Ciphertext, PublicKey, SecretKey, check_ciphertext
from .group import GroupParams

__all__ = ["UpdateToken", "key_update", "ciphertext_update", "recover_next_secret_key"]


@dataclasses.dataclass(frozen=True, slots=True, repr=False)
class UpdateToken:
    """Update token sigma_t = (h, d) of Example ex:dyn_elgamal (``d`` hidden from ``repr``).

    Attributes
    ----------
    group : GroupParams
        The group of the keys it updates.
    h : int
        The public-key element ``h = g^s`` of step ``t`` (in G, not 1).
    d : int
        ``s' - s mod q``, in [0, q).
    t : int or None
        The step ``t`` the token moves away from (to ``t + 1``).

    Raises
    ------
    KeyMismatchError
        If ``h`` is not an element of G other than 1, or ``d`` is outside [0, q).
    """

    group: GroupParams
    h: int
    d: int = dataclasses.field(repr=False)
    t: int | None = None

    def __post_init__(self) -> None:
        grp = group_field(self, ParameterError)
        integer_field(self, "h", ParameterError)
        integer_field(self, "d", ParameterError)
        step_field(self, "t", ParameterError, optional=True)
        if self.h == 1 or not grp.contains(self.h):
            raise KeyMismatchError(f"update token h = {arith.format_int(self.h)} is not an element of the group other than 1")
        if not 0 <= self.d < grp.q:
            raise KeyMismatchError("update token d is outside [0, q) for its group")

    def __repr__(self) -> str:
        return f"UpdateToken(bits={self.group.bits}, h={arith.format_int(self.h)}, t={self.t})"


def key_update(pk: PublicKey, sk: SecretKey, rng: RngLike = None) -> tuple[PublicKey, SecretKey, UpdateToken]:
    """KeyUpd of Example ex:dyn_elgamal: ``(pk_{t+1}, sk_{t+1}, sigma_t)``.

    Draws ``s'`` uniform in {1, ..., q-1}, sets ``d = s' - s mod q`` and ``h' = h g^d mod p``
    (one modular exponentiation).

    Parameters
    ----------
    pk, sk : PublicKey, SecretKey
        The key pair of step t (same group and same step).
    rng : None, RandomSource or numpy.random.Generator
        A stream (an int seed is refused: it would draw the same s' at every step).

    Returns
    -------
    (PublicKey, SecretKey, UpdateToken)
        Keys of step t + 1 and the token ``(h, d)`` of step t.

    Raises
    ------
    KeyMismatchError
        If the keys belong to different groups or different steps.
    """
    check_instance(pk, PublicKey, "pk")
    check_instance(sk, SecretKey, "sk")
    grp = check_same_group(pk, sk, "pk and sk")
    if pk.t != sk.t:
        raise KeyMismatchError(f"pk is of step t = {pk.t} but sk is of step t = {sk.t}")
    s_next = arith.as_random_stream(rng, "key_update").between(1, grp.q)
    d = (s_next - sk.s) % grp.q
    h_next = int(arith.mulmod(pk.h, arith.powmod(grp.g, d, grp.p), grp.p))
    return (PublicKey(grp, h_next, pk.t + 1), SecretKey(grp, s_next, sk.t + 1), UpdateToken(grp, pk.h, d, pk.t))


def ciphertext_update(pk: PublicKey, ct: Ciphertext, token: UpdateToken, rng: RngLike = None) -> Ciphertext:
    """CtUpd of Example ex:dyn_elgamal: ``(c1 g^r, (c1 g^r)^d c2 h^r) mod p`` (re-randomised).

    ``r`` is drawn again in the (probability 1/(q - 1)) case ``c1 g^r = 1``, which would output
    the plaintext as the second component.

    Parameters
    ----------
    pk : PublicKey
        Any public key of the group (only p, q, g are used; the algorithm needs no secret).
    ct : Ciphertext
        A ciphertext under the key of step t.
    token : UpdateToken
        sigma_t = (h, d) from :func:`key_update`.
    rng : None, RandomSource or numpy.random.Generator
        A stream (an int seed is refused: it would repeat r at every call).

    Returns
    -------
    Ciphertext
        An encryption of the same plaintext under the key of step t + 1.

    Raises
    ------
    CiphertextError
        If ``ct`` is malformed.
    KeyMismatchError
        If ``pk``, ``ct`` and ``token`` do not belong to one group, or ``ct`` and ``token``
        record different steps.
    """
    check_instance(pk, PublicKey, "pk")
    check_instance(token, UpdateToken, "token")
    grp = pk.group
    check_ciphertext(grp, ct)
    check_group_of(token, grp, "update token")
    if ct.t is not None and token.t is not None and ct.t != token.t:
        raise KeyMismatchError(f"ciphertext is of step t = {ct.t} but the token updates step t = {token.t}")
    base_t = token.t if token.t is not None else ct.t
    p = grp.p
    src = arith.as_random_stream(rng, "ciphertext_update")
    c1 = 1
    while c1 == 1:
        r = src.between(1, grp.q)
        c1 = arith.mulmod(ct.c1, arith.powmod(grp.g, r, p), p)
    c2 = arith.mulmod(arith.mulmod(arith.powmod(c1, token.d, p), ct.c2, p), arith.powmod(token.h, r, p), p)
    return Ciphertext(grp, int(c1), int(c2), None if base_t is None else base_t + 1)


def recover_next_secret_key(sk_t: SecretKey, token: UpdateToken) -> SecretKey:
    """The attack of Proposition prop:vulnerability: ``sk_{t+1} = sk_t + d mod q``.

    Whoever holds ``sk_t`` and ``sigma_t`` (e.g. a malicious server of the token-based
    scheme that once broke one key) obtains every later secret key with probability 1.

    Raises
    ------
    KeyMismatchError
        If the token belongs to another group or another step than ``sk_t``.
    """
    check_instance(sk_t, SecretKey, "sk_t")
    check_instance(token, UpdateToken, "token")
    if token.t is not None and token.t != sk_t.t:
        raise KeyMismatchError(f"token is of step t = {token.t} but sk_t is of step t = {sk_t.t}")
    grp = check_same_group(sk_t, token, "sk_t and the token")
    return SecretKey(grp, (sk_t.s + token.d) % grp.q, sk_t.t + 1)
