"""The figure layout checks (encctl_gym.plotting) on figures with known defects, and the learning
curve of a run that never came near the optimum."""

from __future__ import annotations

import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from encctl_gym.plotting import FigureLayoutWarning, layout_problems, legend_below, save_figure, thin_tick_labels  # noqa: E402


def _log_axis_within_a_decade():
    fig, ax = plt.subplots(figsize=(1.4, 2.0))
    N = np.arange(20, 46)
    ax.plot(N, 1.0 / N, label="1/N")
    ax.set_xscale("log")  # matplotlib labels the minor ticks 2x10^1, 3x10^1, 4x10^1
    fig.tight_layout()
    return fig, ax


def test_minor_labels_of_a_log_axis_within_a_decade_overlap_and_are_thinned():
    fig, _ = _log_axis_within_a_decade()
    problems = layout_problems(fig)
    assert any("tick labels" in p and "overlap" in p for p in problems)
    thin_tick_labels(fig)
    assert layout_problems(fig) == []
    plt.close(fig)


def test_a_legend_over_the_data_is_found_and_a_legend_below_is_not():
    fig, ax = plt.subplots(figsize=(4, 3))
    x = np.linspace(0, 1, 200)
    ax.plot(x, np.full_like(x, 0.9), label="a line under the legend")
    ax.set_ylim(0, 1)
    ax.legend(loc="upper left")
    assert any("legend covers" in p for p in layout_problems(fig))
    ax.get_legend().remove()
    bottom = legend_below(fig, [ax])
    fig.tight_layout(rect=(0, bottom, 1, 1))
    assert layout_problems(fig) == []
    plt.close(fig)


def test_text_off_the_canvas_and_a_curve_cut_away_are_found():
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([1, 2], [10, 20], label="far above")
    ax.set_ylim(0, 1)
    fig.text(0.9, 0.5, "a long note that runs past the right edge")
    problems = layout_problems(fig)
    assert any("outside the canvas" in p for p in problems)
    assert any("no point of 'far above'" in p for p in problems)
    plt.close(fig)


def test_save_figure_warns_for_what_it_cannot_mend(tmp_path):
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([1, 2], [10, 20], label="far above")
    ax.set_ylim(0, 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(FigureLayoutWarning, match="no point of 'far above'"):
            save_figure(fig, tmp_path / "f.png")
    plt.close(fig)


def test_a_learning_curve_that_stays_above_the_cut_is_still_drawn(tmp_path):
    from encctl_gym.agents.curves import LearningCurve, plot_learning_curves

    E, K = 4, 3
    curve = LearningCurve(
        label="ars small s0",
        algo="ars",
        system="small",
        seed=0,
        N=30,
        gamma=1e-3,
        gamma_gauss=1.2e-3,
        gamma_opt=1e-3,
        design_kind="closed_loop",
        timesteps=np.array([100, 200, 300, 400]),
        epsilon=np.geomspace(1e3, 1e1, E)[:, None] * np.ones((E, K)),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", FigureLayoutWarning)
        path = plot_learning_curves([curve], tmp_path / "curve.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_legend_below_wraps_to_the_figure_width():
    fig, ax = plt.subplots(figsize=(3, 2.5))
    for k in range(6):
        ax.plot([1, 2], [k, k + 1], label=f"a rather long label for curve number {k}")
    bottom = legend_below(fig, [ax], ncol=6)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    assert not [p for p in layout_problems(fig) if "outside the canvas" in p]
    plt.close(fig)
