"""Shared input checks. Every public function validates through these, so that a bad value
always raises an error of :mod:`encctl_gym.errors` that names the value.
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np

from .errors import ParameterError, ShapeError, UnstableSystemError

__all__ = [
    "check_positive",
    "check_nonnegative",
    "check_int",
    "as_finite_array",
    "check_system",
    "spectral_radius",
    "check_schur_stable",
]


def _as_float(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"{name} must be a real number, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise ParameterError(f"{name} must be finite, got {value!r}")
    return v


def check_positive(name: str, value: Any) -> float:
    """Return ``value`` as a float, raising :class:`ParameterError` unless it is finite and > 0."""
    v = _as_float(name, value)
    if v <= 0:
        raise ParameterError(f"{name} must be > 0, got {value!r}")
    return v


def check_nonnegative(name: str, value: Any) -> float:
    """Return ``value`` as a float, raising :class:`ParameterError` unless it is finite and >= 0."""
    v = _as_float(name, value)
    if v < 0:
        raise ParameterError(f"{name} must be >= 0, got {value!r}")
    return v


def check_int(name: str, value: Any, minimum: int | None = None) -> int:
    """Return ``value`` as an int, raising :class:`ParameterError` for non-integers or values below ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, np.integer)):
        if isinstance(value, (float, np.floating)) and math.isfinite(value) and float(value).is_integer():
            value = int(value)
        else:
            raise ParameterError(f"{name} must be an integer, got {value!r}")
    v = int(value)
    if minimum is not None and v < minimum:
        raise ParameterError(f"{name} must be >= {minimum}, got {v}")
    return v


def as_finite_array(name: str, value: Any, ndim: int | None = None) -> np.ndarray:
    """Convert ``value`` to a float64 array with finite entries (and ``ndim`` dimensions if given)."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name} must be a numeric array, got {value!r}") from exc
    if ndim is not None and arr.ndim != ndim:
        raise ShapeError(f"{name} must have {ndim} dimension(s), got shape {arr.shape}")
    if arr.size == 0:
        raise ShapeError(f"{name} must not be empty, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"{name} must have finite entries, got {arr!r}")
    return arr


def check_system(A: Any, B: Any) -> tuple[np.ndarray, np.ndarray]:
    """Validate the plant matrices of eq:system: A is n x n, B is n x m, all entries finite."""
    A = as_finite_array("A", A)
    B = as_finite_array("B", B)
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ShapeError(f"A must be a square matrix, got shape {A.shape}")
    if B.ndim == 1 and A.shape[0] == B.shape[0]:
        B = B.reshape(-1, 1)
    if B.ndim != 2 or B.shape[0] != A.shape[0]:
        raise ShapeError(f"B must have shape ({A.shape[0]}, m) to match A of shape {A.shape}, got {B.shape}")
    return A, B


def spectral_radius(A: np.ndarray) -> float:
    """The largest modulus of the eigenvalues of ``A``."""
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def check_schur_stable(A: np.ndarray) -> float:
    """Raise :class:`UnstableSystemError` unless A is Schur stable; return its spectral radius."""
    rho = spectral_radius(A)
    if not rho < 1.0:
        raise UnstableSystemError(
            f"A must be Schur stable (spectral radius < 1), got spectral radius {rho:.6g}"
        )
    return rho
