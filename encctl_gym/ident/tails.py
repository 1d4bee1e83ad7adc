"""Heavy tails of the identification error: when its mean and variance exist, and what to report.

The error of Definition def:error is a ratio, and near the least-squares minimum ``N = n + m + 1``
its denominator (the smallest eigenvalue of ``G = D D^T``) is often near zero: the error then has
a power-law tail ``P(epsilon > x) ~ x^(-alpha)``, its ``k``-th moment exists only for
``k < alpha``, and a sample mean with a standard error is not an estimate of anything. This
module gives

* the **tail rule** (:func:`error_tail_exponent`, :func:`moment_exists`): ``alpha`` from
  ``n``, ``m``, ``N`` and the estimator, derived below;
* an **empirical check** (:func:`hill_tail_exponent`): the Hill estimator of ``alpha`` on a
  sample of errors;
* a **summary** that says so (:func:`summarize_errors`, :class:`ErrorSummary`): median and
  quantiles always, and the mean only with a flag when it does not exist or is unreliable.

The rule. Write ``d = n + m`` and ``T = N - 1`` columns. For inputs with a joint density (the
Gaussian attack of Theorem thm:sic, AR(1) Gaussian inputs, a policy with Gaussian exploration),
the regressor matrix ``D`` (``d x T``) of eq:data has a joint Gaussian-like density that is
bounded and positive near the rank-deficient matrices, like that of i.i.d. Gaussian columns.
For such a matrix the smallest eigenvalue ``l`` of ``G`` has density ``~ l^((T - d - 1) / 2)``
at zero (that of the real Wishart law, A. Edelman, "Eigenvalues and condition numbers of random
matrices", SIAM J. Matrix Anal. Appl. 9(4), 1988), so ``P(l < s) ~ s^((T - d + 1) / 2)``. Least
squares has ``E[epsilon | D] = (sigma_w2 / d) tr(G^{-1})`` (the first identity of the proof of
Theorem thm:sic) and ``tr(G^{-1}) ~ 1 / l``, hence

``alpha = (T - d + 1) / 2 = (N - n - m) / 2``  (least squares, forgetting):

``alpha = 1/2`` at ``N = n + m + 1`` (the density ``l^(-1/2)``), the mean exists from
``N = n + m + 3`` on and the variance from ``n + m + 5`` on. This matches the inverse Wishart:
``E[G^{-1}]`` is finite iff ``T > d + 1``, its variance iff ``T > d + 3``. Exponential
forgetting multiplies the columns by weights in ``[lambda^(T - 1), 1]``, which changes neither
the rank nor the rate, so its exponent is the same.

Two-stage least squares with ``q`` instruments (:class:`~encctl_gym.ident.instrumental.InstrumentalVariables`,
``q = (L + 1) m``) divides by the smallest singular value of the projection of the ``T x d``
regressors on the ``q``-dimensional instrument space, a ``q x d`` matrix with a density: its
smallest singular value ``s`` has ``P(s < r) ~ r^(q - d + 1)`` and the error ``~ 1 / s^2``, so

``alpha = (q - d + 1) / 2``  (IV, at every N):

moments of the estimate exist up to the degree of over-identification ``q - d``, the classical
result for 2SLS (T. W. Kinal, "The existence of moments of k-class estimators", Econometrica
48(1), 1980). With as many instruments as unknowns (``q = d``) the mean error never exists,
however large ``N``: the tail's weight falls quickly with ``N``, so it is rarely seen in a few
hundred runs, but a mean is not an estimate there.

The Bayesian estimator with a fixed prior of precision ``Lambda > 0`` has
``||P_i D||^2 <= tr Lambda_i^{-1}``: every moment exists (``alpha = inf``). With the
empirical-Bayes default the ridge weight is at least ``1e-6 mean(diag G)`` (the search range of
:data:`~encctl_gym.ident.bayes.EVIDENCE_GRID`), which bounds the error by a multiple of
``1 / tr G``; ``tr G`` is a sum of ``d T`` squares, so ``alpha >= d T / 2`` (returned).

The rule assumes inputs with a density; discrete inputs (random binary) can leave ``G``
singular with positive probability, and a deterministic feedback can confine the regressors to
a subspace. There only the empirical check applies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_positive, format_value
from ..errors import ParameterError
from .registry import make_estimator

__all__ = [
    "error_tail_exponent",
    "moment_exists",
    "HillEstimate",
    "hill_tail_exponent",
    "ErrorSummary",
    "summarize_errors",
    "MIN_HILL_SAMPLES",
]

#: Fewest finite samples for which :func:`hill_tail_exponent` is attempted.
MIN_HILL_SAMPLES = 40
#: Quantiles an :class:`ErrorSummary` reports.
QUANTILES = (0.1, 0.25, 0.5, 0.75, 0.9)
_Z95 = 1.959963984540054


def _sample(name: str, value: Any) -> np.ndarray:
    """A 1-d float sample (NaN allowed: runs without an estimate)."""
    try:
        x = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"{name} must be a numeric array, got {format_value(value)}") from None
    if x.ndim > 1:
        raise ParameterError(f"{name} must be 1-d, got shape {x.shape}")
    return x.ravel()


def _estimator_kind(estimator: Any, n: int, m: int) -> tuple[str, Any]:
    """``("ls" | "forgetting" | "iv" | "bayes-fixed" | "bayes-evidence", instruments)``."""
    if estimator is None:
        return "ls", None
    est = make_estimator(estimator)
    name = est.name
    if name in ("ls", "forgetting"):
        return name, None
    if name == "iv":
        return "iv", est.instruments(n, m)  # type: ignore[attr-defined]
    if name == "bayes":
        return ("bayes-evidence" if est.empirical else "bayes-fixed"), None  # type: ignore[attr-defined]
    raise ParameterError(f"no tail rule for the estimator {name!r}")  # pragma: no cover - every registry name is above


def error_tail_exponent(n: int, m: int, N: int, estimator: Any = None) -> float:
    """The tail exponent ``alpha`` of the identification error, ``P(epsilon > x) ~ x^(-alpha)``.

    Derived in the module docstring for inputs with a joint density (Theorem thm:sic's Gaussian
    attack among them): least squares (eq:estimate) and forgetting ``(N - n - m) / 2``; IV with
    ``q`` instruments ``(q - n - m + 1) / 2``; Bayes with a fixed prior ``inf``; empirical Bayes
    at least ``(n + m)(N - 1) / 2``. The ``k``-th moment of the error exists iff ``k < alpha``
    (:func:`moment_exists`).

    Parameters
    ----------
    n, m : int
        State and input dimensions (>= 1).
    N : int
        Sample size (states ``x_0 .. x_{N-1}``), at least the estimator's minimum.
    estimator : str, mapping or Estimator, optional
        Anything :func:`~encctl_gym.ident.registry.make_estimator` takes; ``None`` is least squares.

    Returns
    -------
    float
        ``alpha`` (``math.inf`` when every moment exists).

    Raises
    ------
    ParameterError
        ``N`` below the estimator's minimum, or a bad estimator.
    """
    n = check_int("n", n, minimum=1)
    m = check_int("m", m, minimum=1)
    kind, q = _estimator_kind(estimator, n, m)
    d = n + m
    if kind == "iv":
        lags = q // m - 1
        N = check_int("N", N, minimum=lags + q + 1)
        if q < d:
            raise ParameterError(f"instrumental variables with q={q} instruments for n + m = {d} unknowns has no estimate")
        return (q - d + 1) / 2.0
    if kind in ("bayes-fixed", "bayes-evidence"):
        N = check_int("N", N, minimum=1)
        return math.inf if kind == "bayes-fixed" or N == 1 else d * (N - 1) / 2.0
    N = check_int("N", N, minimum=d + 1)
    return (N - d) / 2.0


def moment_exists(order: float, n: int, m: int, N: int, estimator: Any = None) -> bool:
    """Whether ``E[epsilon^order]`` is finite: ``order < alpha`` of :func:`error_tail_exponent`.

    Parameters
    ----------
    order : float
        Moment order (> 0): 1 for the mean, 2 for the second moment (and the variance).
    n, m, N, estimator
        As in :func:`error_tail_exponent`.

    Returns
    -------
    bool
    """
    order = check_positive("order", order)
    return order < error_tail_exponent(n, m, N, estimator)


@dataclass(frozen=True)
class HillEstimate:
    """The Hill estimate of a tail exponent.

    Attributes
    ----------
    alpha : float
        ``k / sum_{i <= k} log(X_(i) / X_(k+1))`` over the ``k`` largest of the sample.
    low, high : float
        Its approximate 95 % interval, ``alpha (1 -+ 1.96 / sqrt(k))`` (asymptotic normality
        for an exact Pareto tail; the estimate is also biased where the tail is not yet a power law).
    k : int
        Order statistics used.
    samples : int
        Finite samples in the sample.
    """

    alpha: float
    low: float
    high: float
    k: int
    samples: int


def hill_tail_exponent(samples: Any, k: int | None = None) -> HillEstimate:
    """Hill's estimator of the tail exponent of a positive sample (B. M. Hill, "A simple general
    approach to inference about the tail of a distribution", Ann. Statist. 3(5), 1975).

    Parameters
    ----------
    samples : array_like
        Positive values; NaN entries are skipped.
    k : int, optional
        Order statistics to use (``1 <= k < samples``); default ``max(10, samples // 10)``
        (at most ``samples - 1``).

    Returns
    -------
    HillEstimate

    Raises
    ------
    ParameterError
        Fewer than two finite samples, a non-positive or infinite value, or ``k`` out of range.
    """
    x = _sample("samples", samples)
    x = x[~np.isnan(x)]
    if x.size < 2:
        raise ParameterError(f"a tail exponent needs at least 2 finite samples, got {x.size}")
    if not np.all(np.isfinite(x)) or np.any(x <= 0):
        raise ParameterError("a tail exponent needs positive finite samples")
    k = min(max(10, x.size // 10), x.size - 1) if k is None else check_int("k", k, minimum=1, maximum=x.size - 1)
    top = np.sort(x)[::-1][: k + 1]
    s = float(np.sum(np.log(top[:k] / top[k])))
    alpha = math.inf if s == 0.0 else k / s
    half = _Z95 / math.sqrt(k)
    return HillEstimate(alpha, alpha * max(0.0, 1.0 - half), alpha * (1.0 + half), k, int(x.size))


@dataclass(frozen=True)
class ErrorSummary:
    """What a sample of errors says: quantiles always, the mean with its status.

    Attributes
    ----------
    count : int
        Finite samples.
    mean, se : float
        Sample mean and its standard error (reported only through :meth:`mean_text`).
    quantiles : dict[float, float]
        The 10, 25, 50, 75 and 90 % quantiles.
    tail_exponent : float or None
        ``alpha`` of the tail rule, when one was given.
    hill : HillEstimate or None
        The empirical check (with at least :data:`MIN_HILL_SAMPLES` samples).
    status : str
        ``"exists"``, ``"does not exist"`` (``alpha <= 1``) or ``"unreliable"`` (infinite
        variance by the rule, or a Hill interval entirely below 2).
    """

    count: int
    mean: float
    se: float
    quantiles: dict[float, float]
    tail_exponent: float | None
    hill: HillEstimate | None
    status: str

    @property
    def median(self) -> float:
        return self.quantiles[0.5]

    @property
    def mean_ok(self) -> bool:
        """The mean exists and its standard error means something."""
        return self.status == "exists"

    @property
    def ci95(self) -> tuple[float, float]:
        """``mean -+ 1.96 se`` (only meaningful when :attr:`mean_ok`)."""
        return self.mean - _Z95 * self.se, self.mean + _Z95 * self.se

    def flag(self) -> str:
        """Why the mean is not reported bare (empty when it is fine)."""
        if self.status == "does not exist":
            return f"mean does not exist: tail exponent a = {self.tail_exponent:.3g} <= 1"
        if self.status != "unreliable":
            return ""
        if self.tail_exponent is not None and self.tail_exponent <= 2.0:
            return f"mean unreliable: tail exponent a = {self.tail_exponent:.3g} <= 2 (infinite variance)"
        assert self.hill is not None
        return f"mean unreliable: fitted tail exponent a = {self.hill.alpha:.2g} [{self.hill.low:.2g}, {self.hill.high:.2g}]"

    def mean_text(self, digits: int = 3) -> str:
        """``"m ± se"`` when the mean is fine, else the flag (with the sample mean for the record)."""
        if self.mean_ok:
            return f"{self.mean:.{digits}g} ± {self.se:.1g}"
        return f"{self.flag()} (sample mean {self.mean:.{digits}g})"

    def quantile_text(self, digits: int = 3) -> str:
        """``"median m [q10, q90]"``."""
        q = self.quantiles
        return f"median {q[0.5]:.{digits}g} [{q[0.1]:.{digits}g}, {q[0.9]:.{digits}g}]"


def summarize_errors(errors: Any, *, tail_exponent: float | None = None) -> ErrorSummary:
    """Summarize a sample of errors without trusting a mean that need not exist.

    The mean is flagged ``"does not exist"`` when the rule's ``alpha <= 1`` and ``"unreliable"``
    when ``alpha <= 2`` (infinite variance: the standard error means nothing) or, whatever the
    rule, when the Hill interval of the sample lies entirely below 2 (a heavy tail the rule
    did not predict, e.g. for discrete inputs).

    Parameters
    ----------
    errors : array_like
        Errors (NaN entries, runs without an estimate, are skipped).
    tail_exponent : float, optional
        ``alpha`` from :func:`error_tail_exponent` (``None``: only the empirical check).

    Returns
    -------
    ErrorSummary

    Raises
    ------
    ParameterError
        No finite error, or a negative or infinite one.
    """
    raw = _sample("errors", errors)
    x = as_finite_array("errors", raw[~np.isnan(raw)])
    if x.size == 0:
        raise ParameterError("no error to summarize")
    if np.any(x < 0):
        raise ParameterError("errors must be >= 0")
    t = None if tail_exponent is None else _sample("tail_exponent", tail_exponent)
    if t is not None and t.size != 1:
        raise ParameterError(f"tail_exponent must be one number, got {format_value(tail_exponent)}")
    alpha = None if t is None else float(t[0])
    if alpha is not None and not alpha > 0:
        raise ParameterError(f"tail_exponent must be > 0, got {tail_exponent!r}")
    mean = float(x.mean())
    se = float(x.std(ddof=1) / math.sqrt(x.size)) if x.size > 1 else math.nan
    qs = {p: float(v) for p, v in zip(QUANTILES, np.quantile(x, QUANTILES))}
    hill = hill_tail_exponent(x) if x.size >= MIN_HILL_SAMPLES and np.all(x > 0) else None
    if alpha is not None and alpha <= 1.0:
        status = "does not exist"
    elif (alpha is not None and alpha <= 2.0) or (hill is not None and hill.high < 2.0):
        status = "unreliable"
    else:
        status = "exists"
    return ErrorSummary(int(x.size), mean, se, qs, alpha, hill, status)
