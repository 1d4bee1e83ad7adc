"""Training runs where they are used: a missing run directory, a run evaluated in the environment
it was trained in (``evaluate``, ``compare``, the identification strategies), the runs ``compare``
leaves out, and plant files wherever a command takes a system."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("stable_baselines3")

from encctl_gym import cli
from encctl_gym.agents.runs import read_run
from encctl_gym.errors import ConfigError


def _one_line_error(capsys, argv: list[str], needle: str) -> str:
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0], err
    return err[0]


def test_a_missing_run_directory_says_so_and_names_its_quick_sibling(tmp_path, capsys):
    missing = tmp_path / "ars_small_d0_no_budget_s0"
    with pytest.raises(ConfigError, match="does not exist") as exc:
        read_run(missing)
    assert "-quick" not in str(exc.value)
    quick = tmp_path / "ars_small_d0_no_budget_s0-quick"
    quick.mkdir()
    (quick / "run.json").write_text(json.dumps({"algo": "ars", "observation": "no_budget", "env": {}}))
    line = _one_line_error(capsys, ["evaluate", str(missing), "--no-progress"], "does not exist")
    assert str(quick) in line
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(ConfigError, match="is not a training run"):
        read_run(empty)


def test_train_system_reports_the_systems_defense_period_and_the_shortened_training_one(tmp_path):
    from encctl_gym.agents.config import env_config, load_config
    from encctl_gym.agents.train import system_summary
    from encctl_gym.envs.config import resolve_params
    from encctl_gym.presets import get_preset

    plant = tmp_path / "plant.json"
    plant.write_text(json.dumps({"A": [[0.5, 0.1], [0.0, 0.3]], "B": [[1.0], [0.5]], "sigma_w2": 0.5}))
    cfg = load_config("ars", "paper-example", system=plant)
    line = system_summary(cfg, plant)
    own = get_preset("paper-example").tau_c
    short = resolve_params(env_config(cfg)).tau_c
    assert short < own
    assert f"tau_c = {own:g} s" in line
    assert f"shortened to {short:g} s" in line and f"N = {cfg['horizon']} samples" in line


# ------------------------------------------------------------------ a run plays in its own environment
@pytest.fixture(scope="module")
def ars_run(tmp_path_factory):
    """A tiny ARS run on ``small``: its config sets input_history 0, the environment default is 2."""
    from encctl_gym.agents.config import apply_override, load_config
    from encctl_gym.agents.train import train

    cfg = load_config("ars", "small", quick=True)
    for item in ("n_timesteps=512", "eval.freq=256", "eval.episodes=2"):
        apply_override(cfg, item)
    assert cfg["env"]["input_history"] == 0
    return train(cfg, out=tmp_path_factory.mktemp("train"), progress=False, tensorboard=False)


def test_compare_plays_a_run_in_the_environment_it_was_trained_in(ars_run, tmp_path, capsys):
    from encctl_gym.experiments.compare.attackers import learned_players, run_setting
    from encctl_gym.experiments.compare.protocol import compute
    from encctl_gym.experiments.compare.settings import make_setting

    run = read_run(ars_run)
    setting = make_setting("small", 0, 24)
    assert setting.params.input_history == 2
    play = run_setting(run, setting)
    assert not isinstance(play, str) and play.params.input_history == 0 and play.params.horizon == setting.params.horizon
    [(att, where)] = learned_players(setting, [run])
    assert where.params.input_history == 0
    res = compute(
        ("small",),
        delays=(0,),
        episodes=2,
        cap=24,
        points=2,
        runs=[run],
        elgamal_episodes=1,
        elgamal_N=8,
        attackers=("gaussian",),
    )
    assert [c.attacker for c in res.curves[("small", 0)]] == ["gaussian", "ars"]
    assert (
        cli.main(
            [
                "compare",
                "--quick",
                "--systems",
                "small",
                "--delays",
                "0",
                "--runs",
                str(ars_run),
                "--points",
                "2",
                "--episodes",
                "2",
                "--elgamal-episodes",
                "0",
                "--no-progress",
                "--out",
                str(tmp_path / "c"),
                "--attackers",
                "gaussian",
            ]
        )
        == 0
    )
    assert "| ars |" in capsys.readouterr().out


def test_identification_strategies_and_evaluate_play_a_run_in_its_environment(ars_run, tmp_path):
    import encctl_gym.experiments.identification_strategies as strat
    from encctl_gym.experiments.compare.evaluate_run import run_settings

    run = read_run(ars_run)
    res = strat.compute(("small",), estimators=("ls",), episodes=2, cap=16, points=2, runs=[run])
    assert "ars" in [c.attacker for c in res.curves["small"]]
    [s] = run_settings(run, ("small",), (0,), 16)
    assert s.params.input_history == 0


def test_compare_says_which_runs_it_leaves_out_and_why(ars_run, tmp_path, capsys):
    import shutil

    from encctl_gym.agents.runs import find_runs
    from encctl_gym.experiments.compare.attackers import left_out, run_setting
    from encctl_gym.experiments.compare.settings import make_setting

    run = read_run(ars_run)
    skipped: list = []
    assert find_runs([ars_run.parent], left_out=skipped) == []
    assert skipped == [(ars_run, skipped[0][1])] and "--quick" in skipped[0][1]
    assert "not 'paper-example'" in run_setting(run, make_setting("paper-example", 0, 24))
    assert "reads delivered states" in run_setting(run, make_setting("small", "end", 24))
    # the same label, another system: trained with another noise variance
    other = tmp_path / "other"
    shutil.copytree(ars_run, other)
    meta = json.loads((other / "run.json").read_text())
    meta["env"]["sigma_w2"] = 0.5
    (other / "run.json").write_text(json.dumps(meta))
    [(r, why)] = left_out([read_run(other)], [make_setting("small", 0, 24)])
    assert "sigma_w2 = 0.5" in why
    assert (
        cli.main(
            [
                "compare",
                "--quick",
                "--systems",
                "paper-example",
                "--delays",
                "0",
                "--runs",
                str(ars_run.parent),
                "--runs",
                str(other),
                "--points",
                "2",
                "--episodes",
                "2",
                "--elgamal-episodes",
                "0",
                "--no-progress",
                "--out",
                str(tmp_path / "c"),
                "--attackers",
                "gaussian",
            ]
        )
        == 0
    )
    err = [line for line in capsys.readouterr().err.splitlines() if "leaving out" in line]
    assert len(err) == 2 and str(ars_run) in err[0] and "--quick" in err[0]
    assert str(other) in err[1] and "trained on 'small'" in err[1]


def test_a_refusal_to_play_names_the_run(ars_run):
    from encctl_gym.agents.sb3 import load_attacker
    from encctl_gym.envs.config import resolve_params

    with pytest.raises(ConfigError, match="input_history = 0 in training, 2 here") as exc:
        load_attacker(ars_run, params=resolve_params({"preset": "small", "gamma_opt": False}))
    assert str(ars_run) in str(exc.value)


# ------------------------------------------------------------------ plant files wherever a system is taken
def test_every_command_that_takes_a_system_takes_a_plant_file(ars_run, tmp_path, capsys):
    from encctl_gym.experiments.compare.settings import system_entry
    from encctl_gym.presets import get_preset

    small = get_preset("small")
    plant = tmp_path / "myplant.json"
    plant.write_text(json.dumps({"A": small.A.tolist(), "B": small.B.tolist(), "sigma_w2": 0.5}))
    label, cfg = system_entry(str(plant))
    assert label == "myplant" and cfg is not None and cfg["sigma_w2"] == 0.5 and cfg["A"] == small.A.tolist()
    assert system_entry("small") == ("small", None)
    _one_line_error(
        capsys,
        ["compare", "--quick", "--systems", "no-such-system", "--no-progress", "--out", str(tmp_path / "x")],
        "no plant file of that name",
    )
    _one_line_error(
        capsys,
        ["compare", "--quick", "--systems", str(tmp_path / "none.json"), "--no-progress", "--out", str(tmp_path / "x")],
        "does not exist",
    )
    assert (
        cli.main(
            [
                "compare",
                "--quick",
                "--systems",
                str(plant),
                "--delays",
                "0",
                "--points",
                "2",
                "--episodes",
                "2",
                "--elgamal-episodes",
                "0",
                "--no-progress",
                "--out",
                str(tmp_path / "c"),
                "--attackers",
                "gaussian",
            ]
        )
        == 0
    )
    assert "| myplant | 0 | gaussian |" in capsys.readouterr().out
    assert (
        cli.main(
            [
                "evaluate",
                str(ars_run),
                "--systems",
                str(plant),
                "--points",
                "2",
                "--episodes",
                "2",
                "--samples",
                "16",
                "--no-progress",
                "--out",
                str(tmp_path / "e"),
            ]
        )
        == 0
    )
    assert "myplant" in capsys.readouterr().out
