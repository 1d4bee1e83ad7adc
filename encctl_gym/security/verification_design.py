"""The design with verification: the cheapest secure mix of key length, rotation, audits, noise and
a verification check priced per step (``encctl-gym design --verify NAME|auto --verify-param K=V``).

A check of :mod:`.verification` with bound ``epsilon`` catches an attacker at its first falsified
step but with probability ``epsilon`` (an adaptive attacker that passes once may pass again, so
``epsilon`` bounds the whole attack: :func:`~.verification.undetected_with_check`); with audits at
rate ``p`` besides, the attacker that injects at each of ``N*`` steps stays unseen with probability
at most ``epsilon (1 - p)^(N* - 1)`` (the first step passes the check, every step escapes the
audits; the check and the audits draw independent secrets). A mix is *verification-secure* when
that is at most the design's ``delta``; like an audit-secure mix it then needs no key length for
this threat and runs at the smallest the design allows (``min_key_length``).

Its cost per step is the encrypted step at that key length, the audits, and the check's own work:
the measured seconds of one check on the reference machine (``check_seconds``, measured by the
loop layer: :func:`encctl_gym.loop.verification.measure_check_seconds`; this module, like
:mod:`.defense_design`, imports no cryptography). The chosen mix per cost model is the cheaper of
the design's own chosen mix (:func:`~.defense_design.design_defenses`) and the verification-secure
one. ``auto`` compares no check with the keyed linear check at the smallest secure ``R``
(:func:`~.verification.minimum_secret_range`).

Only the keyed linear check applies to the design's loop (the modified ElGamal scheme); the MAC
verifies the Paillier scheme's loop and is refused here.

The attacker strongest against a mix is reported beside it: against a verification-secure mix the
Kerckhoffs attacker (it knows the check; its pass probability is ``epsilon`` exactly for the
linear check's ``(d, -d)`` move); against an audit-secure mix the sub-tolerance attacker (a
falsification below the audits' encoding tolerance is never caught by an audit: measured in
:mod:`encctl_gym.experiments.integrity`); against a key-secure mix the deciphering attacker of
Definition def:adversary.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import asdict, dataclass
from typing import Any

from .._validation import check_nonnegative, format_value, parse_number
from ..errors import ParameterError
from .defense_design import DefenderCosts, DefenseDesign, DefenseMix
from .verification import check_secret_range, linear_check_pass_bound, minimum_secret_range

__all__ = [
    "VerifiedMix",
    "VerificationDesign",
    "VerifiedDefenseDesign",
    "add_arguments",
    "verify_options",
    "design_verification",
    "format_verification",
    "strongest_attacker",
]

#: The names ``--verify`` takes.
VERIFY_NAMES: tuple[str, ...] = ("linear-check", "auto")


def add_arguments(group: Any) -> None:
    """Register ``--verify`` and ``--verify-param`` on an argparse parser or group."""
    group.add_argument(
        "--verify",
        dest="verify",
        metavar="NAME|auto",
        help="price a verification check per step: linear-check (the keyed linear check), or auto",
    )
    group.add_argument(
        "--verify-param",
        dest="verify_param",
        action="append",
        metavar="KEY=VALUE",
        help="a parameter of the check (linear-check: secret_range=R, default the smallest secure R)",
    )


def verify_options(args: argparse.Namespace) -> dict[str, Any] | None:
    """``{"name": ..., "params": {...}}`` from ``--verify`` and ``--verify-param``, or ``None``.

    Raises
    ------
    ParameterError
        For ``--verify-param`` without ``--verify``, a parameter that is not ``KEY=VALUE``, or a
        value that is not a number.
    """
    name = getattr(args, "verify", None)
    raw = getattr(args, "verify_param", None) or []
    if name is None:
        if raw:
            raise ParameterError("--verify-param needs --verify NAME")
        return None
    params: dict[str, Any] = {}
    for item in raw:
        key, sep, value = str(item).partition("=")
        if not sep or not key.strip():
            raise ParameterError(f"--verify-param must be KEY=VALUE, got {format_value(item)}")
        params[key.strip()] = parse_number(key.strip(), value)
    return {"name": str(name), "params": params}


@dataclass(frozen=True)
class VerifiedMix:
    """A mix with the check (module docstring): key length, audits, the check and the costs."""

    key_length: int
    audit_rate: float
    verification: str | None
    secret_range: int | None
    epsilon: float
    undetected_probability: float
    verification_secure: bool
    step_seconds: float
    audit_seconds: float
    verification_seconds: float
    total_seconds: float
    strongest_attacker: str

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return asdict(self)


@dataclass(frozen=True)
class VerificationDesign:
    """Per cost model: the design's own chosen mix, the verification-secure mix and the cheaper."""

    name: str
    secret_range: int | None
    epsilon: float
    check_seconds: float
    detection_delta: float
    models: dict[str, dict[str, Any]]

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        d = {k: v for k, v in asdict(self).items() if k != "models"}
        d["models"] = {
            m: {k: (v.to_dict() if hasattr(v, "to_dict") else v) for k, v in entry.items()} for m, entry in self.models.items()
        }
        return d


class VerifiedDefenseDesign:
    """A :class:`~.defense_design.DefenseDesign` with its :class:`VerificationDesign` (every
    attribute of the base design reads through, so its formatter prints it unchanged)."""

    def __init__(self, base: DefenseDesign, verification: VerificationDesign) -> None:
        self.base, self.verification = base, verification

    def __getattr__(self, name: str) -> Any:
        return getattr(self.base, name)

    def to_dict(self) -> dict[str, Any]:
        d = self.base.to_dict()
        d["verification"] = self.verification.to_dict()
        return d


def strongest_attacker(mix: DefenseMix | VerifiedMix) -> str:
    """The attacker strongest against a mix (module docstring)."""
    if isinstance(mix, VerifiedMix) and mix.verification_secure:
        return "kerckhoffs (knows the check: passes with epsilon)"
    if mix.audit_secure if isinstance(mix, DefenseMix) else False:
        return "sub-tolerance falsification (never caught by an audit)"
    return "deciphering (def:adversary: breaks the keys)"


def _check(name: str, params: dict[str, Any], m: int, delta: float) -> tuple[str, int]:
    if name == "mac":
        raise ParameterError(
            "--verify mac verifies the Paillier scheme's loop; the defender's design is the modified ElGamal loop's (use linear-check)"
        )
    if name not in VERIFY_NAMES:
        raise ParameterError(f"unknown verification {format_value(name)}; choose one of {', '.join(VERIFY_NAMES)}")
    unknown = sorted(set(params) - {"secret_range"})
    if unknown:
        raise ParameterError(f"the linear check takes the parameter secret_range, not {', '.join(unknown)}")
    R = params.get("secret_range")
    return "linear-check", check_secret_range("secret_range", R) if R is not None else minimum_secret_range(delta)


def design_verification(
    design: DefenseDesign, costs: DefenderCosts, verify: dict[str, Any], *, check_seconds: float
) -> VerifiedDefenseDesign:
    """The cheapest secure mix with the check of ``verify`` (``{"name", "params"}``) per cost model.

    Raises
    ------
    ParameterError
        For an unknown check, the MAC (another scheme's), an unknown or bad parameter, or a
        negative ``check_seconds``.
    """
    t_check = check_nonnegative("check_seconds", check_seconds)
    name, R = _check(str(verify.get("name")), dict(verify.get("params") or {}), costs.m, design.detection_delta)
    eps = linear_check_pass_bound(costs.m, R)
    N, delta = design.audit_steps or design.N_star, design.detection_delta  # the falsified steps an audit must catch one of
    rates = [0.0] if not isinstance(design.audit_rate, float) else [float(design.audit_rate)]
    if design.audit_rate == "auto" and eps > delta:
        p_v = -_expm1_root(delta / eps, max(N - 1, 1))
        while eps * (1.0 - p_v) ** max(N - 1, 0) > delta:  # the closed form's last rounding step
            p_v = math.nextafter(p_v, 1.0)
        rates.append(p_v)
    models: dict[str, dict[str, Any]] = {}
    for model, md in design.models.items():
        k = md.key_floor or min(design.min_key_length, md.chosen.key_length)  # the smallest key the design allows
        mixes = [_verified(costs, k, p, name, R, eps, N, delta, t_check) for p in rates]
        secure = [v for v in mixes if v.verification_secure]
        verified = min(secure or mixes, key=lambda v: v.total_seconds)
        base = md.chosen
        cheaper = verified if verified.verification_secure and verified.total_seconds < base.total_seconds else base
        models[model] = {
            "unverified": base,
            "unverified_attacker": strongest_attacker(base),
            "verified": verified,
            "chosen": "verified" if cheaper is verified else "unverified",
        }
    return VerifiedDefenseDesign(design, VerificationDesign(name, R, eps, t_check, delta, models))


def _expm1_root(ratio: float, N: int) -> float:
    """``expm1(log(ratio) / N)``: minus the audit rate with ``(1 - p)^N = ratio``."""
    return math.expm1(math.log(ratio) / N)


def _verified(
    costs: DefenderCosts, k: int, p: float, name: str, R: int, eps: float, N: int, delta: float, t_check: float
) -> VerifiedMix:
    q = eps * (1.0 - p) ** max(N - 1, 0) if p < 1 else 0.0
    step = costs.encrypted_step_seconds(k)
    aud = costs.audit_seconds(p)
    mix = VerifiedMix(k, p, name, R, eps, q, q <= delta, step, aud, t_check, step + aud + t_check, "")
    return VerifiedMix(**{**asdict(mix), "strongest_attacker": strongest_attacker(mix)})


def format_verification(design: Any) -> list[str]:
    """The verification section of ``encctl-gym design`` (nothing for a design without one)."""
    v: VerificationDesign | None = getattr(design, "verification", None)
    if v is None:
        return []
    lines = [
        "",
        f"  Verification: {v.name}, R = {v.secret_range}: a falsified step passes with at most epsilon = {v.epsilon:.4g}; "
        f"one check (measured) = {v.check_seconds:.3g} s",
    ]
    for model, entry in v.models.items():
        vm, base = entry["verified"], entry["unverified"]
        lines += [
            f"  {model}: chosen {entry['chosen']}",
            f"    without the check   k = {base.key_length:>5d}, p = {base.audit_rate:.4g}, total {base.total_seconds:.4g} s/step; "
            f"strongest attacker: {entry['unverified_attacker']}",
            f"    with the check      k = {vm.key_length:>5d}, p = {vm.audit_rate:.4g}, undetected <= {vm.undetected_probability:.3g} "
            f"({'secure' if vm.verification_secure else 'not secure'}), total {vm.total_seconds:.4g} s/step "
            f"(check {vm.verification_seconds:.3g} s); strongest attacker: {vm.strongest_attacker}",
        ]
    return lines
