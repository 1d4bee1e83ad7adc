"""The :class:`Estimator` protocol: one interface for every identification method of ``[A B]``.

An estimator identifies ``theta = [A B]`` (shape ``(n, n + m)``) of eq:system from the data
matrices of eq:data and is scored by the error of Definition def:error. It is used three ways,
all through the same object:

* **batch**: :meth:`Estimator.fit` on trajectories in the simulator's layout, states
  ``(..., N, n)`` and inputs ``(..., N or N - 1, m)`` (as :mod:`encctl_gym.ident.least_squares`);
* **on a grid of sample sizes**: :meth:`Estimator.prefix_estimates`, the estimate on every
  prefix ``N`` of a grid in one pass (the engine's ``identification_errors``);
* **online, batched over K copies in lockstep** (the environment): :meth:`Estimator.start`
  ``(K, n, m)``, then :meth:`Estimator.update` once per delivered regression column with
  ``z = [x_{j-1}; u_{j-1}]`` of shape ``(K, n + m)`` and ``y = x_j`` of shape ``(K, n)``,
  :meth:`Estimator.estimate` (``(K, n, n + m)``) and :meth:`Estimator.error` (``(K,)``,
  Definition def:error against the true plant).

:class:`MomentEstimator` implements all three for the estimators whose estimate is a function
of weighted second moments of a feature row ``v_j`` per regression column (least squares,
Bayesian least squares, exponential forgetting, instrumental variables): the subclasses say
which row and how to solve; the accumulation, the grid and the online buffer are written once.

Online cost (``p`` features per row, ``d = n + m``): :meth:`~MomentEstimator.update` copies the
K rows into a buffer (``O(K p)``); every :data:`MomentEstimator.BLOCK` updates, and when an
estimate is asked for, the pending rows are folded into the moments with one matrix product
per copy (``O(K BLOCK p^2)``, i.e. ``O(K p^2)`` per update); :meth:`~MomentEstimator.estimate`
costs one solve per copy (``O(K d^3)``, see each estimator) and is cached until the next update.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, Protocol, runtime_checkable

import numpy as np

from .._validation import check_int, check_system
from ..errors import ParameterError, ShapeError
from ..resources import check_memory
from .error import estimation_error
from .least_squares import check_runs, check_sample_sizes, check_trajectory

__all__ = ["Estimator", "MomentEstimator", "estimate_errors", "check_grid"]


@runtime_checkable
class Estimator(Protocol):
    """What every identification method of ``[A B]`` provides (see the module docstring).

    Attributes
    ----------
    name : str
        The registry name (:data:`encctl_gym.ident.registry.ESTIMATORS`).
    """

    name: str

    def min_sample_size(self, n: int, m: int) -> int:
        """Smallest sample size ``N`` (pairs ``(u_t, x_t)``) with an estimate."""
        ...

    def fit(self, x: Any, u: Any) -> np.ndarray:
        """Estimate ``[A B]`` from trajectories ``x (..., N, n)``, ``u (..., N or N-1, m)``;
        returns ``(..., n, n + m)``."""
        ...

    def prefix_estimates(self, x: Any, u: Any, sample_sizes: Any) -> np.ndarray:
        """Estimates on every prefix ``N`` of a grid: ``(runs, K, n, n + m)`` (or ``(K, n, n + m)``)."""
        ...

    def start(self, K: int, n: int, m: int) -> None:
        """Forget all data and start ``K`` online copies for an ``n``-state, ``m``-input plant."""
        ...

    def update(self, z: Any, y: Any) -> None:
        """Add one regression column per copy: ``z = [x_{j-1}; u_{j-1}]`` (K, n + m), ``y = x_j`` (K, n)."""
        ...

    def estimate(self) -> np.ndarray:
        """The current estimates ``[A_hat B_hat]`` of the copies, ``(K, n, n + m)``."""
        ...

    def error(self, A: Any, B: Any) -> np.ndarray:
        """Definition def:error of the current estimates against the true ``(A, B)``, ``(K,)``."""
        ...

    @property
    def count(self) -> int:
        """Regression columns delivered online since :meth:`start`."""
        ...

    @property
    def ready(self) -> bool:
        """Whether :meth:`estimate` is defined (enough columns since :meth:`start`)."""
        ...

    def check_dimensions(self, n: int, m: int) -> None:
        """Raise :class:`~encctl_gym.errors.ParameterError` if the method cannot identify an
        ``n``-state, ``m``-input plant (before any data)."""
        ...


def estimate_errors(theta: np.ndarray, A: Any, B: Any) -> np.ndarray:
    """Definition def:error of a stack of estimates ``theta (..., n, n + m)``; NaN where an
    estimate is NaN (an estimator that has no estimate for that copy says so with NaN).

    The error itself is :func:`encctl_gym.ident.error.estimation_error`.
    """
    A, B = check_system(A, B)
    n = A.shape[0]
    theta = np.asarray(theta, dtype=np.float64)
    if theta.ndim < 2 or theta.shape[-2:] != (n, n + B.shape[1]):
        raise ShapeError(f"estimates must have shape (..., {n}, {n + B.shape[1]}), got {theta.shape}")
    flat = theta.reshape(-1, *theta.shape[-2:])
    out = np.full(flat.shape[0], np.nan)
    ok = np.isfinite(flat).all(axis=(1, 2))
    if ok.any():
        out[ok] = estimation_error(A, B, flat[ok, :, :n], flat[ok, :, n:])
    return out.reshape(theta.shape[:-2])


class MomentEstimator(ABC):
    """An estimator computed from weighted second moments ``M = sum_j w_j v_j v_j^T``.

    ``v_j`` is the feature row of regression column ``j`` (``z_j = [x_j; u_j]``, target
    ``y_j = x_{j+1}`` of eq:data, plus whatever the estimator needs, e.g. instruments);
    the weight of column ``j`` after ``T`` columns is ``decay^(T - 1 - j)`` (1 unless the
    estimator forgets). A subclass defines :meth:`features`, :meth:`batch_rows`,
    :meth:`online_row` (optional), :meth:`solve` and :meth:`min_sample_size`.

    Online state: the moments ``(K, p, p)``, a buffer of ``BLOCK`` pending rows per copy and
    the count. Several uses of one instance do not share anything but the parameters:
    :meth:`fit` and :meth:`prefix_estimates` never touch the online state.
    """

    #: Rows buffered online before they are folded into the moments.
    BLOCK = 64
    #: Registry name (set by each subclass).
    name: str = ""
    #: Forgetting factor of the weights (1: every column counts the same).
    decay: float = 1.0

    def __init__(self) -> None:
        self._K = 0
        self._n = self._m = 0
        self._M: np.ndarray | None = None
        self._buf: np.ndarray | None = None
        self._k = 0
        self._count = 0
        self._cache: np.ndarray | None = None

    # ------------------------------------------------------------------ to define
    @abstractmethod
    def min_sample_size(self, n: int, m: int) -> int:
        """Smallest ``N`` (pairs ``(u_t, x_t)``) for which the estimate is defined."""

    def features(self, n: int, m: int) -> int:
        """Length ``p`` of a feature row (default ``[z; y]``: ``2 n + m``)."""
        return 2 * n + m

    def batch_rows(self, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Feature rows ``(runs, N - 1, p)`` of every regression column (zero rows count for nothing).

        Default: ``v_j = [x_j; u_j; x_{j+1}]``.
        """
        return np.concatenate([x[:, :-1], u, x[:, 1:]], axis=-1)

    def online_row(self, z: np.ndarray, y: np.ndarray) -> np.ndarray | None:
        """Feature rows ``(K, p)`` of one online column (default ``[z; y]``), or None to skip it.

        Called after the inputs are validated; may update per-copy history.
        """
        return np.concatenate([z, y], axis=1)

    def reset_history(self, K: int, n: int, m: int) -> None:
        """Clear per-copy history kept by :meth:`online_row` (default: none)."""

    @abstractmethod
    def solve(self, M: np.ndarray, columns: int, n: int, m: int) -> np.ndarray:
        """Estimates ``(..., n, n + m)`` from moments ``M (..., p, p)`` of ``columns`` columns."""

    def check_dimensions(self, n: int, m: int) -> None:
        """Raise :class:`ParameterError` if the estimator cannot identify an (n, m) plant."""

    @property
    def params(self) -> dict[str, Any]:
        """The estimator's parameters (as the registry takes them)."""
        return {}

    @property
    def label(self) -> str:
        """A short human-readable name with the parameters that matter."""
        return self.name

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.items())
        return f"{type(self).__name__}({args})"

    # ------------------------------------------------------------------ batch
    def _weighted(self, rows: np.ndarray, last: int) -> np.ndarray:
        """Rows scaled by ``sqrt(decay^(last - 1 - j))`` (their index ``j`` counted from 0)."""
        if self.decay == 1.0:
            return rows
        j = np.arange(rows.shape[-2])
        w = np.sqrt(self.decay ** (last - 1 - j))
        return rows * w[:, None]

    def _moments_on_grid(self, V: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Moments after the first ``cols[k]`` columns, for every k: ``(runs, K, p, p)``."""
        runs, _, p = V.shape
        out = np.empty((runs, cols.size, p, p))
        acc = np.zeros((runs, p, p))
        start = 0
        for k, stop in enumerate(cols):
            seg = V[:, start:stop]
            if self.decay != 1.0:
                acc *= self.decay ** (stop - start)
                j = np.arange(start, stop)
                seg = seg * np.sqrt(self.decay ** (stop - 1 - j))[:, None]
            acc += np.swapaxes(seg, -1, -2) @ seg
            out[:, k] = acc
            start = stop
        return out

    def _prepare(self, x: Any, u: Any) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
        x, u = check_trajectory(x, u)
        lead = x.shape[:-2]
        x = x.reshape(-1, *x.shape[-2:])
        u = u.reshape(-1, *u.shape[-2:])
        self.check_dimensions(x.shape[-1], u.shape[-1])
        return x, u, lead

    def _check_N(self, N: int, n: int, m: int, what: str = "N") -> None:
        need = self.min_sample_size(n, m)
        if N < need:
            raise ParameterError(
                f"sample size {what}={N} is too small: the {self.label} estimator needs N >= {need} "
                f"pairs (u_t, x_t) for n={n}, m={m}"
            )

    def fit(self, x: Any, u: Any) -> np.ndarray:
        """Estimate ``[A B]`` from whole trajectories.

        Parameters
        ----------
        x : array_like, shape (..., N, n)
            States ``x_{t_s} .. x_{t_f}``.
        u : array_like, shape (..., N, m) or (..., N - 1, m)
            Inputs (``u_{t_f}`` is not used).

        Returns
        -------
        numpy.ndarray, shape (..., n, n + m)

        Raises
        ------
        ParameterError, ShapeError
            On bad data or too few samples.
        """
        x, u, lead = self._prepare(x, u)
        N, n, m = x.shape[-2], x.shape[-1], u.shape[-1]
        self._check_N(N, n, m)
        V = self._weighted(self.batch_rows(x, u), N - 1)
        M = np.swapaxes(V, -1, -2) @ V
        return self.solve(M, N - 1, n, m).reshape(*lead, n, n + m)

    def prefix_estimates(self, x: Any, u: Any, sample_sizes: Any) -> np.ndarray:
        """Estimates on every prefix ``N`` of a grid, from running moments (one pass over the data).

        Parameters
        ----------
        x : array_like, shape (runs, N_max, n) or (N_max, n)
        u : array_like, shape (runs, N_max or N_max - 1, m) or (N_max or N_max - 1, m)
        sample_sizes : array_like of int
            Strictly increasing, each ``>= min_sample_size(n, m)`` and ``<= N_max``.

        Returns
        -------
        numpy.ndarray, shape (runs, K, n, n + m) (or (K, n, n + m) for 2-D input)
        """
        x, u, squeeze = check_runs(x, u)
        runs, N_max, n = x.shape
        m = u.shape[-1]
        self.check_dimensions(n, m)
        grid = check_grid(self, sample_sizes, n, m, N_max)
        cols = grid - 1
        M = self._moments_on_grid(self.batch_rows(x, u), cols)
        theta = np.empty((runs, grid.size, n, n + m))
        for k, c in enumerate(cols):
            theta[:, k] = self.solve(M[:, k], int(c), n, m)
        return theta[0] if squeeze else theta

    # ------------------------------------------------------------------ online
    def start(self, K: int, n: int, m: int) -> None:
        """Forget all data; start ``K`` copies for an ``n``-state, ``m``-input plant."""
        K = check_int("K", K, minimum=1)
        n = check_int("n", n, minimum=1)
        m = check_int("m", m, minimum=1)
        self.check_dimensions(n, m)
        p = self.features(n, m)
        self.check_online_memory(K, n, m)
        self._K, self._n, self._m = K, n, m
        self._M = np.zeros((K, p, p))
        self._buf = np.empty((K, self.BLOCK, p))
        self._k = 0
        self._count = 0
        self._cache = None
        self.reset_history(K, n, m)

    def check_online_memory(self, K: int, n: int, m: int) -> None:
        """Refuse, before allocating, online moments of ``K`` copies beyond the memory limit
        (:func:`encctl_gym.resources.check_memory` of :meth:`online_bytes`); the column-by-column
        update and the compiled form (:class:`~encctl_gym.ident.compiled.MomentKernels`) both ask."""
        check_memory(
            f"the {self.label} estimator's moments for K = {K} copies of an n = {n}, m = {m} plant "
            f"({self.features(n, m)} features)",
            self.online_bytes(K, n, m),
            advice="use fewer copies or an estimator with fewer features",
        )

    def online_bytes(self, K: int, n: int, m: int) -> int:
        """Bytes :meth:`start` allocates and one estimate uses: per copy, the ``p x p`` moments,
        a block of ``BLOCK`` rows of ``p`` features and a ``p x p`` solve (float64)."""
        p = self.features(n, m)
        return 8 * K * (2 * p * p + self.BLOCK * p + p)

    def _started(self) -> None:
        if self._M is None:
            raise ParameterError(f"{type(self).__name__}: call start(K, n, m) before update/estimate")

    @property
    def count(self) -> int:
        """Regression columns delivered since :meth:`start` (the sample size is ``count + 1``)."""
        return self._count

    @property
    def num_copies(self) -> int:
        """K of the last :meth:`start` (0 before)."""
        return self._K

    @property
    def ready(self) -> bool:
        """Whether :meth:`estimate` is defined (``count + 1 >= min_sample_size``)."""
        return self._M is not None and self._count + 1 >= self.min_sample_size(self._n, self._m)

    def update(self, z: Any, y: Any) -> None:
        """Add one regression column per copy (eq:data).

        Parameters
        ----------
        z : array_like, shape (K, n + m)
            ``[x_{j-1}; u_{j-1}]``: the regressor (previous state and the input applied then).
        y : array_like, shape (K, n)
            ``x_j``: the target.

        Raises
        ------
        ShapeError, ParameterError
            On wrong shapes or non-finite entries; the data so far are left unchanged.
        """
        self._started()
        K, n, m = self._K, self._n, self._m
        if np.shape(z) != (K, n + m) or np.shape(y) != (K, n):
            raise ShapeError(f"update expects z ({K}, {n + m}) and y ({K}, {n}); got {np.shape(z)}, {np.shape(y)}")
        try:
            z = np.asarray(z, dtype=np.float64)
            y = np.asarray(y, dtype=np.float64)
        except (TypeError, ValueError):
            raise ParameterError("update expects numeric z and y") from None
        if not (np.isfinite(z).all() and np.isfinite(y).all()):
            raise ParameterError("update got non-finite entries in z or y")
        row = self.online_row(z, y)
        self._count += 1
        self._cache = None
        if row is None:
            return
        assert self._buf is not None
        self._buf[:, self._k] = row
        self._k += 1
        if self._k == self.BLOCK:
            self._fold()

    def _fold(self) -> None:
        k = self._k
        if not k:
            return
        assert self._M is not None and self._buf is not None
        rows = self._buf[:, :k]
        if self.decay != 1.0:
            self._M *= self.decay**k
            rows = rows * np.sqrt(self.decay ** (k - 1 - np.arange(k)))[:, None]
        for i in range(self._K):  # one product per copy: the same arithmetic as a lone copy
            self._M[i] += rows[i].T @ rows[i]
        self._k = 0

    def moments(self) -> np.ndarray:
        """A copy of the online moments ``(K, p, p)`` (pending rows folded in)."""
        self._started()
        self._fold()
        assert self._M is not None
        return self._M.copy()

    def estimate(self) -> np.ndarray:
        """The current estimates of the K copies, ``(K, n, n + m)`` (a new array).

        Raises
        ------
        ParameterError
            Before :meth:`start`, or before ``min_sample_size(n, m) - 1`` columns.
        """
        self._started()
        if self._cache is None:
            self._check_N(self._count + 1, self._n, self._m, what="count+1")
            self._fold()
            assert self._M is not None
            self._cache = self.solve(self._M, self._count, self._n, self._m)
        return self._cache.copy()

    def error(self, A: Any, B: Any) -> np.ndarray:
        """Definition def:error of the current estimates, ``(K,)`` (NaN for a copy without one)."""
        A, B = check_system(A, B)
        self._started()
        if A.shape != (self._n, self._n) or B.shape != (self._n, self._m):
            raise ShapeError(f"A, B must have shapes ({self._n}, {self._n}), ({self._n}, {self._m}); got {A.shape}, {B.shape}")
        return estimate_errors(self.estimate(), A, B)


def check_grid(estimator: Estimator, sample_sizes: Any, n: int, m: int, N_max: int | None = None) -> np.ndarray:
    """Validate a grid of sample sizes for ``estimator`` on an (n, m) plant.

    Like :func:`~encctl_gym.ident.least_squares.check_sample_sizes` (strictly increasing
    integers, at most ``N_max``), with the estimator's own minimum sample size instead of
    ``n + m + 1``.

    Returns
    -------
    numpy.ndarray of int64

    Raises
    ------
    ParameterError
        For an empty, non-integer, non-increasing or out-of-range grid (the message names it).
    """
    need = estimator.min_sample_size(n, m)
    if need >= n + m + 1:
        grid = check_sample_sizes(sample_sizes, n, m, N_max)
    else:  # defined below n + m + 1 samples (a prior fills the gap): check the rest here
        arr = np.asarray(sample_sizes)
        if arr.ndim != 1 or arr.size == 0:
            raise ParameterError(f"sample_sizes must be a non-empty 1-D sequence of integers, got {sample_sizes!r}")
        if (
            arr.dtype == bool
            or arr.dtype.kind not in "iuf"
            or (arr.dtype.kind == "f" and not (np.all(np.isfinite(arr)) and np.all(arr == np.round(arr))))
        ):
            raise ParameterError(f"sample_sizes must be integers, got {sample_sizes!r}")
        grid = arr.astype(np.int64)
        if np.any(np.diff(grid) <= 0):
            raise ParameterError(f"sample_sizes must be strictly increasing, got {grid.tolist()}")
        if N_max is not None and grid[-1] > N_max:
            raise ParameterError(f"sample size {int(grid[-1])} exceeds the trajectory length N={N_max}")
    if grid[0] < need:
        raise ParameterError(
            f"sample size sample_sizes[0]={int(grid[0])} is too small: the {getattr(estimator, 'label', estimator.name)} "
            f"estimator needs N >= {need} pairs (u_t, x_t) for n={n}, m={m}"
        )
    return grid
