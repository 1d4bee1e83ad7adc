"""Hyperparameter search (agents.tune, encctl-gym tune): a two-trial study end to end, its
objective reproduced by direct paired rollouts, the tuned YAML file, resuming from the SQLite
storage, and one-line errors (including a missing optuna)."""

from __future__ import annotations

import builtins
import importlib.util

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from encctl_gym import cli
from encctl_gym.agents import OptimalDesignAttacker, rollout
from encctl_gym.agents.config import load_config, read_yaml
from encctl_gym.agents.runs import read_run
from encctl_gym.agents.sb3 import load_attacker
from encctl_gym.agents.tune import OBJECTIVE_SEED, SEARCH_SPACES, objective_ratio, tune
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import EncctlError

ALGOS_WITH_SPACES = ("ppo", "ars", "sac", "recurrent_ppo")


def test_every_algorithm_has_a_search_space():
    from encctl_gym.agents.sb3 import ALGORITHMS

    assert set(SEARCH_SPACES) == set(ALGORITHMS) == set(ALGOS_WITH_SPACES)


def test_two_trial_study_writes_a_tuned_file_and_resumes(tmp_path, capsys):
    optuna = pytest.importorskip("optuna")
    argv = [
        "tune",
        "--algo",
        "ars",
        "--preset",
        "small",
        "--quick",
        "--trials",
        "2",
        "--episodes",
        "4",
        "--out",
        str(tmp_path),
        "--no-progress",
        "--no-prune",
        "--set",
        "horizon=16",
    ]
    assert cli.main(argv) == 0
    out = capsys.readouterr().out
    assert "2 trials; best trial" in out and "ars_small.yaml" in out
    study = optuna.load_study(study_name="ars_small", storage=f"sqlite:///{tmp_path / 'study.db'}")
    assert len(study.trials) == 2
    best = study.best_trial
    # the objective: the paired ratio to the oracle on the objective seeds, reproduced directly
    run = read_run(best.user_attrs["run_dir"])
    cfg = {**run.env, "gamma_opt": False}
    p = resolve_params(cfg)
    which = "best" if (run.path / "best_model.zip").exists() else "final"
    e_l = rollout(
        load_attacker(run.path, which=which, params=p), cfg, episodes=4, seed=OBJECTIVE_SEED, record=False
    ).final_epsilon
    e_o = rollout(OptimalDesignAttacker(p), cfg, episodes=4, seed=OBJECTIVE_SEED, record=False).final_epsilon
    assert best.value == pytest.approx(float(np.exp(np.mean(np.log(e_l) - np.log(e_o)))), rel=1e-9)
    assert objective_ratio(run.path, episodes=4)[0] == pytest.approx(best.value, rel=1e-9)
    # the tuned file: a config the loader accepts, with the best trial's drawn values
    tuned = tmp_path / "ars_small.yaml"
    data = read_yaml(tuned)
    assert data["hyperparams"]["n_delta"] == best.params["n_delta"]
    assert data["hyperparams"]["step_rule"] == best.params["step_rule"]
    cfg2 = load_config("ars", "small", path=tuned)
    assert cfg2["hyperparams"]["learning_rate"] == pytest.approx(best.params["learning_rate"])
    # running again resumes the same study from its SQLite file
    argv[argv.index("--trials") + 1] = "1"
    assert cli.main(argv) == 0
    assert "3 trials" in capsys.readouterr().out


def test_tune_errors_are_one_line(tmp_path, capsys, monkeypatch):
    for argv, needle in (
        (["tune", "--algo", "ars", "--trials", "0", "--out", str(tmp_path)], "--trials must be >= 1"),
        (["tune", "--algo", "ars", "--save-config", "--out", str(tmp_path)], "needs --preset"),
        (
            ["tune", "--algo", "ars", "--preset", "small", "--quick", "--set", "hyperparams.n_delta=0", "--out", str(tmp_path)],
            "hyperparams.n_delta must be >= 1",
        ),
        (
            ["tune", "--algo", "ars", "--preset", "small", "--quick", "--seed", "-1", "--out", str(tmp_path)],
            "seed must be >= 0, got -1",
        ),
        (
            ["tune", "--algo", "ars", "--preset", "small", "--quick", "--seed", str(2**32), "--out", str(tmp_path)],
            "seed must be <= 4294967295, got 4294967296",
        ),
    ):
        assert cli.main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and needle in err[0], err
    if importlib.util.find_spec("optuna") is not None:  # the output directory is checked once Optuna is there
        afile = tmp_path / "afile"
        afile.write_text("x")
        assert cli.main(["tune", "--algo", "ars", "--preset", "small", "--quick", "--out", str(afile), "--no-progress"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "the tuning directory (--out)" in err[0] and "is not a directory" in err[0], err
        assert afile.read_text() == "x"
    real_import = builtins.__import__

    def no_optuna(name, *args, **kwargs):
        if name == "optuna" or name.startswith("optuna."):
            raise ModuleNotFoundError("No module named 'optuna'", name="optuna")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_optuna)
    cfg = load_config("ars", "small", quick=True)
    with pytest.raises(EncctlError, match=r"pip install 'encctl-gym\[optuna\]'"):
        tune(cfg, trials=1, out=tmp_path)
