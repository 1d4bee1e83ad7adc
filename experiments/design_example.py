"""The design example of Section "Numerical Simulation" (Theorem thm:opt_sec, eq:opt_key).

``Psi_w = 2I``, ``Psi_u = 0.5I``, ``R_sigma = 100`` (``n = m = 4``), ``gamma_c = 1e-6``,
``tau_c = 31536e4 s`` (10 years) and ``Upsilon = 442e15 FLOPS`` (Fugaku). The paper reports
``N* = 13159``, ``lambda* = 74`` bit and ``k* = 712`` bit. Every number here is computed by
:mod:`encctl_gym.security.design`; this script only tabulates them: from the Gramian traces with
eq:sic2 (the paper's computation) and eq:sic, and from the plant realising the Gramians
(preset ``paper-example``: ``A = I/sqrt(2)``, ``B = 0.5 I``, Lyapunov solves).

Usage: ``python experiments/design_example.py [--out DIR]`` (also ``encctl-gym reproduce``).
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path
from typing import Any, Sequence

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from encctl_gym.presets import get_preset
from encctl_gym.security.design import SecurityDesign, design_security_parameter, paper_design_example
from experiments.common import add_common_arguments, ensure_out_dir, script_main

__all__ = ["PAPER_VALUES", "compute", "format_table", "add_arguments", "run", "main"]

#: What the paper reports.
PAPER_VALUES = {"N_star": 13159, "lam_star": 74, "k_star": 712}


def compute() -> list[tuple[str, SecurityDesign]]:
    """The design example by the security module, three ways.

    Returns
    -------
    list of (str, SecurityDesign)
        ``("traces, eq:sic2", ...)`` (the paper's Theorem thm:opt_sec), ``("traces, eq:sic", ...)``
        and ``("plant paper-example, eq:sic2", ...)``.
    """
    p = get_preset("paper-example")
    plant = design_security_parameter(
        p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2, sigma_x2=p.sigma_x2,
        gamma_c=p.gamma_c, tau_c=p.tau_c, upsilon=p.upsilon,
    )
    return [
        ("traces, eq:sic2 (paper)", paper_design_example("asymptotic")),
        ("traces, eq:sic", paper_design_example("exact")),
        ("plant paper-example, eq:sic2", plant),
    ]


def format_table(rows: Sequence[tuple[str, SecurityDesign]]) -> str:
    """A plain-text table of ``N*``, ``lambda*``, ``k*`` next to the paper's values."""
    head = f"{'computation':32s} {'N*':>7s} {'lambda*':>8s} {'k*':>6s} {'gamma(N*)':>11s} {'log2 Omega(k*)':>15s}"
    lines = [head, "-" * len(head)]
    lines.append(
        f"{'paper':32s} {PAPER_VALUES['N_star']:7d} {PAPER_VALUES['lam_star']:8d} {PAPER_VALUES['k_star']:6d}"
    )
    for label, d in rows:
        lines.append(
            f"{label:32s} {d.N_star:7d} {d.lam_star:8d} {d.k_star:6d} {d.gamma_at_N_star:11.4e} {d.bit_security:15.2f}"
        )
    return "\n".join(lines)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Command-line options (the common ones; only ``--out`` matters here)."""
    add_common_arguments(parser)


def run(args: argparse.Namespace) -> int:
    """Print the table and write ``design_example.csv`` under ``args.out``."""
    out = ensure_out_dir(args.out)
    rows = compute()
    print("Design example (Theorem thm:opt_sec, eq:opt_key): Psi_w = 2I, Psi_u = 0.5I, R_sigma = 100,")
    print("gamma_c = 1e-6, tau_c = 31536e4 s, Upsilon = 442e15 FLOPS")
    print(format_table(rows))
    path = out / "design_example.csv"
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        fields: list[Any] = ["computation", "N_star", "lam_star", "k_star", "gamma_at_N_star", "bit_security",
                             "tr_psi_u", "tr_psi_w", "r_sigma", "gamma_c", "tau_c", "upsilon"]
        w.writerow(fields)
        w.writerow(["paper", PAPER_VALUES["N_star"], PAPER_VALUES["lam_star"], PAPER_VALUES["k_star"]] + [""] * 8)
        for label, d in rows:
            dd = d.to_dict()
            w.writerow([label] + [repr(dd[f]) for f in fields[1:]])
    print(f"  wrote {path}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``python experiments/design_example.py``."""
    return script_main("design_example", __doc__, add_arguments, run, argv)


if __name__ == "__main__":
    sys.exit(main())
