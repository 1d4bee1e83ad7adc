"""What the commands say and draw (issue 34 item 8): counts with their nouns, ``compare --quick``
saying that it leaves ``results/train`` out, the evaluate bar's own label, plain labels on short
log axes, ``tau(N) / T_first`` from the same sequence, and the learning curve's "cut" note."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from encctl_gym._validation import format_count  # noqa: E402
from encctl_gym.plotting import plain_log_ticks  # noqa: E402


def test_a_count_has_its_noun_in_the_right_number():
    assert format_count(1, "episode") == "1 episode"
    assert [format_count(k, "episode") for k in (0, 2, 500)] == ["0 episodes", "2 episodes", "500 episodes"]


def test_compare_quick_says_it_leaves_the_trained_runs_out(tmp_path, monkeypatch):
    pytest.importorskip("stable_baselines3")
    from encctl_gym.experiments.compare.cli import run_roots

    monkeypatch.chdir(tmp_path)
    assert run_roots([], quick=True) == ([], "")  # no results/train: nothing to say
    (tmp_path / "results" / "train").mkdir(parents=True)
    roots, note = run_roots([], quick=True)
    assert roots == [] and "--quick leaves out the trained runs in results/train" in note and "--runs" in note
    assert run_roots([], quick=False) == (["results/train"], "")
    assert run_roots(["mine"], quick=True) == (["mine"], "")


def test_the_comparison_bar_carries_the_commands_label(capsys):
    pytest.importorskip("stable_baselines3")
    from encctl_gym.experiments.compare.protocol import compute

    compute(["small"], delays=[0], episodes=2, cap=12, points=1, elgamal_episodes=0, attackers=["gaussian"],
            progress=True, label="evaluate")  # fmt: skip
    err = capsys.readouterr().err
    assert "evaluate:" in err and "compare:" not in err


def _labels(ax, axis):
    fig = ax.figure
    fig.canvas.draw()
    plain_log_ticks(fig)
    fig.canvas.draw()
    ticks = ax.get_xticklabels() if axis == "x" else ax.get_yticklabels()
    lo, hi = sorted(ax.get_xlim() if axis == "x" else ax.get_ylim())
    return [t.get_text() for t, v in zip(ticks, ax.get_xticks() if axis == "x" else ax.get_yticks()) if lo <= v <= hi]


def test_a_short_log_axis_gets_plain_labels_and_a_long_one_keeps_its_powers():
    fig, (short, long_) = plt.subplots(1, 2)
    short.loglog([5, 40], [0.9, 7.0])
    long_.loglog([1e-4, 1e3], [1.0, 2.0])
    assert _labels(short, "x") == ["5", "10", "20"] and _labels(short, "y") == ["1", "2", "5"]
    assert all("10^" in t or "10^{" in t or "mathdefault" in t for t in _labels(long_, "x") if t)
    plt.close(fig)


def test_tau_over_t_first_starts_at_1_on_the_sequences_own_first_key():
    from encctl_gym.experiments.deciphering_models import sequence_ratio

    rows = [{"breaker": "rho", "bits": 32, "kind": "sequence", "N": k, "tau": 0.5 * k + 1.5} for k in (4, 1, 2)]
    rows += [{"breaker": "rho", "bits": 32, "kind": "fresh", "N": 1, "tau": 0.3}]  # another group's first key
    n, ratio = sequence_ratio(rows, "rho", 32)
    assert n.tolist() == [1, 2, 4] and ratio == pytest.approx([1.0, 1.25, 1.75])
    assert sequence_ratio(rows, "rho", 24)[0].size == 0


def test_the_learning_curves_cut_note_names_a_ratio_not_a_step():
    from encctl_gym.agents.curves import _set_ratio_limits

    class Curve:
        gamma_gauss, gamma, gamma_opt = 1.3, 1.2, 1.0

        def ratio(self):
            return np.array([[55.0, 3.0, 1.1]]), None

    fig, ax = plt.subplots()
    _set_ratio_limits(ax, [Curve()])
    (text,) = [t.get_text() for t in ax.texts]
    assert text.startswith("y axis cut at a ratio of 2 to the optimum") and "55" in text
    plt.close(fig)
