"""Every probe case, and the failures known on this branch that belong to other layers' owners.

:data:`KNOWN_FAILURES` lists cases that fail in code outside the probe's reach of fixes (a
layer whose owner has been told): the tests mark them as expected failures, strictly, so a fix
there shows up as a test to update. It is empty when every case passes.
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


#: Case name -> who owns the fix (see the module docstring).
KNOWN_FAILURES: dict[str, str] = {}
