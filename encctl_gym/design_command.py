"""``encctl-gym design``: the security design of :mod:`encctl_gym.security.design_cli` with the
defender's levers (:mod:`encctl_gym.security.defense_cli`), whose cost terms come from the loop
layer (:func:`encctl_gym.loop.defense_costs.design_loop_defenses`). Only glue: the security
package imports no cryptography, so the measured time models join it here.
"""

from __future__ import annotations

import argparse

from .loop.defense_costs import design_loop_defenses
from .security import defense_cli, design_cli

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The design command's options and the defender's."""
    design_cli.add_arguments(parser)
    defense_cli.add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    """Run ``encctl-gym design`` (with the defender's section when one of its options is given)."""
    return design_cli.run(args, defenses=design_loop_defenses)
