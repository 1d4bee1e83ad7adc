"""Everything the ``design`` command reports for a plant, as a JSON-ready dict (:func:`design_report`).

The optimal security parameter and key length (Theorem thm:opt_sec, eq:opt_key) by the paper's
eq:sic2 and by the exact eq:sic, the A-optimal closed- and open-loop attacks and i.i.d. Gaussian
inputs (:mod:`.attack_design`), each with its ratio to the paper's gamma, the upper bounds of
eq:bound, and optionally one row per deciphering-cost model (:mod:`.cost_models`) with the
records the precomputation model is calibrated on. ``encctl-gym design``
(:mod:`.design_cli`) prints it; tests and scripts call it directly.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .._validation import check_int, check_system, format_value
from ..errors import ParameterError, ResourceLimitError
from ..plant import Plant, as_plant
from .attack_design import gaussian_attack_design, optimal_attack_design, robust_security_design
from .bayes_complexity import sic_tightness
from .complexity import input_upper_bound, noise_upper_bound, sic_asymptotic_from_traces, sic_from_traces
from .cost_models import GUILLEVIC_CORRECTION, check_gnfs_correction, gnfs_log2_complexity
from .design import SecurityDesign, design_from_traces
from .gramians import controllability_gramian, noise_gramian
from .key_length import build_model, design_key_length, key_length_value
from .records import RecordSet, default_records
from .threat import ThreatModel

__all__ = ["design_report", "COMPLEXITIES", "LABELS", "MAX_STATE_DIMENSION"]

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

#: Key of the designs table -> its label.
LABELS: dict[str, str] = {
    "paper_sic2": "(a) eq:sic2, paper (thm:opt_sec)",
    "exact_sic": "(b) eq:sic exact",
    "closed_loop": "(c) gamma_opt closed loop",
    "open_loop": "(d) gamma_opt open loop",
    "gaussian": "(e) Gaussian, tr(Sigma^-1)",
}


def _check_size(n: int, m: int) -> None:
    if n > MAX_STATE_DIMENSION:
        ref_n, ref_s = _LYAPUNOV_REF
        raise ResourceLimitError(
            f"the plant has n = {n} states; the design command accepts n <= {MAX_STATE_DIMENSION} (its Lyapunov "
            f"solves grow as n^3: {ref_s:g} s at n = {ref_n} on the development machine, so about "
            f"{ref_s * (n / ref_n) ** 3:.3g} s here)"
        )


def _cost_model_section(
    designs: dict[str, SecurityDesign],
    threat: ThreatModel,
    *,
    models: Sequence[str],
    complexity: str,
    gnfs_correction: float,
    key_length: Any,
    records: RecordSet,
) -> dict[str, Any]:
    key = COMPLEXITIES[complexity]
    if key not in designs:
        raise ParameterError(f"complexity {complexity!r} was skipped for this plant (see skipped); choose another")
    N_star = designs[key].N_star
    out_designs = {}
    threats = {name: threat.replace(cost_model=build_model(name, gnfs_correction, records)) for name in models}
    for name in models:
        out_designs[name] = design_key_length(N_star, threats[name]).to_dict()
    k_val = designs[key].k_star if key_length is None else check_int("key_length", key_length)
    values = {name: key_length_value(k_val, threats[name], N_star=N_star).to_dict() for name in models}
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


def design_report(
    plant: Plant | tuple[Any, Any],
    threat: ThreatModel,
    *,
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
    plant : Plant or (A, B)
        Plant (``A`` Schur stable, ``n <= 1000``).
    threat : ThreatModel
        ``sigma_u2``, ``sigma_w2``, ``sigma_x2``, ``gamma_c``, ``tau_c``, ``upsilon`` (its
        adversary and cost model are not used: the cost-model section covers ``cost_models``).
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
    if isinstance(plant, tuple) and len(plant) == 2:  # the size bound comes before any eigenvalue
        _check_size(*check_system(*plant)[1].shape)
    p = as_plant(plant)
    A, B, n, m = p.A, p.B, p.n, p.m
    _check_size(n, m)
    rho = p.spectral_radius
    if not isinstance(threat, ThreatModel):
        raise ParameterError(f"design_report: threat must be a ThreatModel, got {format_value(threat)}")
    t = threat.require("sigma_u2", "sigma_w2", "gamma_c")
    gamma_c, tau_c, upsilon = float(t.gamma_c), float(t.tau_c), float(t.upsilon)
    su, sw, sx = float(t.sigma_u2), float(t.sigma_w2), float(t.sigma_x2)
    if not isinstance(complexity, str) or complexity not in COMPLEXITIES:
        raise ParameterError(f"unknown complexity {format_value(complexity)}; choose one of {', '.join(COMPLEXITIES)}")
    c = check_gnfs_correction(gnfs_correction)
    tr_u = float(np.trace(controllability_gramian(A, B)))
    tr_w = float(np.trace(noise_gramian(A)))
    designs, attacks, skipped = _designs(p, t, tr_u, tr_w, solver=solver, sdp_max_dimension=sdp_max_dimension)
    N_ref = designs["paper_sic2"].N_star
    out_designs = _design_entries(designs, attacks, N_ref, tr_u, tr_w, m, n, su, sw, sx)
    res: dict[str, Any] = {
        "system": {"n": n, "m": m, "spectral_radius": rho, "tr_psi_u": tr_u, "tr_psi_w": tr_w, "r_sigma": su / sw},
        "parameters": {"gamma_c": gamma_c, "tau_c": tau_c, "upsilon": upsilon, "sigma_u2": su, "sigma_w2": sw, "sigma_x2": sx},
        "bounds": {
            "N": N_ref,
            "input_upper_bound": float(input_upper_bound(N_ref, m, n, su / sw)),
            "noise_upper_bound": float(noise_upper_bound(N_ref, m, n)),
            "sic_tightness": sic_tightness(A, B, sigma_u2=su, sigma_w2=sw),
        },
        "designs": out_designs,
        "skipped": skipped,
    }
    if cost_models:
        records = calibration if calibration is not None else default_records()
        res["cost_models"] = _cost_model_section(
            designs, t, models=cost_models, complexity=complexity, gnfs_correction=c, key_length=key_length, records=records
        )
        res["models"] = {name: _describe(name, c, records) for name in cost_models}
        res["records"] = _records_section(records)
    return res


def _designs(
    p: Plant, t: ThreatModel, tr_u: float, tr_w: float, *, solver: str | None, sdp_max_dimension: int | None
) -> tuple[dict[str, SecurityDesign], dict[str, Any], dict[str, str]]:
    """The security designs of :data:`LABELS` (in that order), the attack designs they rest on
    and the SDP rows skipped for their size (with the reason)."""
    A, B, n, m = p.A, p.B, p.n, p.m
    su, sw = float(t.sigma_u2), float(t.sigma_w2)
    designs: dict[str, SecurityDesign] = {
        "paper_sic2": design_from_traces(tr_u, tr_w, m, n, t, method="asymptotic"),
        "exact_sic": design_from_traces(tr_u, tr_w, m, n, t, method="exact"),
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
        designs[kind] = robust_security_design(p, t, kind=kind, design=att)
    return {k: designs[k] for k in LABELS if k in designs}, attacks, skipped


def _design_entries(
    designs: dict[str, SecurityDesign],
    attacks: dict[str, Any],
    N_ref: int,
    tr_u: float,
    tr_w: float,
    m: int,
    n: int,
    su: float,
    sw: float,
    sx: float,
) -> dict[str, dict[str, Any]]:
    """Each design's :meth:`SecurityDesign.to_dict` with ``ratio_to_paper``, its complexity at the
    paper's ``N*`` over eq:sic2's (and ``trace_inv_sigma`` for an attack design)."""
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
    return out_designs


def _describe(name: str, c: float, records: RecordSet) -> dict[str, Any]:
    return build_model(name, c, records).describe()


# --------------------------------------------------------------------------- text output
