"""The defender's levers in closed form: what each buys against the attack and what it costs.

Thin over :mod:`encctl_gym.security.defenses`; for the design example (``paper-example``) and
Figure 1 (c) (``fig1-c``):

* **Input noise** ``sigma_d2`` in {0, sigma_w2, 10 sigma_w2, sigma_u2}: ``N*``, ``lambda*`` and ``k*``
  (paper model) from eq:sic generalised to the defender's noise, and the price in normal operation
  under the loop's LQR controller (``Q = I``, ``R = I``): the stationary ``tr P`` and quadratic cost.
* **Audits**: the rate ``p* = 1 - delta^(1/N*)`` that stops an attacker injecting at every step
  before ``N*`` with probability ``1 - delta``, for delta in {1e-2, 1e-3, 1e-6}.

    python -m experiments.defenses [--out results/defenses]

Prints both tables and writes them as ``defenses_analytic.md``. (The measurements of the
defences in the environment need the defender in the loop and are not part of this script.)
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from encctl_gym.errors import EncctlError
from encctl_gym.loop.backend import lqr_gain
from encctl_gym.presets import get_preset
from encctl_gym.security.defenses import minimum_audit_rate, noise_defense_design, noise_defense_price

SYSTEMS = ("paper-example", "fig1-c")
DELTAS = (1e-2, 1e-3, 1e-6)


def noise_rows() -> list[dict[str, float | int | str]]:
    """One row per system and noise level (the first table)."""
    rows: list[dict[str, float | int | str]] = []
    for system in SYSTEMS:
        p = get_preset(system)
        Phi = -lqr_gain(p.A, p.B)
        for label, sd in (("0", 0.0), ("sigma_w2", p.sigma_w2), ("10 sigma_w2", 10 * p.sigma_w2), ("sigma_u2", p.sigma_u2)):
            d = noise_defense_design(p.plant(), p.threat(), sigma_d2=sd)
            price = noise_defense_price(p.A, p.B, Phi, sigma_w2=p.sigma_w2, sigma_d2=sd)
            rows.append(
                {
                    "system": system,
                    "noise": label,
                    "sigma_d2": sd,
                    "N_star": d.N_star,
                    "lambda_star": d.lam_star,
                    "k_star": d.k_star,
                    "trace_P": price["trace_P_defended"],
                    "trace_P_ratio": price["trace_P_defended"] / price["trace_P_base"],
                    "cost_ratio": price["cost_defended"] / price["cost_base"],
                }
            )
    return rows


def audit_rows(noise: list[dict[str, float | int | str]]) -> list[dict[str, float | int | str]]:
    """The audit rate per system (its undefended ``N*``) and delta (the second table)."""
    rows: list[dict[str, float | int | str]] = []
    for r in noise:
        if r["noise"] != "0":
            continue
        for delta in DELTAS:
            rows.append(
                {
                    "system": r["system"],
                    "N_star": r["N_star"],
                    "delta": delta,
                    "audit_rate": minimum_audit_rate(int(r["N_star"]), delta),
                }
            )
    return rows


def format_tables(noise: list[dict[str, float | int | str]], audits: list[dict[str, float | int | str]]) -> str:
    """Both tables as markdown."""
    out = [
        "| system | defender noise sigma_d2 | N* | lambda* | k* (paper model) | tr P (normal operation) | tr P / undefended | LQ cost / undefended |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in noise:
        level = "0 (none)" if r["noise"] == "0" else f"{r['noise']} = {float(r['sigma_d2']):g}"
        out.append(
            f"| {r['system']} | {level} | {r['N_star']} | {r['lambda_star']} | {r['k_star']} | "
            f"{float(r['trace_P']):.4g} | {float(r['trace_P_ratio']):.3g} | {float(r['cost_ratio']):.3g} |"
        )
    out += ["", "| system | N* | delta | audit rate p* = 1 - delta^(1/N*) |", "|---|---|---|---|"]
    for r in audits:
        out.append(f"| {r['system']} | {r['N_star']} | {float(r['delta']):g} | {float(r['audit_rate']):.4g} |")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m experiments.defenses", description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/defenses"))
    args = parser.parse_args(argv)
    try:
        noise = noise_rows()
        text = format_tables(noise, audit_rows(noise))
    except EncctlError as exc:
        print(f"defenses: {exc}", file=sys.stderr)
        return 2
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "defenses_analytic.md"
    path.write_text("# The defender's levers in closed form\n\nCommand: `python -m experiments.defenses`\n\n" + text + "\n")
    print(f"  wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
