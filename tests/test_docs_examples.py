"""Every fenced ```python block of README.md and docs/*.md runs as written, alone.

Readers copy one block, so each block runs in a fresh namespace: a name it uses must be defined
or imported in the block itself (a block that continues an earlier one fails with NameError).
The blocks of one file run in order in one process (imported modules stay loaded), each file as
its own test. A block preceded by the line ``<!-- docs:slow -->`` runs only under ``-m slow`` (the
file's test is then split: the other blocks by default, every block with ``-m slow``). Listings
that are not meant to run use another fence language (``text``, ``bash``).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from encctl_gym.errors import OptionalDependencyError

ROOT = Path(__file__).resolve().parents[1]
SLOW_MARK = "<!-- docs:slow -->"
FENCE = re.compile(r"^(`{3,})([^`\s]*)\s*$")


def python_blocks(text: str) -> list[tuple[int, str, bool]]:
    """The ```python blocks of a Markdown text as (first line number, code, slow).

    ``slow`` is true when the last non-blank line before the opening fence is ``<!-- docs:slow -->``.
    An unclosed fence raises ``ValueError`` (a broken page must not pass by running nothing).
    """
    lines = text.splitlines()
    blocks: list[tuple[int, str, bool]] = []
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        fence, lang = m.group(1), m.group(2).lower()
        start = i
        j = i + 1
        while j < len(lines) and not (lines[j].startswith(fence) and lines[j].strip() == fence):
            j += 1
        if j == len(lines):
            raise ValueError(f"unclosed code fence at line {start + 1}")
        if lang == "python":
            k = start - 1
            while k >= 0 and not lines[k].strip():
                k -= 1
            slow = k >= 0 and lines[k].strip() == SLOW_MARK
            blocks.append((start + 2, "\n".join(lines[start + 1 : j]) + "\n", slow))
        i = j + 1
    return blocks


DOC_FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
CASES = [p for p in DOC_FILES if python_blocks(p.read_text(encoding="utf-8"))]


#: Top-level modules of the optional extras: a page whose example needs one is skipped on an
#: install without that extra (any other missing module is a failure).
EXTRA_MODULES = {
    "stable_baselines3": "rl",
    "sb3_contrib": "rl",
    "torch": "rl",
    "cypari": "cryptanalysis",
    "optuna": "optuna",
    "ray": "ray",
    "distributed": "dask",
    "dask": "dask",
    "pettingzoo": "multiagent",
}


def _run_blocks(path: Path, include_slow: bool, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> int:
    monkeypatch.chdir(tmp_path)  # blocks that write results write them here
    ran = 0
    for line, code, slow in python_blocks(path.read_text(encoding="utf-8")):
        if slow and not include_slow:
            continue
        rel = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
        namespace: dict[str, object] = {"__name__": f"docs_{path.stem}_{line}"}  # each block alone
        try:
            exec(compile(code, f"{rel}:{line}", "exec"), namespace)  # noqa: S102 - the documented examples
        except ModuleNotFoundError as exc:
            top = (exc.name or "").partition(".")[0]
            if top not in EXTRA_MODULES:
                raise
            pytest.skip(f"{rel}:{line} needs the {EXTRA_MODULES[top]} extra ({top} is not installed)")
        except OptionalDependencyError as exc:  # the package's own one-line error naming the extra
            pytest.skip(f"{rel}:{line}: {exc}")
        ran += 1
    return ran


@pytest.mark.parametrize("path", CASES, ids=lambda p: str(p.relative_to(ROOT)))
def test_python_blocks_run_alone(path: Path, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    blocks = python_blocks(path.read_text(encoding="utf-8"))
    if all(slow for _, _, slow in blocks):
        pytest.skip("every block is marked slow")
    assert _run_blocks(path, False, monkeypatch, tmp_path) == sum(not slow for _, _, slow in blocks)


SLOW_CASES = [p for p in CASES if any(slow for _, _, slow in python_blocks(p.read_text(encoding="utf-8")))]


@pytest.mark.slow
@pytest.mark.parametrize("path", SLOW_CASES, ids=lambda p: str(p.relative_to(ROOT)))
def test_python_blocks_run_alone_with_the_slow_ones(path: Path, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    assert _run_blocks(path, True, monkeypatch, tmp_path) == len(python_blocks(path.read_text(encoding="utf-8")))


def test_block_parser_finds_languages_marks_and_unclosed_fences() -> None:
    text = "a\n```python\nx = 1\n```\n\n<!-- docs:slow -->\n\n```python\ny = x\n```\n```text\nz\n```\n````\n```python\n````\n"
    assert python_blocks(text) == [(3, "x = 1\n", False), (9, "y = x\n", True)]
    with pytest.raises(ValueError, match="line 2"):
        python_blocks("a\n```python\nx = 1\n")


def test_a_block_that_continues_an_earlier_one_fails(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("```python\nx = 1\n```\n\n```python\nprint(x)\n```\n", encoding="utf-8")
    with pytest.raises(NameError, match="'x'"):
        _run_blocks(page, False, monkeypatch, tmp_path)
    page.write_text("```python\nx = 1\n```\n\n```python\nx = 2\nprint(x)\n```\n", encoding="utf-8")
    assert _run_blocks(page, False, monkeypatch, tmp_path) == 2


def test_readme_links_point_to_files_of_the_repository() -> None:
    """The README is outside the site (mkdocs checks the links of docs/ only): its relative links
    and images must name files that exist."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    targets = re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text)
    relative = [t for t in targets if "://" not in t]
    assert relative, "the README links no page of docs/"
    missing = [t for t in relative if not (ROOT / t).is_file()]
    assert not missing, missing
