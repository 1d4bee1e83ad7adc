"""The margin an evaluation can resolve: a ratio's 95 % interval and the episodes it would need.

An evaluation reports ratios: an attacker's error over the oracle's (the optimal design,
:class:`agents.optimal.OptimalDesignAttacker`) or over the Gaussian attack's on the same
episodes, and ``E[epsilon] / gamma_opt(N)`` (Definition def:error against the A-optimal design
of :mod:`encctl_gym.security.attack_design`). Each is a *margin* ``ratio - 1`` (``+4 %``) with an
interval whose half-width shrinks like ``1 / sqrt(E)`` in the number of episodes ``E``. The
margin is *resolved* when the interval excludes 1 (its half-width is smaller than the margin);
otherwise the evaluation cannot tell the two attackers apart, and ``E (h / |margin|)^2``
episodes would be needed (the same spread, ``h`` the half-width at ``E``).

Three statistics, one :class:`Resolution` each:

* :func:`paired_resolution`: the ratio of geometric means over paired episodes (the same
  environment seeds), ``exp(mean(log x_e - log y_e))``, with a t interval on the log ratios.
  The log of a least-squares error has every moment even where the error's mean does not
  exist, so this interval is always meaningful.
* :func:`median_resolution`: the median of the per-episode ratios ``x_e / y_e`` with a
  percentile bootstrap interval (a check of the first that assumes nothing about the tails).
* :func:`reference_resolution`: ``mean(x) / c`` against a number such as ``gamma_opt(N)``,
  with a t interval, when the mean exists and has a variance (the tail rule of
  :func:`encctl_gym.ident.tails.summarize_errors`); otherwise the median of ``x / c`` with a
  bootstrap interval, and the statistic says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from encctl_gym._validation import check_int
from encctl_gym.errors import ParameterError

__all__ = ["LEVEL", "Resolution", "paired_resolution", "median_resolution", "reference_resolution", "resolution_line"]

#: Confidence level of every interval here.
LEVEL = 0.95


@dataclass(frozen=True)
class Resolution:
    """A ratio, its interval, and what the episodes behind it can resolve.

    Attributes
    ----------
    statistic : str
        How the ratio was computed (``"geometric mean (paired, t)"``, ``"median (paired,
        bootstrap)"``, ``"mean (t)"``, ``"median (bootstrap)"``).
    estimate, low, high : float
        The ratio and its 95 % interval.
    episodes : int
    """

    statistic: str
    estimate: float
    low: float
    high: float
    episodes: int

    @property
    def margin(self) -> float:
        """``estimate - 1``: how far the ratio is from parity (``+0.04`` is 4 % worse)."""
        return self.estimate - 1.0

    @property
    def half_width(self) -> float:
        """The interval's larger relative half-width, ``max(high / estimate - 1, 1 - low / estimate)``."""
        if not self.estimate > 0 or not math.isfinite(self.high) or not math.isfinite(self.low):
            return math.inf
        return max(self.high / self.estimate - 1.0, 1.0 - self.low / self.estimate)

    @property
    def resolved(self) -> bool:
        """The interval excludes 1: the sign of the margin is established."""
        return self.low > 1.0 or self.high < 1.0

    def episodes_for(self, margin: float) -> float:
        """Episodes whose interval would have half-width ``|margin|`` (``1 / sqrt(E)`` scaling;
        ``inf`` for a zero margin or an interval of unknown width)."""
        margin = abs(float(margin))
        h = self.half_width
        if margin == 0.0 or not math.isfinite(h):
            return math.inf
        return float(math.ceil(self.episodes * (h / margin) ** 2))

    @property
    def episodes_needed(self) -> float:
        """Episodes that would resolve the margin reported (:meth:`episodes_for` of it)."""
        return self.episodes_for(self.margin)


def _t(episodes: int) -> float:
    from scipy.stats import t as student_t

    return float(student_t.ppf(0.5 + LEVEL / 2, episodes - 1))


def _positive_sample(name: str, x: Any) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if a.ndim != 1 or a.size < 2:
        raise ParameterError(f"{name} must be a 1-d sample of at least 2 errors, got shape {a.shape}")
    if not (np.all(np.isfinite(a)) and np.all(a > 0)):
        raise ParameterError(f"{name} must hold positive finite errors")
    return a


def _paired(x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
    a, b = _positive_sample("x", x), _positive_sample("y", y)
    if a.shape != b.shape:
        raise ParameterError(f"paired errors need samples of one size, got {a.size} and {b.size}")
    return a, b


def paired_resolution(x: Any, y: Any) -> Resolution:
    """Ratio of geometric means of paired errors ``x_e / y_e`` with its t interval (module docstring).

    Parameters
    ----------
    x, y : array_like (E,)
        Positive final errors of two attackers, episode ``e`` of both on the same seed (E >= 2).
    """
    a, b = _paired(x, y)
    d = np.log(a) - np.log(b)
    m = float(d.mean())
    h = _t(d.size) * float(d.std(ddof=1)) / math.sqrt(d.size)
    return Resolution("geometric mean (paired, t)", math.exp(m), math.exp(m - h), math.exp(m + h), int(d.size))


def _bootstrap_median(r: np.ndarray, bootstrap: int, seed: int) -> tuple[float, float]:
    B = check_int("bootstrap", bootstrap, minimum=100, maximum=10**6)
    rng = np.random.default_rng(seed)
    meds = np.empty(B)
    for i in range(0, B, 256):  # chunks bound the memory at 256 resamples
        k = min(256, B - i)
        meds[i : i + k] = np.median(r[rng.integers(0, r.size, size=(k, r.size))], axis=1)
    lo, hi = np.quantile(meds, [0.5 - LEVEL / 2, 0.5 + LEVEL / 2])
    return float(lo), float(hi)


def median_resolution(x: Any, y: Any, *, bootstrap: int = 2000, seed: int = 0) -> Resolution:
    """Median of the per-episode ratios ``x_e / y_e`` with a percentile bootstrap interval.

    Parameters
    ----------
    x, y : array_like (E,)
        Paired positive errors (E >= 2).
    bootstrap : int
        Resamples of the episodes (>= 100).
    seed : int
        Seed of the resampling.
    """
    a, b = _paired(x, y)
    r = a / b
    lo, hi = _bootstrap_median(r, bootstrap, seed)
    return Resolution("median (paired, bootstrap)", float(np.median(r)), lo, hi, int(r.size))


def reference_resolution(
    x: Any, reference: float, *, tail_exponent: float | None = None, bootstrap: int = 2000, seed: int = 0
) -> Resolution:
    """``mean(x) / reference`` with its t interval, or the median where the mean is not reliable.

    Parameters
    ----------
    x : array_like (E,)
        Positive errors (E >= 2).
    reference : float
        A positive number, e.g. ``gamma_opt(N)``.
    tail_exponent : float, optional
        The tail rule of the errors (:func:`encctl_gym.ident.tails.error_tail_exponent`); the
        mean is used only if :func:`~encctl_gym.ident.tails.summarize_errors` says it exists.
    bootstrap, seed : int
        Of the median's bootstrap interval.
    """
    from encctl_gym.ident.tails import summarize_errors

    a = _positive_sample("x", x)
    c = float(reference)
    if not (math.isfinite(c) and c > 0):
        raise ParameterError(f"reference must be positive and finite, got {reference!r}")
    if summarize_errors(a, tail_exponent=tail_exponent).mean_ok:
        mean = float(a.mean())
        h = _t(a.size) * float(a.std(ddof=1)) / math.sqrt(a.size)
        return Resolution("mean (t)", mean / c, (mean - h) / c, (mean + h) / c, int(a.size))
    lo, hi = _bootstrap_median(a / c, bootstrap, seed)
    return Resolution("median (bootstrap)", float(np.median(a)) / c, lo, hi, int(a.size))


def resolution_line(what: str, res: Resolution, *, target: float | None = None) -> str:
    """One line: the ratio with its interval, what the episodes resolve, and, when the margin is
    not resolved, a warning with the episodes that would resolve it (and those for ``target``).

    Example: ``ars / oracle: 1.040 [0.921, 1.174] (geometric mean (paired, t)); 100 episodes
    resolve +-13 %: warning: the +4.0 % margin is not resolved; ~1060 episodes needed``.
    """
    head = f"{what}: {res.estimate:.3f} [{res.low:.3f}, {res.high:.3f}] ({res.statistic}); "
    h = res.half_width
    text = head + f"{res.episodes} episodes resolve +-{100 * h:.1f} %"
    if res.resolved:
        text += f": the {100 * res.margin:+.1f} % margin is resolved"
    else:
        need = res.episodes_needed
        text += f": warning: the {100 * res.margin:+.1f} % margin is not resolved; " + (
            f"~{int(need)} episodes needed" if math.isfinite(need) else "no number of episodes resolves a zero margin"
        )
    if target is not None and h > target:
        text += f" (~{int(res.episodes_for(target))} for +-{100 * target:g} %)"
    return text
