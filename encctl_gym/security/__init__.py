"""Security analysis of encrypted control systems (pure math; imports none of crypto, sim, envs).

Modules
-------
gramians
    ``controllability_gramian`` (Psi_u) and ``noise_gramian`` (Psi_w) of Theorem thm:sic.
complexity
    Estimation error (Definition def:error), sample identifying complexity eq:sic and eq:sic2,
    upper bounds eq:bound.
exact
    Exact rational arithmetic: the decimal rule (typed numbers) and the binary rule (computed
    numbers), ``floor_log2``, ``pow2``.
sample_size
    The minimum sample size N* of Theorem thm:opt_sec for eq:sic2, eq:sic, ``c / (N - 1)`` and any
    nonincreasing complexity.
records
    Published attack costs (NFS records), the NIST SP 800-57 table and GNFS corrections
    (package data ``security/data/deciphering_records.json``).
cost_models
    Deciphering-cost models ``paper`` (def:sdt, eq:opt_key), ``precomputation`` (index calculus:
    one precomputation per group, then a cheap descent per key) and ``generic`` (Pollard rho),
    one protocol and one registry; the GNFS formula with its optional o(1) correction.
deciphering
    Sample deciphering time (Definition def:sdt) for the modified, token and static schemes,
    under a security parameter or any cost model; the largest affordable sample size.
design
    Definition def:security (``is_secure``), Theorem thm:opt_sec, eq:opt_key (``SecurityDesign``).
key_length
    eq:opt_key generalised: the smallest safe key length under each cost model, and what a key
    is worth under each.
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
from .cost_models import (
    DECIPHERING_MODELS,
    GUILLEVIC_CORRECTION,
    DecipheringModel,
    GenericModel,
    KeyBreakCost,
    PaperModel,
    PrecomputationModel,
    deciphering_model,
    pollard_rho_log2_operations,
)
from .deciphering import break_cost, max_affordable_samples, per_sample_cost, sample_deciphering_time
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
from .key_length import KeyLengthDesign, KeyValue, design_key_length, key_length_value

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
    "break_cost",
    "KeyBreakCost",
    "DecipheringModel",
    "PaperModel",
    "PrecomputationModel",
    "GenericModel",
    "DECIPHERING_MODELS",
    "deciphering_model",
    "GUILLEVIC_CORRECTION",
    "pollard_rho_log2_operations",
    "KeyLengthDesign",
    "KeyValue",
    "design_key_length",
    "key_length_value",
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
