"""The threat model of a design as one value object, checked once (:class:`ThreatModel`).

Definition def:security fixes what the defender fears and tolerates: the adversary's attack
input variance ``sigma_u2``, the plant's noise and initial-state variances ``sigma_w2`` and
``sigma_x2`` (they decide how fast it identifies the plant, Theorem thm:sic), the acceptable
error ``gamma_c``, the defense period ``tau_c`` (s), the adversary's computing power
``Upsilon`` (FLOPS), who it is (``eavesdropper`` or malicious ``server``, Figure fig:adversary)
and what breaking a key costs it (a deciphering-cost model, :mod:`.cost_models`).

The design functions (:func:`~.design.design_security_parameter`,
:func:`~.design.design_from_traces`, :func:`~.design.design_for_sample_size`,
:func:`~.key_length.design_key_length`, :func:`~.key_length.key_length_value`) take one
:class:`ThreatModel` instead of these values one by one. Numbers are kept as given (an int, a
float or a Fraction): the design reads ``tau_c`` and ``Upsilon`` exactly by the decimal rule
(:func:`~.exact.decimal_fraction`), so ``442e15`` stays 442 * 10^15.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from .._validation import check_nonnegative, check_positive, format_value
from ..errors import ParameterError
from .cost_models import DECIPHERING_MODELS, CostModel, deciphering_model
from .deciphering import ADVERSARIES
from .exact import decimal_fraction

__all__ = ["ThreatModel"]

#: The fields a design of the sample size needs (the key-length designs need only the others).
IDENTIFICATION_FIELDS = ("sigma_u2", "sigma_w2", "gamma_c")


@dataclass(frozen=True, kw_only=True)
class ThreatModel:
    """What the adversary can do and what the defender tolerates (Definition def:security).

    Parameters
    ----------
    tau_c : float
        Defense period in seconds (> 0).
    upsilon : float
        The adversary's computing power in FLOPS (> 0).
    sigma_u2 : float, optional
        Variance of the adversary's i.i.d. attack inputs (> 0).
    sigma_w2 : float, optional
        Variance of the process noise (> 0).
    sigma_x2 : float, default 1.0
        Variance of the initial state (>= 0; used by the exact eq:sic).
    gamma_c : float, optional
        Acceptable estimation error (> 0).
    adversary : {"eavesdropper", "server"}, default "eavesdropper"
        Adversary type of Figure fig:adversary.
    cost_model : str or CostModel, default "paper"
        The deciphering-cost model: a name of
        :data:`~encctl_gym.security.cost_models.DECIPHERING_MODELS` (with its default options)
        or a built model (with its own GNFS correction and calibration).

    Raises
    ------
    ParameterError
        Naming the first bad value.

    Notes
    -----
    ``sigma_u2``, ``sigma_w2`` and ``gamma_c`` are optional because a key-length design for a
    given ``N*`` does not use them; a design of the sample size refuses a threat model without
    them (:meth:`require`).

    Examples
    --------
    >>> t = ThreatModel(sigma_u2=10, sigma_w2=0.1, gamma_c=1e-6, tau_c=31536e4, upsilon=442e15)
    >>> t.r_sigma
    100.0
    """

    tau_c: Any
    upsilon: Any
    sigma_u2: Any = None
    sigma_w2: Any = None
    sigma_x2: Any = 1.0
    gamma_c: Any = None
    adversary: str = "eavesdropper"
    cost_model: str | CostModel = "paper"

    def __post_init__(self) -> None:
        decimal_fraction("tau_c", self.tau_c)
        decimal_fraction("upsilon", self.upsilon)
        for name in ("sigma_u2", "sigma_w2"):
            value = getattr(self, name)
            if value is not None:
                decimal_fraction(name, value)
                check_positive(name, value)  # within the float64 range too
        decimal_fraction("sigma_x2", self.sigma_x2, positive=False)
        check_nonnegative("sigma_x2", self.sigma_x2)
        if self.gamma_c is not None:
            check_positive("gamma_c", self.gamma_c)
        if not isinstance(self.adversary, str) or self.adversary not in ADVERSARIES:
            raise ParameterError(f"unknown adversary {format_value(self.adversary)}; expected one of {', '.join(ADVERSARIES)}")
        if not isinstance(self.cost_model, CostModel):
            DECIPHERING_MODELS.lookup(self.cost_model)

    # -- derived values
    @property
    def r_sigma(self) -> float:
        """``R_sigma = sigma_u2 / sigma_w2`` of eq:sic2."""
        self.require("sigma_u2", "sigma_w2")
        return float(self.sigma_u2) / float(self.sigma_w2)

    @property
    def model(self) -> CostModel:
        """The deciphering-cost model (built from its name with default options)."""
        return self.cost_model if isinstance(self.cost_model, CostModel) else deciphering_model(self.cost_model)

    def require(self, *names: str) -> ThreatModel:
        """Return the threat model after checking that the fields ``names`` are given.

        Raises
        ------
        ParameterError
            Naming the missing fields.
        """
        missing = [name for name in names if getattr(self, name) is None]
        if missing:
            raise ParameterError(f"this design needs {', '.join(missing)} in the threat model, which has none")
        return self

    @classmethod
    def of(cls, preset: Any, cost_model: Any = "paper") -> ThreatModel:
        """The variances and design parameters of a preset (:class:`~encctl_gym.presets.SystemPreset`:
        ``sigma_u2``, ``sigma_w2``, ``sigma_x2``, ``gamma_c``, ``tau_c``, ``upsilon``) under ``cost_model``."""
        return cls(
            sigma_u2=preset.sigma_u2,
            sigma_w2=preset.sigma_w2,
            sigma_x2=preset.sigma_x2,
            gamma_c=preset.gamma_c,
            tau_c=preset.tau_c,
            upsilon=preset.upsilon,
            cost_model=cost_model,
        )

    def replace(self, **changes: Any) -> ThreatModel:
        """A copy with some fields changed (checked again)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """The fields as a JSON-ready dict (a built cost model by its name)."""
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out["cost_model"] = self.model.name
        return out

    @classmethod
    def from_fields(cls, threat: ThreatModel | None, fields: dict[str, Any], where: str) -> ThreatModel:
        """``threat``, or a threat model built from the keyword ``fields`` of a caller that has
        none (``where`` names the function in the message when both or neither are given)."""
        if threat is not None:
            if fields:
                raise ParameterError(f"{where} takes a threat model or its fields, not both (got {', '.join(sorted(fields))})")
            if not isinstance(threat, ThreatModel):
                raise ParameterError(f"{where}: threat must be a ThreatModel, got {format_value(threat)}")
            return threat
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(fields) - names)
        if unknown:
            raise ParameterError(
                f"{where} got unknown argument(s) {', '.join(unknown)}; a threat model has {', '.join(sorted(names))}"
            )
        missing = [name for name in ("tau_c", "upsilon") if name not in fields]
        if missing:
            raise ParameterError(f"{where} needs a threat model or its fields; missing {', '.join(missing)}")
        return cls(**fields)
