"""``encctl-gym design``: the security design of :mod:`encctl_gym.security.design_cli` with the
defender's levers (:mod:`encctl_gym.security.defense_cli`), whose cost terms come from the loop
layer (:func:`encctl_gym.loop.defense_costs.design_loop_defenses`), and ``--scheme NAME``, whose
scheme object comes from the loop's registry (:func:`encctl_gym.loop.scheme.make_scheme`). Only glue: the security
package imports no cryptography, so the measured time models join it here.
"""

from __future__ import annotations

import argparse

from .loop.defense_costs import design_loop_defenses
from .loop.scheme import SCHEMES, make_scheme
from .security import defense_cli, design_cli

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The design command's options and the defender's."""
    design_cli.add_arguments(parser)
    parser.add_argument(
        "--scheme",
        metavar="NAME",
        help="add the key size of this encryption scheme under each of its cost models for N* "
        f"(a name of the scheme registry: {', '.join(SCHEMES)} when this help was built)",
    )
    defense_cli.add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    """Run ``encctl-gym design`` (with the defender's section when one of its options is given)."""
    scheme = None if args.scheme is None else make_scheme(args.scheme)
    return design_cli.run(args, defenses=design_loop_defenses, scheme=scheme)
