"""Modified homomorphic evaluation and decryption (Definition def:modification).

``modified_eval`` keeps the first components of both ciphertexts apart, so the product
can be decrypted with two keys of *different* steps (the theorem after
Definition def:modification):

    Dec_bar(sk_t, sk_{t+k}, Eval_bar(pk_t, Enc(pk_t, m1), Enc(pk_{t+k}, m2))) = m1 m2 mod p.

This is what lets the controller server of eq:ec keep the controller-parameter ciphertexts
under pk_0 forever and never receive an update token.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from ..errors import CiphertextError, KeyMismatchError
from . import arith
from .checks import check_ciphertext_of, check_instance, check_same_group, group_field, integer_field, step_field
from .elgamal import Ciphertext, PublicKey, SecretKey, check_ciphertext, decrypt_components
from .group import GroupParams

__all__ = ["ModifiedCiphertext", "modified_eval", "modified_eval_members", "modified_decrypt", "check_modified_ciphertext"]


@dataclasses.dataclass(frozen=True, slots=True, repr=False)
class ModifiedCiphertext:
    """Three-component ciphertext (c1, c2, c3) = (c11, c21, c12 c22 mod p) of Definition def:modification.

    ``group`` is the group of both input ciphertexts. ``t1`` and ``t2`` optionally record the
    steps of the keys that decrypt ``c1`` and ``c2`` (the steps of the two input
    ciphertexts); ``None`` means unknown (no check).
    """

    group: GroupParams
    c1: int
    c2: int
    c3: int
    t1: int | None = None
    t2: int | None = None

    def __post_init__(self) -> None:
        group_field(self, CiphertextError)
        for name in ("c1", "c2", "c3"):
            integer_field(self, name, CiphertextError)
        step_field(self, "t1", CiphertextError, optional=True)
        step_field(self, "t2", CiphertextError, optional=True)

    def __repr__(self) -> str:
        fmt = arith.format_int
        return (
            f"ModifiedCiphertext(bits={self.group.bits}, c1={fmt(self.c1)}, c2={fmt(self.c2)}, "
            f"c3={fmt(self.c3)}, t1={self.t1}, t2={self.t2})"
        )


def modified_eval(pk: PublicKey, ct1: Ciphertext, ct2: Ciphertext) -> ModifiedCiphertext:
    """Eval_bar of Definition def:modification: ``(c11, c21, c12 c22 mod p)``.

    Only one modular multiplication; the ciphertexts may come from different steps.

    Raises
    ------
    CiphertextError
        If an input is not a two-component ciphertext with components in G.
    KeyMismatchError
        If an input belongs to another group than ``pk``.
    """
    check_instance(pk, PublicKey, "pk")
    grp = pk.group
    check_ciphertext(grp, ct1)
    check_ciphertext(grp, ct2)
    return modified_eval_members(grp, ct1, ct2)


def modified_eval_members(group: GroupParams, ct1: Ciphertext, ct2: Ciphertext) -> ModifiedCiphertext:
    """Eval_bar of Definition def:modification on ciphertexts already checked to belong to ``group``.

    The raw algorithm under :func:`modified_eval`, for a caller that checks its inputs once
    (the controller server of eq:ec checks each state ciphertext once per step, its own
    parameter ciphertexts once at set-up). One modular multiplication.
    """
    return ModifiedCiphertext(group, ct1.c1, ct2.c1, int(arith.mulmod(ct1.c2, ct2.c2, group.p)), ct1.t, ct2.t)


def check_modified_ciphertext(grp: GroupParams, ct: Any) -> ModifiedCiphertext:
    """Check that ``ct`` is a :class:`ModifiedCiphertext` of ``grp`` with components in G.

    Raises
    ------
    CiphertextError
        For another type or a component outside G.
    KeyMismatchError
        If ``ct`` belongs to another group.
    """
    return check_ciphertext_of(grp, ct, ModifiedCiphertext, ("c1", "c2", "c3"), "a ModifiedCiphertext (c1, c2, c3)")


def modified_decrypt(sk1: SecretKey, sk2: SecretKey, ct: ModifiedCiphertext) -> int:
    """Dec_bar of Definition def:modification: ``c~ = Dec(sk2, (c2, c3))``, ``m = Dec(sk1, (c1, c~))``.

    Parameters
    ----------
    sk1 : SecretKey
        Key of the first input ciphertext (sk_0 for the controller parameter in eq:ec).
    sk2 : SecretKey
        Key of the second input ciphertext (sk_t for the state in eq:ec).
    ct : ModifiedCiphertext

    Returns
    -------
    int
        ``m1 m2 mod p``.

    Raises
    ------
    KeyMismatchError
        If the keys and ``ct`` do not belong to one group, or ``ct`` records steps other than
        ``sk1.t`` / ``sk2.t``.
    CiphertextError
        If ``ct`` is malformed.
    """
    check_instance(sk1, SecretKey, "sk1")
    check_instance(sk2, SecretKey, "sk2")
    grp = check_same_group(sk1, sk2, "sk1 and sk2")
    check_modified_ciphertext(grp, ct)
    if ct.t1 is not None and ct.t1 != sk1.t:
        raise KeyMismatchError(f"component c1 is of step t = {ct.t1}, sk1 is of step t = {sk1.t}")
    if ct.t2 is not None and ct.t2 != sk2.t:
        raise KeyMismatchError(f"component c2 is of step t = {ct.t2}, sk2 is of step t = {sk2.t}")
    c_tilde = decrypt_components(grp, sk2.s, ct.c2, ct.c3)
    return decrypt_components(grp, sk1.s, ct.c1, c_tilde)
