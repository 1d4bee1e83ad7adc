"""Issue 34, items 14, 21, 23, 24 (the last in test_agents_train.py): inputs that gave a
traceback or were silently accepted; each test fails without its fix."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from encctl_gym._validation import check_path_name, check_regular_file
from encctl_gym.errors import ConfigError, EncctlError, ParameterError
from encctl_gym.loop.output_feedback import lqg_controller, static_output_feedback
from encctl_gym.plant import observable_order
from encctl_gym.safe_yaml import load_yaml

# a 3-state plant C = [1 0 1] observes: every mode reaches the output (the issue's own plant shape)
A3 = np.array([[0.5, 0.1, 0.0], [0.0, 0.3, 0.2], [0.1, 0.0, 0.4]])
B3 = np.array([[1.0], [0.0], [0.5]])
C3 = np.array([[1.0, 0.0, 1.0]])


# ---------------------------------------------------------------- item 14: scale-free tests
@pytest.mark.parametrize("scale", [1e-300, 1e-200, 1e-12, 1.0, 1e8, 1e12, 1e200, 1e300])
def test_the_observable_order_does_not_depend_on_the_scale_of_c(scale):
    assert observable_order(A3, scale * C3) == 3
    # two equal eigenvalues seen through one output: order 2 at every scale (hand count)
    assert observable_order(np.diag([0.5, 0.5, 0.3]), scale * np.ones((1, 3))) == 2


def test_a_zero_output_matrix_observes_nothing():
    assert observable_order(A3, np.zeros((1, 3))) == 0


@pytest.mark.parametrize("scale", [1e-150, 1e155, 1e300])
def test_the_output_feedback_gain_scales_back_with_c(scale):
    """``u = Phi y`` with ``y = s C x``: the optimal gain for ``s C`` is the gain for ``C`` over
    ``s`` (the cost depends on ``Phi C`` alone), and C = 1e155 I no longer overflows."""
    ref = static_output_feedback(A3, B3, C3)
    got = static_output_feedback(A3, B3, scale * C3)
    np.testing.assert_allclose(got * scale, ref, rtol=1e-9)
    big = static_output_feedback(A3, B3, scale * np.eye(3))
    assert np.all(np.isfinite(big)) and np.max(np.abs(A3 + B3 @ big @ (scale * np.eye(3))).sum(1)) < 2


def test_the_lqg_filter_on_a_scaled_output_is_the_filter_of_the_scaled_measurement():
    """Dividing y by s divides the measurement noise by s: the LQG of (s C, s^2 V) is the LQG of
    (C, V) with its measurement gain over s; the closed loop is the same."""
    ref = lqg_controller(A3, B3, C3, sigma_w2=1.0, sigma_v2=0.5)
    for s in (3.0, 1e100):  # sigma_v2 stays above the measurement floor (a fraction of sigma_w2)
        got = lqg_controller(A3, B3, s * C3, sigma_w2=1.0, sigma_v2=0.5 * s * s)
        np.testing.assert_allclose(got.F, ref.F, rtol=1e-7, atol=1e-12)
        np.testing.assert_allclose(got.G * s, ref.G, rtol=1e-7, atol=1e-12)
    huge = lqg_controller(A3, B3, 1e155 * np.eye(3), sigma_w2=1.0, sigma_v2=0.0)  # C S C^T overflowed before
    assert np.all(np.isfinite(huge.F)) and np.all(np.isfinite(huge.G))
    with pytest.raises(ParameterError, match="finite nonzero"):
        lqg_controller(A3, B3, np.zeros((1, 3)), sigma_w2=1.0, sigma_v2=0.0)


def test_an_environment_on_huge_outputs_gets_a_package_error_not_linalgerror():
    from encctl_gym.envs import EncryptedLTIAttackEnv

    env = EncryptedLTIAttackEnv(config={"preset": "paper-example", "observe": "output", "C": (1e155 * np.eye(4)).tolist()})
    with pytest.raises(EncctlError, match="x_bound"):  # the outputs leave the encoder's range
        env.reset(seed=0)
        env.step(np.zeros(env.action_space.shape, dtype=np.float32))


# ---------------------------------------------------------------- item 21: silently accepted
def test_a_rotating_defender_given_as_a_dict_cannot_wrap_another():
    from encctl_gym.loop.rotation import RotatingDefender

    with pytest.raises(ParameterError, match="cannot wrap another rotating defender"):
        RotatingDefender(every=3, inner={"name": "rotate", "every": 2})
    with pytest.raises(ParameterError, match="cannot wrap another rotating defender"):
        RotatingDefender(every=3, inner=RotatingDefender(every=2))
    assert RotatingDefender(every=3, inner={"name": "noise", "sigma_d2": 0.1}).inner.name == "noise"


def _yaml(text):
    return load_yaml(text, what="plant file", max_nodes=100, max_depth=10, aliases=True)


@pytest.mark.parametrize(
    "text",
    [
        "a: &a {A: 1}\nb: &b {A: 2}\nc:\n  <<: *a\n  <<: *b\n",  # two merge keys
        "a: &a {A: 1}\nb: &b {A: 2}\nc:\n  <<: [*a, *b]\n",  # one merge of two mappings
        "a: &a {A: 1}\nb: &b {<<: *a}\nc:\n  <<: [*a, *b]\n",  # the second gives A through its own merge
    ],
)
def test_two_merges_that_give_one_key_are_refused(text):
    with pytest.raises(ConfigError, match="'A' is given by two merges"):
        _yaml(text)


def test_a_key_written_beside_a_merge_overrides_it_as_yaml_says():
    assert _yaml("a: &a {A: 1, B: 2}\nc:\n  <<: *a\n  A: 3\n")["c"] == {"A": 3, "B": 2}
    assert _yaml("a: &a {A: 1}\nb: &b {B: 2}\nc:\n  <<: [*a, *b]\n")["c"] == {"A": 1, "B": 2}


def test_design_refuses_a_plant_file_whose_merges_give_a_twice(tmp_path, capsys):
    from encctl_gym import cli

    f = tmp_path / "p.yaml"
    f.write_text("x-one: &one {A: [[0.5]]}\nx-two: &two {A: [[0.9]]}\n<<: [*one, *two]\nB: [[1.0]]\n")
    assert cli.main(["design", str(f)]) == 2  # design exited 0 with one of the two A's
    err = capsys.readouterr().err.strip()
    assert "'A' is given by two merges" in err and len(err.splitlines()) == 1


def test_the_games_inject_flag_must_lie_in_its_action_space():
    pytest.importorskip("pettingzoo")
    from encctl_gym.agents.evaluate import budget_config, env_config
    from encctl_gym.agents.game import defender_action
    from encctl_gym.multiagent import EncryptedControlGame

    game = EncryptedControlGame(budget_config(env_config({"preset": "paper-example"}), 16))
    game.reset(seed=0)
    m = game.params.m
    for flag in (1e30, -1.5, 1.0 + 1e-6):
        with pytest.raises(ParameterError, match="inject flag must lie in \\[-1, 1\\]"):
            game.step({"attacker": np.r_[np.zeros(m), flag], "defender": defender_action()})
    game.step({"attacker": np.r_[np.zeros(m), 1.0], "defender": defender_action()})  # the bound itself is in


# ---------------------------------------------------------------- item 23: raw Python errors
def test_a_precomputation_that_is_not_a_path_is_named():
    from encctl_gym.cryptanalysis import get_breaker

    with pytest.raises(ParameterError, match="precomputation file must be a path.*123"):
        get_breaker("index-calculus", precomputation=123)
    with pytest.raises(ParameterError, match="must be a path"):
        check_regular_file("plant file", 4.5)


def test_names_no_file_can_have_are_refused_before_any_work(tmp_path):
    with pytest.raises(ParameterError, match="NAME_MAX"):
        check_path_name("run name (--name)", "a" * 300)
    with pytest.raises(ParameterError, match="NAME_MAX"):
        check_path_name("--save-precomputation", str(tmp_path / ("b" * 300) / "f.npz"))
    with pytest.raises(ParameterError, match="NUL"):
        check_path_name("run name (--name)", "a\x00b")
    with pytest.raises(ParameterError, match="PATH_MAX"):
        check_path_name("x", "/".join(["c" * 200] * 30))
    assert check_path_name("run name", "a" * 200) == "a" * 200


def test_train_and_crack_refuse_a_long_name_in_one_line(tmp_path, capsys):
    from encctl_gym import cli

    code = cli.main(["crack", "--bits", "40", "--keys", "1", "--breaker", "index-calculus",
                     "--save-precomputation", str(tmp_path / ("a" * 300))])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert code == 2 and "NAME_MAX" in err and len(err.splitlines()) == 1


def test_overwrite_refuses_a_run_name_that_is_a_symbolic_link(tmp_path):
    pytest.importorskip("stable_baselines3")
    from encctl_gym.agents.runs import RUN_FILE, new_run_dir

    other = tmp_path / "elsewhere"
    other.mkdir()
    (other / RUN_FILE).write_text("{}")
    runs = tmp_path / "runs"
    runs.mkdir()
    os.symlink(other, runs / "lnk")
    with pytest.raises(ConfigError, match="symbolic link"):
        new_run_dir(runs, "lnk", overwrite=True)
    assert (other / RUN_FILE).exists() and Path(runs / "lnk").is_symlink()  # nothing was deleted
    with pytest.raises(ParameterError, match="NUL"):
        new_run_dir(runs, "a\x00b")
