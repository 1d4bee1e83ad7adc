"""Forging an injected input (Definition def:adversary, step 1, and the remark after it).

The adversary (an eavesdropper in the middle, or a malicious server) replaces the server's
output ciphertexts by its own, built from public keys only, so that the plant applies the input
``a`` of its choosing. Row ``i`` of the forged alpha x beta matrix encrypts the products
``Ecd(a_i) Ecd(1)`` (column 0) and ``Ecd(0)^2`` (the other columns), as if the controller had
multiplied ``Phi = e_i`` by ``xi = (a_i, 0, ..., 0)``; the plant's ``Dcd(Sum(Dec(.)); Delta^2)``
gives :func:`injection_value`, the one definition of that arithmetic (:func:`injection_integers`).

Who reads a forgery: the plant decrypts it; with one randomness per matrix (the default) the
entries that encrypt the known ``Ecd(0)^2 = 1`` carry the mask, so anybody who sees the forged
ciphertexts also reads the injected input (``per_entry=True`` prevents that, at
``2 alpha beta + 2`` exponentiations instead of 4).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import as_finite_array, check_bool, check_int
from ..crypto import arith
from ..crypto.arith import RngLike
from ..crypto.checks import check_instance, check_same_group
from ..crypto.elgamal import Ciphertext, PublicKey, encrypt_member
from ..crypto.encoding import Encoder
from ..crypto.modified import ModifiedCiphertext
from ..errors import EncodingOverflowError, KeyMismatchError, ParameterError

__all__ = ["injection_integers", "injection_value", "forge_injection", "forge_injection_token"]

CtMatrix = list[list[Ciphertext]]
ModMatrix = list[list[ModifiedCiphertext]]


def injection_integers(a: Any, encoder: Encoder, n_cols: int) -> list[list[int]]:
    """Signed integers of the forged products: row i is ``[Ecd(a_i) Ecd(1), Ecd(0)^2, ...]``.

    The one definition of the forged input's arithmetic; :func:`injection_value` decodes it, the
    forgers encrypt it, and the ideal backend's compiled stage
    (:func:`encctl_gym.loop.quantize._forge`) is tested against it.

    Raises
    ------
    EncodingOverflowError
        If some ``a_i``, or a row of products, is not representable.
    """
    if not isinstance(encoder, Encoder):
        raise ParameterError(f"encoder must be an Encoder, got {encoder!r}")
    n_cols = check_int("n_cols", n_cols, minimum=1)
    arr = as_finite_array("a", a).reshape(-1)
    one = encoder.encode_signed(1.0)
    zero2 = encoder.encode_signed(0.0) ** 2
    half = encoder.group.half
    rows = []
    for ai in arr:
        try:
            w = encoder.encode_signed(float(ai)) * one
        except EncodingOverflowError as exc:
            raise EncodingOverflowError(f"injected value a = {float(ai)!r} is not representable: {exc}") from None
        if abs(w) + (n_cols - 1) * zero2 >= half:
            raise EncodingOverflowError(
                f"injected value a = {float(ai)!r} is not representable: |Ecd(a) Ecd(1)| = {abs(w)} "
                f"exceeds (p-1)/2 for a {encoder.group.bits}-bit group"
            )
        rows.append([w] + [zero2] * (n_cols - 1))
    return rows


def injection_value(a: Any, encoder: Encoder, n_cols: int) -> np.ndarray:
    """Exactly the float the plant decodes from :func:`forge_injection` ``(..., a, encoder, n_cols)``.

    The forged row i holds the products ``Ecd(a_i) Ecd(1)`` (column 0) and ``Ecd(0)^2`` (the
    other ``n_cols - 1`` columns), as if the controller had multiplied ``Phi = e_i`` by
    ``xi = (a_i, 0, ..., 0)``: every factor is an encoding at scale Delta (Definition def:ec),
    so the plant's ``Dcd(Sum(Dec(.)); Delta^2)`` gives
    ``(Ecd(a_i) Ecd(1) + (n_cols - 1) Ecd(0)^2) / Delta^2``: ``a_i`` quantised at ``1/Delta``
    (``|Ecd(a) - Delta a| <= 1/2 + shift``), times ``Ecd(1)/Delta`` (exactly 1 when Delta is
    a quadratic residue, e.g. a perfect square such as 4096), plus ``(n_cols - 1) Ecd(0)^2 /
    Delta^2`` (0 is not in the group; ``Ecd(0) = 1``).

    Parameters
    ----------
    a : array_like, shape (alpha,)
        The attacker's input (Definition def:adversary).
    encoder : Encoder
        The plant's encoder (group and Delta are public).
    n_cols : int
        beta, the number of columns of the controller's output matrix.
    """
    rows = injection_integers(a, encoder, n_cols)
    return encoder.decode_signed_array(np.asarray([sum(r) for r in rows], dtype=object), power=2)


def _injection_plaintexts(a: Any, encoder: Encoder, n_cols: int) -> list[list[int]]:
    p = encoder.group.p
    return [[w % p for w in row] for row in injection_integers(a, encoder, n_cols)]


def forge_injection(
    pk_0: PublicKey, pk_t: PublicKey, a: Any, encoder: Encoder, n_cols: int, rng: RngLike = None, *, per_entry: bool = False
) -> ModMatrix:
    """Forge, from public keys only, a modified-scheme output that the plant decodes to ``a``.

    Entry (i, 0) encrypts the product ``Ecd(a_i) Ecd(1)`` and entries (i, j >= 1) encrypt
    ``Ecd(0)^2`` (see :func:`injection_value`). Each entry is
    ``(g^r, g^r', m h_0^r h_t^r')``, which ``Dec_bar(sk_0, sk_t, .)`` maps to m
    (Definition def:modification), so ``Dcd(Sum(Dec_bar(.)); Delta^2)`` equals
    :func:`injection_value` bit for bit.

    Parameters
    ----------
    pk_0, pk_t : PublicKey
        The initial and the current public key (same group).
    a : array_like, shape (alpha,)
        The input the attacker wants the plant to apply.
    encoder : Encoder
        The plant's encoder.
    n_cols : int
        beta (the plant checks the output shape).
    rng : None, RandomSource or numpy.random.Generator
        A stream (an int seed is refused: it would repeat (r, r') in every forgery).
    per_entry : bool, default False
        Fresh randomness for every entry (``2 alpha beta + 2`` exponentiations) instead of one
        pair ``(r, r')`` for the whole matrix (4 exponentiations). With one pair, the entries
        that encrypt ``Ecd(0)^2 = 1`` carry the mask itself, so anybody who sees the forged
        ciphertexts reads the injected input (the plant decrypts it anyway, and the forger knows
        it); ``per_entry=True`` when a third party on the channel must not learn it.

    Returns
    -------
    list of list of ModifiedCiphertext, shape (alpha, n_cols)

    Raises
    ------
    KeyMismatchError
        If the public keys (or the encoder) belong to different groups.
    EncodingOverflowError
        If some ``a_i`` is not representable.
    """
    check_instance(pk_0, PublicKey, "pk_0")
    check_instance(pk_t, PublicKey, "pk_t")
    grp = check_same_group(pk_0, pk_t, "pk_0 and pk_t")
    if isinstance(encoder, Encoder) and encoder.group != grp:
        raise KeyMismatchError("the encoder's group differs from the public keys' group")
    plain = _injection_plaintexts(a, encoder, n_cols)
    src = arith.as_random_stream(rng, "forge_injection")
    p, q, g = grp.p, grp.q, grp.g
    per_entry = check_bool("per_entry", per_entry)

    def entry(m: int, r: int, r2: int) -> ModifiedCiphertext:
        c1, c2 = int(arith.powmod(g, r, p)), int(arith.powmod(g, r2, p))
        mask = arith.mulmod(arith.powmod(pk_0.h, r, p), arith.powmod(pk_t.h, r2, p), p)
        return ModifiedCiphertext(grp, c1, c2, int(arith.mulmod(m, mask, p)), pk_0.t, pk_t.t)

    if per_entry:
        return [[entry(m, src.between(1, q), src.between(1, q)) for m in row] for row in plain]
    # One pair (r, r') for the whole matrix: every entry is still a valid ciphertext of its
    # plaintext, and what the plant decodes does not depend on how the forger randomises.
    r, r2 = src.between(1, q), src.between(1, q)
    first = entry(1, r, r2)  # the mask itself, reused for every entry
    mask = first.c3
    return [
        [ModifiedCiphertext(grp, first.c1, first.c2, int(arith.mulmod(m, mask, p)), pk_0.t, pk_t.t) for m in row] for row in plain
    ]


def forge_injection_token(
    pk_t: PublicKey, a: Any, encoder: Encoder, n_cols: int, rng: RngLike = None, *, per_entry: bool = False
) -> CtMatrix:
    """Token- and static-scheme counterpart of :func:`forge_injection`: ``Enc(pk_t, .)`` of the
    same plaintexts (one ``r`` for the matrix: 2 exponentiations; ``per_entry=True``: one per
    entry, as in :func:`forge_injection`).

    The plant's ``Dcd(Sum(Dec(sk_t, .)); Delta^2)`` yields :func:`injection_value` bit for bit.

    Raises
    ------
    KeyMismatchError
        If the encoder's group differs from the key's.
    EncodingOverflowError
        If some ``a_i`` is not representable.
    """
    check_instance(pk_t, PublicKey, "pk_t")
    if isinstance(encoder, Encoder) and encoder.group != pk_t.group:
        raise KeyMismatchError("the encoder's group differs from the public key's group")
    plain = _injection_plaintexts(a, encoder, n_cols)
    src = arith.as_random_stream(rng, "forge_injection_token")
    grp = pk_t.group
    if check_bool("per_entry", per_entry):
        return [[encrypt_member(pk_t, m, src) for m in row] for row in plain]
    p = grp.p
    r = src.between(1, grp.q)  # one r for the matrix (see forge_injection)
    c1, mask = int(arith.powmod(grp.g, r, p)), arith.powmod(pk_t.h, r, p)
    return [[Ciphertext(grp, c1, int(arith.mulmod(m, mask, p)), pk_t.t) for m in row] for row in plain]
