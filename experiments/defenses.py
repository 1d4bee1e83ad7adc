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
  :mod:`encctl_gym.loop.defenses` (none; audits at three rates; the chi-squared and CUSUM
  detectors; input noise at two levels) against the Gaussian, AR(1) and optimal-design attackers
  through the environment (ideal backend, the system's own budget ``tau_c``): the detection rate
  (Wilson 95 % interval), the detection delay and the samples collected before the attack ends,
  the final error over ``gamma_c`` (medians and quartiles), the defender's own wall time per step
  (its ``act``, timed), and the whole step's time against the undefended loop's.
* **Through real ElGamal** (``--elgamal``): every measured defender at a 64-bit key with the
  index-calculus breaker, real breaks, against the Gaussian, AR(1) and optimal-design attackers,
  beside the same attacks on the ideal backend (:mod:`encctl_gym.experiments.defenses_elgamal`).
* **A learned attacker** (``--ars RUN_DIR``): a trained ARS run, trained without any defence,
  against every measured defender: rows of the measured table (design example, ``defenses_ars.md``).
* **Detection delay against input energy** (``--delays``): the chi-squared and CUSUM detectors
  against every attacker at attack powers ``sigma_u2 / sigma_w2`` in :data:`ENERGY_RATIOS`
  (``defenses_detection.md`` and the figure ``defenses_detection.png``).

    python -m encctl_gym.experiments.defenses [--measure] [--ars RUN_DIR] [--delays] [--rotation] [--elgamal] [--episodes 20] [--out results/defenses] [--figures DIR]

Prints the tables and writes them as ``defenses_analytic.md`` (and ``defenses_measured.md``,
``defenses_rotation.md``, ``defenses_elgamal.md``, ``defenses_ars.md``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym.errors import EncctlError
from encctl_gym.experiments.common import write_recorded_table
from encctl_gym.experiments.defenses_measured import (
    DETECTORS,
    _attackers,
    _episodes,
    _iqr,
    _quartiles,
    format_measured,
    measure,
    wilson_interval,
)
from encctl_gym.experiments.defenses_rotation import format_rotation, rotation_rows
from encctl_gym.loop.backend import lqr_gain
from encctl_gym.presets import get_preset
from encctl_gym.security.defenses import minimum_audit_rate, noise_defense_design, noise_defense_price
from encctl_gym.security.threat import ThreatModel

SYSTEMS = ("paper-example", "fig1-c")
DELTAS = (1e-2, 1e-3, 1e-6)


def noise_rows() -> list[dict[str, float | int | str]]:
    """One row per system and noise level (the first table)."""
    rows: list[dict[str, float | int | str]] = []
    for system in SYSTEMS:
        p = get_preset(system)
        Phi = -lqr_gain(p.A, p.B)
        for label, sd in (("0", 0.0), ("sigma_w2", p.sigma_w2), ("10 sigma_w2", 10 * p.sigma_w2), ("sigma_u2", p.sigma_u2)):
            d = noise_defense_design(p.plant(), ThreatModel.of(p), sigma_d2=sd)
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


#: Attack powers of the detection-delay sweep, in units of the system's sigma_w2.
ENERGY_RATIOS: tuple[float, ...] = (1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0)


def detection_delays(
    system: str, episodes: int, seed: int, *, ratios: tuple[float, ...] = ENERGY_RATIOS, max_samples: int = 2000
) -> list[dict[str, Any]]:
    """Detection delay of the chi-squared and CUSUM detectors against the attacker's input power:
    every attacker at ``sigma_u2 = ratio sigma_w2`` for each ratio, attacks of at most
    ``max_samples`` steps (an attack not detected by then counts as undetected, its delay censored;
    the key length is the preset's design at its own power, so the horizon does not move with the
    power)."""
    import gymnasium as gym

    import encctl_gym  # noqa: F401  (registers the environment)
    from encctl_gym.envs.config import resolve_params

    p = get_preset(system)
    key_length = resolve_params({"preset": system}).key_length  # the design's key at the preset's power, held fixed
    rows: list[dict[str, Any]] = []
    for det_label, spec in DETECTORS:
        for ratio in ratios:
            su2 = ratio * p.sigma_w2
            config = {
                "preset": system,
                "decipher_delay": 0,
                "defender": spec,
                "sigma_u2": su2,
                "key_length": key_length,
                "max_samples": max_samples,
            }
            env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config=config)
            for name, att in _attackers(env).items():
                eps, _, _ = _episodes(env, att, episodes, seed)
                hits = sum(e["detected"] for e in eps)
                rows.append(
                    {
                        "system": system,
                        "detector": det_label,
                        "attacker": name,
                        "sigma_u2": su2,
                        "power_ratio": ratio,
                        "average_power": float(np.mean([e["power"] for e in eps])),
                        "episodes": episodes,
                        "detection_rate": hits / episodes,
                        "detection_interval": wilson_interval(hits, episodes),
                        "delay": _quartiles([float(e["samples"]) for e in eps if e["detected"]]),
                        "max_samples": max_samples,
                    }
                )
    return rows


def format_delays(rows: list[dict[str, Any]]) -> str:
    """The detection-delay table as markdown."""
    out = [
        "| system | detector | attacker | sigma_u2 / sigma_w2 | measured power per channel | detected [95 % CI] "
        "| detection delay (steps), median [IQR] |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lo, hi = r["detection_interval"]
        out.append(
            f"| {r['system']} | {r['detector']} | {r['attacker']} | {r['power_ratio']:g} | {r['average_power']:.3g} | "
            f"{r['detection_rate']:.0%} [{lo:.0%}, {hi:.0%}] | {_iqr(r['delay'], '.0f')} |"
        )
    return "\n".join(out)


def plot_delays(rows: list[dict[str, Any]], path: Path) -> Path:
    """Median detection delay (IQR bars) against the attack power, one panel per system; a
    detector that misses some attacks is drawn with open markers."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from encctl_gym.plotting import legend_below, save_figure

    systems = list(dict.fromkeys(r["system"] for r in rows))
    fig, axes = plt.subplots(1, len(systems), figsize=(6.2 * len(systems), 4.4), squeeze=False)
    styles = {"chi2": "-", "cusum": "--"}
    markers = {"gaussian": "o", "ar1": "s", "optimal": "^"}
    for ax, system in zip(axes[0], systems):
        for det in styles:
            for att in markers:
                sel = [r for r in rows if r["system"] == system and r["detector"] == det and r["attacker"] == att]
                sel = [r for r in sel if np.isfinite(r["delay"][1])]
                if not sel:
                    continue
                x = np.array([r["power_ratio"] for r in sel])
                med = np.array([r["delay"][1] for r in sel])
                err = np.array([[r["delay"][1] - r["delay"][0] for r in sel], [r["delay"][2] - r["delay"][1] for r in sel]])
                line = ax.errorbar(x, med, yerr=err, ls=styles[det], marker=markers[att], ms=5, capsize=2, label=f"{det}, {att}")
                missed = [i for i, r in enumerate(sel) if r["detection_rate"] < 1]
                if missed:
                    ax.plot(x[missed], med[missed], ls="none", marker=markers[att], ms=10, mfc="none", color=line[0].get_color())
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("attack power sigma_u2 / sigma_w2")
        ax.set_ylabel("detection delay (steps)")
        ax.set_title(system)
        ax.grid(True, which="major", alpha=0.3)
    bottom = legend_below(fig, axes[0], ncol=3)
    fig.suptitle("Detection delay vs attack power (open markers: not every attack detected)", fontsize=9)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    return save_figure(fig, path)


def main(argv: list[str] | None = None) -> int:
    """``python -m encctl_gym.experiments.defenses``: compute the tables asked for, then write them."""
    args = _parser().parse_args(argv)
    if not _check_args(args):
        return 2
    from encctl_gym.experiments.defenses_elgamal import ars_rows, elgamal_rows

    try:
        noise = noise_rows()
        text = format_tables(noise, audit_rows(noise))
        measured = [r for system in SYSTEMS for r in measure(system, args.episodes, args.seed)] if args.measure else []
        ars = ars_rows(args.ars, "paper-example", episodes=args.episodes, seed=args.seed) if args.ars is not None else []
        rotation = rotation_rows(args.rotation_samples, args.seed) if args.rotation else None
        elgamal = (
            elgamal_rows(samples=args.elgamal_samples, episodes=args.elgamal_episodes, seed=args.seed) if args.elgamal else None
        )
        delays = [r for system in SYSTEMS for r in detection_delays(system, args.episodes, args.seed)] if args.delays else []
    except EncctlError as exc:
        print(f"defenses: {exc}", file=sys.stderr)
        return 2
    _write_tables(args, text, measured, rotation, ars, elgamal, delays)
    return 0


def _parser() -> argparse.ArgumentParser:
    """The options of ``python -m encctl_gym.experiments.defenses``."""
    parser = argparse.ArgumentParser(prog="python -m encctl_gym.experiments.defenses", description=__doc__.splitlines()[0])
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("results/defenses"),
        help="directory of the Markdown pages (default results/defenses; the recorded ones: docs/results/defenses)",
    )
    parser.add_argument(
        "--measure", action="store_true", help="also measure every defender against every attacker in the environment"
    )
    parser.add_argument(
        "--delays", action="store_true", help="also measure the detectors' delay against the attack power (table and figure)"
    )
    parser.add_argument(
        "--figures", type=Path, default=None, help="directory of the detection-delay figure (default: the --out directory)"
    )
    parser.add_argument("--episodes", type=int, default=20, help="episodes per defender and attacker (default 20)")
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed (default 0): episode e of a measured row plays seed + e; also the crypto_seed of the ElGamal and rotation rows",
    )
    parser.add_argument(
        "--rotation", action="store_true", help="also the group-rotation tables (real ElGamal and a breaker at 64 bits)"
    )
    parser.add_argument("--rotation-samples", type=int, default=200, help="samples per rotation episode (default 200)")
    parser.add_argument(
        "--elgamal",
        action="store_true",
        help="also every defender through real ElGamal at 64 bits with the index-calculus breaker",
    )
    parser.add_argument("--elgamal-samples", type=int, default=200, help="samples per ElGamal attack (default 200)")
    parser.add_argument(
        "--elgamal-episodes", type=int, default=10, help="ElGamal episodes per defender and attacker (default 10)"
    )
    parser.add_argument(
        "--ars",
        type=Path,
        metavar="RUN_DIR",
        help="also a trained ARS run against every defender (design example, ideal backend)",
    )
    return parser


def _check_args(args: argparse.Namespace) -> bool:
    """False (after one line on stderr) when a count is out of range."""
    if args.episodes < 1:
        print(f"defenses: --episodes must be >= 1, got {args.episodes}", file=sys.stderr)
        return False
    if args.elgamal_episodes < 1 or args.elgamal_samples < 9:
        print(
            f"defenses: --elgamal-episodes must be >= 1 and --elgamal-samples >= 9 (n + m + 1), got "
            f"{args.elgamal_episodes} and {args.elgamal_samples}",
            file=sys.stderr,
        )
        return False
    if args.rotation_samples < 9:
        print(f"defenses: --rotation-samples must be >= 9 (n + m + 1), got {args.rotation_samples}", file=sys.stderr)
        return False
    return True


def _write_tables(
    args: argparse.Namespace,
    text: str,
    measured: list[dict[str, Any]],
    rotation: dict[str, list[dict[str, Any]]] | None,
    ars: list[dict[str, Any]],
    elgamal: Any,
    delays: list[dict[str, Any]],
) -> None:
    """Write the pages asked for under ``--out`` (and the detection-delay figure under ``--figures``)."""
    from encctl_gym.experiments.defenses_elgamal import format_elgamal

    args.out.mkdir(parents=True, exist_ok=True)
    cmd = "python -m encctl_gym.experiments.defenses"
    write_recorded_table(args.out / "defenses_analytic.md", "The defender's levers in closed form", cmd, text)
    if measured:
        write_recorded_table(
            args.out / "defenses_measured.md",
            "The defences measured in the environment",
            f"{cmd} --measure --episodes {args.episodes}",
            format_measured(measured),
            f" (seed {args.seed}; decipher_delay = 0, ideal backend, each system's own tau_c)",
        )
    if rotation is not None:
        write_recorded_table(
            args.out / "defenses_rotation.md",
            "Group rotation on the design example",
            f"{cmd} --rotation --rotation-samples {args.rotation_samples}",
            format_rotation(rotation),
            f" (seed {args.seed}; the design: uncorrected GNFS, budget Upsilon tau_c of paper-example; measured: real "
            "ElGamal at 64 bits, index-calculus breaker, Gaussian attacker, one episode per K)",
        )
    if ars:
        write_recorded_table(
            args.out / "defenses_ars.md",
            "A learned attacker against the defences",
            f"{cmd} --ars {args.ars} --episodes {args.episodes}",
            format_measured(ars),
            f" (seed {args.seed}; the run trained without any defence; decipher_delay = 0, ideal backend, the design "
            "example's own tau_c; rows of the measured table)",
        )
    if elgamal is not None:
        write_recorded_table(
            args.out / "defenses_elgamal.md",
            "The defences through real ElGamal",
            f"{cmd} --elgamal --elgamal-samples {args.elgamal_samples} --elgamal-episodes {args.elgamal_episodes}",
            format_elgamal(elgamal),
            f" (seed {args.seed}; paper-example, decipher_delay = 0, crypto = elgamal, key_length = 64, breaker = "
            "index-calculus (breaker_time_limit 60 s), crypto_seed = seed; the same attacks on the ideal backend beside them)",
        )
    if delays:
        write_recorded_table(
            args.out / "defenses_detection.md",
            "Detection delay against the attack power",
            f"{cmd} --delays --episodes {args.episodes}",
            format_delays(delays),
            f" (seed {args.seed}; decipher_delay = 0, ideal backend, attacks of at most 2000 steps)",
        )
        figures = args.out if args.figures is None else args.figures
        figures.mkdir(parents=True, exist_ok=True)
        print(f"  wrote {plot_delays(delays, figures / 'defenses_detection.png')}")


if __name__ == "__main__":
    raise SystemExit(main())
