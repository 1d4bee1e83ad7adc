"""The defender's options of ``encctl-gym design`` and their section of the output.

``--rotate-every K|auto``, ``--audit-rate p|auto`` with ``--detection-delta``, ``--defense-noise S``
and ``--min-key-length``: parsed here, designed by :func:`~.defense_design.design_defenses`, printed
by :func:`format_defenses`. The design command (:mod:`encctl_gym.design_command`) registers
:func:`add_arguments`; :mod:`.design_cli` calls :func:`defense_options` and :func:`format_defenses`;
nothing is designed here.
"""

from __future__ import annotations

import argparse
from typing import Any

from .._validation import check_int, parse_number
from ..errors import ParameterError
from . import verification_design
from .defense_design import DEFAULT_MIN_KEY_LENGTH, DefenseDesign, DefenseMix

__all__ = ["add_arguments", "defense_options", "format_defenses"]

#: The options of this module (destination names) and their CLI spelling.
OPTIONS: dict[str, str] = {
    "rotate_every": "--rotate-every",
    "audit_rate": "--audit-rate",
    "detection_delta": "--detection-delta",
    "defense_noise": "--defense-noise",
    "min_key_length": "--min-key-length",
    "input_bound": "--input-bound",
    "confidentiality_floor": "--confidentiality-floor",
    "detector": "--detector",
    "false_alarm_rate": "--false-alarm",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the defender's options."""
    g = parser.add_argument_group("defender's levers (a section per cost model: the cheapest secure mix)")
    g.add_argument("--rotate-every", dest="rotate_every", metavar="K|auto", help="move to a fresh group every K steps")
    g.add_argument("--audit-rate", dest="audit_rate", metavar="p|auto", help="audit probability per step, in [0, 1]")
    g.add_argument(
        "--detection-delta",
        dest="detection_delta",
        metavar="D",
        help="tolerated probability that an attacker collects N* samples before an audit (default 1e-3)",
    )
    g.add_argument("--defense-noise", dest="defense_noise", metavar="S", help="variance of the defender's input noise (>= 0)")
    g.add_argument(
        "--min-key-length",
        dest="min_key_length",
        metavar="BITS",
        help=f"key length of an audit-secure mix (default {DEFAULT_MIN_KEY_LENGTH})",
    )
    g.add_argument(
        "--input-bound",
        dest="input_bound",
        metavar="U",
        help="the sparse attacker's input bound u_max (default 4 sigma_u, the environment's actuator bound): audits "
        "must catch one of its fewest falsified steps",
    )
    g.add_argument(
        "--confidentiality-floor",
        dest="confidentiality_floor",
        metavar="BITS|nist|nist-2031",
        help="smallest key of any mix, for the signals' own confidentiality (nist: NIST SP 800-57's 2048 bits through "
        "2030; nist-2031: 3072); default none",
    )
    g.add_argument(
        "--detector",
        dest="detector",
        metavar="chi2|cusum",
        help="a detector on the innovation: the key an attacker needs when it must stay undetected with probability at "
        "least 1 - delta (--detection-delta), and the mix the detector secures",
    )
    g.add_argument(
        "--false-alarm", dest="false_alarm_rate", metavar="A", help="the detector's false alarms per step (default 1e-4)"
    )
    verification_design.add_arguments(g)  # --verify NAME|auto, --verify-param KEY=VALUE


def _number_or_auto(name: str, text: str | None) -> float | str | None:
    if text is None:
        return None
    if text.strip().lower() == "auto":
        return "auto"
    return parse_number(name, text)


def defense_options(args: argparse.Namespace) -> dict[str, Any] | None:
    """The keyword arguments of :func:`~.defense_design.design_defenses` from the command line,
    or ``None`` when no defender option was given (values are checked by the design)."""
    verify = verification_design.verify_options(args)
    if all(getattr(args, dest, None) is None for dest in OPTIONS) and verify is None:
        return None
    rotate = _number_or_auto("rotate_every", args.rotate_every)
    out: dict[str, Any] = {
        "rotate_every": rotate if rotate in (None, "auto") else check_int("rotate_every", rotate),
        "audit_rate": _number_or_auto("audit_rate", args.audit_rate),
    }
    if args.detection_delta is not None:
        out["detection_delta"] = parse_number("detection_delta", args.detection_delta)
    if args.defense_noise is not None:
        out["sigma_d2"] = parse_number("defense_noise", args.defense_noise)
    if args.min_key_length is not None:
        out["min_key_length"] = check_int("min_key_length", parse_number("min_key_length", args.min_key_length))
    if args.input_bound is not None:
        out["input_bound"] = parse_number("input_bound", args.input_bound)
    if args.confidentiality_floor is not None:
        text = args.confidentiality_floor.strip()
        out["confidentiality_floor"] = (
            text
            if text.lower().startswith("nist")
            else check_int("confidentiality_floor", parse_number("confidentiality_floor", text))
        )
    if args.detector is not None:
        out["detector"] = args.detector.strip().lower()
    if args.false_alarm_rate is not None:
        if args.detector is None:
            raise ParameterError("--false-alarm needs --detector chi2|cusum")
        out["false_alarm_rate"] = parse_number("false_alarm_rate", args.false_alarm_rate)
    if verify is not None:
        out["verify"] = verify
    return out


def _rotation(K: int | None) -> str:
    return "never" if K is None else str(K)


def _mix_row(label: str, mix: DefenseMix | None, step0: float) -> str:
    if mix is None:
        return f"    {label:<11}{'-':>6}"
    why = (
        "+".join(w for w, ok in (("key", mix.key_secure), ("audit", mix.audit_secure), ("detector", mix.detector_secure)) if ok)
        or "no"
    )
    return (
        f"    {label:<11}{mix.key_length:>6d}{_rotation(mix.rotate_every):>8}{mix.audit_rate:>11.4g}{why:>11}"
        f"{mix.step_seconds:>12.4g}{mix.rotation_seconds:>12.4g}{mix.audit_seconds:>12.4g}{mix.total_seconds:>12.4g}"
        f"{mix.total_seconds / step0:>9.3g}"
    )


def _detector_lines(d: DefenseDesign) -> list[str]:
    st = d.stealth
    if st is None:
        return []
    head = (
        f"  detector {st.detector} ({d.false_alarm_rate:g} false alarms per step): the honest loop alarms within N* = "
        f"{st.horizon} steps with probability {st.false_alarm_within:.3g}; an attacker unseen with probability >= "
        f"1 - delta "
    )
    if st.samples != float("inf"):
        return [
            head + f"needs {st.samples} samples at sigma_d2 = {st.sigma_d2:.4g} (its detection {st.detection:.3g}); the "
            "detector's mix keeps max(that, N*) out"
        ]
    if st.false_alarm_within <= d.detection_delta:
        return [head + "cannot reach gamma_c: the detector alone holds (its mix: the smallest key)"]
    return [
        head + "cannot reach gamma_c, but the honest loop alarms more often than delta: the alarms do not tell an attack "
        "from noise, and the detector secures no mix"
    ]


def format_defenses(design: DefenseDesign) -> list[str]:
    """The defender's section of the text output."""
    d = design
    price = d.noise_price
    lines = [
        "",
        f"  Defender's levers: rotate every {d.rotate_every if d.rotate_every is not None else 'never'}, "
        f"audit rate {d.audit_rate if d.audit_rate is not None else 0}, defense noise sigma_d2 = {d.sigma_d2:g}, "
        f"delta = {d.detection_delta:g}",
        f"  N* = {d.N_star} (eq:sic2 with the defender's noise), lambda* = {d.lam_star}; an attacker falsifying every "
        f"sample meets an audit from p* = 1 - delta^(1/N*) = {d.minimum_audit_rate:.4g}",
        f"  sparse attacker at the input bound u_max = {d.input_bound:.4g}: J_min = {d.fewest_falsified_steps} falsified steps; "
        f"audit-secure from p_J = 1 - delta^(1/{d.audit_steps}) = {d.sparse_audit_rate:.4g} (x {d.sparse_audit_rate / d.minimum_audit_rate:.3g} p*)",
        "  passive attacker (the defender's noise alone): "
        + (
            "cannot identify B without noise"
            if d.passive_samples == float("inf")
            else f"{d.passive_samples:.6g} samples; every key must keep them out"
        ),
        "  confidentiality floor: "
        + (
            f"{d.confidentiality_floor} bits"
            if d.confidentiality_floor is not None
            else "none (--confidentiality-floor nist: NIST SP 800-57 Part 1 Rev. 5, 2048 bits through 2030, 3072 after)"
        ),
        *_detector_lines(d),
        f"  one audit (Phi x and the comparison, measured) = {d.local_control_seconds:.3g} s; "
        f"noise control cost (LQR, Q = R = I): J = {price['cost_defended']:.4g} vs {price['cost_base']:.4g} "
        f"(x {price['cost_defended'] / price['cost_base']:.3g}), tr P x {price['trace_P_defended'] / price['trace_P_base']:.3g}",
    ]
    for name, m in d.models.items():
        step0 = m.step_seconds_at_k_star
        passive = "" if m.passive_key_length is None else f"; the passive attacker needs k >= {m.passive_key_length}"
        lines += [
            "",
            f"  {name}: k* = {m.k_star} with the fixed group and no audits (encrypted step {step0:.4g} s); smallest key "
            f"{m.key_floor}{passive}",
            f"    {'mix':<11}{'k':>6}{'K':>8}{'p':>11}{'secure by':>11}{'step s':>12}{'rotation s':>12}"
            f"{'audits s':>12}{'total s':>12}{'x k*':>9}",
            _mix_row("chosen", m.chosen, step0),
            _mix_row("key only", m.key_only, step0),
            _mix_row("audit only", m.audit_only, step0),
        ]
        if d.stealth is not None:
            lines.append(_mix_row("detector", m.detector_only, step0))
    lines += [
        "",
        "  Cost per step in seconds on the reference machine: step = (3n + 1) modular exponentiations at k bits;",
        "  rotation = (safe-prime search + 1 + 3nm exponentiations) / K; audits = p x one audit; x k*: total over the",
        "  encrypted step at the fixed-group k*. key only: the cheapest key-secure mix without audits; audit only: the",
        f"  audit-secure mix at the smallest key (--min-key-length {d.min_key_length}, lifted to the floor and the passive",
        "  attacker's key). Audit-secure: the sparse attacker's J falsified steps meet an audit. detector: the key that keeps the",
        "  stealthy attacker's samples (at least N*) out, its check (one local computation per step) in the audits column.",
        "  The noise's control cost is per step,",
        "  in the units of the quadratic cost, the same for every mix.",
    ]
    return lines + verification_design.format_verification(design)
