"""The design with verification (issue 33 item 3): the cheapest secure mix with the keyed linear
check priced per step, and ``encctl-gym design --verify``."""

from __future__ import annotations

import json

import pytest

from encctl_gym.cli import main
from encctl_gym.errors import ParameterError
from encctl_gym.presets import get_preset
from encctl_gym.security.defense_design import DefenderCosts, design_defenses
from encctl_gym.security.threat import ThreatModel
from encctl_gym.security.verification_design import design_verification


def _design(local_control_seconds: float, audit_rate=None):
    preset = get_preset("paper-example")
    costs = DefenderCosts(4, 4, lambda k: 1e-9 * k * k, lambda k: 1e-3 * k, local_control_seconds)
    threat = ThreatModel.of(preset)
    import numpy as np

    d = design_defenses(preset.plant(), threat, costs=costs, controller=-0.5 * np.eye(4), audit_rate=audit_rate)
    return d, costs


def test_the_check_wins_when_it_is_cheaper_than_the_key_it_saves():
    d, costs = _design(1e-6)
    v = design_verification(d, costs, {"name": "linear-check", "params": {}}, check_seconds=1e-7).verification
    assert v.secret_range == 1000 and v.epsilon == 1e-3  # ceil(1 / delta), delta = 1e-3
    for entry in v.models.values():
        vm = entry["verified"]
        assert vm.verification_secure and vm.key_length == min(d.min_key_length, entry["unverified"].key_length)
        assert vm.total_seconds == pytest.approx(costs.encrypted_step_seconds(vm.key_length) + 1e-7)
        assert entry["chosen"] == ("verified" if vm.total_seconds < entry["unverified"].total_seconds else "unverified")
        assert entry["chosen"] == "verified"  # no audits offered: the unverified mix pays k*


def test_a_check_too_weak_alone_is_not_secure_and_auto_audits_complete_it():
    d, costs = _design(1e-6, audit_rate="auto")
    v = design_verification(d, costs, {"name": "linear-check", "params": {"secret_range": 10}}, check_seconds=0.0).verification
    assert v.epsilon == 0.1
    for entry in v.models.values():
        vm = entry["verified"]
        # epsilon (1 - p)^(J - 1) <= delta with the smallest such p, J the sparse attacker's falsified steps
        assert vm.verification_secure and 0 < vm.audit_rate < d.sparse_audit_rate
        assert vm.undetected_probability == pytest.approx(0.1 * (1 - vm.audit_rate) ** (d.audit_steps - 1), rel=1e-12)
        assert vm.undetected_probability <= 1e-3 * (1 + 1e-9)


@pytest.mark.parametrize(
    "verify, word",
    [
        ({"name": "mac", "params": {}}, "Paillier"),
        ({"name": "tag", "params": {}}, "tag"),
        ({"name": "linear-check", "params": {"secret_range": 1}}, "secret_range"),
        ({"name": "linear-check", "params": {"alpha": 3}}, "alpha"),
    ],
)
def test_bad_checks_raise_parameter_error(verify, word):
    d, costs = _design(1e-6)
    with pytest.raises(ParameterError, match=word):
        design_verification(d, costs, verify, check_seconds=1e-7)


def test_the_design_command_prints_and_dumps_the_verification(capsys):
    assert main(["design", "--preset", "paper-example", "--verify", "linear-check", "--verify-param", "secret_range=4096"]) == 0
    out = capsys.readouterr().out
    assert "Verification: linear-check, R = 4096" in out and "with the check" in out
    assert main(["design", "--preset", "paper-example", "--verify", "auto", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["defenses"]["verification"]["name"] == "linear-check"


def test_the_design_command_refuses_bad_verify_values_in_one_line(capsys):
    assert main(["design", "--preset", "paper-example", "--verify", "linear-check", "--verify-param", "secret_range=1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "secret_range" in err[0]
    assert main(["design", "--preset", "paper-example", "--verify-param", "secret_range=8"]) == 2
    assert "--verify" in capsys.readouterr().err
