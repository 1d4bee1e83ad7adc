"""Estimators by name: one dict, so a new estimator is one row.

::

    make_estimator("bayes")                        # the registry's defaults
    make_estimator("forgetting", forgetting_factor=0.99)
    make_estimator({"name": "iv", "lags": 2})      # the form a configuration file holds

=============  ==============================================  =================================
name           estimator                                       parameters (defaults)
=============  ==============================================  =================================
``ls``         ordinary least squares, eq:estimate             ``method`` ("auto")
``bayes``      Bayesian least squares (ridge posterior mean)   ``prior_mean`` (0),
                                                               ``prior_variance`` and
                                                               ``noise_variance`` (None: the
                                                               scale by empirical Bayes)
``forgetting`` least squares with exponential forgetting       ``forgetting_factor`` (0.999)
``iv``         instrumental variables, lagged inputs           ``lags`` (ceil(n / m))
``n4sid``      N4SID (subspace), on states ``y = x``, the      ``block_rows`` (max(2, 2 n))
               estimate in the plant's basis; on outputs too
``moesp``      PO-MOESP (subspace), as ``n4sid``               ``block_rows`` (max(2, 2 n))
=============  ==============================================  =================================

The subspace methods (:mod:`~encctl_gym.ident.output_estimators`) are there for the plant measured
through outputs (``observe="output"``); on states they are a slower, less efficient route to the
same ``[A B]`` (see ``docs/ident.md``). Total least squares is not in the registry.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..errors import ParameterError
from ..registry import Registry
from .bayes import BayesianLeastSquares
from .estimator import Estimator, MomentEstimator
from .forgetting import ForgettingLeastSquares
from .instrumental import InstrumentalVariables
from .ordinary import OrdinaryLeastSquares
from .output_estimators import MOESPEstimator, N4SIDEstimator

__all__ = ["ESTIMATORS", "DEFAULT_ESTIMATOR", "estimator_names", "make_estimator", "estimator_spec"]

#: name -> class (:class:`~encctl_gym.registry.Registry`); each class validates its own parameters.
ESTIMATORS: Registry[type[MomentEstimator] | type[N4SIDEstimator] | type[MOESPEstimator]] = Registry(
    "estimator",
    [OrdinaryLeastSquares, BayesianLeastSquares, ForgettingLeastSquares, InstrumentalVariables, N4SIDEstimator, MOESPEstimator],
)

#: The paper's estimator (eq:estimate).
DEFAULT_ESTIMATOR = "ls"


def estimator_names() -> list[str]:
    """The registered names."""
    return ESTIMATORS.names()


def make_estimator(spec: Any = None, **params: Any) -> Estimator:
    """An estimator from a name, a ``{"name": ..., **params}`` mapping, or an estimator.

    Parameters
    ----------
    spec : str, mapping, Estimator or None
        ``None`` is the default (``"ls"``); an :class:`~encctl_gym.ident.estimator.Estimator`
        instance is returned as it is (then ``params`` must be empty).
    **params
        The estimator's parameters (see the table in the module docstring).

    Returns
    -------
    Estimator
        A new instance (except when ``spec`` already is one).

    Raises
    ------
    ParameterError
        For an unknown name, unknown parameters or parameter values the estimator refuses
        (each message names the value).
    """
    if spec is None:
        spec = DEFAULT_ESTIMATOR
    if isinstance(spec, Mapping):
        merged = dict(spec)
        if "name" not in merged:
            raise ParameterError(f"an estimator mapping needs a 'name' key, got {dict(spec)!r}")
        spec = merged.pop("name")
        overlap = sorted(set(merged) & set(params))
        if overlap:
            raise ParameterError(f"estimator parameter(s) {overlap} given twice")
        params = {**merged, **params}
    if not isinstance(spec, str):
        if isinstance(spec, Estimator):
            if params:
                raise ParameterError(f"parameters {sorted(params)} cannot be applied to an existing estimator {spec!r}")
            return spec
        raise ParameterError(f"estimator must be a name, a mapping or an Estimator, got {spec!r}")
    est: Estimator = ESTIMATORS.build(spec, **params)
    return est


def estimator_spec(estimator: Estimator) -> dict[str, Any]:
    """The ``{"name": ..., **params}`` mapping that :func:`make_estimator` turns back into it."""
    params = getattr(estimator, "params", {})
    return {"name": estimator.name, **params}
