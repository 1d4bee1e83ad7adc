"""Deciphering-cost models by name: :data:`DECIPHERING_MODELS` and :func:`deciphering_model`."""

from __future__ import annotations

from typing import Any

from ...errors import ParameterError
from ...registry import Registry
from .base import CostModel
from .models import GenericModel, PaperModel, PrecomputationModel

__all__ = ["DECIPHERING_MODELS", "deciphering_model"]


#: Registry: model name -> class (:class:`~encctl_gym.registry.Registry`); a model's options are
#: the parameters of its constructor.
DECIPHERING_MODELS: Registry[type[CostModel]] = Registry("deciphering model", [PaperModel, PrecomputationModel, GenericModel])


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
    model: CostModel = DECIPHERING_MODELS.build(name, **options)
    return model
