"""Stealthy attackers against the detectors: the frontier of samples to gamma_c against detection.

Thin over :mod:`encctl_gym.security.stealth` (the analysis) and :mod:`encctl_gym.agents.stealth`
(the attackers), on the design example (``paper-example``, ``decipher_delay = 0``):

* **The documented claim** (:func:`claim_rows`): "chi-squared stops the attackers in 11 steps,
  CUSUM in 2-3", measured for the replacing Gaussian attacker, the additive attacker at
  ``1e-3 sigma_u2`` (``injection="add"``) and the honest loop (``injection="pass"``: the false-alarm
  baseline), ``--claim-episodes`` paired episodes of ``--claim-steps`` steps each, against the
  ``chi2`` and ``cusum`` defenders of :mod:`encctl_gym.loop.defenses`.
* **The design example analytically** (:func:`analytic_rows`): for each attack of
  :data:`ANALYTIC_ATTACKS` its KL per step, samples to the design's ``gamma_c = 1e-6`` and the
  probability that each detector stops it within those samples or the horizon (7379), if shorter.
* **The frontier, analytic and measured** (:func:`frontier_rows`, the figure): at a looser
  ``--gamma-c`` (default 1e-3, so the samples to it are within reach of real episodes), each
  attack of :data:`FRONTIER_ATTACKS` plays ``--episodes`` episodes of exactly its samples to
  ``gamma_c`` (capped at ``--cap``) against ``chi2``, ``cusum``, ``audit`` (rate ``--audit-rate``) and no
  defender (whose final error checks the samples); detection rates with Wilson 95 % intervals,
  beside the analytic probability at the same length.

    python -m encctl_gym.experiments.stealth [--episodes 20] [--claim-episodes 30] [--gamma-c 1e-3] [--record]

Writes ``stealth.md`` and ``stealth_cells.csv`` under ``--out`` (default ``results/stealth``) and the
figure ``stealth_frontier.png`` beside them; ``--record`` writes ``docs/results/stealth/`` and the figure
under ``docs/figures/``.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym._validation import check_int, check_positive, check_probability, parse_number
from encctl_gym.errors import ParameterError
from encctl_gym.experiments.common import _checked, ensure_out_dir, script_main
from encctl_gym.experiments.compare.statistics import wilson_interval
from encctl_gym.presets import get_preset
from encctl_gym.security.defenses import chi2_threshold
from encctl_gym.security.stealth import (
    DETECTORS,
    FrontierPoint,
    _gaussian_step_law,
    check_false_alarm_rate,
    cusum_detection_probability,
    frontier_point,
    malleability_excitation,
    stealthy_design,
    window_detection_probability,
)

__all__ = [
    "Attack",
    "ANALYTIC_ATTACKS",
    "FRONTIER_ATTACKS",
    "analytic_point",
    "analytic_rows",
    "claim_rows",
    "frontier_rows",
    "main",
]

OUT_DIR = "results/stealth"
RECORDED_OUT_DIR = "docs/results/stealth"
RECORDED_FIGURE_DIR = "docs/figures"
ENV_ID = "encctl_gym/EncryptedLTIAttack-v0"
PRESET = "paper-example"
#: The chi-squared and CUSUM defenders as documented (W = 10, 1e-4 false alarms per step, c = 2).
WINDOW, FALSE_ALARM, VARIANCE_RATIO = 10, 1e-4, 2.0


@dataclass(frozen=True)
class Attack:
    """One attack: its class (``additive``, ``sparse``, ``malleability``, ``stealthy`` (the KL-budget
    design), ``gaussian`` (replacing), ``honest``), options and label."""

    kind: str
    label: str
    options: dict[str, Any] = field(default_factory=dict)

    @property
    def injection(self) -> str:
        return {"malleability": "scale", "gaussian": "replace", "honest": "pass"}.get(self.kind, "add")


ANALYTIC_ATTACKS: tuple[Attack, ...] = (
    Attack("additive", "honest loop (false alarms)", {"ratio": 0.0}),
    *(Attack("additive", f"additive {r:g} sigma_u2", {"ratio": r}) for r in (1e-4, 1e-3, 1e-2, 1e-1, 1.0)),
    *(Attack("stealthy", f"A-optimal, KL <= {k:g} per step", {"kl_budget": k}) for k in (1e-4, 1e-3, 1e-2)),
    Attack("sparse", "sparse q = 0.05 at u_max", {"q": 0.05, "level": 1.0}),
    Attack("sparse", "sparse q = 0.02 at 0.1 u_max", {"q": 0.02, "level": 0.1}),
    Attack("malleability", "malleability q = 0.3", {"q": 0.3}),
)
FRONTIER_ATTACKS: tuple[Attack, ...] = (
    *(Attack("additive", f"additive {r:g} sigma_u2", {"ratio": r}) for r in (1e-3, 3e-3, 1e-2, 3e-2)),
    Attack("sparse", "sparse q = 0.02 at 0.1 u_max", {"q": 0.02, "level": 0.1}),
    Attack("sparse", "sparse q = 0.05 at 0.05 u_max", {"q": 0.05, "level": 0.05}),
    Attack("malleability", "malleability q = 0.3", {"q": 0.3}),
    Attack("malleability", "malleability q = 1", {"q": 1.0}),
)


def _system() -> dict[str, Any]:
    from encctl_gym.envs.config import resolve_params
    from encctl_gym.loop.backend import lqr_gain
    from encctl_gym.loop.injection import scale_gain

    p = resolve_params({"preset": PRESET, "decipher_delay": 0, "gamma_opt": False})
    return {"A": p.A, "B": p.B, "Phi": -lqr_gain(p.A, p.B), "sigma_w2": p.sigma_w2, "sigma_u2": p.sigma_u2, "u_max": p.u_max,
            "horizon": p.horizon, "gain": scale_gain(p.loop.group())}  # fmt: skip


def _audit_fraction(attack: Attack, m: int) -> float | None:
    """The fraction of steps whose input an audit finds changed: a malleability step changes a
    row with probability ``q`` each (any of ``m``); the others' defaults (1, a sparse ``q``)."""
    return 1.0 - (1.0 - attack.options["q"]) ** m if attack.kind == "malleability" else None


def _excitation(attack: Attack, s: dict[str, Any]) -> tuple[np.ndarray | None, tuple[float, float] | None]:
    """``(Sigma_d, sparse)`` of an attack for :func:`~encctl_gym.security.stealth.frontier_point`."""
    m = s["B"].shape[1]
    o = attack.options
    if attack.kind == "additive":
        return o["ratio"] * s["sigma_u2"] * np.eye(m), None
    if attack.kind == "stealthy":
        d = stealthy_design(s["A"], s["B"], s["Phi"], sigma_w2=s["sigma_w2"], kl_budget=o["kl_budget"], sigma_u2=s["sigma_u2"])
        return d.Sigma_d, None
    if attack.kind == "sparse":
        return None, (o["q"], o["level"] * s["u_max"])
    if attack.kind == "malleability":  # the moment-matched Gaussian of its excitation
        return malleability_excitation(s["A"], s["B"], s["Phi"], sigma_w2=s["sigma_w2"], delta2=o["q"] * (s["gain"] - 1)), None
    raise ValueError(attack.kind)  # pragma: no cover - the attacks above are the only kinds


def analytic_point(
    attack: Attack, s: dict[str, Any], gamma_c: float, audit_rate: float, horizon: int | None = None
) -> FrontierPoint:
    """:func:`~encctl_gym.security.stealth.frontier_point` of one attack on the design example."""
    Sd, sparse = _excitation(attack, s)
    return frontier_point(
        s["A"], s["B"], s["Phi"], sigma_w2=s["sigma_w2"], gamma_c=gamma_c, Sigma_d=Sd, sparse=sparse, window=WINDOW,
        false_alarm_rate=FALSE_ALARM, variance_ratio=VARIANCE_RATIO, audit_rate=audit_rate, horizon=horizon,
        audit_fraction=_audit_fraction(attack, s["B"].shape[1]),
    )  # fmt: skip


def design_audit_rate(delta: float = 1e-3) -> float:
    """The design's audit rate ``p* = 1 - delta^(1/N*)`` for the design example (``N*`` of eq:sic2)."""
    from encctl_gym.security.defenses import minimum_audit_rate
    from encctl_gym.security.design import paper_design_example

    return minimum_audit_rate(paper_design_example().N_star, delta)


def analytic_rows(audit_rate: float) -> list[dict[str, Any]]:
    """The design example (``gamma_c = 1e-6``, its horizon) for every attack of :data:`ANALYTIC_ATTACKS`,
    audits at ``audit_rate`` (the design's ``p*``: :func:`design_audit_rate`)."""
    s = _system()
    gamma_c = float(get_preset(PRESET).gamma_c)
    rows = []
    for att in ANALYTIC_ATTACKS:
        fp = analytic_point(att, s, gamma_c, audit_rate, horizon=s["horizon"])
        rows.append({"attack": att.label, "point": fp, "horizon": s["horizon"]})
    return rows


# ---------------------------------------------------------------------- measured in the environment
def _attacker(attack: Attack, params: Any) -> Any:
    from encctl_gym.agents import GaussianAttacker
    from encctl_gym.agents.stealth import STEALTH_ATTACKERS

    if attack.kind in ("gaussian", "honest"):
        return GaussianAttacker(params)
    return STEALTH_ATTACKERS.build(attack.kind, params=params, **attack.options)


def _defender(detector: str, audit_rate: float) -> Any:
    return {
        "chi2": {"name": "chi2", "window": WINDOW, "false_alarm_rate": FALSE_ALARM},
        "cusum": {"name": "cusum", "false_alarm_rate": FALSE_ALARM, "variance_ratio": VARIANCE_RATIO},
        "audit": {"name": "audit", "rate": audit_rate},
        "none": "fixed",
    }[detector]


def play(
    attack: Attack, detector: str, steps: int, episodes: int, seed: int, audit_rate: float, gamma_c: float
) -> dict[str, Any]:
    """``episodes`` episodes of ``steps`` steps of one attack against one defender (episode ``e``
    seeded ``seed + e`` for every cell: paired); the detections, the samples and the final errors."""
    import gymnasium as gym

    import encctl_gym  # noqa: F401  (registers the environment)

    # gamma_c stays the preset's: a looser one would re-derive the key (a shorter horizon); the
    # errors are compared with the experiment's gamma_c here
    cfg = {"preset": PRESET, "decipher_delay": 0, "injection": attack.injection, "max_samples": int(steps),
           "gamma_opt": False, "defender": _defender(detector, audit_rate)}  # fmt: skip
    env = gym.make(ENV_ID, config=cfg)
    if env.unwrapped.params.horizon != int(steps):  # type: ignore[attr-defined]  # pragma: no cover - guards the length
        raise ParameterError(f"the episode has {env.unwrapped.params.horizon} steps, not the {steps} asked for")  # type: ignore[attr-defined]
    att = _attacker(attack, env.unwrapped.params)  # type: ignore[attr-defined]
    detected, samples, eps = [], [], []
    for e in range(episodes):
        obs, _ = env.reset(seed=seed + e)
        att.reset(np.random.SeedSequence([seed, e]))
        while True:
            obs, _, term, trunc, info = env.step(att.act(obs))
            if term or trunc:
                break
        detected.append(bool(info["detected"]))
        samples.append(int(info["samples_collected"]))
        eps.append(float(info["epsilon"]))
    env.close()
    hits = sum(detected)
    return {"detected": hits, "episodes": episodes, "interval": wilson_interval(hits, episodes), "samples": samples,
            "flags": detected, "epsilon": eps, "gamma_c": gamma_c}  # fmt: skip


def claim_rows(episodes: int, steps: int, seed: int) -> list[dict[str, Any]]:
    """The documented claim: replacing Gaussian, additive at 1e-3 sigma_u2, honest loop; chi2 and CUSUM."""
    attacks = (Attack("gaussian", "gaussian (replaces Phi x)"), Attack("additive", "additive 1e-3 sigma_u2", {"ratio": 1e-3}),
               Attack("honest", "honest loop (false alarms)"))  # fmt: skip
    s = _system()
    rows = []
    for att in attacks:
        for det in ("chi2", "cusum"):
            r = play(att, det, steps, episodes, seed, 0.0, float(get_preset(PRESET).gamma_c))
            r.update(attack=att.label, detector=det, steps=steps, delays=_delays(r), analytic=_claim_analytic(att, det, steps, s))
            rows.append(r)
    return rows


def _delays(r: dict[str, Any]) -> list[int]:
    """The samples at which the detected episodes ended (the detection delay)."""
    return [n for n, d in zip(r["samples"], r["flags"]) if d]


def _claim_analytic(attack: Attack, detector: str, steps: int, s: dict[str, Any]) -> float | None:
    """The analytic probability of an alarm within ``steps`` for the additive and honest rows."""
    n = s["A"].shape[0]
    if attack.kind == "gaussian":
        return None
    ratio = attack.options.get("ratio", 0.0)
    lam = 1.0 + ratio * s["sigma_u2"] * float(s["B"][0, 0]) ** 2 / s["sigma_w2"]  # isotropic B on the design example
    if detector == "chi2":
        law = _gaussian_step_law(np.full(n, lam), WINDOW)
        return window_detection_probability(steps, WINDOW, law, chi2_threshold(n, WINDOW, FALSE_ALARM))
    return cusum_detection_probability(
        steps, n, false_alarm_rate=FALSE_ALARM, variance_ratio=VARIANCE_RATIO, weights=np.full(n, lam)
    )


def frontier_rows(episodes: int, seed: int, gamma_c: float, cap: int, audit_rate: float) -> list[dict[str, Any]]:
    """Every attack of :data:`FRONTIER_ATTACKS` against every detector and no defender, measured and analytic."""
    s = _system()
    rows = []
    for att in FRONTIER_ATTACKS:
        fp = analytic_point(att, s, gamma_c, audit_rate)
        steps = int(min(fp.samples, cap))
        at = analytic_point(att, s, gamma_c, audit_rate, horizon=steps)
        for det in (*DETECTORS, "none"):
            r = play(att, det, steps, episodes, seed, audit_rate, gamma_c)
            r.update(attack=att.label, kind=att.kind, detector=det, steps=steps, samples_to_gamma_c=fp.samples, kl=fp.kl,
                     analytic=None if det == "none" else getattr(at, det))  # fmt: skip
            rows.append(r)
    return rows


# ---------------------------------------------------------------------- the game
def game_rows(episodes: int, seed: int, N: int = 128) -> list[dict[str, Any]]:
    """The additive attacker in the attacker-defender game (``injection="add"``, ``N`` samples, no
    rotation): against no defence, the chi-squared-triggered audit and random audits, beside the
    pass-through attacker (:func:`encctl_gym.agents.game.play`, paired seeds)."""
    from encctl_gym.agents.evaluate import budget_config, env_config
    from encctl_gym.agents.game import DetectorAudit, NoDefence, PassThrough, RandomAudit, ScheduledAttacker, play
    from encctl_gym.agents.stealth import AdditiveAttacker
    from encctl_gym.envs.config import resolve_params
    from encctl_gym.multiagent import GameRules

    config = budget_config(env_config({"preset": PRESET, "decipher_delay": 0, "injection": "add"}), N)
    p = resolve_params(config)
    attackers = [ScheduledAttacker(AdditiveAttacker(p, ratio=r)) for r in (3e-3, 1e-2, 1e-1)] + [PassThrough(p.m)]
    defenders: list[Any] = [NoDefence(), DetectorAudit(p.n, p.m), RandomAudit(0.01), RandomAudit(0.05)]
    rows = []
    for d in defenders:
        for a in attackers:
            o = play(a, d, config, GameRules(rotation=False), episodes=episodes, seed=seed)
            hits = int(o.detected.sum())
            rows.append({"defender": d.name, "attacker": a.name, "detected": hits, "episodes": episodes,
                         "interval": wilson_interval(hits, episodes), "attacker_return": _mean_ci(o.attacker_return),
                         "defender_return": _mean_ci(o.defender_return), "epsilon": float(np.mean(o.epsilon))})  # fmt: skip
    return rows


def _mean_ci(v: np.ndarray) -> tuple[float, float]:
    """Mean and the half-width of its 95 % interval (normal approximation)."""
    v = np.asarray(v, dtype=float)
    return float(v.mean()), float(1.96 * v.std(ddof=1) / np.sqrt(v.size)) if v.size > 1 else 0.0


def format_game(rows: list[dict[str, Any]]) -> str:
    out = [
        "| defender | attacker | detected [95 % CI] | attacker return | defender return | mean final eps |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        (ma, ha), (md, hd) = r["attacker_return"], r["defender_return"]
        out.append(
            f"| {r['defender']} | {r['attacker']} | {_pct(r)} | {ma:.3g} +- {ha:.2g} | {md:.3g} +- {hd:.2g} | {r['epsilon']:.3g} |"
        )
    return "\n".join(out)


def run_game(args: argparse.Namespace) -> int:
    out = ensure_out_dir(args.out or (RECORDED_OUT_DIR if args.record else OUT_DIR))
    t0 = time.time()
    rows = game_rows(args.claim_episodes, args.seed)
    cmd = f"python -m encctl_gym.experiments.stealth --game --claim-episodes {args.claim_episodes} --seed {args.seed}{' --record' if args.record else ''}"
    text = "\n\n".join([
        "# The additive attacker in the attacker-defender game (recorded by experiments/stealth.py --game)",
        f"Command: `{cmd}` ({time.time() - t0:.0f} s). Design example, injection = add, decipher_delay = 0, N = 128 "
        "(deciphering budget), no rotation, default GameRules; paired seeds. Returns: means +- 95 % half-widths.",
        format_game(rows),
    ])  # fmt: skip
    print(text)
    (out / "stealth_game.md").write_text(text + "\n")
    print(f"wrote {out / 'stealth_game.md'}")
    return 0


# ---------------------------------------------------------------------- tables, figure, command
def _pct(r: dict[str, Any]) -> str:
    lo, hi = r["interval"]
    return f"{r['detected']}/{r['episodes']} [{lo:.0%}, {hi:.0%}]"


def _p(v: float | None) -> str:
    return "-" if v is None else f"{v:.3f}"


def format_claim(rows: list[dict[str, Any]]) -> str:
    out = [
        "| attacker | detector | detected within the steps [95 % CI] | analytic | detection delay, median [range] |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        d = r["delays"]
        delay = f"{np.median(d):.0f} [{min(d)}, {max(d)}]" if d else "-"
        out.append(f"| {r['attack']} | {r['detector']} | {_pct(r)} | {_p(r['analytic'])} | {delay} |")
    return "\n".join(out)


def format_analytic(rows: list[dict[str, Any]]) -> str:
    out = [
        "| attack | KL per step (nats) | samples to gamma_c | steps evaluated | chi2 (lower bound) | CUSUM | audit |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        fp = r["point"]
        out.append(
            f"| {r['attack']} | {fp.kl:.3g} | {fp.samples:.4g} | {fp.steps} | {fp.chi2:.3f} ({fp.chi2_lower:.3f}) | {fp.cusum:.3f} | {fp.audit:.3f} |"
        )
    return "\n".join(out)


def format_frontier(rows: list[dict[str, Any]]) -> str:
    out = [
        "| attack | KL per step | samples to gamma_c (steps played) | detector | detected [95 % CI] | analytic | final eps / gamma_c, median |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        ratio = np.median(np.asarray(r["epsilon"]) / r["gamma_c"])
        out.append(
            f"| {r['attack']} | {r['kl']:.3g} | {r['samples_to_gamma_c']:.4g} ({r['steps']}) | {r['detector']} | {_pct(r)} | {_p(r['analytic'])} | {ratio:.3g} |"
        )
    return "\n".join(out)


def _curves(gamma_c: float, audit_rate: float) -> dict[str, list[FrontierPoint]]:
    s = _system()
    fam = {
        "additive (Gaussian)": [Attack("additive", "", {"ratio": r}) for r in np.logspace(-3.5, -1, 14)],
        "sparse at 0.05 u_max": [Attack("sparse", "", {"q": q, "level": 0.05}) for q in np.logspace(-2.5, -0.5, 10)],
        "malleability (moment-matched)": [Attack("malleability", "", {"q": q}) for q in np.logspace(-1.3, 0, 8)],
    }
    return {k: [analytic_point(a, s, gamma_c, audit_rate) for a in v] for k, v in fam.items()}


def plot_frontier(rows: list[dict[str, Any]], gamma_c: float, audit_rate: float, path: Path) -> Path:
    """Per detector: the analytic frontier of each family (line) and the measured attacks (points, Wilson intervals)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from encctl_gym.plotting import legend_below, save_figure

    curves = _curves(gamma_c, audit_rate)
    colours = {"additive (Gaussian)": "C0", "sparse at 0.05 u_max": "C1", "malleability (moment-matched)": "C2"}
    kinds = {"additive": "C0", "sparse": "C1", "malleability": "C2"}
    fig, axes = plt.subplots(1, 3, figsize=(12, 4), sharey=True)
    n = _system()["A"].shape[0]
    grid = np.unique(np.logspace(2, 4.6, 14).astype(int))
    floor = {
        "chi2": [window_detection_probability(int(N), WINDOW, _gaussian_step_law(np.ones(n), WINDOW), chi2_threshold(n, WINDOW, FALSE_ALARM)) for N in grid],
        "cusum": [cusum_detection_probability(int(N), n, false_alarm_rate=FALSE_ALARM, variance_ratio=VARIANCE_RATIO) for N in grid],
    }  # fmt: skip
    for ax, det in zip(axes, DETECTORS):
        if det in floor:
            ax.plot(grid, floor[det], color="0.6", ls="--", label="honest loop: false alarms within N")
        for fam, pts in curves.items():
            ax.plot([p.samples for p in pts], [getattr(p, det) for p in pts], color=colours[fam], label=f"{fam}, analytic")
        for r in (r for r in rows if r["detector"] == det):
            y = r["detected"] / r["episodes"]
            lo, hi = r["interval"]
            ax.errorbar([r["samples_to_gamma_c"]], [y], yerr=[[y - lo], [hi - y]], fmt="o", ms=4, color=kinds[r["kind"]],
                        capsize=2, label=f"{r['kind']}, measured")  # fmt: skip
            ax.plot([r["samples_to_gamma_c"]], [r["analytic"]], "x", ms=6, color="k", label="analytic at the measured attack")
        ax.set_xscale("log")
        ax.set_title(
            {"chi2": "chi-squared (W = 10, 1e-4)", "cusum": "CUSUM (c = 2, 1e-4)", "audit": f"audits (p = {audit_rate:g})"}[det]
        )
        ax.set_xlabel(f"samples to gamma_c = {gamma_c:g}")
        ax.set_ylim(-0.03, 1.03)
    axes[0].set_ylabel("P(detected before gamma_c)")
    bottom = legend_below(fig, axes, ncol=3)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    out = save_figure(fig, path)
    plt.close(fig)
    return out


def write_cells(rows: list[dict[str, Any]], path: Path) -> None:
    keys = ("attack", "detector", "steps", "detected", "episodes", "analytic")
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([*keys, "ci_low", "ci_high", "median_eps_over_gamma_c"])
        for r in rows:
            w.writerow([*(r.get(k, "") for k in keys), *r["interval"], float(np.median(np.asarray(r["epsilon"]) / r["gamma_c"]))])


def run(args: argparse.Namespace) -> int:
    if args.game:
        return run_game(args)
    check_false_alarm_rate(FALSE_ALARM)
    out = ensure_out_dir(args.out or (RECORDED_OUT_DIR if args.record else OUT_DIR))
    figure = Path(RECORDED_FIGURE_DIR if args.record and not args.out else out) / "stealth_frontier.png"
    t0 = time.time()
    claim = claim_rows(args.claim_episodes, args.claim_steps, args.seed)
    p_star = design_audit_rate()
    analytic = analytic_rows(p_star)
    frontier = frontier_rows(args.episodes, args.seed, args.gamma_c, args.cap, args.audit_rate)
    seconds = time.time() - t0
    cmd = (f"python -m encctl_gym.experiments.stealth --episodes {args.episodes} --claim-episodes {args.claim_episodes} "
           f"--claim-steps {args.claim_steps} --gamma-c {args.gamma_c:g} --cap {args.cap} --audit-rate {args.audit_rate:g} "
           f"--seed {args.seed}{' --record' if args.record else ''}")  # fmt: skip
    text = "\n\n".join([
        "# Stealthy attackers against the detectors (recorded by experiments/stealth.py)",
        f"Command: `{cmd}` ({seconds:.0f} s). Design example, decipher_delay = 0, ideal backend; paired seeds.",
        f"## The documented claim ({args.claim_steps} steps, {args.claim_episodes} episodes per cell)", format_claim(claim),
        f"## The design example, analytic (gamma_c = 1e-6, horizon {analytic[0]['horizon']}, audits at p* = {p_star:.3g})",
        format_analytic(analytic),
        f"## The frontier at gamma_c = {args.gamma_c:g} ({args.episodes} episodes per cell)",
        "Each attack plays exactly its samples to gamma_c (the steps played). The malleability rows' analytic values are "
        "those of the moment-matched Gaussian excitation (an approximation); the others are the closed forms of "
        "encctl_gym.security.stealth.", format_frontier(frontier),
    ])  # fmt: skip
    print(text)
    (out / "stealth.md").write_text(text + "\n")
    write_cells(claim + frontier, out / "stealth_cells.csv")
    fig = plot_frontier(frontier, args.gamma_c, args.audit_rate, figure)
    print(f"wrote {out / 'stealth.md'}, {out / 'stealth_cells.csv'} and {fig}")
    return 0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    def count(name: str, minimum: int = 1) -> Callable[[str], int]:
        return _checked(lambda t: check_int(name, int(t), minimum=minimum), name)

    parser.add_argument("--episodes", type=count("episodes", 2), default=20)
    parser.add_argument("--claim-episodes", type=count("claim_episodes", 2), default=30)
    parser.add_argument("--claim-steps", type=count("claim_steps", 11), default=2000)
    parser.add_argument(
        "--gamma-c", type=_checked(lambda t: check_positive("gamma_c", parse_number("gamma_c", t)), "gamma_c"), default=1e-3
    )
    parser.add_argument("--cap", type=count("cap", 11), default=7000, help="longest frontier episode (steps)")
    parser.add_argument(
        "--audit-rate",
        type=_checked(lambda t: check_probability("audit_rate", parse_number("audit_rate", t)), "audit_rate"),
        default=1e-3,
    )
    parser.add_argument("--seed", type=count("seed", 0), default=0)
    parser.add_argument("--out", default=None, help=f"output directory (default {OUT_DIR}; with --record {RECORDED_OUT_DIR})")
    parser.add_argument("--game", action="store_true", help="only the game table (stealth_game.md), --claim-episodes per cell")
    parser.add_argument(
        "--record", action="store_true", help=f"write {RECORDED_OUT_DIR} and the figure under {RECORDED_FIGURE_DIR}"
    )


def main(argv: Sequence[str] | None = None) -> int:
    return script_main("encctl_gym.experiments.stealth", __doc__, add_arguments, run, argv)


if __name__ == "__main__":
    sys.exit(main())
