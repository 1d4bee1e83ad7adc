"""The design with the defender's levers: the cheapest secure mix of key length, group rotation,
audits and input noise, per deciphering-cost model (``encctl-gym design --rotate-every
--audit-rate --defense-noise``).

Security (Definition def:security, with the levers of :mod:`.defenses`):

* **Noise** ``sigma_d2`` moves the sample size the attacker needs to ``N*`` of
  :func:`~.defenses.noise_defense_design` (eq:sic generalised; ``sigma_d2 = 0``: the paper's
  ``N*``). ``lambda* = floor(log2(Upsilon tau_c / N*)) + 1`` (Theorem thm:opt_sec) is the work per
  sample every model must exceed; the models differ in the key length that buys it.
* **Rotation** every ``K`` steps: the attacker meets ``ceil(N* / K)`` groups and pays
  ``ceil(N* / K) C_pre + N* C_key`` (:func:`~.defenses.rotated_deciphering_operations`; the
  precomputation ``C_pre`` is the model's, zero for the paper and generic models, where rotation
  changes nothing). The key is *key-secure* at ``(k, K)`` when that work exceeds
  ``Upsilon tau_c``; ``k*(K)`` is the smallest such ``k`` (nondecreasing in ``K``).
* **Audits** at rate ``p``: the mix is *audit-secure* when the sparse attacker at the input
  bound, which falsifies only ``J = min(J_min, N*)`` steps (:mod:`.quiet_attackers`), gets through
  them before an alarm with probability ``(1 - p)^J <= delta``
  (:func:`~.defenses.undetected_probability`), whatever the key length. (An attacker that
  falsifies every one of ``N*`` samples, the rule ``p* = 1 - delta^(1/N*)``, is printed beside
  it.) An audit-secure mix needs no key length for this threat and uses the smallest one the
  design allows: ``min_key_length`` (default :data:`DEFAULT_MIN_KEY_LENGTH`), lifted to the
  following two.
* **The passive attacker** identifies from the defender's own noise without falsifying
  anything, so audits never see it: every mix's key must make its samples
  (:func:`~.quiet_attackers.passive_samples`) cost more than the budget. Without noise it cannot
  identify ``B`` and sets no bound.
* **The confidentiality floor** (optional, e.g. NIST SP 800-57's 2048 bits): no mix's key is
  shorter.

A mix is secure when it is key-secure or audit-secure (and, by the lifts, passive-secure). Its cost per step, in seconds on the
reference machine (:class:`DefenderCosts`), is

* the encrypted step at ``k`` bits: ``3 n + 1`` modular exponentiations on the plant side (``2 n``
  to encrypt the state, one key update, ``n`` column parts of the modified scheme's decryption,
  :mod:`encctl_gym.crypto.plant_side`), each timed by the measured per-size model
  :func:`~encctl_gym.crypto.group.modular_exponentiation_seconds`;
* the rotation amortised over ``K``: the expected safe-prime search
  (:func:`~encctl_gym.crypto.group.estimate_generation_seconds`) plus ``1 + 3 n m``
  exponentiations (KeyGen, the ``n m`` encryptions ``Enc(pk_0', Ecd(Phi))`` and their fixed
  decryption parts), divided by ``K``;
* the audits: ``p`` local control computations per step, each the measured time of the plant
  side's own check (:func:`encctl_gym.loop.defense_costs.measure_local_control_seconds`);

and, in the units of the quadratic cost, the control cost of the noise
(:func:`~.defenses.noise_defense_price`; the noise is an input of the design, not searched, so
no exchange rate between seconds and control cost is needed).

``auto`` searches exactly: for audits the only rates worth paying are ``0`` and the smallest
secure one ``p_J = 1 - delta^(1/J)`` (:func:`~.quiet_attackers.sparse_audit_rate`; a rate below
``p_J`` secures nothing, one above costs more). For rotation, every key length ``k`` between ``k*(1)`` and
the fixed group's ``k*`` is paired with the largest ``K`` that keeps it key-secure (the cheapest
rotation for that key), ``K = ceil(N* / (g - 1)) - 1`` with ``g`` the fewest groups that suffice
at ``k``; any other ``(k, K)`` costs at least as much, so the minimum over these pairs and the
fixed group is the minimum over all ``K``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from fractions import Fraction
from typing import Any

from .._validation import as_finite_array, check_int, check_nonnegative, check_positive, check_probability, format_value
from ..errors import ModelRangeError, ParameterError
from ..plant import as_plant
from .cost_models import GNFS_MIN_KEY_LENGTH, CostModel, paper_security_parameter
from .deciphering import keys_to_break
from .defenses import noise_defense_design, noise_defense_price, rotation_precomputations, undetected_probability
from .key_length import build_model, defense_budget
from .quiet_attackers import (
    DEFAULT_INPUT_BOUND_SIGMAS,
    StealthySamples,
    check_confidentiality_floor,
    fewest_falsified_steps,
    passive_samples,
    sparse_audit_rate,
    stealthy_samples,
)
from .records import RecordSet
from .rotation import rotated_minimum_key_length
from .threat import ThreatModel

__all__ = [
    "DEFAULT_MIN_KEY_LENGTH",
    "DefenderCosts",
    "DefenseMix",
    "DefenseDesign",
    "ModelDefenseDesign",
    "check_rotate_every",
    "check_detection_delta",
    "design_defenses",
    "largest_rotation_period",
    "plant_exponentiations_per_step",
    "reprovision_exponentiations",
    "rotated_key_length",
]

#: Smallest key length an audit-secure mix uses: the lower end of the GNFS models' range, the
#: largest of the models' lower ends (:mod:`encctl_gym.security.cost_models`).
DEFAULT_MIN_KEY_LENGTH: int = GNFS_MIN_KEY_LENGTH


def plant_exponentiations_per_step(n: int) -> int:
    """``3 n + 1``: the plant side's modular exponentiations per step of the modified scheme
    (``2 n`` for ``Enc(pk_t, x)``, one for KeyUpd, ``n`` column parts ``c2^(-s_t)``)."""
    return 3 * check_int("n", n, minimum=1) + 1


def reprovision_exponentiations(n: int, m: int) -> int:
    """``1 + 3 n m``: exponentiations to move to a fresh group: KeyGen, the ``n m`` encryptions of
    ``Enc(pk_0', Ecd(Phi))`` (two each) and their fixed parts ``c1^(-s_0)`` (one each)."""
    return 1 + 3 * check_int("n", n, minimum=1) * check_int("m", m, minimum=1)


@dataclass(frozen=True)
class DefenderCosts:
    """The defender's cost terms per step, in seconds (module docstring).

    The time models come from the layers that own them (this package is mathematics only):
    :func:`encctl_gym.loop.defense_costs.reference_defender_costs` builds the reference machine's.

    Attributes
    ----------
    n, m : int
        State and input dimensions.
    exponentiation_seconds : callable
        ``k -> `` the time of one modular exponentiation at ``k`` bits.
    group_generation_seconds : callable
        ``k -> `` the expected time of a ``k``-bit safe-prime search.
    local_control_seconds : float
        One audit: ``Phi x`` computed on the plant side and compared.
    """

    n: int
    m: int
    exponentiation_seconds: Callable[[int], float]
    group_generation_seconds: Callable[[int], float]
    local_control_seconds: float

    def __post_init__(self) -> None:
        check_int("n", self.n, minimum=1)
        check_int("m", self.m, minimum=1)
        check_nonnegative("local_control_seconds", self.local_control_seconds)
        for name in ("exponentiation_seconds", "group_generation_seconds"):
            if not callable(getattr(self, name)):
                raise ParameterError(f"{name} must be a function of the key length, got {format_value(getattr(self, name))}")

    def encrypted_step_seconds(self, key_length: int) -> float:
        """``(3 n + 1) t_pow(k)``: the plant side's encrypted step at ``k`` bits."""
        return plant_exponentiations_per_step(self.n) * float(self.exponentiation_seconds(key_length))

    def rotation_seconds(self, key_length: int) -> float:
        """A move to a fresh ``k``-bit group: the expected safe-prime search plus ``1 + 3 n m``
        exponentiations (not yet divided by ``K``)."""
        t_pow = float(self.exponentiation_seconds(key_length))
        return float(self.group_generation_seconds(key_length)) + reprovision_exponentiations(self.n, self.m) * t_pow

    def audit_seconds(self, audit_rate: float) -> float:
        """``p`` local control computations per step."""
        return check_nonnegative("audit_rate", audit_rate) * self.local_control_seconds


def check_rotate_every(K: Any) -> int | None:
    """A rotation period: ``None`` (the group never changes) or an integer ``K >= 1``."""
    return None if K is None else check_int("rotate_every", K, minimum=1)


def check_detection_delta(delta: Any) -> float:
    """The tolerated probability that an attacker collects ``N*`` samples unseen, in (0, 1)."""
    d = check_positive("detection_delta", delta)
    if d >= 1:
        raise ParameterError(f"detection_delta must lie in (0, 1), got {format_value(delta)}")
    return d


def _work(model: CostModel, key_length: int, keys: int, K: int | None) -> Fraction:
    """The attacker's operations, exactly: ``C_first + (N - 1) C_next`` for one group, else
    ``ceil(N / K) C_pre + N C_key`` (:func:`~.defenses.rotated_deciphering_operations`, kept in
    Fractions here so that keys of any length compare exactly with the budget)."""
    cost = model.break_cost(key_length)
    if K is None or cost.precomputation is None:
        return cost.operations(keys)
    return rotation_precomputations(keys, K) * cost.precomputation + keys * cost.next


def rotated_key_length(model: CostModel, keys: int, budget: Fraction, K: int | None) -> int:
    """``k*(K)``: the smallest key length of the model's range whose work for ``keys`` samples,
    with the group rotating every ``K`` steps (``None``: never), exceeds ``budget``.

    Raises
    ------
    ModelRangeError
        If no key length of the range suffices, or the smallest already does.
    """
    keys = check_int("keys", keys, minimum=1)
    K = check_rotate_every(K)
    if K is None:
        return model.minimum_key_length(keys, budget)
    # one home for k*(K): the group-charged search of security.rotation
    return rotated_minimum_key_length(model, keys, K, budget)


def largest_rotation_period(model: CostModel, key_length: int, keys: int, budget: Fraction) -> int | None:
    """The largest ``K`` that keeps a ``key_length``-bit key secure for ``keys`` samples, ``None``
    when the fixed group already is, ``0`` when even ``K = 1`` is not (module docstring)."""
    keys = check_int("keys", keys, minimum=1)
    cost = model.break_cost(key_length)
    if cost.operations(keys) > budget:
        return None
    if cost.precomputation is None or cost.precomputation == 0:
        return 0
    short = budget - keys * cost.next  # > 0 here: what the precomputations must cover
    g = math.floor(short / cost.precomputation) + 1  # fewest groups with g C_pre + N C_key > budget
    if g > keys:
        return 0
    return -(-keys // (g - 1)) - 1


@dataclass(frozen=True)
class DefenseMix:
    """One mix of levers and what it costs (module docstring).

    Attributes
    ----------
    key_length : int
        Bits of p.
    rotate_every : int or None
        ``K`` (``None``: the group never changes).
    audit_rate : float
        ``p``.
    key_secure, audit_secure : bool
        Whether the key (with the rotation) or the audits make it secure.
    undetected_probability : float
        ``(1 - p)^J``, ``J`` the design's :attr:`DefenseDesign.audit_steps`.
    step_seconds, rotation_seconds, audit_seconds, total_seconds : float
        The cost terms per step and their sum.
    """

    key_length: int
    rotate_every: int | None
    audit_rate: float
    key_secure: bool
    audit_secure: bool
    undetected_probability: float
    step_seconds: float
    rotation_seconds: float
    audit_seconds: float
    total_seconds: float
    #: secured by a detector against the stealthy attacker (:func:`~.quiet_attackers.stealthy_samples`)
    detector_secure: bool = False

    @property
    def secure(self) -> bool:
        """Key-secure, audit-secure or detector-secure."""
        return self.key_secure or self.audit_secure or self.detector_secure

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        d = asdict(self)
        d["secure"] = self.secure
        return d


@dataclass(frozen=True)
class ModelDefenseDesign:
    """The design under one cost model: the chosen mix, the best key-secure mix without audits
    and the audit-secure mix at the smallest key (``None`` where the options exclude them)."""

    model: str
    k_star: int
    step_seconds_at_k_star: float
    chosen: DefenseMix
    key_only: DefenseMix | None
    audit_only: DefenseMix | None
    #: the smallest key any mix uses: ``--min-key-length``, the model's range, the confidentiality
    #: floor and the passive attacker's key (with the fixed group)
    key_floor: int = 0
    #: the key that makes the passive attacker's samples too expensive (fixed group), or ``None``
    passive_key_length: int | None = None
    #: with a detector: the mix it secures (the stealthy attacker's samples kept out), or ``None``
    detector_only: DefenseMix | None = None

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {
            "model": self.model,
            "k_star": self.k_star,
            "step_seconds_at_k_star": self.step_seconds_at_k_star,
            "key_floor": self.key_floor,
            "passive_key_length": self.passive_key_length,
            **{
                key: None if v is None else v.to_dict()
                for key, v in (
                    ("chosen", self.chosen),
                    ("key_only", self.key_only),
                    ("audit_only", self.audit_only),
                    ("detector_only", self.detector_only),
                )
            },
        }


@dataclass(frozen=True)
class DefenseDesign:
    """Everything ``encctl-gym design`` prints about the defender's levers."""

    N_star: int
    keys: int
    lam_star: int
    sigma_d2: float
    detection_delta: float
    minimum_audit_rate: float
    rotate_every: int | str | None
    audit_rate: float | str | None
    min_key_length: int
    local_control_seconds: float
    noise_price: dict[str, float]
    models: dict[str, ModelDefenseDesign] = field(default_factory=dict)
    #: ``u_max`` of the sparse attacker
    input_bound: float = 0.0
    #: ``J_min``: the sparse attacker's fewest falsified steps (:mod:`.quiet_attackers`)
    fewest_falsified_steps: int = 0
    #: ``min(J_min, N*)``: the falsified steps an audit must catch one of
    audit_steps: int = 0
    #: ``1 - delta^(1 / audit_steps)``: the audit-secure rate against the sparse attacker
    sparse_audit_rate: float = 0.0
    #: samples the passive attacker needs from the defender's noise (``inf`` without noise)
    passive_samples: float = math.inf
    #: the confidentiality floor in bits, or ``None``
    confidentiality_floor: int | None = None
    #: the stealthy attacker against the design's detector, or ``None`` without one
    stealth: StealthySamples | None = None
    #: the detector's false alarms per step (``None`` without a detector)
    false_alarm_rate: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (an infinite sample count as ``None``)."""
        d = {k: v for k, v in asdict(self).items() if k != "models"}
        d["models"] = {name: v.to_dict() for name, v in self.models.items()}
        if math.isinf(self.passive_samples):
            d["passive_samples"] = None
        if self.stealth is not None and math.isinf(self.stealth.samples):
            d["stealth"]["samples"] = None
        return d


def _mix(costs: DefenderCosts, k: int, K: int | None, p: float, *, key_secure: bool, N_star: int, delta: float) -> DefenseMix:
    """``N_star`` here is the design's ``audit_steps`` (the falsified steps an audit must catch)."""
    q = undetected_probability(N_star, p)
    step = costs.encrypted_step_seconds(k)
    rot = 0.0 if K is None else costs.rotation_seconds(k) / K
    aud = costs.audit_seconds(p)
    return DefenseMix(k, K, p, key_secure, q <= delta, q, step, rot, aud, step + rot + aud)


def _key_candidates(model: CostModel, keys: int, budget: Fraction, rotate: int | str | None) -> list[tuple[int, int | None]]:
    """Key-secure ``(k, K)`` pairs: the given ``K``, or for ``auto`` every key length with its
    largest ``K`` and the fixed group."""
    if rotate != "auto":
        K = check_rotate_every(rotate)
        return [(rotated_key_length(model, keys, budget, K), K)]
    k_fixed = model.minimum_key_length(keys, budget)
    out: list[tuple[int, int | None]] = [(k_fixed, None)]
    if model.break_cost(k_fixed).precomputation is None:
        return out
    for k in range(rotated_key_length(model, keys, budget, 1), k_fixed):
        K = largest_rotation_period(model, k, keys, budget)
        if K:
            out.append((k, K))
    return out


def _check_levers(rotate_every: Any, audit_rate: Any) -> tuple[int | str | None, float | str | None]:
    """``rotate_every`` (``K >= 1``, ``"auto"`` or None) and ``audit_rate`` (``p`` in [0, 1],
    ``"auto"`` or None), checked; any other word is refused."""
    for name, value in (("rotate_every", rotate_every), ("audit_rate", audit_rate)):
        if isinstance(value, str) and value != "auto":
            raise ParameterError(f"{name} must be a number or 'auto', got {format_value(value)}")
    if rotate_every != "auto":
        rotate_every = check_rotate_every(rotate_every)
    if audit_rate not in (None, "auto"):
        audit_rate = check_probability("audit_rate", audit_rate)
    return rotate_every, audit_rate


def _key_for(model: Any, keys: int | None, budget: Any, K: int | None) -> int | None:
    """The smallest key whose work for ``keys`` keys exceeds ``budget`` (with rotation every
    ``K``); ``None`` for no keys (an attacker that never identifies)."""
    if keys is None:
        return None
    try:
        return rotated_key_length(model, keys, budget, K)
    except ModelRangeError:
        lowest = model.key_length_range[0]
        if _work(model, lowest, keys, K) > budget:  # the model's smallest key already keeps it out
            return int(lowest)
        raise


def _model_design(
    model: Any,
    costs: DefenderCosts,
    *,
    keys: int,
    budget: Any,
    rates: Sequence[float],
    rotate_every: int | str | None,
    N_star: int,
    delta: float,
    min_k: int,
    floor: int | None = None,
    passive_keys: int | None = None,
    detector: tuple[int | None, float] | None = None,
) -> ModelDefenseDesign:
    """The cheapest mix under one cost model: for each audit rate, the audit-secure mix at the
    smallest key (when the rate alone keeps ``(1 - p)^J <= delta``, ``J = N_star`` here the
    design's audit steps) or every key-secure ``(k, K)`` of :func:`_key_candidates`; the key-only
    and audit-only mixes beside it. Every key is lifted to the confidentiality ``floor`` and to
    the key that keeps the passive attacker (``passive_keys`` keys to break) out. ``detector``:
    ``(keys, seconds)``, the keys the stealthy attacker must break (``None``: the detector alone
    holds) and the detector's cost per step; its mix joins the candidates."""
    k_star = model.minimum_key_length(keys, budget)
    fixed_K = rotate_every if isinstance(rotate_every, int) else None
    passive_key = _key_for(model, passive_keys, budget, fixed_K)
    k_floor = max(min_k, model.key_length_range[0], floor or 0, passive_key or 0)
    candidates: list[DefenseMix] = []
    key_only: DefenseMix | None = None
    audit_only: DefenseMix | None = None
    for rate in rates:
        if undetected_probability(N_star, rate) <= delta:
            secure_key = _work(model, k_floor, keys, fixed_K) > budget
            mix = _mix(costs, k_floor, fixed_K, rate, key_secure=secure_key, N_star=N_star, delta=delta)
            audit_only = mix
            candidates.append(mix)
            continue
        for k, K in _key_candidates(model, keys, budget, rotate_every):
            k = max(k, floor or 0, _key_for(model, passive_keys, budget, K) or 0)
            mix = _mix(costs, k, K, rate, key_secure=True, N_star=N_star, delta=delta)
            candidates.append(mix)
            if rate == 0.0 and (key_only is None or mix.total_seconds < key_only.total_seconds):
                key_only = mix
    detector_only: DefenseMix | None = None
    if detector is not None:
        stealth_keys, seconds = detector
        k = max(k_floor, _key_for(model, stealth_keys, budget, fixed_K) or 0)
        base = _mix(costs, k, fixed_K, 0.0, key_secure=_work(model, k, keys, fixed_K) > budget, N_star=N_star, delta=delta)
        detector_only = DefenseMix(
            **{**asdict(base), "audit_seconds": seconds, "total_seconds": base.total_seconds + seconds, "detector_secure": True}
        )
        candidates.append(detector_only)
    chosen = min(candidates, key=lambda c: c.total_seconds)
    return ModelDefenseDesign(
        model.name,
        k_star,
        costs.encrypted_step_seconds(k_star),
        chosen,
        key_only,
        audit_only,
        k_floor,
        passive_key,
        detector_only,
    )


def design_defenses(
    plant: Any,
    threat: ThreatModel,
    *,
    costs: DefenderCosts,
    controller: Any,
    cost_models: Sequence[str] = ("paper", "precomputation", "generic"),
    rotate_every: int | str | None = None,
    audit_rate: float | str | None = None,
    detection_delta: float = 1e-3,
    sigma_d2: float = 0.0,
    gnfs_correction: Any = 0.0,
    calibration: RecordSet | None = None,
    min_key_length: int = DEFAULT_MIN_KEY_LENGTH,
    input_bound: float | None = None,
    confidentiality_floor: int | str | None = None,
    detector: str | None = None,
    false_alarm_rate: float = 1e-4,
    detector_window: int = 10,
) -> DefenseDesign:
    """The cheapest secure mix of the defender's levers per cost model (module docstring).

    Parameters
    ----------
    plant : Plant or (A, B)
        The plant of eq:system.
    threat : ThreatModel
        With ``sigma_u2``, ``sigma_w2``, ``gamma_c``, ``tau_c``, ``upsilon`` (and the adversary).
    costs : DefenderCosts
        The cost terms (:func:`encctl_gym.loop.defense_costs.reference_defender_costs`).
    controller : array_like, shape (m, n)
        ``Phi``, for the noise's control cost (the loop's is ``-lqr_gain(A, B)``, ``Q = R = I``).
    cost_models : sequence of str
        Deciphering-cost models (:data:`~.cost_models.DECIPHERING_MODELS`).
    rotate_every : int, "auto" or None
        ``K >= 1``, ``"auto"`` (searched) or ``None`` (the group never changes).
    audit_rate : float, "auto" or None
        ``p`` in [0, 1], ``"auto"`` (0 or ``p_J``) or ``None`` (no audits).
    detection_delta : float, default 1e-3
        Tolerated ``(1 - p)^J`` (and a detector's miss probability), in (0, 1).
    sigma_d2, gnfs_correction, calibration, min_key_length
        The defender's input noise variance (>= 0, default 0); the GNFS models' o(1) correction
        in bits; records of the precomputation model; the smallest key, that of an audit-secure
        mix (default :data:`DEFAULT_MIN_KEY_LENGTH`).
    input_bound, confidentiality_floor, detector, false_alarm_rate, detector_window
        The quiet attackers' options (:mod:`.quiet_attackers`): the sparse attacker's ``u_max``
        (default ``DEFAULT_INPUT_BOUND_SIGMAS sigma_u``); the smallest key of any mix (bits,
        ``"nist"``, ``"nist-2031"`` or ``None``); a detector (``"chi2"``, ``"cusum"`` or ``None``)
        with its false alarms per step and window: the stealthy attacker must stay unseen with
        probability ``>= 1 - detection_delta``, and the detector's mix joins the search.

    Returns
    -------
    DefenseDesign

    Raises
    ------
    ParameterError
        For ``K < 1``, ``p`` outside [0, 1], negative noise, ``delta`` outside (0, 1), an unknown word.
    """
    rotate_every, audit_rate = _check_levers(rotate_every, audit_rate)
    delta, sd = check_detection_delta(detection_delta), check_nonnegative("sigma_d2", sigma_d2)
    min_k = check_int("min_key_length", min_key_length, minimum=1)
    p, t = as_plant(plant), threat.require("sigma_u2", "sigma_w2", "gamma_c")
    N_star = noise_defense_design(p, t, sigma_d2=sd).N_star
    keys, budget = keys_to_break(N_star, "modified", t.adversary), defense_budget(t.tau_c, t.upsilon)
    if not isinstance(costs, DefenderCosts) or (costs.n, costs.m) != (p.n, p.m):
        raise ParameterError(f"costs must be DefenderCosts for n = {p.n}, m = {p.m}, got {format_value(costs)}")
    Phi = as_finite_array("controller", controller, ndim=2)
    price = noise_defense_price(p.A, p.B, Phi, sigma_w2=float(t.sigma_w2), sigma_d2=sd)
    p_star = sparse_audit_rate(N_star, delta)  # the rule for an attacker falsifying every sample (minimum_audit_rate)
    quiet, passive_keys = _quiet_attackers(p, t, Phi, input_bound, sd, N_star, delta)
    quiet["confidentiality_floor"] = floor = check_confidentiality_floor(confidentiality_floor)
    quiet["stealth"], detector_terms = _stealth(p, t, Phi, detector, false_alarm_rate, detector_window, delta, N_star, costs)
    quiet["false_alarm_rate"] = None if detector is None else float(false_alarm_rate)
    rates = [0.0, quiet["sparse_audit_rate"]] if audit_rate == "auto" else [0.0 if audit_rate is None else float(audit_rate)]
    search: dict[str, Any] = dict(keys=keys, budget=budget, rates=rates, rotate_every=rotate_every, delta=delta, min_k=min_k)
    search.update(N_star=quiet["audit_steps"], floor=floor, passive_keys=passive_keys, detector=detector_terms)
    out = {}
    for name in cost_models:
        model = build_model(name, gnfs_correction, calibration)
        out[model.name] = _model_design(model, costs, **search)
    return DefenseDesign(
        N_star=N_star,
        keys=keys,
        lam_star=paper_security_parameter(keys, budget),
        sigma_d2=sd,
        detection_delta=delta,
        minimum_audit_rate=p_star,
        rotate_every=rotate_every,
        audit_rate=audit_rate,
        min_key_length=min_k,
        local_control_seconds=costs.local_control_seconds,
        noise_price=price,
        models=out,
        **quiet,
    )


def _quiet_attackers(
    p: Any, t: Any, Phi: Any, input_bound: float | None, sigma_d2: float, N_star: int, delta: float
) -> tuple[dict[str, Any], int | None]:
    """The :class:`DefenseDesign` fields of the sparse attacker at the input bound (default
    ``DEFAULT_INPUT_BOUND_SIGMAS sigma_u``) and of the passive attacker (:mod:`.quiet_attackers`),
    and the keys the passive attacker must break (``None``: it cannot identify)."""
    u_max = DEFAULT_INPUT_BOUND_SIGMAS * math.sqrt(float(t.sigma_u2)) if input_bound is None else input_bound
    fewest = fewest_falsified_steps(p.A, p.B, Phi, sigma_w2=float(t.sigma_w2), gamma_c=float(t.gamma_c), input_bound=u_max)
    n_passive = passive_samples(p.A, p.B, Phi, sigma_w2=float(t.sigma_w2), sigma_d2=sigma_d2, gamma_c=float(t.gamma_c))
    steps = min(fewest.steps, N_star)
    passive_keys = None if math.isinf(n_passive) else keys_to_break(int(n_passive), "modified", t.adversary)
    fields = {
        "input_bound": float(fewest.input_bound),
        "fewest_falsified_steps": fewest.steps,
        "audit_steps": steps,
        "sparse_audit_rate": sparse_audit_rate(steps, delta),
        "passive_samples": float(n_passive),
    }
    return fields, passive_keys


def _stealth(
    p: Any, t: Any, Phi: Any, detector: str | None, alpha: float, window: int, delta: float, N_star: int, costs: DefenderCosts
) -> tuple[StealthySamples | None, tuple[int | None, float] | None]:
    """The stealthy attacker against ``detector`` and the terms of its mix: ``(keys, seconds)``
    with the keys of ``max(its samples, N*)`` (the detector never lowers the bar below the
    attacker of N*), ``None`` keys when no excitation stays unseen; no mix at all when the honest
    loop alarms within ``N*`` steps with probability above ``delta`` (the alarms do not tell an
    attack from noise) or without a detector."""
    if detector is None:
        return None, None
    st = stealthy_samples(
        p.A,
        p.B,
        Phi,
        sigma_w2=float(t.sigma_w2),
        gamma_c=float(t.gamma_c),
        detector=detector,
        false_alarm_rate=alpha,
        delta=delta,
        power=float(t.sigma_u2),
        horizon=N_star,
        window=check_int("detector_window", window, minimum=1),
    )
    if math.isinf(st.samples):
        return st, ((None, costs.local_control_seconds) if st.false_alarm_within <= delta else None)
    return st, (keys_to_break(max(int(st.samples), N_star), "modified", t.adversary), costs.local_control_seconds)
