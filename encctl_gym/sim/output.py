"""Monte Carlo of identification from outputs: the paper's Gaussian attack, measured through
``y = C x + v``, identified by a subspace method or ARX, scored by the Markov-parameter error.

The trajectories are the engine's own (:func:`~encctl_gym.sim.plant.simulate_gaussian_attack`,
the same seed gives the same states as the state-measured experiments); the outputs add the
measurement noise ``v ~ N(0, sigma_v2 I)`` from a stream of its own. The attacker sees only its
inputs and ``y``. With ``C = I`` and ``sigma_v2 = 0`` the least-squares error of Definition
def:error on the same trajectories is returned beside, so both errors can be compared.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import check_int, check_nonnegative
from ..errors import ParameterError
from ..ident.grid import identification_errors
from ..ident.least_squares import prefix_estimates
from ..ident.subspace import arx, markov_error, moesp, n4sid
from ..plant import check_output_matrix, observable_order
from .plant import LinearPlant, simulate_gaussian_attack

__all__ = ["OUTPUT_ESTIMATORS", "check_output_matrix", "output_attack_errors"]


def _arx(u: np.ndarray, y: np.ndarray, order: int) -> Any:
    """ARX with ``na = nb = ceil(order / p) + 1`` lags: enough for a plant of that order."""
    lags = -(-order // y.shape[-1]) + 1
    return arx(u, y, na=lags, nb=lags)


#: The output-side estimators by name: a batch function ``(u, y, order) -> SubspaceEstimate``.
OUTPUT_ESTIMATORS = {
    "n4sid": lambda u, y, order: n4sid(u, y, order=order),
    "moesp": lambda u, y, order: moesp(u, y, order=order),
    "arx": _arx,
}


def output_attack_errors(
    plant: LinearPlant,
    C: Any,
    *,
    sample_sizes: Any,
    runs: int,
    sigma_u2: float,
    sigma_v2: float,
    seed: Any,
    estimator: str = "n4sid",
    order: int | None = None,
    markov_length: int = 20,
) -> dict[str, np.ndarray]:
    """Errors of ``runs`` Gaussian attacks identified from outputs, on a grid of sample sizes.

    Parameters
    ----------
    plant : LinearPlant
        ``(A, B)`` and the noise of eq:system.
    C : array_like, shape (p, n)
        Output matrix.
    sample_sizes : array_like of int
        Strictly increasing sample sizes.
    runs : int
        Independent attacks.
    sigma_u2, sigma_v2 : float
        Attack input variance (> 0) and measurement noise variance (>= 0).
    seed : int or SeedSequence
        Seed of the trajectories (as :func:`simulate_gaussian_attack`); the measurement noise
        draws from its own child stream.
    estimator : {"n4sid", "moesp", "arx"}
        The output-side method (:data:`OUTPUT_ESTIMATORS`).
    order : int, optional
        The state dimension to fit; default the observable order of ``(A, C)``.
    markov_length : int
        ``L`` of :func:`~encctl_gym.ident.subspace.markov_error`.

    Returns
    -------
    dict
        ``"markov"`` (runs, G): the Markov-parameter error; with ``C = I`` and ``sigma_v2 = 0``
        also ``"state_ls"`` (runs, G): Definition def:error of least squares on the states, and
        ``"state_ls_markov"`` (runs, G): the Markov-parameter error of that same estimate.

    Raises
    ------
    ParameterError
        For an unknown estimator, an unobservable pair asked to fit more states than it shows, or
        too few samples for the method.
    """
    if estimator not in OUTPUT_ESTIMATORS:
        raise ParameterError(f"unknown output estimator {estimator!r}; choose one of {', '.join(OUTPUT_ESTIMATORS)}")
    C = check_output_matrix(C, plant.n)
    sv = check_nonnegative("sigma_v2", sigma_v2)
    grid = np.asarray(sample_sizes)
    if grid.ndim != 1 or len(grid) < 1 or np.any(np.diff(grid) <= 0):
        raise ParameterError("sample_sizes must be a strictly increasing 1-D sequence")
    grid = np.array([check_int("sample size", int(v), minimum=2) for v in grid])
    runs = check_int("runs", runs, minimum=1)
    observable = observable_order(plant.A, C)
    order = observable if order is None else check_int("order", order, minimum=1)
    if order > observable:
        raise ParameterError(
            f"order = {order} exceeds the observable order {observable} of (A, C): the outputs show {observable} states"
        )
    ss = np.random.SeedSequence(seed) if not isinstance(seed, np.random.SeedSequence) else seed
    traj_seed, noise_seed = ss.spawn(2)
    sim = simulate_gaussian_attack(plant, N=int(grid[-1]), runs=runs, sigma_u2=sigma_u2, seed=traj_seed)
    rng = np.random.default_rng(noise_seed)
    y = sim.states @ C.T + np.sqrt(sv) * rng.normal(size=(runs, sim.N, C.shape[0]))
    true = (plant.A, plant.B, C, np.zeros((C.shape[0], plant.m)))
    fit = OUTPUT_ESTIMATORS[estimator]
    markov = np.empty((runs, len(grid)))
    for g, N in enumerate(grid):
        est = fit(sim.inputs[:, :N], y[:, :N], order)
        markov[:, g] = markov_error(true, est, markov_length)
    out = {"markov": markov}
    if sv == 0.0 and C.shape == (plant.n, plant.n) and np.array_equal(C, np.eye(plant.n)):
        out["state_ls"] = identification_errors(sim.states, sim.inputs, plant.A, plant.B, grid)
        AB = prefix_estimates(sim.states, sim.inputs, grid)  # (runs, G, n, n + m)
        n = plant.n
        out["state_ls_markov"] = np.asarray(
            markov_error(true, (AB[..., :n], AB[..., n:], np.eye(n), np.zeros((n, plant.m))), markov_length)
        )
    return out
