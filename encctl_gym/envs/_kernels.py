"""Compiled (numba) per-step kernels of the attack episode.

Each stage of a period is written once, as a function over a range of copies
``k0 <= k < k1`` (``_energy``, ``_plant``, ``_history``, ...); the batched kernels call the
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
delivery, recursive least squares, error, reward, observation) in one call. The batched
kernels release the GIL, so the episode's helper thread (noise draws, Gram catch-up) runs
while they do.

Arguments come grouped in plain tuples, built once per episode (numba dispatches a plain tuple
as fast as separate arguments): ``consts`` = ``(A, B, theta_true_T, c, u_max, budget)``
(:class:`~encctl_gym.envs.steps.KernelConstants`), ``arrays`` = ``(x, energy, X, U, hist, Q,
eps, reward, a_buf, q_buf, qx_buf, sc)`` (:class:`~encctl_gym.envs.steps.EpisodeArrays`), ``quant`` =
the loop's :class:`~encctl_gym.loop.quantize.Quantization`, ``obs_at`` = the observation
offsets of :class:`~encctl_gym.envs.layout.ObservationLayout`; each kernel unpacks them in
that order. The observation is written where :mod:`encctl_gym.envs.layout` says.

Data layout: ``X`` (N, K, n) and ``U`` (N, K, m) are time-major, so the copies' data of one
period are contiguous. The running least squares are kept with the copies innermost: the
recursive ``Q = [P | Theta_hat^T]`` and the Gram matrix with the cross term ``GC = [G | C]``
(``d = n + m``), each of shape (d (d + n), K), where entry (a, b) of every copy is the row
``a (d + n) + b``. The least-squares stages themselves (regression columns, recursion, Gram
catch-up, error) belong to the estimator: they are in :mod:`encctl_gym.ident._rls_kernels`,
and the fused step inlines them from there, as it inlines the loop's arithmetic.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .._jit import install_compile_notice
from ..ident._rls_kernels import _BLOCK, _rls, add_columns, add_gram, estimation_error
from ..loop.quantize import OK, STATE_OVERFLOW, _collect, _forge

install_compile_notice()  # one line on stderr before the first compile (encctl_gym._jit)

__all__ = ["OK", "STATE_OVERFLOW", "PARALLEL_CHUNK", "dims", "add_columns", "add_gram", "estimation_error"]

#: copies per task of the parallel kernel
PARALLEL_CHUNK = 256


# ----------------------------------------------------------------------------- stages
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
def _steady(k0, k1, n, m, H, consts, arrays, obs, obs_at, first, target, j_obs, new, time_frac):
    """The stages after the period of a steady-state step: delivery by recursive least squares,
    error and reward (:func:`_deliver`) and the observation, for the copies ``k0 <= k < k1``."""
    A, B, theta_true_T, c, u_max, budget = consts
    x, energy, X, U, hist, Q, eps, reward, a_buf, q_buf, qx_buf, sc = arrays
    _deliver(k0, k1, n, m, X, U, first, target, Q, sc, theta_true_T, c, eps, reward)
    _observation(k0, k1, n, m, H, obs, obs_at, X, U, j_obs, new, hist, time_frac, energy, budget)


@njit(cache=True, nogil=True)
def step_fused(dims, consts, arrays, quant, act, w, u_at, collect_at, first, target, obs, obs_at, j_obs, new, time_frac):
    """A whole steady-state ideal-backend period for every copy in one call: the period, the
    delivery of the columns ``first <= j < target`` by recursive least squares, the error, the
    reward and the observation. The Gram matrices are left behind; :func:`add_gram` catches them
    up when they are needed. Stage by stage over the whole batch: measured faster here than
    chunk by chunk.
    """
    K = act.shape[0]
    n, m, H = len(dims[0]), len(dims[1]), len(dims[2])
    status = _period(0, K, n, m, H, consts, arrays, quant, act, w, u_at, collect_at, np.empty(n))
    if status != OK:
        return status
    _steady(0, K, n, m, H, consts, arrays, obs, obs_at, first, target, j_obs, new, time_frac)
    return OK


@njit(cache=True, nogil=True, parallel=True)
def step_fused_parallel(dims, consts, arrays, quant, act, w, u_at, collect_at, first, target, obs, obs_at, j_obs, new, time_frac):
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
            _steady(k0, k1, n, m, H, consts, arrays, obs, obs_at, first, target, j_obs, new, time_frac)
    return status.max()
