"""The measured deciphering time against the cost models: the figure ``deciphering_models.png``
and the fit of the first key's time to ``L_p[1/2, c]``.

An index calculus in a prime field costs ``L_p[1/2, c] = exp((c + o(1)) sqrt(ln p ln ln p))``
(the basic method ``c = sqrt 2``, the linear sieve and the Gaussian integer method ``c = 1``).
:func:`fit_lp_half` fits

    T_first(p) = a exp(c sqrt(ln p ln ln p)),       ln p = bits ln 2,

to the measured first-key CPU times of a breaker (least squares on ``ln T_first``, which is
linear in ``ln a`` and c), at the sizes where the asymptotic regime holds (from
:data:`FIT_MIN_BITS` bits; below, fixed costs per key dominate), with Student-t confidence
intervals from the residual scatter: the fitted c is the *effective* exponent over the measured
range, the o(1) included. :func:`plot_models` draws it beside the measurements and the
package's cost models; the rows are those of :mod:`experiments.deciphering_time`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym.errors import ParameterError
from encctl_gym.plotting import save_figure

__all__ = [
    "LpFit",
    "fit_lp_half",
    "lp_half_exponent",
    "model_curves",
    "plot_models",
    "sequence_ratio",
    "format_lp_fits",
    "FIT_MIN_BITS",
]

#: Smallest bit length in the L_p[1/2, c] fit.
FIT_MIN_BITS = 64
#: Breakers whose first key is fitted (the index calculus, and PARI's for comparison).
FITTED_BREAKERS = ("index-calculus", "pari")


def lp_half_exponent(bits: Any) -> np.ndarray:
    """``sqrt(ln p ln ln p)`` with ``ln p = bits ln 2``."""
    ln_p = np.asarray(bits, dtype=float) * math.log(2)
    return np.sqrt(ln_p * np.log(ln_p))


@dataclasses.dataclass(frozen=True)
class LpFit:
    """``T_first = a exp(c sqrt(ln p ln ln p))`` fitted to measured times.

    Attributes
    ----------
    breaker : str
    bits, seconds : tuple
        The points fitted (bit lengths and first-key CPU seconds).
    a, c : float
        The fit.
    a_interval, c_interval : tuple of float
        Confidence intervals at ``level`` (Student t, ``len(bits) - 2`` degrees of freedom).
    level : float
    cov : tuple of tuple of float
        The covariance of ``(ln a, c)`` (residual variance times ``(X^T X)^-1``).
    t : float
        The Student quantile of the intervals.
    """

    breaker: str
    bits: tuple[int, ...]
    seconds: tuple[float, ...]
    a: float
    c: float
    a_interval: tuple[float, float]
    c_interval: tuple[float, float]
    level: float
    cov: tuple[tuple[float, float], tuple[float, float]] = ((math.nan, math.nan), (math.nan, math.nan))
    t: float = math.nan

    def __call__(self, bits: Any) -> np.ndarray:
        """The fitted time at ``bits``."""
        return self.a * np.exp(self.c * lp_half_exponent(bits))

    def band(self, bits: Any) -> tuple[np.ndarray, np.ndarray]:
        """The confidence band of the fitted time at ``bits`` (at :attr:`level`):
        ``exp(ln fit -+ t sqrt(x^T cov x))`` with ``x = (1, sqrt(ln p ln ln p))``."""
        x = lp_half_exponent(bits)
        cov = np.array(self.cov)
        se = np.sqrt(cov[0, 0] + 2 * x * cov[0, 1] + x * x * cov[1, 1])
        mid = self(bits)
        return mid * np.exp(-self.t * se), mid * np.exp(self.t * se)


def fit_lp_half(breaker: str, bits: Sequence[int], seconds: Sequence[float], *, level: float = 0.95) -> LpFit:
    """Least squares of ``ln T = ln a + c sqrt(ln p ln ln p)`` with t-intervals on ``ln a`` and c.

    Raises
    ------
    ParameterError
        For fewer than three points, non-positive times or a level outside (0, 1).
    """
    from scipy import stats

    x, y = lp_half_exponent(bits), np.asarray(seconds, dtype=float)
    if x.size < 3 or x.size != y.size or np.unique(x).size < 2:
        raise ParameterError(f"the L_p[1/2, c] fit needs at least three sizes, got bits {list(bits)}")
    if not np.all(np.isfinite(y) & (y > 0)):
        raise ParameterError(f"the L_p[1/2, c] fit needs positive times, got {list(seconds)}")
    if not 0 < level < 1:
        raise ParameterError(f"level must lie in (0, 1), got {level}")
    X = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(X, np.log(y), rcond=None)
    dof = x.size - 2
    resid = np.log(y) - X @ coef
    s2 = float(resid @ resid) / dof if dof > 0 else float("nan")
    cov = s2 * np.linalg.inv(X.T @ X)
    t = float(stats.t.ppf((1 + level) / 2, dof)) if dof > 0 else float("nan")
    half = t * np.sqrt(np.diag(cov))
    ln_a, c = float(coef[0]), float(coef[1])
    return LpFit(
        breaker,
        tuple(int(b) for b in bits),
        tuple(float(v) for v in y),
        math.exp(ln_a),
        c,
        (math.exp(ln_a - half[0]), math.exp(ln_a + half[0])),
        (c - half[1], c + half[1]),
        level,
        ((float(cov[0, 0]), float(cov[0, 1])), (float(cov[1, 0]), float(cov[1, 1]))),
        t,
    )


def lp_fits(fits: Sequence[dict[str, Any]], *, min_bits: int = FIT_MIN_BITS) -> list[LpFit]:
    """The :func:`fit_lp_half` of each breaker of :data:`FITTED_BREAKERS` with at least three sizes
    from ``min_bits`` bits in ``fits`` (the rows of :func:`experiments.deciphering_time.fit`)."""
    out = []
    for breaker in FITTED_BREAKERS:
        mine = sorted((f for f in fits if f["breaker"] == breaker and int(f["bits"]) >= min_bits), key=lambda f: f["bits"])
        if len(mine) >= 3:
            out.append(fit_lp_half(breaker, [int(f["bits"]) for f in mine], [float(f["T_first"]) for f in mine]))
    return out


def format_lp_fits(fits: Sequence[LpFit]) -> str:
    """The fits as text: a, c with their intervals, then measured against fitted per size."""
    lines = [f"first-key CPU time T_first = a exp(c sqrt(ln p ln ln p)), ln p = bits ln 2, fitted from {FIT_MIN_BITS} bits"]
    for f in fits:
        lines.append(
            f"{f.breaker}: c = {f.c:.3f} [{f.c_interval[0]:.3f}, {f.c_interval[1]:.3f}], a = {f.a:.3g} s "
            f"[{f.a_interval[0]:.3g}, {f.a_interval[1]:.3g}] ({f.level:.0%} intervals, {len(f.bits)} sizes)"
        )
        for b, t in zip(f.bits, f.seconds):
            lines.append(f"  {b:>4} bits: measured {t:10.4g} s, fitted {float(f(b)):10.4g} s")
    if not fits:
        lines.append("(no breaker has three sizes in range: nothing fitted)")
    return "\n".join(lines)


def model_curves(
    bits: Sequence[int] | np.ndarray, n: Sequence[int] | np.ndarray, *, model_bits: int
) -> dict[str, dict[str, np.ndarray]]:
    """What each deciphering-cost model of :mod:`encctl_gym.security.cost_models` predicts, in the
    units the measurements can be compared with (ratios: the models count abstract operations):

    ``ratio``: ``T_1 / T_first`` of a key length, ``C_next / C_first`` (nan where the model's
    formula is not valid, the GNFS models below 40 bits); ``tau``: ``tau(N) / T_first`` at
    ``model_bits``, ``(C_first + (N - 1) C_next) / C_first``; ``first``: ``log2 C_first`` of a
    key length (nan outside the formula's range).
    """
    from encctl_gym.errors import ModelRangeError
    from encctl_gym.security.cost_models import DECIPHERING_MODELS, deciphering_model

    out: dict[str, dict[str, np.ndarray]] = {}
    n_arr = np.asarray(n, dtype=float)
    for name in DECIPHERING_MODELS:
        model = deciphering_model(name)
        ratio, first = [], []
        for k in bits:
            try:
                c = model.break_cost(int(k))
            except ModelRangeError:
                ratio.append(float("nan"))
                first.append(float("nan"))
            else:
                ratio.append(float(c.next / c.first))
                first.append(c.first_bits)
        c = model.break_cost(int(model_bits))
        r = float(c.next / c.first)
        out[name] = {"ratio": np.array(ratio), "tau": 1.0 + (n_arr - 1.0) * r, "first": np.array(first)}
    return out


_STYLES = {"paper": ("k", "-"), "precomputation": ("tab:red", "--"), "generic": ("tab:gray", ":")}


def _first_key_panel(
    ax: Any, fits: Sequence[dict[str, Any]], curves: dict[str, dict[str, np.ndarray]], grid_bits: np.ndarray
) -> None:
    # T_first against the bit length: the measured points, the L_p[1/2, c] fits (with the band of
    # the interval of c, a at its fit), the index calculus's own cost model in seconds at its
    # documented constants (the estimates of ``crack`` also time lattices of the group: not here),
    # and the shapes of the package's deciphering-cost models, scaled to the index calculus's
    # first measured size in range (they count operations, not seconds).
    from encctl_gym.cryptanalysis.index_calculus import choose_bound, cost_model

    colors = {"index-calculus": "tab:blue", "pari": "tab:orange"}
    measured = []
    for breaker, marker in (("index-calculus", "o"), ("pari", "s")):
        mine = sorted((f for f in fits if f["breaker"] == breaker), key=lambda f: f["bits"])
        measured += [float(f["T_first"]) for f in mine]
        if mine:
            ax.semilogy([f["bits"] for f in mine], [f["T_first"] for f in mine], marker, ms=5, color=colors[breaker],
                        label=f"measured: {breaker}")  # fmt: skip
    for f in lp_fits(fits):
        b = np.arange(min(f.bits), max(f.bits) + 1)
        label = f"fit {f.breaker}: $L_p[1/2, {f.c:.2f}]$, c in [{f.c_interval[0]:.2f}, {f.c_interval[1]:.2f}] ({f.level:.0%})"
        ax.semilogy(b, f(b), lw=1.6, color=colors[f.breaker], label=label)
        ax.fill_between(b, *f.band(b), alpha=0.15, color=colors[f.breaker])
    ic = sorted((f for f in fits if f["breaker"] == "index-calculus"), key=lambda f: f["bits"])
    if ic:
        lo_bits = max(int(grid_bits[0]), 24)
        b = np.arange(lo_bits, int(grid_bits[-1]) + 1)
        model = [cost_model(int(k), choose_bound(int(k)))["first"] for k in b]
        ax.semilogy(b, model, color="tab:blue", ls="-.", lw=1.0,
                    label="index-calculus cost model (documented constants)")  # fmt: skip
        # the model at the measured sizes stays inside the axes, however fast this machine is
        measured += [m for k, m in zip(b, model) if any(int(f["bits"]) == int(k) for f in ic) and m > 0]
        anchor = next((f for f in ic if f["bits"] >= FIT_MIN_BITS), ic[-1])
        for name, (color, ls) in _STYLES.items():
            first = curves[name]["first"]
            at = int(np.searchsorted(grid_bits, anchor["bits"]))
            if name not in ("paper", "generic") or at >= first.size or not np.isfinite(first[at]):
                continue  # the precomputation model's first key is the paper's
            ax.semilogy(grid_bits, anchor["T_first"] * np.exp2(first - first[at]), color=color, ls=ls, lw=1.2,
                        label=f"model {name}: shape, scaled at {anchor['bits']} bits")  # fmt: skip
    if measured:  # the models' shapes leave the measured range quickly: keep the data (and the IC model) readable
        ax.set_ylim(min(measured) / 3, max(measured) * 30)  # room above for the legend
    ax.set_xlabel("bit length of $p$")
    ax.set_ylabel("first key $T_{first}$ (CPU seconds)")
    ax.set_title(r"one key from scratch: measured, fitted $L_p[1/2, c]$ and the cost models", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2, frameon=False)


def sequence_ratio(rows: Sequence[dict[str, Any]], breaker: str, bits: int) -> tuple[np.ndarray, np.ndarray]:
    """``N`` and ``tau(N) / tau(1)`` of the breaker's key sequence at ``bits``: ``T_first`` is the
    first key of the same sequence (its precomputation and key 1), not the mean first key of the
    fresh groups (:func:`experiments.deciphering_time.fit`), so every curve starts at 1. Empty
    without a row at ``N = 1``."""
    seq = sorted(
        (r for r in rows if r["breaker"] == breaker and int(r["bits"]) == bits and r["kind"] == "sequence"),
        key=lambda r: int(r["N"]),
    )
    if not seq or int(seq[0]["N"]) != 1:
        return np.zeros(0, dtype=int), np.zeros(0)
    n = np.array([int(r["N"]) for r in seq])
    return n, np.array([float(r["tau"]) for r in seq]) / float(seq[0]["tau"])


def plot_models(
    rows: Sequence[dict[str, Any]], fits: Sequence[dict[str, Any]], path: str | Path, *, model_bits: int = 64
) -> Path:
    """The measured deciphering time overlaid on each cost model, in one figure (``fits``: the
    rows of :func:`experiments.deciphering_time.fit` of ``rows``).

    Top: the first key's CPU time against the bit length, measured, the :func:`fit_lp_half` fits
    and the cost models. Bottom left: ``T_1 / T_first`` against the bit length, measured per
    breaker (markers) and predicted by the ``paper``, ``precomputation`` and ``generic`` models
    (lines). Bottom right: ``tau(N) / T_first`` of each breaker's largest size against N, ``T_first``
    being ``tau(1)`` of the same sequence (so every curve starts at 1), with the
    models' ``tau(N) / T_first`` at ``model_bits``. The ratios compare directly; the first key's
    models count operations and are drawn as shapes only.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    breakers = list(dict.fromkeys(r["breaker"] for r in rows))
    all_bits = sorted({int(f["bits"]) for f in fits})
    grid_bits = np.arange(min(all_bits), max(all_bits) + 1)
    n_max = max(int(r["N"]) for r in rows)
    n_line = np.unique(np.geomspace(1, n_max, 50).round())
    curves = model_curves(grid_bits, n_line, model_bits=model_bits)
    fig = plt.figure(figsize=(13, 11))
    grid = fig.add_gridspec(2, 2, height_ratios=(1.0, 1.1))
    _first_key_panel(fig.add_subplot(grid[0, :]), fits, curves, grid_bits)
    ax1, ax2 = fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[1, 1])
    for breaker in breakers:
        mine = sorted((f for f in fits if f["breaker"] == breaker), key=lambda f: f["bits"])
        ratio = np.array([f["ratio"] for f in mine])
        ax1.semilogy([f["bits"] for f in mine], np.where(ratio > 0, ratio, np.nan), "o", ms=5, label=f"measured: {breaker}")
        bits = max(f["bits"] for f in mine)
        n, ratio = sequence_ratio(rows, breaker, bits)
        if not n.size:
            continue
        ax2.loglog(n, ratio, "o-", ms=3, lw=1.2,
                   label=f"{breaker}, {bits} bits")  # fmt: skip
    for name, (color, ls) in _STYLES.items():
        if name not in curves:
            continue
        ax1.semilogy(grid_bits, curves[name]["ratio"], color=color, ls=ls, lw=1.6, label=f"model: {name}")
        ax2.loglog(n_line, curves[name]["tau"], color=color, ls=ls, lw=1.6, label=f"model: {name} ({model_bits} bits)")
    ax1.set_xlabel("bit length of $p$")
    ax1.set_ylabel("$T_1 / T_{first}$")
    ax1.set_title("each further key relative to the first: breakers (markers) and cost models (lines)", fontsize=9)
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=7, ncol=3, frameon=False, loc="upper center", bbox_to_anchor=(0.5, -0.14))
    ax2.set_xlabel("keys broken $N$")
    ax2.set_ylabel(r"$\tau(N) / T_{first}$")
    ax2.set_title(r"$\tau(N)$ of one dynamic-key sequence, in units of one key from scratch", fontsize=9)
    ax2.grid(True, which="major", alpha=0.3)
    ax2.legend(fontsize=7, ncol=3, frameon=False, loc="upper center", bbox_to_anchor=(0.5, -0.14))
    fig.tight_layout()
    path = Path(path)
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path
