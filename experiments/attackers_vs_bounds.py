"""The headline experiment: every attacker against gamma(N) and gamma_opt(N) (``compare``).

For each system (default: the paper's design example and Figure 1 (c) and (g)) and both
observation settings (``decipher_delay = 0``: states delivered in time, an adaptive attacker;
``"end"``: the paper's blind attacker, nothing delivered before the attack ends), every attacker
plays ``--episodes`` episodes of ``EncryptedLTIAttack-v0`` (ideal backend) with the same
environment seeds and the same energy budget ``m sigma_u2 N``:

* the baselines of :mod:`agents.baselines` (Gaussian = the paper's, random binary, AR(1)),
* the A-optimal design (:class:`agents.OptimalDesignAttacker`; closed loop for delay 0, open
  loop for "end"; an oracle that knows (A, B)),
* the learned attackers of the training runs found under ``--runs`` for that system
  (policies reading states only with delay 0; "blind" policies in both settings); by default
  the best model of the training's evaluation callback (selected on its own episodes, so the
  comparison here, on other seeds, is not biased by the selection).

Error against N, at equal energy. The environment's energy budget ``m sigma_u2 N`` holds for
the whole attack, not per step, so the error of the running estimate within one long attack
(``info["epsilon"]`` along the way) compares attackers at *unequal* energy whenever one of them
paces its energy unevenly (a learned policy may spend it early and beat gamma(N) at small N for
that reason alone). The curves are therefore measured on a log grid of attack lengths, one set
of episodes of exactly N samples (budget ``m sigma_u2 N``) per grid point. With delay 0 the
running error and the energy spent along one full-length attack are also recorded
(``protocol = along`` in ``curves.csv`` and ``pacing_<system>.png``). Attack lengths below the
tau_c budget (the grid and the evaluation cap ``--max-samples``) are set by a shorter defense
period at the same lambda (:func:`agents.evaluate.budget_config`), so the budget fractions an
attacker observes keep their meaning; the security table uses the preset's own tau_c.

Security consequence. For each attacker the sample size it needs to reach ``gamma_c`` is read
from its mean curve when it gets there within the horizon, else extrapolated from a fit
``E[epsilon(N)] ~ c / (N - 1)`` to the upper half of the grid (the 1/N regime of eq:sic2 and
gamma_opt): ``N_c = floor(c / gamma_c) + 2`` (:func:`encctl_gym.security.design.sample_size_for_rate`).
The security parameter that would have been needed against it is ``lam = floor(log2(Upsilon
tau_c / N_c)) + 1`` (Theorem thm:opt_sec, :func:`optimal_security_parameter`) and the key length
``k`` of eq:opt_key (:func:`minimum_key_length`), next to the paper's ``N*``, ``lam*`` and ``k*``.

ElGamal. Every attacker also plays ``--elgamal-episodes`` short episodes (N = 40) through real
ciphertexts with a 64-bit key, next to the same episode on the ideal backend (``elgamal.csv``).

Outputs under ``--out`` (default ``results/compare``): ``curves.csv`` (tidy: system, delay,
attacker, N, mean, standard error, 95 % band, gamma, gamma_opt), ``episodes.csv`` (final error
and average power of every episode), ``security.csv``, ``elgamal.csv``, one PNG per system, and ``summary.md``
(the tables and the finding in words, with the command that reproduces it).

Usage: ``encctl-gym compare [--quick] [--out DIR] [--seed S] [--episodes E] [--systems a,b]
[--runs DIR] [--max-samples N]``.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np

from agents import Attacker, ColoredGaussianAttacker, GaussianAttacker, OptimalDesignAttacker, PRBSAttacker, rollout
from agents.evaluate import budget_config, elgamal_config
from encctl_gym.envs.config import AttackParams, resolve_params
from encctl_gym.errors import ParameterError
from encctl_gym.security.attack_design import AttackDesign, gaussian_attack_design, optimal_attack_design
from encctl_gym.security.design import (
    design_from_traces,
    minimum_key_length,
    optimal_security_parameter,
    sample_size_for_rate,
)
from encctl_gym.sim.montecarlo import log_grid

__all__ = [
    "DEFAULT_SYSTEMS",
    "DELAYS",
    "Setting",
    "Curve",
    "fit_rate",
    "samples_to_reach",
    "security_row",
    "find_runs",
    "length_grid",
    "compute",
    "plot",
    "add_arguments",
    "run",
]

#: The design example and two Figure 1 panels at the extremes of R_sigma (100 and 0.01).
DEFAULT_SYSTEMS = ("paper-example", "fig1-c", "fig1-g")
DELAYS: tuple[Any, ...] = (0, "end")
#: Evaluation cap: no system is attacked longer than the design example's budget (7379 at lam* = 74).
DEFAULT_CAP = 7379
QUICK_SYSTEMS = ("paper-example",)
QUICK_CAP = 60
QUICK_EPISODES = 4


# --------------------------------------------------------------------------- data
@dataclass(frozen=True)
class Setting:
    """One system in one observation setting, with its bounds."""

    system: str
    delay: Any  # 0 or "end"
    config: dict[str, Any]
    params: AttackParams  # of the evaluated attack (capped horizon)
    base: AttackParams  # of the preset (its tau_c, Upsilon and gamma_c define the security design)
    design: AttackDesign  # optimal (closed loop for delay 0, open loop for "end")
    gauss: AttackDesign  # the Gaussian attack's exact asymptotic rate
    capped: bool  # the horizon was cut by the evaluation cap (not by tau_c)

    @property
    def label(self) -> str:
        return f"{self.system} / delay {self.delay}"


@dataclass
class Curve:
    """Mean error of one attacker against N, with the per-episode finals."""

    attacker: str
    oracle: bool
    N: np.ndarray
    mean: np.ndarray
    se: np.ndarray
    episodes: int
    final: np.ndarray  # (E,) error at the horizon
    power: np.ndarray  # (E,) average power
    seconds: float
    # delay 0 only: the running estimate within one full-length attack, and the energy spent
    along_N: np.ndarray | None = None
    along_mean: np.ndarray | None = None
    along_se: np.ndarray | None = None
    along_energy: np.ndarray | None = None  # mean fraction of the episode's energy budget spent


def _stats(eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    mean = eps.mean(axis=0)
    se = eps.std(axis=0, ddof=1) / math.sqrt(eps.shape[0]) if eps.shape[0] > 1 else np.full(mean.shape, np.nan)
    return mean, se


def fit_rate(N: np.ndarray, mean: np.ndarray) -> float:
    """Least-squares ``c`` of ``mean ~ c / (N - 1)`` on the upper half of the grid (log N).

    Parameters
    ----------
    N, mean : array_like
        Grid of sample sizes (increasing) and the mean error there.

    Returns
    -------
    float
        ``c`` (``(N - 1) E[epsilon(N)]`` in the 1/N regime), weighted so every point counts by
        its relative error.
    """
    N = np.asarray(N, dtype=float)
    mean = np.asarray(mean, dtype=float)
    ok = np.isfinite(mean) & (N >= 2)
    N, mean = N[ok], mean[ok]
    if N.size == 0:
        raise ParameterError("no finite error to fit")
    tail = np.log(N) >= 0.5 * (np.log(N[0]) + np.log(N[-1]))
    x, y = 1.0 / (N[tail] - 1.0), mean[tail]
    w = 1.0 / y**2  # relative least squares
    return float(np.sum(w * x * y) / np.sum(w * x * x))


def samples_to_reach(N: np.ndarray, mean: np.ndarray, gamma_c: float) -> tuple[int, str]:
    """The smallest ``N`` with mean error below ``gamma_c``: measured if the curve gets there,
    else extrapolated from :func:`fit_rate` (``floor(c / gamma_c) + 2``).

    Returns
    -------
    (int, str)
        ``N`` and ``"measured"`` or ``"extrapolated"``.
    """
    N = np.asarray(N)
    mean = np.asarray(mean)
    below = np.nonzero(np.isfinite(mean) & (mean < gamma_c))[0]
    if below.size:
        return int(N[below[0]]), "measured"
    return sample_size_for_rate(fit_rate(N, mean), gamma_c), "extrapolated"


def security_row(setting: Setting, curve: Curve) -> dict[str, Any]:
    """The security consequence of one attacker (see the module docstring)."""
    p, b = setting.params, setting.base
    N_c, how = samples_to_reach(curve.N, curve.mean, b.gamma_c)
    lam = optimal_security_parameter(N_c, tau_c=b.tau_c, upsilon=b.upsilon)
    return {
        "system": setting.system,
        "delay": setting.delay,
        "attacker": curve.attacker,
        "oracle": curve.oracle,
        "episodes": curve.episodes,
        "horizon": int(curve.N[-1]),
        "capped": setting.capped,
        "mean_error_at_horizon": float(curve.final.mean()),
        "se_error_at_horizon": float(curve.final.std(ddof=1) / math.sqrt(curve.final.size)) if curve.final.size > 1 else float("nan"),
        "gamma_at_horizon": float(p.gamma(int(curve.N[-1]))),
        "gamma_opt_at_horizon": float(setting.design.gamma(int(curve.N[-1]))),
        "average_power": float(curve.power.mean()),
        "sigma_u2": p.sigma_u2,
        "rate_c": fit_rate(curve.N, curve.mean),
        "rate_over_gaussian_design": fit_rate(curve.N, curve.mean) / setting.gauss.rate,
        "gamma_c": p.gamma_c,
        "N_to_gamma_c": N_c,
        "N_how": how,
        "lambda_needed": lam,
        "k_needed": minimum_key_length(lam),
    }


def bound_rows(setting: Setting) -> list[dict[str, Any]]:
    """The reference rows: the paper's design (eq:sic2), the exact Gaussian rate and gamma_opt."""
    p = setting.base
    paper = design_from_traces(
        p.tr_psi_u, p.tr_psi_w, p.m, p.n, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2, sigma_x2=p.sigma_x2,
        gamma_c=p.gamma_c, tau_c=p.tau_c, upsilon=p.upsilon,
    )
    rows = [{"system": setting.system, "delay": setting.delay, "attacker": "paper gamma (eq:sic2)", "N_to_gamma_c": paper.N_star,
             "N_how": "thm:opt_sec", "lambda_needed": paper.lam_star, "k_needed": paper.k_star,
             "rate_c": (p.m + p.n) * p.sigma_w2 / (p.sigma_u2 * (p.tr_psi_u + p.m) + p.sigma_w2 * p.tr_psi_w)}]
    for label, d in (("gaussian design rate", setting.gauss), (f"gamma_opt ({setting.design.kind})", setting.design)):
        N_c = sample_size_for_rate(d.rate, p.gamma_c)
        lam = optimal_security_parameter(N_c, tau_c=p.tau_c, upsilon=p.upsilon)
        rows.append({"system": setting.system, "delay": setting.delay, "attacker": label, "N_to_gamma_c": N_c,
                     "N_how": "c / gamma_c", "lambda_needed": lam, "k_needed": minimum_key_length(lam), "rate_c": d.rate})
    for r in rows:
        r["rate_over_gaussian_design"] = r["rate_c"] / setting.gauss.rate
    return rows


# --------------------------------------------------------------------------- attackers
def find_runs(roots: Sequence[str | Path]) -> list[Path]:
    """Training run directories (with ``run.json`` and ``model.zip``) under ``roots``; quick
    (smoke-test) runs are skipped unless a root is itself a run."""
    out: list[Path] = []
    for root in roots:
        root = Path(root)
        if (root / "run.json").exists():
            out.append(root)
            continue
        if not root.exists():
            raise ParameterError(f"--runs {root} does not exist")
        for meta in sorted(root.glob("*/run.json")):
            d = meta.parent
            if (d / "model.zip").exists() and not json.loads(meta.read_text()).get("config", {}).get("quick", False):
                out.append(d)
    return out


def _learned(setting: Setting, runs: Sequence[Path], which: str = "best") -> list[Attacker]:
    from agents.sb3 import load_attacker

    atts = []
    for d in runs:
        meta = json.loads((d / "run.json").read_text())
        if meta["env"].get("preset") != setting.system:
            continue
        if setting.delay == "end" and meta["observation"] != "blind":
            continue  # a policy reading states has nothing to read before the end
        name = f"{meta['algo']}" + ("-blind" if meta["observation"] == "blind" else "")
        w = which if which == "final" or (d / "best_model.zip").exists() else "final"
        atts.append(load_attacker(d, which=w, params=setting.params, name=name))
    return atts


def attackers_for(setting: Setting, runs: Sequence[Path], which: str = "best") -> list[Attacker]:
    """The attackers evaluated in one setting (baselines, the oracle design, learned ones)."""
    p = setting.params
    return [
        GaussianAttacker(p),
        PRBSAttacker(p),
        ColoredGaussianAttacker(p, rho=0.5),
        OptimalDesignAttacker(p, design=setting.design, feedback=setting.delay != "end"),
        *_learned(setting, runs, which),
    ]


def make_setting(system: str, delay: Any, cap: int | None) -> Setting:
    """The configuration and bounds of one system in one observation setting."""
    base = resolve_params({"preset": system, "gamma_opt": False, "decipher_delay": delay})
    cfg: dict[str, Any] = {"preset": system, "decipher_delay": delay, "gamma_opt": False}
    capped = cap is not None and base.horizon > cap
    if capped:  # a shorter defense period, same lambda: the budget fractions keep their meaning
        cfg = budget_config(cfg, int(cap))
    p = resolve_params(cfg)
    design = optimal_attack_design(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2, feedback=delay != "end")
    gauss = gaussian_attack_design(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2)
    return Setting(system, delay, cfg, p, base, design, gauss, capped)


def length_grid(params: AttackParams, points: int) -> np.ndarray:
    """Attack lengths of the curves: log grid from ``2 (n + m) + 1`` to the horizon."""
    return log_grid(min(2 * (params.n + params.m) + 1, params.horizon), params.horizon, points)


def evaluate(setting: Setting, attacker: Attacker, *, episodes: int, seed: int, points: int, progress: Any = None) -> Curve:
    """The mean error curve of one attacker in one setting (see the module docstring).

    Main curve ("fresh"): for every N of :func:`length_grid`, ``episodes`` attacks of exactly
    N samples with the energy budget ``m sigma_u2 N``, so every point compares attackers at
    equal energy. With delay 0 also the error of the running estimate within one full-length
    attack ("along", with the energy spent so far), which shows how an attacker paces its
    energy.
    """
    grid = length_grid(setting.params, points)
    cols, t = [], 0.0
    along = None
    if setting.delay != "end":
        along = rollout(attacker, setting.config, episodes=episodes, seed=seed, record=True, progress=progress)
    final = power = None
    for N in grid:
        if along is not None and N == setting.params.horizon:
            r = along  # the same attack, same seeds
        else:
            r = rollout(attacker, budget_config(setting.config, int(N)), episodes=episodes, seed=seed, record=False, progress=progress)
            t += r.seconds
        cols.append(r.final_epsilon)
        final, power = r.final_epsilon, r.average_power
    mean, se = _stats(np.stack(cols, axis=1))
    assert final is not None and power is not None
    c = Curve(attacker.name, attacker.oracle, grid, mean, se, episodes, final, power, t)
    if along is not None:
        d = setting.params.n + setting.params.m
        first = int(np.argmax(along.N >= min(2 * d + 1, int(along.N[-1]))))
        g = log_grid(int(along.N[first]), int(along.N[-1]), 60)
        idx = np.searchsorted(along.N, g)
        c.along_N = along.N[idx]
        c.along_mean, c.along_se = _stats(along.epsilon[:, idx])
        c.along_energy = along.energy[:, idx].mean(axis=0) / setting.params.energy_budget
        c.seconds += along.seconds
    return c


def planned_steps(setting: Setting, n_attackers: int, episodes: int, points: int) -> int:
    """Environment steps of one setting (for the progress bar)."""
    per = int(length_grid(setting.params, points).sum())
    return n_attackers * per * _padded(episodes)


def _padded(episodes: int) -> int:
    B = min(episodes, 64)
    return B * math.ceil(episodes / B)


def elgamal_check(setting: Setting, attacker: Attacker, *, episodes: int, N: int, seed: int, key_length: int = 64) -> list[dict[str, Any]]:
    """A few short episodes through real ElGamal ciphertexts (small key), each next to the same
    episode on the ideal backend (same environment and attacker seeds): the attacker works
    through real ciphertexts and the ideal backend computes the same arithmetic."""
    rows = []
    el_cfg = elgamal_config(setting.config, N, key_length=key_length, crypto_seed=seed)
    ideal_cfg = {k: v for k, v in el_cfg.items() if k not in ("crypto", "crypto_seed")}
    for e in range(episodes):
        r_el = rollout(attacker, el_cfg, episodes=1, seed=seed + e, record=False)
        r_id = rollout(attacker, ideal_cfg, episodes=1, seed=seed + e, record=False, batch=1)
        rows.append({
            "system": setting.system, "delay": setting.delay, "attacker": attacker.name, "episode": e, "N": N,
            "key_length": resolve_params(el_cfg).key_length, "error_elgamal": float(r_el.final_epsilon[0]),
            "error_ideal_same_seed": float(r_id.final_epsilon[0]), "seconds_elgamal": round(r_el.seconds, 3),
        })
    return rows


@dataclass
class Result:
    settings: list[Setting]
    curves: dict[tuple[str, Any], list[Curve]]
    security: list[dict[str, Any]]
    bounds: list[dict[str, Any]]
    seconds: float
    elgamal: list[dict[str, Any]] = field(default_factory=list)


def compute(
    systems: Sequence[str] = DEFAULT_SYSTEMS,
    *,
    delays: Sequence[Any] = DELAYS,
    episodes: int = 50,
    seed: int = 0,
    cap: int | None = DEFAULT_CAP,
    points: int = 10,
    runs: Sequence[Path] = (),
    which: str = "best",
    elgamal_episodes: int = 1,
    elgamal_N: int = 40,
    progress: bool = False,
) -> Result:
    """Run the experiment; every number of the tables and plots comes from here."""
    t0 = time.perf_counter()
    settings = [make_setting(s, d, cap) for s in systems for d in delays]
    plan = [(s, attackers_for(s, runs, which)) for s in settings]
    total = sum(planned_steps(s, len(a), episodes, points) for s, a in plan)
    bar = None
    if progress:
        from tqdm import tqdm

        tty = sys.stderr.isatty()
        bar = tqdm(total=total, desc="compare", unit="step", unit_scale=True, mininterval=0.5 if tty else 30.0, ascii=not tty)
    curves: dict[tuple[str, Any], list[Curve]] = {}
    security: list[dict[str, Any]] = []
    bounds: list[dict[str, Any]] = []
    elgamal: list[dict[str, Any]] = []
    try:
        for setting, atts in plan:
            key = (setting.system, setting.delay)
            curves[key] = []
            for att in atts:
                if bar is not None:
                    bar.set_postfix_str(f"{setting.system} d={setting.delay} {att.name}")
                c = evaluate(setting, att, episodes=episodes, seed=seed, points=points, progress=bar)
                curves[key].append(c)
                security.append(security_row(setting, c))
                if elgamal_episodes > 0:
                    elgamal.extend(elgamal_check(setting, att, episodes=elgamal_episodes, N=elgamal_N, seed=seed))
            bounds.extend(bound_rows(setting))
    finally:
        if bar is not None:
            bar.close()
    return Result(settings, curves, security, bounds, time.perf_counter() - t0, elgamal)


# --------------------------------------------------------------------------- outputs
CURVE_COLUMNS = ("system", "delay", "attacker", "oracle", "protocol", "N", "mean_error", "se", "ci95_low", "ci95_high",
                 "episodes", "gamma", "gamma_opt", "gaussian_design", "energy_fraction")
SECURITY_COLUMNS = ("system", "delay", "attacker", "oracle", "episodes", "horizon", "capped", "mean_error_at_horizon",
                    "se_error_at_horizon", "gamma_at_horizon", "gamma_opt_at_horizon", "average_power", "sigma_u2", "rate_c",
                    "rate_over_gaussian_design", "gamma_c", "N_to_gamma_c", "N_how", "lambda_needed", "k_needed")


def _fmt(v: Any) -> str:
    if isinstance(v, (float, np.floating)):
        return "" if not np.isfinite(v) else repr(float(v))
    return str(v)


def write_csvs(result: Result, out: Path) -> list[Path]:
    """``curves.csv``, ``episodes.csv`` and ``security.csv`` (tidy, one row per observation)."""
    paths = []
    by_key = {(s.system, s.delay): s for s in result.settings}
    with (out / "curves.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(CURVE_COLUMNS)
        for key, cs in result.curves.items():
            s = by_key[key]
            for c in cs:
                parts = [("fresh", c.N, c.mean, c.se, np.full(c.N.shape, np.nan))]
                if c.along_N is not None:
                    parts.append(("along", c.along_N, c.along_mean, c.along_se, c.along_energy))
                for protocol, Ns, means, ses, efrac in parts:
                    for N, m, se, ef in zip(Ns, means, ses, efrac):
                        w.writerow(_fmt(v) for v in (s.system, s.delay, c.attacker, c.oracle, protocol, int(N), m, se,
                                                     m - 1.96 * se, m + 1.96 * se, c.episodes, s.params.gamma(int(N)),
                                                     s.design.gamma(int(N)), s.gauss.gamma(int(N)), ef))
    paths.append(out / "curves.csv")
    with (out / "episodes.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(("system", "delay", "attacker", "episode", "N", "final_error", "average_power"))
        for key, cs in result.curves.items():
            for c in cs:
                for e, (f, pw) in enumerate(zip(c.final, c.power)):
                    w.writerow(_fmt(v) for v in (key[0], key[1], c.attacker, e, int(c.N[-1]), f, pw))
    paths.append(out / "episodes.csv")
    with (out / "security.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(SECURITY_COLUMNS)
        for row in result.security + result.bounds:
            w.writerow(_fmt(row.get(k, "")) for k in SECURITY_COLUMNS)
    paths.append(out / "security.csv")
    if result.elgamal:
        cols = list(result.elgamal[0])
        with (out / "elgamal.csv").open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(cols)
            for row in result.elgamal:
                w.writerow(_fmt(row[k]) for k in cols)
        paths.append(out / "elgamal.csv")
    return paths


def plot(result: Result, out: Path) -> list[Path]:
    """One PNG per system: columns = observation settings; top: mean error against N (95 %
    bands) with gamma(N) and gamma_opt(N); bottom: (N - 1) x mean error, where the 1/N curves
    become flat and the attackers' rates can be told apart."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    systems = list(dict.fromkeys(s.system for s in result.settings))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for system in systems:
        sets = [s for s in result.settings if s.system == system]
        fig, axes = plt.subplots(2, len(sets), figsize=(6.2 * len(sets), 7.5), squeeze=False, sharex="col")
        names = sorted({c.attacker for s in sets for c in result.curves[(s.system, s.delay)]},
                       key=lambda n: [c.attacker for s in sets for c in result.curves[(s.system, s.delay)]].index(n))
        color = {n: colors[i % len(colors)] for i, n in enumerate(names)}
        for j, s in enumerate(sets):
            top, bot = axes[0, j], axes[1, j]
            N0 = min(int(c.N[0]) for c in result.curves[(s.system, s.delay)])
            Nline = np.unique(np.round(np.geomspace(N0, s.params.horizon, 200)).astype(int))
            for c in result.curves[(s.system, s.delay)]:
                pw = c.power.mean()
                lab = f"{c.attacker}{' (oracle)' if c.oracle else ''}, power {pw:.3g}"
                top.plot(c.N, c.mean, color=color[c.attacker], lw=1.4, marker="o", ms=2.5, label=lab)
                top.fill_between(c.N, np.maximum(c.mean - 1.96 * c.se, 0.05 * c.mean), c.mean + 1.96 * c.se, color=color[c.attacker], alpha=0.2, lw=0)
                y = (c.N - 1) * c.mean
                bot.plot(c.N, y, color=color[c.attacker], lw=1.4, marker="o", ms=3)
                bot.fill_between(c.N, (c.N - 1) * (c.mean - 1.96 * c.se), (c.N - 1) * (c.mean + 1.96 * c.se), color=color[c.attacker], alpha=0.2, lw=0)
            for ax, f in ((top, lambda N: N * 0 + 1), (bot, lambda N: N - 1)):
                ax.plot(Nline, s.params.gamma(Nline) * f(Nline), "k--", lw=1.2, label="gamma(N), eq:sic (paper)")
                ax.plot(Nline, s.design.gamma(Nline) * f(Nline), "k:", lw=1.6, label=f"gamma_opt(N), {s.design.kind}")
            bot.axhline(s.gauss.rate, color="0.5", lw=0.8, ls="-.", label="Gaussian attack, exact rate")
            top.set_xscale("log")
            top.set_yscale("log")
            bot.set_xscale("log")
            cap = f", capped at N = {s.params.horizon}" if s.capped else f", N = {s.params.horizon} (tau_c budget)"
            top.set_title(f"{system}, decipher_delay = {s.delay}{cap}", fontsize=10)
            top.set_ylabel("mean identification error  E[eps(N)]")
            bot.set_ylabel("(N - 1) x mean error")
            bot.set_xlabel("sample size N")
            top.grid(True, which="both", alpha=0.3)
            bot.grid(True, which="both", alpha=0.3)
            top.legend(fontsize=7, loc="lower left")
            if j == 0:
                bot.legend(fontsize=7, loc="upper right")
            # axes from the bounds and the Gaussian attack; a far worse curve leaves the axes
            lo = min(np.nanmin((c.N - 1) * c.mean) for c in result.curves[(s.system, s.delay)])
            ref = [s.params.gamma(int(Nline[-1])) * (Nline[-1] - 1), s.design.rate, s.gauss.rate]
            bot.set_ylim(0.85 * min([lo, *ref]), 2.5 * max(ref))
            g = [c for c in result.curves[(s.system, s.delay)] if c.attacker == "gaussian"]
            top_hi = 10 * float(np.nanmax(g[0].mean)) if g else None
            top.set_ylim(0.3 * float(np.min(s.design.gamma(Nline))), top_hi)
        fig.suptitle(f"Attackers against the sample identifying complexity: {system} "
                     f"({result.curves[(sets[0].system, sets[0].delay)][0].episodes} episodes per attacker and N, same seeds, "
                     "energy budget m sigma_u2 N at every N)", fontsize=11)
        fig.tight_layout()
        path = out / f"compare_{system}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
        along = [(s, c) for s in sets for c in result.curves[(s.system, s.delay)] if c.along_N is not None]
        if along:
            paths.append(_plot_pacing(plt, system, along, color, out))
    return paths


def _plot_pacing(plt: Any, system: str, along: list[tuple[Setting, Curve]], color: dict[str, str], out: Path) -> Path:
    """Delay 0: the running error within one full-length attack and the energy spent so far."""
    s0 = along[0][0]
    fig, (top, bot) = plt.subplots(2, 1, figsize=(7.0, 7.5), sharex=True)
    for s, c in along:
        top.plot(c.along_N, c.along_mean, color=color[c.attacker], lw=1.3, label=c.attacker)
        bot.plot(c.along_N, c.along_energy, color=color[c.attacker], lw=1.3)
    Nl = np.asarray(along[0][1].along_N)
    top.plot(Nl, s0.params.gamma(Nl), "k--", lw=1.1, label="gamma(N), eq:sic")
    top.plot(Nl, s0.design.gamma(Nl), "k:", lw=1.5, label="gamma_opt(N)")
    bot.plot(Nl, Nl / s0.params.horizon, "k-", lw=0.8, alpha=0.6, label="uniform pacing")
    top.set(xscale="log", yscale="log", ylabel="mean error of the running estimate",
            title=f"{system}, delay 0: within one attack of N = {s0.params.horizon} (budget for the whole attack)")
    bot.set(xscale="log", xlabel="samples so far", ylabel="fraction of the energy budget spent")
    top.legend(fontsize=7)
    bot.legend(fontsize=7)
    for ax in (top, bot):
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    path = out / f"pacing_{system}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def summary_markdown(result: Result, *, command: str, plots: Sequence[Path]) -> str:
    """The tables and the finding in words (data-driven; pasted into the README)."""
    lines = ["## Attackers against the bounds (`encctl-gym compare`)", ""]
    lines.append(f"Reproduce: `{command}` ({result.seconds / 60:.1f} min on this machine).")
    lines.append("")
    for p in plots:
        lines.append(f"![{p.stem}]({p.as_posix()})")
    lines.append("")
    lines.append("| system | delay | attacker | power | E[eps] at N (± se) | N | (N-1)E[eps] / Gaussian rate | N to gamma_c | lambda | k |")
    lines.append("|---|---|---|---|---|---|---|---|---|---|")
    for r in result.security:
        lines.append(
            f"| {r['system']} | {r['delay']} | {r['attacker']}{' (oracle)' if r['oracle'] else ''} | {r['average_power']:.3g} | "
            f"{r['mean_error_at_horizon']:.3g} ± {r['se_error_at_horizon']:.1g} | {r['horizon']}{'*' if r['capped'] else ''} | "
            f"{r['rate_over_gaussian_design']:.3f} | {r['N_to_gamma_c']} ({r['N_how'][:5]}.) | {r['lambda_needed']} | {r['k_needed']} |"
        )
    for r in result.bounds:
        lines.append(f"| {r['system']} | {r['delay']} | *{r['attacker']}* | | | | {r['rate_over_gaussian_design']:.3f} | "
                     f"{r['N_to_gamma_c']} | {r['lambda_needed']} | {r['k_needed']} |")
    lines.append("")
    lines.append("N marked * is an evaluation cap (the tau_c budget allows more). " + findings(result))
    if result.elgamal:
        same = sum(abs(r["error_elgamal"] - r["error_ideal_same_seed"]) <= 1e-9 * r["error_ideal_same_seed"] for r in result.elgamal)
        lines.append("")
        attackers = len({(r["system"], r["delay"], r["attacker"]) for r in result.elgamal})
        lines.append(f"Through real ElGamal ciphertexts ({result.elgamal[0]['key_length']}-bit key, N = {result.elgamal[0]['N']}): "
                     f"{len(result.elgamal)} episodes over {attackers} attacker settings; {same} of them give the same final "
                     "error as the ideal backend on the same seeds (elgamal.csv).")
    return "\n".join(lines) + "\n"


def findings(result: Result) -> str:
    """Plain-words statements computed from the numbers (no fixed conclusion)."""
    out = []
    for s in result.settings:
        cs = {c.attacker: c for c in result.curves[(s.system, s.delay)]}
        g = cs.get("gaussian")
        if g is None:
            continue
        Nh = int(g.N[-1])
        gam = float(s.params.gamma(Nh))
        beat_gamma = [n for n, c in cs.items() if c.final.mean() + 2 * c.final.std(ddof=1) / math.sqrt(c.final.size) < gam]
        better = []
        for n, c in cs.items():
            if n == "gaussian":
                continue
            d = np.log(c.final) - np.log(g.final)  # paired: same seeds
            se = d.std(ddof=1) / math.sqrt(d.size)
            if d.mean() + 2 * se < 0:
                better.append(f"{n} ({100 * (math.exp(d.mean()) - 1):+.0f}%)")
        out.append(
            f"{s.system}, delay {s.delay}: below the Gaussian attack at N = {Nh} (paired, 2 se): "
            f"{', '.join(better) or 'none'}; below the paper's gamma(N): {', '.join(beat_gamma) or 'none'}."
        )
    for s in result.settings:
        for c in result.curves[(s.system, s.delay)]:
            if c.along_N is None or c.along_energy is None:
                continue
            if 0.1 * s.params.horizon < c.along_N[0]:
                continue  # the energy is recorded from N = 2 (n + m) + 1 on; no extrapolation
            tenth = float(np.interp(0.1 * s.params.horizon, c.along_N, c.along_energy))
            if abs(tenth - 0.1) > 0.1:
                out.append(f"{c.attacker} ({s.system}, delay {s.delay}) paces its energy unevenly: {100 * tenth:.0f}% of the "
                           "attack's budget in its first 10% of samples.")
    return " ".join(out)


# --------------------------------------------------------------------------- command line
def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``encctl-gym compare``."""
    parser.add_argument("--out", default="results/compare", help="output directory (default results/compare)")
    parser.add_argument("--quick", action="store_true", help=f"tiny smoke test ({QUICK_SYSTEMS[0]}, N <= {QUICK_CAP}, {QUICK_EPISODES} episodes)")
    parser.add_argument("--seed", type=int, default=0, help="environment seeds seed, seed + 1, ... (default 0)")
    parser.add_argument("--episodes", type=int, default=None, help="episodes per attacker and setting (default 50)")
    parser.add_argument("--systems", default=None, help=f"comma-separated presets (default {','.join(DEFAULT_SYSTEMS)})")
    parser.add_argument("--delays", default=None, help="comma-separated decipher delays among 0 and end (default 0,end)")
    parser.add_argument("--max-samples", type=int, default=None, help=f"evaluation cap on N (default {DEFAULT_CAP})")
    parser.add_argument("--points", type=int, default=None, help="grid points of the blind (delay end) curves (default 10)")
    parser.add_argument("--runs", action="append", default=[], help="training run directory or a parent of runs (repeatable; "
                        "default results/train if it exists)")
    parser.add_argument("--which", choices=("best", "final"), default="best",
                        help="learned model: the best of the training's evaluation callback (default) or the final one")
    parser.add_argument("--elgamal-episodes", type=int, default=1,
                        help="episodes of each attacker through real ElGamal ciphertexts (64-bit key, N = 40; default 1, 0: none)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def _delay(v: str) -> Any:
    v = v.strip()
    return "end" if v == "end" else int(v)


def run(args: argparse.Namespace) -> int:
    """Run, write CSV, PNG and summary.md; print the summary."""
    quick = args.quick
    systems = tuple(s.strip() for s in args.systems.split(",")) if args.systems else (QUICK_SYSTEMS if quick else DEFAULT_SYSTEMS)
    delays = tuple(_delay(v) for v in args.delays.split(",")) if args.delays else DELAYS
    episodes = args.episodes or (QUICK_EPISODES if quick else 50)
    cap = args.max_samples or (QUICK_CAP if quick else DEFAULT_CAP)
    points = args.points or (4 if quick else 10)
    roots = args.runs or (["results/train"] if Path("results/train").exists() and not quick else [])
    runs = find_runs(roots)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    result = compute(systems, delays=delays, episodes=episodes, seed=args.seed, cap=cap, points=points, runs=runs,
                     which=args.which, elgamal_episodes=args.elgamal_episodes, elgamal_N=min(40, cap),
                     progress=not args.no_progress)
    files = write_csvs(result, out)
    plots = plot(result, out)
    cmd = ["encctl-gym compare", f"--seed {args.seed}", f"--episodes {episodes}", f"--systems {','.join(systems)}",
           f"--max-samples {cap}", f"--which {args.which}"] + [f"--runs {r}" for r in roots] + (["--quick"] if quick else [])
    md = summary_markdown(result, command=" ".join(cmd), plots=plots)
    (out / "summary.md").write_text(md)
    print(md)
    print("wrote " + ", ".join(str(p) for p in [*files, *plots, out / "summary.md"]))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    add_arguments(parser)
    return run(parser.parse_args(argv))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
