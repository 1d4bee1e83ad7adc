"""Subspace identification of a plant measured through its outputs: N4SID, PO-MOESP and ARX.

The paper's adversary sees the state and fits ``(A, B)`` by least squares (eq:estimate); its
future work names subspace identification for the case where only outputs are measured,

    x[t+1] = A x[t] + B u[t] + w[t],        y[t] = C x[t] + D u[t] + v[t],

(eq:system with an output equation). Then ``(A, B, C, D)`` is identifiable only up to a change of
state basis, so estimates are scored by a basis-free error (:func:`markov_error`).

The phases are separate functions, each testable alone:

1. :func:`block_hankel` -- the block Hankel matrices of inputs and outputs (past and future
   windows of ``i`` block rows each, ``j = N - 2 i + 1`` columns).
2. :func:`oblique_projection_factors` -- the LQ factorisation of ``[U_f; W_p; Y_f]``
   (``W_p = [U_p; Y_p]``, past inputs and outputs as instruments) whose blocks give both the
   oblique projection ``Y_f /_{U_f} W_p = L32 L22^+ W_p`` (N4SID) and the column space of the
   extended observability matrix (PO-MOESP, the SVD of ``L32``).
3. :func:`select_order` -- the order from the singular values, reported with them.
4. The system matrices by least squares: N4SID from the estimated state sequence,
   ``[x[t+1]; y[t]] = [A B; C D] [x[t]; u[t]]``; PO-MOESP from the shift invariance of the
   observability matrix (``A``, ``C``) and a least-squares fit of ``(B, D)`` to the part of the
   future outputs the future inputs explain, with the states projected out.

:func:`arx` is the simple baseline: least squares on ``y[t] = sum_k a_k y[t-k] + b_k u[t-k]``.

Every function takes a batch of runs, ``u`` of shape ``(R, N, m)`` and ``y`` of shape
``(R, N, p)`` (or one run without the leading axis), and works on the whole batch at once with
stacked LAPACK calls, which is where it gains on per-run implementations.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int
from ..errors import ParameterError, ShapeError

__all__ = [
    "SubspaceEstimate",
    "arx",
    "arx_realisation",
    "block_hankel",
    "default_block_rows",
    "markov_error",
    "markov_parameters",
    "moesp",
    "n4sid",
    "oblique_projection_factors",
    "select_order",
]


@dataclass(frozen=True)
class SubspaceEstimate:
    """Estimated ``(A, B, C, D)`` of a batch of runs (leading axis ``R``, dropped for one run).

    Attributes
    ----------
    A, B, C, D : ndarray
        Shapes ``(R, n, n)``, ``(R, n, m)``, ``(R, p, n)``, ``(R, p, m)``, in the state basis the
        method chose (compare estimates with :func:`markov_error`, not entry by entry).
    singular_values : ndarray, shape (R, p i)
        The singular values the order was chosen from (step 3 of the module docstring).
    order : int
        The state dimension ``n`` used.
    block_rows : int
        ``i``, the number of block rows of the past and the future windows.
    method : str
        ``"n4sid"``, ``"moesp"`` or ``"arx"``.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    singular_values: np.ndarray
    order: int
    block_rows: int
    method: str


def _as_batch(u: Any, y: Any) -> tuple[np.ndarray, np.ndarray, bool]:
    """``u``, ``y`` as float arrays ``(R, N, m)``, ``(R, N, p)`` and whether the input was one run."""
    u = as_finite_array("u", u)
    y = as_finite_array("y", y)
    single = y.ndim <= 2
    if u.ndim == 1:
        u = u[:, None]
    if y.ndim == 1:
        y = y[:, None]
    if single:
        u, y = u[None], y[None]
    if u.ndim != 3 or y.ndim != 3:
        raise ShapeError(f"u and y must have shapes (R, N, m) and (R, N, p), got {u.shape} and {y.shape}")
    if u.shape[:2] != y.shape[:2]:
        raise ShapeError(f"u and y must have the same runs and samples, got {u.shape} and {y.shape}")
    return u, y, single


def block_hankel(z: Any, start: int, rows: int, cols: int) -> np.ndarray:
    """Block Hankel matrix of a batch of signals.

    ``H[:, r d : (r + 1) d, c] = z[:, start + r + c]`` for ``r < rows`` and ``c < cols``.

    Parameters
    ----------
    z : ndarray, shape (R, N, d)
        Signals (inputs or outputs) of ``R`` runs.
    start, rows, cols : int
        First sample, block rows and columns (``start + rows + cols - 1 <= N``).

    Returns
    -------
    ndarray, shape (R, rows d, cols)
    """
    z = np.asarray(z, dtype=float)
    R, N, d = z.shape
    if start < 0 or rows < 1 or cols < 1 or start + rows + cols - 1 > N:
        raise ShapeError(
            f"a block Hankel matrix of {rows} block rows and {cols} columns from sample {start} needs more than {N} samples"
        )
    window = np.lib.stride_tricks.sliding_window_view(z[:, start : start + rows + cols - 1], rows, axis=1)  # (R, cols, d, rows)
    return np.ascontiguousarray(window.transpose(0, 3, 2, 1).reshape(R, rows * d, cols))


def oblique_projection_factors(u: np.ndarray, y: np.ndarray, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The blocks ``L22``, ``L32`` and ``L21`` of the LQ factorisation of ``[U_f; W_p; Y_f] / sqrt(j)``.

    With ``W_p = [U_p; Y_p]``, the oblique projection of the future outputs along the future inputs
    onto the past is ``Y_f /_{U_f} W_p = L32 L22^+ W_p`` (N4SID), and the column space of ``L32``
    is that of the extended observability matrix ``Gamma_i`` (PO-MOESP; Verhaegen and Verdult,
    *Filtering and System Identification*, Sec. 9.6).

    Returns
    -------
    L22 : ndarray, shape (R, (m + p) i, (m + p) i)
    L32 : ndarray, shape (R, p i, (m + p) i)
    L21 : ndarray, shape (R, (m + p) i, m i)
    """
    L, a, b = _lq_of_windows(u, y, i)
    return L[:, a:b, a:b], L[:, b:, a:b], L[:, a:b, :a]


def _lq_of_windows(u: np.ndarray, y: np.ndarray, i: int) -> tuple[np.ndarray, int, int]:
    """The whole lower factor ``L`` of ``[U_f; W_p; Y_f] / sqrt(j)`` and the first rows ``a``, ``b``
    of ``W_p`` and ``Y_f`` (so ``L11 = L[:, :a, :a]``, ``L31 = L[:, b:, :a]``, ...)."""
    R, N, m = u.shape
    p = y.shape[2]
    j = N - 2 * i + 1
    Up, Uf = block_hankel(u, 0, i, j), block_hankel(u, i, i, j)
    Yp, Yf = block_hankel(y, 0, i, j), block_hankel(y, i, i, j)
    M = np.concatenate([Uf, Up, Yp, Yf], axis=1) / np.sqrt(j)
    return _lower_factor(M), m * i, m * i + (m + p) * i


def _lower_factor(M: np.ndarray) -> np.ndarray:
    """``L`` (lower triangular, positive diagonal) with ``M M^T = L L^T``: the ``L`` of the LQ
    factorisation ``M = L Q^T`` (``Q`` is never needed). The Cholesky factor of the small Gram
    matrix is the same ``L`` at a fraction of the cost; for a run whose Gram matrix is singular
    or too ill-conditioned for it (an input that does not excite every direction), the
    Householder triangle of ``M^T`` is taken instead, with its signs made positive. The choice is
    made run by run, so a run's factor does not depend on the other runs of the batch."""
    if M.shape[2] < M.shape[1]:  # fewer columns than rows: every Gram matrix is singular
        return _householder_lower(M)
    gram = M @ M.transpose(0, 2, 1)
    scale = np.linalg.norm(gram, ord=2, axis=(1, 2))
    L = np.zeros_like(gram)
    ok = np.zeros(len(gram), dtype=bool)
    try:
        L = np.linalg.cholesky(gram)
        ok[:] = True
    except np.linalg.LinAlgError:  # some run's Gram matrix is not positive definite: find which
        for r in range(len(gram)):
            try:
                L[r] = np.linalg.cholesky(gram[r])
                ok[r] = True
            except np.linalg.LinAlgError:
                pass
    diag = np.diagonal(L, axis1=1, axis2=2)
    ok &= np.all(diag**2 > 1e-10 * scale[:, None], axis=1)  # squared condition number below ~1e10
    if not ok.all():
        L[~ok] = _householder_lower(M[~ok])
    return L


def _householder_lower(M: np.ndarray) -> np.ndarray:
    """The lower factor of ``M = L Q^T`` from the Householder triangle of ``M^T``, signs made positive
    (shape ``(R, rows, min(rows, cols))``)."""
    r: np.ndarray = np.linalg.qr(M.transpose(0, 2, 1), mode="r")  # type: ignore[assignment]  # mode="r": R only
    sign = np.where(np.diagonal(r, axis1=1, axis2=2) < 0, -1.0, 1.0)
    return (r * sign[:, :, None]).transpose(0, 2, 1)


def select_order(singular_values: np.ndarray, max_order: int | None = None) -> int:
    """The order at the largest gap of the (batch-averaged) log singular values.

    ``n = argmax_k log s_k - log s_{k+1}`` over ``1 <= k <= max_order`` (default: all but the
    last); singular values below ``1e-12`` of the largest count as zero. A user who knows the
    order passes it instead; the singular values are returned with every estimate either way.
    """
    s = np.atleast_2d(np.asarray(singular_values, dtype=float))
    s = np.exp(np.mean(np.log(np.maximum(s, 1e-12 * s[:, :1])), axis=0))
    top = len(s) - 1 if max_order is None else min(max_order, len(s) - 1)
    if top < 1:
        raise ParameterError(f"cannot choose an order from {len(s)} singular value(s): give more block rows")
    gaps = np.log(s[:top]) - np.log(s[1 : top + 1])
    return int(np.argmax(gaps)) + 1


def default_block_rows(order: int | None, p: int) -> int:
    """``i`` when none is given: ``2 order`` (at least 2), or ``ceil(10 / p)`` (at least 3) when the
    order is to be chosen."""
    return max(2, 2 * order) if order else max(3, -(-10 // p))


def _check_design(u: np.ndarray, y: np.ndarray, order: int | None, block_rows: int | None) -> tuple[int, int | None]:
    R, N, m = u.shape
    p = y.shape[2]
    if order is not None:
        order = check_int("order", order, minimum=1)
    if block_rows is None:
        block_rows = default_block_rows(order, p)
    i = check_int("block_rows", block_rows, minimum=1)
    if order is not None and order > p * i:
        raise ParameterError(f"order = {order} exceeds p * block_rows = {p * i}: give block_rows >= {-(-order // p)}")
    j = N - 2 * i + 1
    unknowns = (m + p) * i + m * i
    if j < unknowns:
        raise ParameterError(
            f"N = {N} samples give {max(j, 0)} Hankel columns for {unknowns} rows of [U_f; W_p] "
            f"(block_rows = {i}, m = {m}, p = {p}): need N >= {unknowns + 2 * i - 1}"
        )
    return i, order


def _factor(u: Any, y: Any, order: int | None, block_rows: int | None) -> tuple[Any, ...]:
    u, y, single = _as_batch(u, y)
    i, order = _check_design(u, y, order, block_rows)
    L, a, b = _lq_of_windows(u, y, i)
    return u, y, single, i, order, L, a, b


def n4sid(
    u: Any, y: Any, order: int | None = None, *, block_rows: int | None = None, max_order: int | None = None
) -> SubspaceEstimate:
    """N4SID: the state sequence from the oblique projection, then least squares.

    The oblique projection ``O = L32 L22^+ W`` (:func:`oblique_projection_factors`), applied to the
    past window ``W = [U; Y]`` at every time, has the SVD ``U S V^T``; its first ``n`` singular
    directions give the state sequence ``x = S_n^{1/2} V_n^T`` (Van Overschee and De Moor, 1994),
    and ``[x[t+1]; y[t]] = [A B; C D] [x[t]; u[t]]`` is solved by least squares over ``t >= i``.

    Parameters
    ----------
    u, y : array_like, shapes (R, N, m) and (R, N, p), or one run (N, m) and (N, p)
        Inputs and outputs.
    order : int, optional
        The state dimension; chosen by :func:`select_order` if not given.
    block_rows : int, optional
        ``i``: the past and future windows (default ``2 order``, at least 2; without an order
        ``ceil(10 / p)``, at least 3).
    max_order : int, optional
        The largest order :func:`select_order` may choose.

    Returns
    -------
    SubspaceEstimate

    Raises
    ------
    ParameterError
        If the data are too short for the windows or the order exceeds ``p i``.
    """
    u, y, single, i, order, L, a, b = _factor(u, y, order, block_rows)
    L22, L32 = L[:, a:b, a:b], L[:, b:, a:b]
    N = u.shape[1]
    cols = N - i + 1
    W = np.concatenate([block_hankel(u, 0, i, cols), block_hankel(y, 0, i, cols)], axis=1)
    oblique = L32 @ np.linalg.pinv(L22) @ W  # (R, p i, cols): Gamma_i x[t + i] for t = 0 .. N - i
    _, s, Vt = np.linalg.svd(oblique, full_matrices=False)
    n = order or select_order(s, max_order)
    x = np.sqrt(s[:, :n, None]) * Vt[:, :n]  # (R, n, cols): x[i], ..., x[N]
    xt, xn = x[:, :, :-2], x[:, :, 1:-1]
    ut, yt = u[:, i : N - 1].transpose(0, 2, 1), y[:, i : N - 1].transpose(0, 2, 1)
    lhs, rhs = np.concatenate([xn, yt], axis=1), np.concatenate([xt, ut], axis=1)
    theta = _solve_rows(lhs, rhs)  # (R, n + p, n + m)
    return _estimate(theta[:, :n, :n], theta[:, :n, n:], theta[:, n:, :n], theta[:, n:, n:], s, n, i, "n4sid", single)


def moesp(
    u: Any, y: Any, order: int | None = None, *, block_rows: int | None = None, max_order: int | None = None
) -> SubspaceEstimate:
    """PO-MOESP: the observability matrix from ``L32``, then ``A``, ``C``, ``B``, ``D``.

    The first ``n`` left singular vectors of ``L32`` span the extended observability matrix
    ``Gamma_i = [C; C A; ...; C A^{i-1}]``; ``C`` is its first block row and ``A`` solves the shift
    equation ``Gamma_i[:-p] A = Gamma_i[p:]`` by least squares. Where that ``A`` is stable,
    ``B``, ``D`` and the initial state enter the outputs linearly,
    ``y[t] = C A^t x0 + sum_{k<t} C A^{t-1-k} B u[k] + D u[t]``, and are fitted by least squares
    over the whole run (Verhaegen and Verdult, Sec. 9.2.4). Where its spectral radius ``rho`` is
    1 or more, that regression grows like ``rho^N`` (it swamped ``B``, which came out 0, or
    overflowed); ``B`` and ``D`` then solve ``Gamma_perp^T L31 = Gamma_perp^T T_i(B, D) L11`` by
    least squares (:func:`_input_matrices`), with ``Gamma_perp`` the remaining left singular
    vectors and ``T_i`` the block Toeplitz matrix of ``D, C B, ..., C A^{i-2} B`` (Sec. 9.3 and
    9.6), where no power of ``A`` above ``i - 2`` enters. Parameters and returns as :func:`n4sid`.
    """
    u, y, single, i, order, L, a, b = _factor(u, y, order, block_rows)
    p = y.shape[2]
    Us, s, _ = np.linalg.svd(L[:, b:, a:b], full_matrices=False)
    n = order or select_order(s, max_order)
    if n > p * (i - 1):
        raise ParameterError(f"order = {n} needs block_rows >= {-(-n // p) + 1} for the shift equation (block_rows = {i})")
    G = Us[:, :, :n] * np.sqrt(s[:, None, :n])
    C = G[:, :p]
    A = _batched_lstsq(G[:, :-p], G[:, p:])
    B, D = _input_matrices(Us[:, :, n:], L[:, :a, :a], L[:, b:, :a], A, C)
    stable = np.max(np.abs(np.linalg.eigvals(A)), axis=1) < 1.0
    if stable.any():
        B[stable], D[stable] = _input_matrices_run(u[stable], y[stable], A[stable], C[stable])
    return _estimate(A, B, C, D, s, n, i, "moesp", single)


def _input_matrices_run(u: np.ndarray, y: np.ndarray, A: np.ndarray, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``B`` and ``D`` (and the initial state) by least squares on the output equation over the
    whole run (:func:`moesp`; only for estimates of ``A`` with spectral radius below 1)."""
    R, N, m = u.shape
    p, n = C.shape[1], C.shape[2]
    # regressor of y[t]: [C A^t | C Z_t | u[t]^T kron I_p], Z_{t+1} = A Z_t + u[t]^T kron I_n
    k = n + n * m + m * p
    Phi = np.empty((R, N, p, k))
    At = np.broadcast_to(np.eye(n), (R, n, n)).copy()
    Z = np.zeros((R, n, n * m))
    eye_n, eye_p = np.eye(n), np.eye(p)
    for t in range(N):
        Phi[:, t, :, :n] = C @ At
        Phi[:, t, :, n : n + n * m] = C @ Z
        Phi[:, t, :, n + n * m :] = np.einsum("rj,ab->rajb", u[:, t], eye_p).reshape(R, p, m * p)
        Z = A @ Z + np.einsum("rj,ab->rajb", u[:, t], eye_n).reshape(R, n, n * m)
        At = A @ At
    theta = _batched_lstsq(Phi.reshape(R, N * p, k), y.reshape(R, N * p, 1))[..., 0]
    B = theta[:, n : n + n * m].reshape(R, m, n).transpose(0, 2, 1)  # vec(B): columns stacked
    D = theta[:, n + n * m :].reshape(R, m, p).transpose(0, 2, 1)
    return B, D


def _input_matrices(
    perp: np.ndarray, L11: np.ndarray, L31: np.ndarray, A: np.ndarray, C: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``B`` and ``D`` minimising ``||perp^T (L31 - T_i(B, D) L11)||_F`` (:func:`moesp`).

    ``Y_f = Gamma_i X_f + T_i U_f + noise`` with ``U_f = L11 Q1`` and ``Y_f Q1^T = L31``; ``perp``
    (``(R, p i, q)``, orthonormal, ``perp^T Gamma_i = 0``) removes the states, and future noise is
    uncorrelated with future inputs. ``T_i`` has ``D`` on its block diagonal and
    ``C A^{r-c-1} B`` in block ``(r, c)``, ``r > c``: linear in ``(B, D)``, so the regressor is
    built column by column of the unknowns.
    """
    R, p, n = C.shape
    m = L11.shape[1] // (L31.shape[1] // p)
    i = L31.shape[1] // p
    P = perp.transpose(0, 2, 1)  # (R, q, p i)
    obs = [C]
    for _ in range(i - 2):
        obs.append(obs[-1] @ A)  # C A^k, k = 0 .. i - 2
    coef_B = np.zeros((R, P.shape[1], m * i, n, m))
    coef_D = np.zeros((R, P.shape[1], m * i, p, m))
    for r in range(i):
        Pr = P[:, :, r * p : (r + 1) * p]
        coef_D += np.einsum("Rqp,Rbk->Rqkpb", Pr, L11[:, r * m : (r + 1) * m])
        for c in range(r):
            coef_B += np.einsum("Rqp,Rpn,Rbk->Rqknb", Pr, obs[r - c - 1], L11[:, c * m : (c + 1) * m])
    X = np.concatenate([coef_B.reshape(R, -1, n * m), coef_D.reshape(R, -1, p * m)], axis=2)
    theta = _batched_lstsq(X, (P @ L31).reshape(R, -1, 1))[..., 0]
    return theta[:, : n * m].reshape(R, n, m), theta[:, n * m :].reshape(R, p, m)


def arx(u: Any, y: Any, na: int = 2, nb: int = 2) -> SubspaceEstimate:
    """ARX least squares, the simple baseline: ``y[t] = sum_{k=1}^{na} a_k y[t-k] + sum_{k=1}^{nb} b_k u[t-k]``.

    The fitted model is returned in observer canonical form (block companion, order ``p max(na, nb)``)
    so that it is scored by :func:`markov_error` like the subspace estimates; ``singular_values``
    is empty and ``block_rows`` is ``max(na, nb)``.
    """
    u, y, single = _as_batch(u, y)
    na, nb = check_int("na", na, minimum=1), check_int("nb", nb, minimum=1)
    R, N, m = u.shape
    p = y.shape[2]
    q = max(na, nb)
    if N - q < na * p + nb * m:
        raise ParameterError(f"ARX with na = {na}, nb = {nb} needs N > {q + na * p + nb * m} samples, got N = {N}")
    regs = [y[:, q - k : N - k] for k in range(1, na + 1)] + [u[:, q - k : N - k] for k in range(1, nb + 1)]
    X = np.concatenate(regs, axis=2)  # (R, N - q, na p + nb m)
    theta = _batched_lstsq(X, y[:, q:])  # (R, na p + nb m, p)
    A, B, C, D = arx_realisation(theta, na, nb, p, m)
    return _estimate(A, B, C, D, np.zeros((R, 0)), p * q, q, "arx", single)


def arx_realisation(theta: np.ndarray, na: int, nb: int, p: int, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(A, B, C, D)`` of ARX coefficients in observer canonical form (block companion, order ``p max(na, nb)``).

    ``theta`` of shape ``(R, na p + nb m, p)`` stacks ``a_1^T .. a_na^T`` then ``b_1^T .. b_nb^T``
    (the least-squares solution of :func:`arx`, one column per output).
    """
    R = theta.shape[0]
    q = max(na, nb)
    a = [theta[:, k * p : (k + 1) * p].transpose(0, 2, 1) for k in range(na)] + [np.zeros((R, p, p))] * (q - na)
    b = [theta[:, na * p + k * m : na * p + (k + 1) * m].transpose(0, 2, 1) for k in range(nb)] + [np.zeros((R, p, m))] * (q - nb)
    n = p * q
    A = np.zeros((R, n, n))
    for k in range(q):  # observer form: x_{k} blocks, y = x_1
        A[:, k * p : (k + 1) * p, :p] = a[k]
        if k + 1 < q:
            A[:, k * p : (k + 1) * p, (k + 1) * p : (k + 2) * p] = np.eye(p)
    B = np.concatenate(b, axis=1)
    C = np.zeros((R, p, n))
    C[:, :, :p] = np.eye(p)
    # y[t] = x_1[t] with x_1[t] = sum_k a_k y[t-k] + b_k u[t-k] realises the ARX model with D = 0
    return A, B, C, np.zeros((R, p, m))


def _batched_lstsq(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """``argmin ||X theta - Y||`` for stacks ``X (R, T, k)``, ``Y (R, T, q)`` (QR, then a pseudo-inverse
    of the small triangle for a rank-deficient stack)."""
    Q, Rm = np.linalg.qr(X, mode="reduced")
    return np.linalg.pinv(Rm) @ (Q.transpose(0, 2, 1) @ Y)


def _solve_rows(lhs: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``Theta`` minimising ``||lhs - Theta rhs||_F`` for stacks (columns are samples)."""
    return _batched_lstsq(rhs.transpose(0, 2, 1), lhs.transpose(0, 2, 1)).transpose(0, 2, 1)


def _estimate(A: Any, B: Any, C: Any, D: Any, s: Any, n: int, i: int, method: str, single: bool) -> SubspaceEstimate:
    if single:
        A, B, C, D, s = A[0], B[0], C[0], D[0], s[0]
    return SubspaceEstimate(A=A, B=B, C=C, D=D, singular_values=s, order=int(n), block_rows=int(i), method=method)


def markov_parameters(A: Any, B: Any, C: Any, D: Any, L: int) -> np.ndarray:
    """The first ``L + 1`` Markov parameters ``h_0 = D``, ``h_k = C A^{k-1} B`` (``k = 1 .. L``).

    They are the impulse response of the plant, the same in every state basis. Leading batch axes
    broadcast; the result has shape ``(..., L + 1, p, m)``.
    """
    A, B, C, D = (np.asarray(M, dtype=float) for M in (A, B, C, D))
    L = check_int("L", L, minimum=1)
    out = [np.broadcast_to(D, np.broadcast_shapes(D.shape, (C @ B).shape))]
    X = B
    for _ in range(L):
        out.append(C @ X)
        X = A @ X
    return np.stack(out, axis=-3)


def markov_error(
    true: tuple[Any, Any, Any, Any], estimate: SubspaceEstimate | tuple[Any, Any, Any, Any], L: int = 20
) -> np.ndarray | float:
    """Basis-free estimation error: the relative squared error of the first ``L`` Markov parameters.

    ``e = sum_{k=0}^{L} ||h_k - h_hat_k||_F^2 / sum_{k=0}^{L} ||h_k||_F^2`` with
    ``h_k`` of :func:`markov_parameters`. It is invariant to the state basis of the estimate (a
    subspace method returns ``(T A T^-1, T B, C T^-1, D)`` for an arbitrary ``T``), it weighs
    what the plant does to inputs over ``L`` steps, and for ``C = I``, ``D = 0`` and small errors it
    ranks estimates like Definition def:error, which the state case keeps.

    Returns a float for one estimate, else an array over the batch.
    """
    if isinstance(estimate, SubspaceEstimate):
        estimate = (estimate.A, estimate.B, estimate.C, estimate.D)
    h = markov_parameters(true[0], true[1], true[2], true[3], L)
    h_hat = markov_parameters(estimate[0], estimate[1], estimate[2], estimate[3], L)
    num = np.sum((h_hat - h) ** 2, axis=(-3, -2, -1))
    den = float(np.sum(h**2))
    if den == 0.0:
        raise ParameterError("the true plant has zero Markov parameters: the relative error is undefined")
    e = num / den
    return float(e) if np.ndim(e) == 0 else e
