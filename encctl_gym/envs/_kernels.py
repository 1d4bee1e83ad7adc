"""Compiled (numba) per-step kernels of the attack episode.

The work of one copy in one period is written once, as functions of the copy index ``k``
(``_*_k``); the batched kernels sweep them over the copies. Inside a copy the floating-point
operations run in a fixed order (no fastmath), so copy ``k`` of a batch computes bit for bit
what a lone environment computes.

The small batched kernels (energy budget, plant update, regression columns, error,
observation) are used one by one by the ElGamal backend, between calls into the crypto layer;
:func:`step_fused` does a whole ideal-backend period (energy budget, forged input quantised
through the residue table of :mod:`encctl_gym.crypto.residue_table`, plant, delivery,
recursive least squares, error, reward, observation) in one call.

Data layout: ``X`` (N, K, n) and ``U`` (N, K, m) are time-major, so the copies' data of one
period are contiguous; ``G`` (K, d, d), ``C`` (K, d, n) and ``Q = [P | Theta_hat^T]``
(K, d, d + n) hold each copy's running least squares, ``d = n + m``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

# status codes
OK = 0
STATE_OVERFLOW = 1


# ----------------------------------------------------------------------------- one copy
@njit(inline="always")
def _energy_k(k, act, u_max, energy, budget, a_out):
    """a = action * u_max, scaled down to exhaust the remaining energy when it would overdraw it
    (``act`` is scaled too: the agent's own input history records what was applied)."""
    m = act.shape[1]
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


@njit(inline="always")
def _plant_k(k, x, u, w, A, B, tmp):
    """x_k <- A x_k + B u_k + w_k (eq:system); ``tmp`` (K, n) is scratch."""
    n = x.shape[1]
    m = u.shape[1]
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += A[i, j] * x[k, j]
        for j in range(m):
            s += B[i, j] * u[k, j]
        tmp[k, i] = s + w[k, i]
    for i in range(n):
        x[k, i] = tmp[k, i]


@njit(inline="always")
def _history_k(k, hist, act):
    """Newest own input first; the oldest drops out."""
    L = hist.shape[1]
    m = act.shape[1]
    for i in range(L - 1, m - 1, -1):
        hist[k, i] = hist[k, i - m]
    for j in range(min(m, L)):
        hist[k, j] = act[k, j]


@njit(inline="always")
def _in_range_k(k, v, bound):
    """|v_j| <= bound for every entry of copy k (the encoder's declared range; NaN fails)."""
    for j in range(v.shape[1]):
        if not abs(v[k, j]) <= bound:
            return False
    return True


@njit(inline="always")
def _quantize_k(k, v, delta, offset, limit, out):
    """Signed integer of the nearest subgroup member to round(delta v) (Definition def:ec);
    False if a value lies outside the table range."""
    for j in range(v.shape[1]):
        i = np.int64(np.rint(v[k, j] * delta))
        if i > limit or i < -limit:
            return False
        out[k, j] = i + offset[i + limit]
    return True


@njit(inline="always")
def _columns_k(k, X, U, first, target, G, C, Q, gram, recursive, z, r, g):
    """Regression columns ``([x_{j-1}; u_{j-1}], x_j)``, ``first <= j < target`` (eq:data):
    if ``gram``, the Gram matrix and cross term; if ``recursive``, recursive least squares on
    ``Q = [P | Theta_hat^T]``: ``r = z^T Q``, ``r[d:] -= y``, ``g = r[:d] / (1 + r[:d] . z)``,
    ``Q -= g r`` (Sherman-Morrison on P and the RLS update of Theta_hat together).
    ``z``, ``g`` (K, d) and ``r`` (K, d + n) are scratch."""
    n = X.shape[2]
    m = U.shape[2]
    d = n + m
    w = d + n
    zk, rk, gk = z[k], r[k], g[k]
    Gk, Ck, Qk = G[k], C[k], Q[k]
    for j in range(first, target):
        for i in range(n):
            zk[i] = X[j - 1, k, i]
        for i in range(m):
            zk[n + i] = U[j - 1, k, i]
        if gram:
            for a in range(d):
                za = zk[a]
                for b in range(d):
                    Gk[a, b] += za * zk[b]
                for b in range(n):
                    Ck[a, b] += za * X[j, k, b]
        if recursive:
            for b in range(w):  # r = z^T Q, summed over a in order (inner loop contiguous)
                rk[b] = 0.0
            for a in range(d):
                za = zk[a]
                for b in range(w):
                    rk[b] += za * Qk[a, b]
            for b in range(n):
                rk[d + b] -= X[j, k, b]
            den = 1.0
            for a in range(d):
                den += rk[a] * zk[a]
            for a in range(d):
                gk[a] = rk[a] / den
            for a in range(d):
                ga = gk[a]
                for b in range(w):
                    Qk[a, b] -= ga * rk[b]


@njit(inline="always")
def _error_k(k, Q, theta_true_T, c):
    """epsilon = ||Theta_hat - Theta||_F^2 / c (Definition def:error)."""
    d = Q.shape[1]
    n = Q.shape[2] - d
    s = 0.0
    for a in range(d):
        for b in range(n):
            e = Q[k, a, d + b] - theta_true_T[a, b]
            s += e * e
    return s / c


@njit(inline="always")
def _observation_k(k, obs, X, U, j, new, hist, time_frac, energy, budget):
    """[x_j | u_{j-1} | new | own inputs | deciphering-time fraction | energy fraction]."""
    n = X.shape[2]
    m = U.shape[2]
    H = hist.shape[1]
    for i in range(n):
        obs[k, i] = X[j, k, i] if j >= 0 else 0.0
    for i in range(m):
        obs[k, n + i] = U[j - 1, k, i] if j >= 1 else 0.0
    obs[k, n + m] = new
    for i in range(H):
        obs[k, n + m + 1 + i] = hist[k, i]
    obs[k, n + m + 1 + H] = time_frac
    obs[k, n + m + 2 + H] = energy[k] / budget


# ----------------------------------------------------------------------------- batched
@njit(cache=True)
def energy_budget(act, u_max, energy, budget, a_out):
    for k in range(act.shape[0]):
        _energy_k(k, act, u_max, energy, budget, a_out)


@njit(cache=True)
def plant_step(x, u, w, A, B):
    tmp = np.empty(x.shape)
    for k in range(x.shape[0]):
        _plant_k(k, x, u, w, A, B, tmp)


@njit(cache=True)
def shift_history(hist, act):
    for k in range(hist.shape[0]):
        _history_k(k, hist, act)


@njit(cache=True)
def add_columns(X, U, first, target, G, C, Q, ready):
    K, d = G.shape[0], G.shape[1]
    z, g, r = np.empty((K, d)), np.empty((K, d)), np.empty((K, Q.shape[2]))
    for k in range(K):
        _columns_k(k, X, U, first, target, G, C, Q, True, ready[k], z, r, g)


@njit(cache=True)
def add_gram(X, U, first, target, G, C):
    """Only the Gram matrix and cross term of columns ``first <= j < target`` (catch-up)."""
    K, d = G.shape[0], G.shape[1]
    z, g, r = np.empty((K, d)), np.empty((K, d)), np.empty((K, d + X.shape[2]))
    for k in range(K):
        _columns_k(k, X, U, first, target, G, C, G, True, False, z, r, g)


@njit(cache=True)
def estimation_error(Q, theta_true_T, c, ready, eps):
    """Definition def:error for the copies flagged in ``ready``."""
    for k in range(Q.shape[0]):
        if ready[k]:
            eps[k] = _error_k(k, Q, theta_true_T, c)


@njit(cache=True)
def fill_observation(obs, X, U, j, new, hist, time_frac, energy, budget):
    for k in range(obs.shape[0]):
        _observation_k(k, obs, X, U, j, new, hist, time_frac, energy, budget)


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
def log_ratio(before, after, out):
    """out = log(before / after): the reward, with the same log as the fused kernels."""
    for k in range(out.shape[0]):
        out[k] = np.log(before[k] / after[k])


@njit(inline="always")
def _period_all(
    act, u_max, energy, budget, delta, offset, limit, one, zero2, n_cols, x_bound,
    x, A, B, w, X, U, u_at, collect_at, hist, a_buf, q_buf, qx_buf, tmp,
):
    """One ideal-backend period for every copy, stage by stage over the batch (contiguous
    sweeps): energy budget, the forged input as the plant decodes it
    (``crypto.controller.injection_value``: ``(Ecd(a) Ecd(1) + (n - 1) Ecd(0)^2) / Delta^2``),
    plant update, own-input history and, if ``collect_at >= 0``, the collected state
    ``Dcd(Ecd(x))``. Returns a status code."""
    K, m = act.shape
    n = x.shape[1]
    dd = delta * delta
    for k in range(K):
        _energy_k(k, act, u_max, energy, budget, a_buf)
    for k in range(K):
        _quantize_k(k, a_buf, delta, offset, limit, q_buf)  # |a| <= u_max: inside the table
    for k in range(K):
        for j in range(m):
            a_buf[k, j] = (q_buf[k, j] * one + (n_cols - 1) * zero2) / dd
            U[u_at, k, j] = a_buf[k, j]
    for k in range(K):
        _plant_k(k, x, a_buf, w, A, B, tmp)
    if hist.shape[1] > 0:
        for k in range(K):
            _history_k(k, hist, act)
    if collect_at >= 0:
        for k in range(K):
            if not _in_range_k(k, x, x_bound) or not _quantize_k(k, x, delta, offset, limit, qx_buf):
                return STATE_OVERFLOW
        for k in range(K):
            for i in range(n):
                X[collect_at, k, i] = qx_buf[k, i] / delta
    return OK


@njit(cache=True)
def step_ideal(
    act, u_max, energy, budget, delta, offset, limit, one, zero2, n_cols, x_bound,
    x, A, B, w, X, U, u_at, collect_at, hist, a_buf, q_buf, qx_buf,
):
    """The period alone (no delivery): see :func:`_period_all`."""
    return _period_all(
        act, u_max, energy, budget, delta, offset, limit, one, zero2, n_cols, x_bound,
        x, A, B, w, X, U, u_at, collect_at, hist, a_buf, q_buf, qx_buf, np.empty(x.shape),
    )


@njit(cache=True)
def step_fused(
    act, u_max, energy, budget, delta, offset, limit, one, zero2, n_cols, x_bound,
    x, A, B, w, X, U, u_at, collect_at, hist, a_buf, q_buf, qx_buf,
    first, target, G, C, Q, theta_true_T, c, eps, reward, obs, j_obs, new, time_frac,
    tmp, z, r, g,
):
    """A whole steady-state ideal-backend period for every copy in one call: the period
    (:func:`_period_all`), the delivery by recursive least squares, the error, the reward and
    the observation (the Gram matrices are left behind; :func:`add_gram` catches them up when
    they are needed)."""
    status = _period_all(
        act, u_max, energy, budget, delta, offset, limit, one, zero2, n_cols, x_bound,
        x, A, B, w, X, U, u_at, collect_at, hist, a_buf, q_buf, qx_buf, tmp,
    )
    if status != OK:
        return status
    K = act.shape[0]
    if target > first:
        for k in range(K):
            before = eps[k]
            _columns_k(k, X, U, first, target, G, C, Q, False, True, z, r, g)
            eps[k] = _error_k(k, Q, theta_true_T, c)
            reward[k] = np.log(before / eps[k])
    else:
        for k in range(K):
            reward[k] = 0.0
    for k in range(K):
        _observation_k(k, obs, X, U, j_obs, new, hist, time_frac, energy, budget)
    return OK


@njit(cache=True, parallel=True)
def step_fused_parallel(
    act, u_max, energy, budget, delta, offset, limit, one, zero2, n_cols, x_bound,
    x, A, B, w, X, U, u_at, collect_at, hist, a_buf, q_buf, qx_buf,
    first, target, G, C, Q, theta_true_T, c, eps, reward, obs, j_obs, new, time_frac,
    tmp, z, r, g,
):
    """:func:`step_fused` with the copies spread over the cores (``prange``).

    The same per-copy functions in the same order as :func:`_period_all` and
    :func:`step_fused`, written copy by copy because ``prange`` distributes copies (stages of
    different copies do not interact), so the numbers are identical.
    """
    K, m = act.shape
    n = x.shape[1]
    dd = delta * delta
    status = np.zeros(K, dtype=np.int64)
    for k in prange(K):
        _energy_k(k, act, u_max, energy, budget, a_buf)
        _quantize_k(k, a_buf, delta, offset, limit, q_buf)
        for j in range(m):
            a_buf[k, j] = (q_buf[k, j] * one + (n_cols - 1) * zero2) / dd
            U[u_at, k, j] = a_buf[k, j]
        _plant_k(k, x, a_buf, w, A, B, tmp)
        if hist.shape[1] > 0:
            _history_k(k, hist, act)
        if collect_at >= 0:
            if not _in_range_k(k, x, x_bound) or not _quantize_k(k, x, delta, offset, limit, qx_buf):
                status[k] = STATE_OVERFLOW
                continue
            for i in range(n):
                X[collect_at, k, i] = qx_buf[k, i] / delta
        if target > first:
            before = eps[k]
            _columns_k(k, X, U, first, target, G, C, Q, False, True, z, r, g)
            eps[k] = _error_k(k, Q, theta_true_T, c)
            reward[k] = np.log(before / eps[k])
        else:
            reward[k] = 0.0
        _observation_k(k, obs, X, U, j_obs, new, hist, time_frac, energy, budget)
    return status.max()
