"""Identification from outputs: what measuring less costs the attacker in samples and the
defender in key bits.

For the design example (preset ``paper-example``) and Figure 1 (c) (``fig1-c``), the paper's
Gaussian attack is measured through ``y = C x + v`` with ``C = I`` (every state), ``C = [I 0]``
(half the states) and one output ``C = [1 1 1 1]``, each with ``sigma_v2 = 0`` and
``sigma_v2 = sigma_w2``, and identified by N4SID, PO-MOESP and ARX
(:mod:`encctl_gym.ident.subspace`). Two more open-loop attackers, which need no state either
(:data:`~encctl_gym.sim.output.OUTPUT_ATTACKS`), are identified by N4SID and ARX: random binary
inputs (PRBS) and the A-optimal open-loop attack design (``optimal-ol``, designed for the state
case with the true plant: where it applies, an oracle). The closed-loop optimal design needs the
state and does not apply. Every estimate is scored by the basis-free Markov-parameter
error (:func:`~encctl_gym.ident.subspace.markov_error`); least squares on the states gives the
reference, in the same error.

The accuracy target is the one the paper designs for, moved into the Markov error: the fitted
state least-squares Markov error at the paper's ``N*`` (eq:opt_sec). Each case's empirical
complexity (:mod:`encctl_gym.security.empirical`, a fitted ``c / N^a`` with bootstrap intervals)
gives the ``N*`` at which it reaches that target and the ``k*`` (paper model, eq:opt_key) a
defender then needs, with intervals; an ``N*`` beyond the simulated grid is an extrapolation and
is marked.

    python -m encctl_gym.experiments.output_identification [--runs 20] [--points 6] [--quick] [--out docs/results/output]

Writes ``output_identification.csv``, ``output_identification.md`` and
``output_identification.png``.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym.errors import EncctlError
from encctl_gym.plotting import legend_below, save_figure
from encctl_gym.presets import get_preset
from encctl_gym.security.attack_design import optimal_attack_design
from encctl_gym.security.design import design_security_parameter
from encctl_gym.security.empirical import empirical_design, fit_empirical_complexity
from encctl_gym.security.threat import ThreatModel
from encctl_gym.sim.output import OUTPUT_ATTACKS, OUTPUT_ESTIMATORS, output_attack_errors
from encctl_gym.sim.plant import LinearPlant

from .common import system_preset

SYSTEMS = ("paper-example", "fig1-c")
OUTPUTS = {"C = I": np.eye(4), "C = [I 0]": np.eye(4)[:2], "one output": np.ones((1, 4))}
#: The estimators each attack is identified by: every one for the paper's Gaussian attack, the
#: cheapest subspace method and the baseline for the others.
ESTIMATORS_OF = {"gaussian": tuple(OUTPUT_ESTIMATORS), "prbs": ("n4sid", "arx"), "optimal-ol": ("n4sid", "arx")}
assert set(ESTIMATORS_OF) == set(OUTPUT_ATTACKS)
ATTACK_COLORS = {"prbs": "tab:red", "optimal-ol": "tab:purple"}


def run(runs: int, points: int, n_max: int | None, seed: int, attacks: tuple[str, ...] = OUTPUT_ATTACKS) -> list[dict[str, Any]]:
    """Every case of the module docstring for ``attacks``: one row each (the numbers of the table and figure)."""
    rows: list[dict[str, Any]] = []
    for system in SYSTEMS:
        p = get_preset(system)
        plant = LinearPlant(p.A, p.B, sigma_w2=p.sigma_w2)
        paper = design_security_parameter(p.plant(), ThreatModel.of(p))
        top = n_max or 2 * paper.N_star
        grid = np.unique(np.geomspace(200, top, points).astype(int))
        ref = output_attack_errors(
            plant, np.eye(4), sample_sizes=grid, runs=runs, sigma_u2=p.sigma_u2, sigma_v2=0.0, seed=seed, estimator="arx"
        )
        ol_design = optimal_attack_design(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2, feedback=False)
        ls_fit = fit_empirical_complexity(grid, ref["state_ls_markov"])
        target = float(ls_fit(paper.N_star))
        base = empirical_design(ls_fit, ThreatModel.of(p), reference=(ls_fit, paper.N_star))
        rows.append(
            _row(
                system, "states (least squares)", 0.0, "gaussian", "ls", grid, ref["state_ls_markov"], ls_fit, base,
                paper.N_star, target,
            )
        )  # fmt: skip
        for label, C in OUTPUTS.items():
            for sv in (0.0, p.sigma_w2):
                for attack in attacks:
                    for est in ESTIMATORS_OF[attack]:
                        out = output_attack_errors(
                            plant, C, sample_sizes=grid, runs=runs, sigma_u2=p.sigma_u2, sigma_v2=sv, seed=seed,
                            estimator=est, attack=attack, design=ol_design if attack == "optimal-ol" else None,
                        )  # fmt: skip
                        fit = fit_empirical_complexity(grid, out["markov"])
                        d: Any
                        try:
                            d = empirical_design(fit, ThreatModel.of(p), reference=(ls_fit, paper.N_star))
                        except EncctlError as exc:  # a rate that does not decrease: reported, not designed
                            d = exc
                        rows.append(_row(system, label, sv, attack, est, grid, out["markov"], fit, d, paper.N_star, target))
                        print(f"  {system}, {label}, sigma_v2 = {sv:g}, {attack}, {est}: a = {fit.a:.3f}", file=sys.stderr)
    return rows


def _row(
    system: str,
    output: str,
    sigma_v2: float,
    attack: str,
    estimator: str,
    grid: np.ndarray,
    errors: np.ndarray,
    fit: Any,
    design: Any,
    paper_N_star: int,
    target: float,
) -> dict[str, Any]:
    row: dict[str, Any] = {
        "system": system,
        "output": output,
        "sigma_v2": sigma_v2,
        "attack": attack,
        "estimator": estimator,
        "runs": errors.shape[0],
        "N": grid.tolist(),
        "median": np.median(errors, axis=0).tolist(),
        "mean": errors.mean(axis=0).tolist(),
        "a": fit.a,
        "a_low": fit.a_interval[0],
        "a_high": fit.a_interval[1],
        "target": target,
        "paper_N_star": paper_N_star,
    }
    if isinstance(design, Exception):
        row.update(
            N_star="", N_star_low="", N_star_high="", k_star="", k_star_low="", k_star_high="", extrapolated="", note=str(design)
        )
    else:
        row.update(
            N_star=design.N_star,
            N_star_low=design.N_star_interval[0],
            N_star_high=design.N_star_interval[1],
            k_star=design.k_star,
            k_star_low=design.k_star_interval[0],
            k_star_high=design.k_star_interval[1],
            extrapolated=design.extrapolated,
            note="",
        )
    return row


def format_table(rows: list[dict[str, Any]]) -> str:
    """The markdown table of the rows."""
    head = (
        "| system | measured | sigma_v2 | attack | estimator | rate a [95 %] | N* [95 %] | k* (paper model) [95 %] |\n"
        "|---|---|---|---|---|---|---|---|"
    )
    lines = [head]
    for r in rows:
        if r["N_star"] == "":
            ns, ks = f"none ({r['note']})", "-"
        else:
            ext = " (extrapolated)" if r["extrapolated"] else ""
            ns = f"{r['N_star']} [{r['N_star_low']}, {r['N_star_high']}]{ext}"
            ks = f"{r['k_star']} [{r['k_star_low']}, {r['k_star_high']}]"
        lines.append(
            f"| {r['system']} | {r['output']} | {r['sigma_v2']:g} | {r['attack']} | {r['estimator']} | "
            f"{r['a']:.3f} [{r['a_low']:.3f}, {r['a_high']:.3f}] | {ns} | {ks} |"
        )
    return "\n".join(lines)


def write(
    rows: list[dict[str, Any]], out: Path, command: str = "python -m encctl_gym.experiments.output_identification"
) -> list[Path]:
    """CSV, markdown and figure of the rows into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    fields = [k for k in rows[0] if k not in ("N", "median", "mean")]
    csv_path = out / "output_identification.csv"
    with csv_path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([*fields, "N", "median", "mean"])
        for r in rows:
            w.writerow(
                [r[f] for f in fields]
                + [" ".join(map(str, r["N"])), " ".join(f"{v:.6g}" for v in r["median"]), " ".join(f"{v:.6g}" for v in r["mean"])]
            )
    md = out / "output_identification.md"
    md.write_text(
        f"# Identification from outputs\n\nCommand: `{command}`"
        f" ({rows[0]['runs']} runs per case). Target: the state least-squares Markov error at the paper's N*.\n\n"
        + format_table(rows)
        + "\n"
    )
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    systems = list(dict.fromkeys(r["system"] for r in rows))
    fig, axes = plt.subplots(
        len(systems), len(OUTPUTS), figsize=(4.2 * len(OUTPUTS), 3.4 * len(systems)), squeeze=False, sharey="row"
    )
    colors = {"n4sid": "tab:blue", "moesp": "tab:orange", "arx": "tab:green", "ls": "k"}
    for i, system in enumerate(systems):
        ref = next(r for r in rows if r["system"] == system and r["estimator"] == "ls")
        for j, label in enumerate(OUTPUTS):
            ax = axes[i, j]
            ax.plot(ref["N"], ref["mean"], color="k", lw=1.6, label="states, least squares")
            for r in rows:
                if r["system"] == system and r["output"] == label and r["attack"] == "gaussian":
                    ax.plot(
                        r["N"],
                        r["mean"],
                        color=colors[r["estimator"]],
                        ls="-" if r["sigma_v2"] == 0 else "--",
                        marker="o",
                        ms=2.5,
                        label=f"{r['estimator']}, sigma_v2 = {r['sigma_v2']:g}",
                    )
            for r in rows:  # the other attacks: N4SID on noise-free sensors
                other = r["attack"] != "gaussian" and r["estimator"] == "n4sid" and r["sigma_v2"] == 0
                if other and (r["system"], r["output"]) == (system, label):
                    ax.plot(r["N"], r["mean"], color=ATTACK_COLORS[r["attack"]], ls="-.", marker="s", ms=2.5,
                            label=f"n4sid, {r['attack']} attack, sigma_v2 = 0")  # fmt: skip
            ax.axhline(ref["target"], color="0.5", lw=0.8, ls=":", label="target (states at the paper's N*)")
            ax.set(xscale="log", yscale="log", title=f"{system}: {label}")
            ax.grid(True, which="major", alpha=0.3)
            if i == len(systems) - 1:
                ax.set_xlabel("attack length N")
            if j == 0:
                ax.set_ylabel("mean Markov-parameter error")
    bottom = legend_below(fig, axes, ncol=4)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    png = save_figure(fig, out / "output_identification.png", dpi=100)
    plt.close(fig)
    return [csv_path, md, png]


#: The systems of the eq:sic check: every distinct preset (the paper's design example and Figures
#: 1 and 2) and the shipped example plant file.
SIC_CHECK_SYSTEMS: tuple[str, ...] = (
    "paper-example", "small", *(f"fig1-{c}" for c in "abcdefghi"),
    *(f"fig2-psi{v}" for v in ("2", "1", "0.5", "0.3", "0.2", "0.1")), "examples/plant_output.yaml",
)  # fmt: skip


def sic_check(runs: int = 200, seed: int = 1, systems: tuple[str, ...] = SIC_CHECK_SYSTEMS) -> str:
    """eq:sic against the exact large-N mean error of least squares on the states (``C = I``, no
    measurement noise), ``sigma_w2 tr(Sigma^-1) / ((n + m) N)`` with the stationary regressor
    covariance ``Sigma``, and against the Monte Carlo mean; beside the closed form of their ratio
    (:func:`~encctl_gym.security.bayes_complexity.sic_tightness`). A markdown table, one row per
    system, each column the range over ``N = 400 .. 6400``."""
    from encctl_gym.security.bayes_complexity import sic_tightness, stationary_regressor_covariance
    from encctl_gym.security.complexity import sic_from_traces
    from encctl_gym.security.gramians import controllability_gramian, noise_gramian
    from encctl_gym.sim.montecarlo import gaussian_attack_errors

    grid = np.array([400, 800, 1600, 3200, 6400])
    lines = [
        f"# eq:sic against the exact large-N mean error\n\nCommand: `python -m encctl_gym.experiments.output_identification "
        f"--sic-check` ({runs} Gaussian attacks per system, least squares on the states, N = 400 .. 6400; 95 % bootstrap "
        "band). Exact: sigma_w2 tr(Sigma^-1) / ((n + m) N), Sigma the stationary regressor covariance. HM/AM: the "
        "harmonic over the arithmetic mean of Sigma's eigenvalues, the closed-form large-N ratio of eq:sic to the exact "
        "mean (`sic_tightness`). Each cell is the range over the five sample sizes.\n",
        "| system | n, m | sigma_u2 / sigma_w2 | HM/AM | eq:sic / exact | eq:sic / Monte Carlo mean | Monte Carlo mean / exact | "
        "eq:sic below the band |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for system in systems:
        ps = system_preset(system)
        A, B, su, sw, sx = ps.A, ps.B, ps.sigma_u2, ps.sigma_w2, ps.sigma_x2
        n, m = B.shape
        errors = gaussian_attack_errors(LinearPlant(A, B, sigma_w2=sw, sigma_x2=sx), sample_sizes=grid, runs=runs,
                                        sigma_u2=su, seed=seed)  # fmt: skip
        fit = fit_empirical_complexity(grid, errors)
        S = stationary_regressor_covariance(A, B, sigma_u2=su, sigma_w2=sw)
        exact = sw * np.trace(np.linalg.inv(S)) / (n + m) / grid
        tr_u, tr_w = np.trace(controllability_gramian(A, B)), np.trace(noise_gramian(A))
        sic = np.asarray(sic_from_traces(grid, tr_u, tr_w, m, n, su, sw, sx))

        def span(v: np.ndarray) -> str:
            return f"{v.min():.3f} to {v.max():.3f}"

        below = int(np.sum(sic < fit.low))
        lines.append(
            f"| {system} | {n}, {m} | {su / sw:g} | {sic_tightness(A, B, sigma_u2=su, sigma_w2=sw):.3f} | {span(sic / exact)} | "
            f"{span(sic / fit.mean)} | {span(fit.mean / exact)} | {below} of {len(grid)} |"
        )
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m encctl_gym.experiments.output_identification", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--runs", type=int, default=20, help="attacks per case and N (default 20)")
    parser.add_argument("--points", type=int, default=6, help="sample sizes on the log grid (default 6)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--quick", action="store_true", help="4 runs, 4 points up to N = 2000")
    parser.add_argument("--out", type=Path, default=Path("results/output_identification"))
    parser.add_argument(
        "--attacks",
        default=",".join(OUTPUT_ATTACKS),
        help=f"comma-separated attacks to run (default all: {','.join(OUTPUT_ATTACKS)})",
    )
    parser.add_argument("--sic-check", action="store_true", help="only the check of eq:sic against the exact mean (sic_check.md)")
    args = parser.parse_args(argv)
    if args.sic_check:
        text = sic_check()
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "sic_check.md").write_text(text)
        print(text + f"  wrote {args.out / 'sic_check.md'}")
        return 0
    runs, points, n_max = (4, 4, 2000) if args.quick else (args.runs, args.points, None)
    attacks = tuple(a.strip() for a in args.attacks.split(","))
    if not attacks or any(a not in OUTPUT_ATTACKS for a in attacks):
        print(
            f"output_identification: --attacks must name some of {', '.join(OUTPUT_ATTACKS)}, got {args.attacks!r}",
            file=sys.stderr,
        )
        return 2
    if runs < 2 or points < 3:  # an interval needs two runs, a fitted rate three sizes
        print(f"output_identification: --runs must be >= 2 and --points >= 3, got {runs} and {points}", file=sys.stderr)
        return 2
    try:
        rows = run(runs, points, n_max, args.seed, attacks)
        shown = " ".join(argv if argv is not None else sys.argv[1:])
        paths = write(rows, args.out, f"python -m encctl_gym.experiments.output_identification {shown}".strip())
    except EncctlError as exc:
        print(f"output_identification: {exc}", file=sys.stderr)
        return 2
    print(format_table(rows))
    for p in paths:
        print(f"  wrote {p}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
