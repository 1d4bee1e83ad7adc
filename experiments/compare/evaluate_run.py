"""``encctl-gym evaluate RUN_DIR``: one training run against the baselines, on paired seeds.

The run's learned attacker plays with the Gaussian (the paper's), AR(1) and optimal-design
(oracle) attackers of the registry, under the protocol of ``compare``
(:mod:`~experiments.compare.protocol`: the same environment seeds for every attacker, the same
energy budget at every attack length), and the same table is printed: the error at the horizon
with its 95 % interval, the error over gamma_opt(N), the paired ratios to the Gaussian attacker
and to the oracle with 95 % intervals, and the security consequence.

Defaults: the run's own system and decipher delay (a blind policy also with ``"end"``), the
training attack length (``--samples N``: another; ``--full-budget``: the tau_c budget at the
system's lambda), 100
episodes per attack length, the best model, and the *stochastic* policy: its noise is its
excitation, and the mean action of a state-feedback policy leaves the regressor ``[x; u]``
nearly rank deficient, so ``--deterministic`` is allowed but warned about. ``--systems`` plays
the run on other presets or plant files too (same observation layout needed). Outputs (CSV, PNG,
``summary.md``) go to ``RUN_DIR/evaluation`` unless ``--out`` is given; a new evaluation
replaces the files of the previous one there.

The margin it can resolve (:mod:`agents.resolution`): after the table, one line per learned
attacker and reference (the oracle, the Gaussian attack, ``gamma_opt(N)``) with the ratio at
the horizon, its 95 % interval, the half-width the episodes resolve and, when the interval
contains 1, a warning with the episodes that would resolve the margin (and those for
``--resolve``, +-5 % by default); also appended to ``summary.md``.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from encctl_gym._validation import format_count
from encctl_gym.agents import Attacker
from encctl_gym.agents.runs import MODEL_FILES, RunInfo, check_output_dir, read_run
from encctl_gym.agents.sb3 import load_attacker  # the [rl] extra: without it the CLI says which extra to install
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ConfigError

from .attackers import system_config
from .cli import names, positive, write_outputs
from .protocol import GAUSSIAN_NAME, compute
from .records import Result
from .report import comparison_table, design_efficiencies
from .settings import Setting, make_setting, parse_delays, system_entry

__all__ = ["BASELINES", "EPISODES", "RESOLVE", "run_settings", "resolution_lines", "system_config", "add_arguments", "run"]

#: The registered attackers a run is evaluated against.
BASELINES = ("gaussian", "colored", "optimal")
#: Default episodes per attacker and attack length.
EPISODES = 100
#: Default target half-width of ``--resolve`` (a fraction).
RESOLVE = 0.05


def resolution_lines(result: Result, learned: Sequence[str], *, target: float = RESOLVE) -> list[str]:
    """What the episodes resolve (module docstring): for every setting and learned attacker, its
    paired ratio to the oracle (geometric mean with a t interval, and the median with a bootstrap
    interval), to the Gaussian attack, and ``E[eps] / gamma_opt(N)`` (the median where the mean
    is not reliable), each by :func:`agents.resolution.resolution_line`."""
    from encctl_gym.agents.resolution import median_resolution, paired_resolution, reference_resolution, resolution_line
    from encctl_gym.ident.tails import error_tail_exponent

    out = []
    for s in result.settings:
        curves = {c.attacker: c for c in result.curves[s.key]}
        oracle = next((c for c in curves.values() if c.oracle), None)
        gauss = curves.get(GAUSSIAN_NAME)
        p = s.params
        for name in learned:
            c = curves.get(name)
            if c is None or c.final.size < 2:
                continue
            N = int(c.N[-1])
            where = f"{s.system}, delay {s.delay}, N = {N}: {name}"
            if oracle is not None:
                out.append(
                    resolution_line(f"{where} / {oracle.attacker}", paired_resolution(c.final, oracle.final), target=target)
                )
                out.append(
                    resolution_line(f"{where} / {oracle.attacker}", median_resolution(c.final, oracle.final), target=target)
                )
            if gauss is not None:
                out.append(resolution_line(f"{where} / {gauss.attacker}", paired_resolution(c.final, gauss.final), target=target))
            rule = error_tail_exponent(p.n, p.m, N) if N > p.n + p.m else None
            res = reference_resolution(c.final, float(s.design.gamma(N)), tail_exponent=rule)
            out.append(resolution_line(f"{where} E[eps] / gamma_opt(N)", res, target=target))
    return out


def run_settings(
    run: RunInfo, systems: tuple[str, ...] | None, delays: tuple[Any, ...] | None, length: int | None
) -> list[Setting]:
    """The settings of an evaluation (module docstring); ``length`` None: each system's full budget."""
    if delays is None:
        own = run.env.get("decipher_delay", 0)
        delays = (own,) + (("end",) if run.observation == "blind" and own != "end" else ())
    out = []
    for entry in systems or (run.system,):
        label, plant = system_entry(entry) if entry != run.system else (entry, None)
        if plant is not None and label == run.system and any(plant[k] != run.env.get(k) for k in ("A", "B")):
            label = entry  # a plant file of the run's label but another plant: a system of its own
        config = system_config(run, label, plant)
        for d in delays:
            if d == "end" and run.observation != "blind":
                raise ConfigError(
                    f"the {run.observation!r} policy of {run.path} reads delivered states; it cannot play with "
                    "decipher_delay 'end' (only a blind policy can)"
                )
            out.append(make_setting(label, d, None, config=config, length=length))
    return out


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``encctl-gym evaluate``."""
    parser.add_argument("run_dir", metavar="RUN_DIR", help="a training run directory (written by encctl-gym train)")
    parser.add_argument(
        "--episodes", type=int, default=None, help=f"episodes per attacker and attack length (default {EPISODES})"
    )
    parser.add_argument(
        "--systems",
        default=None,
        help="comma-separated presets or plant files (as train --system reads) to play on (default: the run's own system)",
    )
    parser.add_argument(
        "--delays",
        default=None,
        help="comma-separated decipher delays: integers >= 0 or end (default: the run's; a blind policy also end)",
    )
    parser.add_argument(
        "--deterministic",
        action="store_true",
        help="play the policy's mean action (not recommended: the policy's noise is its excitation)",
    )
    parser.add_argument(
        "--allow-pickle",
        action="store_true",
        help="allow the pickles a run may need: an older run's vecnormalize.pkl, and stable-baselines3's own loader for a "
        "model its run.json cannot rebuild (a pickle can run any code: only for runs you trust)",
    )
    parser.add_argument(
        "--which",
        choices=("best", "final"),
        default="best",
        help="the best model of the training's evaluations (default) or the final one",
    )
    parser.add_argument(
        "--samples",
        type=int,
        default=None,
        help="attack length N to evaluate at, set through the deciphering budget (default: the training attack length)",
    )
    parser.add_argument(
        "--full-budget", action="store_true", help="evaluate at the full tau_c budget of each system at its lambda"
    )
    parser.add_argument("--points", type=int, default=6, help="attack lengths N on the log grid of every curve (default 6)")
    parser.add_argument("--seed", type=int, default=20_000, help="environment seeds seed, seed + 1, ... (default 20000)")
    parser.add_argument(
        "--elgamal-episodes", type=int, default=0, help="episodes of each attacker through real ElGamal ciphertexts (default 0)"
    )
    parser.add_argument(
        "--resolve",
        type=float,
        default=100 * RESOLVE,
        metavar="PCT",
        help=f"half-width in per cent whose episodes the margin lines estimate (default {100 * RESOLVE:g})",
    )
    parser.add_argument("--out", default=None, help="output directory (default RUN_DIR/evaluation)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    """Evaluate, write CSV, PNG and summary.md; print the table."""
    info = read_run(args.run_dir)
    episodes = positive("episodes", args.episodes) or EPISODES
    positive("points", args.points)
    positive("elgamal-episodes", args.elgamal_episodes, 0)
    if not (args.resolve > 0 and args.resolve < 1000):  # also refuses nan
        raise ConfigError(f"--resolve must be a percentage in (0, 1000), got {args.resolve!r}")
    if args.full_budget and args.samples is not None:
        raise ConfigError("give --samples or --full-budget, not both")
    length = None if args.full_budget else (positive("samples", args.samples, 2) or resolve_params(info.env).horizon)
    if args.deterministic:
        print(
            "encctl-gym evaluate: warning: --deterministic plays the policy's mean action; its noise is its excitation, "
            "and without it a state-feedback policy leaves [x; u] nearly rank deficient (expect a larger error)",
            file=sys.stderr,
        )
    systems = names(args.systems, "systems") if args.systems is not None else None  # an empty list is an error
    delays = parse_delays(args.delays) if args.delays is not None else None
    settings = run_settings(info, systems, delays, length)
    which = args.which if args.which == "final" or (info.path / MODEL_FILES["best"]).exists() else "final"
    info.model_path(which)  # a readable archive, checked before the work
    out = check_output_dir(Path(args.out) if args.out else info.path / "evaluation")

    label = info.algo + ("-blind" if info.observation == "blind" else "")

    def learned(setting: Setting) -> list[Attacker]:
        return [
            load_attacker(
                info.path,
                which=which,
                params=setting.params,
                name=label,
                deterministic=args.deterministic,
                allow_pickle=args.allow_pickle,
            )
        ]

    result = compute(
        settings=settings,
        episodes=episodes,
        seed=args.seed,
        points=args.points,
        attackers=BASELINES,
        elgamal_episodes=args.elgamal_episodes,
        elgamal_N=min(40, min(s.params.horizon for s in settings)),
        progress=not args.no_progress,
        players=learned,
        label="evaluate",
    )
    cmd = [
        f"encctl-gym evaluate {info.path}",
        f"--episodes {episodes}",
        f"--seed {args.seed}",
        f"--points {args.points}",
        f"--which {args.which}",
        "--full-budget" if length is None else f"--samples {length}",
    ]
    if systems:
        cmd.append(f"--systems {','.join(systems)}")
    if delays:
        cmd.append(f"--delays {','.join(str(d) for d in delays)}")
    if args.deterministic:
        cmd.append("--deterministic")
    _, paths = write_outputs(
        result, out, command=" ".join(cmd), title=f"{info.path.name} against the baselines (`encctl-gym evaluate`)"
    )
    print(comparison_table(result))
    print()
    print(design_efficiencies(result))
    lines = resolution_lines(result, [label], target=args.resolve / 100)
    if lines:
        print()
        print("\n".join(lines))
        with (out / "summary.md").open("a") as fh:
            fh.write(
                "\nWhat the episodes resolve (95 % intervals; `agents.resolution`):\n\n"
                + "\n".join(f"* {x}" for x in lines)
                + "\n"
            )
    print(
        f"\n{format_count(episodes, 'episode')} per attacker and attack length on environment seeds {args.seed}, {args.seed + 1}, ...; "
        f"{'deterministic' if args.deterministic else 'stochastic'} policy ({args.which} model)."
    )
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0
