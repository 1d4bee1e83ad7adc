"""Figures of a comparison: error against N per system, and the energy pacing within one attack.

Every number drawn comes from a :class:`~experiments.compare.records.Result`.
"""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym._validation import format_count
from encctl_gym.plotting import legend_below, save_figure

from .records import Curve, Result
from .settings import Setting
from .statistics import Z95

__all__ = ["plot", "plot_pacing"]


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _colors(result: Result, sets: list[Setting], plt: Any) -> dict[str, str]:
    cycle = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    names = list(dict.fromkeys(c.attacker for s in sets for c in result.curves[s.key]))
    return {n: cycle[i % len(cycle)] for i, n in enumerate(names)}


def plot(result: Result, out: Path) -> list[Path]:
    """One PNG per system (``compare_<system>.png``): columns = observation settings; top: mean
    error against N (95 % bands) with gamma(N) and gamma_opt(N); bottom: (N - 1) x mean error,
    where the 1/N curves become flat and the attackers' rates can be told apart. With delivered
    states also ``pacing_<system>.png`` (:func:`plot_pacing`)."""
    plt = _pyplot()
    out = Path(out)
    paths = []
    systems = list(dict.fromkeys(s.system for s in result.settings))
    for system in systems:
        sets = [s for s in result.settings if s.system == system]
        color = _colors(result, sets, plt)
        fig, axes = plt.subplots(2, len(sets), figsize=(6.4 * len(sets), 7.8), squeeze=False, sharex="col")
        for j, s in enumerate(sets):
            top, bot = axes[0, j], axes[1, j]
            cs = result.curves[s.key]
            N0 = min(int(c.N[0]) for c in cs)
            Nline = np.unique(np.round(np.geomspace(N0, s.params.horizon, 200)).astype(int))
            for c in cs:
                lab = f"{c.attacker}{' (oracle)' if c.oracle else ''}, power {c.power.mean():.3g}"
                top.plot(c.N, c.mean, color=color[c.attacker], lw=1.4, marker="o", ms=2.5, label=lab)
                top.fill_between(
                    c.N,
                    np.maximum(c.mean - Z95 * c.se, 0.05 * c.mean),
                    c.mean + Z95 * c.se,
                    color=color[c.attacker],
                    alpha=0.2,
                    lw=0,
                )
                bot.plot(c.N, (c.N - 1) * c.mean, color=color[c.attacker], lw=1.4, marker="o", ms=3)
                bot.fill_between(
                    c.N,
                    (c.N - 1) * (c.mean - Z95 * c.se),
                    (c.N - 1) * (c.mean + Z95 * c.se),
                    color=color[c.attacker],
                    alpha=0.2,
                    lw=0,
                )
            gam, opt = s.params.gamma(Nline), s.design.gamma(Nline)
            top.plot(Nline, gam, "k--", lw=1.2, label="gamma(N), eq:sic (paper)")
            top.plot(Nline, opt, "k:", lw=1.6, label=f"gamma_opt(N), {s.design.kind}")
            bot.plot(Nline, gam * (Nline - 1), "k--", lw=1.2, label="gamma(N), eq:sic (paper)")
            bot.plot(Nline, opt * (Nline - 1), "k:", lw=1.6, label=f"gamma_opt(N), {s.design.kind}")
            bot.axhline(s.gauss.rate, color="0.5", lw=0.8, ls="-.", label="Gaussian attack, exact rate")
            top.set_xscale("log")
            top.set_yscale("log")
            bot.set_xscale("log")
            cap = f"N = {s.params.horizon} (set by the evaluation)" if s.capped else f"N = {s.params.horizon} (tau_c budget)"
            top.set_title(f"{system}, decipher_delay = {s.delay}, {cap}", fontsize=10)
            top.set_ylabel("mean identification error  E[eps(N)]")
            bot.set_ylabel("(N - 1) x mean error")
            bot.set_xlabel("sample size N")
            for ax in (top, bot):
                ax.grid(True, which="both", alpha=0.3)
            # the axes hold the bounds and every attacker's points with their bands (the early,
            # small-N points included)
            lo = min(float(np.nanmin((c.N - 1) * (c.mean - Z95 * np.nan_to_num(c.se)))) for c in cs)
            hi = max(float(np.nanmax((c.N - 1) * (c.mean + Z95 * np.nan_to_num(c.se)))) for c in cs)
            ref = [float(gam[-1] * (Nline[-1] - 1)), float(gam[0] * (Nline[0] - 1)), s.design.rate, s.gauss.rate]
            bot.set_ylim(0.85 * max(min([lo, *ref]), 1e-300), 1.15 * max(hi, 2.2 * max(ref)))
            g = [c for c in cs if c.attacker == "gaussian"]
            top_hi = max(
                10 * float(np.nanmax(g[0].mean)) if g else 0.0,
                1.5 * float(np.max(gam)),
                1.5 * float(np.max(opt)),
                1.5 * max(float(np.nanmin(c.mean)) for c in cs),
            )  # every curve keeps its best point in view
            top.set_ylim(0.3 * float(min(np.min(opt), np.min(gam))), top_hi)
        episodes = result.curves[sets[0].key][0].episodes
        fig.suptitle(
            "\n".join(
                textwrap.wrap(
                    f"Attackers against the sample identifying complexity: {system} ({format_count(episodes, 'episode')} per attacker and N, "
                    "same seeds, energy budget m sigma_u2 N at every N)",
                    int(11 * fig.get_figwidth()),
                )
            ),
            fontsize=11,
        )
        bottom = legend_below(fig, axes, ncol=3 * len(sets))  # one legend for every panel, off the data
        fig.tight_layout(rect=(0, bottom, 1, 0.93 if len(sets) == 1 else 0.96))
        path = out / f"compare_{system}.png"
        save_figure(fig, path, dpi=110)
        plt.close(fig)
        paths.append(path)
        along = [(s, c) for s in sets for c in result.curves[s.key] if c.along_N is not None]
        if along:
            paths.append(plot_pacing(system, along, color, out))
    return paths


def plot_pacing(system: str, along: list[tuple[Setting, Curve]], color: dict[str, str], out: Path) -> Path:
    """Delivered states: the running error within one full-length attack and the energy spent so
    far (``pacing_<system>.png``)."""
    plt = _pyplot()
    s0 = along[0][0]
    fig, (top, bot) = plt.subplots(2, 1, figsize=(7.4, 7.8), sharex=True)
    for _, c in along:
        top.plot(c.along_N, c.along_mean, color=color[c.attacker], lw=1.3, label=c.attacker)
        bot.plot(c.along_N, c.along_energy, color=color[c.attacker], lw=1.3)
    Nl = np.asarray(along[0][1].along_N)
    top.plot(Nl, s0.params.gamma(Nl), "k--", lw=1.1, label="gamma(N), eq:sic")
    top.plot(Nl, s0.design.gamma(Nl), "k:", lw=1.5, label="gamma_opt(N)")
    bot.plot(Nl, Nl / s0.params.horizon, "k-", lw=0.8, alpha=0.6, label="uniform pacing")
    top.set(xscale="log", yscale="log", ylabel="mean error of the running estimate")
    top.set_title(
        f"{system}, delay {s0.delay}: within one attack of N = {s0.params.horizon}\n"
        "(the energy budget holds for the whole attack)",
        fontsize=10,
    )
    bot.set(xscale="log", xlabel="samples so far", ylabel="fraction of the energy budget spent")
    for ax in (top, bot):
        ax.grid(True, which="both", alpha=0.3)
    bottom = legend_below(fig, [top, bot], ncol=3)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    path = Path(out) / f"pacing_{system}.png"
    save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path
