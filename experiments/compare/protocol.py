"""The protocol of the comparison: every attacker, the same seeds, the same energy, error against N.

Error against N, at equal energy. The environment's energy budget ``m sigma_u2 N`` holds for
the whole attack, not per step, so the error of the running estimate within one long attack
(``info["epsilon"]`` along the way) compares attackers at *unequal* energy whenever one of them
paces its energy unevenly (a learned policy may spend it early and beat gamma(N) at small N for
that reason alone). The curves are therefore measured on a log grid of attack lengths
(:func:`~experiments.compare.settings.length_grid`), one set of episodes of exactly N samples
(budget ``m sigma_u2 N``) per grid point, every attacker on the same environment seeds. With
delivered states (an integer delay) the running error and the energy spent along one
full-length attack are also recorded (the ``along`` protocol), which shows how an attacker
paces its energy.

ElGamal. Every attacker also plays a few short episodes through real ciphertexts with a small
key, each next to the same episode on the ideal backend (:func:`elgamal_check`).

:func:`compute` runs it all and returns a :class:`Result`; every number of the tables, plots and
reports comes from there.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym._validation import format_value
from encctl_gym.agents import Attacker, GaussianAttacker, rollout
from encctl_gym.agents.evaluate import budget_config, elgamal_config
from encctl_gym.agents.runs import RunInfo, read_run
from encctl_gym.envs.config import resolve_params
from encctl_gym.resources import check_memory
from encctl_gym.sim.montecarlo import log_grid

from .attackers import DEFAULT_ATTACKERS, learned_players, make_attackers
from .records import Curve, Result
from .settings import DEFAULT_CAP, DEFAULT_SYSTEMS, DELAYS, Setting, length_grid, make_setting
from .statistics import mean_se
from .tables import bound_rows, security_row

__all__ = ["evaluate", "planned_steps", "record_bytes", "elgamal_check", "warm_up", "compute"]

#: The name the Gaussian baseline plays under (the reference of the paired ratios).
GAUSSIAN_NAME = GaussianAttacker.name


def evaluate(setting: Setting, attacker: Attacker, *, episodes: int, seed: int, points: int, progress: Any = None) -> Curve:
    """The mean error curve of one attacker in one setting (see the module docstring).

    Main curve ("fresh"): for every N of :func:`length_grid`, ``episodes`` attacks of exactly
    N samples with the energy budget ``m sigma_u2 N``, so every point compares attackers at
    equal energy. With delivered states also the error of the running estimate within one
    full-length attack ("along", with the energy spent so far).
    """
    grid = length_grid(setting.params, points)
    cols, t = [], 0.0
    along = None
    if setting.params.decipher_delay is not None:
        along = rollout(attacker, setting.config, episodes=episodes, seed=seed, record=True, progress=progress, covariance=True)
    final = power = None
    cov = None
    for N in grid:
        if along is not None and N == setting.params.horizon:
            r = along  # the same attack, same seeds
        else:
            last = N == grid[-1]
            r = rollout(
                attacker,
                budget_config(setting.config, int(N)),
                episodes=episodes,
                seed=seed,
                record=False,
                progress=progress,
                covariance=bool(last),
            )
            t += r.seconds
        cov = r.covariance
        cols.append(r.final_epsilon)
        final, power = r.final_epsilon, r.average_power
    mean, se = mean_se(np.stack(cols, axis=1))
    assert final is not None and power is not None
    c = Curve(attacker.name, attacker.oracle, grid, mean, se, episodes, final, power, t, covariance=cov)
    if along is not None:
        d = setting.params.n + setting.params.m
        first = int(np.argmax(along.N >= min(2 * d + 1, int(along.N[-1]))))
        g = log_grid(int(along.N[first]), int(along.N[-1]), 60)
        idx = np.searchsorted(along.N, g)
        c.along_N = along.N[idx]
        c.along_mean, c.along_se = mean_se(along.epsilon[:, idx])
        c.along_energy = along.energy[:, idx].mean(axis=0) / setting.params.energy_budget
        c.seconds += along.seconds
    return c


def planned_steps(setting: Setting, n_attackers: int, episodes: int, points: int) -> int:
    """Environment steps of one setting (the progress bar's total)."""
    batch = min(episodes, 64)
    padded = batch * math.ceil(episodes / batch)  # rollout plays whole batches
    per = int(length_grid(setting.params, points).sum())
    return n_attackers * per * padded


def record_bytes(plan: Sequence[tuple[Setting, Sequence[Any]]], episodes: int, points: int) -> int:
    """Estimated bytes of what :func:`compute` keeps per episode (float64): each curve's errors at
    every grid point and its finals, and, with delivered states, the largest running record of one
    full-length attack (error and energy at every step)."""
    kept, along = 0, 0
    for setting, atts in plan:
        P = len(length_grid(setting.params, points))
        kept += 8 * episodes * (P + 2) * len(atts)
        if setting.params.decipher_delay is not None:
            along = max(along, 16 * episodes * setting.params.horizon)
    return kept + along


def elgamal_check(
    setting: Setting, attacker: Attacker, *, episodes: int, N: int, seed: int, key_length: int = 64
) -> list[dict[str, Any]]:
    """A few short episodes through real ElGamal ciphertexts (small key), each next to the same
    episode on the ideal backend (same environment and attacker seeds): the attacker works
    through real ciphertexts and the ideal backend computes the same arithmetic."""
    rows = []
    el_cfg = elgamal_config(setting.config, N, key_length=key_length, crypto_seed=seed)
    ideal_cfg = {k: v for k, v in el_cfg.items() if k not in ("crypto", "crypto_seed")}
    for e in range(episodes):
        r_el = rollout(attacker, el_cfg, episodes=1, seed=seed + e, record=False)
        r_id = rollout(attacker, ideal_cfg, episodes=1, seed=seed + e, record=False, batch=1)
        rows.append(
            {
                "system": setting.system,
                "delay": setting.delay,
                "attacker": attacker.name,
                "episode": e,
                "N": N,
                "key_length": resolve_params(el_cfg).key_length,
                "error_elgamal": float(r_el.final_epsilon[0]),
                "error_ideal_same_seed": float(r_id.final_epsilon[0]),
                "seconds_elgamal": round(r_el.seconds, 3),
            }
        )
    return rows


def warm_up(plan: Sequence[tuple[Setting, Sequence[tuple[Attacker, Setting]]]], *, points: int, elgamal: bool = False) -> float:
    """Play one short episode of each setting's first attacker in the setting it plays in (and
    one through ElGamal), so that the compiled kernels are compiled (or loaded from numba's
    cache) before a progress bar starts; returns the seconds it took. The episodes are
    discarded; the attackers are reset by every rollout, so nothing of this reaches the results."""
    t0 = time.perf_counter()
    seen: set[tuple[int, int, int, Any]] = set()
    for _, plays in plan:
        if not plays:
            continue
        att, played = plays[0]
        p = played.params
        key = (p.n, p.m, p.input_history, p.decipher_delay is None)
        if key in seen:
            continue
        seen.add(key)
        N = int(length_grid(p, points)[0])
        rollout(att, budget_config(played.config, N), episodes=1, seed=0, record=True, covariance=True)
        if elgamal:
            rollout(att, elgamal_config(played.config, N, crypto_seed=0), episodes=1, seed=0, record=False)
    return time.perf_counter() - t0


def compute(
    systems: Sequence[str] = DEFAULT_SYSTEMS,
    *,
    delays: Sequence[Any] = DELAYS,
    episodes: int = 50,
    seed: int = 0,
    cap: int | None = DEFAULT_CAP,
    points: int = 10,
    runs: Sequence[RunInfo | str | Path] = (),
    which: str = "best",
    elgamal_episodes: int = 1,
    elgamal_N: int = 40,
    progress: bool = False,
    attackers: Sequence[str] = DEFAULT_ATTACKERS,
    configs: Mapping[str, dict[str, Any]] | None = None,
    deterministic: bool = False,
    settings: Sequence[Setting] | None = None,
    players: Callable[[Setting], Sequence[Attacker]] | None = None,
    label: str = "compare",
) -> Result:
    """Run the comparison; every number of the tables and plots comes from here.

    Parameters
    ----------
    systems : sequence of str
        Preset names, or labels of ``configs``.
    delays : sequence
        Decipher delays (``0``, integers, ``"end"``); one setting per system and delay.
    episodes, seed : int
        Episodes per attacker, attack length and setting; environment seeds ``seed + e``.
    cap : int, optional
        Evaluation cap on the attack length.
    points : int
        Attack lengths per curve (:func:`length_grid`).
    runs : sequence
        Training runs (directories or :class:`agents.runs.RunInfo`) whose learned attackers play
        where they apply, each in the environment it was trained in
        (:func:`~experiments.compare.attackers.run_setting`).
    which : {"best", "final"}
        Which model of a run.
    elgamal_episodes, elgamal_N : int
        Short episodes of each attacker through real ElGamal ciphertexts (0: none).
    progress : bool
        A progress bar on stderr, labelled ``label`` (the command that runs it: ``compare``,
        ``evaluate``).
    attackers : sequence of str
        Names of :data:`~experiments.compare.attackers.ATTACKERS` (default :data:`DEFAULT_ATTACKERS`), played in this
        order before the learned ones.
    configs : mapping, optional
        System label -> environment configuration, for systems that are not presets.
    deterministic : bool
        Learned policies play their mean action (off by default: their noise is their excitation).
    settings : sequence of Setting, optional
        Ready settings (then ``systems``, ``delays``, ``cap`` and ``configs`` are not used).
    players : callable, optional
        Further attackers for a setting (played after the learned ones of ``runs``).

    Raises
    ------
    ResourceLimitError
        If the per-episode records (:func:`record_bytes`) would exceed
        :data:`encctl_gym.resources.MEMORY_LIMIT`, before any episode is played.
    """
    t0 = time.perf_counter()
    infos = [r if isinstance(r, RunInfo) else read_run(r) for r in runs]
    if settings is None:
        cfgs = dict(configs or {})
        settings = [make_setting(s, d, cap, config=cfgs.get(s)) for s in systems for d in delays]
    settings = list(settings)
    for s in settings:  # the grid of every setting is checked before any attacker is built or loaded
        length_grid(s.params, points)
    # every attacker with the setting it plays in: a learned one in the environment it was trained in
    plan = [
        (
            s,
            [
                *((a, s) for a in make_attackers(s, attackers)),
                *learned_players(s, infos, which, deterministic=deterministic),
                *((a, s) for a in (players(s) if players is not None else ())),
            ],
        )
        for s in settings
    ]
    total = sum(planned_steps(s, len(a), episodes, points) for s, a in plan)
    check_memory(
        f"keeping the per-episode records of episodes = {format_value(episodes)} over {len(plan)} setting(s) at points = "
        f"{format_value(points)}",
        record_bytes(plan, episodes, points),
        advice="use fewer episodes",
    )
    warm_up(plan, points=points, elgamal=elgamal_episodes > 0)  # the bar's rate (its ETA) counts no compile time
    bar = _progress_bar(total, label) if progress else None
    try:
        curves, security, bounds, elgamal = _play_plan(
            plan, episodes=episodes, seed=seed, points=points, elgamal_episodes=elgamal_episodes, elgamal_N=elgamal_N, bar=bar
        )
    finally:
        if bar is not None:
            bar.close()
    return Result(settings, curves, security, bounds, time.perf_counter() - t0, elgamal, seed)


def _progress_bar(total: int, label: str = "compare") -> Any:
    """The bar of the command ``label`` on stderr (updated every 30 s when stderr is not a terminal)."""
    from tqdm import tqdm

    tty = sys.stderr.isatty()
    return tqdm(total=total, desc=label, unit="step", unit_scale=True, mininterval=0.5 if tty else 30.0, ascii=not tty)


def _play_plan(
    plan: Sequence[tuple[Setting, Sequence[tuple[Attacker, Setting]]]],
    *,
    episodes: int,
    seed: int,
    points: int,
    elgamal_episodes: int,
    elgamal_N: int,
    bar: Any,
) -> tuple[dict[tuple[str, Any], list[Curve]], list[dict[str, Any]], list[dict[str, Any]], list[dict[str, Any]]]:
    """Play every attacker of every setting: the curves by setting, the security and bound rows,
    and the ElGamal checks."""
    curves: dict[tuple[str, Any], list[Curve]] = {}
    security: list[dict[str, Any]] = []
    bounds: list[dict[str, Any]] = []
    elgamal: list[dict[str, Any]] = []
    for setting, atts in plan:
        curves[setting.key] = []
        for att, play in atts:
            if bar is not None:
                bar.set_postfix_str(f"{setting.system} d={setting.delay} {att.name}")
            curves[setting.key].append(evaluate(play, att, episodes=episodes, seed=seed, points=points, progress=bar))
            if elgamal_episodes > 0:
                elgamal.extend(elgamal_check(play, att, episodes=elgamal_episodes, N=elgamal_N, seed=seed))
        cs = curves[setting.key]
        gauss = next((c for c in cs if c.attacker == GAUSSIAN_NAME), None)
        oracle = next((c for c in cs if c.oracle), None)
        security.extend(security_row(setting, c, gaussian=gauss, oracle=oracle) for c in cs)
        bounds.extend(bound_rows(setting))
    return curves, security, bounds, elgamal
