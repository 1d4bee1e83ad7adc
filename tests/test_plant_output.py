"""Plants measured through outputs: ``C`` and ``sigma_v2`` in the value object, plant files and presets."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from encctl_gym.errors import ConfigError, ParameterError, ShapeError
from encctl_gym.plant import Plant, observable_order
from encctl_gym.plant_file import load_plant_file
from encctl_gym.presets import get_preset

A2 = [[0.6, 0.2], [-0.1, 0.5]]
B2 = [[1.0, 0.0], [0.3, 0.8]]


def test_default_is_the_state_measured_plant():
    p = Plant(A2, B2)
    assert p.C is None and p.sigma_v2 == 0.0 and p.measures_state and p.p == 2
    np.testing.assert_array_equal(p.output_matrix(), np.eye(2))
    assert p == Plant(A2, B2) and p != Plant(A2, B2, C=[[1.0, 0.0]])


def test_output_plant_holds_C_and_noise():
    p = Plant(A2, B2, C=[1.0, 0.0], sigma_v2=0.01)
    assert p.C.shape == (1, 2) and p.p == 1 and p.sigma_v2 == 0.01 and not p.measures_state
    assert not p.C.flags.writeable
    assert pickle.loads(pickle.dumps(p)) == p
    assert hash(p) == hash(Plant(A2, B2, C=[[1.0, 0.0]], sigma_v2=0.01))


@pytest.mark.parametrize("C", [[[1.0, 0.0, 0.0]], [[1.0], [0.0]], np.ones((2, 2, 1))])
def test_C_of_the_wrong_shape_is_refused(C):
    with pytest.raises(ShapeError, match="C must have shape"):
        Plant(A2, B2, C=C)


def test_unobservable_pair_is_refused_naming_the_order():
    # A = a I with one output sees one direction only: observable order 1 of 2 (hand count)
    with pytest.raises(ParameterError, match="shows 1 of the 2 states"):
        Plant(0.5 * np.eye(2), np.eye(2), C=[[1.0, 1.0]])


def test_negative_measurement_noise_is_refused():
    with pytest.raises(ParameterError, match="sigma_v2"):
        Plant(A2, B2, C=[[1.0, 0.0]], sigma_v2=-0.1)


def test_observability_rank_does_not_mistake_a_small_eigenvalue_for_a_lost_state():
    # a diagonal A with distinct eigenvalues and C = [1 ... 1] is observable (hand count: every
    # mode is seen), however small the eigenvalues (the blocks C A^5 reach 1e-30 here)
    lam = np.array([0.9, 0.5, 1e-2, 1e-3, 1e-4, 1e-6])
    A = np.diag(lam)
    C = np.ones((1, 6))
    assert observable_order(A, C) == 6
    # repeated eigenvalue: one output sees one of the two copies (Jordan-free), order 5
    A[1, 1] = 0.9
    assert observable_order(A, C) == 5


def test_observability_rank_is_basis_free():
    rng = np.random.default_rng(3)
    A = np.diag([0.7, 0.7, 0.2])  # a repeated eigenvalue: one output sees 2 of 3 states
    C = np.array([[1.0, 2.0, 1.0]])
    T = rng.normal(size=(3, 3))
    assert observable_order(A, C) == 2
    assert observable_order(T @ A @ np.linalg.inv(T), C @ np.linalg.inv(T)) == 2


def test_plant_file_takes_C_and_sigma_v2(tmp_path):
    f = tmp_path / "p.yaml"
    f.write_text("A: [[0.6, 0.2], [-0.1, 0.5]]\nB: [[1.0, 0.0], [0.3, 0.8]]\nC: [1, 0]\nsigma_v2: 1e-2\n")
    spec = load_plant_file(f)
    np.testing.assert_array_equal(spec.C, [[1.0, 0.0]])
    plant = spec.preset.plant()
    assert plant.p == 1 and plant.sigma_v2 == 0.01
    assert "C" in spec.from_file and "sigma_v2" in spec.from_file


def test_plant_file_errors_name_the_file_and_the_value(tmp_path):
    f = tmp_path / "p.json"
    f.write_text('{"A": [[0.5, 0], [0, 0.5]], "B": [[1, 0], [0, 1]], "C": [[1, 1]]}')
    with pytest.raises(ParameterError, match=r"p\.json.*not observable"):
        load_plant_file(f)
    f.write_text('{"A": [[0.5, 0], [0, 0.4]], "B": [[1, 0], [0, 1]], "C": [[1, 1]], "sigma_v2": -1}')
    with pytest.raises(ParameterError, match="sigma_v2 must be >= 0"):
        load_plant_file(f)
    f.write_text('{"A": [[0.5, 0], [0, 0.4]], "B": [[1, 0], [0, 1]], "sigma_v2": 0.1}')
    with pytest.raises(ConfigError, match="give C too"):
        load_plant_file(f)


def test_presets_measure_the_state_unless_they_say_otherwise():
    assert get_preset("paper-example").plant().C is None
    p = get_preset("small-output").plant()
    assert p.p == 1 and p.sigma_v2 > 0
