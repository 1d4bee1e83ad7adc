"""Every probe case, and the failures known on this branch that belong to other layers' owners.

:data:`KNOWN_FAILURES` lists cases that fail in code this branch does not own (the lead's
``encctl_gym/envs/episode.py``; the residue table of the ideal loop, reached from ``train``): the
tests mark them as expected failures, strictly, so a fix there shows up as a test to update.
"""

from __future__ import annotations

from functools import lru_cache

from . import cases_cli, cases_crypto, cases_envs, cases_numeric, cases_security
from .harness import Case

__all__ = ["all_cases", "KNOWN_FAILURES", "MODULES"]

MODULES = (cases_crypto, cases_security, cases_envs, cases_numeric, cases_cli)


@lru_cache(maxsize=1)
def all_cases() -> tuple[Case, ...]:
    """Every case, in a fixed order (crypto, security analysis, environments, breakers and
    estimators, command line); names are unique."""
    out: list[Case] = []
    for module in MODULES:
        out.extend(module.cases())
    names = [c.name for c in out]
    if len(set(names)) != len(names):
        dup = sorted({n for n in names if names.count(n) > 1})
        raise ValueError(f"duplicate probe case names: {dup[:5]}")
    return tuple(out)


_EPISODE = "lead: encctl_gym/envs/episode.py (EpisodeCore.check_actions)"
_TABLE = ("library: encctl_gym/crypto/residue_table.py and encctl_gym/loop/ideal.py (the ideal loop builds a 517 MiB table for "
          "x_bound = 2e4, under its 1 GiB limit; envs/config(x_bound=20000.0) fails the same way)")

#: Case name -> who owns the fix (see the module docstring).
KNOWN_FAILURES: dict[str, str] = {
    "envs/step(action=array(2,):bool=[True,False])": _EPISODE,
    "vector/vector.step(actions=array(2, 2):complex128=[0.+1.j,0.+1.j,0.+1.j,0.+1.j])": _EPISODE,
    "vector/vector.step(actions=array(2, 2):<U1=['a','b','c','d'])": _EPISODE,
    "agents/train --set env.x_bound=2e4": _TABLE,
}
