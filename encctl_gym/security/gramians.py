"""Controllability Gramians of the plant eq:system (Theorem thm:sic).

``Psi_u`` is the Gramian of the input channel and ``Psi_w`` that of the noise channel:

.. math::

    A \\Psi_u A^\\top - \\Psi_u + B B^\\top = 0, \\qquad A \\Psi_w A^\\top - \\Psi_w + I = 0.

Both exist (and are unique, symmetric, positive semidefinite) only for a Schur-stable ``A``;
an unstable ``A`` raises :class:`~encctl_gym.errors.UnstableSystemError` naming its spectral
radius.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.linalg

from .._validation import as_finite_array, check_schur_stable, check_system, format_value
from ..errors import ParameterError, ShapeError, SolverError

__all__ = ["controllability_gramian", "noise_gramian", "solve_gramian"]


def solve_gramian(A: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """Solve the discrete Lyapunov equation ``A X A^T - X + Q = 0`` for a Schur-stable ``A``.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        Schur-stable system matrix (checked).
    Q : ndarray, shape (n, n)
        Symmetric right-hand side.

    Returns
    -------
    ndarray, shape (n, n)
        The symmetric solution ``X = sum_k A^k Q (A^k)^T``.

    Raises
    ------
    UnstableSystemError
        If ``A`` is not Schur stable (the message names the spectral radius).
    SolverError
        If the solution is not finite or does not satisfy the equation.
    """
    A = as_finite_array("A", A, ndim=2)
    Q = as_finite_array("Q", Q, ndim=2)
    if A.shape[0] != A.shape[1] or Q.shape != A.shape:
        raise ShapeError(f"A must be square and Q of the same shape, got A {A.shape} and Q {Q.shape}")
    check_schur_stable(A)
    X = scipy.linalg.solve_discrete_lyapunov(A, Q)
    X = 0.5 * (X + X.T)
    if not np.all(np.isfinite(X)):
        raise SolverError("the discrete Lyapunov solution is not finite (A too close to instability?)")
    # ||A X A^T - X + Q||_F <= 1e-8 max(1, ||X||_F, ||Q||_F), both sides divided by c so that the
    # norms cannot overflow for entries near 1e300
    c = max(1.0, float(np.max(np.abs(X))), float(np.max(np.abs(Q))))
    resid = np.linalg.norm((A @ X @ A.T - X + Q) / c)
    scale = max(1.0 / c, float(np.linalg.norm(X / c)), float(np.linalg.norm(Q / c)))
    if resid > 1e-8 * scale:
        raise SolverError(f"the discrete Lyapunov solve is inaccurate: residual {resid * c:.3g}")
    return X


def controllability_gramian(A: Any, B: Any) -> np.ndarray:
    """Input Gramian ``Psi_u`` of Theorem thm:sic: ``A Psi_u A^T - Psi_u + B B^T = 0``.

    Parameters
    ----------
    A : array_like, shape (n, n)
        Schur-stable system matrix of eq:system.
    B : array_like, shape (n, m)
        Input matrix of eq:system (a 1-D array of length n is read as one column).

    Returns
    -------
    ndarray, shape (n, n)
        ``Psi_u = sum_{k>=0} A^k B B^T (A^k)^T`` (symmetric, positive semidefinite).

    Raises
    ------
    ShapeError
        If the shapes of ``A`` and ``B`` do not fit.
    UnstableSystemError
        If ``A`` is not Schur stable.
    ParameterError
        If ``B B^T`` overflows float64.

    Examples
    --------
    For ``A = a I`` and ``B = b I``, ``Psi_u = b^2 / (1 - a^2) I``.
    """
    A, B = check_system(A, B)
    with np.errstate(over="ignore", invalid="ignore"):
        Q = B @ B.T
    if not np.all(np.isfinite(Q)):
        raise ParameterError(
            f"B B^T overflows float64: B has entries up to {format_value(float(np.max(np.abs(B))))} in magnitude "
            "(the Gramian needs |B| well below 1e154)"
        )
    return solve_gramian(A, Q)


def noise_gramian(A: Any) -> np.ndarray:
    """Noise Gramian ``Psi_w`` of Theorem thm:sic: ``A Psi_w A^T - Psi_w + I = 0``.

    Parameters
    ----------
    A : array_like, shape (n, n)
        Schur-stable system matrix of eq:system.

    Returns
    -------
    ndarray, shape (n, n)
        ``Psi_w = sum_{k>=0} A^k (A^k)^T`` (symmetric, ``Psi_w >= I``).

    Raises
    ------
    ShapeError
        If ``A`` is not square.
    UnstableSystemError
        If ``A`` is not Schur stable.
    """
    A = as_finite_array("A", A)
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ShapeError(f"A must be a square matrix, got shape {A.shape}")
    return solve_gramian(A, np.eye(A.shape[0]))
