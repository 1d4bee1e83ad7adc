"""experiments.stealth: its pieces on tiny sizes, its one-line errors, and (slow) a whole small run."""

from __future__ import annotations

import numpy as np
import pytest

from encctl_gym.experiments import stealth as exp


def test_analytic_points_of_every_attack_kind():
    s = exp._system()
    kinds = {a.kind: a for a in (*exp.ANALYTIC_ATTACKS, *exp.FRONTIER_ATTACKS)}  # one of each kind
    assert set(kinds) == {"additive", "stealthy", "sparse", "malleability"}
    for att in kinds.values():
        fp = exp.analytic_point(att, s, 1e-3, 1e-3, horizon=500)
        assert 0.0 <= fp.chi2_lower <= fp.chi2 <= 1.0 and 0.0 <= fp.cusum <= 1.0 and 0.0 <= fp.audit <= 1.0
        assert fp.steps <= 500


def test_play_cells_and_their_tables():
    rows = []
    for att in (exp.FRONTIER_ATTACKS[0], exp.FRONTIER_ATTACKS[4], exp.FRONTIER_ATTACKS[-1]):
        r = exp.play(att, "chi2", 15, 2, 0, 1e-3, 1e-3)
        assert r["episodes"] == 2 and len(r["samples"]) == 2 and max(r["samples"]) <= 15
        r.update(attack=att.label, kind=att.kind, detector="chi2", steps=15, samples_to_gamma_c=100, kl=0.1, analytic=0.5)
        rows.append(r)
    table = exp.format_frontier(rows)
    assert table.count("\n") == len(rows) + 1 and "chi2" in table
    honest = exp.play(exp.Attack("honest", "honest"), "audit", 30, 2, 0, 1.0, 1e-3)
    assert honest["detected"] == 0  # the honest loop passes an audit at every step


@pytest.mark.parametrize("argv", [["--gamma-c", "-1"], ["--audit-rate", "2"], ["--episodes", "1"]])
def test_bad_arguments_exit_2(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        exp.main(argv)
    assert exc.value.code == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


@pytest.mark.slow
def test_a_whole_small_run_writes_its_table_cells_and_figure(tmp_path):
    argv = ["--episodes", "2", "--claim-episodes", "2", "--claim-steps", "30", "--cap", "40", "--out", str(tmp_path)]
    assert exp.main(argv) == 0
    text = (tmp_path / "stealth.md").read_text()
    assert "The documented claim" in text and "The frontier" in text
    assert (tmp_path / "stealth_frontier.png").stat().st_size > 0
    cells = np.genfromtxt(tmp_path / "stealth_cells.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert len(cells) == 6 + 4 * len(exp.FRONTIER_ATTACKS)
