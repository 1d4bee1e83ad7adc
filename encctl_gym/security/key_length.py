"""eq:opt_key generalised: the smallest safe key length under each deciphering-cost model.

Definition def:security asks that no sample size ``N >= N*`` be affordable within ``tau_c``:
with ``keys`` the keys to break for ``N*`` samples (:func:`~encctl_gym.security.deciphering.keys_to_break`)
and ``W_k(keys)`` their cost in operations at key length ``k`` under a model
(:mod:`~encctl_gym.security.cost_models`), the design is the smallest ``k*`` with

    W_k*(keys) > Upsilon tau_c.

``W`` grows with ``N``, so nothing beyond ``N*`` is affordable either. Under the ``paper`` model this
is done as in the paper, in two steps: the integer ``lam*`` of Theorem thm:opt_sec, then eq:opt_key
(``log2 Omega(k*) - c >= lam*``), so its ``k*`` is the paper's exactly (712 bits for the design
example); rounding ``lam`` up to an integer can cost the paper model up to one bit of work, the
other models compare the work directly. ``N*`` comes from any complexity
(:mod:`~encctl_gym.security.sample_size`: eq:sic2, eq:sic, or the robust ``gamma_opt`` of
:mod:`~encctl_gym.security.attack_design`).

:func:`design_key_length` gives one :class:`KeyLengthDesign` (with the paper's ``k*`` for the same
``N*`` beside it and the NIST SP 800-57 key length for the same strength);
:func:`key_length_value` says what a given key is worth under a model: the cost of the first and
of each further key, the samples affordable within ``tau_c``, and how many bits of work the
dynamic keys add for ``N*`` samples (``log2 W(N*) - log2 W(1)``: ``log2 N*`` when every key
costs the same, almost nothing when a precomputation dominates).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from fractions import Fraction
from typing import Any

from .._validation import check_int, format_value
from ..errors import ParameterError
from .cost_models import DECIPHERING_MODELS, CostModel, PaperModel, deciphering_model, paper_security_parameter
from .deciphering import keys_to_break, max_affordable_samples
from .exact import decimal_fraction, log2_fraction
from .records import nist_key_length, nist_strength
from .threat import ThreatModel

__all__ = ["KeyLengthDesign", "KeyValue", "design_key_length", "key_length_value", "defense_budget", "build_model"]


def defense_budget(tau_c: Any, upsilon: Any) -> Fraction:
    """``Upsilon tau_c``: the operations the adversary can perform within the defense period, exactly.

    Both are read by the decimal rule (``442e15`` is 442 * 10^15).
    """
    return decimal_fraction("upsilon", upsilon) * decimal_fraction("tau_c", tau_c)


@dataclass(frozen=True)
class KeyLengthDesign:
    """The smallest safe key length under one cost model.

    Attributes
    ----------
    model : str
        Cost model name.
    N_star : int
        Minimum sample size the design protects.
    keys : int
        Keys the adversary must break for ``N*`` samples.
    k_star : int
        Smallest key length with ``W(keys) > Upsilon tau_c`` (paper: via ``lam*``).
    lam_star : int or None
        ``lam*`` of Theorem thm:opt_sec (paper model only).
    budget_bits : float
        ``log2(Upsilon tau_c)``.
    work_bits : float
        ``log2 W(keys)`` at ``k*``: the bits of work the adversary needs for ``N*`` samples.
    first_key_bits, next_key_bits : float
        ``log2`` of the first key's and of a further key's cost at ``k*``.
    dynamic_key_bits : float
        ``work_bits - first_key_bits``: what the per-period keys add.
    paper_k_star : int
        The paper model's ``k*`` (no correction) for the same ``N*``.
    nist_key_length : int or None
        NIST SP 800-57 key length for a strength of ``first_key_bits`` (``None`` above 256 bits).
    gnfs_correction : float
        Correction of the GNFS formula used (bits; 0 for the generic model).
    scheme, adversary : str
    """

    model: str
    N_star: int
    keys: int
    k_star: int
    lam_star: int | None
    budget_bits: float
    work_bits: float
    first_key_bits: float
    next_key_bits: float
    dynamic_key_bits: float
    paper_k_star: int
    nist_key_length: int | None
    gnfs_correction: float
    scheme: str
    adversary: str

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return asdict(self)


@dataclass(frozen=True)
class KeyValue:
    """What a ``key_length``-bit key is worth under one cost model.

    Attributes
    ----------
    model : str
    key_length : int
    first_key_bits, next_key_bits : float
        ``log2`` of the cost of the first and of each further key.
    affordable_samples : int or float
        Largest ``N`` with ``tau(N) <= tau_c`` (``inf`` if one break reveals every sample).
    log2_affordable_samples : float
        ``log2`` of it (``-inf`` for 0, ``inf`` for ``inf``).
    work_bits : float
        ``log2 W(N*)``: work for ``N*`` samples.
    dynamic_key_bits : float
        ``log2 W(N*) - log2 W(1)``.
    secure : bool
        Whether fewer than ``N*`` samples are affordable (Definition def:security).
    nist_strength : int or None
        NIST SP 800-57 strength of the key length (``None`` below 1024 bits).
    """

    model: str
    key_length: int
    first_key_bits: float
    next_key_bits: float
    affordable_samples: int | float
    log2_affordable_samples: float
    work_bits: float
    dynamic_key_bits: float
    secure: bool
    nist_strength: int | None

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (``affordable_samples`` as a float when beyond 2^53)."""
        d = asdict(self)
        a = self.affordable_samples
        d["affordable_samples"] = a if isinstance(a, float) or a < 2**53 else float(a) if a < 2**1023 else math.inf
        return d


def build_model(model: Any, gnfs_correction: Any = 0.0, calibration: Any = None, *, registry: Any = None) -> CostModel:
    """A cost model by name with the options that apply to it: the GNFS correction and the
    calibration go to the models whose constructors take them (the paper and precomputation
    models; the calibration only when given), so no model is named here. A built model is
    returned as it is. ``registry``: the scheme's own models (its ``cost_models``; default the
    discrete-log ones, :data:`DECIPHERING_MODELS`)."""
    if isinstance(model, CostModel):
        return model
    if registry is not None and registry is not DECIPHERING_MODELS:
        takes = registry.options(model)
        options_of = {k: v for k, v in (("gnfs_correction", gnfs_correction), ("calibration", calibration)) if k in takes}
        return registry.build(model, **{k: v for k, v in options_of.items() if v is not None})
    takes = DECIPHERING_MODELS.options(model)
    options: dict[str, Any] = {}
    if "gnfs_correction" in takes:
        options["gnfs_correction"] = gnfs_correction
    if "calibration" in takes and calibration is not None:
        options["calibration"] = calibration
    return deciphering_model(model, **options)


def _threat(threat: Any, where: str) -> ThreatModel:
    if not isinstance(threat, ThreatModel):
        raise ParameterError(f"{where}: threat must be a ThreatModel, got {format_value(threat)}")
    return threat


def design_key_length(N_star: int, threat: ThreatModel, *, scheme: str = "modified") -> KeyLengthDesign:
    """The smallest key length ``k*`` such that no ``N >= N*`` fits in ``tau_c`` under the threat's
    cost model.

    Parameters
    ----------
    N_star : int
        Minimum sample size (>= 1), e.g. ``SecurityDesign.N_star``.
    threat : ThreatModel
        ``tau_c``, ``upsilon``, the adversary and the cost model (a built model carries its own
        GNFS correction and calibration: :func:`build_model`).
    scheme : {"modified", "token", "static"}, default "modified"
        Key handling (:func:`~encctl_gym.security.deciphering.keys_to_break`).

    Returns
    -------
    KeyLengthDesign

    Raises
    ------
    ModelRangeError
        If the answer lies outside the model's key-length range.
    """
    t = _threat(threat, "design_key_length")
    m, adversary = t.model, t.adversary
    N_star = check_int("N_star", N_star, 1)
    keys = keys_to_break(N_star, scheme, adversary)
    budget = defense_budget(t.tau_c, t.upsilon)
    k_star = m.minimum_key_length(keys, budget)
    cost = m.break_cost(k_star)
    work = log2_fraction(cost.operations(keys))
    lam_star = paper_security_parameter(keys, budget) if isinstance(m, PaperModel) else None
    return KeyLengthDesign(
        model=m.name,
        N_star=N_star,
        keys=keys,
        k_star=k_star,
        lam_star=lam_star,
        budget_bits=log2_fraction(budget),
        work_bits=work,
        first_key_bits=cost.first_bits,
        next_key_bits=cost.next_bits,
        dynamic_key_bits=work - cost.first_bits,
        paper_k_star=PaperModel().minimum_key_length(keys, budget),
        nist_key_length=nist_key_length(cost.first_bits),
        gnfs_correction=float(getattr(m, "gnfs_correction", 0.0)),
        scheme=scheme,
        adversary=adversary,
    )


def key_length_value(key_length: int, threat: ThreatModel, *, N_star: int, scheme: str = "modified") -> KeyValue:
    """What a ``key_length``-bit key is worth under the threat's cost model against an adversary
    needing ``N*`` samples.

    Parameters
    ----------
    key_length : int
        Bits of p.
    threat : ThreatModel
        As in :func:`design_key_length`.
    N_star : int
        Samples the adversary needs (>= 1).
    scheme : str
        As in :func:`design_key_length`.

    Returns
    -------
    KeyValue
    """
    t = _threat(threat, "key_length_value")
    m, adversary = t.model, t.adversary
    N_star = check_int("N_star", N_star, 1)
    cost = m.break_cost(check_int("key_length", key_length))
    n_max = max_affordable_samples(t.tau_c, cost, t.upsilon, scheme=scheme, adversary=adversary)
    work = log2_fraction(cost.operations(keys_to_break(N_star, scheme, adversary)))
    if n_max == math.inf:
        log_n = math.inf
    elif n_max == 0:
        log_n = -math.inf
    else:
        log_n = log2_fraction(Fraction(int(n_max)))
    return KeyValue(
        model=m.name,
        key_length=int(key_length),
        first_key_bits=cost.first_bits,
        next_key_bits=cost.next_bits,
        affordable_samples=n_max,
        log2_affordable_samples=log_n,
        work_bits=work,
        dynamic_key_bits=work - cost.first_bits,
        secure=bool(n_max < N_star),
        nist_strength=nist_strength(int(key_length)),
    )
