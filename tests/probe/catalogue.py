"""Every probe case, and the failures known on this branch that belong to other layers' owners.

:data:`KNOWN_FAILURES` lists cases that fail in code this branch does not own (the shared
``encctl_gym/_validation.py``; the agents' ``agents/**`` and ``experiments/compare/**``): the
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


_FORMAT = ("shared: encctl_gym/_validation.py (format_value puts the rows of a 2-D array, or a wrapped row of "
           "complex entries, on separate lines, so the refusal's message is not one line; the value is refused)")
_AGENTS = "agents' engineer: agents/** or experiments/compare/**"

#: Case name -> who owns the fix (see the module docstring).
KNOWN_FAILURES: dict[str, str] = {
    "vector/vector.step(actions=array(2, 2):complex128=[0.+1.j,0.+1.j,0.+1.j,0.+1.j])": _FORMAT,
    'envs/config(A=array(2, 2):complex128=[0.5+0.j,0.1+0.j,0.+0.j,0.3+1.j])': _FORMAT,
    'envs/config(A=array(2, 2):float64=[0.5,nan,0.,0.3])': _FORMAT,
    'envs/config(A=array(2, 2):float64=[0.5,inf,0.,0.3])': _FORMAT,
    'envs/config(A=array(2, 2):bool=[True,False,False,True])': _FORMAT,
    'envs/config(B=array(2, 2):complex128=[1.+1.j,0.+0.j,0.+0.j,1.+0.j])': _FORMAT,
    'envs/config(B=array(2, 2):float64=[nan,0.,0.,1.])': _FORMAT,
    "vector/vector.reset(options={'x0': array(2, 2):complex128=[0.+1.j,0.+1.j,0.+1.j,0.+1.j]})": _FORMAT,
    'ident/least_squares(x=array(40, 2):complex128#5864)': _FORMAT,
    'ident/data_matrices(x=array(40, 2):complex128#5864)': _FORMAT,
    'ident/identification_errors(A=array(2, 2):complex128=[0.5+1.j,0.1+1.j,0.+1.j,0.3+1.j])': _FORMAT,
    'ident/ls.fit(x=array(40, 2):complex128#5864)': _FORMAT,
    'ident/bayes.fit(x=array(40, 2):complex128#5864)': _FORMAT,
    'ident/forgetting.fit(x=array(40, 2):complex128#5864)': _FORMAT,
    'ident/iv.fit(x=array(40, 2):complex128#5864)': _FORMAT,
    'ident/estimation_error(A_hat=array(2, 2):complex128=[0.5+1.j,0.1+1.j,0.+1.j,0.3+1.j])': _FORMAT,
    'ident/solve_normal_equations(C=array(3, 2):complex128#0799)': _FORMAT,
    'sim/LinearPlant(A=array(2, 2):complex128=[0.5+0.j,0.1+0.j,0.+0.j,0.3+1.j])': _FORMAT,
    'sim/LinearPlant(A=array(2, 2):float64=[0.5,nan,0.,0.3])': _FORMAT,
    'sim/LinearPlant(A=array(2, 2):float64=[0.5,inf,0.,0.3])': _FORMAT,
    'sim/LinearPlant(A=array(2, 2):bool=[True,False,False,True])': _FORMAT,
    "agents/train --n-timesteps '999999999999'": _AGENTS,
    "agents/train --verbose '7'": _AGENTS,
    "agents/train --verbose '-1'": _AGENTS,
    "agents/train --config deep_nesting_yaml": _AGENTS,
    "agents/train --set hyperparams.batch_size=99999999999999999": _AGENTS,
    "agents/train --out an existing file": _AGENTS,
    "agents/evaluate RUN_DIR=run.json 5000 digits": _AGENTS,
    "agents/evaluate RUN_DIR=run.json deep nesting": _AGENTS,
    "agents/compare --delays ''": _AGENTS,
    "agents/compare --systems ''": _AGENTS,
    "agents/compare --attackers ''": _AGENTS,
    "agents/compare --max-samples '999999999999'": _AGENTS,
    "agents/compare --runs corrupt model.zip": _AGENTS,
    "agents/compare --runs run.json deep nesting": _AGENTS,
    "agents/compare --out an existing file": _AGENTS,
}
