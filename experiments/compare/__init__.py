"""The headline experiment: every attacker against gamma(N) and gamma_opt(N).

One module per job:

=====================  =====================================================================
module                 holds
=====================  =====================================================================
``settings``           :class:`Setting` (a system in one observation setting, with its bounds)
``attackers``          :data:`ATTACKERS` (baselines and the oracle by name), learned attackers
``statistics``         means, standard errors, paired ratios with 95 % intervals, the 1/N fit
``records``            :class:`Curve` and :class:`Result` (what a comparison measured)
``protocol``           :func:`evaluate`, :func:`compute` -> :class:`Result`
``tables``             the rows (security consequence, paired ratios) and the CSV files
``plots``              the PNGs
``report``             the table printed by ``compare`` and ``evaluate``, ``summary.md``
``cli``                ``encctl-gym compare``
``evaluate_run``       ``encctl-gym evaluate RUN_DIR``
=====================  =====================================================================
"""

from .attackers import ATTACKERS, DEFAULT_ATTACKERS, learned_players, left_out, make_attackers, run_applies, run_setting
from .protocol import compute, elgamal_check, evaluate, planned_steps
from .records import Curve, Result
from .report import comparison_table, findings, summary_markdown
from .settings import DEFAULT_CAP, DEFAULT_SYSTEMS, DELAYS, Setting, length_grid, make_setting, parse_delays
from .statistics import PairedRatio, fit_rate, mean_se, paired_ratio, samples_to_reach
from .tables import CURVE_COLUMNS, EPISODE_COLUMNS, SECURITY_COLUMNS, bound_rows, security_row, write_csvs

__all__ = [
    "ATTACKERS",
    "DEFAULT_ATTACKERS",
    "learned_players",
    "left_out",
    "make_attackers",
    "run_applies",
    "run_setting",
    "Curve",
    "Result",
    "compute",
    "elgamal_check",
    "evaluate",
    "planned_steps",
    "comparison_table",
    "findings",
    "summary_markdown",
    "DEFAULT_CAP",
    "DEFAULT_SYSTEMS",
    "DELAYS",
    "Setting",
    "length_grid",
    "make_setting",
    "parse_delays",
    "PairedRatio",
    "fit_rate",
    "mean_se",
    "paired_ratio",
    "samples_to_reach",
    "CURVE_COLUMNS",
    "EPISODE_COLUMNS",
    "SECURITY_COLUMNS",
    "bound_rows",
    "security_row",
    "write_csvs",
]
