"""The plant of eq:system and its batched Monte Carlo simulation.

The plant is ``x_{t+1} = A x_t + B u_t + w_t`` (eq:system) with ``x_0 ~ N(0, sigma_x2 I)`` and
``w_t ~ N(0, sigma_w2 I)`` i.i.d. The paper's attacker (Definition def:adversary, Theorem
thm:sic) injects i.i.d. Gaussian inputs ``u_t ~ N(0, sigma_u2 I)`` and records ``N`` pairs
``(u_t, x_t)`` for ``t = t_s, ..., t_f`` (``N = t_f - t_s + 1``).

Arrays are laid out ``(runs, time, dim)``: ``states[r, k]`` is ``x_{t_s + k}`` of run ``r``.
(:mod:`encctl_gym.ident.least_squares` turns them into the paper's column-per-time data
matrices.)

Randomness: every simulation is driven by a :class:`numpy.random.SeedSequence`; run ``r`` uses
its own child ``SeedSequence(seed).spawn(runs)[r]``, with separate streams for the initial
state, the noise and the input, so

* a result is reproducible from one integer,
* run ``r`` does not depend on how many runs are simulated with it, and
* the trajectory of length ``N`` is a prefix of the trajectory of length ``N' > N``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_nonnegative, check_positive, check_system, format_value
from ..errors import ParameterError, ShapeError
from ..parallel import SeedLike, as_seed_sequence
from ..resources import check_memory

Size = int | tuple[int, ...] | None
"""A batch shape for drawn states and noise (``None``: one draw)."""

__all__ = ["LinearPlant", "SimulationResult", "SeedLike", "as_seed_sequence", "simulate", "simulate_gaussian_attack"]


def _size_tuple(size: Size) -> tuple[int, ...]:
    if size is None:
        return ()
    if isinstance(size, (int, np.integer)):  # check_int refuses a bool
        return (check_int("size", size, minimum=0),)
    return tuple(check_int("size", s, minimum=0) for s in size)


class LinearPlant:
    """The linear plant ``x_{t+1} = A x_t + B u_t + w_t`` of eq:system.

    Parameters
    ----------
    A : array_like, shape (n, n)
        System matrix (finite entries). Stability is not required for simulation; the
        paper's complexity (Theorem thm:sic) needs a Schur-stable ``A``, which
        :mod:`encctl_gym.security` checks.
    B : array_like, shape (n, m) (or (n,) for m = 1)
        Input matrix.
    sigma_w2 : float
        Variance of the process noise, ``w_t ~ N(0, sigma_w2 I)``; must be > 0.
    sigma_x2 : float, default 1.0
        Variance of the initial state, ``x_0 ~ N(0, sigma_x2 I)``; must be >= 0. Kept separate
        from ``sigma_w2`` as in eq:sic (the paper's simulations use ``sigma_x2 = 1``).

    Raises
    ------
    ShapeError
        If ``A`` is not square or ``B`` does not have ``n`` rows.
    ParameterError
        On non-finite entries, ``sigma_w2 <= 0`` or ``sigma_x2 < 0``.

    Notes
    -----
    :meth:`next_state`, :meth:`initial_state` and :meth:`noise` do no validation so that a
    step-by-step caller (the Gymnasium environment) pays only for a few small numpy ops.
    """

    __slots__ = ("A", "B", "sigma_w2", "sigma_x2", "n", "m", "_AT", "_BT", "_sw", "_sx")

    def __init__(self, A: Any, B: Any, *, sigma_w2: float, sigma_x2: float = 1.0) -> None:
        A, B = check_system(A, B)
        self.A: np.ndarray = A
        self.B: np.ndarray = B
        self.sigma_w2: float = check_positive("sigma_w2", sigma_w2)
        self.sigma_x2: float = check_nonnegative("sigma_x2", sigma_x2)
        self.n: int = A.shape[0]
        self.m: int = B.shape[1]
        self.A.setflags(write=False)
        self.B.setflags(write=False)
        self._AT = np.ascontiguousarray(A.T)
        self._BT = np.ascontiguousarray(B.T)
        self._sw = float(np.sqrt(self.sigma_w2))
        self._sx = float(np.sqrt(self.sigma_x2))

    def __repr__(self) -> str:
        return f"LinearPlant(n={self.n}, m={self.m}, sigma_w2={self.sigma_w2:g}, sigma_x2={self.sigma_x2:g})"

    def initial_state(self, rng: np.random.Generator, size: Size = None) -> np.ndarray:
        """Draw ``x_0 ~ N(0, sigma_x2 I)`` (eq:system): shape ``(*size, n)``, one state for ``size=None``."""
        return self._sx * rng.standard_normal((*_size_tuple(size), self.n))

    def noise(self, rng: np.random.Generator, size: Size = None) -> np.ndarray:
        """Draw process noise ``w_t ~ N(0, sigma_w2 I)`` (eq:system): shape ``(*size, n)``, as :meth:`initial_state`."""
        return self._sw * rng.standard_normal((*_size_tuple(size), self.n))

    def next_state(self, x: np.ndarray, u: np.ndarray, w: np.ndarray) -> np.ndarray:
        """One step of eq:system, ``x_{t+1} = A x_t + B u_t + w_t``.

        Parameters
        ----------
        x : numpy.ndarray, shape (..., n)
        u : numpy.ndarray, shape (..., m)
        w : numpy.ndarray, shape (..., n)
            Batched over (broadcast) leading dimensions.

        Returns
        -------
        numpy.ndarray, shape (..., n)
        """
        return x @ self._AT + u @ self._BT + w


@dataclass(frozen=True)
class SimulationResult:
    """Trajectories of eq:system, laid out ``(runs, time, dim)``.

    Attributes
    ----------
    states : numpy.ndarray, shape (runs, N, n)
        ``x_{t_s}, ..., x_{t_f}``.
    inputs : numpy.ndarray, shape (runs, N, m)
        ``u_{t_s}, ..., u_{t_f}`` (the last input does not enter the data matrices).
    noises : numpy.ndarray, shape (runs, N - 1, n)
        ``w_{t_s}, ..., w_{t_f - 1}`` (the matrix ``W_p`` of eq:data, time along axis 1).
    """

    states: np.ndarray
    inputs: np.ndarray
    noises: np.ndarray

    @property
    def runs(self) -> int:
        """Number of independent runs."""
        return self.states.shape[0]

    @property
    def N(self) -> int:
        """Sample size, the number of pairs ``(u_t, x_t)`` per run."""
        return self.states.shape[1]


def _propagate(plant: LinearPlant, x0: np.ndarray, inputs: np.ndarray, noises: np.ndarray) -> np.ndarray:
    """Run eq:system over time, vectorised over runs: ``x0`` (R, n), inputs (R, N, m), noises (R, N-1, n)."""
    R, N, _ = inputs.shape
    states = np.empty((R, N, plant.n))
    states[:, 0] = x0
    if N > 1:
        # The exogenous drive B u_t + w_t for all t at once; only A x_t is sequential.
        drive = inputs[:, :-1] @ plant._BT
        drive += noises
        AT = plant._AT
        x = states[:, 0]
        for t in range(N - 1):
            x = x @ AT
            x += drive[:, t]
            states[:, t + 1] = x
    return states


def simulate(plant: LinearPlant, inputs: Any, rng: np.random.Generator | SeedLike, *, x0: Any | None = None) -> SimulationResult:
    """Simulate eq:system driven by given inputs, batched over runs.

    Parameters
    ----------
    plant
        The plant.
    inputs : array_like, shape (N, m) or (runs, N, m)
        ``u_{t_s}, ..., u_{t_f}``.
    rng
        A :class:`numpy.random.Generator`, or a seed from which one is made; the initial
        state (unless ``x0`` is given) and the noise are drawn from it.
    x0 : array_like, shape (n,) or (runs, n), optional
        The state ``x_{t_s}``; default ``x_0 ~ N(0, sigma_x2 I)``.

    Returns
    -------
    SimulationResult
        With a leading ``runs`` axis of 1 if ``inputs`` was 2-D.

    Raises
    ------
    ShapeError
        If ``inputs`` or ``x0`` have the wrong shape.
    ParameterError
        If they have non-finite entries.
    """
    if not isinstance(plant, LinearPlant):
        raise ParameterError(f"plant must be a LinearPlant, got {type(plant).__name__}")
    u = as_finite_array("inputs", inputs)
    if u.ndim == 2:
        u = u[None]
    if u.ndim != 3 or u.shape[2] != plant.m:
        raise ShapeError(f"inputs must have shape (N, {plant.m}) or (runs, N, {plant.m}), got {np.shape(inputs)}")
    if not isinstance(rng, np.random.Generator):
        rng = np.random.default_rng(as_seed_sequence(rng))
    R, N, _ = u.shape
    if x0 is None:
        x_init = plant.initial_state(rng, R)
    else:
        x_init = as_finite_array("x0", x0)
        if x_init.shape not in ((plant.n,), (R, plant.n)):
            raise ShapeError(f"x0 must have shape ({plant.n},) or ({R}, {plant.n}), got {x_init.shape}")
        x_init = np.broadcast_to(x_init, (R, plant.n))
    w = plant.noise(rng, (R, N - 1))
    return SimulationResult(states=_propagate(plant, x_init, u, w), inputs=u, noises=w)


def simulate_gaussian_attack(plant: LinearPlant, *, N: int, runs: int, sigma_u2: float, seed: SeedLike) -> SimulationResult:
    """Simulate the paper's attacker: i.i.d. Gaussian inputs ``u_t ~ N(0, sigma_u2 I)``.

    This is the data-collection step of Definition def:adversary under the input
    distribution of Theorem thm:sic, with ``t_s = 0`` (``x_{t_s} = x_0 ~ N(0, sigma_x2 I)``).

    Parameters
    ----------
    plant
        The plant of eq:system.
    N
        Sample size, the number of pairs ``(u_t, x_t)`` per run (>= 1).
    runs
        Number of independent runs (>= 1).
    sigma_u2
        Input variance (>= 0).
    seed
        Integer or :class:`numpy.random.SeedSequence`. Run ``r`` draws from
        ``SeedSequence(seed).spawn(runs)[r]`` (independent streams for ``x_0``, ``w`` and
        ``u``), so run ``r`` is the same whatever ``runs`` is, and a shorter ``N`` gives a
        prefix of the same trajectory.

    Returns
    -------
    SimulationResult
        ``states`` (runs, N, n), ``inputs`` (runs, N, m), ``noises`` (runs, N-1, n).

    Raises
    ------
    ParameterError
        For ``N < 1``, ``runs < 1`` or a negative or non-finite ``sigma_u2``.
    """
    if not isinstance(plant, LinearPlant):
        raise ParameterError(f"plant must be a LinearPlant, got {type(plant).__name__}")
    N = check_int("N", N, minimum=1)
    runs = check_int("runs", runs, minimum=1)
    su = float(np.sqrt(check_nonnegative("sigma_u2", sigma_u2)))
    n, m = plant.n, plant.m
    check_memory(
        f"a Gaussian attack of runs = {format_value(runs)} trajectories of N = {format_value(N)} samples (n = {n}, m = {m})",
        2 * 8 * runs * (N * (2 * n + m) + n),  # noise, inputs and states, and as much again while they are made
        advice="use fewer runs or a shorter N",
    )
    n, m = plant.n, plant.m
    x0 = np.empty((runs, n))
    w = np.empty((runs, N - 1, n))
    u = np.empty((runs, N, m))
    for r, child in enumerate(as_seed_sequence(seed).spawn(runs)):
        s_x, s_w, s_u = (np.random.default_rng(s) for s in child.spawn(3))
        x0[r] = plant._sx * s_x.standard_normal(n)
        w[r] = plant._sw * s_w.standard_normal((N - 1, n))
        u[r] = su * s_u.standard_normal((N, m))
    return SimulationResult(states=_propagate(plant, x0, u, w), inputs=u, noises=w)
