"""Probe cases of :mod:`encctl_gym.security` (Gramians, complexities, deciphering times, the design of
Theorem thm:opt_sec, key lengths, cost models, records, attack designs), exact arithmetic,
durations, presets and plant files."""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from .build import FILES, bad_args, case, write_file
from .harness import Case, api
from .values import BAD, HUGE, HUGER, INF, NAN, Named, explicit

A_ = "security"
A2 = np.array([[0.5, 0.1], [0.0, 0.3]])
B2 = np.array([[1.0], [0.5]])
SEC = "encctl_gym.security"


#: The fields of a ThreatModel: the design functions take them in one value object.
_THREAT_FIELDS = ("tau_c", "upsilon", "sigma_u2", "sigma_w2", "sigma_x2", "gamma_c", "adversary", "cost_model")


def _on_values(path: str, *, plant: bool = False) -> Any:
    """A target that builds the value objects (a Plant from ``A``, ``B``; a ThreatModel from its
    fields; a cost model from ``model``, ``gnfs_correction``, ``calibration``) from the keywords
    and calls ``path`` with them, so every value is probed where it is checked."""

    def run(kw: dict[str, Any]) -> Any:
        kw = dict(kw)
        threat = {k: kw.pop(k) for k in _THREAT_FIELDS if k in kw}
        if "model" in kw:
            build = api(f"{SEC}.key_length:build_model")
            threat["cost_model"] = build(kw.pop("model"), kw.pop("gnfs_correction", 0.0), kw.pop("calibration", None))
        if plant:
            kw["plant"] = api("encctl_gym.plant:Plant")(kw.pop("A"), kw.pop("B"))
        return api(path)(threat=api(f"{SEC}.threat:ThreatModel")(**threat), **kw)

    return run


UNSTABLE = explicit([np.array([[1.5, 0.0], [0.0, 0.3]]), np.array([[1.0, 0.0], [0.0, 0.3]])], "silent")
N_BAD = explicit(
    [0, 1, -5, 2.5, NAN, INF, "100", None, True, HUGER, np.array([10.0, NAN]), np.array([10, "a"], dtype=object), 2 + 0j]
)


def _gramians() -> list[Case]:
    out: list[Case] = []
    mat = BAD["matrix"] + UNSTABLE
    out += bad_args(
        A_,
        f"{SEC}.gramians:controllability_gramian",
        {"A": A2, "B": B2},
        {
            "A": mat,
            "B": explicit([np.ones((3, 1)), np.array([[1 + 1j], [0]]), np.array([[NAN], [0]]), "abc", None, np.ones((2, 1, 1))]),
        },
    )
    out += bad_args(A_, f"{SEC}.gramians:noise_gramian", {"A": A2}, {"A": mat}, drawn=1)
    return out


def _complexity() -> list[Case]:
    out: list[Case] = []
    sic = f"{SEC}.complexity:sample_identifying_complexity"
    valid = {"N": 100, "A": A2, "B": B2, "sigma_u2": 1.0, "sigma_w2": 0.1, "sigma_x2": 1.0}
    out += bad_args(A_, sic, valid, {"N": N_BAD, "sigma_u2": "pos", "sigma_w2": "pos", "sigma_x2": "nonneg", "A": UNSTABLE})
    out += bad_args(
        A_,
        f"{SEC}.complexity:sample_identifying_complexity_asymptotic",
        {"N": 100, "A": A2, "B": B2, "r_sigma": 10.0},
        {"N": N_BAD, "r_sigma": "pos"},
        drawn=1,
    )
    tr = {"N": 100, "tr_psi_u": 2.0, "tr_psi_w": 1.0, "m": 1, "n": 2, "sigma_u2": 1.0, "sigma_w2": 0.1}
    out += bad_args(
        A_,
        f"{SEC}.complexity:sic_from_traces",
        tr,
        {"tr_psi_u": "nonneg", "tr_psi_w": explicit([-1.0, NAN, "a", HUGE]), "m": "int", "n": "int"},
        drawn=1,
    )
    out += bad_args(
        A_,
        f"{SEC}.complexity:sic_asymptotic_from_traces",
        {"N": 100, "tr_psi_u": 2.0, "tr_psi_w": 1.0, "m": 1, "n": 2, "r_sigma": 10.0},
        {"r_sigma": explicit([0.0, -1.0, NAN, "a"]), "m": explicit([0, -1, 2.5, "1"])},
        drawn=0,
    )
    out += bad_args(
        A_,
        f"{SEC}.complexity:input_upper_bound",
        {"N": 100, "m": 1, "n": 2, "r_sigma": 10.0},
        {"N": N_BAD, "m": explicit([0, -1, 2.5, "1", None]), "r_sigma": explicit([0.0, -1.0, NAN, "a"])},
        drawn=0,
    )
    out += bad_args(
        A_,
        f"{SEC}.complexity:noise_upper_bound",
        {"N": 100, "m": 1, "n": 2},
        {"N": explicit([0, 1, -5, 2.5, NAN, "100"]), "n": explicit([0, -1, 2.5, "1", None])},
        drawn=0,
    )
    out += bad_args(
        A_,
        f"{SEC}.complexity:estimation_error",
        {"A": A2, "B": B2, "A_hat": A2, "B_hat": B2},
        {
            "A_hat": explicit([np.zeros((3, 3)), A2 + 1j, np.full((2, 2), NAN), "abc", None]),
            "B_hat": explicit([np.zeros((2, 2)), np.array([[1j], [0]]), None]),
        },
        drawn=0,
    )
    bayes = f"{SEC}.bayes_complexity"
    out += bad_args(
        A_,
        f"{bayes}:bayesian_sample_identifying_complexity",
        {"N": 100, "A": A2, "B": B2, "sigma_u2": 1.0, "sigma_w2": 0.1, "precision": 1.0},
        {
            "precision": explicit([-1.0, NAN, INF, "a", None, np.ones((5, 5)), np.array([[1, 2], [3, -4.0]]), 1 + 1j]),
            "N": explicit([0, -1, 2.5, "a"]),
        },
        drawn=0,
    )
    out += bad_args(
        A_,
        f"{bayes}:bayes_risk_given_gram",
        {"G": np.eye(3), "precision": 1.0, "sigma_w2": 0.1, "n": 2},
        {
            "G": explicit([np.eye(2), -np.eye(3), np.full((3, 3), NAN), np.eye(3) * 1j, "abc", np.triu(np.ones((3, 3)))]),
            "n": explicit([0, -1, 2.5, "2"]),
            "sigma_w2": explicit([-1.0, NAN, 0.0]),
        },
        drawn=0,
    )
    out += bad_args(
        A_,
        f"{bayes}:prior_sample_equivalent",
        {"tr_precision": 1.0, "tr_psi_u": 2.0, "tr_psi_w": 1.0, "m": 1, "sigma_u2": 1.0, "sigma_w2": 0.1},
        {"tr_precision": explicit([-1.0, NAN, "a"]), "m": explicit([0, -1, 2.5])},
        drawn=0,
    )
    return out


def _deciphering() -> list[Case]:
    out: list[Case] = []
    dec = f"{SEC}.deciphering"
    lam_bad = BAD["pos"] + explicit([1e12, 2.0**53, 1e300], "hang")
    valid = {"N": 100, "lam": 74, "upsilon": 442e15}
    scheme = {"scheme": "name", "adversary": "name"}
    out += bad_args(
        A_,
        f"{dec}:sample_deciphering_time",
        valid,
        {"N": explicit([-1, 2.5, NAN, "100", None, True, np.array([1.0, NAN])]), "lam": lam_bad, "upsilon": "pos", **scheme},
    )
    out += bad_args(
        A_,
        f"{dec}:sample_deciphering_time_exact",
        valid,
        {
            "N": explicit([-1, 2.5, NAN, "100", None, True]),
            "lam": explicit([-1.0, NAN, 1e12, 10**12, 2.0**53, HUGE, "a"]),
            "upsilon": explicit([0.0, -1.0, NAN, HUGE, "a"]),
        },
        drawn=0,
        timeout=30,
    )
    out += bad_args(A_, f"{dec}:per_sample_cost", {"lam": 74, "upsilon": 442e15}, {"lam": lam_bad, "upsilon": "pos"}, drawn=1)
    mas = {"tau_c": 3.1536e8, "lam": 74, "upsilon": 442e15}
    out += bad_args(
        A_,
        f"{dec}:max_affordable_samples",
        mas,
        {"tau_c": "pos", "lam": lam_bad + explicit([10**12], "hang"), "upsilon": "pos", **scheme},
        drawn=1,
    )
    out += bad_args(
        A_,
        f"{dec}:max_affordable_samples",
        {"tau_c": 1.0, "lam": 10**12, "upsilon": 1.0},
        {"lam": explicit([10**12, 2.0**53, 1e15], "hang")},
        name="max_affordable_samples.issue",
        drawn=0,
        timeout=30,
    )
    out += bad_args(A_, f"{dec}:keys_to_break", {"N": 100}, {"N": explicit([-1, 2.5, NAN, "a", None, True]), **scheme}, drawn=0)
    out += bad_args(A_, f"{dec}:independent_keys", {}, scheme, drawn=0)
    out += bad_args(
        A_,
        f"{dec}:break_cost",
        {"model": "paper", "security_parameter": 74},
        {"model": "name", "security_parameter": explicit([-1.0, NAN, INF, "a", 1e12, HUGE])},
        drawn=0,
    )
    out += bad_args(
        A_,
        f"{dec}:break_cost",
        {"model": "paper", "key_length": 712},
        {"key_length": explicit([0, -1, 2.5, "a", None, True, 10**308, HUGE, 39])},
        name="break_cost.key_length",
        drawn=0,
    )
    return out


def _design() -> list[Case]:
    out: list[Case] = []
    des = f"{SEC}.design"
    tau_bad = BAD["pos"] + explicit([1e-300, 1e-20], "silent")
    out += bad_args(
        A_,
        f"{des}:optimal_security_parameter",
        {"N_star": 13159, "tau_c": 3.1536e8, "upsilon": 442e15},
        {"N_star": explicit([0, -1, 2.5, NAN, "a", None, True]), "tau_c": BAD["pos"], "upsilon": BAD["pos"]},
        drawn=1,
    )
    gamma = lambda N: 1.0 / N  # noqa: E731
    sec = {"lam": 74, "gamma": gamma, "gamma_c": 1e-6, "tau_c": 3.1536e8, "upsilon": 442e15}
    out += bad_args(
        A_,
        f"{des}:is_secure",
        sec,
        {
            "lam": explicit([-1.0, NAN, "a", None, 1e12]),
            "gamma": explicit(
                [
                    "abc",
                    None,
                    3,
                    Named("N->nan", lambda N: NAN),
                    Named("N->-1", lambda N: -1.0),
                    Named("N->'x'", lambda N: "x"),
                    Named("N->1j", lambda N: 1j),
                ],
                "traceback",
            ),
            "gamma_c": explicit([0.0, -1.0, NAN, "a"]),
            "gamma_infimum": explicit([-1.0, NAN, "a"]),
        },
        drawn=0,
    )
    traces = {
        "tr_psi_u": 2.0,
        "tr_psi_w": 1.0,
        "m": 1,
        "n": 2,
        "sigma_u2": 10.0,
        "sigma_w2": 0.1,
        "gamma_c": 1e-6,
        "tau_c": 3.1536e8,
        "upsilon": 442e15,
    }
    out += bad_args(
        A_,
        _on_values(f"{des}:design_from_traces"),
        traces,
        {
            "gamma_c": BAD["pos"],
            "tau_c": tau_bad,
            "upsilon": "pos",
            "method": "name",
            "sigma_u2": explicit([0.0, -1.0, NAN, HUGE]),
            "m": explicit([0, -1, 2.5, "1", True]),
        },
        name="design_from_traces",
    )
    out += bad_args(
        A_,
        _on_values(f"{des}:design_security_parameter", plant=True),
        {"A": A2, "B": B2, "sigma_u2": 10.0, "sigma_w2": 0.1, "gamma_c": 1e-6, "tau_c": 3.1536e8, "upsilon": 442e15},
        {"A": BAD["matrix"][:6] + UNSTABLE, "sigma_w2": "pos", "sigma_x2": "nonneg", "method": explicit(["bogus", 3, None])},
        name="design_security_parameter",
        drawn=0,
    )
    out += bad_args(A_, f"{des}:paper_design_example", {}, {"method": "name"}, drawn=1)
    ss = f"{SEC}.sample_size"
    out += bad_args(
        A_,
        f"{ss}:optimal_sample_size",
        {"tr_psi_u": 2.0, "tr_psi_w": 1.0, "m": 1, "n": 2, "r_sigma": 100.0, "gamma_c": 1e-6},
        {"gamma_c": BAD["pos"], "r_sigma": explicit([0.0, -1.0, NAN, "a", HUGE]), "tr_psi_u": explicit([-1.0, NAN])},
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        A_,
        f"{ss}:exact_optimal_sample_size",
        {"tr_psi_u": 2.0, "tr_psi_w": 1.0, "m": 1, "n": 2, "sigma_u2": 10.0, "sigma_w2": 0.1, "gamma_c": 1e-6},
        {"gamma_c": explicit([0.0, -1.0, NAN, "a"]), "sigma_w2": explicit([0.0, -1.0, NAN])},
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        A_,
        f"{ss}:minimum_sample_size",
        {"gamma": lambda N: 1.0 / N, "gamma_c": 1e-3},
        {
            "gamma": explicit(
                [
                    Named("N->nan", lambda N: NAN),
                    Named("N->'x'", lambda N: "x"),
                    Named("N->1", lambda N: 1.0),
                    "abc",
                    None,
                    Named("N->-1/N", lambda N: -1.0 / N),
                ],
                "hang",
            ),
            "gamma_c": explicit([0.0, -1.0, NAN, "a"]),
            "n_min": explicit([-1, 2.5, "a"]),
            "n_max": explicit([1, -1, 2.5, "a"]),
        },
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        A_,
        f"{ss}:sample_size_for_rate",
        {"rate": 1.0, "gamma_c": 1e-6},
        {"rate": explicit([0.0, -1.0, NAN, "a", HUGE]), "gamma_c": explicit([0.0, -1.0, NAN])},
        drawn=0,
    )
    return out


def _cost_models() -> list[Case]:
    out: list[Case] = []
    cm = f"{SEC}.cost_models"
    k_bad = explicit([0, -1, 2.5, NAN, INF, "712", None, True, 1 + 0j, 39], "silent") + explicit(
        [10**308, 1e308, HUGE, HUGER], "hang"
    )
    out += bad_args(
        A_,
        f"{cm}:gnfs_log2_complexity",
        {"k": 712},
        {"k": k_bad, "correction": explicit([NAN, "bogus", None, HUGE, -1e308])},
        drawn=0,
    )
    out += bad_args(A_, f"{cm}:gnfs_complexity", {"k": 712}, {"k": explicit([0, -1, NAN, "712", 10**308])}, drawn=0)
    out += bad_args(A_, f"{cm}:bit_security_of_key_length", {"k": 712}, {"k": k_bad}, drawn=0)
    out += bad_args(
        A_,
        f"{cm}:minimum_key_length",
        {"lam": 74},
        {"lam": BAD["pos"] + explicit([1e12, 1e300, 10**12], "hang"), "gnfs_correction": explicit([NAN, "bogus", HUGE])},
        drawn=1,
    )
    out += bad_args(A_, f"{cm}:pollard_rho_log2_operations", {"k": 712}, {"k": explicit([0, -1, NAN, "a", None, HUGE])}, drawn=0)
    out += bad_args(
        A_,
        f"{cm}:check_gnfs_correction",
        {"correction": 0.0},
        {"correction": explicit(["bogus", NAN, INF, None, True, [1.0], HUGE, 2 + 1j])},
        drawn=0,
    )
    out += bad_args(
        A_, f"{cm}:check_security_parameter", {"lam": 74}, {"lam": BAD["pos"] + explicit([1e12, 2.0**53], "hang")}, drawn=1
    )
    out += bad_args(A_, f"{cm}:deciphering_model", {"name": "paper"}, {"name": "name"}, drawn=1)
    out += bad_args(
        A_,
        lambda kw: api(f"{cm}:deciphering_model")("paper", **kw),
        {},
        {"bogus_option": explicit([1], "silent"), "gnfs_correction": explicit([NAN, "x"])},
        name="deciphering_model(paper, **options)",
        drawn=0,
    )
    out += bad_args(
        A_,
        lambda kw: api(f"{cm}:deciphering_model")("precomputation", **kw),
        {},
        {"calibration": explicit(["abc", 42, [1, 2], {"records": []}], "traceback")},
        name="deciphering_model(precomputation)",
        drawn=0,
    )
    out += bad_args(
        A_,
        lambda kw: api(f"{cm}:deciphering_model")(kw.pop("model")).break_cost(**kw),
        {"model": "paper", "key_length": 712},
        {"key_length": explicit([0, -1, 2.5, "a", None, 10**308, HUGE])},
        name="CostModel.break_cost",
        drawn=0,
    )
    out += bad_args(
        A_,
        lambda kw: api(f"{cm}:deciphering_model")(kw.pop("model")).break_cost(**kw),
        {"model": "generic", "key_length": 712},
        {"key_length": explicit([0, -1, 2.5, "a", 10**308])},
        name="GenericModel.break_cost",
        drawn=0,
    )
    kl = f"{SEC}.key_length"
    out += bad_args(
        A_,
        _on_values(f"{kl}:design_key_length"),
        {"model": "paper", "N_star": 13159, "tau_c": 3.1536e8, "upsilon": 442e15},
        {
            "model": "name",
            "N_star": explicit([0, -1, 2.5, NAN, "a", HUGE]),
            "tau_c": BAD["pos"] + explicit([1e-300]),
            "upsilon": explicit([0.0, -1.0, NAN, HUGE, 1e300]),
            "gnfs_correction": explicit([NAN, "bogus"]),
            "adversary": explicit(["bogus", None, 3]),
        },
        name="design_key_length",
        drawn=1,
    )
    out += bad_args(
        A_,
        _on_values(f"{kl}:design_key_length"),
        {"model": "generic", "N_star": 2, "tau_c": 1e300, "upsilon": 1e300},
        {"tau_c": explicit([1e300], "hang")},
        name="design_key_length(generic, 1e600)",
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        A_,
        _on_values(f"{kl}:key_length_value"),
        {"model": "paper", "key_length": 712, "N_star": 13159, "tau_c": 3.1536e8, "upsilon": 442e15},
        {"key_length": explicit([0, -1, 2.5, "a", None, 10**308, HUGE]), "N_star": explicit([0, -1, 2.5])},
        name="key_length_value",
        drawn=0,
    )
    out += bad_args(
        A_,
        f"{kl}:defense_budget",
        {"tau_c": 3.1536e8, "upsilon": 442e15},
        {"tau_c": explicit([0.0, -1.0, NAN, "a", HUGE]), "upsilon": explicit([0.0, NAN, HUGE])},
        drawn=0,
    )
    return out


def _exact() -> list[Case]:
    out: list[Case] = []
    ex = f"{SEC}.exact"
    out += bad_args(A_, f"{ex}:decimal_fraction", {"name": "x", "value": 1.5}, {"value": BAD["pos"]}, drawn=1)
    out += bad_args(
        A_,
        f"{ex}:binary_fraction",
        {"name": "x", "value": 1.5},
        {"value": explicit([NAN, INF, "a", None, 2 + 1j, HUGER])},
        drawn=0,
    )
    out += bad_args(
        A_,
        f"{ex}:pow2",
        {"x": 10},
        {"x": explicit([NAN, INF, "a", None, 1e9, -1e9, 1e300, 2 + 1j, HUGE], "hang")},
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        A_, f"{ex}:floor_log2", {"x": Fraction(3, 2)}, {"x": explicit([Fraction(0), Fraction(-1, 2), 1.5, "a", None, 0])}, drawn=0
    )
    out += bad_args(
        A_, f"{ex}:log2_fraction", {"x": Fraction(3, 2)}, {"x": explicit([Fraction(0), Fraction(-1), "a", None])}, drawn=0
    )
    return out


def _attack_design() -> list[Case]:
    out: list[Case] = []
    ad = f"{SEC}.attack_design"
    valid = {"A": A2, "B": B2, "sigma_u2": 1.0, "sigma_w2": 0.1}
    out += bad_args(
        A_,
        f"{ad}:optimal_attack_design",
        valid,
        {
            "feedback": BAD["bool"],
            "sigma_u2": BAD["pos"][:8],
            "sigma_w2": explicit([0.0, -1.0, NAN, HUGE]),
            "solver": explicit(["bogus", 3, ["SCS"]], "traceback"),
            "tol": explicit([0.0, -1.0, NAN, "a"]),
            "max_dimension": explicit([0, -1, 2.5, "a", True]),
            "A": UNSTABLE + explicit([A2 + 1j]),
        },
        drawn=0,
    )
    out += bad_args(
        A_,
        f"{ad}:optimal_attack_design",
        {"A": 0.5 * np.eye(200), "B": np.eye(200), "sigma_u2": 1.0, "sigma_w2": 1.0},
        {"sigma_u2": explicit([1.0], "hang")},
        name="optimal_attack_design(n+m=400)",
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        A_,
        f"{ad}:gaussian_attack_design",
        valid,
        {"sigma_u2": explicit([0.0, -1.0, NAN, "a"]), "B": explicit([np.ones((3, 1))])},
        drawn=0,
    )
    out += bad_args(
        A_,
        f"{ad}:gamma_opt",
        {"N": 100, **valid},
        {"N": explicit([0, 1, -5, 2.5, NAN, "a", None]), "feedback": explicit(["no", 0, None, NAN])},
        drawn=0,
    )
    robust = {**valid, "gamma_c": 1e-6, "tau_c": 3.1536e8, "upsilon": 442e15}
    out += bad_args(
        A_,
        _on_values(f"{ad}:robust_security_design", plant=True),
        robust,
        {"kind": "name", "gamma_c": explicit([0.0, -1.0, NAN]), "tau_c": explicit([1e-300, -1.0, NAN])},
        name="robust_security_design",
        drawn=0,
    )

    def robust_other_design(kw: dict[str, Any]) -> Any:
        design = api(f"{ad}:optimal_attack_design")(A2, B2, sigma_u2=5.0, sigma_w2=0.1)
        return _on_values(f"{ad}:robust_security_design", plant=True)({"design": design, **robust, **kw})

    out += bad_args(
        A_,
        robust_other_design,
        {},
        {"sigma_u2": explicit([1.0, 2.0])},
        name="robust_security_design(design of sigma_u2=5)",
        drawn=0,
    )
    out += bad_args(A_, f"{ad}:sdp_estimate", {"dimension": 10}, {"dimension": explicit([0, -1, 2.5, "a", None, HUGE])}, drawn=0)
    return out


def _units_presets_files() -> list[Case]:
    out: list[Case] = []
    out += bad_args("units", "encctl_gym.units:parse_duration", {"value": "10y"}, {"value": "duration"}, drawn=2)
    out += bad_args(
        "presets",
        "encctl_gym.presets:get_preset",
        {"name": "small"},
        {"name": explicit(["bogus", "", ["small"], 3, None, "SMALL ", b"small"])},
        drawn=0,
    )

    def plant(which: str) -> Any:
        def run(tmp: Path) -> Any:
            return api("encctl_gym.plant_file:load_plant_file")(write_file(tmp, which))

        return run

    for which in FILES:
        if which == "unstable":  # a plant file need not be stable (the design checks that)
            continue
        out.append(
            case(
                "plant_file",
                f"load_plant_file({which})",
                "hang" if which in ("alias_bomb", "oversized", "deep_nesting_json") else "traceback",
                plant(which),
            )
        )

    def records(which: str) -> Any:
        def run(tmp: Path) -> Any:
            return api(f"{SEC}.records:load_records")(write_file(tmp, which))

        return run

    for which in (
        "missing",
        "directory",
        "empty",
        "broken_yaml",
        "top_level_list",
        "deep_nesting_json",
        "digits_5000",
        "nan_json",
        "binary_junk",
        "oversized",
        "unknown_key",
    ):
        out.append(case(A_, f"load_records({which})", "traceback", records(which)))
    out += bad_args(
        A_,
        f"{SEC}.records:parse_records",
        {"data": {}},
        {
            "data": explicit(
                [[], "abc", None, 42, {"records": "x"}, {"records": [], "nist": [[1, 2]]}, {"records": [{"name": 1}]}],
                "traceback",
            )
        },
        drawn=0,
    )
    out += bad_args(
        A_, f"{SEC}.records:nist_key_length", {"bits": 80}, {"bits": explicit([NAN, -1.0, "a", None, HUGE, 2 + 1j])}, drawn=0
    )
    out += bad_args(
        A_, f"{SEC}.records:nist_strength", {"key_length": 2048}, {"key_length": explicit([NAN, -1, 2.5, "a", None])}, drawn=0
    )
    return out


def _valid() -> list[Case]:
    def paper_example(_: Path) -> None:
        d = api(f"{SEC}.design:paper_design_example")()
        assert (d.N_star, d.lam_star, d.k_star) == (13159, 74, 712), (d.N_star, d.lam_star, d.k_star)

    def deciphering(_: Path) -> None:
        t = api(f"{SEC}.deciphering:sample_deciphering_time")(10, 20, 2.0**10)
        assert t == 10 * 2.0**10, t

    def duration(_: Path) -> None:
        parse = api("encctl_gym.units:parse_duration")
        year = api("encctl_gym.units:SECONDS_PER_YEAR")
        assert parse("10y") == 10 * year and parse("2h") == 7200 and parse(3600) == 3600

    def gnfs(_: Path) -> None:
        # eq:opt_key at k = 712: log2 Omega = 74.004 (the design table)
        bits = float(api(f"{SEC}.cost_models:bit_security_of_key_length")(712))
        assert abs(bits - 74.004) < 5e-3, bits
        ln_n = 712 * math.log(2)
        expected = (64 / 9) ** (1 / 3) * ln_n ** (1 / 3) * math.log(ln_n) ** (2 / 3) / math.log(2)
        assert abs(bits - expected) < 1e-9, (bits, expected)

    def gramian(_: Path) -> None:
        P = api(f"{SEC}.gramians:controllability_gramian")(np.array([[0.5]]), np.array([[1.0]]))
        assert abs(float(P[0, 0]) - 1 / 0.75) < 1e-12

    return [
        case(A_, "valid: the paper's design example", "silent", paper_example, expect="result"),
        case(A_, "valid: tau = N 2^lambda / Upsilon", "silent", deciphering, expect="result"),
        case("units", "valid: durations", "silent", duration, expect="result"),
        case(A_, "valid: eq:opt_key at 712 bits", "silent", gnfs, expect="result"),
        case(A_, "valid: Gramian of a scalar system", "silent", gramian, expect="result"),
    ]


def _beyond_the_issue() -> list[Case]:
    """Cases of the same classes found while fixing the issue's (not among its reproducers)."""

    def plant_text(name: str, text: str, **kw: Any) -> Any:
        def run(tmp: Path) -> Any:
            path = tmp / name
            path.write_text(text)
            return api("encctl_gym.plant_file:load_plant_file")(path, **kw)

        return run

    def yaml_exponents(spec: Any) -> None:  # YAML 1.1 would read 1e-6 and 442e15 as strings
        assert (spec.preset.sigma_w2, spec.preset.upsilon, float(spec.A[0, 0])) == (1e-6, 442e15, 0.5), spec.values()

    def search_to_n_max(_: Path) -> int:  # 1/N < 1e-3 first at N = 1001, which is n_max itself
        return api(f"{SEC}.sample_size:minimum_sample_size")(lambda N: Fraction(1, N), 1e-3, n_max=1001)

    def record_year(tmp: Path) -> Any:
        data_file = api(f"{SEC}.records:DATA_FILE")
        path = tmp / "records.json"
        path.write_text(data_file.read_text().replace('"year": 2015', '"year": ' + "9" * 400, 1))
        return api(f"{SEC}.records:load_records")(path)

    def check_1001(n: Any) -> None:
        assert n == 1001, n

    return [
        case(
            "plant_file",
            "load_plant_file(JSON with A twice)",
            "silent",
            plant_text("dup.json", '{"A": [[0.5]], "B": [[1]], "A": [[0.9]]}'),
        ),
        case(
            "plant_file",
            "load_plant_file(YAML with A twice)",
            "silent",
            plant_text("dup.yaml", "A: [[0.5]]\nB: [[1]]\nA: [[0.9]]\n"),
        ),
        case(
            "plant_file",
            "valid: load_plant_file(YAML exponents 1e-6, 442e15)",
            "traceback",
            plant_text("exp.yaml", "A: [[5e-1]]\nB: [[1]]\nsigma_w2: 1e-6\nupsilon: 442e15\n"),
            expect="result",
            check=yaml_exponents,
        ),
        case(
            "plant_file",
            "load_plant_file(defaults=42)",
            "traceback",
            plant_text("p.json", '{"A": [[0.5]], "B": [[1]]}', defaults=42),
        ),
        case(
            "plant_file",
            "load_plant_file(defaults={'bogus': 1})",
            "silent",
            plant_text("p2.json", '{"A": [[0.5]], "B": [[1]]}', defaults={"bogus": 1}),
        ),
        case(
            A_,
            "controllability_gramian(B=1e200: B B^T overflows)",
            "traceback",
            lambda _: api(f"{SEC}.gramians:controllability_gramian")(np.array([[0.5]]), np.array([[1e200]])),
        ),
        case(
            A_,
            "valid: minimum_sample_size(n_max=1001, the answer)",
            "traceback",
            search_to_n_max,
            expect="result",
            check=check_1001,
        ),
        case(
            A_,
            "minimum_sample_size(n_max=10^5000, never below)",
            "traceback",
            lambda _: api(f"{SEC}.sample_size:minimum_sample_size")(lambda N: 1.0, 0.5, n_max=10**5000),
            slow=True,
        ),  # 16610 doublings
        case(A_, "load_records(a year of 400 digits)", "silent", record_year),
    ]


def cases() -> list[Case]:
    """Every security-analysis case."""
    return [
        *_gramians(),
        *_complexity(),
        *_deciphering(),
        *_design(),
        *_cost_models(),
        *_exact(),
        *_attack_design(),
        *_units_presets_files(),
        *_valid(),
        *_beyond_the_issue(),
    ]
