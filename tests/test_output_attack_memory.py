"""Memory of the output design's simulated attacks (issue 34 item 13): the estimators' working set
against ``tracemalloc``, streaming over chunks of runs with the same numbers, and the refusal
before any simulation."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import encctl_gym.sim.output as sim_output
from encctl_gym.cli import main
from encctl_gym.errors import ResourceLimitError
from encctl_gym.presets import get_preset
from encctl_gym.security.output_design import output_design
from encctl_gym.security.threat import ThreatModel
from encctl_gym.sim.output import OUTPUT_ESTIMATORS, estimator_bytes, output_attack_bytes, output_attack_errors
from encctl_gym.sim.plant import LinearPlant

A = np.array([[0.5, 0.2, 0.0], [0.0, 0.6, 0.1], [0.0, 0.0, 0.4]])
B = np.array([[1.0], [0.0], [0.5]])
C = np.array([[1.0, 0.0, 0.0]])
PLANT = LinearPlant(A, B, sigma_w2=0.1)


def _peak(fn) -> int:
    """Peak bytes numpy allocated (traced) while ``fn`` ran."""
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        fn()
        return tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("estimator", sorted(OUTPUT_ESTIMATORS))
@pytest.mark.parametrize(("m", "p", "order"), [(1, 1, 3), (2, 2, 3), (1, 2, 4)])
def test_the_estimate_bounds_the_estimators_measured_working_set(estimator, m, p, order):
    """Measured peak of one batch of 3 runs of 3000 samples: below the estimate, and above half of it
    (an estimate far too large would refuse designs that fit)."""
    rng = np.random.default_rng(0)
    u, y = rng.normal(size=(3, 3000, m)), rng.normal(size=(3, 3000, p))
    peak = _peak(lambda: OUTPUT_ESTIMATORS[estimator](u, y, order))
    estimate = 3 * estimator_bytes(estimator, 3000, m, p, order)
    assert 0.5 * estimate <= peak <= estimate


def test_streaming_over_chunks_of_runs_gives_the_same_errors_and_a_smaller_peak(monkeypatch):
    common = {"sample_sizes": [1000, 2000, 4000], "runs": 12, "sigma_u2": 1.0, "sigma_v2": 0.01, "seed": 3}
    whole = output_attack_errors(PLANT, C, estimator="n4sid", **common)["markov"]
    peak_whole = _peak(lambda: output_attack_errors(PLANT, C, estimator="n4sid", **common))
    per_run = estimator_bytes("n4sid", 4000, 1, 1, 3)
    monkeypatch.setattr(sim_output, "STREAM_BYTES", 2 * per_run)  # two runs per chunk at the largest N
    streamed = output_attack_errors(PLANT, C, estimator="n4sid", **common)["markov"]
    peak_streamed = _peak(lambda: output_attack_errors(PLANT, C, estimator="n4sid", **common))
    np.testing.assert_array_equal(streamed, whole)
    need, chunk = output_attack_bytes(12, 4000, 3, 1, 1, "n4sid", 3)
    assert chunk == 2 and peak_streamed <= need
    assert peak_streamed < 0.5 * peak_whole  # 12 runs at once against 2


def test_an_unknown_estimator_has_no_memory_estimate():
    from encctl_gym.errors import ParameterError

    with pytest.raises(ParameterError, match="unknown output estimator 'cva'"):
        estimator_bytes("cva", 1000, 1, 1, 3)


def test_attacks_beyond_the_memory_limit_are_refused_before_they_run(monkeypatch):
    calls = []
    monkeypatch.setattr(sim_output, "simulate_gaussian_attack", lambda *a, **k: calls.append(1))
    with pytest.raises(ResourceLimitError, match=r"20 attacks of N = 200000 samples identified by arx.*memory_limit"):
        output_attack_errors(PLANT, C, sample_sizes=[1000, 200000], runs=20, sigma_u2=1.0, sigma_v2=0.0, seed=0,
                             estimator="arx", memory_limit=2**28)  # fmt: skip
    assert calls == []
    p = get_preset("small-output")
    with pytest.raises(ResourceLimitError, match="state-measured reference"):
        output_design(p.plant(), ThreatModel.of(p), estimator="n4sid", runs=4, sample_sizes=[100, 200, 400], memory_limit=10**5)


def test_design_command_names_the_memory_estimate_in_one_line(tmp_path, capsys):
    f = tmp_path / "plant.yaml"
    f.write_text("A: [[0.6, 0.2], [-0.1, 0.5]]\nB: [[1.0, 0.0], [0.3, 0.8]]\nC: [1, 0]\nsigma_v2: 0.01\ngamma_c: 1e-3\n")
    assert main(["design", str(f), "--estimator", "arx", "--runs", "3", "--points", "3", "--memory-limit", "1e-4"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "above the limit" in err and ("MiB" in err or "KiB" in err)
    assert main(["design", str(f), "--estimator", "arx", "--memory-limit", "zero"]) == 2
    assert main(["design", str(f), "--memory-limit", "4"]) == 2
    assert "--memory-limit only applies with --estimator" in capsys.readouterr().err


def test_a_runs_lq_factor_does_not_depend_on_the_other_runs_of_its_chunk():
    """The LQ factor falls back from Cholesky to Householder run by run: a run whose inputs never
    excite one direction (here a zero input) beside well-excited runs leaves their factors as
    they are alone, so chunking the runs cannot change a number."""
    from encctl_gym.ident.subspace import _lower_factor

    rng = np.random.default_rng(2)
    M = rng.normal(size=(3, 8, 400))
    M[1, :2] = 0.0  # rank-deficient rows: a singular Gram matrix
    batch = _lower_factor(M)
    for r in range(3):
        np.testing.assert_array_equal(batch[r], _lower_factor(M[r : r + 1])[0])
    np.testing.assert_allclose(batch[1] @ batch[1].T, M[1] @ M[1].T, atol=1e-9)


@pytest.mark.parametrize("grid", [[], [400, 200, 100], ["a", "b", "c"], [[100, 200]]])
def test_a_bad_grid_is_refused_before_the_memory_check(grid):
    from encctl_gym.errors import ParameterError

    p = get_preset("small-output")
    with pytest.raises(ParameterError, match="strictly increasing 1-D sequence"):
        output_design(p.plant(), ThreatModel.of(p), estimator="n4sid", runs=3, sample_sizes=grid, bootstrap=100)


def test_a_memory_limit_beyond_any_machine_is_accepted(tmp_path):
    f = tmp_path / "plant.yaml"
    f.write_text("A: [[0.6, 0.2], [-0.1, 0.5]]\nB: [[1.0, 0.0], [0.3, 0.8]]\nC: [1, 0]\nsigma_v2: 0.01\ngamma_c: 1e-3\n")
    assert main(["design", str(f), "--estimator", "arx", "--runs", "3", "--points", "3", "--memory-limit", "1e300"]) == 0
