"""Identification strategies, the measurement: the systems and attack lengths, the Monte Carlo
of every attacker and estimator (:func:`compute`), and the rows of the security analysis
(:func:`security_rows`). The experiment is :mod:`encctl_gym.experiments.identification_strategies`."""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from encctl_gym.agents import Attacker
from encctl_gym.agents.baselines import ColoredGaussianAttacker, GaussianAttacker
from encctl_gym.agents.evaluate import budget_config
from encctl_gym.agents.runs import RunInfo
from encctl_gym.errors import ParameterError
from encctl_gym.experiments.compare.attackers import DEFAULT_ATTACKERS, learned_players, make_attackers
from encctl_gym.experiments.compare.settings import Setting, make_setting, system_entry
from encctl_gym.experiments.compare.statistics import fit_rate
from encctl_gym.experiments.compare.tables import bound_rows
from encctl_gym.ident.estimator import Estimator, estimate_errors
from encctl_gym.ident.registry import make_estimator
from encctl_gym.ident.tails import ErrorSummary, error_tail_exponent, summarize_errors
from encctl_gym.security.design import minimum_key_length, optimal_security_parameter, sample_size_for_rate
from encctl_gym.sim.montecarlo import log_grid

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
        atts = [(a, s) for a in make_attackers(s, DEFAULT_ATTACKERS)] + learned_players(s, list(runs), which)
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
