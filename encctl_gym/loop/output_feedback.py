"""The controllers of a loop that measures outputs, and the one function the backends take theirs from.

With a sensor matrix ``C`` the plant side encrypts ``y[t] = C x[t] + v[t]`` instead of ``x[t]``, and
the encrypted controller of eq:ec runs on ``xi = y``. Two controllers are designed here:

* **static output feedback** ``u = Phi y`` (:func:`static_output_feedback`): the gain minimising
  the LQ cost ``J(Phi) = tr P(Phi)`` (``Q = I``, ``R = I``, unit initial covariance) over the
  stabilising static gains, by gradient descent with a backtracking (Armijo) step that keeps the
  closed loop stable (Levine and Athans' necessary conditions, discrete time). It starts from the
  better stabilising one of ``-K_lqr C^+`` (the LQR gain seen through the outputs; the optimum
  itself when ``C = I``) and ``0`` (stabilising whenever ``A`` is Schur stable, as every plant of
  the paper is). If neither stabilises, no gain is searched for and :class:`~encctl_gym.errors.SolverError`
  says so: static output feedback need not exist (the double integrator seen through its position).
* **a dynamic controller** ``x_c[t+1] = F x_c + G y``, ``u = H x_c + J y`` (:func:`lqg_controller`):
  the observer-based LQG controller (a Kalman predictor ``x_c = x_hat[t|t-1]`` with the LQR gain),
  evaluated as *one* encrypted linear map

      [x_c[t+1]; u[t]] = [[F, G], [H, J]] [x_c[t]; y[t]]

  whose input the plant side encrypts each period: it decrypts the controller's new state with
  the input and re-encrypts it with the next output, as encrypted dynamic controllers do.

:func:`loop_controller` is the one place the backends (:mod:`encctl_gym.loop.ideal`,
:mod:`encctl_gym.loop.elgamal`) take their controller from: without ``C`` it is the paper's
state feedback ``u = -K_lqr x`` (unchanged: the same matrix, bit for bit). :class:`OutputLoop`
closes the loop with a backend: it keeps the controller state between periods.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from .._validation import check_int, check_nonnegative, format_value, spectral_radius
from ..errors import ParameterError, SolverError
from .backend import lqr_gain

__all__ = [
    "CONTROLLERS",
    "LQG_MEASUREMENT_FLOOR",
    "OutputController",
    "OutputLoop",
    "controller_matrix",
    "lqg_controller",
    "loop_controller",
    "static_output_feedback",
]

#: The controllers of a loop with outputs, by the name of the environment's ``controller`` key.
CONTROLLERS: tuple[str, ...] = ("static", "lqg")

#: The Kalman predictor of :func:`lqg_controller` uses ``V = max(sigma_v2, LQG_MEASUREMENT_FLOOR * sigma_w2) I``:
#: with noise-free sensors the Riccati equation's ``V = 0`` would ask for an observer gain as large
#: as the plant allows, whose entries the encrypted controller must then quantise.
LQG_MEASUREMENT_FLOOR: float = 1e-2


@dataclass(frozen=True)
class OutputController:
    """``x_c[t+1] = F x_c + G y``, ``u = H x_c + J y`` (static when ``x_c`` is empty).

    Attributes
    ----------
    F, G, H, J : ndarray
        Shapes ``(n_c, n_c)``, ``(n_c, p)``, ``(m, n_c)``, ``(m, p)``.
    kind : str
        ``"state"`` (the paper's ``-K_lqr``, ``y = x``), ``"static"`` or ``"lqg"``.
    """

    F: np.ndarray
    G: np.ndarray
    H: np.ndarray
    J: np.ndarray
    kind: str

    @classmethod
    def static(cls, Phi: np.ndarray, kind: str = "static") -> OutputController:
        """The static gain ``u = Phi y``."""
        m, p = Phi.shape
        return cls(np.zeros((0, 0)), np.zeros((0, p)), np.zeros((m, 0)), np.asarray(Phi, dtype=float), kind)

    @property
    def n_c(self) -> int:
        """Controller state dimension (0 for a static gain)."""
        return int(self.F.shape[0])

    @property
    def matrix(self) -> np.ndarray:
        """The one linear map the encrypted controller evaluates, ``[[F, G], [H, J]]``, shape
        ``(n_c + m, n_c + p)`` (just ``J`` for a static gain)."""
        if self.n_c == 0:
            return self.J
        return np.block([[self.F, self.G], [self.H, self.J]])

    def closed_loop(self, A: np.ndarray, B: np.ndarray, C: np.ndarray) -> np.ndarray:
        """The closed-loop matrix on ``(x, x_c)`` (without noise): ``[[A + B J C, B H], [G C, F]]``."""
        return np.block([[A + B @ self.J @ C, B @ self.H], [self.G @ C, self.F]])


def _lq_cost(A: np.ndarray, B: np.ndarray, C: np.ndarray, F: np.ndarray) -> tuple[float, np.ndarray, np.ndarray] | None:
    """``(J, P, A_cl)`` of the static gain ``F`` (``Q = I``, ``R = I``), or ``None`` if it does not stabilise."""
    Acl = A + B @ F @ C
    if not spectral_radius(Acl) < 1.0:
        return None
    K = F @ C
    P = scipy.linalg.solve_discrete_lyapunov(Acl.T, np.eye(A.shape[0]) + K.T @ K)
    return float(np.trace(P)), P, Acl


def static_output_feedback(A: Any, B: Any, C: Any, *, max_iter: int = 500, tol: float = 1e-9) -> np.ndarray:
    """The LQ-optimal stabilising static output feedback ``u = Phi y`` (module docstring).

    Minimises ``J(Phi) = tr P`` with ``P = A_cl^T P A_cl + I + C^T Phi^T Phi C``,
    ``A_cl = A + B Phi C``. Its gradient is ``2 [(I + B^T P B) Phi C L C^T + B^T P A L C^T]`` with
    ``L = A_cl L A_cl^T + I``; each iteration moves towards the gain that zeroes it with ``P`` and
    ``L`` held (Moerder and Calise's iteration, ``Phi_+ = -(I + B^T P B)^{-1} B^T P A L C^T (C L
    C^T)^{-1}``), with a step halved until the closed loop stays stable and the cost decreases,
    and falls back to the negative gradient where that direction does not descend. It stops when
    the gradient's norm falls below ``tol (1 + ||Phi||)``, no step decreases the cost, or after
    ``max_iter`` iterations.

    Parameters
    ----------
    A, B, C : array_like
        Plant ``(n, n)``, ``(n, m)`` and sensors ``(p, n)``.
    max_iter : int
        Largest number of iterations.
    tol : float
        Relative stopping tolerance on the gradient.

    Returns
    -------
    ndarray, shape (m, p)

    Raises
    ------
    SolverError
        If neither ``-K_lqr C^+`` nor ``0`` stabilises the loop (no stabilising static gain was found).
    """
    A, B, C = (np.asarray(M, dtype=float) for M in (A, B, C))
    max_iter = check_int("max_iter", max_iter, minimum=0)
    # J depends on Phi C alone: the gain for C / s is s times the gain for C, so the iteration runs
    # on C scaled to its largest entry (C = 1e155 I would overflow C L C^T) and the gain is scaled back
    peak = float(np.max(np.abs(C))) if C.size else 0.0
    if peak == 0.0 or not np.isfinite(peak):
        raise ParameterError(f"C must have a finite nonzero entry, got {format_value(C)}")
    return _static_output_feedback(A, B, C / peak, max_iter, tol) / peak


def _static_output_feedback(A: np.ndarray, B: np.ndarray, C: np.ndarray, max_iter: int, tol: float) -> np.ndarray:
    """:func:`static_output_feedback` for a ``C`` whose largest entry is 1."""
    n, m = A.shape[0], B.shape[1]
    start = [-lqr_gain(A, B) @ np.linalg.pinv(C), np.zeros((m, C.shape[0]))]
    scored = [(cost, F) for F in start if (cost := _lq_cost(A, B, C, F)) is not None]
    if not scored:
        raise SolverError(
            f"no stabilising static output feedback found: neither -K_lqr C^+ nor 0 stabilises A + B Phi C "
            f"(spectral radius of A = {spectral_radius(A):.4g}); the plant may need a dynamic controller (controller='lqg')"
        )
    (J, P, Acl), F = min(scored, key=lambda s: s[0][0])
    for _ in range(max_iter):
        Lc = scipy.linalg.solve_discrete_lyapunov(Acl, np.eye(n))
        H = np.eye(m) + B.T @ P @ B
        grad = 2.0 * (H @ F @ C + B.T @ P @ A) @ Lc @ C.T
        if np.linalg.norm(grad) <= tol * (1.0 + float(np.linalg.norm(F))):
            break
        target = -np.linalg.solve(H, B.T @ P @ A @ Lc @ C.T) @ np.linalg.pinv(C @ Lc @ C.T)
        moved = False
        for direction in (target - F, -grad / max(float(np.linalg.norm(grad)), 1e-300)):
            step = 1.0
            while step > 1e-12:
                res = _lq_cost(A, B, C, F + step * direction)
                if res is not None and res[0] < J:
                    F, (J, P, Acl), moved = F + step * direction, res, True
                    break
                step *= 0.5
            if moved:
                break
        if not moved:
            break
    return F


def lqg_controller(A: Any, B: Any, C: Any, *, sigma_w2: float, sigma_v2: float) -> OutputController:
    """The observer-based LQG controller as ``(F, G, H, J)`` (module docstring).

    ``K`` is the LQR gain (``Q = I``, ``R = I``, :func:`~encctl_gym.loop.backend.lqr_gain`);
    ``L = A S C^T (C S C^T + V)^{-1}`` the Kalman predictor gain, ``S`` solving the filter Riccati
    equation with ``W = sigma_w2 I`` and ``V = max(sigma_v2, LQG_MEASUREMENT_FLOOR sigma_w2) I``.
    Then ``F = A - B K - L C``, ``G = L``, ``H = -K``, ``J = 0``; by the separation principle
    the closed loop has the eigenvalues of ``A - B K`` and of ``A - L C``.
    """
    A, B, C = (np.asarray(M, dtype=float) for M in (A, B, C))
    sw = check_nonnegative("sigma_w2", sigma_w2)
    sv = check_nonnegative("sigma_v2", sigma_v2)
    n, p = A.shape[0], C.shape[0]
    # the filter for y = C x + v is the filter for y / s = (C / s) x + v / s with its gain scaled
    # by 1 / s: it runs on C scaled to its largest entry (C = 1e155 I would overflow C S C^T)
    peak = float(np.max(np.abs(C))) if C.size else 0.0
    if peak == 0.0 or not np.isfinite(peak):
        raise ParameterError(f"C must have a finite nonzero entry, got {format_value(C)}")
    Cs = C / peak
    V = max(max(sv, LQG_MEASUREMENT_FLOOR * sw) / peak / peak, np.finfo(float).tiny) * np.eye(p)
    W = max(sw, np.finfo(float).tiny) * np.eye(n)
    try:
        S = scipy.linalg.solve_discrete_are(A.T, Cs.T, W, V)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise SolverError(f"the Kalman predictor's Riccati equation has no stabilising solution ({exc})") from None
    L = A @ S @ Cs.T @ np.linalg.inv(Cs @ S @ Cs.T + V) / peak
    K = lqr_gain(A, B)
    return OutputController(A - B @ K - L @ C, L, -K, np.zeros((B.shape[1], p)), "lqg")


_CONTROLLER_CACHE: dict[tuple[Any, ...], OutputController] = {}


def loop_controller(params: Any) -> OutputController:
    """The controller of the loop of ``params`` (the one function both backends take it from).

    ``params.C`` is ``None`` (or absent): the paper's state feedback ``-K_lqr`` on ``xi = x``.
    Otherwise ``params.controller`` picks :func:`static_output_feedback` (``"static"``) or
    :func:`lqg_controller` (``"lqg"``) for ``(A, B, C)``.
    """
    C = getattr(params, "C", None)
    if C is None:
        return OutputController.static(-lqr_gain(params.A, params.B), kind="state")
    kind = getattr(params, "controller", "static")
    sv = float(getattr(params, "sigma_v2", 0.0))
    A, B, C = (np.ascontiguousarray(M, dtype=float) for M in (params.A, params.B, C))
    key = (kind, A.shape, B.shape, C.shape, A.tobytes(), B.tobytes(), C.tobytes(), float(params.sigma_w2), sv)
    if key in _CONTROLLER_CACHE:  # the backend and the episode design the same controller once
        return _CONTROLLER_CACHE[key]
    if kind == "static":
        ctrl = OutputController.static(static_output_feedback(A, B, C))
    elif kind == "lqg":
        ctrl = lqg_controller(A, B, C, sigma_w2=params.sigma_w2, sigma_v2=sv)
    else:
        raise ParameterError(f"unknown controller {format_value(kind)}; choose one of {', '.join(CONTROLLERS)}")
    if len(_CONTROLLER_CACHE) > 64:
        _CONTROLLER_CACHE.clear()
    _CONTROLLER_CACHE[key] = ctrl
    return ctrl


def controller_matrix(params: Any) -> np.ndarray:
    """The matrix the encrypted controller evaluates (:attr:`OutputController.matrix` of :func:`loop_controller`)."""
    return loop_controller(params).matrix


class OutputLoop:
    """The closed loop of a plant measured through outputs, around a backend (batched like it).

    Each period the plant side encrypts ``xi = [x_c; y]``, the server evaluates
    ``[[F, G], [H, J]] xi`` (eq:ec), and the plant side decrypts the controller's next state and
    the input (:meth:`control`); the next period re-encrypts that state with the next output.

    Parameters
    ----------
    backend : LoopBackend
        Built for the same parameters (its matrix is :func:`controller_matrix` of them).
    controller : OutputController
        :func:`loop_controller` of those parameters.
    """

    def __init__(self, backend: Any, controller: OutputController) -> None:
        self.backend = backend
        self.controller = controller
        self.x_c: np.ndarray = np.zeros((1, controller.n_c))

    def start(self, K: int = 1) -> None:
        """A new episode of the backend; the controller state of ``K`` copies starts at 0."""
        self.backend.start_episode()
        self.x_c = np.zeros((K, self.controller.n_c))

    def collect(self, y: np.ndarray) -> np.ndarray:
        """What deciphering the period's ciphertexts reveals of the outputs: ``Dcd(Ecd(y))`` (K, p).

        The plant side encrypts the controller's input ``[x_c; y]`` (with a dynamic controller the
        state it decrypted last, frozen once the attack replaces the controller's output); the
        adversary keeps the outputs."""
        y = np.atleast_2d(np.asarray(y, dtype=np.float64))
        n_c = self.controller.n_c
        if n_c == 0:
            return self.backend.collect_state(y)
        return self.backend.collect_state(np.concatenate([self.x_c, y], axis=1))[:, n_c:]

    def inject(self, a: np.ndarray) -> np.ndarray:
        """The input the plant applies when the adversary forges ``a`` (K, m).

        The plant side decrypts an output of the controller's full shape; with a dynamic
        controller the adversary forges its state rows as zeros (the plant's controller state
        becomes ``Dcd`` of a forged 0) and the input rows as ``a``."""
        n_c = self.controller.n_c
        if n_c == 0:
            return self.backend.inject(a)
        psi = self.backend.inject(np.concatenate([np.zeros((a.shape[0], n_c)), a], axis=1))
        self.x_c = np.array(psi[:, :n_c])
        return np.array(psi[:, n_c:])

    def control(self, y: np.ndarray) -> np.ndarray:
        """One period of normal operation on the outputs ``y`` (K, p): the input ``u`` (K, m)."""
        y = np.atleast_2d(np.asarray(y, dtype=np.float64))
        psi = self.backend.control(np.concatenate([self.x_c, y], axis=1) if self.controller.n_c else y)
        n_c = self.controller.n_c
        self.x_c = np.array(psi[:, :n_c])
        return np.array(psi[:, n_c:])
