"""The plant ``(A, B)`` of eq:system as a value object, checked once (:class:`Plant`).

A :class:`Plant` holds read-only float64 copies of ``A`` (n x n) and ``B`` (n x m) with finite
real entries, and whether ``A`` is Schur stable (its spectral radius is computed once). Functions
that need a plant take one and trust it instead of re-checking raw matrices on every call.
There is room for an output matrix ``C`` and noise covariances later (python-control's
``StateSpace`` is the model).

Base layer: imports only :mod:`encctl_gym.errors` and :mod:`encctl_gym._validation`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._validation import check_bool, check_schur_stable, check_system, format_value, spectral_radius
from .errors import ParameterError

__all__ = ["Plant", "as_plant"]


class Plant:
    """The linear plant ``x_{t+1} = A x_t + B u_t + w_t`` of eq:system, checked once.

    Parameters
    ----------
    A : array_like, shape (n, n)
        System matrix, finite real entries.
    B : array_like, shape (n, m) (or (n,) for m = 1)
        Input matrix, finite real entries.
    stable : bool, default True
        Require ``A`` to be Schur stable (spectral radius < 1), as every complexity of the paper
        (Theorem thm:sic) does. ``False`` accepts any ``A`` (simulation); :attr:`is_stable`
        still tells.

    Attributes
    ----------
    A, B : numpy.ndarray
        Read-only float64 copies.
    n, m : int
        State and input dimensions.
    spectral_radius : float
        The largest modulus of the eigenvalues of ``A``.

    Raises
    ------
    ShapeError
        If ``A`` is not square or ``B`` does not have ``n`` rows.
    ParameterError
        On non-finite, complex or non-numeric entries.
    UnstableSystemError
        If ``stable`` and ``A`` is not Schur stable (the message gives the spectral radius).

    Examples
    --------
    >>> p = Plant([[0.5, 0.1], [0.0, 0.3]], [1.0, 0.5])
    >>> p.n, p.m
    (2, 1)
    """

    __slots__ = ("A", "B", "spectral_radius")

    A: np.ndarray
    B: np.ndarray
    spectral_radius: float

    def __init__(self, A: Any, B: Any, *, stable: bool = True) -> None:
        A, B = check_system(A, B)
        A = np.array(A, dtype=np.float64, order="C")  # own copies: the caller's arrays stay theirs
        B = np.array(B, dtype=np.float64, order="C")
        if check_bool("stable", stable):
            rho = check_schur_stable(A)
        else:
            rho = spectral_radius(A)
        A.setflags(write=False)
        B.setflags(write=False)
        object.__setattr__(self, "A", A)
        object.__setattr__(self, "B", B)
        object.__setattr__(self, "spectral_radius", float(rho))

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"Plant is immutable; build a new one instead of setting {name!r}")

    @property
    def n(self) -> int:
        """State dimension."""
        return int(self.A.shape[0])

    @property
    def m(self) -> int:
        """Input dimension."""
        return int(self.B.shape[1])

    @property
    def is_stable(self) -> bool:
        """Whether ``A`` is Schur stable."""
        return self.spectral_radius < 1.0

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Plant):
            return NotImplemented
        return bool(np.array_equal(self.A, other.A) and np.array_equal(self.B, other.B))

    def __hash__(self) -> int:
        return hash((self.A.shape, self.B.shape, self.A.tobytes(), self.B.tobytes()))

    def __repr__(self) -> str:
        return f"Plant(n={self.n}, m={self.m}, spectral_radius={self.spectral_radius:.6g})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (_rebuild, (self.A, self.B, self.is_stable))


def _rebuild(A: np.ndarray, B: np.ndarray, stable: bool) -> Plant:
    return Plant(A, B, stable=stable)


def as_plant(plant: Any, *, stable: bool = True) -> Plant:
    """A :class:`Plant` from a plant (returned as it is, after the stability requirement) or from
    a pair ``(A, B)``.

    Raises
    ------
    ShapeError, ParameterError, UnstableSystemError
        As :class:`Plant`; ParameterError also for anything that is neither.
    """
    if isinstance(plant, Plant):
        if check_bool("stable", stable) and not plant.is_stable:
            check_schur_stable(plant.A)  # raises with the spectral radius
        return plant
    if isinstance(plant, tuple) and len(plant) == 2:
        return Plant(*plant, stable=stable)
    raise ParameterError(f"plant must be a Plant or a pair (A, B), got {format_value(plant)}")
