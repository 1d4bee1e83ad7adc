"""Monte Carlo of identification from outputs: the paper's Gaussian attack, measured through
``y = C x + v``, identified by a subspace method or ARX, scored by the Markov-parameter error.

The trajectories are the engine's own (:func:`~encctl_gym.sim.plant.simulate_gaussian_attack`,
the same seed gives the same states as the state-measured experiments); the outputs add the
measurement noise ``v ~ N(0, sigma_v2 I)`` from a stream of its own. The attacker sees only its
inputs and ``y``. With ``C = I`` and ``sigma_v2 = 0`` the least-squares error of Definition
def:error on the same trajectories is returned beside, so both errors can be compared.

Memory: the trajectories are held whole, and the estimators run over chunks of runs whose
working set stays near :data:`STREAM_BYTES` (:func:`estimator_bytes`: the subspace methods'
block Hankel rows, ARX's regressors). The sum is checked against the memory limit before any
simulation (:func:`output_attack_bytes`); a run too long for it is refused with the estimate.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import check_int, check_nonnegative
from ..errors import ParameterError
from ..ident.grid import identification_errors
from ..ident.least_squares import prefix_estimates
from ..ident.subspace import arx, default_block_rows, markov_error, moesp, n4sid
from ..plant import check_output_matrix, observable_order
from ..resources import check_memory
from .plant import LinearPlant, simulate, simulate_gaussian_attack

__all__ = [
    "OUTPUT_ATTACKS",
    "OUTPUT_ESTIMATORS",
    "STREAM_BYTES",
    "attack_inputs",
    "check_output_estimator",
    "check_output_matrix",
    "check_sample_grid",
    "estimator_bytes",
    "output_attack_bytes",
    "output_attack_errors",
]

#: The working set (bytes) one chunk of runs may give an estimator; the chunk holds at least one run.
STREAM_BYTES = 256 * 2**20


def _arx_lags(order: int, p: int) -> int:
    """ARX's ``na = nb``: ``ceil(order / p) + 1`` lags, enough for a plant of that order."""
    return -(-order // p) + 1


def _arx(u: np.ndarray, y: np.ndarray, order: int) -> Any:
    """ARX with ``na = nb = ceil(order / p) + 1`` lags: enough for a plant of that order."""
    lags = _arx_lags(order, y.shape[-1])
    return arx(u, y, na=lags, nb=lags)


def estimator_bytes(estimator: str, N: int, m: int, p: int, order: int) -> int:
    """Bytes one run of ``N`` samples needs inside an estimator of :data:`OUTPUT_ESTIMATORS`.

    The subspace methods hold the ``2 (m + p) i`` rows of ``[U_f; W_p; Y_f]`` twice while they
    factor it (``i`` of :func:`~encctl_gym.ident.subspace.default_block_rows`): measured with
    ``tracemalloc`` at 4.0 to 4.1 words per sample and unit of ``(m + p) i``, estimated at 5.
    ARX holds its ``k = lags (m + p)`` regressor columns and the least-squares workspace: 3.0
    words per sample and column, estimated at 4. The tests hold the estimate above the measured
    peak and below twice it.
    """
    check_output_estimator(estimator)
    if estimator == "arx":
        words = 4 * _arx_lags(order, p) * (m + p)
    else:
        words = 5 * (m + p) * default_block_rows(order, p)
    return 8 * int(N) * words


def check_output_estimator(estimator: Any) -> str:
    """``estimator`` if it names one of :data:`OUTPUT_ESTIMATORS`, else ``ParameterError``."""
    if estimator not in OUTPUT_ESTIMATORS:
        raise ParameterError(f"unknown output estimator {estimator!r}; choose one of {', '.join(OUTPUT_ESTIMATORS)}")
    return str(estimator)


def _trajectory_bytes(runs: int, N: int, n: int, m: int, p: int) -> int:
    """States, process noise, inputs and outputs of ``runs`` attacks of ``N`` samples."""
    return 8 * runs * N * (2 * n + m + p)


def output_attack_bytes(runs: int, N: int, n: int, m: int, p: int, estimator: str, order: int) -> tuple[int, int]:
    """``(total bytes, runs per chunk)`` of :func:`output_attack_errors` at its largest ``N``: the
    trajectories whole, plus one chunk of runs in the estimator (:data:`STREAM_BYTES`, at least one run)."""
    per_run = estimator_bytes(estimator, N, m, p, order)
    chunk = max(1, min(runs, STREAM_BYTES // per_run))
    return _trajectory_bytes(runs, N, n, m, p) + chunk * per_run, chunk


#: The output-side estimators by name: a batch function ``(u, y, order) -> SubspaceEstimate``.
OUTPUT_ESTIMATORS = {
    "n4sid": lambda u, y, order: n4sid(u, y, order=order),
    "moesp": lambda u, y, order: moesp(u, y, order=order),
    "arx": _arx,
}


#: The open-loop attacks whose inputs need no state (the attacker of ``y = C x + v`` has none):
#: ``"gaussian"`` (i.i.d. ``N(0, sigma_u2 I)``, Theorem thm:sic), ``"prbs"`` (random binary
#: ``+-sigma_u`` per channel and step) and ``"optimal-ol"`` (the A-optimal open-loop design of
#: :mod:`encctl_gym.security.attack_design`, ``u = K x_u + v`` on the state ``x_u`` the attacker
#: simulates from its own inputs; designed for Definition def:error, with the true ``(A, B)``).
OUTPUT_ATTACKS: tuple[str, ...] = ("gaussian", "prbs", "optimal-ol")


def attack_inputs(
    plant: LinearPlant, attack: str, *, N: int, runs: int, sigma_u2: float, seed: Any, design: Any = None
) -> np.ndarray:
    """The inputs ``(runs, N, m)`` of an open-loop attack of :data:`OUTPUT_ATTACKS` other than
    ``"gaussian"`` (which :func:`~encctl_gym.sim.plant.simulate_gaussian_attack` draws), each of
    average power ``sigma_u2`` per channel. ``"optimal-ol"`` plays ``design``, the open-loop
    design of :func:`encctl_gym.security.attack_design.optimal_attack_design` (``feedback=False``)
    at that ``sigma_u2`` (the simulator takes it given: the design is the security layer's)."""
    rng = np.random.default_rng(seed)
    m, n = plant.m, plant.n
    if attack == "prbs":
        return np.sqrt(sigma_u2) * (2.0 * rng.integers(0, 2, size=(runs, N, m)) - 1.0)
    if attack == "optimal-ol":
        if design is None:
            raise ParameterError(
                "the optimal-ol attack plays a given design: pass design=optimal_attack_design(A, B, "
                "sigma_u2=..., sigma_w2=..., feedback=False) (encctl_gym.security.attack_design)"
            )
        d = design
        Lv = np.linalg.cholesky(d.V + 1e-15 * np.eye(m))
        S = d.input_state_cov if d.input_state_cov is not None else np.zeros((n, n))
        w, V = np.linalg.eigh(S)
        x = rng.standard_normal((runs, n)) @ (V * np.sqrt(np.maximum(w, 0.0))).T  # x_u ~ N(0, S_u): stationary
        u = np.empty((runs, N, m))
        for t in range(N):
            u[:, t] = x @ d.K.T + rng.standard_normal((runs, m)) @ Lv.T
            x = x @ plant.A.T + u[:, t] @ plant.B.T
        return u
    raise ParameterError(f"unknown attack {attack!r}; choose one of {', '.join(OUTPUT_ATTACKS)}")


def _measured_attacks(
    plant: LinearPlant, C: np.ndarray, sigma_v2: float, attack: str, *, N: int, runs: int, sigma_u2: float, seed: Any, design: Any
) -> tuple[Any, np.ndarray]:
    """The trajectories of ``runs`` attacks (the engine's, for ``"gaussian"``) and their outputs
    ``y = C x + v``, the measurement noise from a child stream of its own."""
    ss = np.random.SeedSequence(seed) if not isinstance(seed, np.random.SeedSequence) else seed
    traj_seed, noise_seed = ss.spawn(2)
    if attack == "gaussian":
        sim = simulate_gaussian_attack(plant, N=N, runs=runs, sigma_u2=sigma_u2, seed=traj_seed)
    else:
        input_seed, plant_seed = traj_seed.spawn(2)
        u = attack_inputs(plant, attack, N=N, runs=runs, sigma_u2=sigma_u2, seed=input_seed, design=design)
        sim = simulate(plant, u, plant_seed)
    rng = np.random.default_rng(noise_seed)
    return sim, sim.states @ C.T + np.sqrt(sigma_v2) * rng.normal(size=(runs, sim.N, C.shape[0]))


def check_sample_grid(sample_sizes: Any) -> np.ndarray:
    """``sample_sizes`` as a strictly increasing 1-D integer array of sizes >= 2 (else ``ParameterError``)."""
    grid = np.asarray(sample_sizes)
    if grid.ndim != 1 or len(grid) < 1 or grid.dtype.kind not in "iuf" or np.any(np.diff(grid) <= 0):
        raise ParameterError("sample_sizes must be a strictly increasing 1-D sequence of sample sizes")
    return np.array([check_int("sample size", v, minimum=2) for v in grid.tolist()])


def _streamed_markov_errors(
    estimator: str, u: np.ndarray, y: np.ndarray, grid: np.ndarray, order: int, true: tuple[Any, ...], markov_length: int
) -> np.ndarray:
    """The Markov error ``(runs, G)`` of ``estimator`` on each prefix of the grid, over chunks of
    runs of about :data:`STREAM_BYTES` each (every run is estimated on its own, so the chunking
    does not change a number)."""
    runs, m, p = u.shape[0], u.shape[2], y.shape[2]
    fit = OUTPUT_ESTIMATORS[estimator]
    markov = np.empty((runs, len(grid)))
    for g, N in enumerate(grid):
        per_chunk = max(1, STREAM_BYTES // estimator_bytes(estimator, int(N), m, p, order))
        for r0 in range(0, runs, per_chunk):
            r1 = min(runs, r0 + per_chunk)
            markov[r0:r1, g] = markov_error(true, fit(u[r0:r1, :N], y[r0:r1, :N], order), markov_length)
    return markov


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
    attack: str = "gaussian",
    design: Any = None,
    memory_limit: int | None = None,
) -> dict[str, np.ndarray]:
    """Errors of ``runs`` attacks identified from outputs, on a grid of sample sizes.

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
    attack : str
        The attack's inputs (:data:`OUTPUT_ATTACKS`; default the paper's Gaussian attack, whose
        trajectories are :func:`~encctl_gym.sim.plant.simulate_gaussian_attack`'s).
    design : AttackDesign, optional
        The open-loop design ``"optimal-ol"`` plays (:func:`attack_inputs`).
    memory_limit : int, optional
        Bytes the call may hold (default :func:`~encctl_gym.resources.default_memory_limit`);
        checked against :func:`output_attack_bytes` before any simulation.

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
    ResourceLimitError
        When the trajectories and one run's estimate exceed ``memory_limit``.
    """
    check_output_estimator(estimator)
    C = check_output_matrix(C, plant.n)
    sv = check_nonnegative("sigma_v2", sigma_v2)
    grid = check_sample_grid(sample_sizes)
    runs = check_int("runs", runs, minimum=1)
    observable = observable_order(plant.A, C)
    order = observable if order is None else check_int("order", order, minimum=1)
    if order > observable:
        raise ParameterError(
            f"order = {order} exceeds the observable order {observable} of (A, C): the outputs show {observable} states"
        )
    p = C.shape[0]
    need, chunk = output_attack_bytes(runs, int(grid[-1]), plant.n, plant.m, p, estimator, order)
    check_memory(
        f"{runs} attacks of N = {int(grid[-1])} samples identified by {estimator} ({chunk} run(s) per chunk)",
        need,
        memory_limit,
        "use fewer runs, a larger gamma_c (shorter attacks) or a larger memory limit",
    )
    sim, y = _measured_attacks(plant, C, sv, attack, N=int(grid[-1]), runs=runs, sigma_u2=sigma_u2, seed=seed, design=design)
    true = (plant.A, plant.B, C, np.zeros((C.shape[0], plant.m)))
    out = {"markov": _streamed_markov_errors(estimator, sim.inputs, y, grid, order, true, markov_length)}
    if sv == 0.0 and C.shape == (plant.n, plant.n) and np.array_equal(C, np.eye(plant.n)):
        out["state_ls"] = identification_errors(sim.states, sim.inputs, plant.A, plant.B, grid)
        AB = prefix_estimates(sim.states, sim.inputs, grid)  # (runs, G, n, n + m)
        n = plant.n
        out["state_ls_markov"] = np.asarray(
            markov_error(true, (AB[..., :n], AB[..., n:], np.eye(n), np.zeros((n, plant.m))), markov_length)
        )
    return out
