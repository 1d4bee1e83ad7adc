"""The recorded output of ``encctl-gym design`` with the defender's levers.

    python -m encctl_gym.experiments.design_options [--record]

Runs the design command for the option sets of :data:`COMMANDS` and for the rotation periods of
:data:`PERIODS` (the precomputation model's chosen row for each), and writes the defender's
section of each output. The audit time is measured at each run; the other times come from the
package's measured per-size models. Writes ``results/defenses/design_options.md`` by default;
``--record`` writes ``docs/results/defenses/design_options.md``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
from pathlib import Path

from encctl_gym import cli

from .common import ensure_out_dir

__all__ = ["COMMANDS", "PERIODS", "defender_section", "main"]

#: The option sets recorded, after ``encctl-gym design --preset paper-example``.
COMMANDS: tuple[tuple[str, ...], ...] = (
    ("--rotate-every", "auto", "--audit-rate", "auto"),
    ("--rotate-every", "auto", "--audit-rate", "auto", "--confidentiality-floor", "nist"),
    ("--cost-model", "precomputation", "--rotate-every", "auto", "--audit-rate", "auto", "--defense-noise", "0.1"),
    (
        "--cost-model",
        "precomputation",
        "--rotate-every",
        "auto",
        "--audit-rate",
        "5e-4",
        "--defense-noise",
        "0.1",
        "--min-key-length",
        "712",
    ),
    ("--audit-rate", "auto", "--detector", "chi2"),
    ("--audit-rate", "auto", "--detector", "cusum", "--false-alarm", "1e-8", "--detection-delta", "0.5"),
)
#: The rotation periods of the key-length table (the last is the design example's N*).
PERIODS: tuple[int, ...] = (1, 10, 100, 1000, 13159)
BASE: tuple[str, ...] = ("design", "--preset", "paper-example")


def _run(argv: list[str]) -> str:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = cli.main(argv)
    if code != 0:
        raise SystemExit(f"design_options: `encctl-gym {' '.join(argv)}` exited {code}")
    return buf.getvalue()


def defender_section(output: str) -> str:
    """The lines of a design output from its defender's section on."""
    lines = output.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("  Defender's levers"))
    return "\n".join(lines[start:]).rstrip()


def _chosen_row(output: str) -> list[str]:
    """The precomputation model's chosen row: k, step s, rotation s, total s."""
    lines = output.splitlines()
    at = next(i for i, line in enumerate(lines) if line.startswith("  precomputation: k* ="))
    row = next(line for line in lines[at:] if line.strip().startswith("chosen")).split()
    return [row[1], row[5], row[6], row[8]]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m encctl_gym.experiments.design_options", description=__doc__.splitlines()[0])
    parser.add_argument("--record", action="store_true", help="write docs/results/defenses/design_options.md")
    parser.add_argument(
        "--out", type=Path, default=Path("results/defenses"), help="directory of the page (default results/defenses)"
    )
    args = parser.parse_args(argv)
    parts = [
        "# encctl-gym design with the defender's levers",
        "",
        "Recorded by `python -m encctl_gym.experiments.design_options --record` (the audit time is measured at each run; "
        "the other times come from the package's measured per-size models).",
    ]
    for options in COMMANDS:
        command = [*BASE, *options]
        parts += ["", f"## `encctl-gym {' '.join(command)}`", "", "```text", defender_section(_run(command)), "```"]
    parts += [
        "",
        "## The key length against the rotation period (precomputation model)",
        "",
        "`encctl-gym design --preset paper-example --cost-model precomputation --rotate-every K`, the chosen row for each K:",
        "",
        "| K | k | step s | rotation s | total s |",
        "|---|---|---|---|---|",
    ]
    for K in PERIODS:
        row = _chosen_row(_run([*BASE, "--cost-model", "precomputation", "--rotate-every", str(K)]))
        parts.append(f"| {K} | " + " | ".join(row) + " |")
    out = ensure_out_dir(Path("docs/results/defenses") if args.record else args.out) / "design_options.md"
    out.write_text("\n".join(parts) + "\n")
    print(f"  wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
