"""Ordinary least squares (eq:estimate) as an :class:`~encctl_gym.ident.estimator.Estimator`.

The paper's estimator, ``[A_hat B_hat] = X_f [X_p; U_p]^+``, behind the protocol: batch and
grid estimates are those of :mod:`encctl_gym.ident.least_squares` (the same numbers as
:func:`~encctl_gym.ident.least_squares.least_squares` and
:func:`~encctl_gym.ident.least_squares.prefix_estimates`), and the online estimate of each copy
is that of :class:`~encctl_gym.ident.least_squares.RecursiveLeastSquares` fed the same columns,
bit for bit (same buffer, same fold, same Jacobi-scaled Cholesky solve). It provides kernels
(:meth:`OrdinaryLeastSquares.online_kernels`): the compiled recursion the environment runs.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from ..errors import ParameterError
from .compiled import RecursiveLeastSquaresKernels
from .estimator import MomentEstimator
from .least_squares import _solve_normal_equations, least_squares, prefix_estimates

__all__ = ["OrdinaryLeastSquares", "gram_solve"]


def gram_solve(M: np.ndarray, n: int, m: int) -> np.ndarray:
    """Least squares from moments ``M = sum_j w_j v_j v_j^T``, ``v_j = [z_j; y_j]``: ``(..., n, n + m)``.

    Solves ``G theta^T = C`` (``G = M[:d, :d]``, ``C = M[:d, d:]``, ``d = n + m``) by
    :func:`~encctl_gym.ident.least_squares.solve_normal_equations`; where ``G`` is (numerically)
    singular, the minimum-norm solution ``pinv(G) C``, which is eq:estimate's pseudo-inverse
    ``X_f D^+`` for the (weighted) data.
    """
    d = n + m
    G, C = M[..., :d, :d], M[..., :d, d:]
    theta, ok = _solve_normal_equations(G, C)
    if not np.all(ok):
        bad = ~ok
        theta[bad] = np.swapaxes(np.linalg.pinv(G[bad], hermitian=True) @ C[bad], -1, -2)
    return theta


class OrdinaryLeastSquares(MomentEstimator):
    """Ordinary least squares, eq:estimate (registry name ``"ls"``, the default).

    Parameters
    ----------
    method : {"auto", "gram", "qr"}
        Solver of the grid estimates (:func:`~encctl_gym.ident.least_squares.prefix_estimates`).

    Notes
    -----
    Costs: :meth:`fit` one batched pseudo-inverse; :meth:`prefix_estimates` one pass over the
    data plus one batched ``d x d`` solve per (run, N); online, ``O(K (2n + m)^2)`` per update
    and one Cholesky solve per copy per estimate (``O(K d^3)``, ``d = n + m``).
    """

    name = "ls"

    def __init__(self, method: Literal["auto", "gram", "qr"] = "auto") -> None:
        super().__init__()
        if method not in ("auto", "gram", "qr"):
            raise ParameterError(f"method must be 'auto', 'gram' or 'qr', got {method!r}")
        self.method = method

    @property
    def params(self) -> dict[str, Any]:
        return {} if self.method == "auto" else {"method": self.method}

    def min_sample_size(self, n: int, m: int) -> int:
        """``n + m + 1``: eq:estimate needs ``n + m`` regression columns."""
        return n + m + 1

    def fit(self, x: Any, u: Any) -> np.ndarray:
        """eq:estimate on whole trajectories (:func:`~encctl_gym.ident.least_squares.least_squares`)."""
        A_hat, B_hat = least_squares(x, u)
        return np.concatenate([A_hat, B_hat], axis=-1)

    def prefix_estimates(self, x: Any, u: Any, sample_sizes: Any) -> np.ndarray:
        """eq:estimate on every prefix (:func:`~encctl_gym.ident.least_squares.prefix_estimates`)."""
        return prefix_estimates(x, u, sample_sizes, method=self.method)

    def solve(self, M: np.ndarray, columns: int, n: int, m: int) -> np.ndarray:
        """Online: the normal equations of eq:estimate (see :func:`gram_solve`)."""
        return gram_solve(M, n, m)

    def online_kernels(
        self, K: int, A: np.ndarray, B: np.ndarray, Q: np.ndarray, refresh: int, cond_limit: float
    ) -> RecursiveLeastSquaresKernels:
        """The compiled online form the attack episode runs
        (:class:`~encctl_gym.ident.compiled.RecursiveLeastSquaresKernels`: recursive least squares,
        re-anchored to the exact solve of eq:estimate)."""
        return RecursiveLeastSquaresKernels(K, A, B, Q, refresh, cond_limit)
