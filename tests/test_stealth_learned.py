"""experiments.stealth_learned: its frontier and configs on their own, and (slow) a quick run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from encctl_gym.experiments import stealth_learned as sl


@pytest.mark.parametrize("detector", ["none", "chi2", "cusum", "audit"])
def test_the_frontier_trades_error_for_detection(detector):
    curve = sl.frontier_curve(detector, 256, levels=12)
    levels, eps, det = (np.array(v) for v in zip(*curve))
    assert np.all(np.diff(levels) > 0) and np.all(np.diff(eps) < 0)  # more excitation, smaller error
    if detector == "none":
        assert np.all(det == 0)
    elif detector == "audit":
        assert np.all(det == pytest.approx(1 - 0.95**256))  # any falsified step is seen at rate 0.05
    else:
        assert np.all(np.diff(det) >= -1e-9) and det[0] < 0.05 < 0.99 < det[-1]  # quiet levels near the false alarms
    # the frontier at a detection: the smallest error among the levels detected at most that often
    d = float(det[len(det) // 2])
    assert sl._frontier_at(curve, d) == min(e for _, e, p in curve if p <= d + 1e-12)
    assert sl._frontier_at(curve, -1.0) == math.inf


def test_each_cell_trains_an_additive_attacker_against_its_detector():
    pytest.importorskip("stable_baselines3")
    cfg = sl._config("ars", "cusum", 1234, 7)
    assert cfg["env"]["injection"] == "add" and cfg["env"]["defender"] == sl.DETECTORS["cusum"]
    assert (cfg["n_timesteps"], cfg["seed"], cfg["stopping"]["rule"], cfg["eval"]["elgamal"]["episodes"]) == (1234, 7, "none", 0)


@pytest.mark.slow
def test_a_quick_run_writes_every_cell(tmp_path):
    pytest.importorskip("stable_baselines3")
    assert sl.main(["--quick", "--out", str(tmp_path)]) == 0
    page = (tmp_path / "stealth_learned.md").read_text()
    rows = [line for line in page.splitlines() if line.startswith("| ") and not line.startswith("| detector")]
    assert len(rows) == 2 * len(sl.DETECTORS)
