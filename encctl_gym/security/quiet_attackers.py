"""The attackers a design must hold against when it relies on audits: the sparse attacker at the
input bound and the passive one (issue 30, item 3; pure mathematics).

The audit rule of :func:`~.defenses.minimum_audit_rate`, ``p* = 1 - delta^(1/N*)``, assumes an
attacker that falsifies each of the ``N*`` samples it needs (eq:sic at ``sigma_u2``). An attacker
that keeps ``Phi x`` and puts its energy into a few steps at the input bound ``u_max`` falsifies
far fewer steps, and an audit sees only the falsified ones.

**The fewest falsified steps.** A sparse attacker adds ``+-u_max`` to every input on a fraction
``q`` of the steps (the :class:`~encctl_gym.agents.stealth.SparseAttacker` of ``add``): its mean
excitation is ``Sigma_d = q u_max^2 I`` and the least-squares error after ``N`` samples tends to
``c(q) / (N - 1)`` with ``c(q) = sigma_w2 [tr(Sigma_xx(q)^-1) + tr(I + Phi Phi^T) / (q u_max^2)]
/ (n + m)`` (:func:`~.stealth.identification_rate`; ``Sigma_xx(q)`` is the closed loop's state
covariance with that excitation). It reaches ``gamma_c`` with ``J = q N`` falsified steps. For a
fixed ``J`` more samples only help it (``J(N)`` decreases towards its limit), so an attacker
that can decipher as many samples as it likes, which is what an audit-secure mix at a short key
allows, needs ``J_min = sigma_w2 tr(I + Phi Phi^T) / ((n + m) u_max^2 gamma_c)`` falsified steps
(:func:`fewest_falsified_steps`: the limit of ``q N`` as ``N`` grows, ``Sigma_xx(q) -> Sigma_xx(0)``).
Audits at rate ``p`` miss all of them with probability ``(1 - p)^J``: the audit-secure rate is
``p_J = 1 - delta^(1 / min(J_min, N*))`` (:func:`sparse_audit_rate`).

**The passive attacker** never falsifies anything: it identifies from the excitation the loop
has on its own. With the defender's input noise ``sigma_d2`` (the noise lever) that is ``Sigma_d =
sigma_d2 I`` and it needs :func:`passive_samples` samples; without excitation ``B`` cannot be
identified (infinitely many). Audits never see it, so a mix is secure against it only if its
key makes those samples too expensive.

**The stealthy attacker against a detector** (chi-squared or CUSUM on the innovation): it adds
white excitation ``Sigma_d = s I`` at the level ``s`` that reaches ``gamma_c`` in the fewest
samples while a detector alarms within those samples with probability at most ``delta``
(:func:`stealthy_samples`, over ``s`` up to the threat model's ``sigma_u2``; the closed forms of
:func:`~.stealth.frontier_point`, with at least ``n + m + 1`` samples, the fewest least squares
can use, and for the window test at least one full window). Small ``s`` needs many samples and meets the detector's
false alarms; large ``s`` is seen. When no level stays below ``delta`` the detector alone keeps
every such attacker from ``gamma_c`` unseen, provided the honest loop itself does not alarm
within ``N*`` steps with probability above ``delta`` (else its alarms do not tell an attack from
noise); otherwise the key must make those samples too expensive. (On the design example the A-optimal excitation under a KL budget is isotropic.)

**The confidentiality floor.** The key also protects the signals themselves over their
lifetime, whatever the identification needs: :data:`NIST_FLOOR` is the finite-field key length
NIST SP 800-57 Part 1 Rev. 5 (Table 2) asks for 112-bit security, acceptable through 2030
(3072 bits, 128-bit security, after).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import check_int, check_positive, format_value
from ..errors import ParameterError
from .defenses import undetected_probability
from .stealth import _matrices, check_false_alarm_rate, frontier_point, identification_rate, samples_to_gamma_c

__all__ = [
    "DEFAULT_INPUT_BOUND_SIGMAS",
    "NIST_FLOOR",
    "NIST_FLOOR_AFTER_2030",
    "FewestSteps",
    "check_confidentiality_floor",
    "fewest_falsified_steps",
    "passive_samples",
    "sparse_audit_rate",
    "DETECTORS",
    "StealthySamples",
    "stealthy_samples",
]

#: The attacker's input bound in units of ``sigma_u`` when none is given: the environment's
#: ``action_scale`` default (``u_max = action_scale sigma_u``, :mod:`encctl_gym.envs.defaults`).
DEFAULT_INPUT_BOUND_SIGMAS: float = 4.0
#: NIST SP 800-57 Part 1 Rev. 5, Table 2: finite-field (DSA, DH) L = 2048 bits for 112-bit
#: security, acceptable through 2030.
NIST_FLOOR: int = 2048
#: The same table's L = 3072 bits (128-bit security), required after 2030.
NIST_FLOOR_AFTER_2030: int = 3072


def check_confidentiality_floor(value: Any) -> int | None:
    """``None``, a key length in bits (>= 1), or ``"nist"`` (:data:`NIST_FLOOR`) /
    ``"nist-2031"`` (:data:`NIST_FLOOR_AFTER_2030`)."""
    if value is None:
        return None
    if isinstance(value, str):
        word = value.strip().lower()
        if word in ("nist", "nist-2030"):
            return NIST_FLOOR
        if word == "nist-2031":
            return NIST_FLOOR_AFTER_2030
        raise ParameterError(
            f"confidentiality_floor must be a key length in bits, 'nist' or 'nist-2031', got {format_value(value)}"
        )
    return check_int("confidentiality_floor", value, minimum=1, maximum=1 << 20)


@dataclass(frozen=True)
class FewestSteps:
    """The sparse attacker at the input bound (module docstring).

    Attributes
    ----------
    steps : int
        ``J_min``: the fewest falsified steps that reach ``gamma_c``.
    input_bound : float
        ``u_max``.
    excitation_trace : float
        ``tr(I + Phi Phi^T)``.
    """

    steps: int
    input_bound: float
    excitation_trace: float


def fewest_falsified_steps(A: Any, B: Any, Phi: Any, *, sigma_w2: float, gamma_c: float, input_bound: float) -> FewestSteps:
    """``J_min = ceil(sigma_w2 tr(I + Phi Phi^T) / ((n + m) u_max^2 gamma_c))``, at least ``m``
    (module docstring).

    Raises
    ------
    ParameterError
        For ``sigma_w2``, ``gamma_c`` or ``input_bound`` not positive and finite.
    """
    A, B, Phi = _matrices(A, B, Phi)
    n, m = B.shape
    sw = check_positive("sigma_w2", sigma_w2)
    gc = check_positive("gamma_c", gamma_c)
    u = check_positive("input_bound", input_bound)
    trace = float(m + np.sum(Phi * Phi))
    value = sw * trace / ((n + m) * u * u * gc)
    if not math.isfinite(value) or value > 1e18:
        raise ParameterError(f"the fewest falsified steps overflow ({value:g}): gamma_c = {gc:g} with input_bound = {u:g}")
    return FewestSteps(max(m, math.ceil(value)), u, trace)  # at least m: B's m columns need m excited steps


def sparse_audit_rate(steps: int, delta: float) -> float:
    """The smallest ``p`` with ``(1 - p)^steps <= delta``: ``1 - delta^(1/steps)`` (rounded up
    until :func:`~.defenses.undetected_probability` says the inequality holds)."""
    J = check_int("steps", steps, minimum=1)
    d = check_positive("delta", delta)
    if d >= 1:
        raise ParameterError(f"delta must lie in (0, 1), got {d}")
    p = -math.expm1(math.log(d) / J)
    while undetected_probability(J, p) > d:  # the design's own evaluation of (1 - p)^J decides
        p = math.nextafter(p, 1.0)
    return p


def passive_samples(A: Any, B: Any, Phi: Any, *, sigma_w2: float, sigma_d2: float, gamma_c: float) -> int | float:
    """Samples a passive attacker needs to reach ``gamma_c`` from the defender's noise alone
    (``Sigma_d = sigma_d2 I``); ``inf`` without noise (``B`` is not identifiable)."""
    A, B, Phi = _matrices(A, B, Phi)
    if sigma_d2 < 0 or not math.isfinite(sigma_d2):
        raise ParameterError(f"sigma_d2 must be finite and >= 0, got {format_value(sigma_d2)}")
    if sigma_d2 == 0:
        return math.inf
    rate = identification_rate(A, B, Phi, sigma_w2=sigma_w2, Sigma_d=sigma_d2 * np.eye(B.shape[1]))
    return samples_to_gamma_c(rate, gamma_c)


#: The detectors :func:`stealthy_samples` plays against.
DETECTORS: tuple[str, ...] = ("chi2", "cusum")


@dataclass(frozen=True)
class StealthySamples:
    """The stealthy attacker against one detector (module docstring).

    Attributes
    ----------
    detector : str
        ``"chi2"`` or ``"cusum"``.
    samples : int or float
        The fewest samples that reach ``gamma_c`` undetected with probability at least
        ``1 - delta`` (``inf``: no excitation level does).
    sigma_d2 : float or None
        Its excitation level ``s`` (``None`` when ``samples`` is infinite).
    detection : float or None
        The detector's alarm probability within those samples.
    false_alarm_within : float
        The honest loop's alarm probability within ``horizon`` steps.
    horizon : int
        The steps ``false_alarm_within`` is for (the design's ``N*``).
    """

    detector: str
    samples: int | float
    sigma_d2: float | None
    detection: float | None
    false_alarm_within: float
    horizon: int


def stealthy_samples(
    A: Any,
    B: Any,
    Phi: Any,
    *,
    sigma_w2: float,
    gamma_c: float,
    detector: str,
    false_alarm_rate: float,
    delta: float,
    power: float,
    horizon: int,
    window: int = 10,
    variance_ratio: float = 2.0,
    levels: int = 48,
) -> StealthySamples:
    """The stealthy attacker's fewest samples against ``detector`` (module docstring): a
    log-spaced scan of ``levels`` excitation levels from ``1e-10 power`` to ``power`` (the threat
    model's ``sigma_u2``: the attacker of N* excites at that level), then a
    bisection between the largest level that stays below ``delta`` and the next one (the samples
    fall as the level rises, so that boundary is the optimum of the scan).

    Raises
    ------
    ParameterError
        For an unknown detector, a false-alarm rate or ``delta`` outside (0, 1), a bad bound.
    """
    if detector not in DETECTORS:
        raise ParameterError(f"unknown detector {format_value(detector)}; choose one of {', '.join(DETECTORS)}")
    alpha = check_false_alarm_rate(false_alarm_rate)
    d = check_positive("delta", delta)
    if d >= 1:
        raise ParameterError(f"delta must lie in (0, 1), got {d}")
    top = check_positive("power", power)
    horizon = check_int("horizon", horizon, minimum=1)
    A, B, Phi = _matrices(A, B, Phi)
    m = B.shape[1]
    kw: dict[str, Any] = {
        "sigma_w2": sigma_w2,
        "gamma_c": gamma_c,
        "window": window,
        "false_alarm_rate": alpha,
        "variance_ratio": variance_ratio,
    }

    # least squares needs n + m + 1 samples whatever the excitation, and the window test judges an
    # attack shorter than its window over one full window (a detector running before the attack)
    shortest = A.shape[0] + m + 1 if detector == "cusum" else max(A.shape[0] + m + 1, int(window))

    def seen(level: float) -> tuple[int | float, float]:
        N = frontier_point(A, B, Phi, Sigma_d=level * np.eye(m), **kw).samples
        N = max(N, shortest)
        point = frontier_point(A, B, Phi, Sigma_d=level * np.eye(m), steps=int(min(N, 10**9)), **kw)
        return N, point.chi2 if detector == "chi2" else point.cusum

    honest = frontier_point(A, B, Phi, Sigma_d=np.zeros((m, m)), horizon=horizon, **kw)
    false_alarms = honest.chi2 if detector == "chi2" else honest.cusum
    grid = np.geomspace(1e-10 * top, top, check_int("levels", levels, minimum=2))
    results = [seen(float(level)) for level in grid]
    ok = [i for i, (_, p) in enumerate(results) if p <= d]
    if not ok:
        return StealthySamples(detector, math.inf, None, None, float(false_alarms), horizon)
    best = max(ok, key=lambda i: grid[i])
    lo, hi = float(grid[best]), float(grid[best + 1]) if best + 1 < len(grid) else float(grid[best])
    N, p = results[best]
    for _ in range(30 if hi > lo else 0):
        mid = math.sqrt(lo * hi)
        n_mid, p_mid = seen(mid)
        if p_mid <= d:
            lo, N, p = mid, n_mid, p_mid
        else:
            hi = mid
    return StealthySamples(detector, N, lo, float(p), float(false_alarms), horizon)
