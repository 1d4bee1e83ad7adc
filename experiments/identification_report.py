"""Identification strategies, the report: the CSV files, the figures, the tables and the findings
of a :class:`~encctl_gym.experiments.identification_results.Result`. The experiment is
:mod:`encctl_gym.experiments.identification_strategies`."""

from __future__ import annotations

import csv
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym.experiments.compare.tables import bound_rows
from encctl_gym.experiments.identification_results import Curve, Result, replicate_interval
from encctl_gym.plotting import legend_below, save_figure

# --------------------------------------------------------------------------- outputs
CURVE_COLUMNS = (
    "system",
    "attacker",
    "oracle",
    "estimator",
    "N",
    "mean_error",
    "se",
    "ci95_low",
    "ci95_high",
    "episodes",
    "gamma",
    "gamma_opt",
    "median",
    "q10",
    "q90",
    "tail_exponent",
    "mean_status",
)
SECURITY_COLUMNS = (
    "system",
    "attacker",
    "oracle",
    "estimator",
    "gamma_c",
    "slope",
    "rate_c",
    "first_below",
    "N_to_gamma_c",
    "N_how",
    "lambda_needed",
    "k_needed",
    "N_to_gamma_c_replicates",
    "N_to_gamma_c_mean",
    "N_to_gamma_c_low",
    "N_to_gamma_c_high",
)


def _fmt(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, (float, np.floating)):
        return "" if not np.isfinite(v) else repr(float(v))
    return str(v)


def write_csvs(result: Result, out: Path) -> list[Path]:
    """``curves.csv``, ``episodes.csv``, ``security.csv`` (tidy)."""
    by = {s.system: s for s in result.settings}
    with (out / "curves.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(CURVE_COLUMNS)
        for system, cs in result.curves.items():
            s = by[system]
            for c in cs:
                tails = c.tail or [None] * c.N.size
                for N, m, se, sm, a in zip(c.N, c.mean, c.se, c.summaries, tails):
                    q = sm.quantiles if sm is not None else {0.1: None, 0.5: None, 0.9: None}
                    w.writerow(
                        _fmt(v)
                        for v in (
                            system,
                            c.attacker,
                            c.oracle,
                            c.estimator,
                            int(N),
                            m,
                            se,
                            m - 1.96 * se,
                            m + 1.96 * se,
                            c.errors.shape[0],
                            float(s.params.gamma(int(N))),
                            float(s.design.gamma(int(N))),
                            q[0.5],
                            q[0.1],
                            q[0.9],
                            a,
                            sm.status if sm is not None else "",
                        )
                    )
    with (out / "episodes.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(("system", "attacker", "estimator", "N", "replicate", "episode", "error"))
        for system, cs in result.curves.items():
            for c in cs:
                E = c.errors.shape[0] // c.replicates
                for k, N in enumerate(c.N):
                    for e, v in enumerate(c.errors[:, k]):
                        w.writerow(_fmt(x) for x in (system, c.attacker, c.estimator, int(N), e // E, e % E, v))
    with (out / "security.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(SECURITY_COLUMNS)
        for r in result.security:
            w.writerow(_fmt(r[k]) for k in SECURITY_COLUMNS)
    return [out / "curves.csv", out / "episodes.csv", out / "security.csv"]


def _grid_axes(plt: Any, result: Result) -> tuple[Any, Any, list[str], list[str]]:
    systems = [s.system for s in result.settings]
    attackers = list(dict.fromkeys(c.attacker for cs in result.curves.values() for c in cs))
    fig, axes = plt.subplots(
        len(systems), len(attackers), figsize=(3.6 * len(attackers), 3.0 * len(systems)), squeeze=False, sharex="row"
    )
    return fig, axes, systems, attackers


def plot(result: Result, out: Path) -> list[Path]:
    """``identification_strategies.png`` and ``identification_strategies_ratio.png`` (module docstring)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    labels = [e.label for e in result.estimators]  # type: ignore[attr-defined]
    color = {lab: colors[i % len(colors)] for i, lab in enumerate(labels)}
    return [_plot_errors(plt, result, color, out), _plot_ratios(plt, result, color, out)]


def _plot_errors(plt: Any, result: Result, color: dict[str, str], out: Path) -> Path:
    """``identification_strategies.png``: each estimator's error against N, a panel per system
    and attacker."""
    by = {s.system: s for s in result.settings}
    fig, axes, systems, attackers = _grid_axes(plt, result)
    for i, system in enumerate(systems):
        for j, att in enumerate(attackers):
            ax = axes[i, j]
            cs = [c for c in result.curves[system] if c.attacker == att]
            if not cs:
                ax.axis("off")
                continue
            _error_panel(ax, by[system], cs, color)
            if i == 0:
                ax.set_title(f"{att}{' (oracle)' if cs[0].oracle else ''}", fontsize=9)
            if j == 0:
                ax.set_ylabel(f"{system}\nE[eps(N)]", fontsize=9)
            if i == len(systems) - 1:
                ax.set_xlabel("attack length N", fontsize=9)
    bottom = legend_below(fig, axes)
    E = result.curves[systems[0]][0].errors.shape[0]
    fig.suptitle(
        "\n".join(
            textwrap.wrap(
                f"Identification strategies: mean error (95 % band; open circles: the median where the mean does not exist "
                f"or is unreliable), {E} attacks per N at energy m sigma_u2 N, each estimator on the same delivered data",
                int(13 * fig.get_figwidth()),
            )
        ),
        fontsize=9,
    )
    fig.tight_layout(rect=(0, bottom, 1, 1))
    path = out / "identification_strategies.png"
    save_figure(fig, path, dpi=100)
    plt.close(fig)
    return path


def _error_panel(ax: Any, s: Any, cs: Sequence[Curve], color: dict[str, str]) -> None:
    """One panel: each estimator's mean (the median, open markers, where the mean does not exist
    or is unreliable) with its 95 % band, ``gamma(N)``, ``gamma_opt(N)`` and ``gamma_c`` in range."""
    N = cs[0].N
    Nl = np.unique(np.round(np.geomspace(N[0], N[-1], 200)).astype(int))
    for c in cs:
        mean, se = c.mean, c.se
        ok = np.isfinite(mean)
        top = c.estimator == "ls"  # the paper's estimator on top of the others
        # where the mean does not exist or is unreliable: the median (open marker), no band
        sms = c.summaries
        bare = np.array([sm is not None and not sm.mean_ok for sm in sms])
        med = np.array([sm.median if sm is not None else np.nan for sm in sms])
        y = np.where(bare, med, mean)
        ax.plot(
            c.N[ok],
            y[ok],
            color=color[c.estimator],
            lw=2.0 if top else 1.2,
            marker="o",
            ms=2,
            label=c.estimator,
            zorder=3 if top else 2,
            ls="--" if top else "-",
        )
        if bare.any():
            ax.plot(c.N[bare], med[bare], ls="none", marker="o", ms=5, mfc="none", color=color[c.estimator], zorder=4)
        band = ok & ~bare
        lo = np.maximum(mean - 1.96 * se, 0.05 * mean)
        ax.fill_between(c.N[band], lo[band], (mean + 1.96 * se)[band], color=color[c.estimator], alpha=0.2, lw=0)
    ax.plot(Nl, s.params.gamma(Nl), "k--", lw=1.0, label="gamma(N), eq:sic")
    ax.plot(Nl, s.design.gamma(Nl), "k:", lw=1.4, label="gamma_opt(N)")
    ax.set(xscale="log", yscale="log")
    ax.grid(True, which="major", alpha=0.3)
    shown = [np.array([(sm.mean if sm.mean_ok else sm.median) if sm is not None else np.nan for sm in c.summaries]) for c in cs]
    lo_y = float(np.nanmin([np.nanmin(v) for v in shown] + [float(np.min(s.design.gamma(Nl)))]))
    hi_y = float(np.nanmax([np.nanmax(v[np.isfinite(v)]) if np.isfinite(v).any() else lo_y for v in shown]))
    ax.set_ylim(0.5 * lo_y, 2.0 * max(hi_y, lo_y))
    if 0.5 * lo_y <= s.base.gamma_c <= 2.0 * max(hi_y, lo_y):  # short runs end above gamma_c
        ax.axhline(s.base.gamma_c, color="0.5", lw=0.7, ls="-.", label="gamma_c")


def _plot_ratios(plt: Any, result: Result, color: dict[str, str], out: Path) -> Path:
    """``identification_strategies_ratio.png``: each estimator's mean error over least squares'."""
    fig, axes, systems, attackers = _grid_axes(plt, result)
    for i, system in enumerate(systems):
        for j, att in enumerate(attackers):
            ax = axes[i, j]
            by_est = {c.estimator: c for c in result.curves[system] if c.attacker == att}
            ref = by_est.get("ls")
            if ref is None:
                ax.axis("off")
                continue
            for lab, c in by_est.items():
                r = c.mean / ref.mean
                ok = np.isfinite(r)
                ax.plot(c.N[ok], r[ok], color=color[lab], lw=1.3, marker="o", ms=2, label=lab)
            ax.axhline(1.0, color="k", lw=0.6)
            ax.set(xscale="log", yscale="log")
            ax.grid(True, which="both", alpha=0.3)
            if i == 0:
                ax.set_title(att, fontsize=9)
            if j == 0:
                ax.set_ylabel(f"{system}\nE[eps] / E[eps of ls]", fontsize=9)
            if i == len(systems) - 1:
                ax.set_xlabel("attack length N", fontsize=9)
    bottom = legend_below(fig, axes)
    fig.suptitle("Each estimator's mean error over that of least squares (eq:estimate), same data", fontsize=10)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    path = out / "identification_strategies_ratio.png"
    save_figure(fig, path, dpi=100)
    plt.close(fig)
    return path


def _cell(c: Curve, N: int) -> str:
    """The mean ± standard error where the mean exists, else the median [10 %, 90 %] and why."""
    k = int(np.searchsorted(c.N, N))
    sm = c.summaries[k]
    if sm is None:
        return "—"
    if sm.mean_ok:
        return f"{sm.mean:.3g} ± {sm.se:.1g}"
    why = "no mean" if sm.status == "does not exist" else "mean unreliable"
    a = sm.tail_exponent if sm.tail_exponent is not None else (sm.hill.alpha if sm.hill is not None else float("nan"))
    return f"{sm.quantile_text()} ({why}, a = {a:.2g})"


def replicate_table(result: Result) -> list[str]:
    """With several replicates: per attacker and estimator, the mean error at the top of the grid
    and the samples to reach gamma_c, as the mean of the replicates with a 95 % t interval."""
    lines: list[str] = []
    R = result.curves[result.settings[0].system][0].replicates if result.settings else 1
    if R < 2:
        return lines
    for s in result.settings:
        _, _, top, capped = result.sizes[s.system]
        sec = {(r["attacker"], r["estimator"]): r for r in result.security if r["system"] == s.system}
        lines += [
            f"#### {s.system}: {R} replicates (mean of the replicate values [95 % t interval])",
            "",
            f"| attacker | estimator | replicate means at N = {top} | E[eps] at N = {top} | N to gamma_c |",
            "|---|---|---|---|---|",
        ]
        for c in result.curves[s.system]:
            k = int(np.searchsorted(c.N, top))
            vals = c.replicate_means()[:, k]
            m, lo, hi = replicate_interval(vals)
            r = sec[(c.attacker, c.estimator)]
            Nc = (
                f"{r['N_to_gamma_c_mean']:.0f} [{r['N_to_gamma_c_low']:.0f}, {r['N_to_gamma_c_high']:.0f}]"
                if r["N_to_gamma_c_mean"] is not None
                else r["N_how"]
            )
            lines.append(
                f"| {c.attacker} | {c.estimator} | {' '.join(f'{v:.3g}' for v in vals)} | {m:.3g} [{lo:.3g}, {hi:.3g}] | {Nc} |"
            )
        lines.append("")
    return lines


def findings(result: Result) -> list[str]:
    """Plain-words statements computed from the numbers (no fixed conclusion)."""
    out = []
    for s in result.settings:
        small, medium, top, capped = result.sizes[s.system]
        cs = result.curves[s.system]
        for N, what in ((small, "small"), (top, "N*" if not capped else "the cap")):
            best = []
            for att in dict.fromkeys(c.attacker for c in cs):
                sms = {c.estimator: c.summaries[int(np.searchsorted(c.N, N))] for c in cs if c.attacker == att}
                fin = {k: v for k, v in sms.items() if v is not None}
                if "ls" in fin:
                    by_mean = all(v.mean_ok for v in fin.values())  # else medians: a mean ratio means nothing
                    val = {k: (v.mean if by_mean else v.median) for k, v in fin.items()}
                    k_best = min(val, key=val.get)  # type: ignore[arg-type]
                    best.append(f"{att}: {k_best} ({val[k_best] / val['ls']:.4g} x ls, {'means' if by_mean else 'medians'})")
            out.append(f"{s.system} at N = {N} ({what}): best estimator per attacker {'; '.join(best)}.")
        rows = [r for r in result.security if r["system"] == s.system and r["N_to_gamma_c"]]
        steady = [r for r in rows if "transient" not in r["N_how"]]
        if rows:
            r = min(steady or rows, key=lambda r: r["N_to_gamma_c"])
            paper = bound_rows(s)[0]
            text = (
                f"{s.system}: fewest samples to reach gamma_c = {s.base.gamma_c:g}: {r['N_to_gamma_c']} "
                f"({r['attacker']} + {r['estimator']}, {r['N_how']}) against the paper's N* = {paper['N_to_gamma_c']}; "
                f"lambda {r['lambda_needed']} against lambda* = {paper['lambda_needed']}"
            )
            lower = [q for q in rows if q["N_to_gamma_c"] < r["N_to_gamma_c"]]
            if steady and lower:
                q = min(lower, key=lambda q: q["N_to_gamma_c"])
                text += (
                    f" (fewer, {q['N_to_gamma_c']}, only from an extrapolation of a transient curve: "
                    f"{q['attacker']} + {q['estimator']}, {q['N_how']})"
                )
            out.append(text + ".")
    return out


def summary_markdown(result: Result, *, command: str, plots: Sequence[Path]) -> str:
    """The tables (errors at small, medium N and N*; samples to gamma_c) and the findings."""
    lines = [
        "## Identification strategies (`experiments/identification_strategies.py`)",
        "",
        f"Reproduce: `{command}` ({result.seconds / 60:.1f} min on this machine).",
        "",
    ]
    lines += [f"![{p.stem}]({p.as_posix()})" for p in plots] + [""]
    for s in result.settings:
        small, medium, top, capped = result.sizes[s.system]
        lines.append(
            f"### {s.system} (gamma_c = {s.base.gamma_c:g}; least squares of this script vs the environment's "
            f"info['epsilon'] for N >= 2 (n + m) + 1: max relative difference {result.env_check[s.system]:.1e})"
        )
        lines.append("")
        lines.append(
            f"| attacker | estimator | E[eps] at N = {small} | N = {medium} | N = {top}{' (cap)' if capped else ' (N*)'} "
            "| N to gamma_c | lambda | k |"
        )
        lines.append("|---|---|---|---|---|---|---|---|")
        sec = {(r["attacker"], r["estimator"]): r for r in result.security if r["system"] == s.system}
        for c in result.curves[s.system]:
            r = sec[(c.attacker, c.estimator)]
            Nc = f"{r['N_to_gamma_c']} ({r['N_how']})" if r["N_to_gamma_c"] else r["N_how"]
            lines.append(
                f"| {c.attacker}{' (oracle)' if c.oracle else ''} | {c.estimator} | {_cell(c, small)} | {_cell(c, medium)} | "
                f"{_cell(c, top)} | {Nc} | {r['lambda_needed'] or '—'} | {r['k_needed'] or '—'} |"
            )
        for b in bound_rows(s):
            lines.append(f"| *{b['attacker']}* | | | | | {b['N_to_gamma_c']} | {b['lambda_needed']} | {b['k_needed']} |")
        lines.append("")
    lines += replicate_table(result)
    lines.append(
        "Cells: mean ± standard error where the mean exists (tail rule of encctl_gym.ident.tails for inputs with a "
        "density, and the Hill check); elsewhere the median [10 %, 90 %] with the tail exponent a. 'extrapolated' "
        "marks a sample size beyond the grid, from the 1/N fit."
    )
    lines.append("")
    lines.append("Findings: " + " ".join(findings(result)))
    return "\n".join(lines) + "\n"
