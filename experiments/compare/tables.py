"""The tidy tables of a comparison: one row per attacker and setting (the security consequence
and the paired ratios), the reference rows, and their CSV files.

Security consequence. For each attacker the sample size it needs to reach ``gamma_c`` is read
from its mean curve when it gets there within the horizon, else extrapolated from a fit
``E[epsilon(N)] ~ c / (N - 1)`` to the upper half of the grid
(:func:`~experiments.compare.statistics.samples_to_reach`). The security parameter that would
have been needed against it is ``lam = floor(log2(Upsilon tau_c / N_c)) + 1`` (Theorem
thm:opt_sec, :func:`encctl_gym.security.design.optimal_security_parameter`) and the key length
``k`` of eq:opt_key (:func:`encctl_gym.security.design.minimum_key_length`), next to the paper's
``N*``, ``lam*`` and ``k*`` (:func:`bound_rows`).

Files (:func:`write_csvs`): ``curves.csv`` (system, delay, attacker, protocol, N, mean, standard
error, 95 % band, gamma, gamma_opt, the Gaussian design's error, energy fraction),
``episodes.csv`` (final error and average power of every episode), ``security.csv`` (the rows
of :func:`security_row` and :func:`bound_rows`), ``elgamal.csv``.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym.ident.tails import error_tail_exponent, summarize_errors
from encctl_gym.security.design import design_from_traces, minimum_key_length, optimal_security_parameter, sample_size_for_rate
from encctl_gym.security.threat import ThreatModel

from .records import Curve, Result
from .settings import Setting
from .statistics import Z95, fit_rate, paired_ratio, samples_to_reach

__all__ = ["CURVE_COLUMNS", "EPISODE_COLUMNS", "SECURITY_COLUMNS", "security_row", "bound_rows", "write_csvs"]

CURVE_COLUMNS = (
    "system",
    "delay",
    "attacker",
    "oracle",
    "protocol",
    "N",
    "mean_error",
    "se",
    "ci95_low",
    "ci95_high",
    "episodes",
    "gamma",
    "gamma_opt",
    "gaussian_design",
    "energy_fraction",
)
EPISODE_COLUMNS = ("system", "delay", "attacker", "episode", "N", "final_error", "average_power")
SECURITY_COLUMNS = (
    "system",
    "delay",
    "attacker",
    "oracle",
    "episodes",
    "horizon",
    "capped",
    "mean_error_at_horizon",
    "se_error_at_horizon",
    "ci95_low_at_horizon",
    "ci95_high_at_horizon",
    "gamma_at_horizon",
    "gamma_opt_at_horizon",
    "error_over_gamma_opt",
    "ratio_to_gaussian",
    "ratio_to_gaussian_low",
    "ratio_to_gaussian_high",
    "ratio_to_oracle",
    "ratio_to_oracle_low",
    "ratio_to_oracle_high",
    "average_power",
    "sigma_u2",
    "rate_c",
    "rate_over_gaussian_design",
    "gamma_c",
    "N_to_gamma_c",
    "N_how",
    "lambda_needed",
    "k_needed",
    "median_at_horizon",
    "q10_at_horizon",
    "q90_at_horizon",
    "mean_status",
    "mean_flag",
)


def security_row(setting: Setting, curve: Curve, *, gaussian: Curve | None = None, oracle: Curve | None = None) -> dict[str, Any]:
    """One attacker's row: error at the horizon with its 95 % interval, the paired ratios to the
    Gaussian attacker and to the oracle on the same episodes (with 95 % intervals), the security
    consequence (module docstring), and the median and 10-90 % quantiles at the horizon with the
    status of the mean (:func:`encctl_gym.ident.tails.summarize_errors`: the least-squares tail
    rule, which assumes inputs with a density, and the Hill check)."""
    p, b = setting.params, setting.base
    N_c, how = samples_to_reach(curve.N, curve.mean, b.gamma_c)
    lam = optimal_security_parameter(N_c, tau_c=b.tau_c, upsilon=b.upsilon)
    Nh = int(curve.N[-1])
    mean = float(curve.final.mean())
    se = float(curve.final.std(ddof=1) / math.sqrt(curve.final.size)) if curve.final.size > 1 else float("nan")
    rate = fit_rate(curve.N, curve.mean)
    tails = summarize_errors(curve.final, tail_exponent=error_tail_exponent(p.n, p.m, Nh) if Nh > p.n + p.m else None)
    row = {
        "system": setting.system,
        "delay": setting.delay,
        "attacker": curve.attacker,
        "oracle": curve.oracle,
        "episodes": curve.episodes,
        "horizon": Nh,
        "capped": setting.capped,
        "mean_error_at_horizon": mean,
        "se_error_at_horizon": se,
        "ci95_low_at_horizon": mean - Z95 * se,
        "ci95_high_at_horizon": mean + Z95 * se,
        "gamma_at_horizon": float(p.gamma(Nh)),
        "gamma_opt_at_horizon": float(setting.design.gamma(Nh)),
        "error_over_gamma_opt": mean / float(setting.design.gamma(Nh)),
        "average_power": float(curve.power.mean()),
        "sigma_u2": p.sigma_u2,
        "rate_c": rate,
        "rate_over_gaussian_design": rate / setting.gauss.rate,
        "gamma_c": p.gamma_c,
        "N_to_gamma_c": N_c,
        "N_how": how,
        "lambda_needed": lam,
        "k_needed": minimum_key_length(lam),
        "median_at_horizon": tails.median,
        "q10_at_horizon": tails.quantiles[0.1],
        "q90_at_horizon": tails.quantiles[0.9],
        "mean_status": tails.status,
        "mean_flag": tails.flag(),
    }
    for label, ref in (("gaussian", gaussian), ("oracle", oracle)):
        if ref is not None and ref is not curve and ref.final.size == curve.final.size and ref.final.size > 1:
            pr = paired_ratio(curve.final, ref.final)
            row.update({f"ratio_to_{label}": pr.ratio, f"ratio_to_{label}_low": pr.low, f"ratio_to_{label}_high": pr.high})
    return row


def bound_rows(setting: Setting) -> list[dict[str, Any]]:
    """The reference rows: the paper's design (eq:sic2, thm:opt_sec), the exact Gaussian rate and gamma_opt."""
    p = setting.base
    threat = ThreatModel(
        sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2, sigma_x2=p.sigma_x2, gamma_c=p.gamma_c, tau_c=p.tau_c, upsilon=p.upsilon
    )
    paper = design_from_traces(p.tr_psi_u, p.tr_psi_w, p.m, p.n, threat)
    rows = [
        {
            "system": setting.system,
            "delay": setting.delay,
            "attacker": "paper gamma (eq:sic2)",
            "N_to_gamma_c": paper.N_star,
            "N_how": "thm:opt_sec",
            "lambda_needed": paper.lam_star,
            "k_needed": paper.k_star,
            "rate_c": (p.m + p.n) * p.sigma_w2 / (p.sigma_u2 * (p.tr_psi_u + p.m) + p.sigma_w2 * p.tr_psi_w),
        }
    ]
    for label, d in (("gaussian design rate", setting.gauss), (f"gamma_opt ({setting.design.kind})", setting.design)):
        N_c = sample_size_for_rate(d.rate, p.gamma_c)
        lam = optimal_security_parameter(N_c, tau_c=p.tau_c, upsilon=p.upsilon)
        rows.append(
            {
                "system": setting.system,
                "delay": setting.delay,
                "attacker": label,
                "N_to_gamma_c": N_c,
                "N_how": "c / gamma_c",
                "lambda_needed": lam,
                "k_needed": minimum_key_length(lam),
                "rate_c": d.rate,
            }
        )
    for r in rows:
        r["rate_over_gaussian_design"] = r["rate_c"] / setting.gauss.rate
    return rows


def _fmt(v: Any) -> str:
    """A CSV cell: floats with every digit (``repr``), non-finite floats empty."""
    if isinstance(v, (float, np.floating)):
        return "" if not np.isfinite(v) else repr(float(v))
    return str(v)


def _write(path: Path, columns: tuple[str, ...] | list[str], rows: Any) -> Path:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(columns)
        for row in rows:
            w.writerow(_fmt(v) for v in row)
    return path


def curve_rows(result: Result) -> list[tuple[Any, ...]]:
    """The rows of ``curves.csv`` (:data:`CURVE_COLUMNS`)."""
    rows = []
    by_key = {s.key: s for s in result.settings}
    for key, cs in result.curves.items():
        s = by_key[key]
        for c in cs:
            parts: list[tuple[str, Any, Any, Any, Any]] = [("fresh", c.N, c.mean, c.se, np.full(c.N.shape, np.nan))]
            if c.along_N is not None:
                parts.append(("along", c.along_N, c.along_mean, c.along_se, c.along_energy))
            for protocol, Ns, means, ses, efrac in parts:
                for N, m, se, ef in zip(Ns, means, ses, efrac):
                    rows.append(
                        (
                            s.system,
                            s.delay,
                            c.attacker,
                            c.oracle,
                            protocol,
                            int(N),
                            m,
                            se,
                            m - Z95 * se,
                            m + Z95 * se,
                            c.episodes,
                            s.params.gamma(int(N)),
                            s.design.gamma(int(N)),
                            s.gauss.gamma(int(N)),
                            ef,
                        )
                    )
    return rows


def write_csvs(result: Result, out: Path) -> list[Path]:
    """``curves.csv``, ``episodes.csv``, ``security.csv`` and (when there are ElGamal episodes)
    ``elgamal.csv`` under ``out`` (tidy, one row per observation)."""
    out = Path(out)
    paths = [_write(out / "curves.csv", CURVE_COLUMNS, curve_rows(result))]
    episodes = [
        (key[0], key[1], c.attacker, e, int(c.N[-1]), f, pw)
        for key, cs in result.curves.items()
        for c in cs
        for e, (f, pw) in enumerate(zip(c.final, c.power))
    ]
    paths.append(_write(out / "episodes.csv", EPISODE_COLUMNS, episodes))
    paths.append(
        _write(
            out / "security.csv",
            SECURITY_COLUMNS,
            ([row.get(k, "") for k in SECURITY_COLUMNS] for row in result.security + result.bounds),
        )
    )
    if result.elgamal:
        cols = list(result.elgamal[0])
        paths.append(_write(out / "elgamal.csv", cols, ([row[k] for k in cols] for row in result.elgamal)))
    return paths
