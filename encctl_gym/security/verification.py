"""Integrity checks of the server's output: the probability that a falsified step passes, and the
work a check adds to a step (pure mathematics; the checks themselves are
:mod:`encctl_gym.loop.verification`).

The adversary of Definition def:adversary returns falsified outputs (step 1: it injects
``u_t = a_t``). Two checks on what the plant decrypts, each keyed by a secret the plant side never
sends:

* **The keyed linear check** (``"linear-check"``; Freivalds' check of a matrix-vector product,
  R. Freivalds, "Fast probabilistic algorithms", MFCS 1979, over the integers). The encrypted
  controller's row sums are the integers ``S = E X`` (``E``: the signed integers encoding Phi,
  ``X`` those of the state; ``Sum`` of eq:ec, after decryption on the multiplicative scheme). The
  plant keeps ``r``, drawn uniformly from ``{1, ..., R}^m``, and ``w = r^T E`` (``n`` integers),
  and accepts a decrypted ``S'`` iff ``r^T S' = w^T X``. A falsified step (``D = S' - S != 0``)
  passes iff ``r^T D = 0``. Since ``r`` is independent of everything the adversary sees,
  ``Pr[r^T D = 0] <= 1 / R`` for ``m >= 2`` (fix the coordinates of ``r`` but one where
  ``D_k != 0``: at most one value of ``r_k`` solves the equation; ``D = (d, -d, 0, ...)`` reaches
  ``1 / R`` exactly, ``r_1 = r_2``), and ``= 0`` for ``m = 1`` (``r_1 D_1 != 0``). Work per step:
  ``n + m`` integer products and sums of integers of ``log2(R) + log2(p)`` bits.
* **The linearly homomorphic MAC** (``"mac"``, for the additive Paillier scheme; the
  Catalano-Fiore style of a MAC evaluated through an additive homomorphism, with the secret
  ``gamma`` binding the server's coefficients to Phi, a fresh secret factor ``rho_t`` per step
  binding the tags to the step, and a fresh ``beta_t`` per step against replays). The plant
  keeps ``alpha`` (uniform in a set of ``A`` residues), ``gamma`` (uniform in ``Z_n^n``),
  ``delta = E gamma mod n`` and, each step, fresh ``rho_t`` (uniform in ``Z_n``) and ``beta_t``
  (uniform in ``Z_n^m``); it sends ``Enc(X_j)``, ``Enc(alpha X_j + rho_t gamma_j)`` and
  ``Enc(beta_t,i)``; the server returns ``c_i = Enc(S_i)`` and ``tau_i = Enc(sum_j E_ij (alpha
  X_j + rho_t gamma_j) + beta_t,i)``; the plant accepts iff ``Dec(tau_i) = alpha Dec(c_i) +
  rho_t delta_i + beta_t,i (mod n)``. A falsified output passes with probability at most
  ``1 / A + 2 / p_min``. The argument: the server can only form affine combinations, with
  integer coefficients it chooses, of everything it was sent at this step and every earlier
  one, and of constants it encrypts itself. Write its output as such a combination: the check
  ``tau' - alpha c' - rho_t delta - beta_t`` is then a polynomial in the secrets (``alpha``, every
  ``rho_s``, ``gamma``, every ``beta_s``). It is identically zero only if ``c'`` uses no tagged
  or mask ciphertext (``alpha c'`` would hold ``alpha^2`` or ``alpha rho_s gamma_j`` terms that
  ``tau'`` cannot), ``tau'`` uses this step's tagged states with exactly the coefficients ``E``
  and no earlier step's (the ``rho_s gamma_j`` terms must be ``rho_t delta``) and this step's
  mask once, and then ``Dec(c') = E X(t)``: the honest output. For any other output, at most one
  ``alpha`` makes every coefficient vanish as a polynomial in the other secrets (the
  coefficient of ``rho_s gamma_j`` or of the constant is of degree at most 1 in ``alpha`` once
  ``c'`` holds no tagged term), and for any other ``alpha`` the polynomial, of degree at most 2 in
  the secrets uniform in ``Z_n`` (so uniform modulo each prime of ``n = p q``), vanishes with
  probability at most ``2 / p_min`` (Schwartz-Zippel modulo the smaller prime), with ``p_min >=
  2^(ceil(k/2) - 1)`` for a ``k``-bit modulus from :func:`encctl_gym.crypto.paillier.keygen`;
  the adversary's view is independent of the secrets by the semantic security of Paillier's
  scheme. Without ``rho_t`` (one ``gamma`` for every step, as this package first built it) the
  difference of two steps' tagged states is ``Enc(alpha (X(t) - X(s)))``: a forgery ``u' = Phi
  x_t + K (x_t - x_s)`` with the tags moved alike passes with probability 1
  (:func:`encctl_gym.loop.verification.forge_across_steps`; measured, ``docs/verification.md``).

Per step versus per attack: both keys are kept for an episode, so a falsification that passes
once tells the adversary a relation the key satisfies and it may pass again (the linear check's
``r_1 = r_2``). The probability that an attacker injecting at each of ``N >= 1`` steps is never
caught is therefore bounded by the first step's, ``epsilon`` (:func:`undetected_with_check`), not by
``epsilon^N`` (which holds for an attacker that does not adapt, or for a key drawn afresh each
step). A check is *verification-secure* for the design's ``delta`` when ``epsilon <= delta``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from .._validation import check_int, check_probability, format_value
from ..errors import ParameterError

__all__ = [
    "VERIFICATIONS",
    "VerificationBound",
    "check_secret_range",
    "linear_check_pass_bound",
    "mac_pass_bound",
    "minimum_secret_range",
    "undetected_with_check",
    "expected_passes_before_detection",
    "verification_bound",
]

#: The checks by name (:mod:`encctl_gym.loop.verification` implements each).
VERIFICATIONS: tuple[str, ...] = ("linear-check", "mac")

#: The largest secret range (bits) a check takes: a 4096-bit integer per coordinate.
MAX_SECRET_BITS = 4096


def check_secret_range(name: str, value: Any) -> int:
    """A secret range ``R >= 2`` (an integer of at most :data:`MAX_SECRET_BITS` bits)."""
    R = check_int(name, value, minimum=2)
    if R.bit_length() > MAX_SECRET_BITS:
        raise ParameterError(f"{name} must have at most {MAX_SECRET_BITS} bits, got {format_value(R)}")
    return R


def linear_check_pass_bound(m: Any, secret_range: Any) -> float:
    """The largest probability that a falsified step passes the keyed linear check: ``1 / R`` for
    ``m >= 2`` inputs, ``0`` for ``m = 1`` (module docstring; tight, reached by ``D = (d, -d, 0, ...)``).

    Raises
    ------
    ParameterError
        For ``m < 1`` or ``R < 2``.
    """
    m = check_int("m", m, minimum=1)
    R = check_secret_range("secret_range", secret_range)
    return 0.0 if m == 1 else 1.0 / R


def mac_pass_bound(alpha_range: Any, modulus_bits: Any) -> float:
    """``1 / A + 2 / 2^(ceil(k/2) - 1)``: the probability bound of the MAC for ``alpha`` uniform in
    ``A`` residues and a ``k``-bit modulus (module docstring).

    Raises
    ------
    ParameterError
        For ``A < 2`` or ``k < 16``.
    """
    A = check_secret_range("alpha_range", alpha_range)
    k = check_int("modulus_bits", modulus_bits, minimum=16, maximum=1 << 16)
    return min(1.0, 1.0 / A + math.ldexp(2.0, -((k + 1) // 2 - 1)))


def minimum_secret_range(delta: float) -> int:
    """The smallest ``R`` with ``1 / R <= delta``: ``ceil(1 / delta)`` (at least 2).

    Raises
    ------
    ParameterError
        For ``delta`` outside (0, 1).
    """
    d = check_probability("delta", delta)
    if not 0.0 < d < 1.0:
        raise ParameterError(f"delta must lie in (0, 1), got {format_value(delta)}")
    R = math.ceil(1.0 / d)
    while 1.0 / R > d:  # the float division's last rounding step
        R += 1
    return max(2, R)


def undetected_with_check(epsilon: float, N: Any, *, adaptive: bool = True) -> float:
    """The probability that an attacker falsifying each of ``N`` steps is never caught: at most
    ``epsilon`` for an adaptive attacker against a key kept for the episode, ``epsilon^N`` for one
    whose every step passes independently (a fresh key per step); 1 for ``N = 0``."""
    e = check_probability("epsilon", epsilon)
    N = check_int("N", N, minimum=0)
    if N == 0:
        return 1.0
    return e if adaptive else e**N


def expected_passes_before_detection(epsilon: float, horizon: Any) -> float:
    """The mean number of falsified steps that pass before the first failure when every step
    passes independently with ``epsilon``, counted up to ``horizon`` steps:
    ``sum_{t=1}^{H} epsilon^t`` (a truncated geometric law)."""
    e = check_probability("epsilon", epsilon)
    H = check_int("horizon", horizon, minimum=1)
    if e == 1.0:
        return float(H)
    return e * (1.0 - e**H) / (1.0 - e)


@dataclass(frozen=True)
class VerificationBound:
    """A check's bound with its parameters.

    Attributes
    ----------
    name : str
        ``"linear-check"`` or ``"mac"``.
    epsilon : float
        The largest probability that one falsified step passes.
    parameters : dict
        What the bound was computed from.
    """

    name: str
    epsilon: float
    parameters: dict[str, Any]

    def secure(self, delta: float) -> bool:
        """``epsilon <= delta``: an attacker is caught at its first falsified step but with
        probability at most ``delta``."""
        return self.epsilon <= check_probability("delta", delta)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return asdict(self)


def verification_bound(
    name: str, *, m: int = 1, secret_range: Any = None, alpha_range: Any = None, modulus_bits: Any = None
) -> VerificationBound:
    """The bound of the check ``name`` of :data:`VERIFICATIONS` for its parameters.

    Raises
    ------
    ParameterError
        For an unknown name or a missing or bad parameter.
    """
    if name == "linear-check":
        if secret_range is None:
            raise ParameterError("the linear check needs secret_range (R >= 2)")
        eps = linear_check_pass_bound(m, secret_range)
        return VerificationBound(name, eps, {"m": int(m), "secret_range": int(secret_range)})
    if name == "mac":
        if alpha_range is None or modulus_bits is None:
            raise ParameterError("the MAC needs alpha_range (A >= 2) and modulus_bits (k)")
        eps = mac_pass_bound(alpha_range, modulus_bits)
        return VerificationBound(name, eps, {"alpha_range": int(alpha_range), "modulus_bits": int(modulus_bits)})
    raise ParameterError(f"unknown verification {format_value(name)}; choose one of {', '.join(VERIFICATIONS)}")
