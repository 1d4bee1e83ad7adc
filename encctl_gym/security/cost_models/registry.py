"""Deciphering-cost models by name: :data:`DECIPHERING_MODELS` and :func:`deciphering_model`."""

from __future__ import annotations

from typing import Any

from ..._validation import format_value
from ...errors import ParameterError
from .base import CostModel
from .models import GenericModel, PaperModel, PrecomputationModel

__all__ = ["DECIPHERING_MODELS", "deciphering_model"]


#: Registry: model name -> class.
DECIPHERING_MODELS: dict[str, type[CostModel]] = {
    "paper": PaperModel,
    "precomputation": PrecomputationModel,
    "generic": GenericModel,
}

_OPTIONS: dict[str, tuple[str, ...]] = {
    "paper": ("gnfs_correction",),
    "precomputation": ("gnfs_correction", "calibration"),
    "generic": (),
}


def deciphering_model(name: Any = "paper", **options: Any) -> CostModel:
    """Build a cost model by name (:data:`DECIPHERING_MODELS`).

    Parameters
    ----------
    name : {"paper", "precomputation", "generic"}, default "paper"
        Or an already built model (returned as it is when no options are given).
    **options
        ``gnfs_correction`` (paper, precomputation), ``calibration`` (precomputation).

    Raises
    ------
    ParameterError
        For an unknown name or an option the model does not take.
    """
    if isinstance(name, CostModel):
        if options:
            raise ParameterError(f"options {sorted(options)} cannot be applied to an already built {name.name} model")
        return name
    if not isinstance(name, str) or name not in DECIPHERING_MODELS:
        raise ParameterError(f"unknown deciphering model {format_value(name)}; choose one of {', '.join(DECIPHERING_MODELS)}")
    bad = sorted(set(options) - set(_OPTIONS[name]))
    if bad:
        allowed = ", ".join(_OPTIONS[name]) or "none"
        raise ParameterError(f"the {name} model takes no option(s) {bad} (its options: {allowed})")
    return DECIPHERING_MODELS[name](**options)
