"""The plant ``(A, B)`` of eq:system as a value object, checked once (:class:`Plant`).

A :class:`Plant` holds read-only float64 copies of ``A`` (n x n) and ``B`` (n x m) with finite
real entries, and whether ``A`` is Schur stable (its spectral radius is computed once). Functions
that need a plant take one and trust it instead of re-checking raw matrices on every call
(python-control's ``StateSpace`` is the model).

A plant measured through sensors also holds an output matrix ``C`` (p x n) and the variance
``sigma_v2`` of its measurement noise, ``y[t] = C x[t] + v[t]``, ``v ~ N(0, sigma_v2 I)``; the
pair ``(A, C)`` must be observable (:func:`observable_order`). ``C = None`` (the default) means
the state itself is measured, as in the paper.

Base layer: imports only :mod:`encctl_gym.errors` and :mod:`encctl_gym._validation`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._validation import (
    as_finite_array,
    check_bool,
    check_nonnegative,
    check_schur_stable,
    check_system,
    format_value,
    spectral_radius,
)
from .errors import ParameterError, ShapeError

__all__ = ["Plant", "as_plant", "check_output_matrix", "observable_order", "OBSERVABILITY_RTOL"]

#: Relative tolerance of the observability rank test (:func:`observable_order`): a new direction
#: of the observable subspace counts when its singular value exceeds ``OBSERVABILITY_RTOL``
#: times ``max(||A||_2, ||C||_2)`` (the scale of the matrices the subspace is built from).
OBSERVABILITY_RTOL: float = 1e-9


def check_output_matrix(C: Any, n: int) -> np.ndarray:
    """``C`` as a ``(p, n)`` float64 matrix with finite real entries (a flat list of ``n`` numbers
    is one output).

    Raises
    ------
    ShapeError
        If ``C`` does not have ``n`` columns (the message gives its shape).
    ParameterError
        On non-finite, complex or non-numeric entries.
    """
    C = as_finite_array("C", C)
    if C.ndim == 1 and C.shape[0] == n:
        C = C.reshape(1, -1)
    if C.ndim != 2 or C.shape[1] != n:
        raise ShapeError(f"C must have shape (p, {n}) with p >= 1 to match A of shape ({n}, {n}), got {C.shape}")
    return C


def observable_order(A: np.ndarray, C: np.ndarray, rtol: float = OBSERVABILITY_RTOL) -> int:
    """Dimension of the observable subspace of ``(A, C)``: the rank of ``[C; C A; ...; C A^{n-1}]``.

    The rank is not read off the observability matrix itself, whose blocks ``C A^k`` shrink like
    ``rho(A)^k`` (a stable ``A`` with a small eigenvalue would look unobservable). Instead an
    orthonormal basis ``V`` of the row space is grown one Krylov step at a time: start from the
    right singular vectors of ``C``, then add the directions of ``A^T V`` orthogonal to ``V``
    (projected out twice) whose singular values exceed ``rtol * max(||A||_2, ||C||_2)``, until no
    direction is new. ``C`` is first divided by its largest entry (the order does not depend on
    the scale of the sensors: ``1e300 C`` and ``1e-300 C`` have the order of ``C``). Each step works on orthonormal vectors, so the test sees directions, not
    the decay of ``A^k``.
    """
    A = np.asarray(A, dtype=float)
    C = np.asarray(C, dtype=float)
    n = A.shape[0]
    # the rank does not depend on the scale of C: C is divided by its largest entry first, so
    # that C = 1e300 [1 0 1] and 1e-300 [1 0 1] see the directions [1 0 1] does
    peak = float(np.max(np.abs(C))) if C.size else 0.0
    if peak == 0.0:
        return 0
    C = C / peak
    tol = rtol * max(float(np.linalg.norm(A, 2)), float(np.linalg.norm(C, 2)))
    _, s, Vt = np.linalg.svd(C, full_matrices=False)
    V = Vt[s > tol].T  # (n, r)
    while 0 < V.shape[1] < n:
        W = A.T @ V
        for _ in range(2):
            W = W - V @ (V.T @ W)
        U, s, _ = np.linalg.svd(W, full_matrices=False)
        new = U[:, s > tol]
        if new.shape[1] == 0:
            break
        V = np.linalg.qr(np.hstack([V, new]))[0][:, : min(n, V.shape[1] + new.shape[1])]
    return int(V.shape[1])


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
    C : array_like, shape (p, n) (or (n,) for p = 1), optional
        Output matrix of ``y = C x + v``; ``None`` (default): the state is measured.
    sigma_v2 : float, default 0
        Measurement noise variance (>= 0); only meaningful with ``C``.

    Attributes
    ----------
    A, B : numpy.ndarray
        Read-only float64 copies.
    C : numpy.ndarray or None
        Read-only float64 copy of the output matrix, or ``None`` (state measured).
    sigma_v2 : float
        Measurement noise variance.
    n, m, p : int
        State, input and output dimensions (``p = n`` without ``C``).
    spectral_radius : float
        The largest modulus of the eigenvalues of ``A``.

    Raises
    ------
    ShapeError
        If ``A`` is not square or ``B`` does not have ``n`` rows.
    ShapeError
        If ``C`` does not have ``n`` columns.
    ParameterError
        On non-finite, complex or non-numeric entries; an unobservable ``(A, C)`` (the message
        gives the observable order, :func:`observable_order`); ``sigma_v2 < 0``.
    UnstableSystemError
        If ``stable`` and ``A`` is not Schur stable (the message gives the spectral radius).

    Examples
    --------
    >>> p = Plant([[0.5, 0.1], [0.0, 0.3]], [1.0, 0.5])
    >>> p.n, p.m
    (2, 1)
    """

    __slots__ = ("A", "B", "C", "sigma_v2", "spectral_radius")

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray | None
    sigma_v2: float
    spectral_radius: float

    def __init__(self, A: Any, B: Any, *, stable: bool = True, C: Any = None, sigma_v2: float = 0.0) -> None:
        A, B = check_system(A, B)
        sv = check_nonnegative("sigma_v2", sigma_v2)
        if C is not None:
            C = np.array(check_output_matrix(C, A.shape[0]), dtype=np.float64, order="C")
            order = observable_order(A, C)
            if order < A.shape[0]:
                raise ParameterError(
                    f"(A, C) is not observable: C of shape {C.shape} shows {order} of the {A.shape[0]} states "
                    f"(observability rank, relative tolerance {OBSERVABILITY_RTOL:g}); C = {format_value(C)}"
                )
            C.setflags(write=False)
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
        object.__setattr__(self, "C", C)
        object.__setattr__(self, "sigma_v2", sv)
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
    def p(self) -> int:
        """Output dimension (``n`` when the state is measured)."""
        return self.n if self.C is None else int(self.C.shape[0])

    @property
    def measures_state(self) -> bool:
        """Whether the state itself is measured (``C is None``)."""
        return self.C is None

    def output_matrix(self) -> np.ndarray:
        """``C``, or the identity when the state is measured."""
        return np.eye(self.n) if self.C is None else self.C

    @property
    def is_stable(self) -> bool:
        """Whether ``A`` is Schur stable."""
        return self.spectral_radius < 1.0

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Plant):
            return NotImplemented
        same_C = (self.C is None and other.C is None) or (
            self.C is not None and other.C is not None and np.array_equal(self.C, other.C)
        )
        return bool(
            np.array_equal(self.A, other.A) and np.array_equal(self.B, other.B) and same_C and self.sigma_v2 == other.sigma_v2
        )

    def __hash__(self) -> int:
        c = None if self.C is None else (self.C.shape, self.C.tobytes())
        return hash((self.A.shape, self.B.shape, self.A.tobytes(), self.B.tobytes(), c, self.sigma_v2))

    def __repr__(self) -> str:
        out = "" if self.C is None else f", p={self.p}, sigma_v2={self.sigma_v2:g}"
        return f"Plant(n={self.n}, m={self.m}{out}, spectral_radius={self.spectral_radius:.6g})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (_rebuild, (self.A, self.B, self.is_stable, self.C, self.sigma_v2))


def _rebuild(A: np.ndarray, B: np.ndarray, stable: bool, C: np.ndarray | None = None, sigma_v2: float = 0.0) -> Plant:
    return Plant(A, B, stable=stable, C=C, sigma_v2=sigma_v2)


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
