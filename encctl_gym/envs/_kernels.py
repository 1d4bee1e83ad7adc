"""Compiled (numba) per-step kernels of the attack episode.

Every kernel loops over the K copies and, inside a copy, over vector entries in a fixed order,
so copy ``i`` of a batch computes bit for bit what a lone environment computes. The small
kernels (energy budget, plant update, regression columns, error) are used one by one by the
ElGamal backend, between calls into the crypto layer; :func:`step_ideal` fuses them with the
ideal backend's quantisation (the residue table of :mod:`encctl_gym.crypto.residue_table`), so
an ideal step is one call. numba inlines the small kernels into the fused one without
reordering floating-point operations (no fastmath), so both paths give identical numbers.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# status codes of step_ideal
OK = 0
STATE_OVERFLOW = 1


@njit(cache=True)
def energy_budget(act, u_max, energy, budget, a_out):
    """a = action * u_max, scaled down to exhaust the remaining energy when it would overdraw it.

    Scales ``act`` in place too (the agent's own input history records what was applied).
    """
    K, m = act.shape
    for k in range(K):
        e = 0.0
        for j in range(m):
            v = act[k, j] * u_max
            a_out[k, j] = v
            e += v * v
        remaining = budget - energy[k]
        if e > remaining:
            if remaining < 0.0:
                remaining = 0.0
            scale = np.sqrt(remaining / e) if e > 0.0 else 1.0
            for j in range(m):
                a_out[k, j] *= scale
                act[k, j] *= scale
            e = remaining
        energy[k] += e


@njit(cache=True)
def plant_step(x, u, w, A, B):
    """x <- A x + B u + w (eq:system), in place, one copy at a time."""
    K, n = x.shape
    m = u.shape[1]
    tmp = np.empty(n)
    for k in range(K):
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += A[i, j] * x[k, j]
            for j in range(m):
                s += B[i, j] * u[k, j]
            tmp[i] = s + w[k, i]
        for i in range(n):
            x[k, i] = tmp[i]


@njit(cache=True)
def shift_history(hist, act):
    """Newest own input first; the oldest drops out."""
    K, L = hist.shape
    m = act.shape[1]
    for k in range(K):
        for i in range(L - 1, m - 1, -1):
            hist[k, i] = hist[k, i - m]
        for j in range(m):
            hist[k, j] = act[k, j]


@njit(cache=True)
def quantize(v, delta, offset, limit, out):
    """Signed integer of the nearest subgroup member to round(delta v) (Definition def:ec).

    Returns False if some value lies outside the table range (the caller raises)."""
    K, L = v.shape
    for k in range(K):
        for j in range(L):
            i = np.int64(np.rint(v[k, j] * delta))
            if i > limit or i < -limit:
                return False
            out[k, j] = i + offset[i + limit]
    return True


@njit(cache=True)
def add_columns(X, U, first, target, G, C, Q, ready):
    """Regression columns ``([x_{j-1}; u_{j-1}], x_j)`` for ``first <= j < target`` (eq:data).

    Accumulates the Gram matrix ``G`` and cross term ``C`` and, for the copies whose recursion
    has started, runs recursive least squares on ``Q = [P | Theta_hat^T]``:
    ``r = z^T Q``, ``r[d:] -= y``, ``k = r[:d] / (1 + r[:d] . z)``, ``Q -= k r``.
    """
    K, _, n = X.shape
    m = U.shape[2]
    d = n + m
    w = d + n
    z = np.empty(d)
    r = np.empty(w)
    kk = np.empty(d)
    for k in range(K):
        for j in range(first, target):
            for i in range(n):
                z[i] = X[k, j - 1, i]
            for i in range(m):
                z[n + i] = U[k, j - 1, i]
            for a in range(d):
                for b in range(d):
                    G[k, a, b] += z[a] * z[b]
                for b in range(n):
                    C[k, a, b] += z[a] * X[k, j, b]
            if ready[k]:
                for b in range(w):
                    s = 0.0
                    for a in range(d):
                        s += z[a] * Q[k, a, b]
                    r[b] = s
                for b in range(n):
                    r[d + b] -= X[k, j, b]
                den = 1.0
                for a in range(d):
                    den += r[a] * z[a]
                for a in range(d):
                    kk[a] = r[a] / den
                for a in range(d):
                    for b in range(w):
                        Q[k, a, b] -= kk[a] * r[b]


@njit(cache=True)
def estimation_error(Q, theta_true_T, c, ready, eps):
    """epsilon = ||Theta_hat - Theta||_F^2 / c (Definition def:error) for the ready copies."""
    K, d, w = Q.shape
    n = w - d
    for k in range(K):
        if ready[k]:
            s = 0.0
            for a in range(d):
                for b in range(n):
                    e = Q[k, a, d + b] - theta_true_T[a, b]
                    s += e * e
            eps[k] = s / c


@njit(cache=True)
def step_ideal(
    act, u_max, energy, budget,
    delta, offset, limit, one, zero2, n_cols,
    x, A, B, w,
    X, U, u_at, collect_at, hist,
    a_buf, q_buf, qx_buf,
):
    """One ideal-backend period for every copy: energy budget, forged input (quantised at Delta
    as the plant decodes it), plant update, own-input history, and, if ``collect_at >= 0``, the
    collected state ``Dcd(Ecd(x))`` stored at ``X[:, collect_at]``. Returns a status code."""
    K, m = act.shape
    n = x.shape[1]
    energy_budget(act, u_max, energy, budget, a_buf)
    quantize(a_buf, delta, offset, limit, q_buf)  # |a| <= u_max lies inside the table by construction
    dd = delta * delta
    for k in range(K):
        for j in range(m):
            a_buf[k, j] = (q_buf[k, j] * one + (n_cols - 1) * zero2) / dd
            U[k, u_at, j] = a_buf[k, j]
    plant_step(x, a_buf, w, A, B)
    if hist.shape[1] > 0:
        shift_history(hist, act)
    if collect_at >= 0:
        if not quantize(x, delta, offset, limit, qx_buf):
            return STATE_OVERFLOW
        for k in range(K):
            for i in range(n):
                X[k, collect_at, i] = qx_buf[k, i] / delta
    return OK


@njit(cache=True)
def check_actions(a):
    """Clip float32 rounding at the box edges; 0 ok, 1 non-finite, 2 outside [-1, 1]."""
    K, m = a.shape
    for k in range(K):
        for j in range(m):
            v = a[k, j]
            if not np.isfinite(v):
                return 1
            if v > 1.0:
                if v > 1.0 + 1e-6:
                    return 2
                a[k, j] = 1.0
            elif v < -1.0:
                if v < -1.0 - 1e-6:
                    return 2
                a[k, j] = -1.0
    return 0


@njit(cache=True)
def fill_observation(obs, X, U, j, new, hist, time_frac, energy, budget):
    """[x_j | u_{j-1} | new | own inputs | deciphering-time fraction | energy fraction]."""
    K, _, n = X.shape
    m = U.shape[2]
    H = hist.shape[1]
    for k in range(K):
        for i in range(n):
            obs[k, i] = X[k, j, i] if j >= 0 else 0.0
        for i in range(m):
            obs[k, n + i] = U[k, j - 1, i] if j >= 1 else 0.0
        obs[k, n + m] = new
        for i in range(H):
            obs[k, n + m + 1 + i] = hist[k, i]
        obs[k, n + m + 1 + H] = time_frac
        obs[k, n + m + 2 + H] = energy[k] / budget
