"""The ``encctl-gym`` command line.

Each subcommand lives in its own module, which provides ``add_arguments(parser)`` and
``run(args) -> int``; this file only dispatches. Errors of the package's hierarchy are printed
as one line (``encctl-gym: error: ...``) with exit code 2, never as a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from typing import Sequence

from . import __version__
from .errors import EncctlError

# name -> (module, one-line help)
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "design": (
        "encctl_gym.security.design_cli",
        "optimal security parameter and key length for a plant (Theorem thm:opt_sec, eq:opt_key)",
    ),
    "reproduce": (
        "experiments.reproduce",
        "reproduce the paper's figures and design example (writes PNG and CSV)",
    ),
    "attack": (
        "encctl_gym.envs.attack_cli",
        "run an attacker through the encrypted-control environment and compare with gamma(N)",
    ),
    "train": (
        "agents.train",
        "train a learned attacker with stable-baselines3 (needs the [rl] extra)",
    ),
    "compare": (
        "experiments.attackers_vs_bounds",
        "the headline experiment: every attacker against gamma(N) and gamma_opt(N)",
    ),
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="encctl-gym",
        description="Adversarial experiments on encrypted control systems "
        "(Teranishi & Kogiso, arXiv 2303.13059).",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module_name, help_text) in SUBCOMMANDS.items():
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            # A subcommand whose optional dependency is missing is still listed, and says why.
            missing = exc.name or module_name

            def _unavailable(args: argparse.Namespace, _missing: str = missing) -> int:
                raise EncctlError(
                    f"this subcommand needs the module {_missing!r}; install the extra that provides it "
                    "(e.g. pip install 'encctl-gym[rl]')"
                )

            p = sub.add_parser(name, help=help_text + " [unavailable]")
            p.set_defaults(_run=_unavailable)
            continue
        p = sub.add_parser(name, help=help_text, description=(module.__doc__ or help_text).strip().splitlines()[0])
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help()
        return 2
    try:
        return int(args._run(args) or 0)
    except EncctlError as exc:
        print(f"encctl-gym {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("encctl-gym: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
