"""The estimation error of Definition def:error.

``epsilon(N) = ||[A B] - [A_hat B_hat]||_F^2 / c`` with ``c = n (n + m)``, the number of entries of
``A`` and ``B``: the mean square error of an estimate of the plant of eq:system. Every estimator
of :mod:`encctl_gym.ident` is scored by it, and the sample identifying complexities of
:mod:`encctl_gym.security.complexity` bound its expectation from below.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import as_finite_array, check_system
from ..errors import ShapeError

__all__ = ["estimation_error"]


def estimation_error(A: Any, B: Any, A_hat: Any, B_hat: Any) -> float | np.ndarray:
    """Estimation error of Definition def:error.

    ``epsilon = ||[A B] - [A_hat B_hat]||_F^2 / (n (n + m))``.

    Parameters
    ----------
    A, B : array_like, shapes (n, n) and (n, m)
        True plant matrices of eq:system.
    A_hat, B_hat : array_like, shapes (..., n, n) and (..., n, m)
        Estimates (e.g. from eq:estimate); leading batch dimensions broadcast against each
        other.

    Returns
    -------
    float or ndarray
        A float for unbatched estimates, else an array of the broadcast batch shape.

    Raises
    ------
    ShapeError
        If the trailing shapes of the estimates do not match ``A`` and ``B``.
    """
    A, B = check_system(A, B)
    n, m = B.shape
    A_hat = as_finite_array("A_hat", A_hat)
    B_hat = as_finite_array("B_hat", B_hat)
    if B_hat.ndim == 1 and m == 1 and B_hat.shape[0] == n:
        B_hat = B_hat.reshape(n, 1)
    if A_hat.ndim < 2 or A_hat.shape[-2:] != (n, n):
        raise ShapeError(f"A_hat must have shape (..., {n}, {n}), got {A_hat.shape}")
    if B_hat.ndim < 2 or B_hat.shape[-2:] != (n, m):
        raise ShapeError(f"B_hat must have shape (..., {n}, {m}), got {B_hat.shape}")
    try:
        batch = np.broadcast_shapes(A_hat.shape[:-2], B_hat.shape[:-2])
    except ValueError as exc:
        raise ShapeError(f"batch shapes of A_hat {A_hat.shape[:-2]} and B_hat {B_hat.shape[:-2]} do not broadcast") from exc
    ea = np.sum((A_hat - A) ** 2, axis=(-2, -1))
    eb = np.sum((B_hat - B) ** 2, axis=(-2, -1))
    err = np.broadcast_to(ea + eb, batch) / (n * (n + m))
    return float(err) if batch == () else np.array(err)
