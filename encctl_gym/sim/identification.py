"""Former home of least-squares identification, now :mod:`encctl_gym.ident`.

Kept as an import path for one version; import from :mod:`encctl_gym.ident` instead.
"""

from __future__ import annotations

from ..ident.least_squares import (
    GRAM_COND_LIMIT,
    RecursiveLeastSquares,
    check_sample_sizes,
    data_matrices,
    identification_errors,
    least_squares,
    prefix_estimates,
)

__all__ = [
    "data_matrices",
    "least_squares",
    "RecursiveLeastSquares",
    "check_sample_sizes",
    "identification_errors",
    "prefix_estimates",
    "GRAM_COND_LIMIT",
]
