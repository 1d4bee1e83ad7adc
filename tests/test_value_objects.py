"""The value objects at the boundary: Plant (encctl_gym.plant) and ThreatModel (security.threat)."""

from __future__ import annotations

import dataclasses
import pickle
from fractions import Fraction

import numpy as np
import pytest

from encctl_gym.errors import ParameterError, ShapeError, UnstableSystemError
from encctl_gym.plant import Plant, as_plant
from encctl_gym.security.cost_models import PrecomputationModel
from encctl_gym.security.design import design_from_traces, design_security_parameter
from encctl_gym.security.key_length import design_key_length, key_length_value
from encctl_gym.security.threat import ThreatModel

A = np.array([[0.5, 0.1], [0.0, 0.3]])
B = np.array([[1.0], [0.5]])
PAPER = dict(sigma_u2=10, sigma_w2=0.1, gamma_c=1e-6, tau_c=31536e4, upsilon=442e15)


# ----------------------------------------------------------------------------- Plant
def test_plant_holds_checked_read_only_copies() -> None:
    a, b = A.copy(), B.ravel().copy()
    p = Plant(a, b)  # a 1-D B is one input column
    assert (p.n, p.m) == (2, 1) and p.B.shape == (2, 1)
    assert p.spectral_radius == pytest.approx(0.5) and p.is_stable  # triangular: eigenvalues 0.5 and 0.3
    a[0, 0] = 7.0  # the caller's array stays the caller's
    assert p.A[0, 0] == 0.5
    with pytest.raises(ValueError):
        p.A[0, 0] = 1.0
    with pytest.raises(AttributeError, match="immutable"):
        p.A = np.eye(2)  # type: ignore[misc]
    assert p == Plant(A, B) and hash(p) == hash(Plant(A, B)) and p != Plant(A, 2 * B)
    assert pickle.loads(pickle.dumps(p)) == p


def test_plant_refuses_bad_matrices_naming_the_problem() -> None:
    with pytest.raises(ShapeError, match="square"):
        Plant(np.ones((2, 3)), np.ones((2, 1)))
    with pytest.raises(ShapeError, match="B must have shape"):
        Plant(A, np.ones((3, 1)))
    with pytest.raises(ParameterError, match="A"):
        Plant([[np.nan, 0.0], [0.0, 0.1]], B)
    with pytest.raises(ParameterError, match="complex"):
        Plant(A + 0j, B)
    with pytest.raises(UnstableSystemError, match="spectral radius 1.2"):
        Plant([[1.2, 0.0], [0.0, 0.1]], B)
    loose = Plant([[1.2, 0.0], [0.0, 0.1]], B, stable=False)  # simulation accepts it
    assert not loose.is_stable and loose.spectral_radius == pytest.approx(1.2)
    with pytest.raises(UnstableSystemError):
        as_plant(loose)
    assert as_plant(loose, stable=False) is loose
    with pytest.raises(ParameterError, match="stable"):
        Plant(A, B, stable="yes")  # type: ignore[arg-type]


def test_as_plant_takes_a_plant_or_a_pair() -> None:
    p = Plant(A, B)
    assert as_plant(p) is p and as_plant((A, B)) == p
    with pytest.raises(ParameterError, match="Plant or a pair"):
        as_plant(A)


# ----------------------------------------------------------------------------- ThreatModel
@pytest.mark.parametrize(
    "field, value",
    [
        ("tau_c", 0.0),
        ("tau_c", "10y"),
        ("upsilon", -1.0),
        ("upsilon", float("nan")),
        ("sigma_u2", 0.0),
        ("sigma_w2", float("inf")),
        ("sigma_x2", -0.5),
        ("gamma_c", 0.0),
        ("adversary", "burglar"),
        ("cost_model", "nfs"),
        ("sigma_u2", True),
    ],
)
def test_threat_model_refuses_each_bad_value_by_name(field: str, value: object) -> None:
    with pytest.raises(ParameterError) as err:
        ThreatModel(**{**PAPER, field: value})
    assert field.replace("cost_model", "deciphering model") in str(err.value)


def test_threat_model_values_and_derived_quantities() -> None:
    t = ThreatModel(**PAPER)
    assert t.sigma_x2 == 1.0 and t.adversary == "eavesdropper" and t.model.name == "paper"
    assert t.r_sigma == pytest.approx(100.0)
    assert t.tau_c == 31536e4 and isinstance(t.upsilon, float)  # kept as given (read by the decimal rule)
    assert ThreatModel(**{**PAPER, "gamma_c": Fraction(1, 10**6)}).gamma_c == Fraction(1, 10**6)
    with pytest.raises(dataclasses.FrozenInstanceError):
        t.tau_c = 1.0  # type: ignore[misc]
    server = t.replace(adversary="server")
    assert server.adversary == "server" and t.adversary == "eavesdropper"
    with pytest.raises(ParameterError, match="adversary"):
        t.replace(adversary="thief")
    assert t.to_dict()["cost_model"] == "paper" and t.to_dict()["upsilon"] == 442e15
    bare = ThreatModel(tau_c=1, upsilon=1)
    with pytest.raises(ParameterError, match="needs sigma_u2, sigma_w2"):
        _ = bare.r_sigma
    with pytest.raises(ParameterError, match="needs sigma_u2, sigma_w2, gamma_c"):
        bare.require("sigma_u2", "sigma_w2", "gamma_c")


def test_threat_model_or_its_fields_never_both() -> None:
    t = ThreatModel(**PAPER)
    assert ThreatModel.from_fields(t, {}, "f") is t
    assert ThreatModel.from_fields(None, dict(PAPER), "f") == t
    with pytest.raises(ParameterError, match="not both"):
        ThreatModel.from_fields(t, {"tau_c": 1}, "f")
    with pytest.raises(ParameterError, match="unknown argument"):
        ThreatModel.from_fields(None, {**PAPER, "sigma": 1}, "f")
    with pytest.raises(ParameterError, match="missing upsilon"):
        ThreatModel.from_fields(None, {"tau_c": 1}, "f")
    with pytest.raises(ParameterError, match="ThreatModel"):
        ThreatModel.from_fields(dict(PAPER), {}, "f")  # type: ignore[arg-type]


# ----------------------------------------------------------------------------- the design functions take them
def test_designs_from_the_value_objects_equal_the_designs_from_the_values() -> None:
    t = ThreatModel(**PAPER)
    by_object = design_from_traces(2, 8, 4, 4, t)
    by_fields = design_from_traces(2, 8, 4, 4, **PAPER)
    assert by_object == by_fields
    assert (by_object.N_star, by_object.lam_star, by_object.k_star) == (13159, 74, 712)  # the paper's reported design
    # the paper's plant A = sqrt(1/2) I, B = 0.5 I has tr Psi_u = 2 and tr Psi_w = 8
    plant = Plant(np.sqrt(0.5) * np.eye(4), 0.5 * np.eye(4))
    assert design_security_parameter(plant, t).N_star == 13159
    with pytest.raises(ParameterError, match="not both"):
        design_from_traces(2, 8, 4, 4, t, tau_c=1.0)
    with pytest.raises(ParameterError, match="ThreatModel"):
        design_security_parameter(plant, dict(PAPER))  # type: ignore[arg-type]


def test_the_threat_carries_the_adversary_and_the_cost_model_to_the_key_length() -> None:
    t = ThreatModel(tau_c=31536e4, upsilon=442e15)
    assert design_key_length(13159, t).k_star == 712
    # one break reveals every key of the token scheme to a malicious server: that one key must
    # then cost the whole budget Upsilon tau_c (2^86.8) instead of 2^86.8 / N*, so it is longer
    server = design_key_length(13159, t.replace(adversary="server"), scheme="token")
    assert server.keys == 1 and server.k_star > 712 and server.lam_star > 74
    pre = design_key_length(13159, t.replace(cost_model=PrecomputationModel(gnfs_correction=5.0)))
    assert pre.model == "precomputation" and pre.gnfs_correction == 5.0
    assert key_length_value(712, t, N_star=13159).secure
    with pytest.raises(ParameterError, match="ThreatModel"):
        key_length_value(712, "paper", N_star=13159)  # type: ignore[arg-type]
