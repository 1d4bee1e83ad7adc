"""Compiled (numba) per-step kernels of the attack episode.

Each stage of a period is written once, as a function over a range of copies
``k0 <= k < k1`` (``_energy``, ``_plant``, ``_columns``, ...); the batched kernels call the
stages on the whole batch, the parallel kernel on chunks of copies spread over the cores.
Inside a copy the floating-point operations run in a fixed order (no fastmath), so copy ``k``
of a batch computes bit for bit what a lone environment computes, whatever the chunking.

Why ranges and not one function per copy: a compiled helper that takes arrays pays reference
counting on every call, and called once per copy that cost dwarfed the arithmetic (about ten
times, measured on the energy stage); called once per range it is paid once per batch.

The small batched kernels (energy budget, plant update, regression columns, error,
observation) are used one by one by the ElGamal backend, between calls into the crypto layer;
:func:`step_fused` does a whole ideal-backend period (energy budget, forged input and collected
state in the loop's exact fixed-point arithmetic, :mod:`encctl_gym.loop.quantize`, plant,
delivery, recursive least squares, error, reward, observation, info) in one call. The batched
kernels release the GIL, so the episode's helper thread (noise draws, Gram catch-up) runs
while they do.

Arguments come grouped in plain tuples, built once per episode (numba dispatches a plain tuple
as fast as separate arguments): ``consts`` = ``(A, B, theta_true_T, c, u_max, budget)``,
``arrays`` = ``(x, energy, X, U, hist, Q, eps, reward, a_buf, q_buf, qx_buf, sc)``, ``quant`` =
the loop's :class:`~encctl_gym.loop.quantize.Quantization`, ``obs_at`` = the observation
offsets of :class:`~encctl_gym.envs.layout.ObservationLayout`; each kernel unpacks them in
that order. The observation and the info rows are written where
:mod:`encctl_gym.envs.layout` says.

Data layout: ``X`` (N, K, n) and ``U`` (N, K, m) are time-major, so the copies' data of one
period are contiguous. The running least squares are kept with the copies innermost: the
recursive ``Q = [P | Theta_hat^T]`` and the Gram matrix with the cross term ``GC = [G | C]``
(``d = n + m``), each of shape (d (d + n), K), where entry (a, b) of every copy is the row
``a (d + n) + b``. The steady-state kernels (:func:`_rls`, :func:`_gram`) then run each of
their operations as one loop over the copies, which the compiler vectorises; no copy's
numbers depend on that.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..loop.quantize import OK, STATE_OVERFLOW, _collect, _forge
from .layout import C_COLLECTED, C_DELIVERED, F_ENERGY, F_EPSILON, F_GAMMA, F_GAMMA_OPT, F_POWER, F_TIME

__all__ = ["OK", "STATE_OVERFLOW", "PARALLEL_CHUNK", "dims"]

#: copies per task of the parallel kernel
PARALLEL_CHUNK = 256
#: copies whose running least squares are updated together over a run of periods
_BLOCK = 16


# ----------------------------------------------------------------------------- stages
@njit(inline="always")
def _scratch(n, m):
    """Scratch vectors ``z``, ``r``, ``g`` of :func:`_columns`, allocated once per kernel call:
    (n + m,), (2n + m,), (n + m,)."""
    return np.empty(n + m), np.empty(2 * n + m), np.empty(n + m)


@njit(inline="always")
def _energy(k0, k1, m, act, u_max, energy, budget, a_out):
    """a = action * u_max, scaled down to exhaust the remaining energy when it would overdraw it
    (``act`` is scaled too: the agent's own input history records what was applied)."""
    for k in range(k0, k1):
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
def _plant(k0, k1, n, m, x, u, w, A, B, tmp):
    """x_k <- A x_k + B u_k + w_k (eq:system); ``tmp`` (n,) is scratch."""
    for k in range(k0, k1):
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += A[i, j] * x[k, j]
            for j in range(m):
                s += B[i, j] * u[k, j]
            tmp[i] = s + w[k, i]
        for i in range(n):
            x[k, i] = tmp[i]


@njit(inline="always")
def _history(k0, k1, m, L, hist, act):
    """Newest own input first; the oldest drops out (``L`` entries of history)."""
    for k in range(k0, k1):
        for i in range(L - 1, m - 1, -1):
            hist[k, i] = hist[k, i - m]
        for j in range(min(m, L)):
            hist[k, j] = act[k, j]


@njit(inline="always")
def _columns(k0, k1, n, m, X, U, first, target, GC, Q, ready, z, r, g):
    """Regression columns ``([x_{j-1}; u_{j-1}], x_j)``, ``first <= j < target`` (eq:data), for
    any mix of copies (the general path: the start of an episode, the ElGamal backend).

    Every copy adds the columns to its Gram matrix and cross term ``GC = [G | C]`` (the upper
    triangle of G, mirrored at the end: G is exactly symmetric). The copies flagged in
    ``ready`` also run recursive least squares on ``Q = [P | Theta_hat^T]``: ``r = z^T Q``,
    ``r[d:] -= y``, ``g = r[:d] / (1 + r[:d] . z)``, ``Q -= g r`` (Sherman-Morrison on P and
    the RLS update of Theta_hat together); P is symmetric, only its upper triangle is read and
    updated. Each copy takes its columns in order of ``j``. ``z``, ``g`` (n + m,) and ``r``
    (2n + m,) are scratch (see :func:`_scratch`). The steady state uses :func:`_rls` and
    :func:`_gram` instead, which compute the same numbers as this faster.
    """
    d = n + m
    w = d + n
    # blocks of copies, period-major inside a block: a block's GC, Q stay in cache while the
    # data of one period, contiguous across copies, stream through
    for kb in range(k0, k1, _BLOCK):
        for j in range(first, target):
            for k in range(kb, min(kb + _BLOCK, k1)):
                for i in range(n):
                    z[i] = X[j - 1, k, i]
                for i in range(m):
                    z[n + i] = U[j - 1, k, i]
                for a in range(d):  # upper triangle of G, and C
                    za = z[a]
                    for b in range(a, d):
                        GC[a * w + b, k] += za * z[b]
                    for b in range(n):
                        GC[a * w + d + b, k] += za * X[j, k, b]
                if ready[k]:
                    for b in range(w):  # r = z^T Q, summed over a in order, in a register
                        acc = 0.0
                        for a in range(d):
                            acc += z[a] * (Q[a * w + b, k] if a <= b or b >= d else Q[b * w + a, k])
                        r[b] = acc
                    for b in range(n):
                        r[d + b] -= X[j, k, b]
                    den = 1.0
                    for a in range(d):
                        den += r[a] * z[a]
                    inv = 1.0 / den
                    for a in range(d):
                        g[a] = r[a] * inv
                    for a in range(d):
                        ga = g[a]
                        for b in range(a, w):
                            Q[a * w + b, k] -= ga * r[b]
    if target > first:
        _mirror(k0, k1, d, w, GC)


@njit(inline="always")
def _mirror(k0, k1, d, w, GC):
    """Lower triangle of G from its upper triangle."""
    for a in range(1, d):
        for b in range(a):
            for k in range(k0, k1):
                GC[a * w + b, k] = GC[b * w + a, k]


@njit(inline="always")
def _regressors(k0, k1, n, m, X, U, j, sc):
    """The regressor ``z = [x_{j-1}; u_{j-1}]`` of every copy into rows ``0 .. n + m - 1`` of
    ``sc`` (copies innermost)."""
    for i in range(n):
        for k in range(k0, k1):
            sc[i, k] = X[j - 1, k, i]
    for i in range(m):
        for k in range(k0, k1):
            sc[n + i, k] = U[j - 1, k, i]


@njit(inline="always")
def _gram(k0, k1, n, m, X, U, first, target, GC, sc):
    """The Gram matrix and cross term of :func:`_columns` alone (the catch-up behind the
    steady state), each operation one loop over the copies, as in :func:`_rls`: the same
    numbers. ``sc`` (2n + m, K) is scratch: rows ``[z | y]``."""
    d = n + m
    w = d + n
    for j in range(first, target):
        _regressors(k0, k1, n, m, X, U, j, sc)
        for i in range(n):
            for k in range(k0, k1):
                sc[d + i, k] = X[j, k, i]
        for a in range(d):  # G_ab += z_a z_b (b >= a), C_ab += z_a y_b
            for b in range(a, w):
                row = a * w + b
                for k in range(k0, k1):
                    GC[row, k] += sc[a, k] * sc[b, k]
    if target > first:
        _mirror(k0, k1, d, w, GC)


@njit(inline="always")
def _error(k0, k1, n, m, Q, theta_true_T, c, ready, eps):
    """epsilon = ||Theta_hat - Theta||_F^2 / c (Definition def:error), copies flagged in ``ready``."""
    d = n + m
    w = d + n
    for k in range(k0, k1):
        if ready[k]:
            s = 0.0
            for a in range(d):  # row sums first: short dependency chains
                t = 0.0
                for b in range(n):
                    e = Q[a * w + d + b, k] - theta_true_T[a, b]
                    t += e * e
                s += t
            eps[k] = s / c


@njit(inline="always")
def _observation(k0, k1, n, m, H, obs, obs_at, X, U, j, new, hist, time_frac, energy, budget):
    """[x_j | u_{j-1} | new | own inputs | deciphering-time fraction | energy fraction], at the
    offsets ``obs_at`` of :class:`~encctl_gym.envs.layout.ObservationLayout`."""
    s0, u0, f0, h0, t0, e0 = obs_at
    for k in range(k0, k1):
        for i in range(n):
            obs[k, s0 + i] = X[j, k, i] if j >= 0 else 0.0
        for i in range(m):
            obs[k, u0 + i] = U[j - 1, k, i] if j >= 1 else 0.0
        obs[k, f0] = new
        for i in range(H):
            obs[k, h0 + i] = hist[k, i]
        obs[k, t0] = time_frac
        obs[k, e0] = energy[k] / budget


@njit(inline="always")
def _info(k0, k1, f, counts, eps, energy, scalars):
    """The info rows of :mod:`encctl_gym.envs.layout`: epsilon, gamma, deciphering time, input
    energy, average power (energy / power_den) and, if ``f`` has the row, gamma_opt; the sample
    counts. ``scalars`` = ``(gamma, time, power_den, gamma_opt, collected, delivered)``."""
    gamma, time, power_den, gamma_opt, collected, delivered = scalars
    for k in range(k0, k1):
        f[F_EPSILON, k] = eps[k]
        f[F_GAMMA, k] = gamma
        f[F_TIME, k] = time
        f[F_ENERGY, k] = energy[k]
        f[F_POWER, k] = energy[k] / power_den
        counts[C_COLLECTED, k] = collected
        counts[C_DELIVERED, k] = delivered
    if f.shape[0] > F_GAMMA_OPT:
        for k in range(k0, k1):
            f[F_GAMMA_OPT, k] = gamma_opt


@njit(inline="always")
def _period(k0, k1, n, m, H, consts, arrays, quant, act, w, u_at, collect_at, tmp):
    """One ideal-backend period of the copies ``k0 <= k < k1``, stage by stage: energy budget,
    forged input, plant update, own-input history and, if ``collect_at >= 0``, the collected
    state. Returns a status code."""
    A, B, theta_true_T, c, u_max, budget = consts
    x, energy, X, U, hist, Q, eps, reward, a_buf, q_buf, qx_buf, sc = arrays
    _energy(k0, k1, m, act, u_max, energy, budget, a_buf)
    _forge(k0, k1, m, quant, a_buf, q_buf, U, u_at)
    _plant(k0, k1, n, m, x, a_buf, w, A, B, tmp)
    if H > 0:
        _history(k0, k1, m, H, hist, act)
    if collect_at >= 0:
        return _collect(k0, k1, n, quant, x, X, collect_at, qx_buf)
    return OK


@njit(inline="always")
def _rls(k0, k1, n, m, X, U, first, target, Q, sc, theta_true_T, c, eps):
    """Recursive least squares of :func:`_columns` for copies that are all recursive, with the
    error of the final estimate: the same operations in the same order for every copy, but
    each one a loop over the copies ``k0 <= k < k1`` (innermost, so it vectorises) instead of
    a loop over a copy's entries. ``sc`` (2d + n + 2, K) is scratch: rows ``z`` (d), ``r``
    (d + n), ``1 / den`` and a row for the error sums; ``z`` is overwritten by ``g``.
    """
    d = n + m
    w = d + n
    iv = d + w  # row of 1 / den
    es = iv + 1  # row of the error sums
    for j in range(first, target):
        _regressors(k0, k1, n, m, X, U, j, sc)
        for b in range(w):  # r = z^T Q, summed over a in order
            for k in range(k0, k1):
                sc[d + b, k] = 0.0
            for a in range(d):
                row = a * w + b if a <= b or b >= d else b * w + a  # P by its upper triangle
                for k in range(k0, k1):
                    sc[d + b, k] += sc[a, k] * Q[row, k]
        for b in range(n):
            for k in range(k0, k1):
                sc[2 * d + b, k] -= X[j, k, b]
        for k in range(k0, k1):
            sc[iv, k] = 1.0
        for a in range(d):
            for k in range(k0, k1):
                sc[iv, k] += sc[d + a, k] * sc[a, k]
        for k in range(k0, k1):
            sc[iv, k] = 1.0 / sc[iv, k]
        for a in range(d):  # g = r[:d] / den, over z
            for k in range(k0, k1):
                sc[a, k] = sc[d + a, k] * sc[iv, k]
        for a in range(d):  # Q -= g r (upper triangle of P, all of Theta_hat^T)
            for b in range(a, w):
                row = a * w + b
                for k in range(k0, k1):
                    Q[row, k] -= sc[a, k] * sc[d + b, k]
    if target > first:  # the error of the final estimate, summed as _error sums it
        for k in range(k0, k1):
            sc[es, k] = 0.0
        for a in range(d):
            for k in range(k0, k1):
                sc[iv, k] = 0.0
            for b in range(n):
                tb = theta_true_T[a, b]
                row = a * w + d + b
                for k in range(k0, k1):
                    e = Q[row, k] - tb
                    sc[iv, k] += e * e
            for k in range(k0, k1):
                sc[es, k] += sc[iv, k]
        for k in range(k0, k1):
            eps[k] = sc[es, k] / c


@njit(inline="always")
def _deliver(k0, k1, n, m, X, U, first, target, Q, sc, theta_true_T, c, eps, reward):
    """Steady-state delivery of the copies ``k0 <= k < k1`` (all recursive): the columns
    ``first <= j < target`` by recursive least squares (the Gram matrices are left behind),
    the error and the reward ``log(eps_before / eps_after)``."""
    if target > first:
        for k in range(k0, k1):
            reward[k] = eps[k]
        _rls(k0, k1, n, m, X, U, first, target, Q, sc, theta_true_T, c, eps)
        for k in range(k0, k1):
            reward[k] = np.log(reward[k] / eps[k])
    else:
        for k in range(k0, k1):
            reward[k] = 0.0


# ----------------------------------------------------------------------------- batched
# The batched kernels take ``dims`` (see :func:`dims`): the sizes n, m and the input-history
# length as the lengths of three tuples. Numba compiles one version per shape with these sizes
# as constants, so the small loops over states and inputs are unrolled.


def dims(n: int, m: int, history: int) -> tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...]]:
    """The sizes ``(n, m, history)`` in the form the batched kernels take: tuples of those lengths."""
    return ((0,) * n, (0,) * m, (0,) * history)


@njit(cache=True, nogil=True)
def energy_budget(dims, act, u_max, energy, budget, a_out):
    _energy(0, act.shape[0], len(dims[1]), act, u_max, energy, budget, a_out)


@njit(cache=True, nogil=True)
def plant_step(dims, x, u, w, A, B):
    n = len(dims[0])
    _plant(0, x.shape[0], n, len(dims[1]), x, u, w, A, B, np.empty(n))


@njit(cache=True, nogil=True)
def shift_history(dims, hist, act):
    _history(0, hist.shape[0], len(dims[1]), len(dims[2]), hist, act)


@njit(cache=True, nogil=True)
def add_columns(dims, X, U, first, target, GC, Q, ready):
    n, m = len(dims[0]), len(dims[1])
    z, r, g = _scratch(n, m)
    _columns(0, ready.shape[0], n, m, X, U, first, target, GC, Q, ready, z, r, g)


@njit(cache=True, nogil=True)
def add_gram(dims, X, U, first, target, GC, sc):
    """Only the Gram matrix and cross term of columns ``first <= j < target`` (catch-up)."""
    _gram(0, GC.shape[1], len(dims[0]), len(dims[1]), X, U, first, target, GC, sc)


@njit(cache=True, nogil=True)
def estimation_error(dims, Q, theta_true_T, c, ready, eps):
    """Definition def:error for the copies flagged in ``ready``."""
    _error(0, eps.shape[0], len(dims[0]), len(dims[1]), Q, theta_true_T, c, ready, eps)


@njit(cache=True, nogil=True)
def fill_observation(dims, obs, obs_at, X, U, j, new, hist, time_frac, energy, budget):
    n, m, H = len(dims[0]), len(dims[1]), len(dims[2])
    _observation(0, obs.shape[0], n, m, H, obs, obs_at, X, U, j, new, hist, time_frac, energy, budget)


@njit(cache=True, nogil=True)
def interleave_noise(src, scale, dst):
    """``dst[c, k] = scale * src[k, c]``: the copies' noise chunks, drawn one copy at a time
    (K, C, n), into the period-major layout (C, K, n) that the step kernels read."""
    K, n_periods, n = src.shape
    for kb in range(0, K, _BLOCK):
        for c in range(n_periods):
            for k in range(kb, min(kb + _BLOCK, K)):
                for i in range(n):
                    dst[c, k, i] = src[k, c, i] * scale


@njit(cache=True, nogil=True)
def load_actions(src, dst):
    """``dst = src`` in float64, float32 rounding at the box edges clipped; returns 0 if all
    are valid, 1 at a non-finite entry, 2 at one outside [-1, 1] (``dst`` is then partial)."""
    K, m = src.shape
    outside = 0
    for k in range(K):  # the common case, branch-free: copy and count entries outside the box
        for j in range(m):
            v = np.float64(src[k, j])
            outside += (v < -1.0) | (v > 1.0) | (v != v)
            dst[k, j] = v
    if outside == 0:
        return 0
    for k in range(K):
        for j in range(m):
            v = dst[k, j]
            if not (-1.0 <= v <= 1.0):  # NaN too
                if not np.isfinite(v):
                    return 1
                if abs(v) > 1.0 + 1e-6:
                    return 2
                dst[k, j] = 1.0 if v > 0.0 else -1.0
    return 0


@njit(cache=True, nogil=True)
def fill_info(f, counts, eps, energy, scalars):
    """The info of every copy (see :func:`_info`)."""
    _info(0, f.shape[1], f, counts, eps, energy, scalars)


@njit(cache=True, nogil=True)
def log_ratio(before, after, out):
    """out = log(before / after): the reward, with the same log as the fused kernels."""
    for k in range(out.shape[0]):
        out[k] = np.log(before[k] / after[k])


@njit(cache=True, nogil=True)
def step_ideal(dims, consts, arrays, quant, act, w, u_at, collect_at):
    """The period alone (no delivery): see :func:`_period`."""
    n, m, H = len(dims[0]), len(dims[1]), len(dims[2])
    return _period(0, act.shape[0], n, m, H, consts, arrays, quant, act, w, u_at, collect_at, np.empty(n))


@njit(inline="always")
def _steady(k0, k1, n, m, H, consts, arrays, obs, obs_at, first, target, j_obs, new, time_frac, info, scalars):
    """The stages after the period of a steady-state step: delivery by recursive least squares,
    error and reward (:func:`_deliver`), observation and info, for the copies ``k0 <= k < k1``."""
    A, B, theta_true_T, c, u_max, budget = consts
    x, energy, X, U, hist, Q, eps, reward, a_buf, q_buf, qx_buf, sc = arrays
    _deliver(k0, k1, n, m, X, U, first, target, Q, sc, theta_true_T, c, eps, reward)
    _observation(k0, k1, n, m, H, obs, obs_at, X, U, j_obs, new, hist, time_frac, energy, budget)
    _info(k0, k1, info[0], info[1], eps, energy, scalars)


@njit(cache=True, nogil=True)
def step_fused(
    dims, consts, arrays, quant, act, w, u_at, collect_at, first, target, obs, obs_at, j_obs, new, time_frac, info, scalars,
):
    """A whole steady-state ideal-backend period for every copy in one call: the period, the
    delivery of the columns ``first <= j < target`` by recursive least squares, the error, the
    reward, the observation and the info rows (``info`` = ``(f, counts)``, ``scalars`` as for
    :func:`_info`). The Gram matrices are left behind; :func:`add_gram` catches them up when
    they are needed. Stage by stage over the whole batch: measured faster here than chunk by
    chunk.
    """
    K = act.shape[0]
    n, m, H = len(dims[0]), len(dims[1]), len(dims[2])
    status = _period(0, K, n, m, H, consts, arrays, quant, act, w, u_at, collect_at, np.empty(n))
    if status != OK:
        return status
    _steady(0, K, n, m, H, consts, arrays, obs, obs_at, first, target, j_obs, new, time_frac, info, scalars)
    return OK


@njit(cache=True, nogil=True, parallel=True)
def step_fused_parallel(
    dims, consts, arrays, quant, act, w, u_at, collect_at, first, target, obs, obs_at, j_obs, new, time_frac, info, scalars,
):
    """:func:`step_fused` with its chunks of :data:`PARALLEL_CHUNK` copies spread over the cores
    (``prange``): the same stages on the same chunks, which do not interact, so the numbers are
    identical."""
    K = act.shape[0]
    n, m, H = len(dims[0]), len(dims[1]), len(dims[2])
    n_chunks = (K + PARALLEL_CHUNK - 1) // PARALLEL_CHUNK
    status = np.zeros(n_chunks, dtype=np.int64)
    for t in prange(n_chunks):
        k0 = t * PARALLEL_CHUNK
        k1 = min(k0 + PARALLEL_CHUNK, K)
        tmp = np.empty(n)  # per task: the tasks run concurrently (sc: each its own columns)
        s = _period(k0, k1, n, m, H, consts, arrays, quant, act, w, u_at, collect_at, tmp)
        if s != OK:
            status[t] = s
        else:
            _steady(k0, k1, n, m, H, consts, arrays, obs, obs_at, first, target, j_obs, new, time_frac, info, scalars)
    return status.max()
