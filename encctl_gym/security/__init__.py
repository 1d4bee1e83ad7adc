"""Security analysis of encrypted control systems (pure math; imports none of crypto, sim, envs).

Modules
-------
gramians
    ``controllability_gramian`` (Psi_u) and ``noise_gramian`` (Psi_w) of Theorem thm:sic.
complexity
    Estimation error (Definition def:error), sample identifying complexity eq:sic and eq:sic2,
    upper bounds eq:bound.
"""

from __future__ import annotations

from .complexity import (
    estimation_error,
    input_upper_bound,
    noise_upper_bound,
    sample_identifying_complexity,
    sample_identifying_complexity_asymptotic,
    sic_asymptotic_from_traces,
    sic_from_traces,
)
from .gramians import controllability_gramian, noise_gramian

__all__ = [
    "controllability_gramian",
    "noise_gramian",
    "estimation_error",
    "sample_identifying_complexity",
    "sample_identifying_complexity_asymptotic",
    "sic_from_traces",
    "sic_asymptotic_from_traces",
    "input_upper_bound",
    "noise_upper_bound",
]
