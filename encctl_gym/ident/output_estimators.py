"""Subspace identification behind the :class:`~encctl_gym.ident.estimator.Estimator` protocol,
and the estimators the environment runs on outputs (``observe="output"``).

Two uses of one method (:func:`~encctl_gym.ident.subspace.n4sid` or
:func:`~encctl_gym.ident.subspace.moesp`, the state dimension ``n`` given):

* **on states** (the :class:`Estimator` protocol, ``make_estimator("n4sid")``): the states are the
  outputs (``y = x``, ``C = I``); the subspace estimate ``(A_s, B_s, C_s, D_s)`` is in a state
  basis of its own, ``x_s = T x`` with ``C_s = T^-1``, and the estimate of ``[A B]`` in the
  plant's basis is ``[C_s A_s C_s^-1, C_s B_s]`` (its ``D_s``, an estimate of 0, is dropped).
  Batched (:meth:`SubspaceEstimator.fit` on ``(..., N, n)`` states), on a grid of sample sizes
  (one fit per prefix) and online (the columns buffered, one fit of every copy at once when an
  estimate is asked for, cached until the next column): ``O(N)`` work per estimate, so
  ``O(N^2)`` over an episode that asks at every step, against ``O(1)`` for least squares.
* **on outputs** (:meth:`start_outputs`, :meth:`deliver_outputs`, :meth:`output_error`): the
  delivered outputs and the attacker's own inputs of ``K`` copies, refitted at every delivery
  (all copies in one stacked call), scored by the Markov-parameter error
  (:func:`~encctl_gym.ident.subspace.markov_error`) against the true ``(A, B, C, 0)``.

:class:`ARXOutputs` is the environment's original estimator on outputs (``estimator="ls"``):
least squares on an ARX model with ``ceil(n / p) + 1`` lags, kept online as the Gram matrix of
its regressors and solved exactly at each delivery once it is well conditioned.
:func:`output_estimator` picks one of them by the environment's ``estimator`` name.

A fit that fails (a singular least-squares problem, ``numpy.linalg.LinAlgError``) or gives a
non-finite estimate leaves that copy without a new estimate (its error stays NaN, which the
environment reads as "keep the previous epsilon").
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import check_int
from ..errors import ParameterError
from .estimator import estimate_errors
from .least_squares import check_sample_sizes, check_trajectory
from .subspace import arx_realisation, markov_error, moesp, n4sid

__all__ = [
    "SubspaceEstimator",
    "N4SIDEstimator",
    "MOESPEstimator",
    "ARXOutputs",
    "OUTPUT_ESTIMATORS",
    "output_estimator",
    "ARX_COND_LIMIT",
]

#: An ARX estimate is taken once the condition number of its regressors' Gram matrix, scaled to
#: unit diagonal, is below this (as the state case's ``EpisodeSchedule.cond_limit``): inputs that
#: barely excite the plant (an attacker forging zeros) give a Gram matrix of full rank whose solve
#: is noise, with Markov errors of 1e60.
ARX_COND_LIMIT = 1e10


def _design_rows(n: int, block_rows: int | None) -> int:
    """``i``, the block rows of the subspace windows for order ``n`` (the methods' default)."""
    return block_rows if block_rows is not None else max(2, 2 * n)


def _min_subspace_samples(n: int, p: int, m: int, block_rows: int | None) -> int:
    """Smallest ``N`` (pairs ``(u_t, y_t)``) the subspace windows of order ``n`` accept: the
    ``N - 2 i + 1`` Hankel columns cover the ``(2 m + p) i`` rows of ``[U_f; W_p]``, and PO-MOESP's
    shift equation needs ``p (i - 1) >= n``."""
    i = _design_rows(n, block_rows)
    i = max(i, -(-n // p) + 1)
    return (2 * m + p) * i + 2 * i - 1


class SubspaceEstimator:
    """A subspace method (:attr:`method`) as an :class:`~encctl_gym.ident.estimator.Estimator` on
    states and as an online estimator on outputs (module docstring).

    Parameters
    ----------
    block_rows : int, optional
        ``i``, the past and future windows (default ``max(2, 2 n)``, and at least
        ``ceil(n / p) + 1`` for the shift equation).
    """

    name = ""
    method: Any = None

    def __init__(self, block_rows: int | None = None) -> None:
        self.block_rows = None if block_rows is None else check_int("block_rows", block_rows, minimum=1)
        self._K = self._n = self._m = 0
        self._x: list[np.ndarray] = []
        self._u: list[np.ndarray] = []
        self._cache: np.ndarray | None = None
        self._theta: tuple[Any, Any, Any, Any] | None = None
        self._p = 0
        self._fitted = 0

    # ------------------------------------------------------------------ shared
    @property
    def params(self) -> dict[str, Any]:
        return {} if self.block_rows is None else {"block_rows": self.block_rows}

    @property
    def label(self) -> str:
        return self.name

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(f'{k}={v!r}' for k, v in self.params.items())})"

    def _rows(self, n: int, p: int) -> int:
        return max(_design_rows(n, self.block_rows), -(-n // p) + 1)

    def _fit(self, u: np.ndarray, y: np.ndarray, n: int) -> tuple[Any, Any, Any, Any] | None:
        """``(A, B, C, D)`` of each run of ``u (R, N, m)``, ``y (R, N, p)`` at order ``n``, or None
        where the least squares fail (module docstring)."""
        try:
            est = type(self).method(u, y, n, block_rows=self._rows(n, y.shape[-1]))
        except np.linalg.LinAlgError:
            return None
        return est.A, est.B, est.C, est.D

    def check_dimensions(self, n: int, m: int) -> None:
        """Every ``n >= 1``, ``m >= 1`` plant is identifiable by the method (nothing to refuse)."""

    # ------------------------------------------------------------------ on states
    def min_sample_size(self, n: int, m: int) -> int:
        """Smallest ``N`` (states ``x_0 .. x_{N-1}``): the windows on ``N - 1`` pairs (``y = x``, ``p = n``)."""
        return _min_subspace_samples(n, n, m, self.block_rows) + 1

    def _to_plant_basis(self, theta: tuple[np.ndarray, ...]) -> np.ndarray:
        """``[C A C^-1, C B]`` of subspace estimates on states (``C = T^-1``), NaN where ``C`` is singular."""
        A, B, C, _ = theta
        out = np.full((A.shape[0], A.shape[1], A.shape[2] + B.shape[2]), np.nan)
        for r in range(A.shape[0]):
            try:
                out[r, :, : A.shape[1]] = np.linalg.solve(C[r].T, (C[r] @ A[r]).T).T
                out[r, :, A.shape[1] :] = C[r] @ B[r]
            except np.linalg.LinAlgError:
                continue
        return out

    def _fit_states(self, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """``[A B]`` estimates of runs ``x (R, N, n)``, ``u (R, N - 1, m)``."""
        R, N, n = x.shape
        self._check_N(N, n, u.shape[-1])
        theta = self._fit(u, x[:, : N - 1], n)
        if theta is None:
            return np.full((R, n, n + u.shape[-1]), np.nan)
        return self._to_plant_basis(theta)

    def _check_N(self, N: int, n: int, m: int) -> None:
        need = self.min_sample_size(n, m)
        if N < need:
            raise ParameterError(
                f"sample size N={N} is too small: the {self.name} estimator needs N >= {need} states for n={n}, m={m}"
            )

    def fit(self, x: Any, u: Any) -> np.ndarray:
        """``[A B]`` from trajectories ``x (..., N, n)``, ``u (..., N or N - 1, m)``: ``(..., n, n + m)``."""
        x, u = check_trajectory(x, u)
        lead = x.shape[:-2]
        theta = self._fit_states(x.reshape(-1, *x.shape[-2:]), u.reshape(-1, *u.shape[-2:]))
        return theta.reshape(*lead, *theta.shape[-2:])

    def prefix_estimates(self, x: Any, u: Any, sample_sizes: Any) -> np.ndarray:
        """Estimates on every prefix ``N`` of a grid (one fit per prefix): ``(runs, K, n, n + m)``
        (``(K, n, n + m)`` for one trajectory)."""
        x, u = check_trajectory(x, u)
        single = x.ndim == 2
        xs, us = x.reshape(-1, *x.shape[-2:]), u.reshape(-1, *u.shape[-2:])
        n, m = xs.shape[-1], us.shape[-1]
        Ns = check_sample_sizes(sample_sizes, n, m, xs.shape[1])
        for N in Ns:
            self._check_N(int(N), n, m)
        out = np.stack([self._fit_states(xs[:, :N], us[:, : N - 1]) for N in Ns.tolist()], axis=1)
        return out[0] if single else out

    def start(self, K: int, n: int, m: int) -> None:
        """Forget all data and start ``K`` online copies on states."""
        self._K, self._n, self._m = int(K), int(n), int(m)
        self._x, self._u = [], []
        self._cache = None

    def update(self, z: Any, y: Any) -> None:
        """One regression column per copy: ``z = [x_{j-1}; u_{j-1}]`` (K, n + m), ``y = x_j`` (K, n)."""
        z = np.asarray(z, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        n, K = self._n, self._K
        if z.shape != (K, n + self._m) or y.shape != (K, n):
            raise ParameterError(
                f"update needs z of shape {(K, n + self._m)} and y of shape {(K, n)}, got {z.shape} and {y.shape}"
            )
        if not self._x:
            self._x.append(z[:, :n].copy())
        self._u.append(z[:, n:].copy())
        self._x.append(y.copy())
        self._cache = None

    @property
    def count(self) -> int:
        """Regression columns delivered since :meth:`start`."""
        return len(self._u)

    @property
    def ready(self) -> bool:
        """Whether the buffered states are enough for the windows."""
        return self._n > 0 and self.count + 1 >= self.min_sample_size(self._n, self._m)

    def estimate(self) -> np.ndarray:
        """The current estimates ``(K, n, n + m)`` (one stacked fit of the buffered columns, cached)."""
        if not self.ready:
            raise ParameterError(
                f"{self.name} has {self.count + 1} states, needs {self.min_sample_size(self._n, self._m)} for an estimate"
            )
        if self._cache is None:
            self._cache = self._fit_states(np.stack(self._x, axis=1), np.stack(self._u, axis=1))
        return self._cache

    def error(self, A: Any, B: Any) -> np.ndarray:
        """Definition def:error of the current estimates, ``(K,)`` (NaN where a fit failed)."""
        return estimate_errors(self.estimate(), A, B)

    # ------------------------------------------------------------------ on outputs
    def min_output_samples(self, n: int, p: int, m: int) -> int:
        """Delivered outputs before the first estimate on outputs (the last one's input is not known yet)."""
        return _min_subspace_samples(n, p, m, self.block_rows) + 1

    def start_outputs(self, K: int, n: int, p: int, m: int) -> None:
        """Start ``K`` copies on outputs of an ``n``-state plant with ``p`` outputs and ``m`` inputs."""
        self._K, self._n, self._p, self._m = int(K), int(n), int(p), int(m)
        self._theta = None
        self._fitted = 0

    def deliver_outputs(self, Y: np.ndarray, U: np.ndarray, delivered: int) -> bool:
        """Refit on the delivered outputs ``Y[:delivered]`` (``(N, K, p)``) and inputs
        ``U[:delivered - 1]``; returns whether there is an estimate."""
        N = int(delivered) - 1  # pairs (u_t, y_t), t < N: the last output's input is not applied yet
        if N + 1 < self.min_output_samples(self._n, self._p, self._m) or N <= self._fitted:
            return self._theta is not None
        u, y = U[:N].transpose(1, 0, 2), Y[:N].transpose(1, 0, 2)
        self._theta = self._fit(np.ascontiguousarray(u), np.ascontiguousarray(y), self._n)
        self._fitted = N
        return self._theta is not None

    def output_error(self, true: tuple[Any, Any, Any, Any], L: int) -> np.ndarray:
        """The Markov-parameter error of each copy's estimate, ``(K,)``; NaN without one."""
        if self._theta is None:
            return np.full(self._K, np.nan)
        with np.errstate(over="ignore", invalid="ignore"):
            e = np.asarray(markov_error(true, self._theta, L), dtype=np.float64).reshape(self._K)
        return np.where(np.isfinite(e), e, np.nan)


class N4SIDEstimator(SubspaceEstimator):
    """N4SID (:func:`~encctl_gym.ident.subspace.n4sid`, Van Overschee and De Moor 1994) behind the
    estimator protocols (registry name ``"n4sid"``)."""

    name = "n4sid"
    method = staticmethod(n4sid)


class MOESPEstimator(SubspaceEstimator):
    """PO-MOESP (:func:`~encctl_gym.ident.subspace.moesp`, Verhaegen and Verdult Sec. 9.6) behind
    the estimator protocols (registry name ``"moesp"``)."""

    name = "moesp"
    method = staticmethod(moesp)


class ARXOutputs:
    """Least squares on an ARX model, online on outputs (the environment's ``estimator="ls"``
    with ``observe="output"``): ``y[t] = sum_{k<=q} a_k y[t-k] + b_k u[t-k]`` with
    ``q = ceil(n / p) + 1`` lags (enough for a plant of order ``n``), the Gram matrix of the
    regressors accumulated at each delivery and solved exactly where its scaled condition number
    is below :data:`ARX_COND_LIMIT` (the same numbers as :func:`~encctl_gym.ident.subspace.arx`
    on the delivered data)."""

    name = "ls"

    def start_outputs(self, K: int, n: int, p: int, m: int) -> None:
        self.K, self.p, self.m = int(K), int(p), int(m)
        self.lags = -(-int(n) // self.p) + 1
        self.d = self.lags * (self.p + self.m)
        self.G = np.zeros((self.K, self.d, self.d))
        self.Cr = np.zeros((self.K, self.d, self.p))
        self._seen = 0
        self._theta: tuple[Any, Any, Any, Any] | None = None
        self._ok = np.zeros(self.K, dtype=bool)

    def min_output_samples(self, n: int, p: int, m: int) -> int:
        lags = -(-int(n) // int(p)) + 1
        return lags * (p + m) + lags

    def deliver_outputs(self, Y: np.ndarray, U: np.ndarray, delivered: int) -> bool:
        """Add the regressors of ``y_t`` for the newly delivered ``t`` and solve where well conditioned."""
        L = self.lags
        for t in range(max(self._seen, L), delivered):  # regressors of y_t: outputs and inputs of t-1 .. t-L
            z = np.concatenate([Y[t - L : t][::-1].transpose(1, 0, 2).reshape(self.K, -1),
                                U[t - L : t][::-1].transpose(1, 0, 2).reshape(self.K, -1)], axis=1)  # fmt: skip
            self.G += z[:, :, None] * z[:, None, :]
            self.Cr += z[:, :, None] * Y[t][:, None, :]
        self._seen = max(self._seen, delivered)
        if delivered - L < self.d:
            return False
        scale = np.sqrt(np.maximum(np.einsum("kii->ki", self.G), np.finfo(float).tiny))
        ok = np.linalg.cond(self.G / scale[:, :, None] / scale[:, None, :]) < ARX_COND_LIMIT
        if not ok.any():
            return False
        theta = np.linalg.solve(self.G[ok], self.Cr[ok])  # (k, d, p): [a_1^T .. a_L^T, b_1^T .. b_L^T]
        self._theta, self._ok = arx_realisation(theta, L, L, self.p, self.m), ok
        return True

    def output_error(self, true: tuple[Any, Any, Any, Any], L: int) -> np.ndarray:
        out = np.full(self.K, np.nan)
        if self._theta is not None:
            out[self._ok] = markov_error(true, self._theta, L)
        return out


#: The environment's estimators on outputs, by its ``estimator`` name.
OUTPUT_ESTIMATORS: dict[str, type] = {"ls": ARXOutputs, "n4sid": N4SIDEstimator, "moesp": MOESPEstimator}


def output_estimator(spec: Any) -> Any:
    """The estimator on outputs of an ``estimator`` specification: ``"ls"`` (ARX least squares,
    :class:`ARXOutputs`), ``"n4sid"`` or ``"moesp"`` (a name, or a mapping with ``name`` and the
    subspace methods' ``block_rows``).

    Raises
    ------
    ParameterError
        For any other estimator (the others identify ``[A B]`` from states).
    """
    name = spec.get("name") if isinstance(spec, dict) else spec
    if not isinstance(name, str) or name not in OUTPUT_ESTIMATORS:
        raise ParameterError(
            f"with observe='output' the attacker's estimator is one of {', '.join(OUTPUT_ESTIMATORS)} "
            f"(ARX least squares, N4SID, PO-MOESP), got {spec!r}"
        )
    params = {k: v for k, v in spec.items() if k != "name"} if isinstance(spec, dict) else {}
    if name == "ls":
        if params:
            raise ParameterError(f"the ARX least squares on outputs takes no parameters, got {sorted(params)}")
        return ARXOutputs()
    return OUTPUT_ESTIMATORS[name](**params)
