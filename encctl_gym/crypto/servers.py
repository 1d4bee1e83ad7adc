"""The controller servers of the encrypted linear controller psi = Phi xi (eq:ec, Definition def:ec).

A server holds public keys and ciphertexts only, and evaluates the controller on the state
ciphertexts it receives:

:class:`ControllerServer` (the proposed scheme, eq:ec)
    Holds ``pk_0`` and the ciphertexts of Phi, encrypted once under ``pk_0``. Each step it
    returns the alpha x beta matrix ``Eval_bar(pk_0, ct_Phi_ij, ct_xi_j)`` (Definition
    def:modification): modular multiplications only, no update token ever.
:class:`StaticControllerServer` (one fixed key pair)
    Holds Phi's ciphertexts under the one key and returns ``Eval(pk, ct_Phi_ij, ct_xi_j)``
    (Example ex:elgamal); nothing is ever updated.
:class:`TokenControllerServer` (the conventional dynamic key of Definition def:ec)
    The static server plus :meth:`~TokenControllerServer.receive_token`: every step it CtUpds
    Phi's ciphertexts to the next key (Example ex:dyn_elgamal), which by Proposition
    prop:vulnerability hands it every future key once one key is broken.

Each evaluation checks the state ciphertexts once (their group and their step) and then runs
the raw algorithms of :mod:`.modified` and :mod:`.elgamal`; Phi's ciphertexts are checked once,
when the server is set up.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from .._validation import format_value
from ..errors import CiphertextError, KeyMismatchError, ParameterError
from . import arith
from .arith import RngLike
from .checks import check_ciphertext_matrix, check_instance
from .dyn_elgamal import UpdateToken, ciphertext_update
from .elgamal import Ciphertext, PublicKey, check_ciphertext, mult_members
from .modified import ModifiedCiphertext, modified_eval_members

__all__ = ["ControllerServer", "StaticControllerServer", "TokenControllerServer"]


def _parameter_ciphertexts(pk: PublicKey, ct_phi: Sequence[Sequence[Ciphertext]]) -> list[list[Ciphertext]]:
    check_instance(pk, PublicKey, "pk")
    rows = check_ciphertext_matrix("ct_phi", ct_phi, Ciphertext)
    for r in rows:
        for c in r:
            check_ciphertext(pk.group, c)
    return rows


def _state_ciphertexts(pk: PublicKey, ct_xi: Any, beta: int, step: int | None) -> list[Ciphertext]:
    """The ``beta`` state ciphertexts, each checked (group, components in G, and ``step`` if given)."""
    try:
        cts = [ct_xi] if isinstance(ct_xi, Ciphertext) else list(ct_xi)
    except TypeError:
        raise CiphertextError(
            f"the state ciphertexts must be a sequence of {beta} Ciphertext, got {format_value(ct_xi)}"
        ) from None
    if len(cts) != beta:
        raise CiphertextError(f"expected {beta} state ciphertexts, got {len(cts)}")
    for c in cts:
        check_ciphertext(pk.group, c)
        if step is not None and c.t is not None and c.t != step:
            raise KeyMismatchError(f"state ciphertext is of step t = {c.t}, the server's Phi ciphertexts of step t = {step}")
    return cts


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
    KeyMismatchError
        If a ciphertext belongs to another group than ``pk0``.
    """

    __slots__ = ("_pk0", "_ct_phi")

    def __init__(self, pk0: PublicKey, ct_phi: Sequence[Sequence[Ciphertext]]) -> None:
        rows = _parameter_ciphertexts(pk0, ct_phi)
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

    def evaluate(self, ct_xi: Sequence[Ciphertext]) -> list[list[ModifiedCiphertext]]:
        """EC of eq:ec: the matrix ``[Eval_bar(pk_0, ct_Phi_ij, ct_xi_j)]_ij`` (Definition def:modification).

        Parameters
        ----------
        ct_xi : sequence of Ciphertext, length beta
            The state ciphertexts under ``pk_t``.

        Raises
        ------
        CiphertextError
            If ``ct_xi`` has the wrong length or a malformed entry.
        KeyMismatchError
            If a state ciphertext belongs to another group.
        """
        grp = self._pk0.group
        cts = _state_ciphertexts(self._pk0, ct_xi, self.shape[1], None)
        return [[modified_eval_members(grp, a, b) for a, b in zip(row, cts)] for row in self._ct_phi]

    def __repr__(self) -> str:
        return f"ControllerServer(shape={self.shape}, pk0=<t={self._pk0.t}>)"


class StaticControllerServer:
    """Server of one fixed key pair: Phi's ciphertexts under ``pk``, ``Eval`` of Example ex:elgamal.

    Parameters
    ----------
    pk : PublicKey
        The public key of the ciphertexts.
    ct_phi : matrix of Ciphertext, shape (alpha, beta)

    Attributes
    ----------
    t : int
        Step of the ciphertexts it holds (that of ``pk``).
    """

    __slots__ = ("_pk", "_ct_phi", "t")

    def __init__(self, pk: PublicKey, ct_phi: Sequence[Sequence[Ciphertext]]) -> None:
        rows = _parameter_ciphertexts(pk, ct_phi)
        self._pk = pk
        self._ct_phi = rows
        self.t = pk.t

    @property
    def shape(self) -> tuple[int, int]:
        """(alpha, beta)."""
        return len(self._ct_phi), len(self._ct_phi[0])

    @property
    def ct_phi(self) -> tuple[tuple[Ciphertext, ...], ...]:
        """Phi's ciphertexts under the current key."""
        return tuple(tuple(r) for r in self._ct_phi)

    def evaluate(self, ct_xi: Sequence[Ciphertext]) -> list[list[Ciphertext]]:
        """The conventional EC: ``[Eval(pk_t, ct_Phi_ij, ct_xi_j)]_ij`` (two components each).

        Raises
        ------
        CiphertextError
            If ``ct_xi`` has the wrong length or a malformed entry.
        KeyMismatchError
            If a state ciphertext is of another group or step than the server's ciphertexts.
        """
        grp = self._pk.group
        cts = _state_ciphertexts(self._pk, ct_xi, self.shape[1], self.t)
        return [[mult_members(grp, a, b, self.t) for a, b in zip(row, cts)] for row in self._ct_phi]

    def __repr__(self) -> str:
        return f"{type(self).__name__}(shape={self.shape}, t={self.t})"


class TokenControllerServer(StaticControllerServer):
    """Conventional server (Definition def:ec): Phi's ciphertexts under ``pk_t``, updated by tokens.

    Parameters
    ----------
    pk : PublicKey
        The public key of the ciphertexts (``pk_0`` at set-up).
    ct_phi : matrix of Ciphertext, shape (alpha, beta)
    rng : None, int, RandomSource or numpy.random.Generator
        The server's own randomness for CtUpd re-randomisation (an int seed is keyed by the
        purpose ``"token server"``).

    Attributes
    ----------
    t : int
        Step of the ciphertexts it holds.
    last_token : UpdateToken or None
        The last token received: what a malicious server of this scheme gets each step.
    """

    __slots__ = ("_rng", "last_token")

    def __init__(self, pk: PublicKey, ct_phi: Sequence[Sequence[Ciphertext]], rng: RngLike = None) -> None:
        super().__init__(pk, ct_phi)
        self._rng = arith.as_random_source(rng, "token server")
        self.last_token: UpdateToken | None = None

    def receive_token(self, token: UpdateToken) -> None:
        """CtUpd every ciphertext of Phi with ``sigma_t`` (Example ex:dyn_elgamal), t -> t + 1.

        Raises
        ------
        KeyMismatchError
            If the token is not for the server's current step.
        """
        if not isinstance(token, UpdateToken):
            raise ParameterError(f"token must be an UpdateToken, got {format_value(token)}")
        if token.t is not None and token.t != self.t:
            raise KeyMismatchError(f"token is for step t = {token.t}, server is at step t = {self.t}")
        self._ct_phi = [[ciphertext_update(self._pk, c, token, self._rng) for c in row] for row in self._ct_phi]
        self.t += 1
        self.last_token = token
