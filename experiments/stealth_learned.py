"""Learned stealthy attackers (issue 30, item 4): ARS and PPO with ``injection="add"`` trained
against chi-squared, CUSUM and audits, where a detection ends the episode, against the analytic
frontier at the same horizon.

    python -m encctl_gym.experiments.stealth_learned [--ars-steps 1000000] [--ppo-steps 200000]
        [--episodes 100] [--seed 0] [--quick] [--record]

For each detector (:data:`DETECTORS`, the settings of :mod:`experiments.stealth`) and algorithm,
a fresh attacker is trained on preset ``small`` (the algorithm's config, ``injection = add``,
``decipher_delay = 0``, the detector as the environment's defender; no stopping rule, a fixed
budget) and then played for ``--episodes`` paired episodes in its training environment: the
fraction detected, the median final error of the undetected episodes over gamma_c, and the
excitation power it used (``info["average_power"]`` over ``sigma_u2``).

The frontier (:func:`frontier_curve`) is the white additive attacker of
:mod:`encctl_gym.security.stealth` at every excitation level: its error after the horizon's
samples, ``c(s) / (N - 1)``, against the detector's alarm probability within them. ``frontier at
the same detection`` is the smallest error of a level detected at most as often as the learned
attacker was; a learned attacker on the frontier has a ratio near 1, above it a ratio above 1.
``frontier at detection 0.5``: the smallest error of a level seen with probability at most 0.5,
to set beside the median final error of attackers that are seen.

Writes ``results/stealth/stealth_learned.md`` by default; ``--record`` writes
``docs/results/stealth/stealth_learned.md``.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym.errors import EncctlError

from .common import ensure_out_dir, write_recorded_table

__all__ = ["DETECTORS", "frontier_curve", "learned_rows", "format_rows", "main"]

#: The environment's defenders the attackers are trained against (the stealth experiment's settings).
DETECTORS: dict[str, Any] = {
    "none": "fixed",
    "chi2": {"name": "chi2", "window": 10, "false_alarm_rate": 1e-4},
    "cusum": {"name": "cusum", "false_alarm_rate": 1e-4, "variance_ratio": 2.0},
    "audit": {"name": "audit", "rate": 0.05},
}
PRESET = "small"


def _config(algo: str, detector: str, steps: int, seed: int) -> dict[str, Any]:
    from encctl_gym.agents.config import load_config

    cfg = load_config(algo, PRESET)
    cfg["env"].update(injection="add", decipher_delay=0, defender=DETECTORS[detector])
    cfg["n_timesteps"], cfg["seed"] = int(steps), int(seed)
    cfg["stopping"].update(rule="none", budget="fixed")
    cfg["eval"]["elgamal"]["episodes"] = 0
    return cfg


def _play(run_dir: Path, episodes: int, seed: int) -> dict[str, Any]:
    """The trained attacker in its training environment: paired episodes ``seed + e``."""
    import gymnasium as gym

    import encctl_gym  # noqa: F401  registers the environment
    from encctl_gym.agents.runs import read_run
    from encctl_gym.agents.sb3 import load_attacker

    run = read_run(run_dir)
    env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config=dict(run.env))
    params = env.unwrapped.params  # type: ignore[attr-defined]
    att = load_attacker(run_dir, which="final", params=params)
    detected, eps_free, eps_all, power, samples = 0, [], [], [], []
    for e in range(episodes):
        obs, _ = env.reset(seed=seed + e)
        att.reset(seed=seed + e)
        while True:
            obs, _, term, trunc, info = env.step(att.act(obs[None])[0])
            if term or trunc:
                break
        detected += bool(info["detected"])
        samples.append(int(info["samples_collected"]))
        power.append(float(info["average_power"]) / float(params.sigma_u2))
        eps_all.append(float(info["epsilon"]))
        if not info["detected"]:
            eps_free.append(float(info["epsilon"]))
    env.close()
    return {
        "horizon": int(params.horizon),
        "gamma_c": float(params.gamma_c),
        "detected": detected,
        "episodes": episodes,
        "median_eps_undetected": float(np.median(eps_free)) if eps_free else math.nan,
        "median_eps": float(np.median(eps_all)),
        "power": float(np.median(power)),
        "samples": float(np.mean(samples)),
    }


def frontier_curve(detector: str, horizon: int, levels: int = 60) -> list[tuple[float, float, float]]:
    """``(level s / sigma_u2, error after horizon samples, alarm probability within them)`` of the
    white additive attacker, for log-spaced levels up to ``u_max^2`` (closed forms)."""
    from encctl_gym.envs.config import resolve_params
    from encctl_gym.loop.backend import lqr_gain
    from encctl_gym.security.stealth import audit_detection_probability, frontier_point, identification_rate

    p = resolve_params({"preset": PRESET})
    Phi = -lqr_gain(p.A, p.B)
    spec = DETECTORS[detector]
    out = []
    for s in np.geomspace(1e-6 * p.sigma_u2, p.u_max**2, levels):
        Sd = float(s) * np.eye(p.m)
        eps = identification_rate(p.A, p.B, Phi, sigma_w2=p.sigma_w2, Sigma_d=Sd) / (horizon - 1)
        if detector in ("chi2", "cusum"):
            pt = frontier_point(
                p.A, p.B, Phi, sigma_w2=p.sigma_w2, gamma_c=p.gamma_c, Sigma_d=Sd, steps=horizon,
                window=spec.get("window", 10), false_alarm_rate=spec["false_alarm_rate"],
            )  # fmt: skip
            det = pt.chi2 if detector == "chi2" else pt.cusum
        elif detector == "audit":
            det = audit_detection_probability(horizon, spec["rate"], 1.0)
        else:
            det = 0.0
        out.append((float(s) / p.sigma_u2, float(eps), float(det)))
    return out


def _frontier_at(curve: list[tuple[float, float, float]], detection: float) -> float:
    """The smallest error of a level detected with probability at most ``detection`` (inf if none)."""
    ok = [eps for _, eps, det in curve if det <= detection + 1e-12]
    return min(ok) if ok else math.inf


def learned_rows(*, steps: dict[str, int], episodes: int, seed: int, runs_dir: Path) -> list[dict[str, Any]]:
    """Train and play every (detector, algorithm) cell; each row with the frontier beside it."""
    from encctl_gym.agents.train import train

    rows = []
    for detector in DETECTORS:
        for algo, n in steps.items():
            t0 = time.perf_counter()
            run = train(_config(algo, detector, n, seed), out=runs_dir, name=f"{algo}_{detector}", overwrite=True,
                        progress=False, tensorboard=False)  # fmt: skip
            seconds = time.perf_counter() - t0
            r = _play(run, episodes, seed + 10_000)
            curve = frontier_curve(detector, r["horizon"])
            rate = r["detected"] / r["episodes"]
            best = _frontier_at(curve, rate)
            rows.append({"detector": detector, "algo": algo, "steps": n, "train_seconds": seconds, **r,
                         "frontier_eps": best, "frontier_half": _frontier_at(curve, 0.5),
                         "false_alarms": _frontier_at_zero(curve)})  # fmt: skip
    return rows


def _frontier_at_zero(curve: list[tuple[float, float, float]]) -> float:
    """The alarm probability of the quietest level (the honest loop's false alarms, nearly)."""
    return min(det for _, _, det in curve)


def format_rows(rows: list[dict[str, Any]]) -> str:
    """The Markdown table."""
    from encctl_gym.experiments.compare.statistics import wilson_interval

    lines = [
        "| detector | algorithm | training steps | detected [95 % CI] | quietest level's alarms | median final eps / gamma_c "
        "| median eps / gamma_c (undetected) | frontier at the same detection / gamma_c | ratio | frontier at detection 0.5 / gamma_c "
        "| power / sigma_u2 | mean samples |",
        "|" + "---|" * 12,
    ]
    for r in rows:
        lo, hi = wilson_interval(r["detected"], r["episodes"])
        gc = r["gamma_c"]
        ratio = r["median_eps_undetected"] / r["frontier_eps"] if math.isfinite(r["frontier_eps"]) else math.nan
        lines.append(
            f"| {r['detector']} | {r['algo']} | {r['steps']} | {r['detected']}/{r['episodes']} [{lo:.0%}, {hi:.0%}] "
            f"| {r['false_alarms']:.3g} | {r['median_eps'] / gc:.3g} | {r['median_eps_undetected'] / gc:.3g} "
            f"| {r['frontier_eps'] / gc:.3g} | {ratio:.3g} | {r['frontier_half'] / gc:.3g} | {r['power']:.3g} | {r['samples']:.1f} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m encctl_gym.experiments.stealth_learned", description=__doc__.splitlines()[0])
    parser.add_argument("--ars-steps", type=int, default=1_000_000, help="ARS training steps (default 1000000)")
    parser.add_argument("--ppo-steps", type=int, default=200_000, help="PPO training steps (default 200000)")
    parser.add_argument("--episodes", type=int, default=100, help="evaluation episodes per cell (default 100)")
    parser.add_argument("--seed", type=int, default=0, help="seed (default 0)")
    parser.add_argument("--quick", action="store_true", help="20000 steps each, 10 episodes: a smoke test")
    parser.add_argument(
        "--out", type=Path, default=Path("results/stealth"), help="directory of the page (default results/stealth)"
    )
    parser.add_argument("--record", action="store_true", help="write docs/results/stealth/stealth_learned.md")
    args = parser.parse_args(argv)
    steps = {"ars": 20_000, "ppo": 20_000} if args.quick else {"ars": args.ars_steps, "ppo": args.ppo_steps}
    episodes = 10 if args.quick else args.episodes
    t0 = time.perf_counter()
    try:
        with tempfile.TemporaryDirectory(prefix="stealth_learned_") as runs:
            rows = learned_rows(steps=steps, episodes=episodes, seed=args.seed, runs_dir=Path(runs))
    except EncctlError as exc:
        print(f"stealth_learned: {exc}", file=sys.stderr)
        return 2
    out = ensure_out_dir(Path("docs/results/stealth") if args.record else args.out)
    cmd = "python -m encctl_gym.experiments.stealth_learned" + "".join(
        f" {a}" for a in (argv if argv is not None else sys.argv[1:])
    )
    notes = (
        f" ({time.perf_counter() - t0:.0f} s). Preset `{PRESET}`, injection = add, decipher_delay = 0, each algorithm's "
        "config with no stopping rule; a detection ends the episode. Detectors: chi-squared window 10 and CUSUM at 1e-4 "
        "false alarms per step, audits at 0.05. Frontier: the white additive attacker's closed forms at the horizon."
    )
    write_recorded_table(
        out / "stealth_learned.md", "Learned stealthy attackers (issue 30, item 4)", cmd, format_rows(rows), notes
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
