"""Numerical engine: the plant of eq:system, least-squares identification (eq:estimate) and
its error (Definition def:error) on grids of sample sizes, and seeded parallel sweeps.

Modules import downward only: ``plant -> identification -> montecarlo``; sweeps run on
:func:`encctl_gym.parallel.run_tasks`.
"""

from __future__ import annotations

from .identification import (
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
