"""Statistics of the comparison: means with standard errors, paired ratios with confidence
intervals, the 1/N rate fit and the sample size that reaches ``gamma_c``.

Every attacker plays the same environment seeds (episode ``e`` is seeded with ``seed + e``), so
two attackers are compared *paired*: the log ratio of their final errors episode by episode,
whose mean and standard error give the ratio of geometric means and its 95 % interval
(:func:`paired_ratio`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from encctl_gym.errors import ParameterError
from encctl_gym.security.design import sample_size_for_rate

__all__ = ["Z95", "wilson_interval", "mean_se", "PairedRatio", "paired_ratio", "fit_rate", "samples_to_reach"]

#: z value of a two-sided 95 % normal interval.
Z95 = 1.959963984540054


def wilson_interval(successes: int, trials: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a binomial proportion ``successes / trials`` (95 % by default),
    inside [0, 1] for any count; ``(0, 1)`` for no trials."""
    if trials == 0:
        return (0.0, 1.0)
    ph = successes / trials
    den = 1 + z * z / trials
    mid = (ph + z * z / (2 * trials)) / den
    half = z * math.sqrt(ph * (1 - ph) / trials + z * z / (4 * trials * trials)) / den
    return (float(max(0.0, mid - half)), float(min(1.0, mid + half)))


def mean_se(eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean over episodes (axis 0) and its standard error (``nan`` for a single episode)."""
    eps = np.asarray(eps, dtype=float)
    mean = eps.mean(axis=0)
    se = eps.std(axis=0, ddof=1) / math.sqrt(eps.shape[0]) if eps.shape[0] > 1 else np.full(np.shape(mean), np.nan)
    return mean, se


@dataclass(frozen=True)
class PairedRatio:
    """``exp(mean(log x - log y))`` over paired episodes, with its 95 % interval.

    Attributes
    ----------
    mean_log, se_log : float
        Mean and standard error of the per-episode log ratio.
    ratio, low, high : float
        ``exp(mean_log)`` and ``exp(mean_log -+ Z95 se_log)``.
    episodes : int
    """

    mean_log: float
    se_log: float
    ratio: float
    low: float
    high: float
    episodes: int

    @property
    def significant_below(self) -> bool:
        """The interval lies below 1 (x has the smaller error)."""
        return self.high < 1.0

    @property
    def significant_above(self) -> bool:
        """The interval lies above 1 (x has the larger error)."""
        return self.low > 1.0


def paired_ratio(x: np.ndarray, y: np.ndarray) -> PairedRatio:
    """The paired ratio of two attackers' final errors on the same episodes.

    Parameters
    ----------
    x, y : array_like (E,)
        Positive final errors, episode ``e`` of both on the same seed.

    Raises
    ------
    ParameterError
        Shapes differ, or an error is not positive and finite.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if x.shape != y.shape or x.ndim != 1 or x.size == 0:
        raise ParameterError(f"paired errors need two equal 1-d samples, got shapes {x.shape} and {y.shape}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y)) and np.all(x > 0) and np.all(y > 0)):
        raise ParameterError("paired errors must be positive and finite")
    d = np.log(x) - np.log(y)
    m = float(d.mean())
    se = float(d.std(ddof=1) / math.sqrt(d.size)) if d.size > 1 else float("nan")
    return PairedRatio(m, se, math.exp(m), math.exp(m - Z95 * se), math.exp(m + Z95 * se), int(d.size))


def fit_rate(N: np.ndarray, mean: np.ndarray) -> float:
    """Least-squares ``c`` of ``mean ~ c / (N - 1)`` on the upper half of the grid (log N).

    Parameters
    ----------
    N, mean : array_like
        Grid of sample sizes (increasing) and the mean error there.

    Returns
    -------
    float
        ``c`` (``(N - 1) E[epsilon(N)]`` in the 1/N regime of eq:sic2 and gamma_opt), weighted so
        every point counts by its relative error.
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
    else extrapolated from :func:`fit_rate` (``floor(c / gamma_c) + 2``,
    :func:`encctl_gym.security.design.sample_size_for_rate`).

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
