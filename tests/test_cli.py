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


def test_a_multi_line_package_error_is_printed_on_one_line(monkeypatch, capsys) -> None:
    """An error whose message spans lines (an array's repr) is still one line on stderr, exit 2."""
    from encctl_gym import cli
    from encctl_gym.errors import ParameterError

    def boom(args):  # type: ignore[no-untyped-def]
        raise ParameterError("A must be real, got array([[0.5+0.j, 0.1+0.j],\n [0. +0.j, 0.3+1.j]])")

    import encctl_gym.design_command as design_command

    monkeypatch.setattr(design_command, "run", boom)  # the parser takes the subcommand's run when it is built
    assert cli.main(["design"]) == 2
    err = capsys.readouterr().err
    assert err == "encctl-gym design: error: A must be real, got array([[0.5+0.j, 0.1+0.j], [0. +0.j, 0.3+1.j]])\n"


def test_a_reader_that_closes_the_pipe_ends_the_command_quietly() -> None:
    # `encctl-gym design ... | head -1`: the reader goes away after one line
    proc = subprocess.Popen(
        [sys.executable, "-m", "encctl_gym.cli", "design", "--preset", "paper-example", "--cost-model", "all"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None
    proc.stdout.readline()
    proc.stdout.close()
    _, err = proc.communicate(timeout=120)
    assert b"Traceback" not in err and b"BrokenPipeError" not in err
    assert proc.returncode in (0, 1)


def test_python_dash_m_encctl_gym_runs_the_command_line() -> None:
    res = subprocess.run([sys.executable, "-m", "encctl_gym", "--version"], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0 and "encctl-gym" in res.stdout, res.stderr


def test_an_underscored_option_is_answered_with_the_dashed_one(capsys: pytest.CaptureFixture) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["design", "--preset", "paper-example", "--gamma_c", "1e-5"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("encctl-gym design: error:") and "--gamma-c" in err[0] and "design --help" in err[0]
