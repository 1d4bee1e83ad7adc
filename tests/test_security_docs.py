"""The label table of docs/paper_labels.md covers every paper label the package cites, and the
cost-model tables of experiments/design_example.py come from the library."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from encctl_gym.experiments import design_example

ROOT = Path(__file__).resolve().parents[1]
LABEL = re.compile(r"\b(?:eq|def|thm|ex|prop|fig):[A-Za-z_0-9]+")


def test_every_cited_label_is_in_the_table() -> None:
    cited: set[str] = set(LABEL.findall((ROOT / "README.md").read_text(encoding="utf-8")))
    for folder in ("encctl_gym", "agents", "experiments", "benchmarks", "docs"):
        for path in (ROOT / folder).rglob("*"):
            if path.suffix in (".py", ".md", ".yaml") and path.name != "paper_labels.md":
                cited |= set(LABEL.findall(path.read_text(encoding="utf-8")))
    table = (ROOT / "docs" / "paper_labels.md").read_text(encoding="utf-8")
    rows = set(re.findall(r"^\| `([a-z]+:[A-Za-z_0-9]+)` \|", table, flags=re.M))
    assert cited, "no labels found"
    assert cited <= rows, sorted(cited - rows)
    assert "--preset figure1" not in (ROOT / "docs" / "security.md").read_text(encoding="utf-8")


def test_design_example_cost_model_tables() -> None:
    rows = design_example.cost_model_designs()
    assert [(d.model, d.gnfs_correction) for d in rows][:3] == [("paper", 0.0), ("precomputation", 0.0), ("generic", 0.0)]
    assert rows[0].k_star == 712 and all(d.paper_k_star == 712 for d in rows)
    assert rows[1].k_star > 712 and rows[4].k_star > rows[1].k_star  # the correction asks for more
    r = math.log2(5300 * 365 / 2)
    dyn = design_example.dynamic_key_bits((13159, 10**8))
    for N, log_n, _k, bits in dyn:
        assert log_n == pytest.approx(math.log2(N))
        assert bits == pytest.approx(math.log2((1 + N * 2**-r) / (1 + 2**-r)), abs=1e-9)
    values = design_example.key_values()
    assert [v.secure for v in values] == [True, False, True]
    text = design_example.format_cost_models(rows, values, dyn)
    assert "precomputation" in text and "13159" in text
