"""The hardening probe as tests: every case of ``tests/probe`` runs in a forked child
with a memory cap and a timeout and must end ``ok`` (a package error naming the value, or a
correct result for a valid input).

The cases of one layer run in one child (a fresh child after a case that hangs or dies), so the
default run costs a few seconds per layer; the default run holds one value per parameter and
failure class, ``-m slow`` the rest of the catalogue and the command lines that train or load
models. ``tests/probe/count.py`` prints the same outcomes as a table per class.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from probe.catalogue import KNOWN_FAILURES, all_cases
from probe.harness import CLASSES, OUTCOMES, Case, Result, fork_available, run_cases

pytestmark = pytest.mark.skipif(not fork_available(), reason="needs fork and /proc (Linux)")

CASES = all_cases()
FAST = [c for c in CASES if not c.slow]
SLOW = [c for c in CASES if c.slow]
_RESULTS: dict[tuple[bool, str], dict[str, Result]] = {}


def _result(case: Case) -> Result:
    """The case's result; the first case of a (speed, area) batch runs the whole batch."""
    key = (case.slow, case.area)
    if key not in _RESULTS:
        batch = [c for c in (SLOW if case.slow else FAST) if c.area == case.area]
        _RESULTS[key] = run_cases(batch)
    return _RESULTS[key][case.name]


def _check(case: Case) -> None:
    res = _result(case)
    owner = KNOWN_FAILURES.get(case.name)
    if owner is not None:
        if res.outcome == "ok":
            pytest.fail(f"{case.name} is fixed: remove it from KNOWN_FAILURES ({owner})")
        pytest.xfail(f"[{res.outcome}] reported to {owner}: {res.detail[:200]}")
    assert res.outcome in ("ok", "n/a"), f"[{res.outcome}] {case.name}: {res.detail}"
    assert res.outcome == "ok", f"{case.name} is not applicable in this checkout: {res.detail}"


@pytest.mark.parametrize("case", FAST, ids=[c.name for c in FAST])
def test_probe(case: Case) -> None:
    _check(case)


@pytest.mark.slow
@pytest.mark.parametrize("case", SLOW, ids=[c.name for c in SLOW])
def test_probe_slow(case: Case) -> None:
    _check(case)


def test_catalogue_covers_every_class_and_layer() -> None:
    # about a thousand cases in the issue; every class and every layer it names is probed
    assert len(CASES) >= 1000
    assert {c.kind for c in CASES} == set(CLASSES)
    assert {"crypto", "security", "envs", "vector", "cryptanalysis", "ident", "sim", "cli", "agents"} <= {c.area for c in CASES}
    assert set(KNOWN_FAILURES) <= {c.name for c in CASES}
    # every subcommand of the command line is probed
    from encctl_gym.cli import SUBCOMMANDS

    probed = {c.name.split("/", 1)[1].split()[0] for c in CASES if c.area in ("cli", "agents")}
    assert set(SUBCOMMANDS) <= probed


def test_the_harness_classifies_each_outcome() -> None:
    # one case per outcome: the classifier itself is tested against known answers
    import numpy as np
    from probe.harness import NotApplicable, SecurityFinding

    from encctl_gym.errors import ParameterError

    def raise_(exc: BaseException):  # noqa: ANN202
        def run(_: Path) -> None:
            raise exc

        return run

    def grow(_: Path) -> None:
        blocks = []
        while True:
            blocks.append(np.ones(2**24))

    cases = [
        Case("t/ok", "t", "silent", raise_(ParameterError("x = -1 must be > 0"))),
        Case("t/silent", "t", "silent", lambda _: 42),
        Case("t/traceback", "t", "traceback", raise_(TypeError("boom"))),
        Case("t/multi-line message", "t", "traceback", raise_(ParameterError("a\nb"))),
        Case("t/security", "t", "security", raise_(SecurityFinding("leak"))),
        Case("t/n/a", "t", "silent", raise_(NotApplicable("no such name"))),
        Case("t/memory", "t", "hang", grow),
        Case("t/hang", "t", "hang", lambda _: __import__("time").sleep(60), timeout=2),
        Case("t/after a hang", "t", "silent", lambda _: 1, expect="result", check=lambda v: None),
        Case(
            "t/wrong result",
            "t",
            "silent",
            lambda _: 1,
            expect="result",
            check=lambda v: (_ for _ in ()).throw(AssertionError(v)),
        ),
    ]
    res = run_cases(cases)
    got = {name: r.outcome for name, r in res.items()}
    assert got == {
        "t/ok": "ok",
        "t/silent": "silent",
        "t/traceback": "traceback",
        "t/multi-line message": "traceback",
        "t/security": "security",
        "t/n/a": "n/a",
        "t/memory": "hang",
        "t/hang": "hang",
        "t/after a hang": "ok",
        "t/wrong result": "silent",
    }
    assert set(got.values()) <= set(OUTCOMES)


def test_cli_case_needs_one_line_and_exit_code_2() -> None:
    from probe.build import cli

    cases = [cli("t", "one line", ["design", "--preset", "bogus"]), cli("t", "valid is silent", ["design", "--preset", "small"])]
    res = run_cases(cases)
    assert res["t/one line"].outcome == "ok" and res["t/valid is silent"].outcome == "silent"


def test_a_broken_pipe_is_not_a_traceback() -> None:
    # `encctl-gym design ... | head -1`: the reader goes away; no traceback, no "Exception ignored"
    repo = Path(__file__).resolve().parents[1]
    proc = subprocess.run(
        f"{sys.executable} -m encctl_gym.cli design --preset small | head -1",
        shell=True,
        cwd=repo,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.stdout.startswith("System:") and "Traceback" not in proc.stderr and "Error" not in proc.stderr, proc.stderr
