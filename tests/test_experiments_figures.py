"""Tests of the reproduction scripts: the paper's claims on a reduced grid, outputs and CLI."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from encctl_gym import cli
from encctl_gym.experiments import design_example, fig1_variance_ratio, fig2_gramian, reproduce
from encctl_gym.experiments.common import COLUMNS, QUICK, GridConfig, Table, read_csv
from encctl_gym.security.complexity import input_upper_bound

REPO = Path(__file__).resolve().parents[1]
# Reduced grid: 50 runs as in the paper, N up to 2000 (the claims are about the 1/N regime).
REDUCED = GridConfig(N_max=2000, points=15, runs=50)
TINY = GridConfig(N_max=60, points=4, runs=3)


@pytest.fixture(scope="module")
def fig1() -> Table:
    return fig1_variance_ratio.compute(REDUCED, seed=0, n_jobs=1)


@pytest.fixture(scope="module")
def fig2() -> Table:
    return fig2_gramian.compute(REDUCED, seed=0, n_jobs=1)


def test_fig1_table_is_tidy(fig1: Table) -> None:
    assert fig1.panels() == list("abcdefghi")
    grid = REDUCED.grid(4, 4)
    assert len(fig1) == 9 * grid.size * REDUCED.runs
    s = fig1.summary("b")  # row sigma_w2 = 0.1, column sigma_u2 = 1
    assert (s["sigma_w2"], s["sigma_u2"], s["r_sigma"]) == (0.1, 1.0, 10.0)
    s = fig1.summary("g")
    assert (s["sigma_w2"], s["sigma_u2"]) == (10.0, 0.1)
    assert np.allclose(s["psi_u"], 2.0, rtol=1e-3)  # Psi_u ~= 2I for A = 0.7071 I, B = I
    assert np.all(np.isnan(fig1.columns["bound"]))
    assert np.all(fig1.columns["error"] > 0)


def test_fig1_gamma_lies_below_the_mean_error_in_every_panel(fig1: Table) -> None:
    # Theorem thm:sic / eq:sic2: gamma(N) is a lower bound of E[epsilon(N)].
    for panel in fig1.panels():
        s = fig1.summary(panel)
        big = s["N"] >= 50
        assert np.all(s["gamma"][big] < s["mean"][big]), panel


def test_fig1_errors_shrink_as_the_variance_ratio_grows(fig1: Table) -> None:
    # "The estimation errors and their expectations ... are smaller as the variance ratio increases."
    def level(p: str) -> float:
        s = fig1.summary(p)
        return float(np.mean(s["mean"][s["N"] >= 50] * (s["N"][s["N"] >= 50] - 1)))

    for row in ("abc", "def", "ghi"):  # fixed sigma_w2, sigma_u2 = 0.1, 1, 10
        a, b, c = (level(p) for p in row)
        assert a > b > c, row
    for col in ("adg", "beh", "cfi"):  # fixed sigma_u2, sigma_w2 = 0.1, 1, 10: R decreases
        a, b, c = (level(p) for p in col)
        assert a < b < c, col


def test_fig1_gamma_less_conservative_for_larger_variance_ratio(fig1: Table) -> None:
    # "the sample identifying complexity with the larger variance ratio is less conservative"
    def gap(p: str) -> float:
        s = fig1.summary(p)
        big = s["N"] >= 50
        return float(np.mean(s["mean"][big] / s["gamma"][big]))

    # In expectation mean/gamma is ~1.5, ~1.16, ~1.13 along the first row (Jensen's gap of
    # tr E[(D D^T)^-1]): (b) and (c) differ by less than the noise of a 50-run mean, so only
    # (a) against both is checked there; the last row spans ~50, ~6, ~1.5.
    assert gap("a") > max(gap("b"), gap("c"))
    assert gap("g") > gap("h") > gap("i")


def test_fig2_gamma_approaches_the_bound_as_psi_u_decreases(fig2: Table) -> None:
    ratios = []
    for panel, psi in zip(fig2_gramian.PANELS, fig2_gramian.PSI_U):
        s = fig2.summary(panel)
        assert s["psi_u"] == pytest.approx(psi, rel=1e-9)
        assert s["r_sigma"] == pytest.approx(100.0)
        np.testing.assert_allclose(s["bound"], input_upper_bound(s["N"], 4, 4, 100.0))
        r = s["bound"] / s["gamma"]
        np.testing.assert_allclose(r, r[0], rtol=1e-12)  # the ratio does not depend on N
        ratios.append(r[0])
    ratios = np.array(ratios)
    assert np.all(ratios > 1.0)
    assert np.all(np.diff(ratios) < 0)  # monotone towards 1 as tr(Psi_u) decreases
    assert ratios[-1] < 1.15 and ratios[0] > 2.0


def test_fig2_mean_error_grows_as_psi_u_decreases_and_stays_above_gamma(fig2: Table) -> None:
    levels = []
    for panel in fig2_gramian.PANELS:
        s = fig2.summary(panel)
        big = s["N"] >= 50
        levels.append(np.mean(s["mean"][big] * (s["N"][big] - 1)))
        # gamma is a lower bound of E[epsilon]; for Psi_u = I (panel b) it is nearly tight
        # (E[D D^T] is almost a multiple of I, so Jensen's gap vanishes) and a 50-run mean may dip a
        # few percent below it: allow 10% of Monte Carlo noise (std of a 50-run mean ~ 4%).
        assert np.all(s["mean"][big] > 0.9 * s["gamma"][big]), panel
    assert np.all(np.diff(levels) > 0), levels


def test_compute_is_reproducible_and_independent_of_workers() -> None:
    a = fig2_gramian.compute(TINY, seed=5, n_jobs=1)
    b = fig2_gramian.compute(TINY, seed=5, n_jobs=2)
    np.testing.assert_array_equal(a.columns["error"], b.columns["error"])
    c = fig2_gramian.compute(TINY, seed=6, n_jobs=1)
    assert not np.array_equal(a.columns["error"], c.columns["error"])
    # Figures use different streams for the same master seed.
    d = fig1_variance_ratio.compute(TINY, seed=5, n_jobs=1)
    assert not np.array_equal(a.panel("a").columns["error"], d.panel("c").columns["error"])


def test_csv_round_trip(tmp_path: Path) -> None:
    t = fig2_gramian.compute(TINY, seed=1, n_jobs=1)
    path = t.to_csv(tmp_path / "t.csv")
    assert path.read_text().splitlines()[0] == ",".join(COLUMNS)
    back = read_csv(path)
    for c in ("N", "run"):
        np.testing.assert_array_equal(back.columns[c], t.columns[c])
    for c in ("error", "gamma", "bound", "psi_u"):
        np.testing.assert_array_equal(back.columns[c], t.columns[c])  # repr() keeps every bit
    assert back.panels() == t.panels()


def test_design_example_matches_the_paper() -> None:
    rows = design_example.compute()
    for label, d in rows:
        assert (d.N_star, d.lam_star, d.k_star) == (13159, 74, 712), label
    text = design_example.format_table(rows)
    assert "13159" in text and "712" in text


def test_reproduce_quick_through_the_cli(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc = cli.main(["reproduce", "--quick", "--n-jobs", "1", "--no-progress", "--out", str(tmp_path), "--seed", "3"])
    assert rc == 0
    out = capsys.readouterr().out
    for name in (
        "fig1_variance_ratio.png",
        "fig1_variance_ratio.csv",
        "fig2_gramian.png",
        "fig2_gramian.csv",
        "design_example.csv",
    ):
        assert (tmp_path / name).stat().st_size > 0
        assert name in out
    assert (tmp_path / "fig1_variance_ratio.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    t = read_csv(tmp_path / "fig1_variance_ratio.csv")
    assert len(t) == 9 * QUICK.runs * QUICK.grid(4, 4).size
    assert t.columns["N"].max() == QUICK.N_max


@pytest.mark.parametrize(
    ("option", "value", "text"),
    [
        ("--n-jobs", "0", "n_jobs must be -1 (all cores) or >= 1, got 0"),
        ("--n-jobs", "-5", "n_jobs must be -1 (all cores) or >= 1, got -5"),
        ("--n-jobs", "abc", "--n-jobs must be -1 (all cores) or a count >= 1, got 'abc'"),
        ("--seed", "-1", "--seed must be >= 0, got -1"),
        ("--seed", "2.5", "--seed must be a non-negative integer, got '2.5'"),
        ("--scheduler", "bogus", "scheduler must be 'local' or a Dask scheduler address like 'tcp://host:8786', got 'bogus'"),
    ],
)
def test_cli_bad_option_is_a_one_line_error_before_any_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str, value: str, text: str
) -> None:
    """--seed, --n-jobs and --scheduler are checked as they are parsed (the design step, which
    uses none of them, would otherwise run and exit 0)."""
    with pytest.raises(SystemExit) as exc:
        cli.main(["reproduce", "--quick", "--only", "design", option, value, "--out", str(tmp_path)])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("encctl-gym reproduce: error:") and text in err and "\n" not in err
    assert not any(tmp_path.iterdir())  # nothing was written


def test_reproduce_module_and_script_entry_points(tmp_path: Path) -> None:
    # `python -m encctl_gym.experiments.reproduce` and `python experiments/<script>.py` both work.
    r = subprocess.run(
        [sys.executable, "-m", "encctl_gym.experiments.reproduce", "--only", "design", "--out", str(tmp_path)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert "13159" in r.stdout
    r = subprocess.run(
        [sys.executable, str(REPO / "experiments" / "design_example.py"), "--out", str(tmp_path / "x")],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "x" / "design_example.csv").exists()
    assert reproduce.main(["--only", "design", "--out", str(tmp_path / "y")]) == 0
