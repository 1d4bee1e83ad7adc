"""The report of a comparison: the table (printed by ``compare`` and ``evaluate``), the finding
in words, and ``summary.md``.

Nothing here is fixed text about the outcome: every statement is computed from a
:class:`~experiments.compare.records.Result`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym._validation import format_count

from .protocol import GAUSSIAN_NAME
from .records import Result
from .statistics import paired_ratio

__all__ = ["comparison_table", "design_efficiencies", "findings", "summary_markdown"]


def _ratio(r: dict[str, Any], which: str) -> str:
    if f"ratio_to_{which}" not in r:
        return ""
    return f"{r[f'ratio_to_{which}']:.3f} [{r[f'ratio_to_{which}_low']:.3f}, {r[f'ratio_to_{which}_high']:.3f}]"


def _error_cell(r: dict[str, Any]) -> str:
    if r.get("mean_status", "exists") == "exists":
        return f"{r['mean_error_at_horizon']:.3g} [{r['ci95_low_at_horizon']:.3g}, {r['ci95_high_at_horizon']:.3g}]"
    return (
        f"median {r['median_at_horizon']:.3g} [10-90 %: {r['q10_at_horizon']:.3g}, {r['q90_at_horizon']:.3g}]; {r['mean_flag']}"
    )


def comparison_table(result: Result) -> str:
    """The markdown table of every attacker and setting, then the reference rows.

    Columns: average power; mean final error at the horizon with its 95 % interval (where the
    mean does not exist or is unreliable, the median with the 10-90 % quantiles and why); the horizon
    (``*``: set by the evaluation, not by the system's tau_c); the error over ``gamma_opt(N)``; the paired ratios to the
    Gaussian attacker and to the oracle on the same episodes (ratio of geometric means, 95 %
    interval); the fitted rate over the Gaussian design's; the samples needed to reach
    ``gamma_c`` and the lambda and key length that would have been needed.
    """
    lines = [
        "| system | delay | attacker | power | E[eps] at N [95% CI] | N | E[eps] / gamma_opt | vs Gaussian (paired) [95% CI] "
        "| vs oracle (paired) [95% CI] | (N-1)E[eps] / Gaussian rate | N to gamma_c | lambda | k |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in result.security:
        lines.append(
            f"| {r['system']} | {r['delay']} | {r['attacker']}{' (oracle)' if r['oracle'] else ''} | {r['average_power']:.3g} | "
            f"{_error_cell(r)} | "
            f"{r['horizon']}{'*' if r['capped'] else ''} | {r['error_over_gamma_opt']:.3f} | {_ratio(r, 'gaussian')} | "
            f"{_ratio(r, 'oracle')} | {r['rate_over_gaussian_design']:.3f} | {r['N_to_gamma_c']} ({r['N_how'][:5]}.) | "
            f"{r['lambda_needed']} | {r['k_needed']} |"
        )
    for r in result.bounds:
        lines.append(
            f"| {r['system']} | {r['delay']} | *{r['attacker']}* | | | | | | | {r['rate_over_gaussian_design']:.3f} | "
            f"{r['N_to_gamma_c']} | {r['lambda_needed']} | {r['k_needed']} |"
        )
    return "\n".join(lines)


def design_efficiencies(result: Result) -> str:
    """One line per setting: each attacker's design efficiency ``tr(Sigma_opt^-1) / tr(Sigma^-1)``
    of the regressors its attacks at the horizon delivered (:func:`agents.evaluate.design_efficiency`;
    1 is the setting's optimal design, closed loop with delivered states, open loop when blind)."""
    from encctl_gym.agents.evaluate import design_efficiency

    out = []
    for s in result.settings:
        parts = [
            f"{c.attacker} {design_efficiency(c.covariance, s.design):.4f}"
            for c in result.curves[s.key]
            if c.covariance is not None
        ]
        if parts:
            out.append(
                f"{s.system}, delay {s.delay}, N = {s.params.horizon}: design efficiency tr(Sigma_opt^-1) / tr(Sigma^-1) "
                f"({s.design.kind} optimum): " + ", ".join(parts) + "."
            )
    return "\n".join(out)


def findings(result: Result) -> str:
    """Plain-words statements computed from the numbers (no fixed conclusion)."""
    out = []
    for s in result.settings:
        cs = {c.attacker: c for c in result.curves[s.key]}
        g = cs.get(GAUSSIAN_NAME)
        if g is None or g.final.size < 2:
            continue
        Nh = int(g.N[-1])
        gam = float(s.params.gamma(Nh))
        beat_gamma = [n for n, c in cs.items() if c.final.mean() + 2 * c.final.std(ddof=1) / math.sqrt(c.final.size) < gam]
        better = []
        for n, c in cs.items():
            if n == GAUSSIAN_NAME:
                continue
            pr = paired_ratio(c.final, g.final)
            if pr.significant_below:
                better.append(f"{n} ({100 * (pr.ratio - 1):+.0f}%)")
        out.append(
            f"{s.system}, delay {s.delay}: below the Gaussian attack at N = {Nh} (paired, 95% interval below 1): "
            f"{', '.join(better) or 'none'}; below the paper's gamma(N): {', '.join(beat_gamma) or 'none'}."
        )
    for s in result.settings:
        for c in result.curves[s.key]:
            if c.along_N is None or c.along_energy is None:
                continue
            if 0.1 * s.params.horizon < c.along_N[0]:
                continue  # the energy is recorded from N = 2 (n + m) + 1 on; no extrapolation
            tenth = float(np.interp(0.1 * s.params.horizon, c.along_N, c.along_energy))
            if abs(tenth - 0.1) > 0.1:
                out.append(
                    f"{c.attacker} ({s.system}, delay {s.delay}) paces its energy unevenly: {100 * tenth:.0f}% of the "
                    "attack's budget in its first 10% of samples."
                )
    return " ".join(out)


def summary_markdown(
    result: Result, *, command: str, plots: Sequence[Path], title: str = "Attackers against the bounds (`encctl-gym compare`)"
) -> str:
    """The table and the finding in words, with the command that reproduces them; images are
    linked by file name (the PNGs sit beside ``summary.md``)."""
    lines = [f"## {title}", ""]
    lines.append(f"Reproduce: `{command}` ({result.seconds / 60:.1f} min on this machine).")
    lines.append("")
    for p in plots:
        lines.append(f"![{Path(p).stem}]({Path(p).name})")
    lines.append("")
    lines.append(comparison_table(result))
    lines.append("")
    lines.append(
        f"Environment seeds {result.seed}, {result.seed + 1}, ... for every attacker (paired). "
        "N marked * is set by the evaluation (a cap or an exact length), not by the system's tau_c budget. " + findings(result)
    )
    eff = design_efficiencies(result)
    if eff:
        lines.append("")
        lines.append(eff.replace("\n", "\n\n"))
    if result.elgamal:
        same = sum(
            abs(r["error_elgamal"] - r["error_ideal_same_seed"]) <= 1e-9 * r["error_ideal_same_seed"] for r in result.elgamal
        )
        lines.append("")
        attackers = len({(r["system"], r["delay"], r["attacker"]) for r in result.elgamal})
        lines.append(
            f"Through real ElGamal ciphertexts ({result.elgamal[0]['key_length']}-bit key, N = {result.elgamal[0]['N']}): "
            f"{format_count(len(result.elgamal), 'episode')} over {format_count(attackers, 'attacker setting')}; {same} of them give the same final "
            "error as the ideal backend on the same seeds (elgamal.csv)."
        )
    return "\n".join(lines) + "\n"
