"""encctl_gym.agents.resolution: ratios with intervals and the episodes a margin needs, on synthetic samples
whose answers are known by construction."""

from __future__ import annotations

import math

import numpy as np
import pytest

from encctl_gym.agents.resolution import median_resolution, paired_resolution, reference_resolution, resolution_line
from encctl_gym.errors import ParameterError

#: t_{0.975} with 99 and 399 degrees of freedom (statistical tables).
T99 = 1.984217
T399 = 1.965927


def standardized(E: int, seed: int = 0) -> np.ndarray:
    """E numbers of mean exactly 0 and sample standard deviation exactly 1."""
    z = np.random.default_rng(seed).standard_normal(E)
    z -= z.mean()
    return z / z.std(ddof=1)


def paired_sample(E: int, mu: float, s: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Errors y (oracle) and x = y exp(mu + s z): the log ratios have mean mu and sd s exactly."""
    y = np.exp(np.random.default_rng(seed + 1).normal(-10.0, 1.0, E))
    return y * np.exp(mu + s * standardized(E, seed)), y


def test_paired_ratio_and_half_width_are_the_t_interval_of_the_log_ratios():
    s = 0.13 * math.sqrt(100) / T99  # a 13 % half-width (log scale) at 100 episodes
    x, y = paired_sample(100, math.log(1.04), s)
    r = paired_resolution(x, y)
    assert r.estimate == pytest.approx(1.04, rel=1e-12)
    assert math.log(r.high / r.estimate) == pytest.approx(0.13, rel=1e-5)
    assert math.log(r.estimate / r.low) == pytest.approx(0.13, rel=1e-5)
    assert r.half_width == pytest.approx(math.expm1(0.13), rel=1e-5)
    assert r.margin == pytest.approx(0.04)
    assert not r.resolved
    # the episodes that resolve a 4 % margin with this spread: 100 (0.13 / 0.04)^2 ~ 1356 (on the ratio scale)
    need = r.episodes_needed
    assert need == math.ceil(100 * (math.expm1(0.13) / 0.04) ** 2)


def test_the_episodes_needed_do_resolve_the_margin_and_fewer_do_not():
    s = 0.13 * math.sqrt(100) / T99
    x, y = paired_sample(100, math.log(1.04), s)
    need = int(paired_resolution(x, y).episodes_needed)
    more = paired_resolution(*paired_sample(int(1.1 * need), math.log(1.04), s, seed=3))
    fewer = paired_resolution(*paired_sample(int(0.6 * need), math.log(1.04), s, seed=3))
    assert more.resolved and more.low > 1.0
    assert not fewer.resolved


def test_episodes_for_a_target_scale_as_one_over_the_square():
    s = 0.05 * math.sqrt(400) / T399
    r = paired_resolution(*paired_sample(400, math.log(1.1), s))
    assert r.resolved
    h = r.half_width
    assert r.episodes_for(h) == 400
    assert r.episodes_for(h / 2) == 1600
    assert r.episodes_for(0.0) == math.inf


def test_median_of_a_constant_ratio_has_a_zero_width_interval():
    y = np.linspace(1.0, 2.0, 31)
    r = median_resolution(1.25 * y, y)
    assert (r.estimate, r.low, r.high) == pytest.approx((1.25, 1.25, 1.25))
    assert r.half_width == pytest.approx(0.0, abs=1e-12)


def test_median_bootstrap_interval_covers_the_true_median_about_95_percent():
    rng = np.random.default_rng(7)
    hits = 0
    reps = 150
    for i in range(reps):
        y = rng.lognormal(0.0, 1.0, 61)
        x = y * rng.lognormal(math.log(1.2), 0.3, 61)  # the ratio's median is 1.2
        r = median_resolution(x, y, bootstrap=400, seed=i)
        hits += r.low <= 1.2 <= r.high
    assert 0.87 * reps <= hits <= reps  # binomial(150, 0.95): 0.87 is 4 standard deviations below


def test_reference_ratio_uses_the_mean_where_it_exists_and_the_median_where_it_does_not():
    x = 2.0 + 0.1 * standardized(100)  # mean 2, sd 0.1
    r = reference_resolution(x, 1.6)
    assert r.statistic == "mean (t)"
    assert r.estimate == pytest.approx(1.25)
    assert (r.high - r.estimate) * 1.6 == pytest.approx(T99 * 0.1 / 10, rel=1e-5)
    pareto = (1.0 - np.random.default_rng(1).random(200)) ** (-1 / 0.8)  # tail exponent 0.8: no mean
    r2 = reference_resolution(pareto, 1.0, tail_exponent=0.8)
    assert r2.statistic == "median (bootstrap)"
    assert r2.estimate == pytest.approx(float(np.median(pareto)))
    assert r2.low <= r2.estimate <= r2.high


def test_the_line_warns_when_the_margin_is_not_resolved():
    s = 0.13 * math.sqrt(100) / T99
    r = paired_resolution(*paired_sample(100, math.log(1.04), s))
    line = resolution_line("ars / oracle", r, target=0.05)
    assert "100 episodes resolve +-13.9 %" in line
    assert "warning: the +4.0 % margin is not resolved" in line
    assert f"~{int(r.episodes_needed)} episodes needed" in line
    assert f"(~{int(r.episodes_for(0.05))} for +-5 %)" in line
    ok = paired_resolution(*paired_sample(100, math.log(1.3), s))
    assert "margin is resolved" in resolution_line("gaussian / oracle", ok) and "warning" not in resolution_line("g", ok)


@pytest.mark.parametrize(
    ("x", "y", "match"),
    [
        ([1.0], [1.0], "at least 2"),
        ([1.0, 2.0], [1.0, 2.0, 3.0], "one size"),
        ([1.0, -2.0], [1.0, 2.0], "positive finite"),
        ([1.0, np.nan], [1.0, 2.0], "positive finite"),
    ],
)
def test_bad_samples_are_refused(x, y, match):
    with pytest.raises(ParameterError, match=match):
        paired_resolution(x, y)


def test_bad_reference_is_refused():
    with pytest.raises(ParameterError, match="reference"):
        reference_resolution([1.0, 2.0], 0.0)


def test_evaluate_lines_warn_for_a_learned_attacker_whose_margin_the_episodes_cannot_resolve():
    pytest.importorskip("sb3_contrib", reason="the training configurations name the rl extra's algorithms")
    from encctl_gym.experiments.compare.evaluate_run import resolution_lines
    from encctl_gym.experiments.compare.records import Curve, Result
    from encctl_gym.experiments.compare.settings import make_setting

    setting = make_setting("paper-example", 0, 256)
    N = setting.params.horizon
    s = 0.13 * math.sqrt(100) / T99
    x, y = paired_sample(100, math.log(1.04), s)
    g = y * 1.3

    def c(name: str, final: np.ndarray, oracle: bool = False) -> Curve:
        return Curve(name, oracle, np.array([N]), final[None].mean(1), np.zeros(1), final.size, final, np.ones(final.size), 0.0)

    result = Result([setting], {setting.key: [c("gaussian", g), c("optimal-cl", y, True), c("ars", x)]}, [], [], 0.0)
    lines = resolution_lines(result, ["ars"], target=0.05)
    assert len(lines) == 4
    assert lines[0].startswith(f"paper-example, delay 0, N = {N}: ars / optimal-cl: 1.040 [")
    assert "100 episodes resolve +-13.9 %: warning: the +4.0 % margin is not resolved" in lines[0]
    assert "median (paired, bootstrap)" in lines[1]
    assert lines[2].startswith(f"paper-example, delay 0, N = {N}: ars / gaussian: {1.04 / 1.3:.3f}")
    assert "E[eps] / gamma_opt(N)" in lines[3]


def test_curve_table_reports_first_best_and_last_ratio_to_gamma_opt():
    from encctl_gym.agents.curves import LearningCurve, curve_table

    c = LearningCurve("ars x s0", "ars", "x", 0, 256, 2.0, 3.0, 2.0, "closed_loop")
    for step, eps in ((0, [4.0, 6.0]), (10, [2.0, 2.4]), (20, [2.4, 2.8])):
        c.append(step, np.array(eps))
    row = curve_table([c]).splitlines()[2]
    assert row == "| ars x s0 | 256 | 20 | 3 | 2.500 | 1.100 (10) | 1.300 |"
