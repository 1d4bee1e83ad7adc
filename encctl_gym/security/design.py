"""Security parameter design: Definition def:security, Theorem thm:opt_sec, eq:opt_key.

Definition def:security: an encrypted control system is *secure* if no sample size ``N`` has
both ``gamma(N) < gamma_c`` (the adversary identifies the plant well enough) and
``tau(N) <= tau_c`` (it can break the ``N`` ciphertexts within the defense period).
``gamma`` decreases and ``tau`` increases in ``N``, so with ``N*`` the smallest ``N`` with
``gamma(N) < gamma_c`` and ``N_max`` the largest ``N`` with ``tau(N) <= tau_c``, the system
is secure iff ``N_max < N*`` iff ``gamma(N_max) >= gamma_c`` (:func:`is_secure`, under the
paper's cost or any model of :mod:`~encctl_gym.security.cost_models`).

Theorem thm:opt_sec (eq:opt_sec): with ``N*`` of :mod:`~encctl_gym.security.sample_size`,

    lam* = floor(log2(Upsilon tau_c / N*)) + 1

the smallest integer with ``2^lam N* > Upsilon tau_c`` (strict; a power-of-two ratio ``2^j``
gives ``j + 1``), computed exactly (:func:`~encctl_gym.security.cost_models.paper_security_parameter`).
If ``Upsilon tau_c < N*`` the formula gives ``lam* <= 0``; a security parameter is at least 1,
so ``lam* = 1`` is returned (the adversary cannot even perform ``N*`` operations in the defense
period), and eq:opt_key then refuses it as below the range of the GNFS formula.

eq:opt_key: ``k*`` is the smallest ``k`` with ``Omega(k) >= 2^lam*``, ``Omega`` the running time of
the general number field sieve (:func:`~encctl_gym.security.cost_models.minimum_key_length`).
The same design under the other cost models is :mod:`~encctl_gym.security.key_length`.

This module holds the result type :class:`SecurityDesign`, the designs from Gramian traces or
from a plant, and re-exports the names other layers import from here (``minimum_key_length``,
``bit_security_of_key_length``, ``sample_size_for_rate``, ...).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import check_int, check_nonnegative, check_positive, format_value
from ..errors import ModelRangeError, ParameterError
from ..plant import Plant, as_plant
from ..presets import PAPER_DESIGN_EXAMPLE
from .cost_models import (
    KeyBreakCost,
    bit_security_of_key_length,
    check_security_parameter,
    gnfs_complexity,
    gnfs_log2_complexity,
    minimum_key_length,
    paper_security_parameter,
)
from .deciphering import max_affordable_samples
from .exact import binary_fraction, decimal_fraction
from .gramians import controllability_gramian, noise_gramian
from .sample_size import (
    check_complexity,
    complexity_value,
    exact_optimal_sample_size,
    exact_sic_asymptotic_function,
    exact_sic_function,
    minimum_sample_size,
    optimal_sample_size,
    sample_size_for_rate,
)
from .threat import IDENTIFICATION_FIELDS, ThreatModel

__all__ = [
    "SecurityDesign",
    "is_secure",
    "minimum_sample_size",
    "sample_size_for_rate",
    "optimal_sample_size",
    "exact_optimal_sample_size",
    "optimal_security_parameter",
    "exact_sic_function",
    "exact_sic_asymptotic_function",
    "design_for_sample_size",
    "design_from_traces",
    "design_security_parameter",
    "paper_design_example",
    "gnfs_complexity",
    "gnfs_log2_complexity",
    "bit_security_of_key_length",
    "minimum_key_length",
    "PAPER_EXAMPLE",
    "METHODS",
]

#: The design example of Section "Numerical Simulation" from its traces (kept here as an import
#: path; the constants live in :mod:`encctl_gym.presets`).
PAPER_EXAMPLE: dict[str, Any] = PAPER_DESIGN_EXAMPLE

#: Values of :attr:`SecurityDesign.method`: the complexity that gave ``N*``.
METHODS: tuple[str, ...] = ("asymptotic", "exact", "closed_loop", "open_loop", "gaussian", "input_noise")


@dataclass(frozen=True)
class SecurityDesign:
    """Result of a security parameter design (Theorem thm:opt_sec and eq:opt_key).

    Attributes
    ----------
    method : str
        ``"asymptotic"`` (eq:sic2, the paper's Theorem thm:opt_sec), ``"exact"`` (eq:sic),
        ``"closed_loop"``, ``"open_loop"`` or ``"gaussian"`` (robust designs of
        :mod:`encctl_gym.security.attack_design`), ``"input_noise"`` (the defender's input noise,
        :func:`encctl_gym.security.defenses.noise_defense_design`).
    N_star : int
        Smallest sample size with ``gamma(N) < gamma_c``.
    lam_star : int
        Smallest security parameter with ``tau(N*, lam) > tau_c``.
    k_star : int
        Smallest key length with ``Omega(k) >= 2^lam*`` (eq:opt_key).
    gamma_c, tau_c, upsilon : float
        Design parameters (acceptable error, defense period in s, adversary FLOPS).
    m, n : int
        Input and state dimensions.
    sigma_u2, sigma_w2, sigma_x2 : float
        Variances of attack input, noise, initial state.
    tr_psi_u, tr_psi_w : float
        Gramian traces.
    gamma_at_N_star : float
        ``gamma(N*)`` (< gamma_c).
    gamma_before_N_star : float
        ``gamma(N* - 1)`` (>= gamma_c; ``nan`` when ``N* = 2``).
    bit_security : float
        ``log2 Omega(k*)`` (>= lam*).
    """

    method: str
    N_star: int
    lam_star: int
    k_star: int
    gamma_c: float
    tau_c: float
    upsilon: float
    m: int
    n: int
    sigma_u2: float
    sigma_w2: float
    sigma_x2: float
    tr_psi_u: float
    tr_psi_w: float
    gamma_at_N_star: float
    gamma_before_N_star: float
    bit_security: float

    @property
    def r_sigma(self) -> float:
        """Variance ratio ``R_sigma = sigma_u2 / sigma_w2``."""
        return self.sigma_u2 / self.sigma_w2

    def to_dict(self) -> dict[str, Any]:
        """The fields (and ``r_sigma``) as a JSON-ready dict."""
        d = dataclasses.asdict(self)
        d["r_sigma"] = self.r_sigma
        return d


def optimal_security_parameter(N_star: int, *, tau_c: Any, upsilon: Any) -> int:
    """``lam*`` of Theorem thm:opt_sec (eq:opt_sec), exactly.

    ``lam* = floor(log2(Upsilon tau_c / N*)) + 1``, the smallest integer with
    ``tau(N*, lam) = 2^lam N* / Upsilon > tau_c``. Returns at least 1 (see module notes).

    Parameters
    ----------
    N_star : int
        Minimum sample size (>= 1).
    tau_c : float
        Defense period in seconds (> 0).
    upsilon : float
        Adversary FLOPS (> 0).

    Returns
    -------
    int
    """
    N_star = check_int("N_star", N_star, 1)
    budget = decimal_fraction("upsilon", upsilon) * decimal_fraction("tau_c", tau_c)
    return paper_security_parameter(N_star, budget)


# --------------------------------------------------------------------------- Definition def:security
def is_secure(
    lam: Any,
    *,
    gamma: Callable[[int], Any],
    gamma_c: Any,
    tau_c: Any,
    upsilon: Any,
    scheme: str = "modified",
    adversary: str = "eavesdropper",
    gamma_infimum: Any = 0.0,
) -> bool:
    """Definition def:security, evaluated exactly, under the paper's cost or any cost model.

    Insecure iff some integer ``N >= 2`` has ``gamma(N) < gamma_c`` and ``tau(N) <= tau_c``.
    With ``gamma`` nonincreasing and ``tau`` nondecreasing in ``N`` this holds iff the largest
    affordable ``N_max`` (:func:`~encctl_gym.security.deciphering.max_affordable_samples`,
    exact) is >= 2 and ``gamma(N_max) < gamma_c`` (exact comparison). When one break reveals
    every sample (``scheme="static"``, or ``"token"`` against a ``"server"``) and that break is
    affordable, ``N_max`` is infinite and the system is secure iff ``gamma_infimum >= gamma_c``.
    ``N = 1`` gives no regression column (eq:estimate) and never counts.

    Parameters
    ----------
    lam : int, float or KeyBreakCost
        Security parameter (integer >= 1, or real > 0), or the cost of breaking keys under a
        model (:func:`~encctl_gym.security.deciphering.break_cost`).
    gamma : callable
        Sample identifying complexity ``int -> float | Fraction``, nonincreasing (e.g.
        :func:`exact_sic_asymptotic_function`, or ``AttackDesign.gamma``).
    gamma_c : float
        Acceptable estimation error (> 0).
    tau_c : float
        Defense period, seconds (> 0).
    upsilon : float
        Adversary FLOPS (> 0).
    scheme, adversary : str
        See :mod:`encctl_gym.security.deciphering`.
    gamma_infimum : float, default 0.0
        ``lim_{N->inf} gamma(N)`` (0 for every complexity here).

    Returns
    -------
    bool

    Raises
    ------
    ParameterError
        For a bad ``lam``, ``gamma_c``, ``tau_c``, ``upsilon`` or ``gamma_infimum`` (checked on
        every path), a ``gamma`` that is not callable, or a ``gamma(N)`` that is not a finite
        real >= 0.
    """
    if not isinstance(lam, KeyBreakCost):
        check_security_parameter(lam)
    check_complexity(gamma)
    g_inf = binary_fraction("gamma_infimum", check_nonnegative("gamma_infimum", gamma_infimum))
    g_c = decimal_fraction("gamma_c", gamma_c)
    n_max = max_affordable_samples(tau_c, lam, upsilon, scheme=scheme, adversary=adversary)
    if n_max == math.inf:
        return g_inf >= g_c
    if n_max < 2:
        return True
    return not (complexity_value(gamma, int(n_max)) < g_c)


# --------------------------------------------------------------------------- full designs
def _gamma_float(gamma: Callable[[int], Any], N: int) -> float:
    return float(gamma(N)) if N >= 2 else math.nan


def design_for_sample_size(
    method: str, N_star: int, gamma: Callable[[int], Any], threat: ThreatModel, *, m: int, n: int, tr_psi_u: Any, tr_psi_w: Any
) -> SecurityDesign:
    """Theorem thm:opt_sec and eq:opt_key for a given ``N*``: ``lam*``, ``k*`` and the record.

    The last step of every design (:func:`design_from_traces` and the robust designs of
    :func:`~encctl_gym.security.attack_design.robust_security_design`).

    Parameters
    ----------
    method : str
        One of :data:`METHODS`: the complexity that gave ``N*``.
    N_star : int
        Smallest sample size with ``gamma(N) < gamma_c`` (>= 2).
    gamma : callable
        The complexity, for ``gamma(N*)`` and ``gamma(N* - 1)`` in the record.
    threat : ThreatModel
        Variances, ``gamma_c``, ``tau_c`` and ``Upsilon`` (recorded as floats).
    m, n, tr_psi_u, tr_psi_w
        Dimensions and Gramian traces, as in :func:`design_from_traces` (recorded as floats).

    Returns
    -------
    SecurityDesign

    Raises
    ------
    ModelRangeError
        If ``lam*`` lies outside the range of the GNFS formula (see
        :func:`~encctl_gym.security.cost_models.minimum_key_length`).
    """
    if not isinstance(method, str) or method not in METHODS:
        raise ParameterError(f"unknown method {format_value(method)}; expected one of {', '.join(METHODS)}")
    t = _threat(threat, "design_for_sample_size").require(*IDENTIFICATION_FIELDS)
    N_star = check_int("N_star", N_star, 2)
    lam_star = optimal_security_parameter(N_star, tau_c=t.tau_c, upsilon=t.upsilon)
    try:
        k_star = minimum_key_length(lam_star)
    except ModelRangeError as exc:
        raise ModelRangeError(
            f"Theorem thm:opt_sec gives lam* = {lam_star} for N* = {format_value(N_star)} (tau_c = {format_value(t.tau_c)} s, "
            f"Upsilon = {format_value(t.upsilon)} FLOPS), and eq:opt_key cannot turn it into a key length: {exc}"
        ) from None
    return SecurityDesign(
        method=method,
        N_star=N_star,
        lam_star=lam_star,
        k_star=k_star,
        gamma_c=float(t.gamma_c),
        tau_c=float(t.tau_c),
        upsilon=float(t.upsilon),
        m=check_int("m", m, 1),
        n=check_int("n", n, 1),
        sigma_u2=float(t.sigma_u2),
        sigma_w2=float(t.sigma_w2),
        sigma_x2=float(t.sigma_x2),
        tr_psi_u=check_nonnegative("tr_psi_u", tr_psi_u),
        tr_psi_w=check_positive("tr_psi_w", tr_psi_w),
        gamma_at_N_star=_gamma_float(gamma, N_star),
        gamma_before_N_star=_gamma_float(gamma, N_star - 1),
        bit_security=float(gnfs_log2_complexity(k_star)),
    )


def _threat(threat: Any, where: str) -> ThreatModel:
    if not isinstance(threat, ThreatModel):
        raise ParameterError(f"{where}: threat must be a ThreatModel, got {format_value(threat)}")
    return threat


def design_from_traces(
    tr_psi_u: Any, tr_psi_w: Any, m: int, n: int, threat: ThreatModel | None = None, *, method: str = "asymptotic", **fields: Any
) -> SecurityDesign:
    """Theorem thm:opt_sec and eq:opt_key from the Gramian traces.

    Parameters
    ----------
    tr_psi_u, tr_psi_w : float
        ``tr Psi_u >= 0`` and ``tr Psi_w > 0``.
    m, n : int
        Dimensions.
    threat : ThreatModel
        ``sigma_u2``, ``sigma_w2`` (only ``R_sigma`` matters for ``"asymptotic"``), ``sigma_x2``
        (used by ``"exact"``), ``gamma_c``, ``tau_c``, ``upsilon``.
    method : {"asymptotic", "exact"}
        ``"asymptotic"``: eq:sic2 / eq:opt_sec as in the paper; ``"exact"``: eq:sic.
    **fields
        Instead of ``threat``: its fields as keywords (``sigma_u2=..., tau_c=...``), for a caller
        that holds them one by one.

    Returns
    -------
    SecurityDesign
    """
    t = ThreatModel.from_fields(threat, fields, "design_from_traces").require(*IDENTIFICATION_FIELDS)
    m = check_int("m", m, 1)
    n = check_int("n", n, 1)
    su = decimal_fraction("sigma_u2", t.sigma_u2)
    sw = decimal_fraction("sigma_w2", t.sigma_w2)
    if not isinstance(method, str):
        raise ParameterError(f"unknown method {format_value(method)}; expected 'asymptotic' or 'exact'")
    if method == "asymptotic":
        N_star = optimal_sample_size(tr_psi_u, tr_psi_w, m, n, r_sigma=su / sw, gamma_c=t.gamma_c)
        gamma = exact_sic_asymptotic_function(tr_psi_u, tr_psi_w, m, n, r_sigma=su / sw)
    elif method == "exact":
        N_star = exact_optimal_sample_size(
            tr_psi_u, tr_psi_w, m, n, sigma_u2=su, sigma_w2=sw, sigma_x2=t.sigma_x2, gamma_c=t.gamma_c
        )
        gamma = exact_sic_function(tr_psi_u, tr_psi_w, m, n, sigma_u2=su, sigma_w2=sw, sigma_x2=t.sigma_x2)
    else:
        raise ParameterError(f"unknown method {format_value(method)}; expected 'asymptotic' or 'exact'")
    return design_for_sample_size(method, N_star, gamma, t, m=m, n=n, tr_psi_u=tr_psi_u, tr_psi_w=tr_psi_w)


def design_security_parameter(
    plant: Plant | tuple[Any, Any], threat: ThreatModel, *, method: str = "asymptotic"
) -> SecurityDesign:
    """Theorem thm:opt_sec and eq:opt_key for a plant (Gramians by Lyapunov solves).

    Parameters
    ----------
    plant : Plant or (A, B)
        Plant of eq:system (``A`` Schur stable).
    threat : ThreatModel
        As in :func:`design_from_traces`.
    method : {"asymptotic", "exact"}
        As in :func:`design_from_traces`.

    Returns
    -------
    SecurityDesign
    """
    p = as_plant(plant)
    t = _threat(threat, "design_security_parameter")
    tr_u = float(np.trace(controllability_gramian(p.A, p.B)))
    tr_w = float(np.trace(noise_gramian(p.A)))
    return design_from_traces(tr_u, tr_w, p.m, p.n, t, method=method)


def paper_design_example(method: str = "asymptotic") -> SecurityDesign:
    """The design example of Section "Numerical Simulation" from its traces (the paper reports
    N* = 13159, lam* = 74, k* = 712).

    Parameters
    ----------
    method : {"asymptotic", "exact"}
        ``"asymptotic"`` is the paper's computation.

    Returns
    -------
    SecurityDesign
    """
    p: dict[str, Any] = dict(PAPER_DESIGN_EXAMPLE)
    tr_u, tr_w, m, n = p.pop("tr_psi_u"), p.pop("tr_psi_w"), int(p.pop("m")), int(p.pop("n"))
    return design_from_traces(tr_u, tr_w, m, n, ThreatModel(**p), method=method)
