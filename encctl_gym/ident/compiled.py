"""Compiled online forms of estimators: what an estimator provides to run on the episode's fast path.

An estimator that provides kernels implements :class:`ProvidesKernels`:
``online_kernels(K, A, B, Q, refresh, cond_limit)`` returns an :class:`OnlineKernels` that keeps
``K`` copies' estimates up to date from the episode's data arrays with compiled code, and
scores them (Definition def:error) against the true plant. The episode uses it when the
estimator provides one and calls the estimator column by column
(:meth:`~encctl_gym.ident.estimator.Estimator.update`) otherwise: no estimator is special-cased
by its class. :class:`OnlineKernels` with ``fused = True`` keep their steady state as the
recursion ``Q = [P | Theta_hat^T]`` that the environment's fused step runs inline.

:class:`RecursiveLeastSquaresKernels` is ordinary least squares' (eq:estimate): recursive least
squares by Sherman-Morrison (:mod:`encctl_gym.ident._rls_kernels`), re-anchored to the exact
solve from the running Gram matrices every ``refresh`` columns and at the end.

:class:`MomentKernels` is the moment estimators' (:class:`~encctl_gym.ident.estimator.MomentEstimator`:
Bayesian least squares, forgetting, instrumental variables): the feature rows go into the
moments by a compiled stage (:func:`encctl_gym.ident._moment_kernels.add_rows`), one column at
a time as the estimator's own ``update`` and fold add them, and the estimate is the estimator's
compiled solve on those moments; it is not fused (every delivery settles).
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np

from ..errors import SolverError
from . import _moment_kernels as mk
from . import _rls_kernels as rk

__all__ = ["OnlineKernels", "ProvidesKernels", "RecursiveLeastSquaresKernels", "MomentKernels"]


@runtime_checkable
class OnlineKernels(Protocol):
    """K copies of an estimator's compiled online form, on the episode's arrays.

    Attributes
    ----------
    fused : bool
        Its steady state is the recursion in ``Q`` that the fused step runs.
    all_ready : bool
        Every copy is in the steady state.
    since_refresh : int
        Columns since the last exact re-anchoring.
    refresh : int
        Columns between exact re-anchorings.
    """

    fused: bool
    all_ready: bool
    since_refresh: int
    refresh: int

    def reset(self) -> None:
        """Forget all data (a new episode)."""
        ...

    def add_columns(self, dims: Any, X: np.ndarray, U: np.ndarray, first: int, target: int, GC: np.ndarray) -> None:
        """The regression columns ``first <= j < target`` into the Gram matrices ``GC`` and the estimates."""
        ...

    def steady_error(self, dims: Any, eps: np.ndarray) -> None:
        """The error of every copy's estimate into ``eps`` (steady state: all copies ready)."""
        ...

    def settle(self, dims: Any, G: np.ndarray, C: np.ndarray, columns: int, delivered: int, final: bool, eps: np.ndarray) -> None:
        """After ``columns`` new columns (``delivered`` samples in all): re-anchor where due (always
        when ``final``), and the error of every copy with an estimate into ``eps``."""
        ...


@runtime_checkable
class ProvidesKernels(Protocol):
    """An estimator with a compiled online form (see the module docstring)."""

    def online_kernels(
        self, K: int, A: np.ndarray, B: np.ndarray, Q: np.ndarray, refresh: int, cond_limit: float
    ) -> OnlineKernels:
        """The compiled online form for ``K`` copies of the plant ``(A, B)``, keeping its state in ``Q``."""
        ...


def _condition(Gs: np.ndarray) -> np.ndarray:
    """2-norm condition numbers of symmetric positive semidefinite matrices (..., d, d), from
    their eigenvalues (``inf`` where singular)."""
    lam = np.linalg.eigvalsh(Gs)
    lo, hi = lam[..., 0], lam[..., -1]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(lo > 0.0, hi / np.where(lo > 0.0, lo, 1.0), np.inf)


def _pinv_psd(G: np.ndarray) -> np.ndarray:
    """Moore-Penrose pseudo-inverses of symmetric positive semidefinite matrices (..., d, d),
    from their eigendecompositions; eigenvalues below ``d * eps * max`` count as zero (NumPy's
    default cut-off for ``pinv``)."""
    lam, V = np.linalg.eigh(G)
    keep = lam > G.shape[-1] * np.finfo(float).eps * lam[..., -1:]
    inv = np.where(keep, 1.0 / np.where(keep, lam, 1.0), 0.0)
    return (V * inv[..., None, :]) @ np.swapaxes(V, -1, -2)


class RecursiveLeastSquaresKernels:
    """Ordinary least squares (eq:estimate) online for K copies, compiled.

    Parameters
    ----------
    K : int
        Copies.
    A, B : numpy.ndarray
        The true plant (the error of Definition def:error is against it).
    Q : numpy.ndarray, shape (d (d + n), K)
        Where the recursion ``[P | Theta_hat^T]`` is kept (P by its upper triangle, copies innermost).
    refresh : int
        Every copy is re-anchored to the exact solve after this many columns.
    cond_limit : float
        A copy starts its recursion once the condition number of its Jacobi-scaled Gram matrix is below this.
    """

    fused = True

    def __init__(self, K: int, A: np.ndarray, B: np.ndarray, Q: np.ndarray, refresh: int, cond_limit: float) -> None:
        self.n, self.m = A.shape[0], B.shape[1]
        self.d = self.n + self.m
        self.K = K
        self.theta_true_T = np.ascontiguousarray(np.hstack([A, B]).T)
        self.c = float(self.n * self.d)  # Definition def:error
        self.Q = Q
        self.ready = np.zeros(K, dtype=bool)  # recursion started (well-conditioned Gram matrix)
        self.refresh = refresh
        self.cond_limit = cond_limit
        self.since_refresh = 0
        self.all_ready = False

    def reset(self) -> None:
        self.ready[:] = False
        self.all_ready = False
        self.since_refresh = 0

    def add_columns(self, dims: Any, X: np.ndarray, U: np.ndarray, first: int, target: int, GC: np.ndarray) -> None:
        rk.add_columns(dims, X, U, first, target, GC, self.Q, self.ready)

    def steady_error(self, dims: Any, eps: np.ndarray) -> None:
        rk.estimation_error(dims, self.Q, self.theta_true_T, self.c, self.ready, eps)

    def settle(self, dims: Any, G: np.ndarray, C: np.ndarray, columns: int, delivered: int, final: bool, eps: np.ndarray) -> None:
        if delivered - 1 < self.d:  # fewer than n + m columns: no estimate yet
            return
        self.since_refresh += columns
        if final or self.since_refresh >= self.refresh:  # exact solve: bounds drift; final = eq:estimate
            stale = np.ones(self.K, dtype=bool)
            self.since_refresh = 0
        else:
            stale = ~self.ready
        if stale.any():
            rows = np.nonzero(stale)[0]
            theta_hat_T = self._refresh(G, C, rows)
            eps[rows] = ((theta_hat_T - self.theta_true_T) ** 2).sum(axis=(1, 2)) / self.c
        rk.estimation_error(dims, self.Q, self.theta_true_T, self.c, self.ready & ~stale, eps)
        self.all_ready = bool(self.ready.all())

    def _refresh(self, G_all: np.ndarray, C_all: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Exact least squares (eq:estimate) for the copies ``rows`` from the running Gram matrices.

        A copy whose Jacobi-scaled Gram matrix is well conditioned (condition number below
        ``cond_limit``) solves ``G [P | Theta_hat^T] = [I | C]`` and (re)starts its recursion
        from the solution; any other copy gets the minimum-norm least-squares solution
        ``pinv(G) C`` of eq:estimate and stays non-recursive. A started recursion is re-anchored
        without a new check: G only grows, by positive semidefinite terms, so its smallest
        eigenvalue never falls. Called for copies that are not yet recursive, and for every copy
        each ``refresh`` columns to bound rounding drift. Returns Theta_hat^T of those copies,
        shape (len(rows), n + m, n).
        """
        d = self.d
        G, C = G_all[rows], C_all[rows]
        ok = self.ready[rows]  # a copy: the ones already recursive stay so
        if not ok.all():
            fresh = ~ok
            g = G[fresh]
            s = 1.0 / np.sqrt(np.maximum(np.einsum("kii->ki", g), 1e-300))
            ok[fresh] = _condition(g * s[:, :, None] * s[:, None, :]) < self.cond_limit
        sol = np.zeros((len(rows), d, d + self.n))
        if ok.any():
            g, c = G[ok], C[ok]
            s = 1.0 / np.sqrt(np.einsum("kii->ki", g))  # Jacobi scaling
            rhs = np.concatenate((np.broadcast_to(np.eye(d), g.shape) * s[:, :, None], c * s[:, :, None]), axis=2)
            try:
                sol[ok] = np.linalg.solve(g * s[:, :, None] * s[:, None, :], rhs) * s[:, :, None]
            except np.linalg.LinAlgError:  # cannot happen to a well-conditioned matrix; never crash on it
                ok[:] = False
        if not ok.all():
            bad = ~ok
            sol[bad, :, d:] = _pinv_psd(G[bad]) @ C[bad]
        self.Q[:, rows[ok]] = sol[ok].reshape(-1, d * (d + self.n)).T
        self.ready[rows] = ok
        return sol[:, :, d:]


class MomentKernels:
    """A moment estimator online for K copies, compiled (not fused: every delivery settles).

    Parameters
    ----------
    estimator : MomentEstimator
        Gives the feature count, the decay, the minimum sample size, the label and
        ``online_solve(M, columns, n, m) -> theta (K, n, n + m)`` (NaN for a copy without an
        estimate): its solve on the moments ``M (K, p, p)``, compiled where it has one (a method,
        so that an episode pickles).
    K : int
        Copies.
    A, B : numpy.ndarray
        The true plant (the error of Definition def:error is against it).
    refresh : int
        Kept for the protocol (nothing drifts: the moments are exact sums).
    lags : int, default 0
        Instrumental variables' ``L`` (the rows carry ``L + 1`` lagged inputs); 0 for ``[z; y]`` rows.
    """

    fused = False
    all_ready = False  # no steady state of its own: every delivery goes through settle

    def __init__(self, estimator: Any, K: int, A: np.ndarray, B: np.ndarray, refresh: int, *, lags: int = 0) -> None:
        self.n, self.m = A.shape[0], B.shape[1]
        self.d = self.n + self.m
        self.K = K
        self.estimator = estimator
        estimator.check_online_memory(K, self.n, self.m)  # before the moments are allocated
        self.theta_true = np.hstack([A, B])
        self.c = float(self.n * self.d)  # Definition def:error
        self.M = np.zeros((K, estimator.features(self.n, self.m), estimator.features(self.n, self.m)))
        self.decay = float(estimator.decay)
        self.lags = int(lags)
        self.need = int(estimator.min_sample_size(self.n, self.m))
        self.refresh = refresh
        self.since_refresh = 0
        self._sc = np.zeros((self.d + self.n, K))
        #: the last estimates ``[A_hat B_hat]`` (K, n, n + m), NaN before the first
        self.theta = np.full((K, self.n, self.d), np.nan)

    def solve(self, M: np.ndarray, columns: int) -> np.ndarray:
        """The estimator's estimates from the moments ``M`` of ``columns`` columns, ``(K, n, n + m)``."""
        return self.estimator.online_solve(M, columns, self.n, self.m)

    def reset(self) -> None:
        self.M[:] = 0.0
        self.since_refresh = 0
        self.theta[:] = np.nan

    def add_columns(self, dims: Any, X: np.ndarray, U: np.ndarray, first: int, target: int, GC: np.ndarray) -> None:
        mk.add_rows(X, U, first, target, self.M, self.decay, self.lags)
        rk.add_gram(dims, X, U, first, target, GC, self._sc)  # the Gram matrices the rewards read

    def steady_error(self, dims: Any, eps: np.ndarray) -> None:
        raise SolverError("MomentKernels has no steady state (all_ready is False): settle every delivery")

    def settle(self, dims: Any, G: np.ndarray, C: np.ndarray, columns: int, delivered: int, final: bool, eps: np.ndarray) -> None:
        """The estimate once ``delivered >= min_sample_size`` and its error into ``eps`` (a copy
        without an estimate, NaN, keeps its previous error), as the column-by-column update does.

        Raises
        ------
        SolverError
            If an estimate's error overflows float64.
        """
        if delivered < self.need:
            return
        theta = self.theta = self.solve(self.M, delivered - 1)
        with np.errstate(over="ignore", invalid="ignore"):
            err = ((theta - self.theta_true) ** 2).sum(axis=(1, 2)) / self.c
        if np.isinf(err).any():
            raise SolverError(
                f"the {self.estimator.label} estimator's error overflowed float64 (epsilon = inf) after {delivered} samples "
                f"(copy {int(np.argmax(np.isinf(err)))}): its estimate is too far from any plant to measure"
            )
        ok = np.isfinite(err)
        eps[ok] = err[ok]
