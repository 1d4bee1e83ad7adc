"""The empirical design from outputs (security.output_design) and its honesty where the answer is known."""

from __future__ import annotations

import json

import numpy as np
import pytest

from encctl_gym.cli import main
from encctl_gym.errors import ParameterError
from encctl_gym.plant import Plant
from encctl_gym.presets import get_preset
from encctl_gym.security.bayes_complexity import stationary_regressor_covariance
from encctl_gym.security.complexity import sic_from_traces
from encctl_gym.security.empirical import fit_empirical_complexity
from encctl_gym.security.gramians import controllability_gramian, noise_gramian
from encctl_gym.security.output_design import output_design
from encctl_gym.security.threat import ThreatModel


def test_fitted_rate_intervals_cover_the_true_rate_at_their_level():
    """A synthetic curve c / N^a with known (a, c): each run's errors are the curve times a
    mean-one factor of the run (gamma, shape 4) and of each point (gamma, shape 8), so the mean
    over runs estimates c / N^a without bias. Over 200 replications the 90 % intervals of a and c
    contain the truth in 80 % to 97 % of them (a binomial band around 90 % for 200 draws, with the
    percentile bootstrap's known slight under-coverage at 40 runs)."""
    a, c = 1.3, 2.5
    N = np.array([100.0, 200.0, 400.0, 800.0, 1600.0])
    rng = np.random.default_rng(0)
    hits_a = hits_c = 0
    reps = 200
    for r in range(reps):
        run = rng.gamma(4.0, 1 / 4.0, size=(40, 1))
        point = rng.gamma(8.0, 1 / 8.0, size=(40, len(N)))
        errors = c / N**a * run * point
        fit = fit_empirical_complexity(N, errors, level=0.9, bootstrap=200, seed=r)
        hits_a += fit.a_interval[0] <= a <= fit.a_interval[1]
        hits_c += fit.c_interval[0] <= c <= fit.c_interval[1]
    assert 0.80 * reps <= hits_a <= 0.97 * reps
    assert 0.80 * reps <= hits_c <= 0.97 * reps


@pytest.mark.slow
def test_state_least_squares_curve_reproduces_the_known_value_and_sits_above_eq_sic():
    """C = I, sigma_v2 = 0: least squares on the states. Its band contains the exact large-N mean
    error sigma_w2 tr(Sigma^-1) / ((n + m) N) (Sigma: the stationary regressor covariance), and
    eq:sic, a lower bound of the expected error (Definition def:sic), lies below that value and
    below the mean at every N (here about 10 % below: at 150 runs the band reaches down to it)."""
    p = get_preset("small")
    grid = np.array([800, 1600, 3200, 6400])
    d = output_design(Plant(p.A, p.B, C=np.eye(2)), ThreatModel.of(p), estimator="arx", runs=150, sample_sizes=grid, seed=3,
                      bootstrap=400)  # fmt: skip
    f = d.state_fit
    S = stationary_regressor_covariance(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2)
    exact = p.sigma_w2 * np.trace(np.linalg.inv(S)) / (p.n + p.m) / grid
    assert np.all((f.low <= exact) & (exact <= f.high))
    tr_u, tr_w = np.trace(controllability_gramian(p.A, p.B)), np.trace(noise_gramian(p.A))
    sic = sic_from_traces(grid, tr_u, tr_w, p.m, p.n, p.sigma_u2, p.sigma_w2, p.sigma_x2)
    assert np.all(sic <= exact) and np.all(sic < f.mean)
    assert f.a_interval[0] <= 1.0 <= f.a_interval[1]  # the 1/N rate of Theorem thm:sic


def test_output_design_of_a_plant_with_one_output():
    p = get_preset("small-output")
    d = output_design(p.plant(), ThreatModel.of(p), estimator="n4sid", runs=6, points=4, bootstrap=200)
    assert d.p == 1 and d.output_design is not None
    lo, hi = d.output_design.N_star_interval
    assert lo <= d.output_design.N_star <= hi
    assert d.target > 0
    json.dumps(d.to_dict())


def test_a_grid_shorter_than_the_estimator_needs_is_refused():
    p = get_preset("small-output")
    with pytest.raises(ParameterError, match="samples"):
        output_design(p.plant(), ThreatModel.of(p), estimator="n4sid", runs=3, sample_sizes=[12, 16, 20], bootstrap=200)
    with pytest.raises(ParameterError, match="unknown output estimator"):
        output_design(p.plant(), ThreatModel.of(p), estimator="cva")


def test_design_command_prints_the_output_design_beside_the_state_design(capsys, tmp_path):
    f = tmp_path / "plant.yaml"
    f.write_text("A: [[0.6, 0.2], [-0.1, 0.5]]\nB: [[1.0, 0.0], [0.3, 0.8]]\nC: [1, 0]\nsigma_v2: 0.01\ngamma_c: 1e-3\n")
    assert main(["design", str(f), "--estimator", "arx", "--runs", "4", "--points", "3"]) == 0
    out = capsys.readouterr().out
    assert "(a) eq:sic2" in out and "Empirical design from outputs" in out and "output, arx, Markov error" in out
    assert main(["design", str(f), "--estimator", "arx", "--runs", "3", "--points", "3", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["output_design"]["p"] == 1
    assert main(["design", str(f), "--estimator", "nope"]) == 2
    assert main(["design", str(f), "--runs", "3"]) == 2
    assert "only applies with --estimator" in capsys.readouterr().err


def test_output_attacks_have_the_gaussian_attacks_power():
    from encctl_gym.sim.output import attack_inputs
    from encctl_gym.sim.plant import LinearPlant

    p = get_preset("small")
    plant = LinearPlant(p.A, p.B, sigma_w2=p.sigma_w2)
    u = attack_inputs(plant, "prbs", N=500, runs=4, sigma_u2=2.0, seed=1)
    np.testing.assert_array_equal(np.abs(u), np.sqrt(2.0))  # +-sigma_u: power sigma_u2 exactly
    from encctl_gym.security.attack_design import optimal_attack_design

    with pytest.raises(ParameterError, match="plays a given design"):
        attack_inputs(plant, "optimal-ol", N=10, runs=1, sigma_u2=2.0, seed=1)
    design = optimal_attack_design(p.A, p.B, sigma_u2=2.0, sigma_w2=p.sigma_w2, feedback=False)
    u = attack_inputs(plant, "optimal-ol", N=4000, runs=8, sigma_u2=2.0, seed=1, design=design)
    assert np.mean(u**2) == pytest.approx(2.0, rel=0.05)  # the design's power constraint, stationary from t = 0
    with pytest.raises(ParameterError, match="unknown attack"):
        attack_inputs(plant, "chirp", N=10, runs=1, sigma_u2=1.0, seed=0)
