"""The attacker-defender game on the design example: static and learned players on both sides.

On the game of :mod:`encctl_gym.multiagent` (preset ``paper-example``, an attack of ``N``
samples set by the deciphering budget, ideal backend, the default :class:`GameRules` with the
rotate lever off: a learner that rotates at random would generate a 712-bit group, about 0.1 s,
at every other step):

* **Learning** (:func:`encctl_gym.agents.game_training.alternate`): ``--rounds`` rounds of best responses
  with ``--algo`` (PPO or the package's ARS), ``--steps`` steps each, from the Gaussian attacker
  and no defence; then an attacker trained from scratch against the last learned defender alone
  (the *exploiter*).
* **The game table**: rows the defenders (none, random audits at two rates, the chi-squared
  detector confirmed by an audit, input noise at two levels, the learned one), columns the
  attackers (Gaussian, AR(1), the optimal design, sparse and timed Gaussian, pass-through, the
  last learned attacker, the exploiter). Every cell plays the same ``--episodes`` seeds (paired):
  the attacker's final error, the samples collected, the detection rate, the defender's cost and
  both returns, each with its 95 % t interval over the episodes (Wilson's for the detection rate).
* **Exploitability** of the learned defender: the exploiter's return against it minus the best
  static attacker's, paired episode by episode, with its 95 % interval.
* **Learning curves** of every best response (the return of each training episode, a running
  mean), one panel per side.

    python -m encctl_gym.experiments.game [--N 128] [--episodes 30] [--steps 20000] [--rounds 2] [--algo ppo]
        [--out results/game] [--figure FILE] [--record]

Writes ``game_ALGO.md`` (the tables), ``game_ALGO_cells.csv`` (one row per cell) and the figure
``game_learning_curves_ALGO.png`` under ``--out`` (default ``results/game``). ``--record`` writes
the recorded pages of the documentation instead: the tables under ``docs/results/game`` and the
figure under ``docs/figures`` (an explicit ``--out`` or ``--figure`` still wins).

**Static only** (``--static-only``, no training): the static defenders with the rotate lever on
(group rotation every ``K`` of :data:`ROTATION_PERIODS` steps, the chi-squared detector's audit
with rotation every 10 steps, and no defence, random audits and the detector alone for reference) against the static attackers (Gaussian, AR(1), the
optimal design, pass-through, sparse Gaussian), under ``--deciphering-model`` (default
``precomputation``: the attacker pays one precomputation per group it meets, charged by the
game's :class:`~encctl_gym.multiagent.clock.GroupClock`, so rotation shortens its attack; under
the paper's model every key costs the same and rotation changes nothing). Writes
``game_static.md`` and ``game_static_cells.csv`` (under ``--out``, or ``docs/results/game`` with ``--record``).

    python -m encctl_gym.experiments.game --static-only [--N 128] [--episodes 30] [--record]
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym._validation import check_int
from encctl_gym.agents import ColoredGaussianAttacker, GaussianAttacker, OptimalDesignAttacker
from encctl_gym.agents.evaluate import budget_config, env_config
from encctl_gym.agents.game import (
    Combined,
    ConstantNoise,
    DetectorAudit,
    NoDefence,
    Outcome,
    PassThrough,
    Player,
    RandomAudit,
    RotateEvery,
    ScheduledAttacker,
    play,
)
from encctl_gym.agents.game_training import Curve, alternate, train_side
from encctl_gym.envs.config import resolve_params
from encctl_gym.experiments.common import _checked, ensure_out_dir, script_main
from encctl_gym.experiments.compare.statistics import wilson_interval
from encctl_gym.experiments.identification_strategies import replicate_interval
from encctl_gym.multiagent import GameRules
from encctl_gym.plotting import legend_below, save_figure

#: Default output directory (untracked results).
OUT_DIR = "results/game"
#: Where ``--record`` writes the tables, and the figure.
RECORDED_OUT_DIR = "docs/results/game"
RECORDED_FIGURE_DIR = "docs/figures"

METRICS = (
    ("epsilon", "the attacker's final error epsilon"),
    ("samples", "samples collected"),
    ("detected", "detection rate"),
    ("cost", "the defender's cost"),
    ("attacker_return", "the attacker's return"),
    ("defender_return", "the defender's return"),
)


#: Rotation periods of the static-only table's rotation rows.
ROTATION_PERIODS: tuple[int, ...] = (1, 10, 100)


def static_players(params: Any) -> tuple[list[Player], list[Player]]:
    """The static defenders and attackers of the table."""
    p = params
    defenders: list[Player] = [
        NoDefence(),
        RandomAudit(0.01),
        RandomAudit(0.05),
        DetectorAudit(p.n, p.m),
        ConstantNoise(0.01),
        ConstantNoise(0.1),
    ]
    attackers: list[Player] = [
        ScheduledAttacker(GaussianAttacker(p)),
        ScheduledAttacker(ColoredGaussianAttacker(p)),
        ScheduledAttacker(OptimalDesignAttacker(p)),
        ScheduledAttacker(GaussianAttacker(p), q=0.25),
        ScheduledAttacker(GaussianAttacker(p), period=32, duty=8),
        PassThrough(p.m),
    ]
    return defenders, attackers


def rate_interval(hits: np.ndarray) -> tuple[float, float, float]:
    """A rate with its 95 % Wilson score interval (:func:`~encctl_gym.experiments.compare.statistics.wilson_interval`)."""
    k, n = int(np.sum(hits)), int(np.size(hits))
    return (k / n, *wilson_interval(k, n))


def cell(outcome: Outcome) -> dict[str, tuple[float, float, float]]:
    """Mean and 95 % interval of every metric of one cell (t intervals; Wilson for the rate)."""
    return {key: (rate_interval if key == "detected" else replicate_interval)(getattr(outcome, key)) for key, _ in METRICS}


def _fmt(v: float) -> str:
    if not np.isfinite(v):
        return "-"
    return f"{v:.3g}" if abs(v) < 1e4 else f"{v:.2e}"


def metric_table(key: str, title: str, rows: list[str], cols: list[str], cells: dict[tuple[str, str], Any]) -> str:
    """One metric as a markdown table: ``mean [low, high]`` per defender (row) and attacker (column)."""
    lines = [f"**{title}** (mean [95 % interval])", "", "| defender | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
    for r in rows:
        vals = []
        for c in cols:
            m, lo, hi = cells[(r, c)][key]
            vals.append(_fmt(m) if not np.isfinite(lo) or lo == hi else f"{_fmt(m)} [{_fmt(lo)}, {_fmt(hi)}]")
        lines.append(f"| {r} | " + " | ".join(vals) + " |")
    return "\n".join(lines)


def plot_curves(curves: Sequence[Curve], path: str | Path, window: int = 50) -> Path:
    """The learning curves, one panel per side: running mean of ``window`` training episodes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9.0, 3.6))
    for ax, side in zip(axes, ("defender", "attacker")):
        for c in curves:
            if c.side != side or len(c.returns) == 0:
                continue
            w = min(window, len(c.returns))
            smooth = np.convolve(c.returns, np.ones(w) / w, mode="valid")
            ax.plot(c.timesteps[w - 1 :], smooth, label=c.label)
        ax.set_title(f"{side}: return per training episode")
        ax.set_xlabel("training steps")
        ax.set_ylabel(f"return (running mean of {window})")
    bottom = legend_below(fig, axes, ncol=3)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    out = save_figure(fig, path)
    plt.close(fig)
    return out


def rotation_players(params: Any) -> tuple[list[Player], list[Player]]:
    """The defenders and attackers of the static-only table (module docstring)."""
    p = params
    defenders: list[Player] = [
        NoDefence(),
        RandomAudit(0.05),
        DetectorAudit(p.n, p.m),
        *(RotateEvery(K) for K in ROTATION_PERIODS),
        Combined(DetectorAudit(p.n, p.m), RotateEvery(10)),
    ]
    attackers: list[Player] = [
        ScheduledAttacker(GaussianAttacker(p)),
        ScheduledAttacker(ColoredGaussianAttacker(p)),
        ScheduledAttacker(OptimalDesignAttacker(p)),
        PassThrough(p.m),
        ScheduledAttacker(GaussianAttacker(p), q=0.25),
    ]
    return defenders, attackers


def write_cells(path: Path, cells: dict[tuple[str, str], Any]) -> None:
    """One CSV row per cell: every metric's mean and 95 % interval."""
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["defender", "attacker"] + [f"{k}_{s}" for k, _ in METRICS for s in ("mean", "low", "high")])
        for (dn, an), c in cells.items():
            w.writerow([dn, an] + [f"{v:.6g}" for k, _ in METRICS for v in c[k]])


def run_static(args: argparse.Namespace) -> int:
    """The static-only table with rotation (module docstring)."""
    t0 = time.time()
    base = {"preset": args.preset, "deciphering_model": args.deciphering_model}
    if args.key_length is not None:
        base["key_length"] = args.key_length
    config = budget_config(env_config(base), args.N)
    params = resolve_params(config)
    rules = GameRules()  # the rotate lever on
    defenders, attackers = rotation_players(params)
    cells: dict[tuple[str, str], Any] = {}
    for d in defenders:
        for a in attackers:
            cells[(d.name, a.name)] = cell(play(a, d, config, rules, episodes=args.episodes, seed=args.seed))
    theta = np.hstack([params.A, params.B])
    eps0 = float(np.sum(theta**2)) / (params.n * (params.n + params.m))  # Definition def:error of the estimate [A B] = 0
    rows, cols = [d.name for d in defenders], [a.name for a in attackers]
    c = params.cost
    key = f" --key-length {args.key_length}" if args.key_length is not None else ""
    header = [
        "# The game's static defenders with group rotation (recorded by experiments/game.py --static-only)",
        "",
        f"Command: `python -m encctl_gym.experiments.game --static-only --N {args.N} --episodes {args.episodes} "
        f"--deciphering-model {args.deciphering_model}{key} --seed {args.seed}{_record_flag(args)}` ({time.time() - t0:.0f} s).",
        "",
        f"Plant `{args.preset}`, ideal backend, {params.key_length}-bit groups, `deciphering_model = {args.deciphering_model}`: "
        f"one key costs {float(c.next):.3g} operations, the first key of a group {float(c.first):.3g} (its precomputation), "
        f"tau_c set so that one group pays for N = {args.N} samples (deciphering budget). The game charges the budget per group "
        "the defender moves to (multiagent.clock.GroupClock), so rotate(K) ends the attack at the first sample "
        "the budget cannot pay. Default GameRules (rotation_cost = "
        f"{rules.rotation_cost}, audit_cost = {rules.audit_cost}, detection_penalty = {rules.detection_penalty}). "
        f"{args.episodes} paired episodes per cell (episode e seeded {args.seed} + e in every cell). epsilon_0 = {eps0:.3g} is "
        "the error before any data (of the estimate [A B] = 0).",
    ]
    body = [metric_table(k, title, rows, cols, cells) for k, title in METRICS]
    text = "\n".join(header) + "\n\n" + "\n\n".join(body) + "\n"
    print(text)
    out = ensure_out_dir(out_dir(args))
    md, cells_csv = out / "game_static.md", out / "game_static_cells.csv"
    md.write_text(text)
    write_cells(cells_csv, cells)
    print(f"wrote {md} and {cells_csv}")
    return 0


def run(args: argparse.Namespace) -> int:
    if args.static_only:
        return run_static(args)
    t0 = time.time()
    config = budget_config(env_config({"preset": args.preset}), args.N)
    params = resolve_params(config)
    rules = GameRules(rotation=False)  # the audit and noise levers (module docstring)
    defenders, attackers = static_players(params)
    alt = alternate(
        attackers[0], defenders[0], config, rules, rounds=args.rounds, steps=args.steps, algo=args.algo, seed=args.seed
    )
    learned_defender, learned_attacker = alt.defenders[-1], alt.attackers[-1]
    learned_defender.name, learned_attacker.name = (
        f"learned ({args.algo}, r{args.rounds})",
        f"learned ({args.algo}, r{args.rounds})",
    )
    exploiter, exploit_curve = train_side(
        "attacker",
        learned_defender,
        config,
        rules,
        algo=args.algo,
        steps=args.steps,
        seed=args.seed + 1000,
        label=f"exploiter {args.algo}",
    )
    exploiter.name = "exploiter"
    curves = [*alt.curves, exploit_curve]
    t_train = time.time() - t0
    rows_d = [*defenders, learned_defender]
    cols_a = [*attackers, learned_attacker, exploiter]
    outcomes: dict[tuple[str, str], Outcome] = {}
    cells: dict[tuple[str, str], Any] = {}
    for d in rows_d:
        for a in cols_a:
            o = play(a, d, config, rules, episodes=args.episodes, seed=args.seed)
            outcomes[(d.name, a.name)] = o
            cells[(d.name, a.name)] = cell(o)
    # exploitability: the exploiter against the learned defender, over the best static attacker
    statics = [a.name for a in attackers]
    best = max(statics, key=lambda name: outcomes[(learned_defender.name, name)].attacker_return.mean())
    gain = (
        outcomes[(learned_defender.name, exploiter.name)].attacker_return
        - outcomes[(learned_defender.name, best)].attacker_return
    )
    g, glo, ghi = replicate_interval(gain)
    theta = np.hstack([params.A, params.B])
    eps0 = float(np.sum(theta**2)) / (params.n * (params.n + params.m))  # Definition def:error of the estimate [A B] = 0
    rows, cols = [d.name for d in rows_d], [a.name for a in cols_a]
    r = rules
    header = [
        "# The attacker-defender game (recorded by experiments/game.py)",
        "",
        f"Command: `python -m encctl_gym.experiments.game --N {args.N} --episodes {args.episodes} --steps {args.steps} "
        f"--rounds {args.rounds} --algo {args.algo} --seed {args.seed}{_record_flag(args)}` ({t_train:.0f} s of training, "
        f"{time.time() - t0:.0f} s in all).",
        "",
        f"Plant `{args.preset}`, attacks of N = {args.N} samples (deciphering budget), ideal backend; rules: audit_cost = {r.audit_cost}, "
        f"audit_budget = {r.audit_budget}, noise_max = sigma_u2 = {params.sigma_u2:g}, noise_weight = {r.noise_weight}, "
        f"detection_penalty = {r.detection_penalty}, chi-squared window {r.window} at false-alarm rate {r.false_alarm_rate}, "
        f"rotation lever {'on' if r.rotation else 'off'}. "
        f"{args.episodes} paired episodes per cell (episode e seeded {args.seed} + e in every cell). epsilon_0 = {eps0:.3g} is "
        "the error before any data (of the estimate [A B] = 0): an attack detected within n + m samples ends there.",
        "",
        f"**Exploitability of the learned defender**: the exploiter (an attacker trained from scratch against it, {args.steps} steps) "
        f"returns {_fmt(outcomes[(learned_defender.name, exploiter.name)].attacker_return.mean())} against it; the best static attacker "
        f"({best}) returns {_fmt(outcomes[(learned_defender.name, best)].attacker_return.mean())}: a gain of {_fmt(g)} "
        f"[{_fmt(glo)}, {_fmt(ghi)}] (paired, 95 %), so the best attacker found against it returns "
        f"{_fmt(max(outcomes[(learned_defender.name, exploiter.name)].attacker_return.mean(), outcomes[(learned_defender.name, best)].attacker_return.mean()))}. "
        "Against no defence the exploiter returns "
        f"{_fmt(outcomes[(rows[0], exploiter.name)].attacker_return.mean())} and the Gaussian attacker "
        f"{_fmt(outcomes[(rows[0], cols[0])].attacker_return.mean())}.",
    ]
    body = [metric_table(key, title, rows, cols, cells) for key, title in METRICS]
    text = "\n".join(header) + "\n\n" + "\n\n".join(body) + "\n"
    print(text)
    out = ensure_out_dir(out_dir(args))
    md, cells_csv = out / f"game_{args.algo}.md", out / f"game_{args.algo}_cells.csv"
    md.write_text(text)
    write_cells(cells_csv, cells)
    fig = plot_curves(curves, figure_path(args))
    print(f"wrote {md}, {cells_csv} and {fig}")
    return 0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    def positive(name: str) -> Any:
        return _checked(lambda t: check_int(name, int(t), minimum=1), name)

    parser.add_argument("--preset", default="paper-example")
    parser.add_argument("--N", type=_checked(lambda t: check_int("N", int(t), minimum=16), "N"), default=128)
    parser.add_argument("--episodes", type=_checked(lambda t: check_int("episodes", int(t), minimum=2), "episodes"), default=30)
    parser.add_argument("--steps", type=positive("steps"), default=20_000)
    parser.add_argument("--rounds", type=positive("rounds"), default=2)
    parser.add_argument("--algo", choices=("ppo", "ars"), default="ppo")
    parser.add_argument("--seed", type=_checked(lambda t: check_int("seed", int(t), minimum=0), "seed"), default=0)
    parser.add_argument("--out", default=None, help=f"output directory (default {OUT_DIR}; with --record {RECORDED_OUT_DIR})")
    parser.add_argument(
        "--record",
        action="store_true",
        help=f"write the documentation's recorded pages ({RECORDED_OUT_DIR}, the figure under {RECORDED_FIGURE_DIR})",
    )
    parser.add_argument("--static-only", action="store_true", help="the static table with rotation, no training")
    parser.add_argument("--deciphering-model", default="precomputation", help="with --static-only (default: precomputation)")
    parser.add_argument(
        "--key-length", type=_checked(lambda t: check_int("key_length", int(t), minimum=16), "key_length"), default=None
    )
    parser.add_argument(
        "--figure",
        default=None,
        help=f"learning-curve figure (default OUT/game_learning_curves_ALGO.png; with --record under {RECORDED_FIGURE_DIR})",
    )


def out_dir(args: argparse.Namespace) -> str:
    """``--out``, else the recorded directory with ``--record``, else :data:`OUT_DIR`."""
    return args.out or (RECORDED_OUT_DIR if args.record else OUT_DIR)


def figure_path(args: argparse.Namespace) -> str:
    """``--figure``, else ``game_learning_curves_ALGO.png`` under the recorded figures with
    ``--record`` (and no ``--out``), else under the output directory."""
    name = f"game_learning_curves_{args.algo}.png"
    if args.figure:
        return str(args.figure)
    if args.record and not args.out:
        return f"{RECORDED_FIGURE_DIR}/{name}"
    return f"{out_dir(args)}/{name}"


def _record_flag(args: argparse.Namespace) -> str:
    return " --record" if args.record else ""


def main(argv: Sequence[str] | None = None) -> int:
    return script_main("encctl_gym.experiments.game", __doc__, add_arguments, run, argv)


if __name__ == "__main__":
    sys.exit(main())
