"""Security analysis of encrypted control systems (pure math; imports none of crypto, sim, envs).

Modules
-------
gramians
    ``controllability_gramian`` (Psi_u) and ``noise_gramian`` (Psi_w) of Theorem thm:sic.
complexity
    Estimation error (Definition def:error), sample identifying complexity eq:sic and eq:sic2,
    upper bounds eq:bound.
deciphering
    Sample deciphering time (Definition def:sdt) for the modified, token and static schemes.
design
    Definition def:security (``is_secure``), Theorem thm:opt_sec, eq:opt_key (GNFS key length).
attack_design
    A-optimal attack inputs (closed and open loop), ``gamma_opt`` and robust designs (needs
    cvxpy; imported on use).
design_cli
    The ``encctl-gym design`` subcommand.
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
from .deciphering import max_affordable_samples, per_sample_cost, sample_deciphering_time
from .design import (
    SecurityDesign,
    bit_security_of_key_length,
    design_from_traces,
    design_security_parameter,
    gnfs_complexity,
    gnfs_log2_complexity,
    is_secure,
    minimum_key_length,
    optimal_sample_size,
    optimal_security_parameter,
    paper_design_example,
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
    "sample_deciphering_time",
    "per_sample_cost",
    "max_affordable_samples",
    "SecurityDesign",
    "is_secure",
    "optimal_sample_size",
    "optimal_security_parameter",
    "design_from_traces",
    "design_security_parameter",
    "paper_design_example",
    "gnfs_complexity",
    "gnfs_log2_complexity",
    "bit_security_of_key_length",
    "minimum_key_length",
]
