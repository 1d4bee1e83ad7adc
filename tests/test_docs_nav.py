"""Every page under docs/ is in mkdocs.yml's nav (``mkdocs build --strict`` fails otherwise, in CI
only: this catches it in the default test run, without mkdocs installed)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def nav_pages(text: str) -> set[str]:
    """The ``.md`` paths named in the nav section of ``mkdocs.yml``'s text."""
    nav = text.split("\nnav:", 1)[1]
    nav = re.split(r"\n\S", nav, maxsplit=1)[0]  # up to the next top-level key
    return set(re.findall(r"([\w./-]+\.md)\s*$", nav, flags=re.MULTILINE))


def test_nav_pages_reads_nested_entries():
    text = 'site_name: x\nnav:\n  - Home: index.md\n  - A:\n      - "B: c": results/b.md\ntheme: y\n  - z.md\n'
    assert nav_pages(text) == {"index.md", "results/b.md"}


def test_every_docs_page_is_in_the_nav_and_every_nav_page_exists():
    pages = nav_pages((ROOT / "mkdocs.yml").read_text())
    on_disk = {p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md")}
    assert sorted(on_disk - pages) == [], "pages outside mkdocs.yml's nav"
    assert sorted(pages - on_disk) == [], "nav entries without a page"
