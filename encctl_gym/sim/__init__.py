"""Numerical engine: the plant of eq:system and batched Monte Carlo sweeps of the paper's
Gaussian attack, identified by least squares (eq:estimate, :mod:`encctl_gym.ident`) and scored
by Definition def:error on grids of sample sizes.

Modules import downward only: ``plant -> montecarlo``, on :mod:`encctl_gym.ident` and
:func:`encctl_gym.parallel.run_tasks`.
"""

from __future__ import annotations

from . import montecarlo, plant
from .montecarlo import *  # noqa: F403
from .plant import *  # noqa: F403

__all__ = [*plant.__all__, *montecarlo.__all__]
