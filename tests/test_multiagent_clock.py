"""The game's deciphering clock charged per group (encctl_gym.multiagent.clock): the defender's
rotations shorten the attack under the precomputation model exactly as the single environment's
``rotate_group_every`` horizon says, change nothing under the paper's model; and the game's
refusal of ``observe="output"``."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

pytest.importorskip("pettingzoo")

from encctl_gym.agents.evaluate import budget_config, env_config  # noqa: E402
from encctl_gym.agents.game import RotateEvery, defender_action  # noqa: E402
from encctl_gym.envs.config import resolve_params  # noqa: E402
from encctl_gym.errors import ParameterError  # noqa: E402
from encctl_gym.multiagent import EncryptedControlGame  # noqa: E402
from encctl_gym.multiagent.clock import GroupClock  # noqa: E402
from encctl_gym.security.rotation import rotated_deciphering_time  # noqa: E402

N = 40


def _cfg(model="precomputation"):
    return budget_config(env_config({"preset": "paper-example", "deciphering_model": model, "key_length": 128}), N)


def _run(cfg, defender, seed=0):
    """One game, the attacker injecting zeros: per step (attacker obs, attacker info, terminated)."""
    game = EncryptedControlGame(cfg)
    m = game.params.m
    obs, _ = game.reset(seed=seed)
    defender.reset()
    steps = []
    while game.agents:
        obs, _, term, _, info = game.step({"attacker": np.r_[np.zeros(m), 1.0], "defender": defender.act(obs["defender"])})
        steps.append((obs["attacker"], info["attacker"], term["attacker"]))
    game.close()
    return game, steps


@pytest.mark.parametrize("K", [10, 16])
def test_rotating_every_k_ends_the_attack_where_the_single_environments_horizon_does(K):
    cfg = _cfg()
    reference = resolve_params({**cfg, "rotate_group_every": K}).horizon  # the configuration's exact arithmetic
    assert reference < N  # the precomputation of a second group is more than the budget left
    game, steps = _run(cfg, RotateEvery(K))
    _, info, terminated = steps[-1]
    assert info["samples_collected"] == reference and terminated and not info["detected"]
    p = game.params
    expected = rotated_deciphering_time(reference, p.cost, p.upsilon, K, scheme=p.loop.encryption(), adversary=p.adversary)
    assert info["deciphering_time"] == pytest.approx(float(expected), rel=1e-12) and info["deciphering_time"] <= p.tau_c


def test_rotating_at_every_step_leaves_the_attacker_one_sample():
    cfg = _cfg()
    p = resolve_params(cfg)
    assert p.upsilon * p.tau_c < 2 * p.cost.first  # hand count: two precomputations are more than the budget
    _, steps = _run(cfg, RotateEvery(1))
    assert len(steps) == 1 and steps[0][1]["samples_collected"] == 1 and steps[0][2]


def test_without_rotation_and_under_the_papers_model_the_attack_keeps_its_length():
    _, steps = _run(_cfg(), RotateEvery(10**6))
    assert steps[-1][1]["samples_collected"] == N
    _, steps = _run(_cfg("paper"), RotateEvery(5))  # every key costs the same: rotation changes nothing
    assert steps[-1][1]["samples_collected"] == N and steps[-1][1]["group_rotations"] > 0


def test_the_observed_budget_fraction_counts_the_new_groups_precomputation():
    base = _cfg()
    cfg = {**base, "tau_c": 3 * base["tau_c"], "max_samples": N}  # room for two precomputations
    game, steps = _run(cfg, RotateEvery(8))
    p, at = game.params, game.episode.layout.time_fraction
    budget = Fraction(p.upsilon) * Fraction(p.tau_c)
    first, nxt = Fraction(p.cost.first), Fraction(p.cost.next)
    fractions = [float(obs[at]) for obs, _, _ in steps]
    # step k collects sample k + 2 (x_0 at reset); the rotation before step 7 puts sample 9 in group 2
    for k, f in enumerate(fractions[:6]):
        assert f == pytest.approx(float((first + (k + 1) * nxt) / budget), rel=1e-6)
    assert fractions[7] == pytest.approx(float((2 * first + 7 * nxt) / budget), rel=1e-6)
    # three times the budget of one group of N: three precomputations, so three groups of 8 (a fourth costs more)
    assert first > 200 * nxt and max(fractions) <= 1.0 and steps[-1][1]["samples_collected"] == 3 * 8


def test_the_clock_charges_groups_by_hand_count():
    p = resolve_params(_cfg())
    clock = GroupClock(p)
    first, nxt = clock.first, clock.next
    for n in (1, 7, N):  # one group: the episode's own table (sample_deciphering_time)
        assert float(clock.work(n, 1) / clock.upsilon) == pytest.approx(float(p.deciphering_time(n)), rel=1e-12)
    clock.reset(1)
    assert clock.work(1, 1) == first and clock.work(0, 1) == 0
    clock.advance(2, rotated=False)
    clock.advance(2, rotated=True)  # moved, no sample yet: the group is not charged
    assert clock.groups == 1 and clock.rotated
    clock.advance(3, rotated=False)
    assert clock.groups == 2 and clock.work(clock.samples, clock.groups) == 2 * first + nxt


def test_the_game_refuses_observe_output_naming_observe():
    cfg = budget_config(env_config({"preset": "paper-example", "observe": "output"}), N)
    with pytest.raises(ParameterError, match="observe"):
        EncryptedControlGame(cfg)


def test_a_defender_that_never_rotates_is_unchanged_by_the_clock():
    cfg = _cfg()
    _, a = _run(cfg, RotateEvery(10**6))
    game = EncryptedControlGame(cfg)
    m = game.params.m
    game.reset(seed=0)
    for obs, info, _ in a:
        o, _, _, _, i = game.step({"attacker": np.r_[np.zeros(m), 1.0], "defender": defender_action()})
        assert np.array_equal(o["attacker"], obs) and i["attacker"]["deciphering_time"] == info["deciphering_time"]


@pytest.mark.slow
def test_the_static_only_table_records_the_rotation_rows(tmp_path):
    from encctl_gym.experiments.game import main

    assert main(["--static-only", "--N", "32", "--episodes", "2", "--out", str(tmp_path)]) == 0
    text = (tmp_path / "game_static.md").read_text()
    samples = text.split("**samples collected**")[1].split("**")[0]
    rows = {line.split(" | ")[0].strip("| "): line for line in samples.splitlines() if line.startswith("| rotate")}
    assert set(rows) == {"rotate(K=1)", "rotate(K=10)", "rotate(K=100)"}
    assert rows["rotate(K=10)"].count("| 10 ") == 5 and rows["rotate(K=100)"].count("| 32 ") == 5  # K past N: one group
    assert (tmp_path / "game_static_cells.csv").read_text().count("\n") == 1 + 7 * 5


def test_combined_defenders_set_a_lever_if_any_of_them_does():
    from encctl_gym.agents.game import Combined, ConstantNoise, DetectorAudit

    both = Combined(DetectorAudit(2, 1), RotateEvery(2), ConstantNoise(0.25))
    assert both.name == "chi2+rotate(K=2)+noise(0.25)"
    both.reset(0)
    quiet, alarm = np.zeros(6, np.float32), np.array([0, 0, 0, 2.0, 0, 0], np.float32)  # entry n + m: the statistic
    got = [both.act(o).tolist() for o in (quiet, alarm, quiet, quiet)]
    assert got == [[-1, 0.25, -1, -1], [1, 0.25, 1, -1], [-1, 0.25, -1, -1], [-1, 0.25, 1, -1]]
    with pytest.raises(ParameterError, match="two defenders"):
        Combined(RotateEvery(2))
