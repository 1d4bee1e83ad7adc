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

``--estimator n4sid`` (or ``moesp``, ``arx``) adds the empirical design of the plant measured through
its outputs (the file's ``C`` and ``sigma_v2``; ``C = I`` without them) beside the state-measured
one (:mod:`encctl_gym.security.output_design`): ``--runs`` simulated Gaussian attacks per ``N``
(default 20) on ``--points`` sizes from ``N*/4`` to ``2 N*`` (default 6), seed ``--seed``; for the
paper's N* = 13159 this takes minutes.

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
from collections.abc import Callable
from typing import Any

import numpy as np

from .._validation import check_int, check_positive, format_value, parse_number
from ..errors import ConfigError, ParameterError
from ..plant_file import fields_help, load_plant_file, load_system
from ..presets import DESIGN_FIELDS, design_defaults, get_preset, preset_names
from ..units import SECONDS_PER_UNIT, parse_duration
from . import defense_cli
from .attack_design import SDP_MAX_DIMENSION
from .cost_models import DECIPHERING_MODELS, GUILLEVIC_CORRECTION, check_gnfs_correction
from .defense_design import DefenseDesign
from .records import load_records
from .report import COMPLEXITIES, LABELS, design_report
from .scheme_design import format_scheme_key_lengths, scheme_key_lengths
from .threat import ThreatModel

__all__ = ["add_arguments", "run", "parse_duration", "load_system", "DEFAULTS", "parse_cost_models", "parse_gnfs_correction"]

#: Option defaults: the paper's design example (from :mod:`encctl_gym.presets`).
DEFAULTS: dict[str, Any] = design_defaults()


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the options of ``encctl-gym design``; the help ends with the plant-file fields."""
    parser.formatter_class = argparse.RawDescriptionHelpFormatter  # keeps the field table's lines
    parser.epilog = (
        "plant file fields (JSON, YAML or NPZ with these names, nothing else;\n"
        "the optional ones default to the paper's design example):\n"
        + fields_help()
        + "\nexamples in the repository: examples/plant_state.yaml (the state measured),\n"
        "examples/plant_output.yaml (with C and sigma_v2, for --estimator)"
    )
    parser.add_argument(
        "system_file",
        nargs="?",
        metavar="SYSTEM_FILE",
        help="plant file: JSON/YAML ({'A': [[...]], 'B': [[...]]}, optional C, sigma_v2, sigma_u2, sigma_w2, "
        "sigma_x2, gamma_c, tau_c, upsilon; see the fields below) or NPZ with the same names",
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
    parser.add_argument(
        "--estimator",
        metavar="NAME",
        help="add the empirical design from outputs y = C x + v with this identification method: n4sid, moesp or arx",
    )
    parser.add_argument("--runs", metavar="R", help="with --estimator: simulated attacks per N (default 20)")
    parser.add_argument("--points", metavar="P", help="with --estimator: attack lengths on the log grid (default 6)")
    parser.add_argument("--seed", metavar="S", help="with --estimator: seed of the simulated attacks (default 0)")
    parser.add_argument(
        "--memory-limit",
        dest="memory_limit",
        metavar="GIB",
        help="with --estimator: GiB the simulated attacks may hold, checked before they run (default 8, or less under ulimit -v)",
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
        f"  eq:sic / mean least-squares error at large N = {b['sic_tightness']:.3f} (HM/AM of the eigenvalues of the regressor "
        f"covariance): least squares reaches gamma_c near {1 / b['sic_tightness']:.3g}x the paper's N*",
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
def _plant_of(args: argparse.Namespace) -> tuple[Any, Any, Any, float, str, dict[str, Any], dict[str, str]]:
    """``(A, B, C, sigma_v2, title, values, sources)`` of ``--preset`` or SYSTEM_FILE: the
    design values (defaults overridden by the preset or file) and where each came from."""
    if args.preset and args.system_file:
        raise ConfigError("give either SYSTEM_FILE or --preset, not both")
    base: dict[str, Any] = dict(DEFAULTS)
    sources: dict[str, str] = {}
    C, sigma_v2 = None, 0.0  # the sensors of --estimator (a plant file's or preset's)
    if args.preset:
        preset = get_preset(args.preset)
        A, B = preset.A, preset.B
        C, sigma_v2 = preset.C, preset.sigma_v2
        title = f"preset {args.preset}, {preset.description}"
        base.update({key: getattr(preset, key) for key in DESIGN_FIELDS})
        sources = {key: "preset" for key in DESIGN_FIELDS}
    elif args.system_file:
        spec = load_plant_file(args.system_file, defaults=DEFAULTS)
        A, B = spec.A, spec.B
        C, sigma_v2 = spec.C, spec.preset.sigma_v2
        title = str(args.system_file)
        base.update(spec.values())
        sources = {key: ("file" if key in spec.from_file else "default") for key in DESIGN_FIELDS}
    else:
        raise ConfigError("give a SYSTEM_FILE (JSON, YAML or NPZ with A and B) or --preset NAME")
    return A, B, C, sigma_v2, title, base, sources


def run(args: argparse.Namespace, defenses: Callable[..., DefenseDesign] | None = None, scheme: Any = None) -> int:
    """Run ``encctl-gym design``: print the tables (or JSON); return 0. ``defenses`` designs the
    defender's levers when one of their options is given (:mod:`encctl_gym.design_command`
    passes :func:`encctl_gym.loop.defense_costs.design_loop_defenses`); ``scheme`` (an
    :class:`~encctl_gym.loop.scheme.EncryptionScheme`, from ``--scheme``) adds its key size per
    cost model (:func:`~encctl_gym.security.scheme_design.scheme_key_lengths`)."""
    A, B, C, sigma_v2, title, base, sources = _plant_of(args)
    sources_line = None
    values: dict[str, Any] = {}
    for key in DESIGN_FIELDS:
        raw = getattr(args, key)
        if raw is None:
            values[key] = base[key]
        else:
            values[key] = parse_duration(raw, "tau_c") if key == "tau_c" else parse_number(key, raw)
            sources[key] = "option"
    threat = ThreatModel(**values)  # checks every value once
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
    res = design_report(
        (A, B),
        threat,
        solver=args.solver,
        sdp_max_dimension=sdp,
        cost_models=models,
        gnfs_correction=correction,
        complexity=args.complexity,
        key_length=key_length,
        calibration=records,
    )
    defense = defense_cli.defense_options(args)
    if defense is not None:
        if defenses is None:
            raise ConfigError("the defender's options need the loop's cost terms: run them through encctl-gym design")
        res["defenses"] = defenses(
            (A, B),
            threat,
            cost_models=models or tuple(DECIPHERING_MODELS),
            gnfs_correction=correction,
            calibration=records,
            **defense,
        )
    if scheme is not None:
        N_star = res["designs"][COMPLEXITIES[args.complexity]]["N_star"]
        res["scheme"] = scheme_key_lengths(scheme, N_star, threat, gnfs_correction=correction)
    output = _output_design(args, A, B, C, sigma_v2, threat)
    if output is not None:
        res["output_design"] = output.to_dict()
    if args.json:
        if "defenses" in res:
            res["defenses"] = res["defenses"].to_dict()
        res["title"] = title
        res["sources"] = sources
        print(json.dumps(_sanitize(res), indent=2, allow_nan=False))
    else:
        text = _format_table(res, title, sources_line)
        if "scheme" in res:
            text += "\n" + "\n".join(format_scheme_key_lengths(res["scheme"]))
        if "defenses" in res:
            text += "\n" + "\n".join(defense_cli.format_defenses(res["defenses"]))
        print(text)
        if output is not None:
            from .output_design import format_output_design

            print()
            print(format_output_design(output))
    return 0


def _output_design(args: argparse.Namespace, A: Any, B: Any, C: Any, sigma_v2: float, threat: ThreatModel) -> Any:
    """The empirical design of ``--estimator`` (None without it); its options only apply with it."""
    given = [opt for opt in ("runs", "points", "seed", "memory_limit") if getattr(args, opt) is not None]
    if args.estimator is None:
        if given:
            raise ConfigError(f"{', '.join('--' + g.replace('_', '-') for g in given)} only applies with --estimator")
        return None
    from ..plant import Plant
    from .output_design import output_design

    def opt(name: str, default: int, minimum: int) -> int:
        raw = getattr(args, name)
        return default if raw is None else check_int(name, parse_number(name, raw), minimum)

    limit = None
    if args.memory_limit is not None:
        gib = check_positive("memory_limit", parse_number("memory_limit", args.memory_limit))
        # gib * 2**30 overflows a float near 1e299 GiB; anything above 2**40 GiB is beyond any machine
        limit = max(1, int(gib * 2**30)) if gib < 2**40 else 2**70
    plant = Plant(A, B, C=np.eye(A.shape[0]) if C is None else C, sigma_v2=sigma_v2)
    return output_design(
        plant,
        threat,
        estimator=args.estimator,
        runs=opt("runs", 20, 2),
        points=opt("points", 6, 3),
        seed=opt("seed", 0, 0),
        memory_limit=limit,
    )


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
