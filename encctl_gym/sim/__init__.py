"""Numerical engine: the plant of eq:system and batched Monte Carlo sweeps of the paper's
Gaussian attack, identified by least squares (eq:estimate, :mod:`encctl_gym.ident`) and scored
by Definition def:error on grids of sample sizes.

Modules import downward only: ``plant -> montecarlo``, on :mod:`encctl_gym.ident` and
:func:`encctl_gym.parallel.run_tasks`. The least-squares names are re-exported here for one
version (their home is :mod:`encctl_gym.ident`).
"""

from __future__ import annotations

# the least-squares and task names this package gave before they had homes of their own
from ..ident.least_squares import RecursiveLeastSquares, data_matrices, identification_errors, least_squares, prefix_estimates  # noqa: E501
from ..parallel import child_seeds, run_tasks
from . import montecarlo, plant
from .montecarlo import *  # noqa: F403
from .plant import *  # noqa: F403

__all__ = [
    *plant.__all__,
    *montecarlo.__all__,
    "data_matrices",
    "least_squares",
    "RecursiveLeastSquares",
    "prefix_estimates",
    "identification_errors",
    "child_seeds",
    "run_tasks",
]
