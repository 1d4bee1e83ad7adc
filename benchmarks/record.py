"""Recorded benchmark results, and the benchmark table of the docs made from them.

Each benchmark script, run with ``--record``, writes ``benchmarks/results/<name>.json``: the
figures it measured in that run, the rows it contributes to the benchmark table of docs/benchmarks.md (its
own wording of what was measured), the command, the date and the machine. ``python
benchmarks/record.py`` rewrites the table in docs/benchmarks.md (between the markers
``<!-- bench:table -->`` and ``<!-- /bench:table -->``) from the recorded files, so the docs
never show a number that no recorded run printed.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import platform
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
README = ROOT / "docs" / "benchmarks.md"  # the page that carries the table
BEGIN, END = "<!-- bench:table -->", "<!-- /bench:table -->"
#: The order of the benchmarks in the table.
ORDER = ("bench_crypto", "bench_montecarlo", "bench_env", "bench_cryptanalysis")


def machine() -> str:
    """A one-line description of this machine."""
    return f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}"


def write(name: str, figures: dict[str, Any], rows: Sequence[tuple[str, str]], argv: Sequence[str] | None = None) -> Path:
    """Record one run of benchmark ``name``: its figures and its README rows (measurement, result)."""
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / f"{name}.json"
    doc = {
        "benchmark": name,
        "command": "python benchmarks/" + name + ".py " + " ".join(sys.argv[1:] if argv is None else argv),
        "date": _dt.datetime.now().strftime("%Y-%m-%d"),
        "machine": machine(),
        "figures": figures,
        "rows": [list(r) for r in rows],
    }
    path.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    return path


def table(results: Path = RESULTS) -> str:
    """The markdown table of every recorded benchmark, in :data:`ORDER`."""
    docs = {p.stem: json.loads(p.read_text(encoding="utf-8")) for p in sorted(results.glob("*.json"))}
    names = [n for n in ORDER if n in docs] + sorted(set(docs) - set(ORDER))
    lines = ["| measurement | result | recorded by |", "|---|---|---|"]
    for name in names:
        doc = docs[name]
        for measurement, result in doc["rows"]:
            lines.append(f"| {measurement} | {result} | `{doc['command'].strip()}`, {doc['date']} |")
    return "\n".join(lines)


def update_readme(readme: Path = README, results: Path = RESULTS) -> bool:
    """Replace the table between the markers in ``readme``; return True if it changed."""
    text = readme.read_text(encoding="utf-8")
    if BEGIN not in text or END not in text:
        raise SystemExit(f"{readme} has no {BEGIN} ... {END} block")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    new = f"{head}{BEGIN}\n{table(results)}\n{END}{tail}"
    if new != text:
        readme.write_text(new, encoding="utf-8")
    return new != text


if __name__ == "__main__":
    changed = update_readme()
    print(f"{README.relative_to(ROOT)} benchmark table " + ("updated" if changed else "already up to date"))
