"""Instrumental variables for ``[A B]`` with lagged inputs as instruments.

Regression column ``j`` of eq:data is ``x_{j+1} = [A B] z_j + w_j`` with ``z_j = [x_j; u_j]``.
The instruments ``zeta_j = [u_j; u_{j-1}; ...; u_{j-L}]`` (``q = (L + 1) m`` of them) are
uncorrelated with ``w_j`` (the attacker chose them before ``w_j`` happened) and correlated with
``z_j`` (``x_j`` responds to ``u_{j-1}, u_{j-2}, ...`` through ``B, AB, ...``). The estimate is
two-stage least squares (Söderström and Stoica, *System Identification*, 1989, Chapter 8):

``theta_hat^T = (R^T W R)^{-1} R^T W S``,  ``R = sum_j zeta_j z_j^T``, ``S = sum_j zeta_j x_{j+1}^T``,
``W = (sum_j zeta_j zeta_j^T)^{-1}``,

which is the plain IV estimate ``R^{-1} S`` when ``q = n + m``. It stays consistent when the
noise is coloured or the regressors carry measurement error (for eq:system's white noise and
exactly deciphered states least squares is consistent and more efficient). Each instrument is
built from the attacker's own inputs, so the columns ``j < L`` (without ``L`` past inputs) are
not used.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._validation import check_int
from ..errors import ParameterError
from . import _moment_kernels as mk
from .compiled import MomentKernels
from .estimator import MomentEstimator

__all__ = ["InstrumentalVariables", "MAX_LAGS"]

_EPS = np.finfo(np.float64).eps

#: Largest ``lags``, so that a mistyped value is refused at once rather than sized: ``(L + 1) m``
#: instruments make ``p^2`` moments per copy (about 0.5 GiB at L = MAX_LAGS, m = 2).
MAX_LAGS = 4096


class InstrumentalVariables(MomentEstimator):
    """Two-stage least squares with lagged inputs as instruments (registry name ``"iv"``).

    Parameters
    ----------
    lags : int, optional
        ``1 <= L <= MAX_LAGS``: instruments ``u_j, u_{j-1}, ..., u_{j-L}``. Default ``ceil(n / m)``, the
        fewest that give at least ``n + m`` instruments.

    Notes
    -----
    Needs ``N >= L + (L + 1) m + 1`` samples (``(L + 1) m`` usable columns for the instrument
    Gram matrix). Where the instruments do not determine ``[A B]`` numerically (e.g. inputs
    that do not excite the states within ``L`` steps) the estimate is NaN.

    Costs: moments of ``q + 2 n + m`` features per column (``q = (L + 1) m``); per estimate and
    copy, one Cholesky of ``q x q`` and one QR of ``q x d``.

    Raises
    ------
    ParameterError
        For ``lags`` outside ``[1, MAX_LAGS]``, and (at :meth:`fit` / :meth:`start`) when ``(L + 1) m < n + m``:
        fewer instruments than unknowns per row, an under-determined problem.
    """

    name = "iv"

    def __init__(self, lags: int | None = None) -> None:
        super().__init__()
        self.lags = None if lags is None else check_int("lags", lags, minimum=1, maximum=MAX_LAGS)
        self._hist: np.ndarray | None = None

    @property
    def params(self) -> dict[str, Any]:
        return {} if self.lags is None else {"lags": self.lags}

    @property
    def label(self) -> str:
        return "iv" if self.lags is None else f"iv(lags={self.lags})"

    def lags_for(self, n: int, m: int) -> int:
        """``L`` for an (n, m) plant."""
        return self.lags if self.lags is not None else max(1, math.ceil(n / m))

    def instruments(self, n: int, m: int) -> int:
        """``q = (L + 1) m``."""
        return (self.lags_for(n, m) + 1) * m

    def check_dimensions(self, n: int, m: int) -> None:
        """Refuse an under-determined problem (fewer instruments than ``n + m``)."""
        L, q = self.lags_for(n, m), self.instruments(n, m)
        if q < n + m:
            raise ParameterError(
                f"instrumental variables with lags={L} give (lags + 1) m = {q} instruments for n + m = {n + m} "
                f"unknowns per row of [A B]: under-determined (use lags >= ceil(n / m) = {math.ceil(n / m)})"
            )

    def min_sample_size(self, n: int, m: int) -> int:
        """``L + q + 1``: ``q`` usable columns after the first ``L``."""
        return self.lags_for(n, m) + self.instruments(n, m) + 1

    def features(self, n: int, m: int) -> int:
        return self.instruments(n, m) + 2 * n + m

    def batch_rows(self, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Rows ``[zeta_j; z_j; x_{j+1}]``; zero for ``j < L`` (they count for nothing)."""
        runs, T, m = u.shape
        n = x.shape[-1]
        L = self.lags_for(n, m)
        V = np.zeros((runs, T, self.features(n, m)))
        if T > L:
            zeta = np.concatenate([u[:, L - k : T - k] for k in range(L + 1)], axis=-1)  # u_j, u_{j-1}, ...
            V[:, L:] = np.concatenate([zeta, x[:, L:-1], u[:, L:], x[:, L + 1 :]], axis=-1)
        return V

    def reset_history(self, K: int, n: int, m: int) -> None:
        self._hist = np.zeros((K, self.lags_for(n, m), m))  # newest first

    def online_row(self, z: np.ndarray, y: np.ndarray) -> np.ndarray | None:
        assert self._hist is not None
        n = y.shape[1]
        u = z[:, n:]
        row = None
        if self._count >= self._hist.shape[1]:
            zeta = np.concatenate([u, self._hist.reshape(u.shape[0], -1)], axis=1)
            row = np.concatenate([zeta, z, y], axis=1)
        self._hist[:, 1:] = self._hist[:, :-1]
        self._hist[:, 0] = u
        return row

    def solve(self, M: np.ndarray, columns: int, n: int, m: int) -> np.ndarray:
        """Two-stage least squares from the moments (see the module docstring); NaN where singular."""
        q, d = self.instruments(n, m), n + m
        lead = M.shape[:-2]
        Mf = M.reshape(-1, *M.shape[-2:])
        Zz, Zx, Zy = Mf[:, :q, :q], Mf[:, :q, q : q + d], Mf[:, :q, q + d :]
        out = np.full((Mf.shape[0], n, d), np.nan)
        for i in range(Mf.shape[0]):
            try:
                L = np.linalg.cholesky(Zz[i])
            except np.linalg.LinAlgError:
                continue
            W = np.linalg.solve(L, Zx[i])  # whitened first stage, q x d
            r = np.linalg.solve(L, Zy[i])
            Qw, Rw = np.linalg.qr(W)
            dg = np.abs(np.diag(Rw))
            if not dg.min() > 0 or (dg.min() / dg.max()) ** 2 < d * _EPS:
                continue
            out[i] = np.linalg.solve(Rw, Qw.T @ r).T
        return out.reshape(*lead, n, d)

    def online_kernels(
        self, K: int, A: np.ndarray, B: np.ndarray, Q: np.ndarray, refresh: int, cond_limit: float
    ) -> MomentKernels:
        """The compiled online form (:class:`~encctl_gym.ident.compiled.MomentKernels`): the rows
        ``[zeta_j; z_j; x_{j+1}]`` (from column ``L`` on) by a compiled stage, with :meth:`online_solve`."""
        n, m = A.shape[0], B.shape[1]
        self.check_dimensions(n, m)
        return MomentKernels(self, K, A, B, refresh, lags=self.lags_for(n, m))

    def online_solve(self, M: np.ndarray, columns: int, n: int, m: int) -> np.ndarray:
        """:meth:`solve` compiled (:func:`encctl_gym.ident._moment_kernels.iv_solve`; NaN where singular)."""
        theta = np.empty((M.shape[0], n, n + m))
        mk.iv_solve(M, n, m, self.instruments(n, m), theta)
        return theta
