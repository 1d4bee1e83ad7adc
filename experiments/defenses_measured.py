"""The defences measured in the environment: every defender of :data:`MEASURED_DEFENDERS`
against the Gaussian, AR(1) and optimal-design attackers, episode by episode, and the rows of
the measured table (shared by :mod:`encctl_gym.experiments.defenses` and
:mod:`encctl_gym.experiments.defenses_elgamal`)."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from encctl_gym.experiments.compare.statistics import wilson_interval
from encctl_gym.presets import get_preset

#: The defenders measured (label, the environment's ``defender`` value).
MEASURED_DEFENDERS: tuple[tuple[str, Any], ...] = (
    ("none", "fixed"),
    ("audit p = 1e-4", {"name": "audit", "rate": 1e-4}),
    ("audit p = 5e-4", {"name": "audit", "rate": 5e-4}),
    ("audit p = 1e-3", {"name": "audit", "rate": 1e-3}),
    ("chi2, W = 10, 1e-4 per step", {"name": "chi2", "window": 10, "false_alarm_rate": 1e-4}),
    ("cusum, c = 2, 1e-4 per step", {"name": "cusum", "false_alarm_rate": 1e-4, "variance_ratio": 2.0}),
    ("noise sigma_d2 = sigma_w2", "noise-w"),
    ("noise sigma_d2 = 10 sigma_w2", "noise-10w"),
)

#: The detectors of the detection-delay sweep (label, ``defender`` value).
DETECTORS: tuple[tuple[str, dict[str, Any]], ...] = (
    ("chi2", {"name": "chi2", "window": 10, "false_alarm_rate": 1e-4}),
    ("cusum", {"name": "cusum", "false_alarm_rate": 1e-4, "variance_ratio": 2.0}),
)


def _defender_spec(spec: Any, p: Any) -> Any:
    if spec == "noise-w":
        return {"name": "noise", "sigma_d2": p.sigma_w2}
    if spec == "noise-10w":
        return {"name": "noise", "sigma_d2": 10 * p.sigma_w2}
    return spec


def _attackers(env: Any) -> dict[str, Any]:
    from encctl_gym.agents import ColoredGaussianAttacker, GaussianAttacker, OptimalDesignAttacker

    params = env.unwrapped.params
    return {
        "gaussian": GaussianAttacker(params),
        "ar1": ColoredGaussianAttacker(params),
        "optimal": OptimalDesignAttacker.from_env(env.unwrapped),
    }


class _TimedPolicy:
    """The defender of an environment with its ``act`` timed (the defender's own cost per step)."""

    def __init__(self, core: Any) -> None:
        self.policy, self.seconds, self.calls = core.defender, 0.0, 0
        core.defender = self

    def __getattr__(self, name: str) -> Any:
        return getattr(self.policy, name)

    def act(self, view: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return self.policy.act(view)
        finally:
            self.seconds += time.perf_counter() - t0
            self.calls += 1


def _episodes(env: Any, att: Any, episodes: int, seed: int) -> tuple[list[dict[str, Any]], float, float]:
    """``episodes`` attacks; per episode ``detected``, ``samples``, ``epsilon``, ``energy``; the
    wall time per step and the defender's own time per step (its ``act``), both after one untimed
    step, so compiled kernels are loaded before the clock runs."""
    obs, _ = env.reset(seed=seed)
    att.reset(seed=0)
    env.step(att.act(obs[None])[0])
    timer = _TimedPolicy(env.unwrapped.episode)
    out, steps, t0 = [], 0, time.perf_counter()
    for e in range(episodes):
        obs, info = env.reset(seed=seed + e)
        att.reset(seed=np.random.SeedSequence([seed, e]))
        while True:
            obs, _, term, trunc, info = env.step(att.act(obs[None])[0])
            steps += 1
            if term or trunc:
                break
        out.append(
            {
                "detected": bool(info["detected"]),
                "samples": int(info["samples_collected"]),
                "epsilon": float(info["epsilon"]),
                "power": float(info["average_power"]),
            }
        )
    wall = (time.perf_counter() - t0) / steps
    env.unwrapped.episode.defender = timer.policy
    return out, wall, timer.seconds / steps


def _quartiles(values: list[float]) -> tuple[float, float, float]:
    if not values:
        return (math.nan, math.nan, math.nan)
    q = np.quantile(values, [0.25, 0.5, 0.75])
    return float(q[0]), float(q[1]), float(q[2])


def measured_row(
    system: str,
    defender: str,
    attacker: str,
    eps: list[dict[str, Any]],
    horizon: int,
    gamma_c: float,
    per_step: float,
    defender_step: float,
    base_step: float,
) -> dict[str, Any]:
    """One row of the measured table from the episodes of :func:`_episodes` (``base_step``: the
    undefended loop's time per step against the same attacker)."""
    hits = sum(e["detected"] for e in eps)
    return {
        "system": system,
        "defender": defender,
        "attacker": attacker,
        "episodes": len(eps),
        "detection_rate": hits / len(eps),
        "detection_interval": wilson_interval(hits, len(eps)),
        "samples": _quartiles([float(e["samples"]) for e in eps]),
        "samples_median": float(np.median([e["samples"] for e in eps])),
        "delay": _quartiles([float(e["samples"]) for e in eps if e["detected"]]),
        "error_over_gamma_c": _quartiles([e["epsilon"] / gamma_c for e in eps]),
        "horizon": horizon,
        "seconds_per_step": per_step,
        "defender_seconds_per_step": defender_step,
        "time_ratio": per_step / base_step,
    }


def measure(system: str, episodes: int, seed: int) -> list[dict[str, Any]]:
    """Every defender against every attacker of the module docstring, ``episodes`` each."""
    import gymnasium as gym

    import encctl_gym  # noqa: F401  (registers the environment)

    p = get_preset(system)
    rows: list[dict[str, Any]] = []
    base_time: dict[str, float] = {}
    for label, spec in MEASURED_DEFENDERS:
        config = {"preset": system, "decipher_delay": 0, "defender": _defender_spec(spec, p)}
        env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config=config)
        params = env.unwrapped.params  # type: ignore[attr-defined]
        for name, att in _attackers(env).items():
            eps, per_step, defender_step = _episodes(env, att, episodes, seed)
            if label == "none":
                base_time[name] = per_step
            rows.append(
                measured_row(system, label, name, eps, params.horizon, p.gamma_c, per_step, defender_step, base_time[name])
            )
    return rows


def _iqr(q: tuple[float, float, float], fmt: str = ".3g") -> str:
    if not np.isfinite(q[1]):
        return "-"
    return f"{q[1]:{fmt}} [{q[0]:{fmt}}, {q[2]:{fmt}}]"


def format_measured(rows: list[dict[str, Any]]) -> str:
    """The measured table as markdown."""
    out = [
        "| system | defender | attacker | detected [95 % CI] | detection delay, median [IQR] | samples collected, median [IQR] "
        "| final E[eps] / gamma_c, median [IQR] | defender's own time per step (us) | time per step / undefended |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lo, hi = r["detection_interval"]
        out.append(
            f"| {r['system']} | {r['defender']} | {r['attacker']} | {r['detection_rate']:.0%} [{lo:.0%}, {hi:.0%}] | "
            f"{_iqr(r['delay'], '.0f')} | {_iqr(r['samples'], '.0f')} of {r['horizon']} | {_iqr(r['error_over_gamma_c'])} | "
            f"{1e6 * r['defender_seconds_per_step']:.1f} | {r['time_ratio']:.2f} |"
        )
    return "\n".join(out)
