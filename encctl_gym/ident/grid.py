"""The estimation error ``epsilon(N)`` of Definition def:error on a grid of sample sizes.

:func:`identification_errors` scores least squares (:func:`.least_squares.prefix_estimates`,
the default) or any estimator of the registry (:mod:`.registry`) on every prefix ``N`` of a
grid, from one trajectory per run. It sits above the estimators and their registry, so none of
them imports it.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from .._validation import as_finite_array, check_system
from ..errors import ParameterError, ShapeError
from .error import estimation_error
from .estimator import estimate_errors
from .least_squares import prefix_estimates
from .registry import make_estimator

__all__ = ["identification_errors"]


def identification_errors(
    x: Any, u: Any, A: Any, B: Any, sample_sizes: Any, *, method: Literal["auto", "gram", "qr"] = "auto", estimator: Any = None
) -> np.ndarray:
    """The estimation error ``epsilon(N)`` of Definition def:error on a grid of ``N``.

    ``epsilon(N) = ||[A B] - [A_hat B_hat]||_F^2 / (n (n + m))`` where ``[A_hat B_hat]`` is the
    estimate on the first ``N`` pairs of each trajectory: by default the least-squares estimate
    eq:estimate from :func:`prefix_estimates` (one pass over the data, no re-solve from scratch
    per ``N``), else the ``prefix_estimates`` of the given estimator
    (:mod:`encctl_gym.ident.registry`); the error from
    :func:`encctl_gym.ident.error.estimation_error`.

    Parameters
    ----------
    x : array_like, shape (runs, N_max, n) or (N_max, n)
        States ``x_{t_s}, x_{t_s+1}, ...``.
    u : array_like, shape (runs, N_max or N_max - 1, m) or (N_max or N_max - 1, m)
        Inputs.
    A, B : array_like
        The true system of eq:system.
    sample_sizes : array_like of int
        Strictly increasing, each ``<= N_max`` and at least the estimator's minimum sample
        size (``n + m + 1`` for least squares).
    method
        ``"auto"`` (default), ``"gram"`` or ``"qr"``: the least-squares solver (see
        :func:`prefix_estimates`); only with the default estimator.
    estimator : str, mapping or Estimator, optional
        Anything :func:`encctl_gym.ident.registry.make_estimator` takes. ``None`` (default) is
        least squares, with exactly the numbers of :func:`prefix_estimates`.

    Returns
    -------
    numpy.ndarray, shape (runs, K) (or (K,) for 2-D input)
        NaN where the estimator has no estimate (see the estimator).

    Raises
    ------
    ParameterError, ShapeError
        On a bad system, bad data, bad grid or bad estimator.
    """
    A, B = check_system(A, B)
    x_arr = as_finite_array("x", x)
    u_arr = as_finite_array("u", u)
    n, m = A.shape[0], B.shape[1]
    if x_arr.shape[-1] != n or u_arr.shape[-1] != m:
        raise ShapeError(f"data dimensions (n={x_arr.shape[-1]}, m={u_arr.shape[-1]}) do not match the system (n={n}, m={m})")
    if estimator is not None:
        est = make_estimator(estimator)
        if method != "auto":
            raise ParameterError(
                f"method={method!r} is the least-squares solver; pass it to the estimator instead "
                "(make_estimator('ls', method=...))"
            )
        return estimate_errors(est.prefix_estimates(x_arr, u_arr, sample_sizes), A, B)
    theta = prefix_estimates(x_arr, u_arr, sample_sizes, method=method)
    return np.asarray(estimation_error(A, B, theta[..., :n], theta[..., n:]), dtype=np.float64)
