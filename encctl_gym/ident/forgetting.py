"""Least squares with exponential forgetting: eq:estimate with weights ``lambda^(T - 1 - j)``.

After ``T`` regression columns the estimate minimises
``sum_j lambda^(T - 1 - j) ||x_{j+1} - [A B] z_j||^2`` (``z_j = [x_j; u_j]``, eq:data): recent
columns count fully, a column ``k`` steps old counts ``lambda^k``. It is the classical
recursive least squares for slowly varying plants (Ljung, *System Identification*, 2nd ed.,
Section 11.2); its memory is about ``1 / (1 - lambda)`` columns. The plant of eq:system does not
vary, so for this plant forgetting only discards information: with ``lambda < 1`` the error stops
falling once ``N`` exceeds the memory. ``lambda = 1`` is ordinary least squares.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import check_real, format_value
from ..errors import ParameterError
from . import _moment_kernels as mk
from .compiled import MomentKernels
from .estimator import MomentEstimator
from .ordinary import gram_solve

__all__ = ["ForgettingLeastSquares", "DEFAULT_FORGETTING_FACTOR"]

#: Memory of about 1000 columns.
DEFAULT_FORGETTING_FACTOR = 0.999


class ForgettingLeastSquares(MomentEstimator):
    """Exponentially weighted least squares (registry name ``"forgetting"``).

    Parameters
    ----------
    forgetting_factor : float in (0, 1], default 0.999
        ``lambda``: the weight of a column one step older.

    Notes
    -----
    Costs: as :class:`~encctl_gym.ident.ordinary.OrdinaryLeastSquares` (the weights are applied
    to the rows of each segment and to the moments between segments); the same Jacobi-scaled
    Cholesky solve, with the minimum-norm solution where the weighted Gram matrix is singular.
    """

    name = "forgetting"

    def __init__(self, forgetting_factor: float = DEFAULT_FORGETTING_FACTOR) -> None:
        super().__init__()
        lam = check_real("forgetting_factor", forgetting_factor)  # a finite real number: no str, no bool
        if not 0.0 < lam <= 1.0:
            raise ParameterError(f"forgetting_factor must lie in (0, 1], got {format_value(forgetting_factor)}")
        self.forgetting_factor = lam
        self.decay = lam

    @property
    def params(self) -> dict[str, Any]:
        return {"forgetting_factor": self.forgetting_factor}

    @property
    def label(self) -> str:
        return f"forgetting({self.forgetting_factor:g})"

    def min_sample_size(self, n: int, m: int) -> int:
        """``n + m + 1``, as eq:estimate."""
        return n + m + 1

    def solve(self, M: np.ndarray, columns: int, n: int, m: int) -> np.ndarray:
        """The weighted normal equations (see :func:`~encctl_gym.ident.ordinary.gram_solve`)."""
        return gram_solve(M, n, m)

    def online_kernels(
        self, K: int, A: np.ndarray, B: np.ndarray, Q: np.ndarray, refresh: int, cond_limit: float
    ) -> MomentKernels:
        """The compiled online form (:class:`~encctl_gym.ident.compiled.MomentKernels`) with
        :meth:`online_solve`."""
        return MomentKernels(self, K, A, B, refresh)

    def online_solve(self, M: np.ndarray, columns: int, n: int, m: int) -> np.ndarray:
        """:meth:`solve` compiled: the Jacobi-scaled Cholesky solve of every copy
        (:func:`encctl_gym.ident._moment_kernels.gram_solve`), and for the copies it refuses
        :func:`~encctl_gym.ident.ordinary.gram_solve`'s minimum-norm solve."""
        theta = np.empty((M.shape[0], n, n + m))
        ok = np.empty(M.shape[0], dtype=bool)
        mk.gram_solve(M, n, m, theta, ok)
        if not ok.all():
            theta[~ok] = gram_solve(M[~ok], n, m)
        return theta
