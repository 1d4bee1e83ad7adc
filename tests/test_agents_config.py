"""Training configurations: layers, the schema, hyperparameters against the constructors, hostile
files, plant files, run directories and broken runs (no training here)."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from encctl_gym import cli
from encctl_gym.agents.config import (
    CONFIG_DIR,
    DEFAULTS_DIR,
    apply_override,
    default_config,
    env_config,
    load_config,
    read_yaml,
    run_name,
)
from encctl_gym.agents.hyperparams import check_value
from encctl_gym.agents.runs import find_runs, new_run_dir, read_run
from encctl_gym.agents.sb3 import ALGORITHMS, SB3VecEnv, algorithm_class, load_attacker
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ConfigError, ResourceLimitError
from encctl_gym.presets import get_preset


def _one_line_error(capsys, argv: list[str], needle: str) -> str:
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0], err
    return err[0]


# ------------------------------------------------------------------ layers
def test_every_algorithm_has_a_default_and_every_file_resolves():
    assert sorted(p.stem for p in DEFAULTS_DIR.glob("*.yaml")) == sorted(ALGORITHMS)
    for algo in ALGORITHMS:
        for quick in (False, True):
            cfg = load_config(algo, "fig1-e", quick=quick)  # a preset without a tuned file
            assert cfg["env"]["preset"] == "fig1-e" and cfg["system"] == "fig1-e"
            assert cfg["config_files"] == [str(DEFAULTS_DIR / f"{algo}.yaml")]
            assert resolve_params(env_config(cfg)).horizon == cfg["horizon"]
            venv = SB3VecEnv(env_config(cfg), 1, cfg["observation"])
            assert venv.observation_space.shape[0] >= 1
    for path in CONFIG_DIR.glob("*_*.yaml"):
        algo, preset = next(
            (a, path.stem[len(a) + 1 :]) for a in sorted(ALGORITHMS, key=len, reverse=True) if path.stem.startswith(a + "_")
        )
        cfg = load_config(algo, preset)
        assert cfg["config_files"][-1] == str(path) and cfg["env"]["preset"] == preset


def test_a_tuned_file_overrides_the_default_and_quick_overrides_both():
    default = default_config("ppo")
    tuned = load_config("ppo", "paper-example")
    recipe = read_yaml(CONFIG_DIR / "ppo_paper-example.yaml")  # the PPO recipe of the design example
    assert tuned["n_timesteps"] == recipe["n_timesteps"] != default["n_timesteps"]
    assert tuned["hyperparams"]["policy_kwargs"]["net_arch"] == recipe["hyperparams"]["policy_kwargs"]["net_arch"]
    assert tuned["hyperparams"]["learning_rate"] == recipe["hyperparams"]["learning_rate"]
    assert tuned["eval"]["episodes"] == default["eval"]["episodes"]  # merged, not replaced
    quick = load_config("ppo", "paper-example", quick=True)
    assert quick["n_timesteps"] == 4096 and quick["hyperparams"]["n_steps"] == 128
    assert quick["hyperparams"]["gamma"] == recipe["hyperparams"]["gamma"]  # merged, not replaced


def test_config_file_then_preset(tmp_path):
    f = tmp_path / "mine.yaml"
    f.write_text("algo: sac\nenv: {preset: fig1-c}\nn_timesteps: 777\nquick: {n_timesteps: 55}\n")
    cfg = load_config("sac", path=f)
    assert (cfg["env"]["preset"], cfg["n_timesteps"]) == ("fig1-c", 777)
    assert load_config("sac", path=f, quick=True)["n_timesteps"] == 55
    assert load_config("sac", "fig1-g", path=f)["env"]["preset"] == "fig1-g"  # --preset names the system
    with pytest.raises(ConfigError, match="not 'ppo'"):
        load_config("ppo", path=f)


def test_system_file_replaces_a_and_b(tmp_path):
    A = [[0.5, 0.1], [0.0, 0.3]]
    B = [[1.0], [0.5]]
    f = tmp_path / "plant.json"
    f.write_text(json.dumps({"A": A, "B": B}))
    cfg = load_config("ppo", system=f)
    p = resolve_params(env_config(cfg))
    assert np.array_equal(p.A, np.array(A)) and np.array_equal(p.B, np.array(B))
    assert cfg["system"] == "plant" and run_name(cfg, 3) == "ppo_plant_d0_full_s3"
    base = get_preset("paper-example")  # the rest from the preset
    assert (p.sigma_w2, p.sigma_u2, p.sigma_x2, p.gamma_c, p.upsilon) == (
        base.sigma_w2,
        base.sigma_u2,
        base.sigma_x2,
        base.gamma_c,
        base.upsilon,
    )
    assert p.horizon == cfg["horizon"] == 256
    bomb = tmp_path / "bomb.yaml"  # 484 bytes whose aliases expand to 9^9 numbers
    levels = ["x0: &x0 [1, 1, 1, 1, 1, 1, 1, 1, 1]"] + [f"x{i}: &x{i} [{', '.join([f'*x{i - 1}'] * 9)}]" for i in range(1, 9)]
    bomb.write_text("\n".join(levels + ["A: *x8", "B: [[1]]"]) + "\n")
    with pytest.raises(ResourceLimitError, match="alias"):
        load_config("ppo", system=bomb)
    extra = tmp_path / "extra.json"
    extra.write_text(json.dumps({"A": A, "B": B, "sigma_u2": 2.5, "colour": 1}))
    with pytest.raises(ConfigError, match="colour"):
        load_config("ppo", system=extra)
    extra.write_text(json.dumps({"A": A, "B": B, "sigma_u2": 2.5, "tau_c": "1y"}))
    q = resolve_params(env_config(load_config("ppo", system=extra)))
    assert q.sigma_u2 == 2.5 and q.sources["sigma_u2"] == "config" and q.sigma_w2 == base.sigma_w2  # the file's values are used
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"A": [[2.0]], "B": [[1.0]]}))
    with pytest.raises(ConfigError, match="env:.*"):
        load_config("ppo", system=bad)  # unstable A: the environment's error, as a ConfigError


def test_a_plant_file_and_the_environments_config_are_completed_by_one_rule(tmp_path):
    """train --system and config={"A": A, "B": B} take the same missing values from the same
    preset; with preset None neither completes anything."""
    from encctl_gym.agents.config import plant_config

    A, B = [[0.5, 0.1], [0.0, 0.3]], [[1.0], [0.5]]
    f = tmp_path / "plant.json"
    f.write_text(json.dumps({"A": A, "B": B}))
    cli_side = resolve_params(env_config(load_config("ppo", system=f)))
    with pytest.warns(UserWarning, match="sigma_w2"):
        env_side = resolve_params({"A": A, "B": B, "gamma_opt": False})
    keys = ("sigma_w2", "sigma_u2", "sigma_x2", "gamma_c", "upsilon")
    assert [getattr(cli_side, k) for k in keys] == [getattr(env_side, k) for k in keys]
    with pytest.raises(ConfigError, match="sigma_w2"):
        plant_config(f, None)


# ------------------------------------------------------------------ the schema and --set
@pytest.mark.parametrize(
    "item, needle",
    [
        ("bogus=1", "unknown config key 'bogus'"),
        ("eval.bogus=1", "unknown config key 'eval.bogus'"),
        ("env.bogus=1", "env.bogus"),
        ("hyperparams.bogus=1", "unknown hyperparams key 'bogus' for PPO"),
        ("hyperparams.policy_kwargs.activation_fn=bogus", "activation_fn 'bogus'"),
        ("hyperparams.policy_kwargs.bogus=3", "unknown hyperparams.policy_kwargs key 'bogus'"),
        ("hyperparams.policy_kwargs.net_arch=[64, -1]", "layer sizes must be >= 1"),
        ("hyperparams.n_steps=abc", "does not fit its type int"),
        ("hyperparams.n_steps=0", "must be >= 1"),
        ("hyperparams.gamma=1.5", "must lie in (0, 1]"),
        ("hyperparams.learning_rate=-1", "must be > 0"),
        ("hyperparams.seed=3", "set by encctl-gym train itself"),
        ("hyperparams.rollout_buffer_class=x", "does not fit"),
        ("n_envs=0", "n_envs must be >= 1"),
        ("n_envs=two", "n_envs must be an integer"),
        ("seed=-1", "seed must be >= 0"),
        ("observation=eyes", "observation must be one of"),
        ("normalize.norm_obs=maybe", "true or false"),
        ("horizon=1", "horizon must be >= 2"),
        ("env.decipher_delay=abc", "decipher_delay"),
        ("policy=CnnLstmPolicy", "unknown policy 'CnnLstmPolicy' for PPO"),
        ("hyperparams.gamma.x=1", "is not a mapping"),
        ("no_equals_sign", "is not KEY=VALUE"),
        ("hyperparams..gamma=1", "empty part"),
        ("hyperparams.gamma=[1, 2", "not valid YAML"),
    ],
)
def test_bad_overrides_are_config_errors_and_leave_the_config_untouched(item, needle):
    cfg = load_config("ppo", "paper-example")
    before = json.dumps(cfg, sort_keys=True)
    with pytest.raises(ConfigError) as exc:
        apply_override(cfg, item)
    assert needle in str(exc.value) and "\n" not in str(exc.value)
    assert json.dumps(cfg, sort_keys=True) == before


def test_good_overrides_apply():
    cfg = load_config("ppo", "paper-example")
    apply_override(cfg, "hyperparams.learning_rate=1e-3")
    apply_override(cfg, "hyperparams.policy_kwargs.net_arch={pi: [], vf: [8]}")
    apply_override(cfg, "env.max_samples=512")
    apply_override(cfg, "eval.elgamal.episodes=0")
    assert cfg["hyperparams"]["learning_rate"] == 1e-3
    assert cfg["hyperparams"]["policy_kwargs"]["net_arch"] == {"pi": [], "vf": [8]}
    assert cfg["env"]["max_samples"] == 512 and cfg["eval"]["elgamal"]["episodes"] == 0
    sac = load_config("sac", "small")
    apply_override(sac, "hyperparams.train_freq=[1, episode]")
    assert sac["hyperparams"]["train_freq"] == [1, "episode"]
    assert check_value("train_freq", [1, "episode"], int | tuple[int, str]) == (1, "episode")


def test_unknown_algorithm_everywhere():
    with pytest.raises(ConfigError, match="choose one of ppo, sac, recurrent_ppo"):
        load_config("dqn", "paper-example")
    with pytest.raises(ConfigError):
        algorithm_class("dqn")
    assert algorithm_class("recurrent_ppo") is ALGORITHMS["recurrent_ppo"]


# ------------------------------------------------------------------ hostile files
@pytest.mark.parametrize(
    "text, needle",
    [
        ("!!python/object/apply:os.system ['echo pwned']\n", "cannot read config file"),
        ("- a\n- b\n", "mapping at the top level, got a list"),
        ("a: &x [1, 2]\nb: *x\n", "alias"),
        ("n_envs: [1, 2\n", "cannot read config file"),
        ("n_envs: 'sixteen'\n", "n_envs must be an integer"),
        ("env: [1]\n", "env must be a mapping"),
        ("hyperparams: 3\n", "hyperparams must be a mapping"),
        ("quick: 3\n", "'quick' must be a mapping"),
    ],
)
def test_hostile_or_malformed_yaml_is_one_config_error(tmp_path, text, needle):
    f = tmp_path / "c.yaml"
    f.write_text(text)
    with pytest.raises(ConfigError) as exc:
        load_config("ppo", path=f)
    assert needle in str(exc.value) and "\n" not in str(exc.value)


def test_billion_laughs_is_refused_before_expansion(tmp_path):
    lines = ["a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]" for i in range(1, 9)]
    f = tmp_path / "bomb.yaml"
    f.write_text("\n".join(lines) + "\n")
    with pytest.raises(ConfigError, match="alias"):
        read_yaml(f)
    big = tmp_path / "big.yaml"
    big.write_text("x: " + "1" * (1 << 20) + "\n")
    with pytest.raises(ConfigError, match="more than MAX_CONFIG_BYTES"):
        read_yaml(big)


def test_cli_train_reports_bad_input_in_one_line(capsys, tmp_path):
    out = str(tmp_path / "o")
    _one_line_error(capsys, ["train", "--algo", "ppo", "--preset", "no-such-preset", "--out", out], "no-such-preset")
    _one_line_error(
        capsys,
        ["train", "--algo", "ppo", "--out", out, "--set", "hyperparams.policy_kwargs.activation_fn=bogus"],
        "activation_fn 'bogus'",
    )
    _one_line_error(
        capsys,
        ["train", "--algo", "sac", "--out", out, "--set", "hyperparams.n_epochs=3"],
        "unknown hyperparams key 'n_epochs' for SAC",
    )
    _one_line_error(capsys, ["train", "--algo", "ppo", "--out", out, "--n-envs", "0"], "n_envs must be >= 1")
    f = tmp_path / "hostile.yaml"
    f.write_text("!!python/object/apply:os.system ['echo pwned']\n")
    _one_line_error(capsys, ["train", "--algo", "ppo", "--config", str(f), "--out", out], "cannot read config file")
    _one_line_error(capsys, ["train", "--algo", "ppo", "--system", str(tmp_path / "none.json"), "--out", out], "does not exist")
    assert not Path(out).exists()  # nothing was created for a rejected run


# ------------------------------------------------------------------ run directories
def test_new_run_dir_never_replaces_silently(tmp_path):
    a = new_run_dir(tmp_path, "run")
    assert a == tmp_path / "run"
    (a / "run.json").write_text("{}")
    (a / "best_model.zip").write_text("old")
    b = new_run_dir(tmp_path, "run")
    assert b == tmp_path / "run-2" and (a / "best_model.zip").exists()
    (b / "x").write_text("1")
    assert new_run_dir(tmp_path, "run") == tmp_path / "run-3"
    c = new_run_dir(tmp_path, "run", overwrite=True)
    assert c == a and list(c.iterdir()) == []  # the old run's files are gone, none survives into the new one
    other = tmp_path / "notes"
    other.mkdir()
    (other / "important.txt").write_text("keep")
    with pytest.raises(ConfigError, match="refuses to delete"):
        new_run_dir(tmp_path, "notes", overwrite=True)
    assert (other / "important.txt").exists()
    with pytest.raises(ConfigError, match="plain directory name"):
        new_run_dir(tmp_path, "../escape")


def _run_dir(tmp_path: Path, meta: object) -> Path:
    d = tmp_path / "r"
    d.mkdir(exist_ok=True)
    (d / "run.json").write_text(meta if isinstance(meta, str) else json.dumps(meta))
    return d


@pytest.mark.parametrize(
    "meta, needle",
    [
        ("{not json", "cannot read"),
        ([1, 2], "must hold a JSON object"),
        ({"algo": "ppo", "observation": "full"}, "field 'env'"),
        ({"algo": 3, "observation": "full", "env": {}}, "field 'algo'"),
        ({"algo": "ppo", "observation": "full", "env": {}, "seed": "x"}, "field 'seed'"),
    ],
)
def test_broken_run_json_is_a_config_error(tmp_path, meta, needle):
    d = _run_dir(tmp_path, meta)
    with pytest.raises(ConfigError, match=needle):
        read_run(d)
    (d / "model.zip").write_text("x")
    with pytest.raises(ConfigError):
        find_runs([tmp_path])
    with pytest.raises(ConfigError):
        load_attacker(d)


def test_corrupt_or_missing_model_is_a_config_error(tmp_path, capsys):
    meta = {"algo": "ppo", "observation": "full", "env": {"preset": "small", "gamma_opt": False}, "config": {}}
    d = _run_dir(tmp_path, meta)
    with pytest.raises(ConfigError, match="no model.zip"):
        load_attacker(d)
    (d / "model.zip").write_bytes(b"PK\x03\x04 this is not a zip archive")
    with pytest.raises(ConfigError, match="cannot load"):
        load_attacker(d)
    with zipfile.ZipFile(d / "model.zip", "w") as z:  # a valid zip without a model inside
        z.writestr("data", "{broken")
    with pytest.raises(ConfigError, match="cannot load"):
        load_attacker(d)
    _one_line_error(capsys, ["evaluate", str(d), "--no-progress"], "cannot load")
    _one_line_error(
        capsys,
        ["compare", "--quick", "--systems", "small", "--runs", str(d), "--no-progress", "--out", str(tmp_path / "c")],
        "cannot load",
    )
    meta["algo"] = "dqn"
    d = _run_dir(tmp_path, meta)
    _one_line_error(capsys, ["evaluate", str(d)], "unknown algorithm 'dqn'")


# ------------------------------------------------------------------ hardening
def _depth(v: object) -> int:
    return 1 + max((_depth(x) for x in v), default=0) if isinstance(v, list) else 0


def test_nesting_is_bounded_before_yaml_builds_anything(tmp_path):
    from encctl_gym.agents.config import MAX_CONFIG_DEPTH

    ok = tmp_path / "ok.yaml"  # the top-level mapping is one level, the flow lists the others
    ok.write_text("x: " + "[" * (MAX_CONFIG_DEPTH - 1) + "]" * (MAX_CONFIG_DEPTH - 1) + "\n")
    assert _depth(read_yaml(ok)["x"]) == MAX_CONFIG_DEPTH - 1
    deep = tmp_path / "deep.yaml"
    deep.write_text("x: " + "[" * MAX_CONFIG_DEPTH + "]" * MAX_CONFIG_DEPTH + "\n")
    with pytest.raises(ConfigError, match=f"more than {MAX_CONFIG_DEPTH} levels"):
        read_yaml(deep)
    bomb = tmp_path / "bomb.yaml"  # deeper than Python's recursion limit
    bomb.write_text("x: " + "[" * 100_000 + "]" * 100_000 + "\n")
    with pytest.raises(ConfigError, match="levels deep") as exc:
        read_yaml(bomb)
    assert "\n" not in str(exc.value)
    cfg = load_config("ppo", "small", quick=True)
    with pytest.raises(ConfigError, match="override value"):
        apply_override(cfg, "hyperparams.policy_kwargs.net_arch=" + "[" * 5000 + "]" * 5000)


def test_integers_of_more_than_4300_digits_are_one_config_error(tmp_path):
    f = tmp_path / "digits.yaml"
    f.write_text("n_envs: " + "9" * 5000 + "\n")
    with pytest.raises(ConfigError, match="cannot read config file") as exc:
        read_yaml(f)
    assert len(str(exc.value)) < 500
    with pytest.raises(ConfigError, match="override value"):
        apply_override(load_config("ppo", "small", quick=True), "seed=" + "9" * 5000)


@pytest.mark.parametrize(
    "key, largest",
    [
        ("n_timesteps", 2**53),
        ("eval.freq", 2**53),
        ("horizon", 2**53),
        ("n_envs", 2**53),
        ("eval.final_episodes", 2**53),
        ("seed", 2**32 - 1),
        ("eval.seed", 2**32 - 1),
    ],
)
def test_counts_and_seeds_have_an_upper_bound(key, largest):
    from encctl_gym.agents.config import SCHEMA

    rule = SCHEMA
    for part in key.split("."):
        rule = rule[part]
    assert rule(key, largest) == largest  # the largest value passes the entry's check
    with pytest.raises(ConfigError, match=f"{key} must be <= {largest}, got {largest + 1}"):
        rule(key, largest + 1)
    with pytest.raises(ConfigError, match="integer of 1333 bits"):  # named by its size, never printed in full
        apply_override(load_config("ppo", "small", quick=True), f"{key}={'9' * 401}")


def test_a_seed_numpy_cannot_take_is_refused_in_one_line(capsys, tmp_path):
    np.random.seed(2**32 - 1)  # the largest seed is one NumPy's global generator (seeded by stable-baselines3) takes
    with pytest.raises(ValueError):
        np.random.seed(2**32)
    out = str(tmp_path / "o")
    _one_line_error(
        capsys,
        ["train", "--algo", "ppo", "--preset", "small", "--quick", "--out", out, "--seed", str(2**32)],
        "seed must be <= 4294967295, got 4294967296",
    )
    _one_line_error(
        capsys,
        ["train", "--algo", "ppo", "--preset", "small", "--quick", "--out", out, "--n-timesteps", "9" * 401],
        "n_timesteps must be <= 9007199254740992",
    )
    with pytest.raises(SystemExit) as exc:  # argparse's own error, one line through the CLI's parser
        cli.main(["train", "--algo", "ppo", "--preset", "small", "--quick", "--out", out, "--verbose", "7"])
    err = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and len(err) == 1 and "--verbose: invalid choice: 7" in err[0], err
    assert not Path(out).exists()


def test_the_final_elgamal_evaluation_is_checked_before_training():
    cfg = load_config("ppo", "small", quick=True)
    with pytest.raises(ConfigError, match=r"eval\.elgamal \(max_samples = \d+, key_length = 100000\)"):
        apply_override(cfg, "eval.elgamal.key_length=100000")
    apply_override(cfg, "eval.elgamal.episodes=0")  # no ElGamal episodes: nothing to check
    apply_override(cfg, "eval.elgamal.key_length=100000")
    assert cfg["eval"]["elgamal"]["key_length"] == 100000


def test_integer_hyperparameters_stay_within_int64():
    from encctl_gym.agents.hyperparams import INT64_MAX

    assert INT64_MAX == np.iinfo(np.int64).max
    assert check_value("hyperparams.batch_size", INT64_MAX, int) == INT64_MAX
    with pytest.raises(ConfigError, match="batch_size holds the integer <integer of 1333 bits"):
        check_value("hyperparams.batch_size", int("9" * 401), int)
    with pytest.raises(ConfigError, match="net_arch holds the integer 9223372036854775808"):
        check_value("hyperparams.policy_kwargs.net_arch", [64, INT64_MAX + 1], list[int])


def test_network_bytes_by_hand():
    from encctl_gym.agents.hyperparams import network_bytes

    # [64, 64] from 11 inputs to 2 outputs: (11 + 1) 64 + (64 + 1) 64 + (64 + 1) 2 = 5058 weights, actor and critic
    assert network_bytes([64, 64], 11, 2) == 32 * 2 * 5058
    # pi: (3 + 1) 8 + (8 + 1) 1 = 41; vf: (3 + 1) 4 + (4 + 1) 1 = 21
    assert network_bytes({"pi": [8], "vf": [4]}, 3, 1) == 32 * (41 + 21)
    assert network_bytes(None, 11, 2) == 0


def test_huge_policy_networks_are_refused_before_pytorch_allocates(capsys, tmp_path):
    out = str(tmp_path / "o")
    line = _one_line_error(
        capsys,
        [
            "train",
            "--algo",
            "ppo",
            "--preset",
            "small",
            "--quick",
            "--n-timesteps",
            "64",
            "--no-progress",
            "--no-tensorboard",
            "--no-final-eval",
            "--out",
            out,
            "--set",
            "hyperparams.policy_kwargs.net_arch=[100000000]",
        ],
        "net_arch = [100000000]",
    )
    assert "GiB" in line and "memory_limit" in line


def test_run_json_parse_failures_are_config_errors(tmp_path, monkeypatch):
    import encctl_gym.agents.runs as runs

    d = _run_dir(tmp_path, '{"algo": "ppo", "observation": "full", "env": {}, "seed": ' + "9" * 5000 + "}")
    with pytest.raises(ConfigError, match="cannot read .*run.json.*4300") as exc:
        read_run(d)
    assert len(str(exc.value)) < 500
    _run_dir(tmp_path, '{"algo": "ppo", "env": ' + "[" * 100_000 + "]" * 100_000 + "}")
    with pytest.raises(ConfigError, match="nests too deeply"):
        read_run(d)
    _run_dir(tmp_path, {"algo": "ppo", "observation": "full", "env": {}, "pad": "x" * 200})
    monkeypatch.setattr(runs, "MAX_RUN_FILE_BYTES", 100)
    with pytest.raises(ConfigError, match=r"run.json' has \d+ bytes, more than MAX_RUN_FILE_BYTES = 100"):
        read_run(d)


def test_model_archives_are_checked_without_unpickling(tmp_path):
    from encctl_gym.agents.runs import check_model_file

    p = tmp_path / "model.zip"
    p.write_bytes(b"PK\x03\x04" + b"\x00" * 40 + b"garbage")
    with pytest.raises(ConfigError, match="not a readable model archive"):
        check_model_file(p)
    with zipfile.ZipFile(p, "w") as z:
        z.writestr("notes.txt", "hello")
    with pytest.raises(ConfigError, match="no 'data' member among \\['notes.txt'\\]"):
        check_model_file(p)
    with zipfile.ZipFile(p, "w") as z:
        z.writestr("data", "{}")
    assert check_model_file(p) is None


def test_an_output_path_that_is_a_file_is_refused(tmp_path):
    from encctl_gym.agents.runs import check_output_dir

    f = tmp_path / "afile"
    f.write_text("x")
    with pytest.raises(ConfigError, match="the runs directory .* exists and is not a directory"):
        new_run_dir(f, "run")
    with pytest.raises(ConfigError, match="cannot create the output directory"):
        check_output_dir(f / "sub")
    assert check_output_dir(tmp_path / "a" / "b") == tmp_path / "a" / "b" and (tmp_path / "a" / "b").is_dir()
    assert f.read_text() == "x"


def test_evaluate_refuses_empty_lists_and_a_file_as_out_before_the_work(tmp_path, capsys):
    meta = {"algo": "ppo", "observation": "full", "env": {"preset": "small", "gamma_opt": False, "max_samples": 20}, "config": {}}
    d = _run_dir(tmp_path, meta)
    with zipfile.ZipFile(d / "model.zip", "w") as z:  # passes the archive check; never loaded here
        z.writestr("data", "{}")
    afile = tmp_path / "afile"
    afile.write_text("x")
    base = ["evaluate", str(d), "--no-progress", "--episodes", "1"]
    _one_line_error(capsys, [*base, "--systems", ""], "no systems in ''")
    _one_line_error(capsys, [*base, "--delays", ""], "decipher delay ''")
    _one_line_error(capsys, [*base, "--samples", "9" * 401], "--samples must be <= 9223372036854775807")
    _one_line_error(capsys, [*base, "--out", str(afile)], "exists and is not a directory")
    _one_line_error(capsys, [*base, "--points", "100000000"], "points = 100000000 attack lengths exceed the horizon N = 20")
    assert afile.read_text() == "x"
