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
* **Audits** at rate ``p``: the mix is *audit-secure* when an attacker injecting at every step
  collects ``N*`` samples before an alarm with probability ``(1 - p)^{N*} <= delta``
  (:func:`~.defenses.undetected_probability`), whatever the key length. An audit-secure mix
  needs no key length for this threat and uses the smallest one the design allows
  (``min_key_length``, default :data:`DEFAULT_MIN_KEY_LENGTH`).

A mix is secure when it is key-secure or audit-secure. Its cost per step, in seconds on the
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
secure one ``p* = 1 - delta^(1/N*)`` (:func:`~.defenses.minimum_audit_rate`; a rate below ``p*``
secures nothing, one above costs more). For rotation, every key length ``k`` between ``k*(1)`` and
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
from ..errors import ParameterError
from ..plant import as_plant
from .cost_models import GNFS_MIN_KEY_LENGTH, CostModel, paper_security_parameter
from .deciphering import keys_to_break
from .defenses import (
    minimum_audit_rate,
    noise_defense_design,
    noise_defense_price,
    rotation_precomputations,
    undetected_probability,
)
from .key_length import build_model, defense_budget
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
        ``(1 - p)^{N*}``.
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

    @property
    def secure(self) -> bool:
        """Key-secure or audit-secure."""
        return self.key_secure or self.audit_secure

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

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {
            "model": self.model,
            "k_star": self.k_star,
            "step_seconds_at_k_star": self.step_seconds_at_k_star,
            **{
                key: None if v is None else v.to_dict()
                for key, v in (("chosen", self.chosen), ("key_only", self.key_only), ("audit_only", self.audit_only))
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

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        d = {k: v for k, v in asdict(self).items() if k != "models"}
        d["models"] = {name: v.to_dict() for name, v in self.models.items()}
        return d


def _mix(costs: DefenderCosts, k: int, K: int | None, p: float, *, key_secure: bool, N_star: int, delta: float) -> DefenseMix:
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
) -> ModelDefenseDesign:
    """The cheapest mix under one cost model: for each audit rate, the audit-secure mix at the
    smallest key (when the rate alone keeps ``(1 - p)^{N*} <= delta``) or every key-secure
    ``(k, K)`` of :func:`_key_candidates`; the key-only and audit-only mixes beside it."""
    k_star = model.minimum_key_length(keys, budget)
    k_floor = max(min_k, model.key_length_range[0])
    fixed_K = rotate_every if isinstance(rotate_every, int) else None
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
            mix = _mix(costs, k, K, rate, key_secure=True, N_star=N_star, delta=delta)
            candidates.append(mix)
            if rate == 0.0 and (key_only is None or mix.total_seconds < key_only.total_seconds):
                key_only = mix
    chosen = min(candidates, key=lambda c: c.total_seconds)
    return ModelDefenseDesign(model.name, k_star, costs.encrypted_step_seconds(k_star), chosen, key_only, audit_only)


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
        ``p`` in [0, 1], ``"auto"`` (0 or ``p*``) or ``None`` (no audits).
    detection_delta : float, default 1e-3
        Tolerated ``(1 - p)^{N*}``, in (0, 1).
    sigma_d2 : float, default 0.0
        The defender's input noise variance (>= 0).
    gnfs_correction : float, default 0.0
        o(1) correction of the GNFS models in bits.
    calibration : RecordSet, optional
        Records of the precomputation model.
    min_key_length : int, default :data:`DEFAULT_MIN_KEY_LENGTH`
        The key length of an audit-secure mix.
    Returns
    -------
    DefenseDesign

    Raises
    ------
    ParameterError
        For ``K < 1``, ``p`` outside [0, 1], negative noise, ``delta`` outside (0, 1), an unknown
        option word.
    """
    rotate_every, audit_rate = _check_levers(rotate_every, audit_rate)
    delta = check_detection_delta(detection_delta)
    sd = check_nonnegative("sigma_d2", sigma_d2)
    min_k = check_int("min_key_length", min_key_length, minimum=1)
    p = as_plant(plant)
    t = threat.require("sigma_u2", "sigma_w2", "gamma_c")
    N_star = noise_defense_design(p, t, sigma_d2=sd).N_star
    keys = keys_to_break(N_star, "modified", t.adversary)
    budget = defense_budget(t.tau_c, t.upsilon)
    if not isinstance(costs, DefenderCosts) or (costs.n, costs.m) != (p.n, p.m):
        raise ParameterError(f"costs must be DefenderCosts for n = {p.n}, m = {p.m}, got {format_value(costs)}")
    Phi = as_finite_array("controller", controller, ndim=2)
    price = noise_defense_price(p.A, p.B, Phi, sigma_w2=float(t.sigma_w2), sigma_d2=sd)
    p_star = minimum_audit_rate(N_star, delta)
    while undetected_probability(N_star, p_star) > delta:  # the closed form's last rounding step
        p_star = math.nextafter(p_star, 1.0)
    rates = [0.0, p_star] if audit_rate == "auto" else [0.0 if audit_rate is None else float(audit_rate)]
    out: dict[str, ModelDefenseDesign] = {}
    for name in cost_models:
        model = build_model(name, gnfs_correction, calibration)
        out[model.name] = _model_design(
            model,
            costs,
            keys=keys,
            budget=budget,
            rates=rates,
            rotate_every=rotate_every,
            N_star=N_star,
            delta=delta,
            min_k=min_k,
        )
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
    )
