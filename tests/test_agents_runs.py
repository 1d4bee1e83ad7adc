"""Training runs where they are used: a missing run directory, a run evaluated in the environment
it was trained in (``evaluate``, ``compare``, the identification strategies), the runs ``compare``
leaves out, and plant files wherever a command takes a system."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("stable_baselines3")

from agents.runs import read_run
from encctl_gym import cli
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
    from agents.config import env_config, load_config
    from agents.train import system_summary
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
