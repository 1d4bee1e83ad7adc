"""How the adversary's action enters the loop: the one injection seam (Definition def:adversary, step 1).

Three modes, the environment's ``injection`` key (and, per step, the game's):

============  ===========================================================================
mode          the input the plant applies in the period
============  ===========================================================================
``replace``   the adversary's forgery *replaces* the server's output: ``u = Dcd(Ecd(a))``
              (the forgery of Definition def:adversary; :mod:`encctl_gym.attacks.forgery`)
``add``       the server's honest output *plus* the action: ``u = Phi x + a``, quantised as
              the plant decodes it (:func:`added_row`); the adversary keeps ``Phi x`` and
              adds its excitation (a stealthy, covert attacker)
``pass``      the honest loop: ``u = Phi x`` (eq:ec); the action is unused and no energy is spent
``scale``     the malleable server *without any key* (Remark after def:adversary): row ``i`` of
              the honest output is multiplied by an integer ``c_i`` in the plaintext domain,
              ``u_i = c_i (Phi x)_i`` (:func:`scale_multipliers`: the sign of ``a_i`` picks
              ``c_i`` = 0, 1 or :func:`scale_gain`); see :mod:`encctl_gym.agents.stealth`
============  ===========================================================================

What a scheme must have broken to *add* is the scheme's business
(:meth:`~encctl_gym.loop.scheme.EncryptionScheme.injection_needs`): on the multiplicative ElGamal
schemes the adversary reads the honest products with ``sk_0`` and ``sk_t`` (one more key than the
samples, charged to its budget) in the period itself, so it needs the period's key at once
(``decipher_delay = 0``); on an additive scheme it multiplies the output by ``Enc(d)`` and needs
no key at all.

The additive rule, in the integers the plant decodes (Definition def:ec, eq:ec): row ``i`` of the
honest output holds the products ``P_ij = Ecd(Phi_ij) Ecd(x_j)`` and decodes to
``sum_j P_ij / Delta^2``. Adding ``a_i`` puts ``d_i = rint(Delta a_i) Ecd(1)`` on the first
product (``Ecd(1) / Delta`` is 1 when Delta is a quadratic residue, e.g. 4096) and sends the
plaintext nearest to ``P_i0 + d_i`` (the scheme's
:meth:`~encctl_gym.loop.scheme.EncryptionScheme.nearest_plaintext`): on ElGamal the plaintexts
are the subgroup G, which the plant checks every decrypted product against, so the adversary
sends the nearest member of G (the encoder's search, :func:`~encctl_gym.crypto.encoding.nearest_member`;
an error of a few ``1 / Delta^2``); on a scheme whose plaintexts are all integers, ``P_i0 + d_i``
itself. ``d_i = 0`` for ``a_i = 0`` and ``P_i0`` is a plaintext already, so an additive attack
with a zero action is the honest loop bit for bit. Both backends use :func:`added_row`: the
ElGamal one on the products it decrypts with the broken keys, the ideal one on the products of
its exact arithmetic.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from .._validation import format_value
from ..errors import ParameterError

__all__ = [
    "INJECTIONS",
    "REPLACE",
    "ADD",
    "PASS",
    "SCALE",
    "InjectionNeeds",
    "check_injection",
    "injection_code",
    "added_row",
    "addition",
    "scale_gain",
    "scale_multipliers",
]

#: The injection modes, by the name of the environment's ``injection`` key.
INJECTIONS: tuple[str, ...] = ("replace", "add", "pass", "scale")
#: Their codes in the compiled stages (:mod:`encctl_gym.envs._kernels`, :mod:`encctl_gym.loop.quantize`;
#: only ``REPLACE`` is compiled, the others run through the backend's ``period_input``).
REPLACE, ADD, PASS, SCALE = 0, 1, 2, 3


@dataclass(frozen=True)
class InjectionNeeds:
    """What an injection mode needs the adversary to have broken (a scheme's answer).

    Attributes
    ----------
    extra_keys : int
        Keys to break beyond the samples' (ElGamal ``add``: ``sk_0``, to read ``Phi`` inside the
        products), charged to the deciphering budget once, at the attack start.
    period_key : bool
        The mode needs the period's own key within the period (ElGamal ``add``: the products of
        this period are read with ``sk_t``), so the samples' deciphering delay must be 0.
    """

    extra_keys: int = 0
    period_key: bool = False


def check_injection(value: Any, name: str = "injection") -> str:
    """An injection mode of :data:`INJECTIONS`.

    Raises
    ------
    ParameterError
        For anything else (the modes are listed).
    """
    if not isinstance(value, str) or value not in INJECTIONS:
        raise ParameterError(f"unknown {name} {format_value(value)}; choose one of {', '.join(INJECTIONS)}")
    return value


def injection_code(mode: str) -> int:
    """The compiled stages' code of an injection mode (:data:`REPLACE`, :data:`ADD`, :data:`PASS`)."""
    return INJECTIONS.index(check_injection(mode))


def addition(a: float, delta: float, one: int) -> int:
    """``d = rint(Delta a) Ecd(1)``: the integer an additive attacker adds to a row's products."""
    return int(round(float(a) * float(delta))) * int(one)


def added_row(products: Sequence[int], a: float, delta: float, one: int, nearest: Callable[[int], int]) -> list[int]:
    """Row ``i`` of the output after adding ``a`` (the module docstring's rule): the plaintext
    nearest to ``P_i0 + d`` in place of the first product, the others unchanged.

    Parameters
    ----------
    products : sequence of int
        The honest row ``P_i0 .. P_i,beta-1`` (signed integers, as the plant decrypts them).
    a : float
        The adversary's addition to this input (energy-limited, ``|a| <= u_max``).
    delta : float
        The encoder's scale Delta.
    one : int
        ``Ecd(1)``.
    nearest : callable
        The scheme's nearest plaintext to a signed integer (:meth:`EncryptionScheme.nearest_plaintext`).

    Returns
    -------
    list of int
        The row the adversary sends (encrypted by the scheme).
    """
    row = [int(v) for v in products]
    row[0] = int(nearest(row[0] + addition(a, delta, one)))
    return row


def scale_gain(group: Any) -> int:
    """The smallest integer ``c >= 2`` whose residue lies in the plaintext group G (``scale`` mode).

    ElGamal's plaintexts are the order-q subgroup G of ``Z_p^*``; the plant checks every decrypted
    product against it, so a server that multiplies a product ciphertext by the plaintext ``c``
    (the multiplicative homomorphism, no key needed) must pick ``c`` in G. For a safe prime
    ``p = 2q + 1``, G is the quadratic residues: 2 when ``p = +-1 mod 8``, else 3 when it is a
    residue, and 4 (a square) always. Public: the server knows ``p``.
    """
    for c in range(2, 5):
        if group.contains(c):
            return c
    raise ParameterError(f"no multiplier in 2..4 lies in the group (4 is a square): {format_value(group)}")  # pragma: no cover


def scale_multipliers(a: Sequence[float], gain: int) -> list[int]:
    """The row multipliers of ``scale`` mode from the (energy-limited) action: ``c_i = 0`` for
    ``a_i < 0`` (the row's summands replaced by a public-key forgery of 0: the row is omitted),
    1 for ``a_i = 0`` (honest), ``gain`` (:func:`scale_gain`) for ``a_i > 0`` (every summand's
    ciphertext multiplied by the plaintext ``gain``). Only the sign of ``a_i`` counts."""
    return [0 if float(v) < 0.0 else (1 if float(v) == 0.0 else int(gain)) for v in a]
