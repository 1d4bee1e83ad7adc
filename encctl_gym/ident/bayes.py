"""Bayesian least squares: a Gaussian prior on ``[A B]`` and its posterior mean (ridge).

Model (eq:data with Gaussian noise): row ``i`` of ``theta = [A B]`` has the prior
``theta_i ~ N(m0_i, diag(V_i))`` and the targets ``x_{t+1, i} = theta_i z_t + w_{t, i}`` with
``w ~ N(0, sigma_w2)``. The posterior of ``theta_i`` given the data is Gaussian with precision
``(Lambda_i + G) / sigma_w2`` and mean

``theta_hat_i = (Lambda_i + G)^{-1} (Lambda_i m0_i + C_i)``,  ``Lambda_i = sigma_w2 diag(V_i)^{-1}``,

where ``G = sum_t z_t z_t^T`` and ``C = sum_t z_t x_{t+1}^T`` (the moments of eq:estimate):
ridge regression towards ``m0`` with weight ``Lambda``, ordinary least squares as
``Lambda -> 0``. The posterior does not depend on how the inputs were chosen (as long as not on
``theta`` itself), so it holds for feedback attackers too. Its expected error is in
:mod:`encctl_gym.security.bayes_complexity`.

Default prior (an attacker that knows neither ``(A, B)`` nor ``sigma_w2``): prior mean 0 and
an isotropic prior whose scale is chosen from the data by *empirical Bayes*: with the
conjugate form ``V = v sigma_w2 I`` (so ``Lambda = I / v``), ``v`` maximises the marginal
likelihood of the delivered targets with ``sigma_w2`` profiled out (MacKay, "Bayesian
interpolation", Neural Computation 4(3), 1992; Bishop, *Pattern Recognition and Machine
Learning*, 2006, Section 3.5). Everything it needs is in the moments the attacker already
keeps (``G``, ``C`` and ``sum_t x_{t+1} x_{t+1}^T``), so the online update is unchanged. With a
fixed ``prior_variance`` and ``noise_variance`` the estimator is the textbook posterior mean.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ParameterError, ShapeError
from . import _moment_kernels as mk
from .compiled import MomentKernels
from .estimator import MomentEstimator

__all__ = ["BayesianLeastSquares", "EVIDENCE_GRID"]

#: Grid of the empirical-Bayes search: ``v * mean(diag G)`` on these values (log10), i.e. from
#: a prior ten thousand times stronger than the data to one a million times weaker; the best
#: grid point is refined by golden-section search between its neighbours (to 1e-9 decades),
#: so the estimate depends continuously on the data.
EVIDENCE_GRID = np.linspace(-4.0, 6.0, 201)
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
_GOLDEN_STEPS = 40


def _positive_array(name: str, value: Any) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a positive number or array, got {value!r}") from None
    if arr.ndim > 2:
        raise ShapeError(f"{name} must be a scalar, an (n + m,) vector or an (n, n + m) array, got shape {arr.shape}")
    if arr.size == 0 or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ParameterError(f"{name} must be finite and > 0, got {value!r}")
    return arr


class BayesianLeastSquares(MomentEstimator):
    """Posterior mean of ``[A B]`` under a Gaussian prior (registry name ``"bayes"``).

    Parameters
    ----------
    prior_mean : float or array_like of shape (n, n + m), default 0.0
        ``m0``: the prior mean of ``[A B]``.
    prior_variance : float or array_like of shape (n + m,) or (n, n + m), optional
        ``V``: the prior variance of each entry of ``[A B]`` (a vector is one variance per
        column of ``[A B]``, shared by the rows). Needs ``noise_variance``.
    noise_variance : float, optional
        ``sigma_w2`` assumed by the posterior. Needs ``prior_variance``.

    Notes
    -----
    With neither (the default), the isotropic scale is chosen by empirical Bayes (see the
    module docstring): the attacker needs neither ``(A, B)`` nor ``sigma_w2``.

    Costs: batch and grid estimates from the same moments as least squares; per estimate and
    copy, ``n`` solves of ``d x d`` (fixed prior) or one symmetric eigendecomposition plus a
    search over :data:`EVIDENCE_GRID` (empirical Bayes), ``d = n + m``. The estimate exists from
    the first sample on (the prior mean before any column).

    Raises
    ------
    ParameterError
        For a non-positive or non-finite variance, or only one of ``prior_variance`` and
        ``noise_variance``.
    ShapeError
        (at :meth:`fit` / :meth:`start`) for a prior mean or variance of the wrong shape.
    """

    name = "bayes"

    def __init__(self, prior_mean: Any = 0.0, prior_variance: Any = None, noise_variance: Any = None) -> None:
        super().__init__()
        try:
            m0 = np.asarray(prior_mean, dtype=np.float64)
        except (TypeError, ValueError):
            raise ParameterError(f"prior_mean must be a number or an (n, n + m) array, got {prior_mean!r}") from None
        if m0.ndim not in (0, 2) or not np.all(np.isfinite(m0)):
            raise ShapeError(f"prior_mean must be a finite scalar or an (n, n + m) array, got {prior_mean!r}")
        with np.errstate(over="ignore"):
            square = float(np.square(m0).sum())
        if not math.isfinite(square):  # the prior's own error (Definition def:error) would overflow
            raise ParameterError(
                f"prior_mean's squared entries overflow float64 (sum of squares {square}, largest entry "
                f"{float(np.abs(m0).max()):.4g}): its estimation error cannot be measured (entries must stay below about 1e154)"
            )
        self.prior_mean = m0
        if (prior_variance is None) != (noise_variance is None):
            missing = "noise_variance" if noise_variance is None else "prior_variance"
            raise ParameterError(
                f"give prior_variance and noise_variance together (the posterior mean depends on their ratio); "
                f"{missing} is missing (neither: empirical Bayes)"
            )
        self.prior_variance = None if prior_variance is None else _positive_array("prior_variance", prior_variance)
        if noise_variance is None:
            self.noise_variance = None
        else:
            nv = _positive_array("noise_variance", noise_variance)
            if nv.ndim:
                raise ShapeError(f"noise_variance must be a scalar, got shape {nv.shape}")
            self.noise_variance = float(nv)

    # ------------------------------------------------------------------ description
    @property
    def empirical(self) -> bool:
        """True when the prior scale is chosen by empirical Bayes."""
        return self.prior_variance is None

    @property
    def params(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if self.prior_mean.ndim or float(self.prior_mean) != 0.0:
            out["prior_mean"] = self.prior_mean.tolist()
        if not self.empirical:
            assert self.prior_variance is not None
            out["prior_variance"] = self.prior_variance.tolist()
            out["noise_variance"] = self.noise_variance
        return out

    @property
    def label(self) -> str:
        if self.empirical:
            return "bayes(evidence)"
        v = self.prior_variance
        assert v is not None
        scale = f"{float(v):g}" if v.ndim == 0 else "V"
        return f"bayes(var={scale}, noise={self.noise_variance:g})"

    def min_sample_size(self, n: int, m: int) -> int:
        """1: the prior mean is an estimate before any regression column."""
        return 1

    def check_dimensions(self, n: int, m: int) -> None:
        """The prior's shapes must fit an (n, m) plant."""
        d = n + m
        if self.prior_mean.ndim and self.prior_mean.shape != (n, d):
            raise ShapeError(f"prior_mean must have shape ({n}, {d}) for n={n}, m={m}, got {self.prior_mean.shape}")
        v = self.prior_variance
        if v is not None and v.ndim and v.shape not in ((d,), (n, d)):
            raise ShapeError(
                f"prior_variance must be a scalar or have shape ({d},) or ({n}, {d}) for n={n}, m={m}, got {v.shape}"
            )

    # ------------------------------------------------------------------ the prior
    def mean_matrix(self, n: int, m: int) -> np.ndarray:
        """``m0`` as an ``(n, n + m)`` array."""
        self.check_dimensions(n, m)
        return np.broadcast_to(self.prior_mean, (n, n + m)).astype(np.float64)

    def precision(self, n: int, m: int) -> np.ndarray:
        """The ridge weights ``Lambda_i = sigma_w2 diag(V_i)^{-1}`` of a fixed prior, ``(n, d, d)``.

        Raises
        ------
        ParameterError
            For the empirical-Bayes default (its weight is chosen from the data).
        """
        if self.empirical:
            raise ParameterError("the empirical-Bayes prior has no fixed precision; give prior_variance and noise_variance")
        self.check_dimensions(n, m)
        d = n + m
        assert self.prior_variance is not None and self.noise_variance is not None
        V = np.broadcast_to(self.prior_variance, (n, d))
        return self.noise_variance * np.einsum("ij,jk->ijk", 1.0 / V, np.eye(d))

    # ------------------------------------------------------------------ the solve
    def solve(self, M: np.ndarray, columns: int, n: int, m: int) -> np.ndarray:
        """Posterior means from the moments ``M = sum_t [z; y][z; y]^T`` (see the class docstring)."""
        d = n + m
        G, C, YY = M[..., :d, :d], M[..., :d, d:], M[..., d:, d:]
        m0 = self.mean_matrix(n, m)
        if not self.empirical:
            Lam = self.precision(n, m)  # (n, d, d)
            lhs = G[..., None, :, :] + Lam  # (..., n, d, d)
            rhs = np.einsum("ijk,ik->ij", Lam, m0) + np.swapaxes(C, -1, -2)  # (..., n, d)
            return np.linalg.solve(lhs, rhs[..., None])[..., 0]
        return self._evidence_solve(G, C, YY, columns, m0)

    def _evidence_solve(self, G: np.ndarray, C: np.ndarray, YY: np.ndarray, T: int, m0: np.ndarray) -> np.ndarray:
        """Empirical Bayes: the posterior mean at the ``v`` of largest profiled marginal likelihood.

        Per output row the marginal is ``N(D^T m0_i, sigma^2 (I + v D^T D))``; with
        ``G = Q diag(g) Q^T``, ``log det(I + v D^T D) = sum_k log(1 + v g_k)`` and the residual
        quadratic form is ``S - sum_k beta_k v / (1 + v g_k)`` (``b = Q^T (C - G m0^T)``,
        ``beta_k = ||b_k||^2``), so the log evidence with ``sigma_w2`` profiled out is
        ``-n/2 sum_k log(1 + v g_k) - n T/2 log(quad)``. It is maximised over
        :data:`EVIDENCE_GRID` (log10 of ``v`` times the mean eigenvalue of G), then by
        golden-section search inside the best cell's bracket; the posterior mean is
        ``m0 + (Q diag(v / (1 + v g)) b)^T``. Compiled
        (:func:`encctl_gym.ident._moment_kernels.evidence_solve`): the batch, grid and online
        estimates all run this one implementation.
        """
        lead, d, n = G.shape[:-2], G.shape[-1], C.shape[-1]
        Gf = np.ascontiguousarray(G.reshape(-1, d, d))
        Cf = np.ascontiguousarray(C.reshape(-1, d, n))
        YYf = np.ascontiguousarray(YY.reshape(-1, n, n))
        out = np.empty((Gf.shape[0], n, d))
        mk.evidence_solve(Gf, Cf, YYf, int(T), np.ascontiguousarray(m0), EVIDENCE_GRID, _GOLDEN, _GOLDEN_STEPS, out)
        return out.reshape(*lead, n, d)

    def online_kernels(
        self, K: int, A: np.ndarray, B: np.ndarray, Q: np.ndarray, refresh: int, cond_limit: float
    ) -> MomentKernels:
        """The compiled online form (:class:`~encctl_gym.ident.compiled.MomentKernels`): the
        moments by a compiled stage, the estimate by :meth:`solve` (the empirical-Bayes search is
        compiled, :func:`encctl_gym.ident._moment_kernels.evidence_solve`)."""
        self.check_dimensions(A.shape[0], B.shape[1])
        return MomentKernels(self, K, A, B, refresh)

    def online_solve(self, M: np.ndarray, columns: int, n: int, m: int) -> np.ndarray:
        """The estimates of the online form: :meth:`solve`."""
        return self.solve(M, columns, n, m)
