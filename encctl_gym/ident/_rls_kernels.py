"""Compiled (numba) recursive least squares over K copies in lockstep: the kernels of
:class:`~encctl_gym.ident.compiled.RecursiveLeastSquaresKernels`, the compiled online form of
ordinary least squares (eq:estimate) that the attack episode runs.

Data layout (copies innermost): the recursive ``Q = [P | Theta_hat^T]`` and the Gram matrix with
the cross term ``GC = [G | C]`` (``d = n + m``), each of shape (d (d + n), K), where entry
(a, b) of every copy is the row ``a (d + n) + b``; the data ``X`` (N, K, n) and ``U`` (N, K, m)
are time-major. The steady-state stages (:func:`_rls`, :func:`_gram`) run each of their
operations as one loop over the copies, which the compiler vectorises; inside a copy the
floating-point operations run in a fixed order (no fastmath), so copy ``k`` of a batch computes
bit for bit what a lone copy computes. The inline stages work on a range of copies
``k0 <= k < k1`` so that the environment's fused step (:mod:`encctl_gym.envs._kernels`) can
inline them, chunk by chunk.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._jit import install_compile_notice

install_compile_notice()  # one line on stderr before the first compile (encctl_gym._jit)

__all__ = ["add_columns", "add_gram", "estimation_error"]

#: copies whose running least squares are updated together over a run of periods
_BLOCK = 16


@njit(inline="always")
def _scratch(n, m):
    """Scratch vectors ``z``, ``r``, ``g`` of :func:`_columns`, allocated once per kernel call:
    (n + m,), (2n + m,), (n + m,)."""
    return np.empty(n + m), np.empty(2 * n + m), np.empty(n + m)


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


# The batched kernels take ``dims``: the sizes n, m and the input-history length as the lengths
# of three tuples (see :func:`encctl_gym.envs._kernels.dims`).


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
