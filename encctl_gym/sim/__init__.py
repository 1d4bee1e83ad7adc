"""Numerical engine: the plant of eq:system and batched Monte Carlo sweeps of the paper's
Gaussian attack, identified by least squares (eq:estimate, :mod:`encctl_gym.ident`) and scored
by Definition def:error on grids of sample sizes.

Modules import downward only: ``plant -> montecarlo``, on :mod:`encctl_gym.ident` and
:func:`encctl_gym.parallel.run_tasks`. The least-squares names are re-exported here for one
version (their home is :mod:`encctl_gym.ident`).
"""

from __future__ import annotations

from ..ident.least_squares import (
    RecursiveLeastSquares,
    data_matrices,
    identification_errors,
    least_squares,
    prefix_estimates,
)
from .montecarlo import AttackSpec, gaussian_attack_errors, log_grid, sweep_gaussian_attack
from ..parallel import child_seeds, run_tasks
from .plant import LinearPlant, SimulationResult, simulate, simulate_gaussian_attack

__all__ = [
    "LinearPlant",
    "SimulationResult",
    "simulate",
    "simulate_gaussian_attack",
    "data_matrices",
    "least_squares",
    "RecursiveLeastSquares",
    "prefix_estimates",
    "identification_errors",
    "child_seeds",
    "run_tasks",
    "AttackSpec",
    "log_grid",
    "gaussian_attack_errors",
    "sweep_gaussian_attack",
]
