"""Tests of encctl_gym.parallel and sim.montecarlo: seeded tasks on joblib and Dask."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from encctl_gym.errors import ConfigError, EncctlError, ParameterError, ShapeError
from encctl_gym.parallel import child_seeds, run_tasks
from encctl_gym.sim.montecarlo import AttackSpec, gaussian_attack_errors, log_grid, sweep_gaussian_attack
from encctl_gym.sim.plant import LinearPlant


def draw(task: int, seed: np.random.SeedSequence) -> np.ndarray:
    """A task whose result depends on its child seed only."""
    return task + np.random.default_rng(seed).standard_normal(4)


SYSTEMS = [
    AttackSpec(0.5 * np.eye(2), np.eye(2), sigma_w2=0.1, sigma_u2=1.0),
    AttackSpec(np.array([[0.3, 0.1], [0.0, -0.2]]), np.array([[1.0], [0.5]]), sigma_w2=1.0, sigma_u2=10.0),
    AttackSpec(0.7 * np.eye(2), 0.2 * np.eye(2), sigma_w2=0.5, sigma_u2=0.1, sigma_x2=3.0),
]
GRID = [6, 10, 30, 100]


def test_child_seeds_equal_spawn_and_do_not_mutate() -> None:
    ss = np.random.SeedSequence(42)
    a = child_seeds(ss, 3)
    b = child_seeds(ss, 3)
    ref = np.random.SeedSequence(42).spawn(3)
    for x, y, z in zip(a, b, ref):
        assert x.spawn_key == y.spawn_key == z.spawn_key
        np.testing.assert_array_equal(x.generate_state(4), z.generate_state(4))
    assert ss.n_children_spawned == 0
    assert child_seeds(1, 0) == []


def test_run_tasks_same_result_serial_processes_threads() -> None:
    serial = run_tasks(draw, range(5), seed=3, n_jobs=1)
    procs = run_tasks(draw, range(5), seed=3, n_jobs=2)
    threads = run_tasks(draw, range(5), seed=3, n_jobs=2, backend="threading")
    for s, p, t in zip(serial, procs, threads):
        np.testing.assert_array_equal(s, p)
        np.testing.assert_array_equal(s, t)
    seeds = child_seeds(3, 5)
    for i, r in enumerate(serial):  # results in task order, task i with child seed i
        np.testing.assert_array_equal(r, i + np.random.default_rng(seeds[i]).standard_normal(4))
    other = run_tasks(draw, range(5), seed=4, n_jobs=1)
    assert not np.array_equal(serial[0], other[0])


def test_task_result_does_not_depend_on_the_other_tasks() -> None:
    # Task i's seed is child i: a longer task list does not change the first results.
    short = run_tasks(draw, [0, 0], seed=9, n_jobs=1)
    long = run_tasks(draw, [0, 0, 0, 0], seed=9, n_jobs=1)
    np.testing.assert_array_equal(short[1], long[1])
    assert not np.array_equal(long[0], long[1])


@pytest.mark.parametrize(
    "kwargs", [{"n_jobs": 0}, {"n_jobs": -2}, {"backend": "ray"}, {"scheduler": "nonsense"}, {"scheduler": 5}]
)
def test_run_tasks_rejects_bad_options(kwargs) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ParameterError):
        run_tasks(draw, range(2), seed=0, **{"n_jobs": 2, **kwargs})


@pytest.mark.parametrize(
    "scheduler, message",
    [("tcp://", "names no host:port"), (5, "or a distributed.Client, got 5"), (object(), "or a distributed.Client")],
)
def test_run_tasks_refuses_a_scheduler_before_any_task(scheduler, message) -> None:  # type: ignore[no-untyped-def]
    def never(task, seed):  # type: ignore[no-untyped-def]
        pytest.fail("a task ran")

    with pytest.raises(ParameterError, match=message):
        run_tasks(never, range(2), seed=0, scheduler=scheduler)


def test_missing_dask_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)  # makes `import distributed` fail
    with pytest.raises(ConfigError, match=r"encctl-gym\[dask\]"):
        run_tasks(draw, range(2), seed=0, scheduler="local")


def test_unreachable_scheduler_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("distributed")
    import encctl_gym.parallel as parallel

    monkeypatch.setattr(parallel, "CONNECT_TIMEOUT", "1s")
    with pytest.raises(ConfigError, match="cannot connect"):
        run_tasks(draw, range(2), seed=0, scheduler="tcp://127.0.0.1:1")


def test_gaussian_attack_errors_shape_and_seed() -> None:
    plant = LinearPlant(SYSTEMS[0].A, SYSTEMS[0].B, sigma_w2=0.1)
    e1 = gaussian_attack_errors(plant, sample_sizes=GRID, runs=4, sigma_u2=1.0, seed=5)
    e2 = gaussian_attack_errors(plant, sample_sizes=GRID, runs=4, sigma_u2=1.0, seed=5)
    assert e1.shape == (4, len(GRID)) and np.all(e1 > 0)
    np.testing.assert_array_equal(e1, e2)
    with pytest.raises(ParameterError, match="N >= n"):
        gaussian_attack_errors(plant, sample_sizes=[4, 10], runs=2, sigma_u2=1.0, seed=0)


def test_sweep_local_equals_serial_bit_for_bit() -> None:
    serial = sweep_gaussian_attack(SYSTEMS, sample_sizes=GRID, runs=5, seed=17, n_jobs=1)
    procs = sweep_gaussian_attack(SYSTEMS, sample_sizes=GRID, runs=5, seed=17, n_jobs=2)
    assert serial.shape == (3, 5, len(GRID))
    np.testing.assert_array_equal(serial, procs)
    # System i is task i: equals a direct call with child seed i.
    seeds = child_seeds(17, 3)
    s = SYSTEMS[2]
    direct = gaussian_attack_errors(
        LinearPlant(s.A, s.B, sigma_w2=s.sigma_w2, sigma_x2=s.sigma_x2),
        sample_sizes=GRID,
        runs=5,
        sigma_u2=s.sigma_u2,
        seed=seeds[2],
    )
    np.testing.assert_array_equal(serial[2], direct)


def test_sweep_on_local_dask_cluster_equals_local_bit_for_bit() -> None:
    pytest.importorskip("distributed")
    local = sweep_gaussian_attack(SYSTEMS, sample_sizes=GRID, runs=5, seed=17, n_jobs=1)
    dask = sweep_gaussian_attack(
        SYSTEMS,
        sample_sizes=GRID,
        runs=5,
        seed=17,
        scheduler="local",
        cluster_kwargs={"processes": False, "n_workers": 1, "threads_per_worker": 2},
    )
    np.testing.assert_array_equal(local, dask)


def test_sweep_on_existing_dask_client() -> None:
    distributed = pytest.importorskip("distributed")
    local = run_tasks(draw, range(4), seed=2, n_jobs=1)
    with (
        distributed.LocalCluster(processes=False, n_workers=1, threads_per_worker=2, dashboard_address=None) as cluster,
        distributed.Client(cluster) as client,
    ):
        remote = run_tasks(draw, range(4), seed=2, scheduler=client)
        with pytest.raises(ParameterError):
            run_tasks(draw, range(2), seed=0, scheduler=client.scheduler.address, cluster_kwargs={"x": 1})
        via_address = run_tasks(draw, range(4), seed=2, scheduler=client.scheduler.address)
    for a, b, c in zip(local, remote, via_address):
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, c)


def test_sweep_validates_before_starting_workers() -> None:
    with pytest.raises(ParameterError):
        sweep_gaussian_attack([], sample_sizes=GRID, runs=2, seed=0)
    with pytest.raises(ParameterError):
        sweep_gaussian_attack(["x"], sample_sizes=GRID, runs=2, seed=0)  # type: ignore[list-item]
    bad = AttackSpec(np.eye(2), np.ones((3, 1)), sigma_w2=0.1, sigma_u2=1.0)
    with pytest.raises(ShapeError):
        sweep_gaussian_attack([bad], sample_sizes=GRID, runs=2, seed=0)
    neg = AttackSpec(np.eye(2) * 0.5, np.eye(2), sigma_w2=0.1, sigma_u2=-1.0)
    with pytest.raises(ParameterError):
        sweep_gaussian_attack([neg], sample_sizes=GRID, runs=2, seed=0)
    with pytest.raises(EncctlError):
        sweep_gaussian_attack(SYSTEMS, sample_sizes=[], runs=2, seed=0)


def test_log_grid() -> None:
    g = log_grid(9, 10_000, 30)
    assert g[0] == 9 and g[-1] == 10_000 and np.all(np.diff(g) > 0) and 25 <= g.size <= 30
    assert log_grid(9, 100, 1).tolist() == [100]
    with pytest.raises(ParameterError):
        log_grid(10, 5, 3)


# ---------------------------------------------------------------- hardening
def test_log_grid_refuses_sizes_beyond_int64_and_grids_beyond_memory() -> None:
    with pytest.raises(ParameterError, match=r"N_max must be <= 9007199254740992, got <integer of 1329 bits"):
        log_grid(10, 10**400, 5)
    with pytest.raises(ParameterError, match=r"N_max must be <= 9007199254740992, got 9223372036854775807"):
        log_grid(2, 2**63 - 1, 3)  # was an int64 overflow of the rounded float grid
    with pytest.raises(EncctlError, match=r"points = 1000000000000 .* GiB"):
        log_grid(10, 1000, 10**12)
    assert log_grid(2, 2**53, 3).tolist() == [2, 2**27, 2**53]  # the geometric mean of 2 and 2^53 is 2^27


def test_child_seeds_refuses_a_count_beyond_memory() -> None:
    with pytest.raises(EncctlError, match=r"n = 1000000000000 child seeds needs about"):
        child_seeds(0, 10**12)


@pytest.mark.parametrize(
    ("kwargs", "text"),
    [
        ({"func": "abc"}, "func must be a function"),
        ({"tasks": None}, "tasks must be a sequence"),
        ({"tasks": 3}, "tasks must be a sequence of task descriptions, got 3"),
        ({"scheduler": "bogus"}, "got 'bogus'"),
    ],
)
def test_run_tasks_refuses_what_it_cannot_run(kwargs, text) -> None:  # type: ignore[no-untyped-def]
    args = {"func": lambda t, s: t, "tasks": [1, 2], "seed": 0, "n_jobs": 1, **kwargs}
    with pytest.raises(ParameterError, match=text):
        run_tasks(**args)


def test_gaussian_attack_of_an_impossible_size_is_refused_with_its_memory() -> None:
    from encctl_gym.sim.plant import simulate_gaussian_attack

    plant = LinearPlant(np.array([[0.5, 0.1], [0.0, 0.3]]), np.array([[1.0], [0.5]]), sigma_w2=0.1)
    # 2 * 8 * runs * (N (2n + m) + n) bytes = 16 * 10^9 * (5 N + 2): N = 10^9 is about 7.5e10 GiB
    with pytest.raises(EncctlError, match=r"runs = 3 trajectories of N = 1000000000 .* GiB"):
        simulate_gaussian_attack(plant, N=10**9, runs=3, sigma_u2=1.0, seed=0)
    with pytest.raises(EncctlError, match=r"runs = 1000000000 trajectories"):
        gaussian_attack_errors(plant, sample_sizes=[10, 20], runs=10**9, sigma_u2=1.0, seed=0)
