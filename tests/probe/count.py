"""Run every probe case and print the count per class ("the count of cases per class
before and after").

Usage::

    PYTHONPATH=/path/to/checkout python tests/probe/count.py [--json] [--fast] [--area crypto] [--timeout 20]

The cases come from this file's ``tests/probe``; the code probed is whatever ``encctl_gym``
(and ``agents``, ``experiments``) Python imports: set ``PYTHONPATH`` to the checkout to probe
(the script prints which one it imported). A case whose public name, parameter, configuration
key or subcommand option does not exist in that checkout is counted ``n/a``.

The table has one row per class the cases were written to catch (``security``, ``hang``,
``silent``, ``traceback``) and their outcomes in columns: ``ok``, each failure class, ``n/a``.
A case written for one class can fail in another (a bad value meant to be refused that instead
raises a ``TypeError`` is a traceback). ``--json`` prints every case's outcome and detail.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the tests directory: `import probe`

from probe.catalogue import KNOWN_FAILURES, all_cases  # noqa: E402
from probe.harness import CLASSES, OUTCOMES, Result, run_cases  # noqa: E402

__all__ = ["count", "table", "main"]


def _checkout() -> str:
    import encctl_gym

    root = Path(encctl_gym.__file__).resolve().parents[1]
    try:
        rev = subprocess.run(
            ["git", "-C", str(root), "describe", "--always", "--dirty"], capture_output=True, text=True, timeout=10
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        rev = "?"
    return f"{root} (git {rev or '?'})"


def count(results: dict[str, Result], cases: list) -> dict[str, dict[str, int]]:
    """``{class: {"cases": n, outcome: n, ...}}`` for the targeted classes and ``total``."""
    rows: dict[str, dict[str, int]] = {k: {"cases": 0, **{o: 0 for o in OUTCOMES}} for k in (*CLASSES, "total")}
    for c in cases:
        outcome = results[c.name].outcome
        for key in (c.kind, "total"):
            rows[key]["cases"] += 1
            rows[key][outcome] += 1
    for row in rows.values():
        row["failing"] = sum(row[k] for k in CLASSES)
    return rows


def table(rows: dict[str, dict[str, int]]) -> str:
    """The rows of :func:`count` as a text table."""
    cols = ["cases", "n/a", "ok", "failing", *CLASSES]
    head = f"{'class':<10}" + "".join(f"{c:>11}" for c in cols)
    lines = [head, "-" * len(head)]
    for key, row in rows.items():
        lines.append(f"{key:<10}" + "".join(f"{row[c]:>11}" for c in cols))
    lines.append(
        f"(columns {', '.join(CLASSES)}: how the failing cases failed; n/a: the name the case needs is not in this checkout)"
    )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print every case's outcome as JSON")
    parser.add_argument("--fast", action="store_true", help="only the cases of the default test run (not -m slow)")
    parser.add_argument("--area", action="append", help="only this area (repeatable): crypto, security, envs, ...")
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds per case (default 60)")
    parser.add_argument("--failing", action="store_true", help="list the failing cases after the table")
    args = parser.parse_args(argv)
    cases = [c for c in all_cases() if (not args.fast or not c.slow) and (not args.area or c.area in args.area)]
    where = _checkout()
    t0 = time.perf_counter()
    progress = {"n": 0}

    def tick(res: Result) -> None:
        progress["n"] += 1
        if not args.json and sys.stderr.isatty():
            print(f"\r{progress['n']}/{len(cases)} cases", end="", file=sys.stderr, flush=True)

    results: dict[str, Result] = {}
    areas = list(dict.fromkeys(c.area for c in cases))
    for area in areas:  # one child per area (and a fresh one after a case that hangs or dies)
        results.update(run_cases([c for c in cases if c.area == area], timeout=args.timeout, on_result=tick))
    seconds = time.perf_counter() - t0
    rows = count(results, cases)
    if args.json:
        print(
            json.dumps(
                {
                    "checkout": where,
                    "seconds": round(seconds, 1),
                    "timeout": args.timeout,
                    "counts": rows,
                    "cases": [
                        {
                            "name": c.name,
                            "area": c.area,
                            "class": c.kind,
                            "expect": c.expect,
                            "slow": c.slow,
                            "owner": c.owner,
                            "known": KNOWN_FAILURES.get(c.name),
                            "outcome": results[c.name].outcome,
                            "detail": results[c.name].detail[:500],
                            "seconds": round(results[c.name].seconds, 3),
                        }
                        for c in cases
                    ],
                },
                indent=1,
            )
        )
        return 0
    if sys.stderr.isatty():
        print(file=sys.stderr)
    print(f"probe of {where}: {len(cases)} cases in {seconds:.0f} s (timeout {args.timeout:g} s per case, pid {os.getpid()})")
    print(table(rows))
    by_owner: dict[str, int] = {}
    for c in cases:
        if results[c.name].outcome in CLASSES:
            by_owner[c.owner] = by_owner.get(c.owner, 0) + 1
    if by_owner:
        print("failing by owner: " + ", ".join(f"{k} {v}" for k, v in sorted(by_owner.items())))
    if args.failing:
        for c in cases:
            r = results[c.name]
            if r.outcome in CLASSES:
                print(f"[{r.outcome}] {c.name} ({c.owner}): {r.detail[:300]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
