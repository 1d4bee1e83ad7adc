"""Identification of the plant ``(A, B)`` from (deciphered) data, and its error.

* :mod:`.error` -- the estimation error of Definition def:error.
* :mod:`.least_squares` -- the data matrices of eq:data and the least-squares estimate of
  eq:estimate: batch, recursive, and on a whole grid of sample sizes in one pass.
* :mod:`.estimator` -- the :class:`Estimator` protocol (batch fit, grid of N, online update of
  K copies in lockstep, the estimate, the error) and the shared moment machinery.
* :mod:`.ordinary`, :mod:`.bayes`, :mod:`.forgetting`, :mod:`.instrumental` -- the estimators:
  least squares, Bayesian least squares (Gaussian prior, ridge posterior mean), exponential
  forgetting, instrumental variables.
* :mod:`.registry` -- estimators by name (``make_estimator("bayes")``).

Pure numerical code (numpy): it imports only the package's base modules. The sample
identifying complexities of :mod:`encctl_gym.security` bound the expected error of these
estimates; the Monte Carlo engine (:mod:`encctl_gym.sim`) and the environment use them.
"""

from __future__ import annotations

from .bayes import BayesianLeastSquares
from .error import estimation_error
from .estimator import Estimator, MomentEstimator, estimate_errors
from .forgetting import ForgettingLeastSquares
from .instrumental import InstrumentalVariables
from .least_squares import (
    GRAM_COND_LIMIT,
    RecursiveLeastSquares,
    check_sample_sizes,
    data_matrices,
    identification_errors,
    least_squares,
    prefix_estimates,
    solve_normal_equations,
)
from .ordinary import OrdinaryLeastSquares
from .registry import DEFAULT_ESTIMATOR, ESTIMATORS, estimator_names, estimator_spec, make_estimator

__all__ = [
    "estimation_error",
    "data_matrices",
    "least_squares",
    "RecursiveLeastSquares",
    "check_sample_sizes",
    "prefix_estimates",
    "identification_errors",
    "solve_normal_equations",
    "GRAM_COND_LIMIT",
    "Estimator",
    "MomentEstimator",
    "estimate_errors",
    "OrdinaryLeastSquares",
    "BayesianLeastSquares",
    "ForgettingLeastSquares",
    "InstrumentalVariables",
    "ESTIMATORS",
    "DEFAULT_ESTIMATOR",
    "estimator_names",
    "estimator_spec",
    "make_estimator",
]
