"""Configuration of the attack environment: defaults, merging, validation.

Following HighwayEnv, every knob lives in one dictionary, :func:`default_config`, merged with
the user's ``config`` and keyword arguments and resolved once into an immutable
:class:`AttackParams` that the single and the vector environment share.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from .._user_warning import warn_user
from .._validation import (
    check_bool,
    check_int,
    check_nonnegative,
    check_positive,
    check_probability,
    check_regular_file,
    check_schur_stable,
    check_system,
    format_value,
)
from ..errors import BudgetError, ConfigError, ParameterError
from ..ident.registry import make_estimator
from ..loop import BACKENDS as _LOOP_BACKENDS
from ..loop.defender import make_defender
from ..loop.injection import check_injection
from ..loop.scheme import MalleableScheme, make_scheme
from ..loop.spec import LoopSpec
from ..plant import Plant
from ..presets import get_preset
from ..security.complexity import sic_from_traces
from ..security.cost_models import (
    GENERIC_MIN_KEY_LENGTH,
    GUILLEVIC_CORRECTION,
    CostModel,
    KeyBreakCost,
    check_gnfs_correction,
    check_security_parameter,
)
from ..security.deciphering import ADVERSARIES, independent_keys, max_affordable_samples, per_sample_cost, sample_deciphering_time
from ..security.design import design_from_traces
from ..security.exact import decimal_fraction
from ..security.gramians import controllability_gramian, noise_gramian
from ..security.rotation import check_rotation_period, rotated_affordable_samples, rotated_deciphering_time
from ..security.threat import ThreatModel
from ..units import parse_duration
from .defaults import default_config
from .layout import ObservationLayout
from .rewards import REWARDS as _REWARD_CLASSES

__all__ = ["default_config", "AttackParams", "resolve_params", "completion_preset", "REWARDS", "BACKENDS", "DECIPHERING_CLOCKS"]

#: What the environment charges for deciphering: the cost model's tau(N), or the breaker's measured seconds.
DECIPHERING_CLOCKS: tuple[str, ...] = ("model", "measured")

#: Names of the rewards (:data:`encctl_gym.envs.rewards.REWARDS`) and backends (:data:`encctl_gym.loop.BACKENDS`).
REWARDS: tuple[str, ...] = tuple(_REWARD_CLASSES)
BACKENDS: tuple[str, ...] = tuple(_LOOP_BACKENDS)


@dataclass(frozen=True)
class AttackParams:
    """Resolved, validated parameters of one environment (shared by the vector environment).

    The fields are flat; the value objects they compose are :attr:`plant` (the
    :class:`~encctl_gym.plant.Plant` ``(A, B)``), :attr:`threat` (the
    :class:`~encctl_gym.security.threat.ThreatModel`: variances, gamma_c, tau_c, Upsilon, the
    adversary and the cost model) and :attr:`loop` (the :class:`~encctl_gym.loop.spec.LoopSpec`:
    backend, scheme, key length, Delta, breaker, defender), each built once from the checked
    fields.
    """

    A: np.ndarray
    B: np.ndarray
    sigma_w2: float
    sigma_x2: float
    sigma_u2: float
    scheme: Any  # the scheme specification (a name of loop.scheme.SCHEMES, a mapping with a name, or an object)
    adversary: str
    security_parameter: float  # lambda of the paper's model for this key (def:bit_sec, eq:opt_key)
    key_length: int
    upsilon: float
    tau_c: float
    gamma_c: float
    deciphering_model: str
    cost: KeyBreakCost  # operations for the first key of the group and for each further key
    sample_cost: float  # seconds to break the first key (2^lambda / Upsilon under the paper's model)
    next_sample_cost: float  # seconds to break each further key of the same group
    budget_samples: float  # samples affordable within tau_c (inf if one break reveals all)
    horizon: int  # N: the attack length in samples
    independent_keys: bool  # every sample under its own key (def:sdt), else one break reveals all
    budget_limited: bool  # the horizon is set by tau_c (terminated) rather than max_samples (truncated)
    #  (with deciphering_clock="measured" the horizon is max_samples; tau_c ends the episode when measured time passes it)
    decipher_delay: int | None  # None means "end"
    warmup_steps: int
    estimator: Any  # the estimator specification (a name or a mapping), checked
    reward: str
    logdet_regularization: float
    crypto: str
    delta: int
    x_bound: float
    u_max: float
    input_history: int
    gamma_opt: bool
    crypto_seed: int | None
    breaker: str | None  # None: the break is simulated (the plant's key is read)
    breaker_time_limit: float
    deciphering_clock: str  # "model" (tau(N) of the cost model) or "measured" (the breaker's wall seconds)
    tr_psi_u: float
    tr_psi_w: float
    sources: dict[str, str] = field(default_factory=dict)  # where A, B, the variances and design values came from
    defender: Any = "fixed"  # the defender policy specification (a name or a policy object), checked
    horizon_capped: bool = False  # no max_samples and a budget beyond MAX_DEFAULT_HORIZON: N is that cap
    rotate_group_every: int | None = None  # K: a fresh group every K attack steps (None: one group)
    audit_probability: float | None = None  # p: audits per step added to the defender (None: none)
    defense_noise_sigma2: float | None = None  # sigma_d2: input noise added to the defender (None: none)
    breaker_precomputation: str | None = None  # a precomputation file the breaker loads (index calculus)
    cost_model: CostModel | None = None  # the built deciphering model (its GNFS correction); None: the named one's defaults

    observe: str = "state"  # "state" (x is sent) or "output" (y = C x + v is sent: envs.output_episode)
    C: np.ndarray | None = None  # the sensors of observe="output" (None: the state is sent)
    sigma_v2: float = 0.0  # measurement noise variance of observe="output"
    controller: str = "static"  # the loop's controller on outputs (loop.output_feedback.CONTROLLERS)
    injection: str = "replace"  # how the action enters the loop (loop.injection.INJECTIONS)

    @cached_property
    def plant(self) -> Plant:
        """The plant ``(A, B)`` of eq:system (with ``C`` and ``sigma_v2`` when outputs are sent) as a value object."""
        return Plant(self.A, self.B) if self.C is None else Plant(self.A, self.B, C=self.C, sigma_v2=self.sigma_v2)

    @cached_property
    def threat(self) -> ThreatModel:
        """The adversary and the defender's tolerances (Definition def:security)."""
        return ThreatModel(
            tau_c=self.tau_c,
            upsilon=self.upsilon,
            sigma_u2=self.sigma_u2,
            sigma_w2=self.sigma_w2,
            sigma_x2=self.sigma_x2,
            gamma_c=self.gamma_c,
            adversary=self.adversary,
            cost_model=self.cost_model if self.cost_model is not None else self.deciphering_model,
        )

    @cached_property
    def loop(self) -> LoopSpec:
        """The closed loop as the loop layer takes it (:class:`~encctl_gym.loop.spec.LoopSpec`):
        the plant, backend, scheme, key length, Delta, breaker, defender and injection mode."""
        return LoopSpec(
            plant=self.plant,
            sigma_w2=self.sigma_w2,
            adversary=self.adversary,
            horizon=self.horizon,
            crypto=self.crypto,
            scheme=self.scheme,
            key_length=self.key_length,
            delta=self.delta,
            x_bound=self.x_bound,
            u_max=self.u_max,
            breaker=self.breaker,
            breaker_time_limit=self.breaker_time_limit,
            crypto_seed=self.crypto_seed,
            defender=self.defender,
            rotate_group_every=self.rotate_group_every,
            breaker_precomputation=self.breaker_precomputation,
            observe=self.observe,
            controller=self.controller,
            injection=self.injection,
            audit_probability=self.audit_probability,
            defense_noise_sigma2=self.defense_noise_sigma2,
            ciphertexts=bool(getattr(_LOOP_BACKENDS[self.crypto], "needs_key_length_group", True)),
        )

    @property
    def observed_dim(self) -> int:
        """Length of what the plant sends and the attacker deciphers: ``p`` for outputs, else ``n``."""
        return self.n if self.C is None else int(self.C.shape[0])

    def warn_if_capped(self) -> None:
        """Warn (once per environment, when it is made) that the attack length is the default cap
        :data:`MAX_DEFAULT_HORIZON`, not what the budget buys."""
        if self.horizon_capped:
            warn_user(
                f"the deciphering budget buys N = {format_value(self.budget_samples)} samples within tau_c = "
                f"{self.tau_c:g} s (k = {self.key_length} bits); without max_samples the attack is capped at "
                f"N = {self.horizon} (MAX_DEFAULT_HORIZON) and truncated there: set max_samples for another length"
            )

    @property
    def n(self) -> int:
        return int(self.A.shape[0])

    @property
    def m(self) -> int:
        return int(self.B.shape[1])

    def deciphering_time(self, N: Any) -> Any:
        """tau(N) of the configured model (Definition def:sdt, :func:`sample_deciphering_time`), seconds;
        with ``rotate_group_every`` the model charged per group
        (:func:`~encctl_gym.security.rotation.rotated_deciphering_time`)."""
        if self.rotate_group_every is not None:
            return rotated_deciphering_time(
                N, self.cost, self.upsilon, self.rotate_group_every, scheme=self.loop.encryption(), adversary=self.adversary
            )
        return sample_deciphering_time(N, self.cost, self.upsilon, scheme=self.loop.encryption(), adversary=self.adversary)

    @property
    def energy_budget(self) -> float:
        """Total input energy sum_t ||a_t||^2 allowed over the episode: m sigma_u2 N."""
        return self.m * self.sigma_u2 * self.horizon

    @property
    def layout(self) -> ObservationLayout:
        """The observation layout of this environment."""
        return ObservationLayout.of(self)

    @property
    def obs_dim(self) -> int:
        return self.layout.dim

    def observation_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Finite bounds of the observation (:meth:`ObservationLayout.bounds`)."""
        return self.layout.bounds(x_bound=self.x_bound, u_max=self.u_max, delta=self.delta)

    def gamma(self, N: Any) -> Any:
        """gamma(N) of eq:sic (Theorem thm:sic) for this plant and the attacker's input power."""
        return sic_from_traces(N, self.tr_psi_u, self.tr_psi_w, self.m, self.n, self.sigma_u2, self.sigma_w2, self.sigma_x2)


#: Longest warm-up accepted: the warm-up runs the encrypted controller period by period, and the
#: plant forgets x_0 geometrically fast under it, so more is never needed.
MAX_WARMUP_STEPS = 100_000

#: Most own past inputs in the observation (``input_history``): the observation holds
#: ``input_history * m`` entries, shifted every step, and the compiled kernels are specialised
#: (unrolled) for each length, so that a longer history costs compile time at the first step.
MAX_INPUT_HISTORY = 64

#: Largest encoder scaling factor Delta: the loop's arithmetic holds ``Delta`` and the quantised
#: values ``round(Delta x)`` in float64 and int64, exact only up to 2^53.
MAX_DELTA = 2**53

#: Attack length N when ``max_samples`` is not given and the deciphering budget buys more
#: samples (short keys: ``key_length=64`` buys about 9e18): the episode is truncated there. One
#: copy holds N (n + m) floats of data, about 100 MB at n = m = 4, and every one of the N
#: samples is a key to break when a real breaker is set.
MAX_DEFAULT_HORIZON = 2**20

#: Values taken from the preset, the package's defaults or the configuration, by key
#: (:attr:`AttackParams.sources`).
SOURCE_KEYS = ("A", "B", "sigma_w2", "sigma_x2", "sigma_u2", "upsilon", "tau_c", "gamma_c")


def _choice(name: str, value: Any, options: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in options:
        raise ParameterError(f"unknown {name} {format_value(value)}; choose one of {', '.join(options)}")
    return value


def _breaking(cfg: Mapping[str, Any], crypto: str) -> tuple[str | None, str, float]:
    """The checked ``breaker``, ``deciphering_clock`` and ``breaker_time_limit`` (the breaker's
    feasibility on the loop's group is checked when the backend is built)."""
    from ..cryptanalysis.factoring_registry import FACTORERS
    from ..cryptanalysis.registry import BREAKERS as breakers

    breaker = cfg["breaker"]
    if breaker is not None:  # a discrete-log breaker or a factorer (the scheme refuses the other family)
        breaker = _choice("breaker", breaker, (*breakers, *FACTORERS))
        if crypto != "elgamal":
            raise ParameterError(f"breaker={breaker!r} needs crypto='elgamal': the {crypto} backend has no ciphertexts to break")
    clock = _choice("deciphering_clock", cfg["deciphering_clock"], DECIPHERING_CLOCKS)
    if clock == "measured" and breaker is None:
        raise ParameterError("deciphering_clock='measured' needs a breaker: nothing is broken, so nothing is measured")
    return breaker, clock, parse_duration(cfg["breaker_time_limit"], "breaker_time_limit")


def _breaker_file(cfg: Mapping[str, Any], breaker: str | None) -> str | None:
    """The checked ``breaker_precomputation``: ``None``, or an existing regular file for a breaker
    that loads one (its content is read and checked against the group when the breaker is built)."""
    from ..cryptanalysis.registry import BREAKERS as breakers

    path = cfg["breaker_precomputation"]
    if path is None:
        return None
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"breaker_precomputation must be a file name or None, got {format_value(path)}")
    if breaker is None or "precomputation" not in breakers.options(breaker):
        raise ParameterError(
            f"breaker_precomputation is a file of the index calculus's precomputation; it needs "
            f"breaker='index-calculus', got breaker={breaker!r}"
        )
    return check_regular_file("breaker_precomputation", path)


def completion_preset(config: Mapping[str, Any]) -> Any:
    """The preset whose values complete a plant given by ``A`` and ``B``.

    One rule for the environment and ``encctl-gym train --system``: the configuration's
    ``preset`` when it has that key (``None``: nothing is completed, every design value must be
    given), else the default's (``default_config()["preset"]``, the paper's example).

    Parameters
    ----------
    config : mapping
        The user's configuration (before it is merged over :func:`default_config`).

    Returns
    -------
    str or None
        The preset name, or ``None``; not checked here (:func:`resolve_params` checks it).
    """
    return config["preset"] if "preset" in config else default_config()["preset"]


def _merged_config(config: Mapping[str, Any] | None, kwargs: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(cfg, merged)``: the user's keys over :func:`default_config`, and the user's keys alone."""
    if config is not None and not isinstance(config, Mapping):
        raise ConfigError(f"config must be a mapping of configuration keys to values, got {format_value(config)}")
    cfg = default_config()
    merged = dict(config or {})
    merged.update(kwargs)
    unknown = sorted(set(merged) - set(cfg), key=str)
    if unknown:
        raise ParameterError(f"unknown configuration key(s) {format_value(unknown)}; known keys: {sorted(cfg)}")
    cfg.update(merged)
    return cfg, merged


def resolve_plant(cfg: dict[str, Any], merged: Mapping[str, Any]) -> tuple[Any, dict[str, Any], dict[str, Any]]:
    """The plant room: ``(preset, values, sources)``, ``values`` holding the checked ``A``, ``B``
    (eq:system, Schur stable) and the raw design values of :data:`SOURCE_KEYS` (from the
    configuration, else the preset, else the default; all missing ones named at once)."""
    name = cfg["preset"] = completion_preset(merged)
    if name is not None and not isinstance(name, str):
        raise ParameterError(f"preset must be a preset name or None, got {format_value(name)}")
    preset = get_preset(name) if name is not None else None
    if preset is None and (cfg["A"] is None or cfg["B"] is None):
        raise ParameterError("without a preset, both A and B must be given")
    sources: dict[str, str] = {}
    missing: list[str] = []

    def pick(key: str, default: Any = None) -> Any:
        if cfg[key] is not None:
            sources[key] = "config"
            return cfg[key]
        if preset is not None:
            sources[key] = f"preset {preset.name}"
            return getattr(preset, key)
        if default is not None:
            sources[key] = "default"
            return default
        missing.append(key)
        return None

    A, B = check_system(pick("A"), pick("B"))
    check_schur_stable(A)
    raw = {key: pick(key, 1.0 if key == "sigma_x2" else None) for key in SOURCE_KEYS[2:]}
    if missing:
        raise ParameterError(f"without a preset these values must be given too: {', '.join(missing)}")
    inherited = [k for k in SOURCE_KEYS if sources.get(k, "").startswith("preset")]
    if preset is not None and {"A", "B"} & set(merged) and inherited:
        warn_user(
            f"A/B are given and the other values come from preset {preset.name!r}: {', '.join(inherited)}; "
            "pass preset=None to give them all yourself"
        )
    return preset, {"A": A, "B": B, **raw}, sources


def resolve_threat(values: Mapping[str, Any], cfg: Mapping[str, Any]) -> dict[str, Any]:
    """The threat room (Definition def:security): the checked variances, ``upsilon``, ``tau_c``,
    ``gamma_c`` and the adversary."""
    return {
        "sigma_w2": check_positive("sigma_w2", values["sigma_w2"]),
        "sigma_x2": check_nonnegative("sigma_x2", values["sigma_x2"]),
        "sigma_u2": check_positive("sigma_u2", values["sigma_u2"]),
        "upsilon": check_positive("upsilon", values["upsilon"]),
        "tau_c": parse_duration(values["tau_c"], "tau_c"),
        "gamma_c": check_positive("gamma_c", values["gamma_c"]),
        "adversary": _choice("adversary", cfg["adversary"], ADVERSARIES),
    }


def _cost_models(cfg: Mapping[str, Any], encryption: Any) -> tuple[str, CostModel, Any]:
    """``(name, model, baseline)``: the scheme's deciphering-cost model the configuration names
    and the scheme's baseline model (eq:opt_key: lambda <-> key length), with the GNFS correction
    where the model takes one."""
    registry = encryption.cost_models
    given = cfg["deciphering_model"]
    model_name = _choice("deciphering_model", encryption.baseline_model if given is None else given, tuple(registry))
    correction = cfg["gnfs_correction"]
    if correction == "guillevic":
        correction = GUILLEVIC_CORRECTION
    correction = check_gnfs_correction(correction)

    def build(name: str) -> Any:
        return registry.build(name, **({"gnfs_correction": correction} if "gnfs_correction" in registry.options(name) else {}))

    return model_name, build(model_name), build(encryption.baseline_model)


def resolve_key(
    cfg: Mapping[str, Any], encryption: Any, traces: tuple[float, float], threat: Mapping[str, Any], n: int, m: int
) -> dict[str, Any]:
    """The key room (eq:opt_key, Theorem thm:opt_sec): the cost model, lambda, the key length and
    what breaking one key costs, under the scheme's own cost models."""
    lam_cfg, k_cfg = cfg["security_parameter"], cfg["key_length"]
    if lam_cfg is not None and k_cfg is not None:
        raise ParameterError("give either security_parameter or key_length, not both")
    model_name, model, baseline = _cost_models(cfg, encryption)
    if k_cfg is not None:
        key_length = check_int("key_length", k_cfg, minimum=GENERIC_MIN_KEY_LENGTH)
        cost = model.break_cost(key_length)
        lam = cost.security_parameter
        if model_name != encryption.baseline_model or lam is None:
            lam = baseline.security_parameter_of_key_length(key_length)
    else:
        if lam_cfg is not None:
            lam = check_security_parameter(lam_cfg)
        else:
            t = threat
            design = design_from_traces(
                *traces, m, n, sigma_u2=t["sigma_u2"], sigma_w2=t["sigma_w2"], sigma_x2=t["sigma_x2"], gamma_c=t["gamma_c"],
                tau_c=t["tau_c"], upsilon=t["upsilon"],
            )  # fmt: skip
            lam = design.lam_star  # Theorem thm:opt_sec
        key_length = baseline.key_length_for_security_parameter(lam)  # eq:opt_key
        cost = (
            baseline.cost_of_security_parameter(lam) if model_name == encryption.baseline_model else model.break_cost(key_length)
        )
    return {
        "deciphering_model": model_name,
        "cost_model": model,
        "security_parameter": lam,
        "key_length": key_length,
        "cost": cost,
    }


def resolve_budget(
    cfg: Mapping[str, Any], encryption: Any, key: Mapping[str, Any], threat: Mapping[str, Any], clock: str, n: int, m: int
) -> dict[str, Any]:
    """The budget room (Definition def:sdt): the samples ``tau_c`` buys (every group charged with
    ``rotate_group_every``), the attack length N and whether the budget or ``max_samples`` sets it."""
    tau_c, upsilon, adversary, cost = threat["tau_c"], threat["upsilon"], threat["adversary"], key["cost"]
    rotate_every = cfg["rotate_group_every"]
    if rotate_every is not None:  # every group's keys are charged (security.rotation)
        rotate_every = check_rotation_period(rotate_every)
        budget: int | float = rotated_affordable_samples(
            tau_c, cost, upsilon, rotate_every, scheme=encryption, adversary=adversary
        )
    else:
        budget = max_affordable_samples(tau_c, cost, upsilon, scheme=encryption, adversary=adversary)
    max_samples = cfg["max_samples"]
    if max_samples is not None:
        max_samples = check_int("max_samples", max_samples, minimum=1)
    if clock == "measured":
        if max_samples is None:
            raise ParameterError(
                "with deciphering_clock='measured' the number of samples tau_c buys is known only as the "
                "keys are broken: set max_samples (the episode terminates earlier if the measured time passes tau_c)"
            )
        budget = math.inf  # the measured clock, not the model, ends the episode within tau_c
    if budget == math.inf and max_samples is None:  # budget may be an int beyond float range
        raise ParameterError(
            f"with scheme={encryption.name!r} and adversary={adversary!r} one break reveals every sample, so the "
            "deciphering budget does not bound the attack: set max_samples"
        )
    if max_samples is not None and max_samples < budget:
        horizon, budget_limited = max_samples, False
    elif max_samples is None and budget > MAX_DEFAULT_HORIZON:
        horizon, budget_limited = MAX_DEFAULT_HORIZON, False  # the environment warns (AttackParams.warn_if_capped)
    else:
        horizon, budget_limited = int(budget), True
    if horizon < n + m + 1:
        raise BudgetError(
            f"the attack can collect only N = {horizon} samples (budget {budget} within tau_c = {tau_c:g} s at "
            f"lambda = {format_value(key['security_parameter'])}, k = {key['key_length']} bits, {key['deciphering_model']} "
            f"model, Upsilon = {upsilon:g}; max_samples = {max_samples}); identification needs N >= n + m + 1 = {n + m + 1}"
        )
    return {
        "budget_samples": budget,
        "horizon": horizon,
        "budget_limited": budget_limited,
        "horizon_capped": max_samples is None and horizon < budget,
        "rotate_group_every": rotate_every,
        "sample_cost": per_sample_cost(cost, upsilon),
        "next_sample_cost": float(cost.next / decimal_fraction("upsilon", upsilon)),
        "independent_keys": independent_keys(encryption, adversary),
    }


def resolve_episode(cfg: Mapping[str, Any], A: np.ndarray, B: np.ndarray) -> dict[str, Any]:
    """The episode room: the deciphering delay, warm-up, observation history, estimator and reward."""
    delay = cfg["decipher_delay"]
    if isinstance(delay, str):
        if delay != "end":
            raise ParameterError(f"decipher_delay must be a non-negative integer or 'end', got {format_value(delay)}")
        delay_v: int | None = None
    else:
        delay_v = check_int("decipher_delay", delay, minimum=0)
    warmup = check_int("warmup_steps", cfg["warmup_steps"], minimum=0)
    if warmup > MAX_WARMUP_STEPS:
        raise ParameterError(f"warmup_steps must be <= {MAX_WARMUP_STEPS} (MAX_WARMUP_STEPS), got {format_value(warmup)}")
    input_history = check_int("input_history", cfg["input_history"], minimum=0)
    if input_history > MAX_INPUT_HISTORY:
        raise ParameterError(
            f"input_history must be <= {MAX_INPUT_HISTORY} (MAX_INPUT_HISTORY), got {format_value(input_history)}"
        )
    return {
        "decipher_delay": delay_v,
        "warmup_steps": warmup,
        "input_history": input_history,
        "logdet_regularization": check_positive("logdet_regularization", cfg["logdet_regularization"]),
        "gamma_opt": check_bool("gamma_opt", cfg["gamma_opt"]),
    }


def resolve_loop(cfg: Mapping[str, Any], encryption: Any, sigma_u2: float, adversary: str) -> dict[str, Any]:
    """The loop room (Definition def:ec, def:adversary): backend, breaker and clock, Delta, the
    encoder's bounds, the seed, the defender and its levers, and the injection mode with what the
    scheme needs for it."""
    crypto = _choice("crypto backend", cfg["crypto"], BACKENDS)
    breaker, clock, breaker_limit = _breaking(cfg, crypto)
    delta = check_int("delta", cfg["delta"], minimum=2)
    if delta > MAX_DELTA:
        raise ParameterError(f"delta must be <= 2^53 (MAX_DELTA: exact in float64), got {format_value(delta)}")
    action_scale = check_positive("action_scale", cfg["action_scale"])
    u_max = action_scale * math.sqrt(sigma_u2)
    if not math.isfinite(u_max):
        raise ParameterError(
            f"action_scale * sqrt(sigma_u2) (the actuator bound u_max) must be finite, got action_scale = "
            f"{format_value(action_scale)} and sigma_u2 = {format_value(sigma_u2)}"
        )
    crypto_seed = cfg["crypto_seed"]
    if crypto_seed is not None:
        crypto_seed = check_int("crypto_seed", crypto_seed, minimum=0)
    make_defender(cfg["defender"])  # an unknown name or an object that is no policy fails here
    audit_p, noise_d2 = cfg["audit_probability"], cfg["defense_noise_sigma2"]
    return {
        "crypto": crypto,
        "breaker": breaker,
        "deciphering_clock": clock,
        "breaker_time_limit": breaker_limit,
        "breaker_precomputation": _breaker_file(cfg, breaker),
        "delta": delta,
        "x_bound": check_positive("x_bound", cfg["x_bound"]),
        "u_max": u_max,
        "crypto_seed": crypto_seed,
        "defender": cfg["defender"],
        "audit_probability": None if audit_p is None else check_probability("audit_probability", audit_p),
        "defense_noise_sigma2": None if noise_d2 is None else check_nonnegative("defense_noise_sigma2", noise_d2),
        "injection": _injection(cfg, encryption, adversary),
    }


def _injection(cfg: Mapping[str, Any], encryption: Any, adversary: str) -> str:
    """The checked ``injection``: a mode of :data:`~encctl_gym.loop.injection.INJECTIONS` the scheme
    can realise with the configured deciphering delay."""
    mode = check_injection(cfg["injection"])
    if mode != "replace" and cfg["observe"] == "output":
        raise ParameterError(
            f"injection={mode!r} with observe='output' is not built: the output episode runs the forgery "
            "(injection='replace') only"
        )
    if mode == "scale" and not isinstance(encryption, MalleableScheme):
        raise ParameterError(
            f"injection='scale' needs a scheme with a scale() (the ElGamal schemes); the {encryption.name} scheme has none"
        )
    needs = encryption.injection_needs(mode, adversary)
    if needs.period_key and cfg["decipher_delay"] != 0:
        raise ParameterError(
            f"injection={mode!r} on the {encryption.name} scheme reads the period's products with the period's key, "
            f"so it needs decipher_delay=0, got decipher_delay={format_value(cfg['decipher_delay'])}"
        )
    return mode


def resolve_params(config: Mapping[str, Any] | None = None, **kwargs: Any) -> AttackParams:
    """Merge ``config`` and ``kwargs`` over :func:`default_config` and validate everything.

    One resolver per room, each owning its keys and checking each once: the plant
    (:func:`resolve_plant`), the threat (:func:`resolve_threat`), the key (:func:`resolve_key`,
    under the scheme's own cost models), the budget (:func:`resolve_budget`), the episode
    (:func:`resolve_episode`), the loop (:func:`resolve_loop`) and the outputs
    (:func:`~encctl_gym.envs.output_episode.resolve_output`).

    A plant given by ``A`` and ``B`` is completed from a preset (:func:`completion_preset`: the
    configuration's ``preset``, else the default ``"paper-example"``): the variances and design
    values it does not give come from that preset, and a warning names them. With
    ``preset=None`` nothing is completed: every variance and design value must then be given
    (all missing ones are named at once). :attr:`AttackParams.sources` records where each value
    came from.

    Raises
    ------
    ParameterError
        Unknown keys, schemes, backends, rewards or presets; non-positive Upsilon, tau_c or
        variances; an unstable A (UnstableSystemError); mismatched shapes (ShapeError); a flag
        that is not a bool; missing values without a preset.
    ConfigError
        A configuration that is not a mapping.
    BudgetError
        A budget too small to identify anything (fewer than n + m + 1 samples).
    """
    cfg, merged = _merged_config(config, kwargs)
    preset, values, sources = resolve_plant(cfg, merged)
    A, B = values["A"], values["B"]
    n, m = A.shape[0], B.shape[1]
    threat = resolve_threat(values, cfg)
    encryption = make_scheme(cfg["scheme"])  # the scheme seam: its keys, costs and what the adversary must break
    reward = _choice("reward", cfg["reward"], REWARDS)
    estimator = cfg["estimator"]
    make_estimator(estimator).check_dimensions(n, m)  # an unknown or impossible estimator fails here
    loop = resolve_loop(cfg, encryption, threat["sigma_u2"], threat["adversary"])
    traces = (float(np.trace(controllability_gramian(A, B))), float(np.trace(noise_gramian(A))))
    key = resolve_key(cfg, encryption, traces, threat, n, m)
    budget = resolve_budget(cfg, encryption, key, threat, loop["deciphering_clock"], n, m)
    episode = resolve_episode(cfg, A, B)
    from .output_episode import resolve_output

    output = resolve_output(cfg, preset, A, B, estimator=estimator, reward=reward, defender=cfg["defender"])
    return AttackParams(
        A=A,
        B=B,
        scheme=cfg["scheme"],
        estimator=estimator,
        reward=reward,
        tr_psi_u=traces[0],
        tr_psi_w=traces[1],
        sources=sources,
        **threat,
        **key,
        **budget,
        **episode,
        **loop,
        **output,
    )
