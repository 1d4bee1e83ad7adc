"""Compiled stages of the moment estimators' online form (:class:`encctl_gym.ident.compiled.MomentKernels`).

* :func:`add_rows`: the feature rows of the regression columns ``first <= j < target`` into the
  moments ``M (K, p, p)``, one column at a time, as :meth:`MomentEstimator.update
  <encctl_gym.ident.estimator.MomentEstimator.update>` followed by a fold would add them
  (forgetting: ``M <- decay M + v v^T``); ``lags > 0``: the instrumental-variables row
  ``[u_j; u_{j-1}; ...; u_{j-L}; z_j; x_{j+1}]`` for ``j >= L`` (eq:data);
* :func:`gram_solve`: least squares from the moments by the Jacobi-scaled Cholesky solve of
  :func:`encctl_gym.ident.least_squares.solve_normal_equations` (the copies it refuses are left
  to the minimum-norm solve of :func:`encctl_gym.ident.ordinary.gram_solve`);
* :func:`iv_solve`: two-stage least squares (:meth:`InstrumentalVariables.solve
  <encctl_gym.ident.instrumental.InstrumentalVariables.solve>`): Cholesky of the instrument
  Gram matrix, Householder QR of the whitened first stage, NaN where singular;
* :func:`evidence_solve`: the empirical-Bayes posterior mean (:mod:`encctl_gym.ident.bayes`),
  the one implementation that both the batch and the online forms run.

Sizes are small (``d = n + m``): plain loops, one copy at a time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._jit import install_compile_notice

install_compile_notice()  # one line on stderr before the first compile (encctl_gym._jit)

_EPS = np.finfo(np.float64).eps


@njit(cache=True, nogil=True)
def add_rows(X, U, first, target, M, decay, lags):  # pragma: no cover - compiled
    K, n = X.shape[1], X.shape[2]
    m = U.shape[2]
    p = M.shape[1]
    q = (lags + 1) * m if lags > 0 else 0
    v = np.empty(p)
    for k in range(K):
        for j in range(first, target):
            c = j - 1  # the column's index: z = [x_c; u_c], y = x_{c+1}
            if lags > 0 and c < lags:
                continue  # no L past inputs yet: the column counts for nothing
            for lag in range(lags + 1 if lags > 0 else 0):
                for i in range(m):
                    v[lag * m + i] = U[c - lag, k, i]
            for i in range(n):
                v[q + i] = X[c, k, i]
            for i in range(m):
                v[q + n + i] = U[c, k, i]
            for i in range(n):
                v[q + n + m + i] = X[j, k, i]
            if decay != 1.0:
                for a in range(p):
                    for b in range(p):
                        M[k, a, b] *= decay
            for a in range(p):
                va = v[a]
                for b in range(p):
                    M[k, a, b] += va * v[b]


@njit(cache=True, inline="always")
def _cholesky(A, L):  # pragma: no cover - compiled
    """Lower Cholesky factor of the leading square of A into L; False if not positive definite."""
    d = L.shape[0]
    for j in range(d):
        s = A[j, j]
        for t in range(j):
            s -= L[j, t] * L[j, t]
        if not s > 0.0:
            return False
        L[j, j] = math.sqrt(s)
        for i in range(j + 1, d):
            s = A[i, j]
            for t in range(j):
                s -= L[i, t] * L[j, t]
            L[i, j] = s / L[j, j]
        for i in range(j):
            L[i, j] = 0.0
    return True


@njit(cache=True, nogil=True)
def gram_solve(M, n, m, theta, ok):  # pragma: no cover - compiled
    """``G theta^T = C`` per copy (``G = M[:d, :d]``, ``C = M[:d, d:d+n]``), Jacobi-scaled
    Cholesky; ``ok[k] = False`` where the scaled factor is (numerically) singular."""
    K = M.shape[0]
    d = n + m
    L = np.empty((d, d))
    Gs = np.empty((d, d))
    s = np.empty(d)
    y = np.empty((d, n))
    for k in range(K):
        ok[k] = False
        good = True
        for i in range(d):
            if not M[k, i, i] > 0.0:
                good = False
        if not good:
            continue
        for i in range(d):
            s[i] = 1.0 / math.sqrt(M[k, i, i])
        for i in range(d):
            for j in range(d):
                Gs[i, j] = M[k, i, j] * s[i] * s[j]
        if not _cholesky(Gs, L):
            continue
        lo, hi = L[0, 0], L[0, 0]
        for i in range(d):
            lo = min(lo, L[i, i])
            hi = max(hi, L[i, i])
        if (lo / hi) ** 2 < d * _EPS:
            continue
        for r in range(n):  # forward, then back substitution, column r of C scaled
            for i in range(d):
                t = M[k, i, d + r] * s[i]
                for j in range(i):
                    t -= L[i, j] * y[j, r]
                y[i, r] = t / L[i, i]
            for i in range(d - 1, -1, -1):
                t = y[i, r]
                for j in range(i + 1, d):
                    t -= L[j, i] * y[j, r]
                y[i, r] = t / L[i, i]
            for i in range(d):
                theta[k, r, i] = y[i, r] * s[i]
        ok[k] = True


@njit(cache=True, nogil=True)
def iv_solve(M, n, m, q, theta):  # pragma: no cover - compiled
    """Two-stage least squares per copy from the moments of ``[zeta; z; y]`` (NaN where singular)."""
    K = M.shape[0]
    d = n + m
    L = np.empty((q, q))
    W = np.empty((q, d))
    r = np.empty((q, n))
    hv = np.empty(q)
    for k in range(K):
        for a in range(n):
            for b in range(d):
                theta[k, a, b] = np.nan
        if not _cholesky(M[k, :q, :q], L):
            continue
        for c in range(d + n):  # W = L^{-1} Zx, r = L^{-1} Zy (forward substitution)
            for i in range(q):
                t = M[k, i, q + c]
                for j in range(i):
                    t -= L[i, j] * (W[j, c] if c < d else r[j, c - d])
                if c < d:
                    W[i, c] = t / L[i, i]
                else:
                    r[i, c - d] = t / L[i, i]
        # Householder QR of W (q x d): R in W's upper triangle, Q^T applied to r on the way
        for j in range(d):
            norm = 0.0
            for i in range(j, q):
                norm += W[i, j] * W[i, j]
            norm = math.sqrt(norm)
            if norm == 0.0:
                continue
            alpha = -norm if W[j, j] >= 0.0 else norm
            for i in range(j, q):
                hv[i] = W[i, j]
            hv[j] -= alpha
            hh = 0.0
            for i in range(j, q):
                hh += hv[i] * hv[i]
            if hh == 0.0:
                continue
            for c in range(j, d):
                t = 0.0
                for i in range(j, q):
                    t += hv[i] * W[i, c]
                t *= 2.0 / hh
                for i in range(j, q):
                    W[i, c] -= t * hv[i]
            for c in range(n):
                t = 0.0
                for i in range(j, q):
                    t += hv[i] * r[i, c]
                t *= 2.0 / hh
                for i in range(j, q):
                    r[i, c] -= t * hv[i]
        lo, hi = abs(W[0, 0]), abs(W[0, 0])
        for i in range(d):
            lo = min(lo, abs(W[i, i]))
            hi = max(hi, abs(W[i, i]))
        if not lo > 0.0 or (lo / hi) ** 2 < d * _EPS:
            continue
        for c in range(n):  # R theta^T = (Q^T r)[:d]
            for i in range(d - 1, -1, -1):
                t = r[i, c]
                for j in range(i + 1, d):
                    t -= W[i, j] * theta[k, c, j]
                theta[k, c, i] = t / W[i, i]


@njit(cache=True, inline="always")
def _evidence(v, g, beta, S, n, T):  # pragma: no cover - compiled
    """The profiled log evidence at ``v`` (:meth:`BayesianLeastSquares._evidence_solve`).

    ``log det(I + v G) = log prod_k (1 + v g_k)``, one logarithm per ``1e100`` of the product
    (never overflowing) instead of one per eigenvalue: the absolute error stays of the order of
    ``d`` roundings, as for a sum of ``log1p``."""
    logdet = 0.0
    prod = 1.0
    quad = S
    for i in range(g.shape[0]):
        vg = v * g[i]
        prod *= 1.0 + vg
        if prod > 1e100:
            logdet += math.log(prod)
            prod = 1.0
        quad -= beta[i] * v / (1.0 + vg)
    logdet += math.log(prod)
    floor = 1e-300 + 1e-15 * abs(S)
    return -0.5 * n * logdet - 0.5 * n * T * math.log(max(quad, floor))


@njit(cache=True, nogil=True)
def evidence_solve(G, C, YY, T, m0, grid, golden, steps, out):  # pragma: no cover - compiled
    """Empirical Bayes per copy: the posterior mean at the ``v`` of largest profiled evidence,
    found on ``grid`` (log10 of ``v`` times the mean eigenvalue) and refined by ``steps``
    golden-section steps in the best cell's bracket. ``out`` (K, n, d) starts as the prior mean."""
    K, d, n = G.shape[0], G.shape[1], C.shape[2]
    P = grid.shape[0]
    ct = np.empty((d, n))
    b = np.empty((d, n))
    beta = np.empty(d)
    logv = np.empty(P)
    for k in range(K):
        for a in range(n):
            for c in range(d):
                out[k, a, c] = m0[a, c]
        gbar = 0.0
        for i in range(d):
            gbar += G[k, i, i]
        gbar /= d
        if T == 0 or not gbar > 0.0:
            continue
        g, Q = np.linalg.eigh(np.ascontiguousarray(G[k]))
        for i in range(d):
            g[i] = max(g[i], 0.0)
        S = 0.0
        for i in range(n):
            S += YY[k, i, i]
        for i in range(n):
            for j in range(d):
                S -= 2.0 * m0[i, j] * C[k, j, i]
                gm = 0.0
                for t in range(d):
                    gm += G[k, j, t] * m0[i, t]
                S += m0[i, j] * gm
        for j in range(d):  # D (y - D^T m0) = C - G m0^T
            for i in range(n):
                t = C[k, j, i]
                for c in range(d):
                    t -= G[k, j, c] * m0[i, c]
                ct[j, i] = t
        for j in range(d):  # b = Q^T ct, beta = row sums of b^2
            beta[j] = 0.0
            for i in range(n):
                t = 0.0
                for c in range(d):
                    t += Q[c, j] * ct[c, i]
                b[j, i] = t
                beta[j] += t * t
        shift = math.log10(gbar)
        best, top = 0, -np.inf
        for i in range(P):
            logv[i] = grid[i] - shift
            f = _evidence(10.0 ** logv[i], g, beta, S, n, T)
            if f > top:
                best, top = i, f
        lo = logv[max(best - 1, 0)]
        hi = logv[min(best + 1, P - 1)]
        for _ in range(steps):
            p1 = hi - golden * (hi - lo)
            p2 = lo + golden * (hi - lo)
            if _evidence(10.0**p1, g, beta, S, n, T) >= _evidence(10.0**p2, g, beta, S, n, T):
                hi = p2
            else:
                lo = p1
        v = 10.0 ** (0.5 * (lo + hi))
        for j in range(d):
            w = v / (1.0 + v * g[j])
            for i in range(n):
                b[j, i] *= w
        for c in range(d):  # out = m0 + (Q (w b))^T
            for i in range(n):
                t = 0.0
                for j in range(d):
                    t += Q[c, j] * b[j, i]
                out[k, i, c] += t
