"""Optimal security parameter and key length for a plant (Theorem thm:opt_sec, eq:opt_key).

Usage::

    encctl-gym design SYSTEM_FILE [--gamma-c 1e-6] [--tau-c 10y] [--upsilon 442e15]
                                  [--sigma-u2 10] [--sigma-w2 0.1] [--sigma-x2 1] [--json]
    encctl-gym design --preset paper-example

``SYSTEM_FILE`` holds the plant of eq:system: JSON or YAML with keys ``A`` and ``B`` (nested
lists), or NPZ with arrays ``A`` and ``B``. The defaults of every option are the paper's design
example (gamma_c = 1e-6, tau_c = 10 years = 31536e4 s, Upsilon = 442e15 FLOPS (Fugaku),
sigma_u2 = 10, sigma_w2 = 0.1, sigma_x2 = 1); an option given on the command line overrides a
preset. ``--tau-c`` accepts units: ``10y`` (1 y = 365 d), ``5d``, ``2h``, ``30min``, ``3600s``
or plain seconds.

The table compares N*, lam*, k* for (a) the paper's eq:sic2 (Theorem thm:opt_sec), (b) the
exact eq:sic, (c) the A-optimal closed-loop attack gamma_opt, (d) the A-optimal open-loop attack
and (e) i.i.d. Gaussian inputs with the sharper tr(Sigma^-1) bound (see
:mod:`encctl_gym.security.attack_design`), with each one's ratio to the paper's gamma.
"""

from __future__ import annotations

import argparse
import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import check_nonnegative, check_positive, check_schur_stable, check_system
from ..errors import ConfigError, ParameterError
from ..presets import SECONDS_PER_YEAR, get_preset, preset_names
from .attack_design import gaussian_attack_design, optimal_attack_design, robust_security_design
from .complexity import input_upper_bound, noise_upper_bound, sic_asymptotic_from_traces, sic_from_traces
from .design import SecurityDesign, design_from_traces
from .gramians import controllability_gramian, noise_gramian

__all__ = ["add_arguments", "run", "parse_duration", "load_system", "DEFAULTS", "compute"]

SECONDS_PER_UNIT: dict[str, float] = {
    "s": 1.0,
    "sec": 1.0,
    "min": 60.0,
    "h": 3600.0,
    "d": 86400.0,
    "y": float(SECONDS_PER_YEAR),  # the paper: 10 years = 31536e4 s
}

#: Option defaults: the paper's design example.
DEFAULTS: dict[str, Any] = {
    "gamma_c": 1e-6,
    "tau_c": 31536e4,
    "upsilon": 442e15,
    "sigma_u2": 10.0,
    "sigma_w2": 0.1,
    "sigma_x2": 1.0,
}

def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the options of ``encctl-gym design``."""
    parser.add_argument("system_file", nargs="?", metavar="SYSTEM_FILE",
                        help="JSON/YAML ({'A': [[...]], 'B': [[...]]}) or NPZ (arrays A, B)")
    parser.add_argument("--preset", choices=preset_names(), metavar="NAME",
                        help="use a preset plant (with its variances and design parameters) instead of a file: "
                        + ", ".join(preset_names()))
    parser.add_argument("--gamma-c", dest="gamma_c", metavar="G",
                        help="acceptable estimation error gamma_c (default 1e-6)")
    parser.add_argument("--tau-c", dest="tau_c", metavar="T",
                        help="defense period: 10y, 5d, 2h, 30min, 3600s or seconds (default 10y)")
    parser.add_argument("--upsilon", metavar="FLOPS", help="adversary computing speed in FLOPS (default 442e15)")
    parser.add_argument("--sigma-u2", dest="sigma_u2", metavar="V", help="attack input variance (default 10)")
    parser.add_argument("--sigma-w2", dest="sigma_w2", metavar="V", help="noise variance (default 0.1)")
    parser.add_argument("--sigma-x2", dest="sigma_x2", metavar="V", help="initial-state variance (default 1)")
    parser.add_argument("--solver", metavar="NAME", help="cvxpy solver for the attack designs (default Clarabel, then SCS)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")


# --------------------------------------------------------------------------- parsing
def _parse_number(name: str, text: Any) -> float:
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return float(text)
    try:
        return float(str(text).strip())
    except ValueError:
        raise ParameterError(f"{name} must be a number, got {text!r}") from None


def parse_duration(text: Any) -> float:
    """Parse a defense period: ``"10y"``, ``"5d"``, ``"2h"``, ``"30min"``, ``"3600s"`` or seconds.

    A year is 365 days (the paper's 10 years = 31536e4 s).

    Parameters
    ----------
    text : str or float
        The duration.

    Returns
    -------
    float
        Seconds (> 0).

    Raises
    ------
    ParameterError
        For an unknown unit, a malformed number or a non-positive duration.
    """
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return check_positive("tau_c", text)
    s = str(text).strip().lower()
    match = re.fullmatch(r"([0-9]*\.?[0-9]+(?:e[+-]?[0-9]+)?|[0-9]+\.)\s*([a-z]*)", s)
    if not match:
        raise ParameterError(f"tau_c must be a duration like 10y, 5d, 2h, 30min, 3600s or seconds, got {text!r}")
    value, unit = match.groups()
    unit = {"": "s", "second": "s", "seconds": "s", "minute": "min", "minutes": "min", "mins": "min",
            "hour": "h", "hours": "h", "day": "d", "days": "d", "year": "y", "years": "y", "yr": "y"}.get(unit, unit)
    if unit not in SECONDS_PER_UNIT:
        raise ParameterError(f"tau_c has unknown unit {match.group(2)!r} in {text!r}; use s, min, h, d or y")
    return check_positive("tau_c", float(value) * SECONDS_PER_UNIT[unit])


def load_system(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Read ``A`` and ``B`` from a JSON, YAML or NPZ file.

    Parameters
    ----------
    path : str or Path
        ``.json``, ``.yaml``/``.yml`` (keys ``A``, ``B``) or ``.npz`` (arrays ``A``, ``B``).

    Returns
    -------
    (ndarray, ndarray)
        ``A`` (n x n) and ``B`` (n x m), validated by ``check_system``.

    Raises
    ------
    ConfigError
        If the file is missing, unreadable, of unknown type, or lacks numeric ``A``/``B``.
    ShapeError
        If the shapes of ``A`` and ``B`` do not fit.
    """
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"system file {str(p)!r} does not exist")
    suffix = p.suffix.lower()
    try:
        if suffix == ".json":
            data = json.loads(p.read_text())
        elif suffix in (".yaml", ".yml"):
            import yaml

            data = yaml.safe_load(p.read_text())
        elif suffix == ".npz":
            with np.load(p, allow_pickle=False) as z:
                data = {k: z[k] for k in z.files}
        else:
            raise ConfigError(f"system file {str(p)!r} must end in .json, .yaml, .yml or .npz")
    except ConfigError:
        raise
    except Exception as exc:  # noqa: BLE001 - any parse failure becomes a one-line ConfigError
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ConfigError(f"cannot read system file {str(p)!r}: {msg}") from exc
    if not isinstance(data, dict) or "A" not in data or "B" not in data:
        raise ConfigError(f"system file {str(p)!r} must define 'A' and 'B'")
    arrays = []
    for key in ("A", "B"):
        try:
            arrays.append(np.asarray(data[key], dtype=np.float64))
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"system file {str(p)!r}: {key} is not a numeric matrix ({exc})") from exc
    try:
        return check_system(*arrays)
    except ParameterError as exc:
        raise type(exc)(f"system file {str(p)!r}: {exc}") from exc


# --------------------------------------------------------------------------- computation
def compute(
    A: Any, B: Any, *, gamma_c: float, tau_c: float, upsilon: float, sigma_u2: float, sigma_w2: float,
    sigma_x2: float = 1.0, solver: str | None = None,
) -> dict[str, Any]:
    """All quantities of the ``design`` table as a JSON-ready dict.

    Parameters
    ----------
    A, B : array_like
        Plant (``A`` Schur stable).
    gamma_c, tau_c, upsilon, sigma_u2, sigma_w2, sigma_x2 : float
        Design parameters (see the module docstring).
    solver : str, optional
        cvxpy solver for the attack designs.

    Returns
    -------
    dict
        ``system`` (n, m, traces, R_sigma), ``parameters``, ``bounds`` and ``designs`` (one
        :meth:`SecurityDesign.to_dict` per method with ``ratio_to_paper`` = gamma / gamma_sic2
        at the paper's ``N*``).
    """
    A, B = check_system(A, B)
    rho = check_schur_stable(A)
    n, m = B.shape
    gamma_c = check_positive("gamma_c", gamma_c)
    tau_c = check_positive("tau_c", tau_c)
    upsilon = check_positive("upsilon", upsilon)
    su = check_positive("sigma_u2", sigma_u2)
    sw = check_positive("sigma_w2", sigma_w2)
    sx = check_nonnegative("sigma_x2", sigma_x2)
    tr_u = float(np.trace(controllability_gramian(A, B)))
    tr_w = float(np.trace(noise_gramian(A)))
    kw = dict(gamma_c=gamma_c, tau_c=tau_c, upsilon=upsilon)
    designs: dict[str, SecurityDesign] = {
        "paper_sic2": design_from_traces(tr_u, tr_w, m, n, sigma_u2=su, sigma_w2=sw, sigma_x2=sx, method="asymptotic", **kw),
        "exact_sic": design_from_traces(tr_u, tr_w, m, n, sigma_u2=su, sigma_w2=sw, sigma_x2=sx, method="exact", **kw),
    }
    attacks = {
        "closed_loop": optimal_attack_design(A, B, sigma_u2=su, sigma_w2=sw, feedback=True, solver=solver),
        "open_loop": optimal_attack_design(A, B, sigma_u2=su, sigma_w2=sw, feedback=False, solver=solver),
        "gaussian": gaussian_attack_design(A, B, sigma_u2=su, sigma_w2=sw),
    }
    for kind, att in attacks.items():
        designs[kind] = robust_security_design(A, B, sigma_u2=su, sigma_w2=sw, sigma_x2=sx, kind=kind, design=att, **kw)
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
    return {
        "system": {"n": n, "m": m, "spectral_radius": rho, "tr_psi_u": tr_u, "tr_psi_w": tr_w, "r_sigma": su / sw},
        "parameters": {"gamma_c": gamma_c, "tau_c": tau_c, "upsilon": upsilon,
                       "sigma_u2": su, "sigma_w2": sw, "sigma_x2": sx},
        "bounds": {
            "N": N_ref,
            "input_upper_bound": float(input_upper_bound(N_ref, m, n, su / sw)),
            "noise_upper_bound": float(noise_upper_bound(N_ref, m, n)),
        },
        "designs": out_designs,
    }


LABELS = {
    "paper_sic2": "(a) eq:sic2, paper (thm:opt_sec)",
    "exact_sic": "(b) eq:sic exact",
    "closed_loop": "(c) gamma_opt closed loop",
    "open_loop": "(d) gamma_opt open loop",
    "gaussian": "(e) Gaussian, tr(Sigma^-1)",
}


def _format_table(res: dict[str, Any], title: str) -> str:
    s, p, b = res["system"], res["parameters"], res["bounds"]
    lines = [
        f"System: {title}",
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
    for name, d in res["designs"].items():
        lines.append(
            f"  {LABELS[name]:<34}{d['N_star']:>10d}{d['lam_star']:>6d}{d['k_star']:>7d}"
            f"{d['bit_security']:>16.3f}{d['gamma_at_N_star']:>13.5e}{d['ratio_to_paper']:>13.5f}"
        )
    lines += [
        "",
        "  N*: smallest N with gamma(N) < gamma_c; lam*: smallest lam with 2^lam N* / Upsilon > tau_c;",
        "  k*: smallest key length with GNFS cost Omega(k) >= 2^lam* (eq:opt_key).",
        f"  gamma/paper: gamma(N) / gamma_sic2(N) at N = {b['N']} (constant in N for (c)-(e)).",
    ]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    """Run ``encctl-gym design``: print the table (or JSON); return 0."""
    if args.preset and args.system_file:
        raise ConfigError("give either SYSTEM_FILE or --preset, not both")
    defaults = dict(DEFAULTS)
    if args.preset:
        preset = get_preset(args.preset)
        A, B = preset.A, preset.B
        title = f"preset {args.preset}, {preset.description}"
        defaults.update(
            gamma_c=preset.gamma_c, tau_c=preset.tau_c, upsilon=preset.upsilon,
            sigma_u2=preset.sigma_u2, sigma_w2=preset.sigma_w2, sigma_x2=preset.sigma_x2,
        )
    elif args.system_file:
        A, B = load_system(args.system_file)
        title = str(args.system_file)
    else:
        raise ConfigError("give a SYSTEM_FILE (JSON, YAML or NPZ with A and B) or --preset NAME")
    values = {}
    for key in ("gamma_c", "upsilon", "sigma_u2", "sigma_w2", "sigma_x2"):
        raw = getattr(args, key)
        values[key] = defaults[key] if raw is None else _parse_number(key, raw)
    values["tau_c"] = defaults["tau_c"] if args.tau_c is None else parse_duration(args.tau_c)
    for key in ("gamma_c", "upsilon", "sigma_u2", "sigma_w2", "tau_c"):
        check_positive(key, values[key])
    check_nonnegative("sigma_x2", values["sigma_x2"])
    res = compute(A, B, solver=args.solver, **values)
    if args.json:
        res["title"] = title
        print(json.dumps(_sanitize(res), indent=2, allow_nan=False))
    else:
        print(_format_table(res, title))
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
