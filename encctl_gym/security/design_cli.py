"""Optimal security parameter and key length for a plant (Theorem thm:opt_sec, eq:opt_key), under every cost model.

Usage::

    encctl-gym design SYSTEM_FILE [--gamma-c 1e-6] [--tau-c 10y] [--upsilon 442e15]
                                  [--sigma-u2 10] [--sigma-w2 0.1] [--sigma-x2 1] [--json]
    encctl-gym design --preset paper-example [--cost-model paper|precomputation|generic|all]
                      [--gnfs-correction BITS|guillevic] [--complexity sic2] [--key-length 712]

``SYSTEM_FILE`` is a plant file (:mod:`encctl_gym.plant_file`): JSON, YAML or NPZ with ``A``, ``B``
and optionally ``sigma_u2``, ``sigma_w2``, ``sigma_x2``, ``gamma_c``, ``tau_c``, ``upsilon``. A value
given on the command line overrides the file (or preset), which overrides the defaults: the
paper's design example (gamma_c = 1e-6, tau_c = 10 years = 31536e4 s, Upsilon = 442e15 FLOPS
(Fugaku), sigma_u2 = 10, sigma_w2 = 0.1, sigma_x2 = 1). For a file, the output says which values
came from where. ``--tau-c`` accepts units (:func:`encctl_gym.units.parse_duration`): ``10y``
(1 y = 365 d), ``5d``, ``2h``, ``30min``, ``3600s`` or plain seconds.

The first table compares N*, lam*, k* for (a) the paper's eq:sic2 (Theorem thm:opt_sec), (b) the
exact eq:sic, (c) the A-optimal closed-loop attack gamma_opt, (d) the A-optimal open-loop attack
and (e) i.i.d. Gaussian inputs with the sharper tr(Sigma^-1) bound (see
:mod:`encctl_gym.security.attack_design`), with each one's ratio to the paper's gamma; all under
the paper's cost (2^lam per key, GNFS key length). Rows (c) and (d) solve an SDP whose cost grows
as (n+m)^4.75; above ``--sdp-max-dim`` (default 48) they are skipped with the estimate, and the
command refuses plants with n > 1000 before any solve.

``--cost-model`` adds one row per deciphering-cost model (:mod:`encctl_gym.security.cost_models`)
for the N* of ``--complexity``: the bits of work the adversary needs for N* samples at k*, k*,
the paper's k* beside it, the cost of the first and of each further key, the bits the dynamic keys
add, and the NIST SP 800-57 key length for the first key's strength; then what a ``--key-length``
key (default: the paper's k*) is worth under each model, and the published records the
precomputation model is calibrated on (``--calibration FILE`` replaces them).
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from .._validation import (
    check_int,
    check_nonnegative,
    check_positive,
    check_schur_stable,
    check_system,
    format_value,
    parse_number,
)
from ..errors import ConfigError, ParameterError, ResourceLimitError
from ..plant_file import load_plant_file, load_system
from ..presets import DESIGN_FIELDS, design_defaults, get_preset, preset_names
from ..units import SECONDS_PER_UNIT, parse_duration
from .attack_design import SDP_MAX_DIMENSION, gaussian_attack_design, optimal_attack_design, robust_security_design
from .complexity import input_upper_bound, noise_upper_bound, sic_asymptotic_from_traces, sic_from_traces
from .cost_models import DECIPHERING_MODELS, GUILLEVIC_CORRECTION, check_gnfs_correction, gnfs_log2_complexity
from .design import SecurityDesign, design_from_traces
from .gramians import controllability_gramian, noise_gramian
from .key_length import build_model, design_key_length, key_length_value
from .records import RecordSet, default_records, load_records

__all__ = [
    "add_arguments",
    "run",
    "parse_duration",
    "load_system",
    "DEFAULTS",
    "compute",
    "COMPLEXITIES",
    "MAX_STATE_DIMENSION",
    "parse_cost_models",
    "parse_gnfs_correction",
]

#: Option defaults: the paper's design example (from :mod:`encctl_gym.presets`).
DEFAULTS: dict[str, Any] = design_defaults()

#: Largest state dimension the command accepts: the Lyapunov solves grow as n^3
#: (n = m = 1000 took 18 s on the development machine).
MAX_STATE_DIMENSION: int = 1000
_LYAPUNOV_REF = (1000, 18.0)

#: ``--complexity`` choices -> key of the designs table.
COMPLEXITIES: dict[str, str] = {
    "sic2": "paper_sic2",
    "sic": "exact_sic",
    "closed_loop": "closed_loop",
    "open_loop": "open_loop",
    "gaussian": "gaussian",
}

LABELS = {
    "paper_sic2": "(a) eq:sic2, paper (thm:opt_sec)",
    "exact_sic": "(b) eq:sic exact",
    "closed_loop": "(c) gamma_opt closed loop",
    "open_loop": "(d) gamma_opt open loop",
    "gaussian": "(e) Gaussian, tr(Sigma^-1)",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the options of ``encctl-gym design``."""
    parser.add_argument(
        "system_file",
        nargs="?",
        metavar="SYSTEM_FILE",
        help="plant file: JSON/YAML ({'A': [[...]], 'B': [[...]]}, optional sigma_u2, sigma_w2, "
        "sigma_x2, gamma_c, tau_c, upsilon) or NPZ with the same names",
    )
    parser.add_argument(
        "--preset",
        choices=preset_names(),
        metavar="NAME",
        help="use a preset plant (with its variances and design parameters) instead of a file: " + ", ".join(preset_names()),
    )
    parser.add_argument("--gamma-c", dest="gamma_c", metavar="G", help="acceptable estimation error gamma_c (default 1e-6)")
    parser.add_argument(
        "--tau-c", dest="tau_c", metavar="T", help="defense period: 10y, 5d, 2h, 30min, 3600s or seconds (default 10y)"
    )
    parser.add_argument("--upsilon", metavar="FLOPS", help="adversary computing speed in FLOPS (default 442e15)")
    parser.add_argument("--sigma-u2", dest="sigma_u2", metavar="V", help="attack input variance (default 10)")
    parser.add_argument("--sigma-w2", dest="sigma_w2", metavar="V", help="noise variance (default 0.1)")
    parser.add_argument("--sigma-x2", dest="sigma_x2", metavar="V", help="initial-state variance (default 1)")
    parser.add_argument("--solver", metavar="NAME", help="cvxpy solver for the attack designs (default Clarabel, then SCS)")
    parser.add_argument(
        "--sdp-max-dim",
        dest="sdp_max_dim",
        metavar="P",
        help=f"largest n + m for the attack-design SDPs of rows (c), (d) (default {SDP_MAX_DIMENSION}; "
        "larger plants skip those rows with an estimate)",
    )
    parser.add_argument(
        "--cost-model",
        dest="cost_model",
        metavar="MODEL",
        help="add the key length under deciphering-cost models: "
        + ", ".join(DECIPHERING_MODELS)
        + ", all, or a comma-separated list",
    )
    parser.add_argument(
        "--gnfs-correction",
        dest="gnfs_correction",
        metavar="BITS",
        help="o(1) correction of the GNFS cost in bits for the paper and precomputation models "
        f"(default 0, the paper's numbers; 'guillevic' = {GUILLEVIC_CORRECTION:g})",
    )
    parser.add_argument(
        "--complexity",
        choices=list(COMPLEXITIES),
        default="sic2",
        help="which N* the cost-model rows protect (default sic2, the paper's)",
    )
    parser.add_argument(
        "--key-length",
        dest="key_length",
        metavar="K",
        help="key length whose worth the cost-model section shows (default: the paper's k*)",
    )
    parser.add_argument(
        "--calibration",
        metavar="FILE",
        help="records file (layout of security/data/deciphering_records.json) for the precomputation model's per-key ratio",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")


# --------------------------------------------------------------------------- option parsing
def parse_cost_models(text: Any) -> tuple[str, ...]:
    """``"all"``, a model name or a comma-separated list of names -> model names.

    Raises
    ------
    ParameterError
        For an unknown name.
    """
    if not isinstance(text, str) or not text.strip():
        raise ParameterError(f"cost model must be one of {', '.join(DECIPHERING_MODELS)} or all, got {format_value(text)}")
    names = [t.strip() for t in text.split(",")]
    if names == ["all"]:
        return tuple(DECIPHERING_MODELS)
    bad = [t for t in names if t not in DECIPHERING_MODELS]
    if bad:
        raise ParameterError(f"unknown cost model(s) {bad}; choose from {', '.join(DECIPHERING_MODELS)} or all")
    return tuple(dict.fromkeys(names))


def parse_gnfs_correction(text: Any) -> float:
    """A GNFS correction from the command line: a number of bits or ``"guillevic"``."""
    if isinstance(text, str) and text.strip().lower() == "guillevic":
        return GUILLEVIC_CORRECTION
    return check_gnfs_correction(parse_number("gnfs_correction", text))


def _check_size(n: int, m: int) -> None:
    if n > MAX_STATE_DIMENSION:
        ref_n, ref_s = _LYAPUNOV_REF
        raise ResourceLimitError(
            f"the plant has n = {n} states; the design command accepts n <= {MAX_STATE_DIMENSION} (its Lyapunov "
            f"solves grow as n^3: {ref_s:g} s at n = {ref_n} on the development machine, so about "
            f"{ref_s * (n / ref_n) ** 3:.3g} s here)"
        )


# --------------------------------------------------------------------------- computation
def _cost_model_section(
    designs: dict[str, SecurityDesign],
    *,
    models: Sequence[str],
    complexity: str,
    gnfs_correction: float,
    key_length: Any,
    records: RecordSet,
    tau_c: float,
    upsilon: float,
) -> dict[str, Any]:
    key = COMPLEXITIES[complexity]
    if key not in designs:
        raise ParameterError(f"--complexity {complexity} was skipped for this plant (see the table); choose another")
    N_star = designs[key].N_star
    out_designs = {}
    for name in models:
        d = design_key_length(name, N_star, tau_c=tau_c, upsilon=upsilon, gnfs_correction=gnfs_correction, calibration=records)
        out_designs[name] = d.to_dict()
    k_val = designs[key].k_star if key_length is None else check_int("key_length", key_length)
    values = {
        name: key_length_value(
            name, k_val, N_star=N_star, tau_c=tau_c, upsilon=upsilon, gnfs_correction=gnfs_correction, calibration=records
        ).to_dict()
        for name in models
    }
    first = next(iter(out_designs.values()))
    return {
        "complexity": complexity,
        "N_star": N_star,
        "budget_bits": first["budget_bits"],
        "gnfs_correction": gnfs_correction,
        "designs": out_designs,
        "key_value": {"key_length": k_val, "models": values},
    }


def _records_section(records: RecordSet) -> dict[str, Any]:
    out = records.to_dict()
    for r, entry in zip(records.records, out["records"]):
        entry["formula_bits"] = float(gnfs_log2_complexity(r.key_length))
        entry["formula_minus_record_bits"] = None if r.log2_operations is None else entry["formula_bits"] - r.log2_operations
    for row in out["nist_sp800_57"]["rows"]:
        row["formula_bits"] = float(gnfs_log2_complexity(row["key_length"]))
        row["formula_guillevic_bits"] = float(gnfs_log2_complexity(row["key_length"], GUILLEVIC_CORRECTION))
    return out


def compute(
    A: Any,
    B: Any,
    *,
    gamma_c: float,
    tau_c: float,
    upsilon: float,
    sigma_u2: float,
    sigma_w2: float,
    sigma_x2: float = 1.0,
    solver: str | None = None,
    sdp_max_dimension: int | None = None,
    cost_models: Sequence[str] | None = None,
    gnfs_correction: Any = 0.0,
    complexity: str = "sic2",
    key_length: Any = None,
    calibration: RecordSet | None = None,
) -> dict[str, Any]:
    """All quantities of the ``design`` output as a JSON-ready dict.

    Parameters
    ----------
    A, B : array_like
        Plant (``A`` Schur stable, ``n <= 1000``).
    gamma_c, tau_c, upsilon, sigma_u2, sigma_w2, sigma_x2 : float
        Design parameters (see the module docstring).
    solver : str, optional
        cvxpy solver for the attack designs.
    sdp_max_dimension : int, optional
        Largest ``n + m`` for the SDP rows (default :data:`~encctl_gym.security.attack_design.SDP_MAX_DIMENSION`).
    cost_models : sequence of str, optional
        Models for the cost-model section (none by default).
    gnfs_correction : float, default 0.0
        o(1) correction of the GNFS formula in the cost-model section.
    complexity : str, default "sic2"
        Which N* the cost-model section protects (:data:`COMPLEXITIES`).
    key_length : int, optional
        Key length valued in the cost-model section (default: the paper's k*).
    calibration : RecordSet, optional
        Records for the precomputation model (default: the shipped ones).

    Returns
    -------
    dict
        ``system``, ``parameters``, ``bounds``, ``designs`` (one :meth:`SecurityDesign.to_dict`
        per method with ``ratio_to_paper``), ``skipped`` (rows not computed, with the reason),
        and with ``cost_models`` also ``cost_models`` and ``records``.
    """
    A, B = check_system(A, B)
    n, m = B.shape
    _check_size(n, m)
    rho = check_schur_stable(A)
    gamma_c = check_positive("gamma_c", gamma_c)
    tau_c = check_positive("tau_c", tau_c)
    upsilon = check_positive("upsilon", upsilon)
    su = check_positive("sigma_u2", sigma_u2)
    sw = check_positive("sigma_w2", sigma_w2)
    sx = check_nonnegative("sigma_x2", sigma_x2)
    if not isinstance(complexity, str) or complexity not in COMPLEXITIES:
        raise ParameterError(f"unknown complexity {format_value(complexity)}; choose one of {', '.join(COMPLEXITIES)}")
    c = check_gnfs_correction(gnfs_correction)
    tr_u = float(np.trace(controllability_gramian(A, B)))
    tr_w = float(np.trace(noise_gramian(A)))
    kw: dict[str, Any] = dict(gamma_c=gamma_c, tau_c=tau_c, upsilon=upsilon)
    designs: dict[str, SecurityDesign] = {
        "paper_sic2": design_from_traces(tr_u, tr_w, m, n, sigma_u2=su, sigma_w2=sw, sigma_x2=sx, method="asymptotic", **kw),
        "exact_sic": design_from_traces(tr_u, tr_w, m, n, sigma_u2=su, sigma_w2=sw, sigma_x2=sx, method="exact", **kw),
    }
    attacks: dict[str, Any] = {}
    skipped: dict[str, str] = {}
    for kind, feedback in (("closed_loop", True), ("open_loop", False)):
        try:
            attacks[kind] = optimal_attack_design(
                A, B, sigma_u2=su, sigma_w2=sw, feedback=feedback, solver=solver, max_dimension=sdp_max_dimension
            )
        except ResourceLimitError as exc:
            skipped[kind] = str(exc)
    attacks["gaussian"] = gaussian_attack_design(A, B, sigma_u2=su, sigma_w2=sw)
    for kind, att in attacks.items():
        designs[kind] = robust_security_design(A, B, sigma_u2=su, sigma_w2=sw, sigma_x2=sx, kind=kind, design=att, **kw)
    designs = {k: designs[k] for k in LABELS if k in designs}
    N_ref = designs["paper_sic2"].N_star
    g_ref = float(sic_asymptotic_from_traces(N_ref, tr_u, tr_w, m, n, su / sw))
    ratios = {
        "paper_sic2": 1.0,
        "exact_sic": float(sic_from_traces(N_ref, tr_u, tr_w, m, n, su, sw, sx)) / g_ref,
        **{kind: float(att.gamma(N_ref)) / g_ref for kind, att in attacks.items()},
    }
    out_designs = {}
    for name, d in designs.items():
        entry = d.to_dict()
        entry["ratio_to_paper"] = ratios[name]
        if name in attacks:
            entry["trace_inv_sigma"] = attacks[name].trace_inv
        out_designs[name] = entry
    res: dict[str, Any] = {
        "system": {"n": n, "m": m, "spectral_radius": rho, "tr_psi_u": tr_u, "tr_psi_w": tr_w, "r_sigma": su / sw},
        "parameters": {"gamma_c": gamma_c, "tau_c": tau_c, "upsilon": upsilon, "sigma_u2": su, "sigma_w2": sw, "sigma_x2": sx},
        "bounds": {
            "N": N_ref,
            "input_upper_bound": float(input_upper_bound(N_ref, m, n, su / sw)),
            "noise_upper_bound": float(noise_upper_bound(N_ref, m, n)),
        },
        "designs": out_designs,
        "skipped": skipped,
    }
    if cost_models:
        records = calibration if calibration is not None else default_records()
        res["cost_models"] = _cost_model_section(
            designs,
            models=cost_models,
            complexity=complexity,
            gnfs_correction=c,
            key_length=key_length,
            records=records,
            tau_c=tau_c,
            upsilon=upsilon,
        )
        res["models"] = {name: _describe(name, c, records) for name in cost_models}
        res["records"] = _records_section(records)
    return res


def _describe(name: str, c: float, records: RecordSet) -> dict[str, Any]:
    return build_model(name, c, records).describe()


# --------------------------------------------------------------------------- text output
def _bits(x: float | None, width: int, digits: int = 3) -> str:
    if x is None:
        return f"{'-':>{width}}"
    return f"{x:>{width}.{digits}f}"


def _count(v: Any) -> str:
    if v == math.inf:
        return "inf"
    v = int(v)
    return str(v) if v < 10**9 else f"2^{math.log2(v):.2f}"


def _format_cost_models(res: dict[str, Any]) -> list[str]:
    cm = res["cost_models"]
    lines = [
        "",
        f"  Deciphering-cost models: N* = {cm['N_star']} from --complexity {cm['complexity']}; "
        f"budget Upsilon tau_c = 2^{cm['budget_bits']:.3f} operations; GNFS correction {cm['gnfs_correction']:g} bits",
        f"  {'model':<16}{'N*':>8}{'work(N*)':>10}{'k*':>7}{'paper k*':>10}{'first key':>11}{'next key':>10}"
        f"{'dyn. keys':>11}{'NIST k':>8}",
    ]
    for name, d in cm["designs"].items():
        nist = "-" if d["nist_key_length"] is None else str(d["nist_key_length"])
        lines.append(
            f"  {name:<16}{d['N_star']:>8d}{_bits(d['work_bits'], 10)}{d['k_star']:>7d}{d['paper_k_star']:>10d}"
            f"{_bits(d['first_key_bits'], 11)}{_bits(d['next_key_bits'], 10)}{_bits(d['dynamic_key_bits'], 11)}{nist:>8}"
        )
    kv = cm["key_value"]
    k = kv["key_length"]
    some = next(iter(kv["models"].values()))
    strength = "below its smallest row (80 bits at 1024)" if some["nist_strength"] is None else f"{some['nist_strength']} bits"
    lines += [
        "",
        f"  What a {k}-bit key is worth (NIST SP 800-57 strength: {strength}); the adversary needs N* = {cm['N_star']}:",
        f"  {'model':<16}{'first key':>11}{'next key':>10}{'samples in tau_c':>18}{'dyn. keys':>11}{'secure':>8}",
    ]
    for name, v in kv["models"].items():
        lines.append(
            f"  {name:<16}{_bits(v['first_key_bits'], 11)}{_bits(v['next_key_bits'], 10)}"
            f"{_count(v['affordable_samples']):>18}{_bits(v['dynamic_key_bits'], 11)}{'yes' if v['secure'] else 'no':>8}"
        )
    lines += [
        "",
        "  work(N*): log2 of the operations for N* samples at k*; first/next key: log2 operations for the first key",
        "  (with any precomputation) and each further key; dyn. keys: bits the per-period keys add, work(N*) - first key;",
        "  NIST k: NIST SP 800-57 key length for the first key's strength; paper k*: the paper model without correction.",
    ]
    if "records" in res:
        rec = res["records"]
        lines += [
            "",
            f"  Records ({rec['path']}; one operation = one core clock cycle):",
            f"  {'name':<12}{'bits':>6}  {'problem':<10}{'total':<18}{'per key':<14}{'ratio':>7}{'ops':>8}"
            f"{'formula':>9}{'diff':>7}  used",
        ]
        for r in rec["records"]:
            basis = "" if r["time_basis"] == "core" else " (wall)"
            lines.append(
                f"  {r['name']:<12}{r['key_length']:>6d}  {r['problem']:<10}{(r['total'] + basis):<18}{(r['per_key'] or '-'):<14}"
                f"{_bits(r['log2_ratio'], 7, 2)}{_bits(r['log2_operations'], 8, 2)}{_bits(r['formula_bits'], 9, 2)}"
                f"{_bits(r['formula_minus_record_bits'], 7, 2)}  {'ratio' if r['use_for_ratio'] else '-'}"
            )
        lines.append(
            "  ratio: log2(total / per-key time); ops: log2 cycles of the total; formula: log2 Omega(k); diff: formula - ops."
        )
        lines += [
            "",
            "  NIST SP 800-57 comparable strengths against the GNFS formula (bits):",
            f"  {'key length':>12}{'NIST':>8}{'formula':>10}{'formula - ' + format(GUILLEVIC_CORRECTION, 'g'):>18}",
        ]
        for row in rec["nist_sp800_57"]["rows"]:
            lines.append(
                f"  {row['key_length']:>12d}{row['strength']:>8d}{row['formula_bits']:>10.2f}"
                f"{row['formula_guillevic_bits']:>18.2f}"
            )
    return lines


def _format_table(res: dict[str, Any], title: str, sources: str | None = None) -> str:
    s, p, b = res["system"], res["parameters"], res["bounds"]
    lines = [f"System: {title}"]
    if sources:
        lines.append(f"  values {sources}")
    lines += [
        f"  n = {s['n']}, m = {s['m']}, spectral radius of A = {s['spectral_radius']:.6g}",
        f"  tr Psi_u = {s['tr_psi_u']:.6g}   tr Psi_w = {s['tr_psi_w']:.6g}   "
        f"R_sigma = sigma_u2/sigma_w2 = {p['sigma_u2']:g}/{p['sigma_w2']:g} = {s['r_sigma']:.6g}   sigma_x2 = {p['sigma_x2']:g}",
        f"  gamma_c = {p['gamma_c']:g}   tau_c = {p['tau_c']:.6g} s ({p['tau_c'] / SECONDS_PER_UNIT['y']:.4g} y)   "
        f"Upsilon = {p['upsilon']:.4g} FLOPS",
        f"  upper bounds at N = {b['N']}: eq:bound (m+n)/((N-1) m R) = {b['input_upper_bound']:.4e}, "
        f"(m+n)/((N-1) n) = {b['noise_upper_bound']:.4e}",
        "",
        f"  {'complexity':<34}{'N*':>10}{'lam*':>6}{'k*':>7}{'log2 Omega(k*)':>16}{'gamma(N*)':>13}{'gamma/paper':>13}",
    ]
    for name in LABELS:
        if name in res["designs"]:
            d = res["designs"][name]
            lines.append(
                f"  {LABELS[name]:<34}{d['N_star']:>10d}{d['lam_star']:>6d}{d['k_star']:>7d}"
                f"{d['bit_security']:>16.3f}{d['gamma_at_N_star']:>13.5e}{d['ratio_to_paper']:>13.5f}"
            )
        elif name in res["skipped"]:
            lines.append(f"  {LABELS[name]:<34}  skipped: {res['skipped'][name]}")
    lines += [
        "",
        "  N*: smallest N with gamma(N) < gamma_c; lam*: smallest lam with 2^lam N* / Upsilon > tau_c;",
        "  k*: smallest key length with GNFS cost Omega(k) >= 2^lam* (eq:opt_key).",
        f"  gamma/paper: gamma(N) / gamma_sic2(N) at N = {b['N']} (constant in N for (c)-(e)).",
    ]
    if "cost_models" in res:
        lines += _format_cost_models(res)
    return "\n".join(lines)


# --------------------------------------------------------------------------- the command
def run(args: argparse.Namespace) -> int:
    """Run ``encctl-gym design``: print the tables (or JSON); return 0."""
    if args.preset and args.system_file:
        raise ConfigError("give either SYSTEM_FILE or --preset, not both")
    base: dict[str, Any] = dict(DEFAULTS)
    sources: dict[str, str] = {}
    sources_line = None
    if args.preset:
        preset = get_preset(args.preset)
        A, B = preset.A, preset.B
        title = f"preset {args.preset}, {preset.description}"
        base.update({key: getattr(preset, key) for key in DESIGN_FIELDS})
        sources = {key: "preset" for key in DESIGN_FIELDS}
    elif args.system_file:
        spec = load_plant_file(args.system_file, defaults=DEFAULTS)
        A, B = spec.A, spec.B
        title = str(args.system_file)
        base.update(spec.values())
        sources = {key: ("file" if key in spec.from_file else "default") for key in DESIGN_FIELDS}
    else:
        raise ConfigError("give a SYSTEM_FILE (JSON, YAML or NPZ with A and B) or --preset NAME")
    values: dict[str, float] = {}
    for key in DESIGN_FIELDS:
        raw = getattr(args, key)
        if raw is None:
            values[key] = base[key]
        else:
            values[key] = parse_duration(raw, "tau_c") if key == "tau_c" else parse_number(key, raw)
            sources[key] = "option"
    for key in ("gamma_c", "upsilon", "sigma_u2", "sigma_w2", "tau_c"):
        check_positive(key, values[key])
    check_nonnegative("sigma_x2", values["sigma_x2"])
    if args.system_file:
        groups: dict[str, list[str]] = {}
        for key in DESIGN_FIELDS:
            groups.setdefault(sources[key], []).append(key)
        names = {"file": "from the file", "option": "from the command line", "default": "defaults (the paper's design example)"}
        sources_line = "; ".join(f"{', '.join(v)} {names[k]}" for k, v in groups.items())
    models = parse_cost_models(args.cost_model) if args.cost_model is not None else None
    extra_given = [
        opt
        for opt, v in (
            ("--gnfs-correction", args.gnfs_correction),
            ("--key-length", args.key_length),
            ("--calibration", args.calibration),
        )
        if v is not None
    ]
    if models is None and (extra_given or args.complexity != "sic2"):
        raise ConfigError(f"{', '.join(extra_given) or '--complexity'} only applies with --cost-model")
    correction = 0.0 if args.gnfs_correction is None else parse_gnfs_correction(args.gnfs_correction)
    key_length = None if args.key_length is None else check_int("key_length", parse_number("key_length", args.key_length))
    records = None if args.calibration is None else load_records(args.calibration)
    sdp = None if args.sdp_max_dim is None else check_int("sdp_max_dim", parse_number("sdp_max_dim", args.sdp_max_dim), 2)
    res = compute(
        A,
        B,
        solver=args.solver,
        sdp_max_dimension=sdp,
        cost_models=models,
        gnfs_correction=correction,
        complexity=args.complexity,
        key_length=key_length,
        calibration=records,
        **values,
    )
    if args.json:
        res["title"] = title
        res["sources"] = sources
        print(json.dumps(_sanitize(res), indent=2, allow_nan=False))
    else:
        print(_format_table(res, title, sources_line))
    return 0


def _sanitize(obj: Any) -> Any:
    """NaN/inf become None and numpy scalars Python numbers, so the output is strict JSON."""
    if isinstance(obj, dict):
        return {k: _sanitize(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_sanitize(v) for v in obj]
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj
