"""The design with the defender's levers (encctl_gym.security.defense_design): each cost term
against a hand count, ``auto`` against hand-computable mixes and a brute force over K, the key
length nondecreasing in K, and the refusals of bad values (library and CLI)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from encctl_gym import cli
from encctl_gym.errors import ParameterError
from encctl_gym.presets import get_preset
from encctl_gym.security.cost_models import deciphering_model
from encctl_gym.security.deciphering import keys_to_break
from encctl_gym.security.defense_design import DefenderCosts, design_defenses, largest_rotation_period, rotated_key_length
from encctl_gym.security.key_length import defense_budget, design_key_length
from encctl_gym.security.threat import ThreatModel

PRESET = get_preset("paper-example")
PHI = np.zeros((PRESET.B.shape[1], PRESET.A.shape[0]))  # A is stable: the zero controller is a controller


def toy_costs(local: float = 1e-3) -> DefenderCosts:
    """Time models a hand can count: t_pow(k) = k microseconds, a safe-prime search 0.5 s."""
    n, m = PRESET.A.shape[0], PRESET.B.shape[1]
    return DefenderCosts(n, m, lambda k: k * 1e-6, lambda k: 0.5, local)


def design(**kw):
    kw.setdefault("costs", toy_costs())
    return design_defenses(PRESET.plant(), ThreatModel.of(PRESET), controller=PHI, **kw)


def test_each_cost_term_is_the_hand_count():
    n, m = PRESET.A.shape[0], PRESET.B.shape[1]
    d = design(cost_models=("precomputation",), rotate_every=100, audit_rate=1e-4, detection_delta=1e-3)
    mix = d.models["precomputation"].chosen
    k = mix.key_length
    assert mix.rotate_every == 100 and mix.audit_rate == 1e-4
    # the plant side per step: 2n to encrypt the state, one key update, n column parts
    assert mix.step_seconds == pytest.approx((2 * n + 1 + n) * k * 1e-6, rel=1e-12)
    # a new group: the search, KeyGen, n m encryptions (two each) and their fixed parts, over K
    assert mix.rotation_seconds == pytest.approx((0.5 + (1 + 2 * n * m + n * m) * k * 1e-6) / 100, rel=1e-12)
    assert mix.audit_seconds == pytest.approx(1e-4 * 1e-3, rel=1e-12)
    assert mix.total_seconds == pytest.approx(mix.step_seconds + mix.rotation_seconds + mix.audit_seconds, rel=1e-12)
    # p = 1e-4 is below p_J: the key carries the security, and (1 - p)^J is the hand's, J the
    # sparse attacker's fewest falsified steps (Phi = 0: J_min = sigma_w2 m / ((n + m) u_max^2 gamma_c))
    u2 = 16 * PRESET.sigma_u2
    J = math.ceil(PRESET.sigma_w2 * m / ((n + m) * u2 * PRESET.gamma_c))
    assert d.fewest_falsified_steps == J and d.audit_steps == min(J, d.N_star) < d.N_star
    assert mix.key_secure and not mix.audit_secure
    assert mix.undetected_probability == pytest.approx(math.exp(d.audit_steps * math.log(1 - 1e-4)), rel=1e-12)


def test_the_noise_moves_n_star_and_its_control_cost_is_the_lyapunov_price():
    base, noisy = design(cost_models=("paper",)), design(cost_models=("paper",), sigma_d2=PRESET.sigma_w2)
    assert noisy.N_star > base.N_star
    assert noisy.models["paper"].k_star <= base.models["paper"].k_star
    # with Phi = 0 the state covariance is the noise Gramian of A with Sigma = sigma_d2 B B^T + sigma_w2 I
    from scipy.linalg import solve_discrete_lyapunov

    A, B, sw = PRESET.A, PRESET.B, PRESET.sigma_w2
    P = solve_discrete_lyapunov(A, sw * (B @ B.T) + sw * np.eye(A.shape[0]))
    assert noisy.noise_price["cost_defended"] == pytest.approx(np.trace(P) + sw * B.shape[1], rel=1e-9)


def test_without_rotation_the_key_is_the_cost_models_design():
    t = ThreatModel.of(PRESET)
    d = design()
    for name in ("paper", "precomputation", "generic"):
        ref = design_key_length(d.N_star, t.replace(cost_model=name)).k_star
        assert d.models[name].k_star == ref == d.models[name].chosen.key_length


def test_larger_k_never_shortens_the_key():
    model = deciphering_model("precomputation")
    N = design().N_star
    keys, budget = keys_to_break(N), defense_budget(PRESET.tau_c, PRESET.upsilon)
    Ks = [1, 2, 5, 10, 30, 100, 300, 1000, 3000, N - 1, N, 10 * N]
    ks = [rotated_key_length(model, keys, budget, K) for K in Ks]
    assert ks == sorted(ks)
    assert ks[0] < ks[-1]  # rotation buys key length under the precomputation model
    assert ks[-1] == rotated_key_length(model, keys, budget, None) == model.minimum_key_length(keys, budget)
    paper = deciphering_model("paper")
    assert len({rotated_key_length(paper, keys, budget, K) for K in Ks}) == 1  # no precomputation: no effect


def test_the_largest_rotation_period_is_the_largest():
    model = deciphering_model("precomputation")
    N = design().N_star
    keys, budget = keys_to_break(N), defense_budget(PRESET.tau_c, PRESET.upsilon)
    k = rotated_key_length(model, keys, budget, 100)
    K = largest_rotation_period(model, k, keys, budget)
    assert K is not None and K >= 100
    c = model.break_cost(k)
    work = lambda K: -(-keys // K) * c.precomputation + keys * c.next  # noqa: E731  (the hand's formula)
    assert work(K) > budget and not work(K + 1) > budget
    assert largest_rotation_period(model, model.minimum_key_length(keys, budget), keys, budget) is None


def test_auto_rotation_is_the_minimum_over_every_period():
    d = design(cost_models=("precomputation",), rotate_every="auto")
    best = d.models["precomputation"].chosen
    N = d.N_star
    costs = toy_costs()
    model = deciphering_model("precomputation")
    keys, budget = keys_to_break(N), defense_budget(PRESET.tau_c, PRESET.upsilon)
    grid = sorted({int(round(v)) for v in np.geomspace(1, N, 150)})
    brute = []
    for K in grid:
        k = rotated_key_length(model, keys, budget, K)
        brute.append(costs.encrypted_step_seconds(k) + costs.rotation_seconds(k) / K)
    brute.append(costs.encrypted_step_seconds(model.minimum_key_length(keys, budget)))
    assert best.key_secure and best.total_seconds <= min(brute) * (1 + 1e-12)


@pytest.mark.parametrize("local, winner", [(1e-3, "audit"), (1e3, "key")])
def test_auto_audits_pick_the_cheaper_of_two_hand_computable_mixes(local, winner):
    n = PRESET.A.shape[0]
    d = design(cost_models=("paper",), audit_rate="auto", detection_delta=1e-3, costs=toy_costs(local))
    N = d.N_star
    p_star = 1 - 1e-3 ** (1 / N)
    assert d.minimum_audit_rate == pytest.approx(p_star, rel=1e-9)  # the rule for an attacker falsifying every sample
    p_J = 1 - 1e-3 ** (1 / d.audit_steps)  # the sparse attacker's: the rate audit-secure mixes pay
    assert d.sparse_audit_rate == pytest.approx(p_J, rel=1e-9) and p_J > p_star
    k_star = d.models["paper"].k_star
    key_mix = (3 * n + 1) * k_star * 1e-6  # the fixed group at k*, no audits
    audit_mix = (3 * n + 1) * 40 * 1e-6 + p_J * local  # the smallest key, audits at p_J
    chosen = d.models["paper"].chosen
    assert chosen.total_seconds == pytest.approx(min(key_mix, audit_mix), rel=1e-9)
    assert (chosen.audit_secure, chosen.key_length) == ((True, 40) if winner == "audit" else (False, k_star))
    assert (audit_mix < key_mix) == (winner == "audit")
    assert (chosen.undetected_probability <= 1e-3) == (winner == "audit")


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"rotate_every": 0}, "rotate_every must be >= 1, got 0"),
        ({"rotate_every": "often"}, "rotate_every must be a number or 'auto'"),
        ({"audit_rate": 1.5}, "audit_rate must lie in \\[0, 1\\], got 1.5"),
        ({"audit_rate": -0.1}, "audit_rate must be >= 0"),
        ({"sigma_d2": -1.0}, "sigma_d2 must be >= 0"),
        ({"detection_delta": 0.0}, "detection_delta must be > 0"),
        ({"detection_delta": 1.0}, "detection_delta must lie in \\(0, 1\\)"),
    ],
)
def test_bad_values_are_refused(kw, match):
    with pytest.raises(ParameterError, match=match):
        design(**kw)


@pytest.mark.parametrize(
    "args, match",
    [
        (["--rotate-every", "0"], "rotate_every must be >= 1, got 0"),
        (["--audit-rate", "2"], "audit_rate must lie in [0, 1], got 2"),
        (["--defense-noise", "-1"], "sigma_d2 must be >= 0"),
        (["--detection-delta", "1"], "detection_delta must lie in (0, 1)"),
    ],
)
def test_the_cli_refuses_bad_values_in_one_line(capsys, args, match):
    assert cli.main(["design", "--preset", "paper-example", *args]) == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1


def test_the_cli_prints_the_section_and_json(capsys):
    argv = ["design", "--preset", "paper-example", "--cost-model", "precomputation", "--rotate-every", "auto"]
    assert cli.main([*argv, "--audit-rate", "auto"]) == 0
    out = capsys.readouterr().out
    assert "Defender's levers" in out and "precomputation: k* =" in out and "audit only" in out
    assert cli.main([*argv, "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    chosen = res["defenses"]["models"]["precomputation"]["chosen"]
    assert chosen["key_secure"] and chosen["rotate_every"] is not None
