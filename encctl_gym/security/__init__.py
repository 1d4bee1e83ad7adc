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
    one base class and one registry; the GNFS formula with its optional o(1) correction.
threat
    ``ThreatModel``: variances, gamma_c, tau_c, Upsilon, adversary and cost model, checked once;
    the design functions take one.
deciphering
    Sample deciphering time (Definition def:sdt) for the modified, token and static schemes,
    under a security parameter or any cost model; the largest affordable sample size.
design
    Definition def:security (``is_secure``), Theorem thm:opt_sec, eq:opt_key (``SecurityDesign``).
key_length
    eq:opt_key generalised: the smallest safe key length under each cost model, and what a key
    is worth under each.
defenses
    The defences' closed forms: eq:sic with the defender's input noise, its Lyapunov price,
    audit rates, the chi-squared detector's threshold, group rotation's precomputations.
rotation
    Group rotation charged per group under every cost model: tau(N), the affordable samples and
    the key length a rotation period needs.
empirical
    An empirical sample identifying complexity (a fitted ``c / N^a`` with bootstrap intervals)
    for estimators without a closed form, and the design with intervals for N*, lambda*, k*.
attack_design
    A-optimal attack inputs (closed and open loop), ``gamma_opt`` and robust designs (needs
    cvxpy; imported on use).
report
    ``design_report``: everything the design command reports for a plant, as a dict.
defense_design
    The cheapest secure mix of key length, group rotation, audits and noise per cost model,
    with the defender's cost per step (its time models are passed in by the loop layer).
defense_cli
    The defender's options of ``encctl-gym design`` and their section of the output.
design_cli
    The ``encctl-gym design`` subcommand (prints :func:`.report.design_report`; with the
    defender's levers through :mod:`encctl_gym.design_command`).
"""

from __future__ import annotations

import sys

from .attack_design import *  # noqa: F403
from .bayes_complexity import *  # noqa: F403
from .complexity import *  # noqa: F403
from .cost_models import *  # noqa: F403
from .deciphering import *  # noqa: F403
from .defenses import *  # noqa: F403
from .design import *  # noqa: F403
from .empirical import *  # noqa: F403
from .exact import *  # noqa: F403
from .gramians import *  # noqa: F403
from .key_length import *  # noqa: F403
from .records import *  # noqa: F403
from .rotation import *  # noqa: F403
from .sample_size import *  # noqa: F403
from .threat import *  # noqa: F403

#: The public names of the modules above, in their order (each module's ``__all__``).
__all__ = list(
    dict.fromkeys(
        name
        for module in (
            "gramians",
            "exact",
            "complexity",
            "bayes_complexity",
            "sample_size",
            "records",
            "cost_models",
            "threat",
            "deciphering",
            "design",
            "key_length",
            "defenses",
            "rotation",
            "empirical",
            "attack_design",
        )
        for name in sys.modules[f"{__name__}.{module}"].__all__
    )
)
