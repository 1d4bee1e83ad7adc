"""Issue 34, first contact: what a new user meets in the first hour.

Item 2: the repository ships example plant files (state and output), the README names them and
``design --help`` lists the plant-file fields.

Item 5: experiments write under ``results/`` by default, under ``docs/`` only when asked to
record (``--record``, or an explicit ``--out``).

Item 1: on a core install (no ``[rl]`` extra) ``train``, ``evaluate`` and ``tune`` answer any
arguments with the one-line error naming the extra, not argparse's "unrecognized arguments".
The missing extra is simulated in a fresh interpreter by an import hook that refuses
stable-baselines3, sb3-contrib, torch and tensorboard.
"""

from __future__ import annotations

import ast
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

BLOCK_RL = textwrap.dedent(
    """
    import contextlib, io, json, sys

    class BlockRL:
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in ("stable_baselines3", "sb3_contrib", "torch", "tensorboard"):
                raise ModuleNotFoundError(f"No module named {name!r}", name=name)
            return None

    sys.meta_path.insert(0, BlockRL())
    from encctl_gym.cli import main

    results = []
    for argv in json.loads(sys.argv[1]):
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as exc:
                code = exc.code
        results.append([code, out.getvalue(), err.getvalue()])
    print(json.dumps(results))
    """
)

COMMANDS = [["train", "--algo", "ppo", "--quick"], ["evaluate", "results/train/some_run"], ["tune", "--algo", "ars"], ["train"]]


@pytest.fixture(scope="module")
def without_rl() -> list[tuple[int, str, str]]:
    """``(exit code, stdout, stderr)`` of each of :data:`COMMANDS` and ``train --help`` in one
    interpreter without the ``[rl]`` extra."""
    argvs = [*COMMANDS, ["train", "--help"]]
    done = subprocess.run([sys.executable, "-c", BLOCK_RL, json.dumps(argvs)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return [tuple(r) for r in json.loads(done.stdout.strip().splitlines()[-1])]


@pytest.mark.parametrize("k", range(len(COMMANDS)), ids=[" ".join(c) for c in COMMANDS])
def test_a_core_install_names_the_rl_extra_whatever_the_arguments(without_rl: list[tuple[int, str, str]], k: int) -> None:
    code, _, err = without_rl[k]
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "pip install 'encctl-gym[rl]'" in lines[0], err
    assert "unrecognized arguments" not in err and f"encctl-gym {COMMANDS[k][0]}: error:" in lines[0]


def test_the_help_of_an_unavailable_subcommand_says_what_is_missing(without_rl: list[tuple[int, str, str]]) -> None:
    code, out, _ = without_rl[-1]
    assert code == 0 and "Not available here" in out and "encctl-gym[rl]" in " ".join(out.split())


def test_with_the_extra_installed_unknown_options_are_still_refused(capsys: pytest.CaptureFixture) -> None:
    pytest.importorskip("stable_baselines3")
    from encctl_gym.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["train", "--algo", "ppo", "--no-such-option"])
    assert exc.value.code == 2 and "unrecognized arguments: --no-such-option" in capsys.readouterr().err


# --------------------------------------------------------------------------- item 2
EXAMPLES = ROOT / "examples"


def test_the_example_plant_files_load_with_every_value_from_the_file() -> None:
    from encctl_gym.plant_file import PLANT_FIELDS, load_plant_file

    state = load_plant_file(EXAMPLES / "plant_state.yaml")
    output = load_plant_file(EXAMPLES / "plant_output.yaml")
    assert set(state.from_file) == set(PLANT_FIELDS) - {"C", "sigma_v2"} and not state.from_defaults
    assert set(output.from_file) == set(PLANT_FIELDS) and not output.from_defaults
    plant = output.preset.plant()
    assert plant.C is not None and plant.C.shape == (1, 3)


def test_design_runs_on_the_state_example(capsys: pytest.CaptureFixture) -> None:
    from encctl_gym.cli import main

    assert main(["design", str(EXAMPLES / "plant_state.yaml"), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["system"]["n"] == 3 and res["system"]["m"] == 1


def test_design_help_lists_the_plant_file_fields_and_the_examples(capsys: pytest.CaptureFixture) -> None:
    from encctl_gym.cli import main
    from encctl_gym.plant_file import PLANT_FIELDS

    with pytest.raises(SystemExit):
        main(["design", "--help"])
    out = capsys.readouterr().out
    fields = out[out.index("plant file fields") :]
    listed = [line.split()[0] for line in fields.splitlines()[2:] if line.startswith("  ")]
    assert listed == list(PLANT_FIELDS)
    assert "examples/plant_state.yaml" in out and "examples/plant_output.yaml" in out


def test_the_readme_names_the_example_plant_files() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    for name in ("plant_state.yaml", "plant_output.yaml"):
        assert f"examples/{name}" in text and (EXAMPLES / name).is_file()


# --------------------------------------------------------------------------- item 5
def _argument_defaults(path: Path) -> list[tuple[int, str]]:
    """``(line, default)`` of every ``add_argument(..., default="..." or Path("..."))`` in a file."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "add_argument":
            for kw in node.keywords:
                value = kw.value
                if isinstance(value, ast.Call) and value.args:  # Path("...")
                    value = value.args[0]
                if kw.arg == "default" and isinstance(value, ast.Constant) and isinstance(value.value, str):
                    found.append((node.lineno, value.value))
    return found


def test_no_experiment_writes_under_docs_by_default() -> None:
    files = sorted((ROOT / "experiments").rglob("*.py")) + sorted((ROOT / "benchmarks").glob("*.py"))
    into_docs = [
        f"{p.relative_to(ROOT)}:{line} default {value!r}"
        for p in files
        for line, value in _argument_defaults(p)
        if value.replace("\\", "/").lstrip("./").startswith("docs")
    ]
    assert not into_docs, into_docs
    assert any(value == "results/defenses" for _, value in _argument_defaults(ROOT / "experiments" / "defenses.py"))


def test_the_game_writes_to_results_unless_recording() -> None:
    pytest.importorskip("pettingzoo")
    import argparse

    from encctl_gym.experiments import game

    parser = argparse.ArgumentParser()
    game.add_arguments(parser)
    plain, recorded = parser.parse_args([]), parser.parse_args(["--record", "--algo", "ars"])
    assert game.out_dir(plain) == "results/game"
    assert game.figure_path(plain) == "results/game/game_learning_curves_ppo.png"
    assert game.out_dir(recorded) == "docs/results/game"
    assert game.figure_path(recorded) == "docs/figures/game_learning_curves_ars.png"
    mine = parser.parse_args(["--record", "--out", "elsewhere"])
    assert (game.out_dir(mine), game.figure_path(mine)) == ("elsewhere", "elsewhere/game_learning_curves_ppo.png")


def test_the_defenses_figure_goes_beside_the_pages_and_every_option_has_help() -> None:
    from encctl_gym.experiments import defenses

    parser = defenses._parser()
    assert parser.parse_args([]).figures is None  # written under --out (results/defenses)
    missing = [a.option_strings for a in parser._actions if a.option_strings and not a.help]
    assert not missing, missing
