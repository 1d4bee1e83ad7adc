"""Identification strategies: input strategies (attackers) times estimators, against gamma(N).

For each system (default: the paper's design example, Figure 1 (c) and (g), and the ``small``
plant, which is not a multiple of the identity) and each attacker of ``agents`` (the paper's
Gaussian input, random binary, AR(1), the A-optimal design, and the learned attackers of the
training runs under ``--runs``), the attacks are played through ``EncryptedLTIAttack-v0`` (ideal
backend, ``decipher_delay = 0``): one set of ``--episodes`` episodes of exactly ``N`` samples for
every ``N`` of a log grid, with the energy budget ``m sigma_u2 N`` of that length
(:func:`agents.evaluate.budget_config`, as ``encctl-gym compare`` does), so every point compares
inputs at equal energy. From each episode the deciphered and delivered data
(``episode.delivered_data()``: states ``(K, N, n)`` and inputs ``(K, N - 1, m)`` in float64) are
identified by every estimator of ``--estimators`` (:mod:`encctl_gym.ident.registry`) on the
*same* data, and scored by Definition def:error.

The grid runs from ``n + m + 1`` (the least-squares minimum) to ``N*`` of Theorem thm:opt_sec
(eq:opt_sec for the preset's ``gamma_c``), or to ``--max-samples`` if ``N*`` is larger; it
contains the three sample sizes of the table: small (``n + m + 1``), medium (their geometric
mean) and ``N*`` (or the cap).

Security consequence. For every attacker and estimator, the sample size that reaches the
preset's ``gamma_c`` is ``floor(c / gamma_c) + 2`` for the rate ``c`` of a fit
``E[epsilon] ~ c / (N - 1)`` to the upper half of the grid
(:func:`experiments.compare.statistics.fit_rate`), flagged as inside the grid or extrapolated
(and how far), and as transient where the log-log slope there is outside [-1.1, -0.9]; where the
curve does not fall like ``1/N`` (slope above -0.8, e.g. least squares with forgetting) it is
reported as not reached. Then ``lambda = floor(log2(Upsilon tau_c / N_c)) + 1`` (Theorem thm:opt_sec) and the
key length of eq:opt_key, next to the paper's ``N*``, ``lambda*`` and ``k*``.

Heavy tails and replicates. Near ``N = n + m + 1`` the error of least squares has no mean
(:mod:`encctl_gym.ident.tails`: tail exponent ``(N - n - m) / 2``; IV with as many instruments as
unknowns has none at any N): every cell of the tables is the mean with its standard error only
where the mean exists by the tail rule (inputs with a density: the Gaussian and AR(1) attackers)
and the Hill check does not contradict it; elsewhere it is the median with the 10-90 %
quantiles and the reason. ``--replicates R`` repeats the whole experiment on disjoint
environment seeds (``seed + r * episodes``) and fresh attacker streams, and reports each
estimator's mean at ``N*`` and the samples to reach gamma_c as the spread over replicates
(mean and 95 % t interval of the replicate values).

Outputs under ``--out`` (default ``results/strategies``): ``curves.csv`` (system, attacker,
estimator, N, mean, standard error, 95 % band, median, 10 and 90 % quantiles, the status of the
mean, gamma, gamma_opt), ``episodes.csv`` (every episode's error per estimator and its
replicate), ``security.csv`` (per replicate), ``identification_strategies.png`` (mean error
against N with bands, gamma(N) and gamma_opt(N); rows systems, columns attackers),
``identification_strategies_ratio.png`` (each estimator's mean error over least squares') and
``summary.md`` (the tables and the finding in words).

Usage: ``python -m encctl_gym.experiments.identification_strategies [--quick] [--out DIR] [--seed S]
[--episodes E] [--replicates R] [--systems a,b] [--estimators ls,bayes] [--runs DIR] [--max-samples N]``; also
``encctl-gym reproduce`` (step ``strategies``).
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import textwrap
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np
from encctl_gym.agents import Attacker
from encctl_gym.agents.baselines import ColoredGaussianAttacker, GaussianAttacker
from encctl_gym.agents.evaluate import budget_config
from encctl_gym.agents.runs import RunInfo, find_runs
from encctl_gym.experiments.common import add_common_arguments, ensure_out_dir, entry_point
from encctl_gym.experiments.compare.attackers import ATTACKERS, learned_players, left_out, make_attackers
from encctl_gym.experiments.compare.settings import Setting, make_setting, system_entry
from encctl_gym.experiments.compare.statistics import fit_rate
from encctl_gym.experiments.compare.tables import bound_rows

from encctl_gym.errors import ParameterError
from encctl_gym.ident.estimator import Estimator, estimate_errors
from encctl_gym.ident.registry import estimator_names, make_estimator
from encctl_gym.ident.tails import ErrorSummary, error_tail_exponent, summarize_errors
from encctl_gym.plotting import legend_below, save_figure
from encctl_gym.security.design import minimum_key_length, optimal_security_parameter, sample_size_for_rate
from encctl_gym.sim.montecarlo import log_grid

__all__ = [
    "DEFAULT_SYSTEMS",
    "DEFAULT_ESTIMATORS",
    "Curve",
    "Result",
    "collect",
    "attack_lengths",
    "table_sizes",
    "replicate_interval",
    "compute",
    "security_rows",
    "plot",
    "summary_markdown",
    "add_arguments",
    "run",
    "main",
]

#: The design example, Figure 1 (c) and (g) (R_sigma = 100 and 0.01), and a plant that is not a
#: multiple of the identity.
DEFAULT_SYSTEMS = ("paper-example", "fig1-c", "fig1-g", "small")
DEFAULT_ESTIMATORS = ("ls", "bayes", "forgetting", "iv")
#: The design example's N* (13159): no system is attacked longer.
DEFAULT_CAP = 13159
DEFAULT_EPISODES = 50
DEFAULT_POINTS = 12
QUICK_SYSTEMS = ("small",)
QUICK_CAP = 40
QUICK_EPISODES = 4
QUICK_POINTS = 4
#: Below this log-log slope of the mean error over the upper half of the grid, the curve is in
#: the 1/N regime and c / (N - 1) may be extrapolated.
ONE_OVER_N_SLOPE = -0.8


# --------------------------------------------------------------------------- data
def collect(
    attacker: Attacker, config: dict[str, Any], *, episodes: int, seed: int, batch: int = 64
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Play ``episodes`` attacks through the vector environment; return what was delivered.

    Episode ``e`` is reset with ``seed + e`` and the attacker is seeded per batch as in
    :func:`agents.evaluate.rollout`, so the data are those of ``encctl-gym compare`` for the same
    seeds.

    Returns
    -------
    states : ndarray (episodes, N, n)
    inputs : ndarray (episodes, N - 1, m)
        ``episode.delivered_data()`` at the end of each attack (float64).
    epsilon : ndarray (episodes,)
        The environment's own ``info["epsilon"]`` (least squares) at the end.
    """
    from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv

    B = min(episodes, batch)
    env = EncryptedLTIAttackVectorEnv(B, config=config)
    xs, us, eps = [], [], []
    done, chunk = 0, 0
    try:
        while done < episodes:
            obs, info = env.reset(seed=seed + done)
            attacker.reset(seed=np.random.SeedSequence([seed, chunk]))
            while True:
                obs, _, te, tr, info = env.step(attacker.act(obs))
                if te[0] or tr[0]:
                    break
            take = min(B, episodes - done)
            x, u = env.episode.delivered_data()
            xs.append(x[:take])
            us.append(u[:take])
            eps.append(info["epsilon"][:take])
            done += take
            chunk += 1
    finally:
        env.close()
    return np.concatenate(xs), np.concatenate(us), np.concatenate(eps)


def table_sizes(setting: Setting, cap: int | None) -> tuple[int, int, int, bool]:
    """(small, medium, N*, capped): ``n + m + 1``, their geometric mean, ``N*`` or the cap."""
    p = setting.base
    N_star = int(bound_rows(setting)[0]["N_to_gamma_c"])
    capped = cap is not None and N_star > cap
    top = int(cap) if cap is not None and capped else N_star
    small = p.n + p.m + 1
    return small, int(round(math.sqrt(small * top))), top, capped


def attack_lengths(setting: Setting, cap: int | None, points: int) -> np.ndarray:
    """The log grid of attack lengths, with the three table sizes in it."""
    small, medium, top, _ = table_sizes(setting, cap)
    return np.unique(np.concatenate([log_grid(small, top, points), [small, medium, top]])).astype(np.int64)


def replicate_interval(values: Any) -> tuple[float, float, float]:
    """Mean of replicate values with its 95 % t interval (``(v, nan, nan)`` for one replicate)."""
    from scipy.stats import t as student_t

    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return float("nan"), float("nan"), float("nan")
    c = float(v.mean())
    if v.size < 2:
        return c, float("nan"), float("nan")
    h = float(student_t.ppf(0.975, v.size - 1) * v.std(ddof=1) / math.sqrt(v.size))
    return c, c - h, c + h


@dataclass
class Curve:
    """Errors of one attacker and one estimator on every attack length.

    ``errors`` stacks ``replicates`` blocks of equally many episodes; ``tail`` is the tail
    exponent of :func:`~encctl_gym.ident.tails.error_tail_exponent` at each N (None where the
    rule does not apply: inputs without a density).
    """

    attacker: str
    oracle: bool
    estimator: str
    N: np.ndarray
    errors: np.ndarray  # (R * E, len(N)), NaN where the estimator has no estimate
    replicates: int = 1
    tail: list[float | None] | None = None

    @property
    def summaries(self) -> list[ErrorSummary | None]:
        """Per N: median, quantiles and the status of the mean (None where no estimate)."""
        tail = self.tail or [None] * self.N.size
        out: list[ErrorSummary | None] = []
        for k in range(self.N.size):
            col = self.errors[:, k]
            out.append(summarize_errors(col, tail_exponent=tail[k]) if np.isfinite(col).any() else None)
        return out

    def replicate_means(self) -> np.ndarray:
        """``(replicates, len(N))``: the mean of each replicate's episodes."""
        R = self.replicates
        blocks = self.errors.reshape(R, self.errors.shape[0] // R, -1)
        return np.stack([Curve("", False, "", self.N, b).mean for b in blocks])

    @property
    def mean(self) -> np.ndarray:
        """Mean over the episodes with an estimate (NaN where none has one)."""
        ok = np.isfinite(self.errors)
        cnt = ok.sum(axis=0)
        tot = np.where(ok, self.errors, 0.0).sum(axis=0)
        return np.where(cnt > 0, tot / np.maximum(cnt, 1), np.nan)

    @property
    def se(self) -> np.ndarray:
        """Standard error of :attr:`mean` (NaN with fewer than two estimates)."""
        ok = np.isfinite(self.errors)
        cnt = ok.sum(axis=0)
        dev = np.where(ok, self.errors - self.mean, 0.0)
        var = (dev**2).sum(axis=0) / np.maximum(cnt - 1, 1)
        return np.where(cnt > 1, np.sqrt(var / np.maximum(cnt, 1)), np.nan)


@dataclass
class Result:
    """Everything the tables and plots show."""

    settings: list[Setting]
    estimators: list[Estimator]
    curves: dict[str, list[Curve]]  # system -> curves
    env_check: dict[str, float]  # system -> max |LS estimator - env epsilon| / epsilon, N >= 2 (n + m) + 1
    sizes: dict[str, tuple[int, int, int, bool]]
    seconds: float
    security: list[dict[str, Any]] = field(default_factory=list)


def _mean_se(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c = Curve("", False, "", np.zeros(a.shape[1]), a)
    return c.mean, c.se


def compute(
    systems: Sequence[str] = DEFAULT_SYSTEMS,
    *,
    estimators: Sequence[Any] = DEFAULT_ESTIMATORS,
    episodes: int = DEFAULT_EPISODES,
    seed: int = 0,
    cap: int | None = DEFAULT_CAP,
    points: int = DEFAULT_POINTS,
    runs: Sequence[RunInfo] = (),
    which: str = "best",
    progress: bool = False,
    replicates: int = 1,
) -> Result:
    """Run the experiment (see the module docstring); every number of the outputs comes from here.

    Replicate ``r`` plays episodes on the environment seeds ``seed + r * episodes + e`` (disjoint
    across replicates), its attackers seeded from that base.
    """
    t0 = time.perf_counter()
    if replicates < 1:
        raise ParameterError(f"replicates must be >= 1, got {replicates}")
    ests = [make_estimator(e) for e in estimators]
    if not ests:
        raise ParameterError("estimators must not be empty")
    if episodes < 2:
        raise ParameterError(f"episodes must be >= 2 (standard errors), got {episodes}")
    settings: list[Any] = []
    curves: dict[str, list[Curve]] = {}
    checks: dict[str, Any] = {}
    sizes: dict[str, Any] = {}
    for entry in systems:
        system, plant = system_entry(entry)  # a preset, or a plant file as train --system reads it
        s = make_setting(system, 0, cap, config=plant)
        settings.append(s)
        sizes[system] = table_sizes(s, cap)
        grid = attack_lengths(s, cap, points)
        p = s.params
        for est in ests:
            est.check_dimensions(p.n, p.m)
        # a learned attacker plays in the environment it was trained in (its run.json)
        atts = [(a, s) for a in make_attackers(s, tuple(ATTACKERS))] + learned_players(s, list(runs), which)
        curves[system] = []
        worst = 0.0
        for att, play in atts:
            errs = {est.label: np.full((replicates * episodes, grid.size), np.nan) for est in ests}  # type: ignore[attr-defined]
            if progress:
                print(
                    f"identification strategies: {system}, {att.name}, {grid.size} attack lengths up to {grid[-1]}, "
                    f"{replicates} replicate(s)",
                    file=sys.stderr,
                    flush=True,
                )
            for r in range(replicates):
                rows = slice(r * episodes, (r + 1) * episodes)
                for k, N in enumerate(grid):
                    x, u, eps_env = collect(att, budget_config(play.config, int(N)), episodes=episodes, seed=seed + r * episodes)
                    for est in ests:
                        if N < est.min_sample_size(p.n, p.m):
                            continue
                        e = estimate_errors(est.fit(x, u), p.A, p.B)
                        errs[est.label][rows, k] = e  # type: ignore[attr-defined]
                        if est.name == "ls" and not est.params and N >= 2 * (p.n + p.m) + 1:  # type: ignore[attr-defined]
                            worst = max(worst, float(np.max(np.abs(e - eps_env) / eps_env)))
            density = isinstance(att, (GaussianAttacker, ColoredGaussianAttacker))  # inputs with a joint density
            for est in ests:
                tail = [
                    error_tail_exponent(p.n, p.m, int(N), est) if density and N >= est.min_sample_size(p.n, p.m) else None
                    for N in grid
                ]
                curves[system].append(Curve(att.name, att.oracle, est.label, grid, errs[est.label], replicates, tail))  # type: ignore[attr-defined]
        checks[system] = worst
    res = Result(settings, ests, curves, checks, sizes, time.perf_counter() - t0)
    res.security = security_rows(res)
    return res


# --------------------------------------------------------------------------- security
def _slope(N: np.ndarray, mean: np.ndarray) -> float:
    ok = np.isfinite(mean) & (mean > 0)
    N, mean = N[ok], mean[ok]
    tail = np.log(N) >= 0.5 * (np.log(N[0]) + np.log(N[-1]))
    if tail.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log(N[tail] - 1.0), np.log(mean[tail]), 1)[0])


def security_rows(result: Result) -> list[dict[str, Any]]:
    """Per system, attacker and estimator: samples to reach gamma_c, lambda and k (module docstring).

    ``N_to_gamma_c`` is ``floor(c / gamma_c) + 2`` for the rate ``c`` fitted to the upper half of
    the grid (:func:`experiments.compare.statistics.fit_rate`; finer than the grid where the
    curve crosses gamma_c inside it), or None where the curve does not fall like 1/N (slope
    above :data:`ONE_OVER_N_SLOPE`). ``N_how`` says which, how far beyond the grid, and whether
    the slope is still away from -1 (a transient, so the extrapolation is not a measurement).
    ``first_below`` is the first grid point whose mean error is below gamma_c. Where the tail
    rule says the mean does not exist on the fitted half of the grid, ``N_how`` says so (the fit is
    then to sample means of an error without a mean). With several replicates the same is done
    on each replicate's mean curve: ``N_to_gamma_c_replicates`` and its mean with a 95 % t
    interval (``N_to_gamma_c_mean``, ``_low``, ``_high``).
    """
    rows = []
    for s in result.settings:
        b = s.base
        for c in result.curves[s.system]:
            mean = c.mean
            ok = np.isfinite(mean)
            slope, rate, N_c, how = _to_gamma_c(c.N, mean, b.gamma_c)
            below = np.flatnonzero(ok & (mean < b.gamma_c))
            first = int(c.N[below[0]]) if below.size else None
            fitted = np.log(c.N) >= 0.5 * (np.log(c.N[ok][0]) + np.log(c.N[ok][-1])) if ok.any() else np.zeros(c.N.size, bool)
            if c.tail is not None and any(a is not None and a <= 1.0 for a, f in zip(c.tail, fitted) if f):
                how += ", no mean by the tail rule"
            reps = [_to_gamma_c(c.N, rm, b.gamma_c)[2] for rm in c.replicate_means()] if c.replicates > 1 else []
            rc, rlo, rhi = (
                replicate_interval([v for v in reps if v is not None]) if reps and None not in reps else (None, None, None)
            )
            lam = optimal_security_parameter(N_c, tau_c=b.tau_c, upsilon=b.upsilon) if N_c else None
            rows.append(
                {
                    "system": s.system,
                    "attacker": c.attacker,
                    "oracle": c.oracle,
                    "estimator": c.estimator,
                    "gamma_c": b.gamma_c,
                    "slope": slope,
                    "rate_c": rate,
                    "first_below": first,
                    "N_to_gamma_c": N_c,
                    "N_how": how,
                    "lambda_needed": lam,
                    "k_needed": minimum_key_length(lam) if lam else None,
                    "N_to_gamma_c_replicates": " ".join(str(v) for v in reps),
                    "N_to_gamma_c_mean": rc,
                    "N_to_gamma_c_low": rlo,
                    "N_to_gamma_c_high": rhi,
                }
            )
    return rows


def _to_gamma_c(N: np.ndarray, mean: np.ndarray, gamma_c: float) -> tuple[float, float, int | None, str]:
    """(slope, rate, N to gamma_c or None, how) of one mean curve (see :func:`security_rows`)."""
    ok = np.isfinite(mean)
    slope = _slope(N, mean)
    rate = fit_rate(N, mean) if ok.sum() >= 2 else float("nan")
    if not (slope <= ONE_OVER_N_SLOPE):
        return slope, rate, None, f"not reached (slope {slope:.2f})"
    N_c = sample_size_for_rate(rate, gamma_c)
    top = int(N[ok][-1])
    how = "fit, inside the grid" if N_c <= top else f"fit, extrapolated {N_c / top:.3g}x beyond N = {top}"
    if not (-1.1 <= slope <= -0.9):
        how += f", transient slope {slope:.2f}"
    return slope, rate, N_c, how


# --------------------------------------------------------------------------- outputs
CURVE_COLUMNS = (
    "system",
    "attacker",
    "oracle",
    "estimator",
    "N",
    "mean_error",
    "se",
    "ci95_low",
    "ci95_high",
    "episodes",
    "gamma",
    "gamma_opt",
    "median",
    "q10",
    "q90",
    "tail_exponent",
    "mean_status",
)
SECURITY_COLUMNS = (
    "system",
    "attacker",
    "oracle",
    "estimator",
    "gamma_c",
    "slope",
    "rate_c",
    "first_below",
    "N_to_gamma_c",
    "N_how",
    "lambda_needed",
    "k_needed",
    "N_to_gamma_c_replicates",
    "N_to_gamma_c_mean",
    "N_to_gamma_c_low",
    "N_to_gamma_c_high",
)


def _fmt(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, (float, np.floating)):
        return "" if not np.isfinite(v) else repr(float(v))
    return str(v)


def write_csvs(result: Result, out: Path) -> list[Path]:
    """``curves.csv``, ``episodes.csv``, ``security.csv`` (tidy)."""
    by = {s.system: s for s in result.settings}
    with (out / "curves.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(CURVE_COLUMNS)
        for system, cs in result.curves.items():
            s = by[system]
            for c in cs:
                tails = c.tail or [None] * c.N.size
                for N, m, se, sm, a in zip(c.N, c.mean, c.se, c.summaries, tails):
                    q = sm.quantiles if sm is not None else {0.1: None, 0.5: None, 0.9: None}
                    w.writerow(
                        _fmt(v)
                        for v in (
                            system,
                            c.attacker,
                            c.oracle,
                            c.estimator,
                            int(N),
                            m,
                            se,
                            m - 1.96 * se,
                            m + 1.96 * se,
                            c.errors.shape[0],
                            float(s.params.gamma(int(N))),
                            float(s.design.gamma(int(N))),
                            q[0.5],
                            q[0.1],
                            q[0.9],
                            a,
                            sm.status if sm is not None else "",
                        )
                    )
    with (out / "episodes.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(("system", "attacker", "estimator", "N", "replicate", "episode", "error"))
        for system, cs in result.curves.items():
            for c in cs:
                E = c.errors.shape[0] // c.replicates
                for k, N in enumerate(c.N):
                    for e, v in enumerate(c.errors[:, k]):
                        w.writerow(_fmt(x) for x in (system, c.attacker, c.estimator, int(N), e // E, e % E, v))
    with (out / "security.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(SECURITY_COLUMNS)
        for r in result.security:
            w.writerow(_fmt(r[k]) for k in SECURITY_COLUMNS)
    return [out / "curves.csv", out / "episodes.csv", out / "security.csv"]


def _grid_axes(plt: Any, result: Result) -> tuple[Any, Any, list[str], list[str]]:
    systems = [s.system for s in result.settings]
    attackers = list(dict.fromkeys(c.attacker for cs in result.curves.values() for c in cs))
    fig, axes = plt.subplots(
        len(systems), len(attackers), figsize=(3.6 * len(attackers), 3.0 * len(systems)), squeeze=False, sharex="row"
    )
    return fig, axes, systems, attackers


def plot(result: Result, out: Path) -> list[Path]:
    """``identification_strategies.png`` and ``identification_strategies_ratio.png`` (module docstring)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    labels = [e.label for e in result.estimators]  # type: ignore[attr-defined]
    color = {lab: colors[i % len(colors)] for i, lab in enumerate(labels)}
    by = {s.system: s for s in result.settings}
    paths = []
    fig, axes, systems, attackers = _grid_axes(plt, result)
    for i, system in enumerate(systems):
        s = by[system]
        for j, att in enumerate(attackers):
            ax = axes[i, j]
            cs = [c for c in result.curves[system] if c.attacker == att]
            if not cs:
                ax.axis("off")
                continue
            N = cs[0].N
            Nl = np.unique(np.round(np.geomspace(N[0], N[-1], 200)).astype(int))
            for c in cs:
                mean, se = c.mean, c.se
                ok = np.isfinite(mean)
                top = c.estimator == "ls"  # the paper's estimator on top of the others
                # where the mean does not exist or is unreliable: the median (open marker), no band
                sms = c.summaries
                bare = np.array([sm is not None and not sm.mean_ok for sm in sms])
                med = np.array([sm.median if sm is not None else np.nan for sm in sms])
                y = np.where(bare, med, mean)
                ax.plot(
                    c.N[ok],
                    y[ok],
                    color=color[c.estimator],
                    lw=2.0 if top else 1.2,
                    marker="o",
                    ms=2,
                    label=c.estimator,
                    zorder=3 if top else 2,
                    ls="--" if top else "-",
                )
                if bare.any():
                    ax.plot(c.N[bare], med[bare], ls="none", marker="o", ms=5, mfc="none", color=color[c.estimator], zorder=4)
                band = ok & ~bare
                lo = np.maximum(mean - 1.96 * se, 0.05 * mean)
                ax.fill_between(c.N[band], lo[band], (mean + 1.96 * se)[band], color=color[c.estimator], alpha=0.2, lw=0)
            ax.plot(Nl, s.params.gamma(Nl), "k--", lw=1.0, label="gamma(N), eq:sic")
            ax.plot(Nl, s.design.gamma(Nl), "k:", lw=1.4, label="gamma_opt(N)")
            ax.set(xscale="log", yscale="log")
            ax.grid(True, which="major", alpha=0.3)
            if i == 0:
                ax.set_title(f"{att}{' (oracle)' if cs[0].oracle else ''}", fontsize=9)
            if j == 0:
                ax.set_ylabel(f"{system}\nE[eps(N)]", fontsize=9)
            if i == len(systems) - 1:
                ax.set_xlabel("attack length N", fontsize=9)
            shown = [
                np.array([(sm.mean if sm.mean_ok else sm.median) if sm is not None else np.nan for sm in c.summaries]) for c in cs
            ]
            lo_y = float(np.nanmin([np.nanmin(v) for v in shown] + [float(np.min(s.design.gamma(Nl)))]))
            hi_y = float(np.nanmax([np.nanmax(v[np.isfinite(v)]) if np.isfinite(v).any() else lo_y for v in shown]))
            ax.set_ylim(0.5 * lo_y, 2.0 * max(hi_y, lo_y))
            if 0.5 * lo_y <= s.base.gamma_c <= 2.0 * max(hi_y, lo_y):  # short runs end above gamma_c
                ax.axhline(s.base.gamma_c, color="0.5", lw=0.7, ls="-.", label="gamma_c")
    bottom = legend_below(fig, axes)
    E = result.curves[systems[0]][0].errors.shape[0]
    fig.suptitle(
        "\n".join(
            textwrap.wrap(
                f"Identification strategies: mean error (95 % band; open circles: the median where the mean does not exist "
                f"or is unreliable), {E} attacks per N at energy m sigma_u2 N, each estimator on the same delivered data",
                int(13 * fig.get_figwidth()),
            )
        ),
        fontsize=9,
    )
    fig.tight_layout(rect=(0, bottom, 1, 1))
    path = out / "identification_strategies.png"
    save_figure(fig, path, dpi=100)
    plt.close(fig)
    paths.append(path)

    fig, axes, systems, attackers = _grid_axes(plt, result)
    for i, system in enumerate(systems):
        for j, att in enumerate(attackers):
            ax = axes[i, j]
            by_est = {c.estimator: c for c in result.curves[system] if c.attacker == att}
            ref = by_est.get("ls")
            if ref is None:
                ax.axis("off")
                continue
            for lab, c in by_est.items():
                r = c.mean / ref.mean
                ok = np.isfinite(r)
                ax.plot(c.N[ok], r[ok], color=color[lab], lw=1.3, marker="o", ms=2, label=lab)
            ax.axhline(1.0, color="k", lw=0.6)
            ax.set(xscale="log", yscale="log")
            ax.grid(True, which="both", alpha=0.3)
            if i == 0:
                ax.set_title(att, fontsize=9)
            if j == 0:
                ax.set_ylabel(f"{system}\nE[eps] / E[eps of ls]", fontsize=9)
            if i == len(systems) - 1:
                ax.set_xlabel("attack length N", fontsize=9)
    bottom = legend_below(fig, axes)
    fig.suptitle("Each estimator's mean error over that of least squares (eq:estimate), same data", fontsize=10)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    path = out / "identification_strategies_ratio.png"
    save_figure(fig, path, dpi=100)
    plt.close(fig)
    paths.append(path)
    return paths


def _cell(c: Curve, N: int) -> str:
    """The mean ± standard error where the mean exists, else the median [10 %, 90 %] and why."""
    k = int(np.searchsorted(c.N, N))
    sm = c.summaries[k]
    if sm is None:
        return "—"
    if sm.mean_ok:
        return f"{sm.mean:.3g} ± {sm.se:.1g}"
    why = "no mean" if sm.status == "does not exist" else "mean unreliable"
    a = sm.tail_exponent if sm.tail_exponent is not None else (sm.hill.alpha if sm.hill is not None else float("nan"))
    return f"{sm.quantile_text()} ({why}, a = {a:.2g})"


def replicate_table(result: Result) -> list[str]:
    """With several replicates: per attacker and estimator, the mean error at the top of the grid
    and the samples to reach gamma_c, as the mean of the replicates with a 95 % t interval."""
    lines: list[str] = []
    R = result.curves[result.settings[0].system][0].replicates if result.settings else 1
    if R < 2:
        return lines
    for s in result.settings:
        _, _, top, capped = result.sizes[s.system]
        sec = {(r["attacker"], r["estimator"]): r for r in result.security if r["system"] == s.system}
        lines += [
            f"#### {s.system}: {R} replicates (mean of the replicate values [95 % t interval])",
            "",
            f"| attacker | estimator | replicate means at N = {top} | E[eps] at N = {top} | N to gamma_c |",
            "|---|---|---|---|---|",
        ]
        for c in result.curves[s.system]:
            k = int(np.searchsorted(c.N, top))
            vals = c.replicate_means()[:, k]
            m, lo, hi = replicate_interval(vals)
            r = sec[(c.attacker, c.estimator)]
            Nc = (
                f"{r['N_to_gamma_c_mean']:.0f} [{r['N_to_gamma_c_low']:.0f}, {r['N_to_gamma_c_high']:.0f}]"
                if r["N_to_gamma_c_mean"] is not None
                else r["N_how"]
            )
            lines.append(
                f"| {c.attacker} | {c.estimator} | {' '.join(f'{v:.3g}' for v in vals)} | {m:.3g} [{lo:.3g}, {hi:.3g}] | {Nc} |"
            )
        lines.append("")
    return lines


def findings(result: Result) -> list[str]:
    """Plain-words statements computed from the numbers (no fixed conclusion)."""
    out = []
    for s in result.settings:
        small, medium, top, capped = result.sizes[s.system]
        cs = result.curves[s.system]
        for N, what in ((small, "small"), (top, "N*" if not capped else "the cap")):
            best = []
            for att in dict.fromkeys(c.attacker for c in cs):
                sms = {c.estimator: c.summaries[int(np.searchsorted(c.N, N))] for c in cs if c.attacker == att}
                fin = {k: v for k, v in sms.items() if v is not None}
                if "ls" in fin:
                    by_mean = all(v.mean_ok for v in fin.values())  # else medians: a mean ratio means nothing
                    val = {k: (v.mean if by_mean else v.median) for k, v in fin.items()}
                    k_best = min(val, key=val.get)  # type: ignore[arg-type]
                    best.append(f"{att}: {k_best} ({val[k_best] / val['ls']:.4g} x ls, {'means' if by_mean else 'medians'})")
            out.append(f"{s.system} at N = {N} ({what}): best estimator per attacker {'; '.join(best)}.")
        rows = [r for r in result.security if r["system"] == s.system and r["N_to_gamma_c"]]
        steady = [r for r in rows if "transient" not in r["N_how"]]
        if rows:
            r = min(steady or rows, key=lambda r: r["N_to_gamma_c"])
            paper = bound_rows(s)[0]
            text = (
                f"{s.system}: fewest samples to reach gamma_c = {s.base.gamma_c:g}: {r['N_to_gamma_c']} "
                f"({r['attacker']} + {r['estimator']}, {r['N_how']}) against the paper's N* = {paper['N_to_gamma_c']}; "
                f"lambda {r['lambda_needed']} against lambda* = {paper['lambda_needed']}"
            )
            lower = [q for q in rows if q["N_to_gamma_c"] < r["N_to_gamma_c"]]
            if steady and lower:
                q = min(lower, key=lambda q: q["N_to_gamma_c"])
                text += (
                    f" (fewer, {q['N_to_gamma_c']}, only from an extrapolation of a transient curve: "
                    f"{q['attacker']} + {q['estimator']}, {q['N_how']})"
                )
            out.append(text + ".")
    return out


def summary_markdown(result: Result, *, command: str, plots: Sequence[Path]) -> str:
    """The tables (errors at small, medium N and N*; samples to gamma_c) and the findings."""
    lines = [
        "## Identification strategies (`experiments/identification_strategies.py`)",
        "",
        f"Reproduce: `{command}` ({result.seconds / 60:.1f} min on this machine).",
        "",
    ]
    lines += [f"![{p.stem}]({p.as_posix()})" for p in plots] + [""]
    for s in result.settings:
        small, medium, top, capped = result.sizes[s.system]
        lines.append(
            f"### {s.system} (gamma_c = {s.base.gamma_c:g}; least squares of this script vs the environment's "
            f"info['epsilon'] for N >= 2 (n + m) + 1: max relative difference {result.env_check[s.system]:.1e})"
        )
        lines.append("")
        lines.append(
            f"| attacker | estimator | E[eps] at N = {small} | N = {medium} | N = {top}{' (cap)' if capped else ' (N*)'} "
            "| N to gamma_c | lambda | k |"
        )
        lines.append("|---|---|---|---|---|---|---|---|")
        sec = {(r["attacker"], r["estimator"]): r for r in result.security if r["system"] == s.system}
        for c in result.curves[s.system]:
            r = sec[(c.attacker, c.estimator)]
            Nc = f"{r['N_to_gamma_c']} ({r['N_how']})" if r["N_to_gamma_c"] else r["N_how"]
            lines.append(
                f"| {c.attacker}{' (oracle)' if c.oracle else ''} | {c.estimator} | {_cell(c, small)} | {_cell(c, medium)} | "
                f"{_cell(c, top)} | {Nc} | {r['lambda_needed'] or '—'} | {r['k_needed'] or '—'} |"
            )
        for b in bound_rows(s):
            lines.append(f"| *{b['attacker']}* | | | | | {b['N_to_gamma_c']} | {b['lambda_needed']} | {b['k_needed']} |")
        lines.append("")
    lines += replicate_table(result)
    lines.append(
        "Cells: mean ± standard error where the mean exists (tail rule of encctl_gym.ident.tails for inputs with a "
        "density, and the Hill check); elsewhere the median [10 %, 90 %] with the tail exponent a. 'extrapolated' "
        "marks a sample size beyond the grid, from the 1/N fit."
    )
    lines.append("")
    lines.append("Findings: " + " ".join(findings(result)))
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- command line
def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options: the common ones of the reproduction scripts plus the experiment's own."""
    add_common_arguments(parser)
    add_own_arguments(parser)


def add_own_arguments(parser: argparse.ArgumentParser) -> None:
    """The options that ``encctl-gym reproduce`` does not have (their defaults apply there)."""
    parser.add_argument(
        "--episodes",
        type=int,
        default=None,
        help=f"attacks per attacker and N (default {DEFAULT_EPISODES}; quick {QUICK_EPISODES})",
    )
    parser.add_argument("--replicates", type=int, default=1, help="independent repetitions on disjoint seeds (default 1)")
    parser.add_argument(
        "--systems",
        default=None,
        help=f"comma-separated presets or plant files (as train --system reads; default {','.join(DEFAULT_SYSTEMS)})",
    )
    parser.add_argument(
        "--estimators",
        default=None,
        help=f"comma-separated registry names (default {','.join(DEFAULT_ESTIMATORS)}; known: {', '.join(estimator_names())})",
    )
    parser.add_argument(
        "--max-samples", type=int, default=None, help=f"cap on the attack length (default {DEFAULT_CAP}; quick {QUICK_CAP})"
    )
    parser.add_argument("--points", type=int, default=None, help=f"grid points (default {DEFAULT_POINTS}; quick {QUICK_POINTS})")
    parser.add_argument(
        "--runs",
        action="append",
        default=[],
        help="training run directory or a parent of runs: its learned attackers join (repeatable; needs the [rl] extra)",
    )
    parser.add_argument("--which", choices=("best", "final"), default="best", help="learned model: best (default) or final")


def run(args: argparse.Namespace) -> int:
    """Run, write the CSVs, PNGs and ``summary.md`` under ``args.out``; print the summary."""
    quick = bool(getattr(args, "quick", False))
    systems_arg = getattr(args, "systems", None)
    systems = tuple(x.strip() for x in systems_arg.split(",")) if systems_arg else (QUICK_SYSTEMS if quick else DEFAULT_SYSTEMS)
    est_arg = getattr(args, "estimators", None)
    estimators = tuple(x.strip() for x in est_arg.split(",")) if est_arg else DEFAULT_ESTIMATORS
    episodes = getattr(args, "episodes", None) or (QUICK_EPISODES if quick else DEFAULT_EPISODES)
    cap = getattr(args, "max_samples", None) or (QUICK_CAP if quick else DEFAULT_CAP)
    points = getattr(args, "points", None) or (QUICK_POINTS if quick else DEFAULT_POINTS)
    roots = getattr(args, "runs", None) or []
    which = getattr(args, "which", "best")
    out = ensure_out_dir(getattr(args, "out", "results/strategies"))
    skipped: list[tuple[Path, str]] = []
    runs = find_runs(roots, left_out=skipped)
    if runs:  # the runs that play in none of the systems, said before the work
        entries = [system_entry(e) for e in systems]
        skipped += [
            (r.path, why) for r, why in left_out(runs, [make_setting(label, 0, cap, config=cfg) for label, cfg in entries])
        ]
    for path, why in skipped:
        print(f"identification strategies: leaving out the run {path}: {why}", file=sys.stderr)
    result = compute(
        systems,
        estimators=estimators,
        episodes=episodes,
        seed=args.seed,
        cap=cap,
        points=points,
        runs=runs,
        which=which,
        progress=not getattr(args, "no_progress", True),
        replicates=getattr(args, "replicates", 1) or 1,
    )
    files = write_csvs(result, out)
    plots = plot(result, out)
    cmd = (
        [
            "python -m encctl_gym.experiments.identification_strategies",
            f"--seed {args.seed}",
            f"--episodes {episodes}",
            f"--replicates {getattr(args, 'replicates', 1) or 1}",
            f"--systems {','.join(systems)}",
            f"--estimators {','.join(estimators)}",
            f"--max-samples {cap}",
            f"--points {points}",
        ]
        + [f"--runs {r}" for r in roots]
        + (["--quick"] if quick else [])
    )
    md = summary_markdown(result, command=" ".join(cmd), plots=[Path(p.name) for p in plots])
    (out / "summary.md").write_text(md)
    print(md)
    print("identification strategies: wrote " + ", ".join(str(p) for p in [*files, *plots, out / "summary.md"]))
    return 0


main = entry_point("identification_strategies", __doc__, add_arguments, run)


if __name__ == "__main__":
    sys.exit(main())
