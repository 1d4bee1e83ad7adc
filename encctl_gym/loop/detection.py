"""The plant side's checks of what comes back from the controller server: audits and a detector.

Both run where the secret key is, on the plant side of Figure fig:ecs, on batches of ``K`` loops
in lockstep (the vector environment's copies), each with its own random stream:

* :class:`Audit` -- with probability ``p`` per step the plant side recomputes ``Phi x`` itself
  (it encrypted ``Phi``, so it knows it) and compares it with the input it decrypted; a difference
  beyond the encoder's error bound is an alarm. A step whose input is the controller's own
  (nothing injected) never alarms.
* :class:`ChiSquaredDetector` -- no local controller computation: the closed-loop innovation
  ``r[t] = x[t+1] - (A + B Phi) x[t]`` is ``N(0, Sigma)`` without an attack, so the window sum
  ``S[t] = sum_{k=t-W+1}^{t} r_k^T Sigma^-1 r_k`` is chi-squared with ``n W`` degrees of freedom
  and the threshold of :func:`encctl_gym.security.defenses.chi2_threshold` gives the false-alarm
  rate per step. Whatever the attacker injects instead of ``Phi x`` enters ``r`` as
  ``B (a - Phi x)``.
* :class:`CusumDetector` -- Page's CUSUM on the same statistic ``s = r^T Sigma^-1 r``: the
  log-likelihood ratio ``z = (1 - 1/c) s / 2 - n ln(c) / 2`` of an innovation covariance ``c Sigma``
  against ``Sigma``, accumulated as ``g = max(0, g + z)``; an alarm at ``g > h`` with ``h`` from
  :func:`encctl_gym.security.defenses.cusum_threshold` for a false-alarm rate per step (after an
  alarm the loop starts again from 0, so the rate is the inverse of the average run length).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_nonnegative, check_probability
from ..errors import ParameterError, ShapeError
from ..security.defenses import chi2_threshold, cusum_threshold

__all__ = ["Audit", "ChiSquaredDetector", "CusumDetector", "check_audit_rate"]


def check_audit_rate(rate: Any, name: str = "audit_rate") -> float:
    """``rate`` as an audit probability in [0, 1] (:func:`~encctl_gym._validation.check_probability`)."""
    return check_probability(name, rate)


class Audit:
    """Random audits of the decrypted input against the plant side's own ``Phi x``.

    Parameters
    ----------
    Phi : array_like, shape (m, n)
        The controller gain the plant side encrypted.
    rate : float
        Audit probability per step and loop, in [0, 1].
    rngs : sequence of numpy.random.Generator
        The plant side's own streams, one per loop: loop ``k`` is audited when
        ``rngs[k].random() < rate``.
    tolerance : float
        The largest difference the encoding can explain (the encoder's error bound), unless
        :meth:`check` is given one per loop and input.
    """

    def __init__(self, Phi: Any, rate: float, rngs: Sequence[np.random.Generator], tolerance: float = 0.0) -> None:
        self.Phi = as_finite_array("Phi", Phi, ndim=2)
        self.rate = check_audit_rate(rate)
        self.tolerance = check_nonnegative("tolerance", tolerance)
        self._rngs = rngs
        self.audits = 0

    def check(self, x: Any, u_decrypted: Any, tolerance: Any = None) -> np.ndarray:
        """One step of ``K`` loops: which are audited and caught, shape (K,) of bool. A loop is
        caught when an entry of ``u - Phi x`` exceeds the tolerance (``tolerance``: a float or an
        array broadcasting to (K, m); default the constructor's)."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        u = np.atleast_2d(np.asarray(u_decrypted, dtype=float))
        if x.shape[1] != self.Phi.shape[1] or u.shape != (x.shape[0], self.Phi.shape[0]):
            raise ShapeError(
                f"x and u must have shapes (K, {self.Phi.shape[1]}) and (K, {self.Phi.shape[0]}), got {x.shape} and {u.shape}"
            )
        K = x.shape[0]
        if len(self._rngs) < K:
            raise ShapeError(f"the audit has {len(self._rngs)} random streams for {K} loops")
        audited = np.array([rng.random() < self.rate for rng in self._rngs[:K]], dtype=bool)
        self.audits += int(audited.sum())
        if not audited.any():
            return audited
        tol = self.tolerance if tolerance is None else tolerance
        return audited & np.any(np.abs(u - x @ self.Phi.T) > tol, axis=1)


class _InnovationTest:
    """What both tests on the closed-loop innovation share: ``A_cl``, the whitening of ``Sigma``
    and the per-step statistic ``s = r^T Sigma^-1 r`` of ``K`` loops."""

    def __init__(self, A_cl: Any, noise_covariance: Any, num_loops: int) -> None:
        self.A_cl = as_finite_array("A_cl", A_cl, ndim=2)
        n = self.A_cl.shape[0]
        S = as_finite_array("noise_covariance", noise_covariance, ndim=2)
        if self.A_cl.shape != (n, n) or S.shape != (n, n):
            raise ShapeError(f"A_cl and noise_covariance must be square of the same size, got {self.A_cl.shape} and {S.shape}")
        try:
            L = np.linalg.cholesky(0.5 * (S + S.T))
        except np.linalg.LinAlgError:
            raise ParameterError("noise_covariance must be positive definite") from None
        self._whiten = np.linalg.inv(L)  # r^T Sigma^-1 r = ||L^-1 r||^2
        self.n = n
        self.K = check_int("num_loops", num_loops, minimum=1)

    def _statistic(self, x: Any, x_next: Any) -> np.ndarray:
        x = np.atleast_2d(np.asarray(x, dtype=float))
        x_next = np.atleast_2d(np.asarray(x_next, dtype=float))
        r = x_next - x @ self.A_cl.T
        return np.sum((r @ self._whiten.T) ** 2, axis=1)


class ChiSquaredDetector(_InnovationTest):
    """The window chi-squared test on the closed-loop innovation (module docstring).

    Parameters
    ----------
    A_cl : array_like, shape (n, n)
        ``A + B Phi``.
    noise_covariance : array_like, shape (n, n)
        ``Sigma`` of the innovation without an attack (``sigma_w2 I``, plus ``sigma_d2 B B^T`` with
        the defender's input noise); positive definite.
    window : int
        ``W``, the number of innovations summed.
    false_alarm_rate : float
        The target probability of an alarm at a step without an attack.
    num_loops : int
        ``K``, the loops checked in lockstep.
    """

    def __init__(self, A_cl: Any, noise_covariance: Any, *, window: int, false_alarm_rate: float, num_loops: int = 1) -> None:
        super().__init__(A_cl, noise_covariance, num_loops)
        self.window = check_int("window", window, minimum=1, maximum=10**6)
        self.threshold = chi2_threshold(self.n, self.window, false_alarm_rate)
        self.false_alarm_rate = float(false_alarm_rate)
        self.reset()

    def reset(self) -> None:
        """Forget the window (a new episode)."""
        self._buffer = np.zeros((self.K, self.window))
        self._filled = 0
        self._pos = 0
        self.statistic = np.zeros(self.K)

    def update(self, x: Any, x_next: Any) -> np.ndarray:
        """Add the innovation of one step of ``K`` loops; returns the alarms, shape (K,) of bool
        (none until the window is full)."""
        s = self._statistic(x, x_next)
        self._buffer[:, self._pos] = s
        self._pos = (self._pos + 1) % self.window
        self._filled = min(self._filled + 1, self.window)
        self.statistic = self._buffer.sum(axis=1)
        if self._filled < self.window:
            return np.zeros(self.K, dtype=bool)
        return self.statistic > self.threshold


class CusumDetector(_InnovationTest):
    """Page's CUSUM on the closed-loop innovation (module docstring).

    Parameters
    ----------
    A_cl, noise_covariance, num_loops
        As for :class:`ChiSquaredDetector`.
    false_alarm_rate : float
        The target alarm rate per step without an attack (the average run length to a false
        alarm is its inverse; :func:`~encctl_gym.security.defenses.cusum_threshold`).
    variance_ratio : float, default 2.0
        ``c > 1``: the inflation of the innovation covariance the test is tuned for.
    """

    def __init__(
        self, A_cl: Any, noise_covariance: Any, *, false_alarm_rate: float, variance_ratio: float = 2.0, num_loops: int = 1
    ) -> None:
        super().__init__(A_cl, noise_covariance, num_loops)
        self.threshold = cusum_threshold(self.n, variance_ratio, false_alarm_rate)
        self.false_alarm_rate = float(false_alarm_rate)
        self.variance_ratio = float(variance_ratio)
        c = self.variance_ratio
        self._a, self._b = 0.5 * (1.0 - 1.0 / c), 0.5 * self.n * np.log(c)
        self.reset()

    def reset(self) -> None:
        """Back to ``g = 0`` (a new episode)."""
        self.statistic = np.zeros(self.K)

    def update(self, x: Any, x_next: Any) -> np.ndarray:
        """Add the innovation of one step of ``K`` loops; returns the alarms, shape (K,) of bool.
        A loop that alarms starts again from ``g = 0``."""
        z = self._a * self._statistic(x, x_next) - self._b
        self.statistic = np.maximum(0.0, self.statistic + z)
        alarms = self.statistic > self.threshold
        self.statistic[alarms] = 0.0
        return alarms
