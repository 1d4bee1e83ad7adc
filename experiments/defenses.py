"""The defender's levers in closed form: what each buys against the attack and what it costs.

Thin over :mod:`encctl_gym.security.defenses`; for the design example (``paper-example``) and
Figure 1 (c) (``fig1-c``):

* **Input noise** ``sigma_d2`` in {0, sigma_w2, 10 sigma_w2, sigma_u2}: ``N*``, ``lambda*`` and ``k*``
  (paper model) from eq:sic generalised to the defender's noise, and the price in normal operation
  under the loop's LQR controller (``Q = I``, ``R = I``): the stationary ``tr P`` and quadratic cost.
* **Audits**: the rate ``p* = 1 - delta^(1/N*)`` that stops an attacker injecting at every step
  before ``N*`` with probability ``1 - delta``, for delta in {1e-2, 1e-3, 1e-6}.

* **Measured in the environment** (``--measure``): each defender policy of
  :mod:`encctl_gym.loop.defenses` (none; audits at three rates; the chi-squared detector; input
  noise at two levels) against the Gaussian, AR(1) and optimal-design attackers through the
  environment (ideal backend, the system's own budget ``tau_c``): the detection rate, the samples
  collected before the attack ends, the median final error over ``gamma_c``, and the wall time
  per step against the undefended loop (a ratio measured in the same run).

    python -m encctl_gym.experiments.defenses [--measure] [--episodes 20] [--out results/defenses]

Prints the tables and writes them as ``defenses_analytic.md`` (and ``defenses_measured.md``).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

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


#: The defenders measured (label, the environment's ``defender`` value).
MEASURED_DEFENDERS: tuple[tuple[str, Any], ...] = (
    ("none", "fixed"),
    ("audit p = 1e-4", {"name": "audit", "rate": 1e-4}),
    ("audit p = 5e-4", {"name": "audit", "rate": 5e-4}),
    ("audit p = 1e-3", {"name": "audit", "rate": 1e-3}),
    ("chi2, W = 10, 1e-4 per step", {"name": "chi2", "window": 10, "false_alarm_rate": 1e-4}),
    ("noise sigma_d2 = sigma_w2", "noise-w"),
    ("noise sigma_d2 = 10 sigma_w2", "noise-10w"),
)


def measure(system: str, episodes: int, seed: int) -> list[dict[str, Any]]:
    """Every defender against every attacker of the module docstring, ``episodes`` each."""
    import gymnasium as gym
    from encctl_gym.agents import ColoredGaussianAttacker, GaussianAttacker, OptimalDesignAttacker

    import encctl_gym  # noqa: F401  (registers the environment)

    p = get_preset(system)
    rows: list[dict[str, Any]] = []
    base_time: dict[str, float] = {}
    for label, spec in MEASURED_DEFENDERS:
        if spec == "noise-w":
            spec = {"name": "noise", "sigma_d2": p.sigma_w2}
        elif spec == "noise-10w":
            spec = {"name": "noise", "sigma_d2": 10 * p.sigma_w2}
        env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config={"preset": system, "decipher_delay": 0, "defender": spec})
        params = env.unwrapped.params  # type: ignore[attr-defined]
        attackers = {
            "gaussian": GaussianAttacker(params),
            "ar1": ColoredGaussianAttacker(params),
            "optimal": OptimalDesignAttacker.from_env(env.unwrapped),
        }
        for name, att in attackers.items():
            detected, samples, finals = [], [], []
            obs, _ = env.reset(seed=seed)  # one untimed step: compiled kernels are loaded before the clock runs
            att.reset(seed=0)
            env.step(att.act(obs[None])[0])
            steps, t0 = 0, time.perf_counter()
            for e in range(episodes):
                obs, info = env.reset(seed=seed + e)
                att.reset(seed=np.random.SeedSequence([seed, e]))
                while True:
                    obs, _, term, trunc, info = env.step(att.act(obs[None])[0])
                    steps += 1
                    if term or trunc:
                        break
                detected.append(bool(info["detected"]))
                samples.append(int(info["samples_collected"]))
                finals.append(float(info["epsilon"]))
            per_step = (time.perf_counter() - t0) / steps
            if label == "none":
                base_time[name] = per_step
            rows.append(
                {
                    "system": system,
                    "defender": label,
                    "attacker": name,
                    "episodes": episodes,
                    "detection_rate": float(np.mean(detected)),
                    "samples_median": float(np.median(samples)),
                    "error_over_gamma_c": float(np.median(finals)) / p.gamma_c,
                    "horizon": params.horizon,
                    "time_ratio": per_step / base_time[name],
                }
            )
    return rows


def format_measured(rows: list[dict[str, Any]]) -> str:
    """The measured table as markdown."""
    out = [
        "| system | defender | attacker | detected | samples collected (median) | final error / gamma_c (median) | time per step / undefended |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        out.append(
            f"| {r['system']} | {r['defender']} | {r['attacker']} | {r['detection_rate']:.0%} | "
            f"{r['samples_median']:.0f} of {r['horizon']} | {r['error_over_gamma_c']:.3g} | {r['time_ratio']:.2f} |"
        )
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m encctl_gym.experiments.defenses", description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/defenses"))
    parser.add_argument(
        "--measure", action="store_true", help="also measure every defender against every attacker in the environment"
    )
    parser.add_argument("--episodes", type=int, default=20, help="episodes per defender and attacker (default 20)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    if args.episodes < 1:
        print(f"defenses: --episodes must be >= 1, got {args.episodes}", file=sys.stderr)
        return 2
    try:
        noise = noise_rows()
        text = format_tables(noise, audit_rows(noise))
        measured = [r for system in SYSTEMS for r in measure(system, args.episodes, args.seed)] if args.measure else []
    except EncctlError as exc:
        print(f"defenses: {exc}", file=sys.stderr)
        return 2
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "defenses_analytic.md"
    path.write_text(
        "# The defender's levers in closed form\n\nCommand: `python -m encctl_gym.experiments.defenses`\n\n" + text + "\n"
    )
    print(f"  wrote {path}")
    if measured:
        table = format_measured(measured)
        print(table)
        path = args.out / "defenses_measured.md"
        path.write_text(
            f"# The defences measured in the environment\n\nCommand: `python -m encctl_gym.experiments.defenses --measure --episodes {args.episodes}`"
            f" (seed {args.seed}; decipher_delay = 0, ideal backend, each system's own tau_c)\n\n" + table + "\n"
        )
        print(f"  wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
