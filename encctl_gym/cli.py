"""The ``encctl-gym`` command line.

Each subcommand lives in its own module, which provides ``add_arguments(parser)`` and
``run(args) -> int``; this file only dispatches. Errors of the package's hierarchy are printed
as one line (``encctl-gym: error: ...``) with exit code 2, never as a traceback.
"""

from __future__ import annotations

import argparse
import difflib
import importlib
import os
import sys
from collections.abc import Sequence
from typing import NoReturn

from . import __version__
from ._validation import one_line
from .errors import EncctlError

# name -> (module, one-line help)
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "design": (
        "encctl_gym.design_command",
        "optimal security parameter and key length for a plant (Theorem thm:opt_sec, eq:opt_key)",
    ),
    "reproduce": ("encctl_gym.experiments.reproduce", "reproduce the paper's figures and design example (writes PNG and CSV)"),
    "train": ("encctl_gym.agents.train", "train a learned attacker with stable-baselines3 (needs the [rl] extra)"),
    "compare": (
        "encctl_gym.experiments.compare.cli",
        "the headline experiment: every attacker against gamma(N) and gamma_opt(N)",
    ),
    "tune": (
        "encctl_gym.agents.tune",
        "hyperparameter search for a learned attacker with Optuna, written as a tuned config (needs the [rl] and [optuna] extras)",
    ),
    "evaluate": (
        "encctl_gym.experiments.compare.evaluate_run",
        "a training run against the Gaussian, AR(1) and oracle attackers on paired seeds (needs the [rl] extra)",
    ),
    "crack": (
        "encctl_gym.cryptanalysis.cli",
        "break N keys of one dynamic-key sequence with a real discrete-logarithm attack and time each key",
    ),
}


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line on stderr with exit code 2 (argparse
    prints the whole usage block first); ``--help`` still prints the usage."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser(selected: str | None = None) -> argparse.ArgumentParser:
    """The argument parser; only the ``selected`` subcommand's module is imported (so that, e.g.,
    ``design`` does not load torch)."""
    parser = OneLineParser(
        prog="encctl-gym",
        description="Adversarial experiments on encrypted control systems (Teranishi & Kogiso, arXiv 2303.13059).",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    for name, (module_name, help_text) in SUBCOMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        if name != selected:
            continue
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            missing = exc.name or module_name
            if missing == module_name or module_name.startswith(missing + "."):
                raise  # the subcommand's own module is missing: a packaging error, not a missing extra

            def _unavailable(args: argparse.Namespace, _missing: str = missing) -> int:
                raise EncctlError(
                    f"this subcommand needs the module {_missing!r}; install the extra that provides it "
                    "(pip install 'encctl-gym[rl]')"
                )

            # its options are unknown without its module: whatever is given, the answer is the extra
            p.set_defaults(_run=_unavailable, _missing_module=missing)
            p.epilog = f"Not available here: the module {missing!r} is not installed (pip install 'encctl-gym[rl]')."
            continue
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``encctl-gym``; returns the exit code."""
    args_list = list(sys.argv[1:] if argv is None else argv)
    selected = next((a for a in args_list if a in SUBCOMMANDS), None)
    parser = build_parser(selected)
    args, unknown = parser.parse_known_args(args_list)
    if unknown and not getattr(args, "_missing_module", None):
        _refuse_unknown(parser, getattr(args, "command", None), unknown)
    if not getattr(args, "_run", None):
        parser.print_help()
        return 2
    try:
        return int(args._run(args) or 0)
    except EncctlError as exc:
        print(f"encctl-gym {args.command}: error: {one_line(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("encctl-gym: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader of stdout went away (``encctl-gym design ... | head``)
        _silence_stdout()
        return 1


def _refuse_unknown(parser: argparse.ArgumentParser, command: str | None, unknown: list[str]) -> NoReturn:
    """Refuse arguments no parser took, from the subcommand they were given to, suggesting its
    nearest option for each (``--gamma_c`` -> ``--gamma-c``): one line, exit code 2."""
    target = parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction) and command in action.choices:
            target = action.choices[command]
    options = [o for action in target._actions for o in action.option_strings if o.startswith("--")]
    hints = []
    for arg in unknown:
        name = arg.split("=", 1)[0]
        if not name.startswith("-"):
            continue
        dashed = "--" + name.lstrip("-").replace("_", "-")
        match = [dashed] if dashed in options else difflib.get_close_matches(dashed, options, n=1)
        if match:
            hints.append(f"did you mean {match[0]} for {name}?")
    hint = ("; " + " ".join(hints)) if hints else ""
    target.error(f"unrecognized arguments: {' '.join(unknown)}{hint}")


def _silence_stdout() -> None:
    """Point stdout at /dev/null: Python would report the broken pipe again when it flushes
    stdout at exit."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # no file descriptor behind stdout
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
