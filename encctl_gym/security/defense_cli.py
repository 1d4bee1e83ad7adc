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
    if verify is not None:
        out["verify"] = verify
    return out


def _rotation(K: int | None) -> str:
    return "never" if K is None else str(K)


def _mix_row(label: str, mix: DefenseMix | None, step0: float) -> str:
    if mix is None:
        return f"    {label:<11}{'-':>6}"
    why = "+".join(w for w, ok in (("key", mix.key_secure), ("audit", mix.audit_secure)) if ok) or "no"
    return (
        f"    {label:<11}{mix.key_length:>6d}{_rotation(mix.rotate_every):>8}{mix.audit_rate:>11.4g}{why:>11}"
        f"{mix.step_seconds:>12.4g}{mix.rotation_seconds:>12.4g}{mix.audit_seconds:>12.4g}{mix.total_seconds:>12.4g}"
        f"{mix.total_seconds / step0:>9.3g}"
    )


def format_defenses(design: DefenseDesign) -> list[str]:
    """The defender's section of the text output."""
    d = design
    price = d.noise_price
    lines = [
        "",
        f"  Defender's levers: rotate every {d.rotate_every if d.rotate_every is not None else 'never'}, "
        f"audit rate {d.audit_rate if d.audit_rate is not None else 0}, defense noise sigma_d2 = {d.sigma_d2:g}, "
        f"delta = {d.detection_delta:g}",
        f"  N* = {d.N_star} (eq:sic2 with the defender's noise), lambda* = {d.lam_star}; "
        f"audit-secure from p* = 1 - delta^(1/N*) = {d.minimum_audit_rate:.4g}",
        f"  one audit (Phi x and the comparison, measured) = {d.local_control_seconds:.3g} s; "
        f"noise control cost (LQR, Q = R = I): J = {price['cost_defended']:.4g} vs {price['cost_base']:.4g} "
        f"(x {price['cost_defended'] / price['cost_base']:.3g}), tr P x {price['trace_P_defended'] / price['trace_P_base']:.3g}",
    ]
    for name, m in d.models.items():
        step0 = m.step_seconds_at_k_star
        lines += [
            "",
            f"  {name}: k* = {m.k_star} with the fixed group and no audits (encrypted step {step0:.4g} s)",
            f"    {'mix':<11}{'k':>6}{'K':>8}{'p':>11}{'secure by':>11}{'step s':>12}{'rotation s':>12}"
            f"{'audits s':>12}{'total s':>12}{'x k*':>9}",
            _mix_row("chosen", m.chosen, step0),
            _mix_row("key only", m.key_only, step0),
            _mix_row("audit only", m.audit_only, step0),
        ]
    lines += [
        "",
        "  Cost per step in seconds on the reference machine: step = (3n + 1) modular exponentiations at k bits;",
        "  rotation = (safe-prime search + 1 + 3nm exponentiations) / K; audits = p x one audit; x k*: total over the",
        "  encrypted step at the fixed-group k*. key only: the cheapest key-secure mix without audits; audit only: the",
        f"  audit-secure mix at the smallest key (--min-key-length {d.min_key_length}). The noise's control cost is per step,",
        "  in the units of the quadratic cost, the same for every mix.",
    ]
    return lines + verification_design.format_verification(design)
