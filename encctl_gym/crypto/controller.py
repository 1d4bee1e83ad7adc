"""The encrypted linear controller psi = Phi xi of eq:ec, its parties, and injection forging.

Parties
-------
:class:`ControllerServer` (the proposed scheme, eq:ec)
    Holds only ``pk_0`` and the ciphertexts of Phi, encrypted once under ``pk_0``. Each step
    it returns the alpha x beta matrix ``modified_eval(pk_0, ct_Phi_ij, ct_xi_j)``
    (Definition def:modification): modular multiplications only, no update token ever.
:class:`TokenControllerServer` (the conventional scheme of Definition def:ec)
    Holds Phi's ciphertexts under ``pk_t``; it must :meth:`~TokenControllerServer.receive_token`
    every step to CtUpd them (Example ex:dyn_elgamal), which by Proposition
    prop:vulnerability hands it every future key once one key is broken.
:class:`PlantCryptoSide`
    The system side: keys (``sk_0`` and the current ``sk_t``), encryption of the state
    under ``pk_t``, decryption (two-key ``Dec_bar(sk_0, sk_t, .)`` or ``Dec(sk_t, .)``),
    ``Sum`` (every decrypted product is lifted to a signed integer and the row is summed in
    Z, so a row sum never wraps modulo p), decoding with ``Delta**2`` and the key update.

Cost of one step, modified scheme, alpha = beta = 4: 8 exponentiations to encrypt the state,
1 for the key update, 4 for the column parts ``c2^(-s_t)`` (one per column: the state
ciphertext's first component is shared by the whole column); the parts ``c1^(-s_0)`` of
Phi's fixed first components are computed once at set-up. The server does 16 modular
multiplications. Total: 13 exponentiations per step.

High level
----------
:class:`EncryptedLinearController` runs the whole loop ``step(x) -> u``;
:class:`QuantizedLinearController` computes the *same* numbers without ciphertexts (same
integers for Phi and xi, products and sums in Z, decoding with ``Delta**2``), bit for bit.

Attacks
-------
:func:`forge_injection` (and :func:`forge_injection_token`) build, from public keys only,
output ciphertexts that make the plant apply the attacker's input ``a``
(Definition def:adversary, first step, and the remark after it); :func:`injection_value`
is exactly the float the plant decodes.
"""

from __future__ import annotations

from typing import Any, Literal, Optional, Sequence, Union

import numpy as np

from .._validation import as_finite_array, check_int, check_nonnegative
from ..errors import CiphertextError, EncodingOverflowError, KeyMismatchError, ParameterError
from . import arith
from .arith import RandomSource, RngLike
from .checks import check_group_of, check_instance
from .dyn_elgamal import UpdateToken, ciphertext_update, key_update
from .elgamal import (
    Ciphertext,
    PublicKey,
    SecretKey,
    check_ciphertext,
    check_same_group,
    encrypt,
    encrypt_member,
    keygen,
)
from .encoding import Encoder, lift
from .group import GroupParams, as_group
from .modified import ModifiedCiphertext, check_modified_ciphertext

__all__ = [
    "ControllerServer",
    "TokenControllerServer",
    "PlantCryptoSide",
    "EncryptedLinearController",
    "QuantizedLinearController",
    "forge_injection",
    "forge_injection_token",
    "injection_value",
    "SCHEMES",
]

SCHEMES = ("modified", "token")

CtMatrix = list[list[Ciphertext]]
ModMatrix = list[list[ModifiedCiphertext]]


# ---------------------------------------------------------------------- quantisation
class QuantizedLinearController:
    """psi = Phi xi with exactly the quantisation of the encrypted controller (no ciphertexts).

    Phi and xi are encoded to the signed integers of Definition def:ec (the same integers
    whose residues the plant encrypts), multiplied and summed in Z, and decoded with
    ``Delta**2``. :class:`EncryptedLinearController` decrypts to the same floats, bit for
    bit; the environment's ``crypto="ideal"`` backend uses this class.

    Parameters
    ----------
    Phi : array_like, shape (alpha, beta)
        Controller parameter (finite).
    encoder : Encoder
        Encoder (group, Delta, max_shift) for Phi and the state.
    x_bound : float
        Declared bound on the controller input: ``|xi_j| <= x_bound``.

    Attributes
    ----------
    phi_int : numpy.ndarray of object, shape (alpha, beta)
        The signed integers encoding Phi.
    state_encoder : Encoder
        ``encoder`` restricted to the range ``|x| <= x_bound``.

    Raises
    ------
    ParameterError
        If Phi is not a finite 2-D array or ``x_bound`` is negative or not finite.
    EncodingOverflowError
        If, for some ``|xi_j| <= x_bound``, a product or a row sum could reach ``(p-1)/2``
        in magnitude (it would wrap modulo p), or Phi itself is not representable.
    """

    def __init__(self, Phi: Any, encoder: Encoder, x_bound: float) -> None:
        if not isinstance(encoder, Encoder):
            raise ParameterError(f"encoder must be an Encoder, got {encoder!r}")
        phi = as_finite_array("Phi", Phi)
        if phi.ndim == 1:
            phi = phi.reshape(1, -1)
        if phi.ndim != 2:
            raise ParameterError(f"Phi must be a 2-D matrix, got shape {phi.shape}")
        self.Phi = phi
        self.alpha, self.beta = phi.shape
        self.encoder = encoder
        self.group = encoder.group
        self.x_bound = check_nonnegative("x_bound", x_bound)
        self.state_encoder = Encoder(
            encoder.group, encoder.delta, x_bound=self.x_bound, max_shift=encoder.max_shift
        )
        self.phi_int = encoder.encode_signed_array(phi)
        # Worst case over |xi_j| <= x_bound: |w_xi| <= round(Delta x_bound) + max_shift.
        w_max = self.state_encoder.max_abs_signed(self.x_bound)
        half = self.group.half
        for i in range(self.alpha):
            row_abs = sum(abs(w) for w in self.phi_int[i])
            if row_abs * w_max >= half:
                raise EncodingOverflowError(
                    f"row {i} of Phi can overflow: sum_j |Ecd(Phi_{i}j)| * (round(Delta x_bound) "
                    f"+ max_shift) = {row_abs * w_max} >= (p-1)/2 for a {self.group.bits}-bit "
                    f"group (Delta = {encoder.delta!r}, x_bound = {self.x_bound!r}); use a "
                    f"larger group or a smaller Delta or x_bound"
                )
        self._phi_rows = [[int(w) for w in row] for row in self.phi_int]

    def encode_state(self, x: Any) -> list[int]:
        """The signed integers encoding the controller input xi (checks shape, NaN, range)."""
        try:
            xi = np.asarray(x, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"x must be a numeric vector, got {x!r}") from exc
        if xi.size != self.beta or (xi.ndim > 1 and max(xi.shape) != xi.size):
            raise ParameterError(f"x must have {self.beta} entries, got shape {np.shape(x)}")
        xi = xi.reshape(self.beta)
        return [int(w) for w in self.state_encoder.encode_signed_array(xi)]

    def row_sums(self, w_xi: Sequence[int]) -> list[int]:
        """``Sum`` of eq:ec over the integer products: ``sum_j w_Phi_ij w_xi_j`` in Z."""
        return [sum(a * b for a, b in zip(row, w_xi)) for row in self._phi_rows]

    def decode_row_sums(self, sums: Sequence[int]) -> np.ndarray:
        """Decode integer row sums with ``Delta**2`` (exactly rounded floats)."""
        return self.encoder.decode_signed_array(np.asarray(list(sums), dtype=object), power=2)

    def compute(self, x: Any) -> np.ndarray:
        """The controller output psi = Dcd(Sum(Ecd(Phi) Ecd(x)); Delta^2), shape (alpha,)."""
        return self.decode_row_sums(self.row_sums(self.encode_state(x)))

    __call__ = compute
    step = compute

    def compute_batch(self, X: Any) -> np.ndarray:
        """Row-wise :meth:`compute` for ``X`` of shape (runs, beta); returns (runs, alpha)."""
        arr = as_finite_array("X", X)
        if arr.ndim != 2 or arr.shape[1] != self.beta:
            raise ParameterError(f"X must have shape (runs, {self.beta}), got {arr.shape}")
        W = self.state_encoder.encode_signed_array(arr)  # (runs, beta), object ints
        S = W.dot(self.phi_int.T)  # exact integer products and sums (object dtype)
        return self.encoder.decode_signed_array(S, power=2)

    def __repr__(self) -> str:
        return (
            f"QuantizedLinearController(alpha={self.alpha}, beta={self.beta}, "
            f"encoder={self.encoder!r}, x_bound={self.x_bound!r})"
        )


# ---------------------------------------------------------------------- servers
def _ct_matrix(name: str, mat: Any, cls: type, shape: Optional[tuple[int, int]] = None) -> list[list[Any]]:
    try:
        rows = [list(r) for r in mat]
    except TypeError as exc:
        raise CiphertextError(f"{name} must be a matrix of {cls.__name__}, got {mat!r}") from exc
    if not rows or any(len(r) != len(rows[0]) for r in rows) or not rows[0]:
        raise CiphertextError(f"{name} must be a non-empty rectangular matrix, got row lengths "
                              f"{[len(r) for r in rows]}")
    if shape is not None and (len(rows), len(rows[0])) != shape:
        raise CiphertextError(f"{name} must have shape {shape}, got {(len(rows), len(rows[0]))}")
    for r in rows:
        for c in r:
            if not isinstance(c, cls):
                raise CiphertextError(f"{name} must contain {cls.__name__} entries, got {c!r}")
    return rows


class ControllerServer:
    """Controller server of eq:ec: holds ``pk_0`` and ``ct_Phi`` under ``pk_0``, nothing secret.

    The class has ``__slots__`` and stores exactly a public key and ciphertexts; it has no
    randomness and no method that accepts a token or a secret key.

    Parameters
    ----------
    pk0 : PublicKey
        The initial public key.
    ct_phi : matrix of Ciphertext, shape (alpha, beta)
        ``Enc(pk_0, Ecd(Phi_ij; Delta))``.

    Raises
    ------
    CiphertextError
        If ``ct_phi`` is not a rectangular matrix of valid ciphertexts.
    """

    __slots__ = ("_pk0", "_ct_phi")

    def __init__(self, pk0: PublicKey, ct_phi: Sequence[Sequence[Ciphertext]]) -> None:
        check_instance(pk0, PublicKey, "pk0")
        rows = _ct_matrix("ct_phi", ct_phi, Ciphertext)
        for r in rows:
            for c in r:
                check_ciphertext(pk0.group, c)
        self._pk0 = pk0
        self._ct_phi = tuple(tuple(r) for r in rows)

    @property
    def pk0(self) -> PublicKey:
        """The public key ``pk_0``."""
        return self._pk0

    @property
    def ct_phi(self) -> tuple[tuple[Ciphertext, ...], ...]:
        """Phi's ciphertexts (under ``pk_0``)."""
        return self._ct_phi

    @property
    def shape(self) -> tuple[int, int]:
        """(alpha, beta)."""
        return len(self._ct_phi), len(self._ct_phi[0])

    def evaluate(self, ct_xi: Sequence[Ciphertext]) -> ModMatrix:
        """EC of eq:ec: the matrix ``[modified_eval(pk_0, ct_Phi_ij, ct_xi_j)]_ij``.

        Parameters
        ----------
        ct_xi : sequence of Ciphertext, length beta
            The state ciphertexts under ``pk_t``.

        Returns
        -------
        list of list of ModifiedCiphertext, shape (alpha, beta)

        Raises
        ------
        CiphertextError
            If ``ct_xi`` has the wrong length or a malformed entry.
        """
        grp = self._pk0.group
        alpha, beta = self.shape
        cts = list(ct_xi) if not isinstance(ct_xi, Ciphertext) else [ct_xi]
        if len(cts) != beta:
            raise CiphertextError(f"expected {beta} state ciphertexts, got {len(cts)}")
        for c in cts:
            check_ciphertext(grp, c)
        p = grp.p
        out: ModMatrix = []
        for row in self._ct_phi:
            out.append(
                [
                    ModifiedCiphertext(grp, a.c1, b.c1, int(arith.mulmod(a.c2, b.c2, p)), a.t, b.t)
                    for a, b in zip(row, cts)
                ]
            )
        return out

    def __repr__(self) -> str:
        return f"ControllerServer(shape={self.shape}, pk0=<t={self._pk0.t}>)"


class TokenControllerServer:
    """Conventional server (Definition def:ec): Phi's ciphertexts under ``pk_t``, updated by tokens.

    Parameters
    ----------
    pk : PublicKey
        The public key of the ciphertexts (``pk_0`` at set-up).
    ct_phi : matrix of Ciphertext, shape (alpha, beta)
    rng : None, int, RandomSource or numpy.random.Generator
        The server's own randomness for CtUpd re-randomisation.

    Attributes
    ----------
    t : int
        Step of the ciphertexts it holds.
    last_token : UpdateToken or None
        The last token received: what a malicious server of this scheme gets each step.
    """

    __slots__ = ("_pk", "_ct_phi", "_rng", "t", "last_token")

    def __init__(self, pk: PublicKey, ct_phi: Sequence[Sequence[Ciphertext]], rng: RngLike = None) -> None:
        check_instance(pk, PublicKey, "pk")
        rows = _ct_matrix("ct_phi", ct_phi, Ciphertext)
        for r in rows:
            for c in r:
                check_ciphertext(pk.group, c)
        self._pk = pk
        self._ct_phi = [list(r) for r in rows]
        self._rng = arith.as_random_source(rng, "token server")
        self.t = pk.t
        self.last_token: Optional[UpdateToken] = None

    @property
    def shape(self) -> tuple[int, int]:
        """(alpha, beta)."""
        return len(self._ct_phi), len(self._ct_phi[0])

    @property
    def ct_phi(self) -> tuple[tuple[Ciphertext, ...], ...]:
        """Phi's ciphertexts under the current key."""
        return tuple(tuple(r) for r in self._ct_phi)

    def receive_token(self, token: UpdateToken) -> None:
        """CtUpd every ciphertext of Phi with ``sigma_t`` (Example ex:dyn_elgamal), t -> t + 1.

        Raises
        ------
        KeyMismatchError
            If the token is not for the server's current step.
        """
        if not isinstance(token, UpdateToken):
            raise ParameterError(f"token must be an UpdateToken, got {token!r}")
        if token.t is not None and token.t != self.t:
            raise KeyMismatchError(f"token is for step t = {token.t}, server is at step t = {self.t}")
        self._ct_phi = [
            [ciphertext_update(self._pk, c, token, self._rng) for c in row] for row in self._ct_phi
        ]
        self.t += 1
        self.last_token = token

    def evaluate(self, ct_xi: Sequence[Ciphertext]) -> CtMatrix:
        """The conventional EC: ``[Eval(pk_t, ct_Phi_ij, ct_xi_j)]_ij`` (two components each).

        Raises
        ------
        CiphertextError
            If ``ct_xi`` has the wrong length or a malformed entry.
        KeyMismatchError
            If a state ciphertext is of another step than the server's ciphertexts.
        """
        grp = self._pk.group
        alpha, beta = self.shape
        cts = list(ct_xi) if not isinstance(ct_xi, Ciphertext) else [ct_xi]
        if len(cts) != beta:
            raise CiphertextError(f"expected {beta} state ciphertexts, got {len(cts)}")
        for c in cts:
            check_ciphertext(grp, c)
            if c.t is not None and c.t != self.t:
                raise KeyMismatchError(
                    f"state ciphertext is of step t = {c.t}, server's Phi ciphertexts of step t = {self.t}"
                )
        p = grp.p
        return [
            [
                Ciphertext(grp, int(arith.mulmod(a.c1, b.c1, p)), int(arith.mulmod(a.c2, b.c2, p)), self.t)
                for a, b in zip(row, cts)
            ]
            for row in self._ct_phi
        ]

    def __repr__(self) -> str:
        return f"TokenControllerServer(shape={self.shape}, t={self.t})"


# ---------------------------------------------------------------------- plant side
class PlantCryptoSide:
    """The system side of eq:ec: keys, state encryption, decryption, Sum, decoding, key update.

    Parameters
    ----------
    quantization : QuantizedLinearController
        Encoding of Phi and of the state (shared with the plaintext reference).
    scheme : {"modified", "token"}
    rng : None, int, RandomSource or numpy.random.Generator
        Randomness for keys and encryptions.

    Attributes
    ----------
    pk0 : PublicKey
        The initial public key (the modified scheme's server keeps it forever).
    pk, sk : PublicKey, SecretKey
        The current key pair of step ``t``.
    """

    def __init__(
        self,
        quantization: QuantizedLinearController,
        scheme: Literal["modified", "token"] = "modified",
        rng: RngLike = None,
    ) -> None:
        if scheme not in SCHEMES:
            raise ParameterError(f"scheme must be one of {SCHEMES}, got {scheme!r}")
        self.scheme = scheme
        self.quantization = quantization
        self.group = quantization.group
        self._rng = arith.as_random_source(rng, "plant")
        self.pk0, self._sk0 = keygen(self.group, self._rng)
        self.pk, self._sk = self.pk0, self._sk0
        self._mask0: dict[int, Any] = {}

    @property
    def t(self) -> int:
        """The current time step."""
        return self._sk.t

    def encrypt_parameter(self) -> CtMatrix:
        """``Enc(pk_0, Ecd(Phi_ij; Delta))`` for every entry; caches ``c1^(-s_0)`` (modified scheme)."""
        p, q = self.group.p, self.group.q
        ct = [
            [encrypt(self.pk0, int(w) % p, self._rng) for w in row]
            for row in self.quantization.phi_int
        ]
        if self.scheme == "modified":
            s0 = self._sk0.s
            for row in ct:
                for c in row:
                    self._mask0[c.c1] = arith.powmod(c.c1, q - s0, p)
        return ct

    def encrypt_state(self, x: Any) -> list[Ciphertext]:
        """``Enc(pk_t, Ecd(x_j; Delta))`` for j = 1..beta (checks the range |x_j| <= x_bound)."""
        p = self.group.p
        # The encoder only returns members of G, so the plaintext check can be skipped.
        return [encrypt_member(self.pk, w % p, self._rng) for w in self.quantization.encode_state(x)]

    @property
    def secret_key(self) -> SecretKey:
        """The current secret key ``sk_t``. The plant's own; the attack environment uses it to
        simulate an adversary's break of a ciphertext whose deciphering time it has charged."""
        return self._sk

    def decrypt_products(self, out: Sequence[Sequence[Any]]) -> list[list[int]]:
        """Decrypt the server's alpha x beta output and lift every product to a signed integer.

        Modified scheme: ``Dec_bar(sk_0, sk_t, .)`` with the cached ``c1^(-s_0)`` and one
        ``c2^(-s_t)`` per distinct c2 (per column). Token scheme: ``Dec(sk_t, .)``.

        Raises
        ------
        CiphertextError
            If the output has the wrong shape or malformed entries.
        KeyMismatchError
            If an entry records steps other than (0, t) (modified) or t (token).
        """
        grp = self.group
        p, q = grp.p, grp.q
        shape = (self.quantization.alpha, self.quantization.beta)
        if self.scheme == "modified":
            rows = _ct_matrix("server output", out, ModifiedCiphertext, shape)
            s0, st, t = self._sk0.s, self._sk.s, self._sk.t
            col: dict[int, Any] = {}
            other: dict[int, Any] = {}  # c1 parts of ciphertexts that are not Phi's (e.g. injected)
            res = []
            for row in rows:
                lifted = []
                for c in row:
                    if not isinstance(c, ModifiedCiphertext):
                        check_modified_ciphertext(grp, c)  # raises CiphertextError
                    check_group_of(c, grp)
                    if not (0 < c.c1 < p and 0 < c.c2 < p and grp.contains(c.c3)):
                        check_modified_ciphertext(grp, c)  # raises, naming the component
                    if (c.t1 is not None and c.t1 != self._sk0.t) or (c.t2 is not None and c.t2 != t):
                        raise KeyMismatchError(
                            f"output ciphertext records steps (t1, t2) = ({c.t1}, {c.t2}), "
                            f"the plant decrypts with the keys of steps ({self._sk0.t}, {t})"
                        )
                    # c1 and c2 are checked for membership when first seen (the cached
                    # c1 of Phi's ciphertexts were made by the plant itself).
                    a = self._mask0.get(c.c1)
                    if a is None:
                        a = other.get(c.c1)
                    if a is None:  # not one of Phi's ciphertexts (e.g. an injected one)
                        if not grp.contains(c.c1):
                            check_modified_ciphertext(grp, c)  # raises, naming c1
                        a = other[c.c1] = arith.powmod(c.c1, q - s0, p)
                    b = col.get(c.c2)
                    if b is None:
                        if not grp.contains(c.c2):
                            check_modified_ciphertext(grp, c)  # raises, naming c2
                        b = col[c.c2] = arith.powmod(c.c2, q - st, p)
                    m = int(arith.mulmod(arith.mulmod(a, b, p), c.c3, p))
                    lifted.append(lift(grp, m))
                res.append(lifted)
            return res
        rows = _ct_matrix("server output", out, Ciphertext, shape)
        st, t = self._sk.s, self._sk.t
        masks: dict[int, Any] = {}  # c1^(-s_t) per distinct c1
        res = []
        for row in rows:
            lifted = []
            for c in row:
                check_ciphertext(grp, c)
                if c.t is not None and c.t != t:
                    raise KeyMismatchError(
                        f"output ciphertext is of step t = {c.t}, the plant's key of step t = {t}"
                    )
                a = masks.get(c.c1)
                if a is None:
                    a = masks[c.c1] = arith.powmod(c.c1, q - st, p)
                m = int(arith.mulmod(a, c.c2, p))
                lifted.append(lift(grp, m))
            res.append(lifted)
        return res

    def decrypt_output(self, out: Sequence[Sequence[Any]]) -> np.ndarray:
        """``Dcd(Sum(Dec(.)); Delta^2)``: the control input, shape (alpha,)."""
        products = self.decrypt_products(out)
        return self.quantization.decode_row_sums([sum(r) for r in products])

    def update_keys(self) -> UpdateToken:
        """KeyUpd (Example ex:dyn_elgamal): move to step t + 1; return sigma_t.

        The modified scheme discards the token; the token scheme sends it to the server.
        """
        self.pk, self._sk, token = key_update(self.pk, self._sk, self._rng)
        return token

    def __repr__(self) -> str:
        return f"PlantCryptoSide(scheme={self.scheme!r}, t={self.t}, bits={self.group.bits})"


# ---------------------------------------------------------------------- high level
class EncryptedLinearController:
    """Closed-loop encrypted linear controller u = Phi x of eq:ec (``step(x) -> u``).

    Each :meth:`step`: the plant encrypts x under ``pk_t``; the server evaluates (modified
    scheme: ``Eval_bar`` with Phi under ``pk_0``; token scheme: ``Eval`` with Phi under
    ``pk_t``); the plant decrypts (``Dec_bar(sk_0, sk_t, .)`` or ``Dec(sk_t, .)``), sums
    each row in Z, decodes with ``Delta**2`` and updates the keys (the token scheme sends
    sigma_t to the server, which CtUpds Phi's ciphertexts). The result equals
    :meth:`QuantizedLinearController.compute` bit for bit.

    Parameters
    ----------
    Phi : array_like, shape (alpha, beta)
        Controller parameter.
    group : GroupParams or int
        The group, or a bit length (:func:`~.group.get_group`).
    delta : float
        Scaling factor Delta > 0 of Definition def:ec.
    x_bound : float
        Declared bound ``|x_j| <= x_bound`` on the controller input.
    scheme : {"modified", "token"}, default "modified"
    rng : None, int, RandomSource or numpy.random.Generator
        Randomness (``None``: secure; a seed makes runs reproducible, unsafe for deployment).
    max_shift : int, optional
        Passed to :class:`~.encoding.Encoder`.

    Attributes
    ----------
    server : ControllerServer or TokenControllerServer
    plant : PlantCryptoSide
    quantized : QuantizedLinearController
        The plaintext reference with the same quantisation.
    last_state_ciphertexts : list of Ciphertext or None
        ``ct_{x,t}`` of the last step (what an eavesdropper sees).
    last_output_ciphertexts : matrix or None
        The output matrix the plant decrypted in the last step (possibly injected).

    Raises
    ------
    EncodingOverflowError
        If some ``|x_j| <= x_bound`` could make a product or row sum wrap modulo p.
    """

    def __init__(
        self,
        Phi: Any,
        group: Union[GroupParams, int],
        delta: float,
        x_bound: float,
        scheme: Literal["modified", "token"] = "modified",
        rng: RngLike = None,
        max_shift: Optional[int] = None,
    ) -> None:
        if scheme not in SCHEMES:
            raise ParameterError(f"scheme must be one of {SCHEMES}, got {scheme!r}")
        src = arith.as_random_source(rng, "controller")
        self.group = as_group(group, rng=src)
        self.scheme = scheme
        self.encoder = Encoder(self.group, delta, max_shift=max_shift)
        self.quantized = QuantizedLinearController(Phi, self.encoder, x_bound)
        self.alpha, self.beta = self.quantized.alpha, self.quantized.beta
        self.x_bound = self.quantized.x_bound
        # The server's randomness (token scheme only) is independent of the plant's.
        server_rng: RandomSource = (
            arith.SecureRandom() if src.secure else arith.SeededRandom(src.below(2**63))
        )
        self.plant = PlantCryptoSide(self.quantized, scheme, src)
        ct_phi = self.plant.encrypt_parameter()
        self.server: Union[ControllerServer, TokenControllerServer]
        if scheme == "modified":
            self.server = ControllerServer(self.plant.pk0, ct_phi)
        else:
            self.server = TokenControllerServer(self.plant.pk0, ct_phi, server_rng)
        self.last_state_ciphertexts: Optional[list[Ciphertext]] = None
        self.last_output_ciphertexts: Optional[list[list[Any]]] = None

    @property
    def pk(self) -> PublicKey:
        """The current public key ``pk_t``."""
        return self.plant.pk

    @property
    def pk0(self) -> PublicKey:
        """The initial public key ``pk_0``."""
        return self.plant.pk0

    @property
    def t(self) -> int:
        """The current time step (number of completed steps)."""
        return self.plant.t

    def step(self, x: Any, inject: Optional[Sequence[Sequence[Any]]] = None) -> np.ndarray:
        """One control step: encrypt x, evaluate on the server, decrypt, Sum, decode, update keys.

        Parameters
        ----------
        x : array_like, shape (beta,)
            Controller input with ``|x_j| <= x_bound``.
        inject : matrix of ModifiedCiphertext (or Ciphertext for the token scheme), optional
            Replaces the server's output (a man-in-the-middle or malicious server, e.g.
            from :func:`forge_injection`); the server still sees the state ciphertexts.

        Returns
        -------
        numpy.ndarray, shape (alpha,)
            The decoded control input.

        Raises
        ------
        ParameterError
            If x has the wrong size or non-finite entries.
        EncodingOverflowError
            If ``|x_j| > x_bound``.
        CiphertextError, KeyMismatchError
            If an injected output is malformed or of the wrong step.
        """
        ct_x = self.plant.encrypt_state(x)
        out = self.server.evaluate(ct_x)
        if inject is not None:
            out = [list(r) for r in inject]
        u = self.plant.decrypt_output(out)
        token = self.plant.update_keys()
        if isinstance(self.server, TokenControllerServer):
            self.server.receive_token(token)
        self.last_state_ciphertexts = ct_x
        self.last_output_ciphertexts = out
        return u

    def reference(self, x: Any) -> np.ndarray:
        """The plaintext computation with the same quantisation (no ciphertexts, no key update)."""
        return self.quantized.compute(x)

    def __repr__(self) -> str:
        return (
            f"EncryptedLinearController(scheme={self.scheme!r}, shape=({self.alpha}, {self.beta}), "
            f"bits={self.group.bits}, delta={self.encoder.delta!r}, x_bound={self.x_bound!r}, t={self.t})"
        )


# ---------------------------------------------------------------------- injection
def _injection_integers(a: Any, encoder: Encoder, n_cols: int) -> list[list[int]]:
    """Signed integers of the forged products: row i is ``[Ecd(a_i) Ecd(1), Ecd(0)^2, ...]``."""
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
    rows = _injection_integers(a, encoder, n_cols)
    return encoder.decode_signed_array(np.asarray([sum(r) for r in rows], dtype=object), power=2)


def _injection_plaintexts(a: Any, encoder: Encoder, n_cols: int) -> list[list[int]]:
    p = encoder.group.p
    return [[w % p for w in row] for row in _injection_integers(a, encoder, n_cols)]


def forge_injection(
    pk_0: PublicKey,
    pk_t: PublicKey,
    a: Any,
    encoder: Encoder,
    n_cols: int,
    rng: RngLike = None,
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
    # One pair (r, r') for the whole matrix: 4 exponentiations per forgery. Every entry is still
    # a valid ciphertext of its plaintext; how an attacker randomises its own forgeries does not
    # change what the plant decodes.
    r, r2 = src.between(1, q), src.between(1, q)
    c1, c2 = int(arith.powmod(g, r, p)), int(arith.powmod(g, r2, p))
    mask = arith.mulmod(arith.powmod(pk_0.h, r, p), arith.powmod(pk_t.h, r2, p), p)
    return [
        [ModifiedCiphertext(grp, c1, c2, int(arith.mulmod(m, mask, p)), pk_0.t, pk_t.t) for m in row]
        for row in plain
    ]


def forge_injection_token(
    pk_t: PublicKey, a: Any, encoder: Encoder, n_cols: int, rng: RngLike = None
) -> CtMatrix:
    """Token-scheme counterpart of :func:`forge_injection`: ``Enc(pk_t, .)`` of the same plaintexts.

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
    p = grp.p
    r = src.between(1, grp.q)  # one r for the matrix (see forge_injection): 2 exponentiations
    c1, mask = int(arith.powmod(grp.g, r, p)), arith.powmod(pk_t.h, r, p)
    return [[Ciphertext(grp, c1, int(arith.mulmod(m, mask, p)), pk_t.t) for m in row] for row in plain]
