"""Identification of the plant ``(A, B)`` from (deciphered) data, and its error.

* :mod:`.error` -- the estimation error of Definition def:error.
* :mod:`.least_squares` -- the data matrices of eq:data and the least-squares estimate of
  eq:estimate: batch, recursive, and on a whole grid of sample sizes in one pass.

Pure numerical code (numpy): it imports only the package's base modules. The sample
identifying complexities of :mod:`encctl_gym.security` bound the expected error of these
estimates; the Monte Carlo engine (:mod:`encctl_gym.sim`) and the environment use them.
"""

from __future__ import annotations

from .error import estimation_error
from .least_squares import (
    GRAM_COND_LIMIT,
    RecursiveLeastSquares,
    check_sample_sizes,
    data_matrices,
    identification_errors,
    least_squares,
    prefix_estimates,
)

__all__ = [
    "estimation_error",
    "data_matrices",
    "least_squares",
    "RecursiveLeastSquares",
    "check_sample_sizes",
    "prefix_estimates",
    "identification_errors",
    "GRAM_COND_LIMIT",
]
