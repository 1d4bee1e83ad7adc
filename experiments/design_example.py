"""The design example of Section "Numerical Simulation" (Theorem thm:opt_sec, eq:opt_key), under every cost model.

``Psi_w = 2I``, ``Psi_u = 0.5I``, ``R_sigma = 100`` (``n = m = 4``), ``gamma_c = 1e-6``,
``tau_c = 31536e4 s`` (10 years) and ``Upsilon = 442e15 FLOPS`` (Fugaku). The paper reports
``N* = 13159``, ``lambda* = 74`` bit and ``k* = 712`` bit. Every number here is computed by
:mod:`encctl_gym.security`; this script only tabulates them:

1. the paper's design from the Gramian traces with eq:sic2 (the paper's computation) and eq:sic,
   and from the plant realising the Gramians (preset ``paper-example``: ``A = I/sqrt(2)``,
   ``B = 0.5 I``, Lyapunov solves);
2. the key length ``k*`` under each deciphering-cost model (:mod:`encctl_gym.security.key_length`),
   without and with the GNFS correction of 11.91 bits;
3. what the paper's 712-bit key is worth under each model;
4. how many bits the dynamic keys add under the precomputation model as the sample size grows
   (``log2(1 + N 2^-r) - log2(1 + 2^-r)``, against the paper's ``log2 N``).

Usage: ``python experiments/design_example.py [--out DIR]`` (also ``encctl-gym reproduce``).
Writes ``design_example.csv`` and ``design_example_cost_models.csv``.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from encctl_gym.experiments.common import add_common_arguments, ensure_out_dir, entry_point
from encctl_gym.presets import PAPER_DESIGN_PARAMETERS, PAPER_REPORTED, get_preset
from encctl_gym.security.cost_models import DECIPHERING_MODELS, GUILLEVIC_CORRECTION
from encctl_gym.security.design import SecurityDesign, design_security_parameter, paper_design_example
from encctl_gym.security.key_length import KeyLengthDesign, KeyValue, build_model, design_key_length, key_length_value
from encctl_gym.security.threat import ThreatModel

__all__ = [
    "PAPER_VALUES",
    "compute",
    "cost_model_designs",
    "key_values",
    "dynamic_key_bits",
    "format_table",
    "format_cost_models",
    "add_arguments",
    "run",
    "main",
]

#: What the paper reports.
PAPER_VALUES = PAPER_REPORTED

#: Sample sizes of the dynamic-key table (the design example's N* first).
DYNAMIC_KEY_SAMPLES = (13159, 10**5, 10**6, 10**7, 10**8, 10**10)


def _threat(cost_model: Any) -> ThreatModel:
    """The design example's defense period and adversary under ``cost_model``."""
    return ThreatModel(tau_c=PAPER_DESIGN_PARAMETERS["tau_c"], upsilon=PAPER_DESIGN_PARAMETERS["upsilon"], cost_model=cost_model)


def compute() -> list[tuple[str, SecurityDesign]]:
    """The design example by the security module, three ways.

    Returns
    -------
    list of (str, SecurityDesign)
        ``("traces, eq:sic2", ...)`` (the paper's Theorem thm:opt_sec), ``("traces, eq:sic", ...)``
        and ``("plant paper-example, eq:sic2", ...)``.
    """
    p = get_preset("paper-example")
    plant = design_security_parameter(p.plant(), ThreatModel.of(p))
    return [
        ("traces, eq:sic2 (paper)", paper_design_example("asymptotic")),
        ("traces, eq:sic", paper_design_example("exact")),
        ("plant paper-example, eq:sic2", plant),
    ]


def cost_model_designs(N_star: int | None = None) -> list[KeyLengthDesign]:
    """``k*`` of the design example under every model, without and with the 11.91-bit GNFS correction
    (the generic model has no GNFS term and appears once)."""
    N = paper_design_example().N_star if N_star is None else N_star
    rows = []
    for correction in (0.0, GUILLEVIC_CORRECTION):
        for name in DECIPHERING_MODELS:
            if name == "generic" and correction:
                continue
            rows.append(design_key_length(N, _threat(build_model(name, correction))))
    return rows


def key_values(key_length: int | None = None) -> list[KeyValue]:
    """What the paper's ``k*`` (or ``key_length``) is worth under every model (no correction)."""
    d = paper_design_example()
    k = d.k_star if key_length is None else key_length
    return [key_length_value(k, _threat(name), N_star=d.N_star) for name in DECIPHERING_MODELS]


def dynamic_key_bits(samples: Sequence[int] = DYNAMIC_KEY_SAMPLES) -> list[tuple[int, float, int, float]]:
    """For each sample size ``N``: ``log2 N`` (what the dynamic keys add under the paper's cost), the
    precomputation model's ``k*`` for ``N`` and the bits the dynamic keys add there."""
    out = []
    for N in samples:
        d = design_key_length(N, _threat("precomputation"))
        out.append((N, math.log2(N), d.k_star, d.dynamic_key_bits))
    return out


def format_table(rows: Sequence[tuple[str, SecurityDesign]]) -> str:
    """A plain-text table of ``N*``, ``lambda*``, ``k*`` next to the paper's values."""
    head = f"{'computation':32s} {'N*':>7s} {'lambda*':>8s} {'k*':>6s} {'gamma(N*)':>11s} {'log2 Omega(k*)':>15s}"
    lines = [head, "-" * len(head)]
    lines.append(f"{'paper':32s} {PAPER_VALUES['N_star']:7d} {PAPER_VALUES['lam_star']:8d} {PAPER_VALUES['k_star']:6d}")
    for label, d in rows:
        lines.append(f"{label:32s} {d.N_star:7d} {d.lam_star:8d} {d.k_star:6d} {d.gamma_at_N_star:11.4e} {d.bit_security:15.2f}")
    return "\n".join(lines)


def format_cost_models(
    designs: Sequence[KeyLengthDesign], values: Sequence[KeyValue], dynamic: Sequence[tuple[int, float, int, float]]
) -> str:
    """The three cost-model tables as text."""
    lines = [
        f"budget Upsilon tau_c = 2^{designs[0].budget_bits:.3f} operations",
        f"{'model':16s} {'GNFS corr.':>10s} {'N*':>7s} {'k*':>6s} {'paper k*':>8s} {'work(N*)':>9s} "
        f"{'first key':>9s} {'next key':>9s} {'dyn. keys':>9s} {'NIST k':>7s}",
    ]
    for d in designs:
        nist = "-" if d.nist_key_length is None else str(d.nist_key_length)
        lines.append(
            f"{d.model:16s} {d.gnfs_correction:10.2f} {d.N_star:7d} {d.k_star:6d} {d.paper_k_star:8d} {d.work_bits:9.3f} "
            f"{d.first_key_bits:9.3f} {d.next_key_bits:9.3f} {d.dynamic_key_bits:9.3f} {nist:>7s}"
        )
    k = values[0].key_length
    lines += [
        "",
        f"a {k}-bit key (no correction): {'model':16s} {'first key':>9s} {'next key':>9s} "
        f"{'log2 N in tau_c':>15s} {'secure':>6s}",
    ]
    for v in values:
        n = "-inf" if v.log2_affordable_samples == -math.inf else f"{v.log2_affordable_samples:.3f}"
        lines.append(
            f"{'':30s}{v.model:16s} {v.first_key_bits:9.3f} {v.next_key_bits:9.3f} {n:>15s} {'yes' if v.secure else 'no':>6s}"
        )
    lines += ["", f"{'N':>12s} {'log2 N':>7s} {'precomputation k*':>18s} {'dyn. keys there':>16s}"]
    for N, log_n, k_star, dyn in dynamic:
        lines.append(f"{N:12d} {log_n:7.3f} {k_star:18d} {dyn:16.3f}")
    return "\n".join(lines)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Command-line options (the common ones; only ``--out`` matters here)."""
    add_common_arguments(parser)


def run(args: argparse.Namespace) -> int:
    """Print the tables and write ``design_example.csv`` and ``design_example_cost_models.csv`` under ``args.out``."""
    out = ensure_out_dir(args.out)
    rows = compute()
    print("Design example (Theorem thm:opt_sec, eq:opt_key): Psi_w = 2I, Psi_u = 0.5I, R_sigma = 100,")
    print("gamma_c = 1e-6, tau_c = 31536e4 s, Upsilon = 442e15 FLOPS")
    print(format_table(rows))
    path = out / "design_example.csv"
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        fields: list[Any] = [
            "computation",
            "N_star",
            "lam_star",
            "k_star",
            "gamma_at_N_star",
            "bit_security",
            "tr_psi_u",
            "tr_psi_w",
            "r_sigma",
            "gamma_c",
            "tau_c",
            "upsilon",
        ]
        w.writerow(fields)
        w.writerow(["paper", PAPER_VALUES["N_star"], PAPER_VALUES["lam_star"], PAPER_VALUES["k_star"]] + [""] * 8)
        for label, d in rows:
            dd = d.to_dict()
            w.writerow([label] + [repr(dd[f]) for f in fields[1:]])
    print(f"  wrote {path}")
    designs, values, dynamic = cost_model_designs(), key_values(), dynamic_key_bits()
    print("\nThe same design under the deciphering-cost models (encctl_gym.security.cost_models):")
    print(format_cost_models(designs, values, dynamic))
    path = out / "design_example_cost_models.csv"
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        fields = list(designs[0].to_dict())
        w.writerow(fields)
        for kd in designs:
            dd = kd.to_dict()
            w.writerow([repr(dd[f]) if isinstance(dd[f], float) else dd[f] for f in fields])
    print(f"  wrote {path}")
    return 0


main = entry_point("design_example", __doc__, add_arguments, run)


if __name__ == "__main__":
    sys.exit(main())
