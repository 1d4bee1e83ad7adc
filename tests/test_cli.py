"""The command-line dispatcher."""

from __future__ import annotations

import subprocess
import sys

import pytest

from encctl_gym.cli import SUBCOMMANDS, main


def test_help_lists_every_subcommand(capsys: pytest.CaptureFixture) -> None:
    assert main([]) == 2
    out = capsys.readouterr().out
    for name in SUBCOMMANDS:
        assert name in out


def test_error_of_the_hierarchy_is_one_line_and_exit_2(capsys: pytest.CaptureFixture) -> None:
    assert main(["design", "--preset", "paper-example", "--gamma-c", "-1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("encctl-gym design: error:") and "gamma_c" in err[0]


def test_design_does_not_import_torch() -> None:
    code = (
        "import sys; from encctl_gym.cli import main; main(['design', '--preset', 'small', '--json']); "
        "assert 'torch' not in sys.modules, 'torch imported'"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr


def test_console_script_version() -> None:
    res = subprocess.run([sys.executable, "-m", "encctl_gym.cli", "--version"], capture_output=True, text=True)
    assert res.returncode == 0 and "encctl-gym" in res.stdout
