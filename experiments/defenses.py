"""The defender's levers in closed form: what each buys against the attack and what it costs.

Thin over :mod:`encctl_gym.security.defenses`; for the design example (``paper-example``) and
Figure 1 (c) (``fig1-c``):

* **Input noise** ``sigma_d2`` in {0, sigma_w2, 10 sigma_w2, sigma_u2}: ``N*``, ``lambda*`` and ``k*``
  (paper model) from eq:sic generalised to the defender's noise, and the price in normal operation
  under the loop's LQR controller (``Q = I``, ``R = I``): the stationary ``tr P`` and quadratic cost.
* **Audits**: the rate ``p* = 1 - delta^(1/N*)`` that stops an attacker injecting at every step
  before ``N*`` with probability ``1 - delta``, for delta in {1e-2, 1e-3, 1e-6}.

* **Group rotation** (``--rotation``): the design example's ``k*`` when the group rotates every
  ``K`` in {1, 10, 100, N*} steps (precomputation model: one precomputation per group, and the
  paper model, which rotation leaves unchanged), with a fresh group of ``k*`` bits generated and
  timed; and the same periods measured through real ElGamal at 64 bits with the index-calculus
  breaker, which redoes its precomputation on every new group (counted and timed), with the
  plant side's cost (encryptions and bytes re-provisioned, group generation, waiting for the pool).
* **Measured in the environment** (``--measure``): each defender policy of
  :mod:`encctl_gym.loop.defenses` (none; audits at three rates; the chi-squared detector; input
  noise at two levels) against the Gaussian, AR(1) and optimal-design attackers through the
  environment (ideal backend, the system's own budget ``tau_c``): the detection rate, the samples
  collected before the attack ends, the median final error over ``gamma_c``, and the wall time
  per step against the undefended loop (a ratio measured in the same run).

    python -m encctl_gym.experiments.defenses [--measure] [--episodes 20] [--rotation] [--out results/defenses]

Prints the tables and writes them as ``defenses_analytic.md`` (and ``defenses_measured.md``,
``defenses_rotation.md``).
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


#: Rotation periods of the rotation rows (``None``: ``K = N*``, one group for the whole attack).
ROTATION_PERIODS: tuple[int | None, ...] = (1, 10, 100, None)


def rotation_rows(samples: int = 200, seed: int = 0, breaker: str = "index-calculus") -> dict[str, list[dict[str, Any]]]:
    """Group rotation on the design example: the key length it needs, and the loop measured.

    ``design``: per ``K`` of :data:`ROTATION_PERIODS`, ``k*`` under the precomputation model
    charged per group (:func:`~encctl_gym.security.rotation.rotated_minimum_key_length`) and under
    the paper model, the plant side's cost per step amortised over ``K`` (``n m / K`` encryptions,
    their bytes, and the generation of one ``k*``-bit group, by the package's time model and
    measured once here).

    ``measured``: one episode of ``samples`` samples per ``K`` through real ElGamal at 64 bits
    with ``breaker`` and the Gaussian attacker (``crypto_seed = seed``): the groups met, the
    breaker's precomputations (counted on its cost records) and their seconds, the seconds per key,
    and what the plant side spent.
    """
    import time as _time

    import gymnasium as gym
    from encctl_gym.agents import GaussianAttacker

    import encctl_gym  # noqa: F401  (registers the environment)
    from encctl_gym.crypto.group import estimate_generation_seconds, generate_safe_prime_group
    from encctl_gym.loop.provisioning import provisioning_bytes
    from encctl_gym.security.cost_models import PaperModel, PrecomputationModel
    from encctl_gym.security.key_length import defense_budget
    from encctl_gym.security.rotation import rotated_minimum_key_length

    p = get_preset("paper-example")
    N_star = int(noise_defense_design(p.plant(), p.threat(), sigma_d2=0.0).N_star)
    budget = defense_budget(p.tau_c, p.upsilon)
    n, m = p.A.shape[0], p.B.shape[1]
    design: list[dict[str, Any]] = []
    for K in ROTATION_PERIODS:
        every = N_star if K is None else K
        k_pre = rotated_minimum_key_length(PrecomputationModel(), N_star, every, budget)
        k_paper = rotated_minimum_key_length(PaperModel(), N_star, every, budget)
        t0 = _time.perf_counter()
        group = generate_safe_prime_group(k_pre, rng=seed + every)
        generated = _time.perf_counter() - t0
        design.append(
            {
                "K": every,
                "label": f"N* = {N_star}" if K is None else str(K),
                "k_star_precomputation": k_pre,
                "k_star_paper": k_paper,
                "encryptions_per_step": n * m / every,
                "bytes_per_step": provisioning_bytes(group, n * m) / every,
                "generation_model_seconds": estimate_generation_seconds(k_pre),
                "generation_seconds": generated,
            }
        )
    measured: list[dict[str, Any]] = []
    for K in ROTATION_PERIODS:
        every = N_star if K is None else K
        config = {
            "preset": "paper-example",
            "crypto": "elgamal",
            "key_length": 64,
            "breaker": breaker,
            "deciphering_model": "precomputation",
            "max_samples": samples,
            "rotate_group_every": every,
            "crypto_seed": seed,
            "gamma_opt": False,
        }
        env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config=config)
        att = GaussianAttacker(env.unwrapped.params)  # type: ignore[attr-defined]
        obs, info = env.reset(seed=seed)
        att.reset(seed=seed)
        steps, t0 = 0, _time.perf_counter()
        while True:
            obs, _, term, trunc, info = env.step(att.act(obs[None])[0])
            steps += 1
            if term or trunc:
                break
        wall = _time.perf_counter() - t0
        loop = env.unwrapped.episode.loop  # type: ignore[attr-defined]
        costs = list(loop.decipherer.costs)
        pre = [c.seconds for method, c in costs if method == "precomputation"]
        keys = [c.seconds for method, c in costs if method != "precomputation"]
        measured.append(
            {
                "K": every,
                "label": f"N* = {N_star}" if K is None else str(K),
                "samples": int(info["samples_collected"]),
                "groups": int(info["groups"]),
                "groups_expected": -(-int(info["samples_collected"]) // every),
                "precomputations": int(info["breaker_precomputations"]),
                "precomputation_seconds": float(sum(pre)),
                "seconds_per_key": float(np.mean(keys)) if keys else float("nan"),
                "breaker_seconds": float(loop.deciphering_seconds),
                "encryptions": int(info["provisioning_encryptions"]),
                "bytes": int(info["provisioning_bytes"]),
                "generation_seconds": float(info["group_generation_seconds"]),
                "generation_model_seconds": float(info["group_generation_model_seconds"]),
                "wait_seconds": float(info["group_wait_seconds"]),
                "seconds_per_step": wall / steps,
                "error_over_gamma_c": float(info["epsilon"]) / p.gamma_c,
            }
        )
        env.close()
    return {"design": design, "measured": measured}


def format_rotation(rows: dict[str, list[dict[str, Any]]]) -> str:
    """Both rotation tables as markdown."""
    out = [
        "| K | k* (precomputation model, per group) | k* (paper model) | encryptions per step | bytes per step "
        "| group generation at k* bits: model / measured (s) |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows["design"]:
        out.append(
            f"| {r['label']} | {r['k_star_precomputation']} | {r['k_star_paper']} | {r['encryptions_per_step']:.4g} | "
            f"{r['bytes_per_step']:.4g} | {r['generation_model_seconds']:.3g} / {r['generation_seconds']:.3g} |"
        )
    out += [
        "",
        "| K | samples | groups (ceil(N/K)) | breaker precomputations | precomputation s (total) | s per key "
        "| breaker s (total) | encryptions re-provisioned | bytes | generation s: measured / model | waited s | s per step |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows["measured"]:
        out.append(
            f"| {r['label']} | {r['samples']} | {r['groups']} ({r['groups_expected']}) | {r['precomputations']} | "
            f"{r['precomputation_seconds']:.3g} | {r['seconds_per_key']:.2g} | {r['breaker_seconds']:.3g} | "
            f"{r['encryptions']} | {r['bytes']} | {r['generation_seconds']:.3g} / {r['generation_model_seconds']:.3g} | "
            f"{r['wait_seconds']:.2g} | {r['seconds_per_step']:.3g} |"
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
    parser.add_argument(
        "--rotation", action="store_true", help="also the group-rotation tables (real ElGamal and a breaker at 64 bits)"
    )
    parser.add_argument("--rotation-samples", type=int, default=200, help="samples per rotation episode (default 200)")
    args = parser.parse_args(argv)
    if args.episodes < 1:
        print(f"defenses: --episodes must be >= 1, got {args.episodes}", file=sys.stderr)
        return 2
    if args.rotation_samples < 9:
        print(f"defenses: --rotation-samples must be >= 9 (n + m + 1), got {args.rotation_samples}", file=sys.stderr)
        return 2
    try:
        noise = noise_rows()
        text = format_tables(noise, audit_rows(noise))
        measured = [r for system in SYSTEMS for r in measure(system, args.episodes, args.seed)] if args.measure else []
        rotation = rotation_rows(args.rotation_samples, args.seed) if args.rotation else None
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
    if rotation is not None:
        table = format_rotation(rotation)
        print(table)
        path = args.out / "defenses_rotation.md"
        path.write_text(
            "# Group rotation on the design example\n\nCommand: `python -m encctl_gym.experiments.defenses --rotation "
            f"--rotation-samples {args.rotation_samples}` (seed {args.seed}; the design: uncorrected GNFS, budget "
            "Upsilon tau_c of paper-example; measured: real ElGamal at 64 bits, index-calculus breaker, Gaussian "
            "attacker, one episode per K)\n\n" + table + "\n"
        )
        print(f"  wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
