"""The tail rule of the identification error, the Hill estimator and the flagged summaries."""

from __future__ import annotations

import math

import numpy as np
import pytest

from encctl_gym.errors import ParameterError
from encctl_gym.ident.tails import error_tail_exponent, hill_tail_exponent, moment_exists, summarize_errors
from encctl_gym.presets import get_preset
from encctl_gym.sim.montecarlo import error_summaries, gaussian_attack_errors
from encctl_gym.sim.plant import LinearPlant

SMALL = get_preset("small")  # n = m = 2


def _inverse_wishart_moment_finite(order: int, d: int, T: int) -> bool:
    # E[(G^{-1})^k] for G ~ Wishart_d(I, T) is finite iff T > d + 2k - 1 (mean: T > d + 1;
    # second moments: T > d + 3), an independent statement of the rule for i.i.d. Gaussian columns
    return T > d + 2 * order - 1


@pytest.mark.parametrize("n,m", [(2, 2), (4, 4), (3, 1), (1, 5)])
def test_least_squares_rule_is_the_inverse_wishart_condition(n: int, m: int) -> None:
    d = n + m
    for N in range(d + 1, d + 9):
        for order in (1, 2, 3):
            assert moment_exists(order, n, m, N) == _inverse_wishart_moment_finite(order, d, N - 1), (n, m, N, order)
            assert moment_exists(order, n, m, N, "forgetting") == moment_exists(order, n, m, N)
    # at the least-squares minimum the smallest eigenvalue of G has density l^(-1/2): alpha = 1/2
    assert error_tail_exponent(n, m, d + 1) == 0.5


def test_other_estimators() -> None:
    n, m = 4, 4
    q = 2 * m  # default lags ceil(n / m) = 1
    for N in (10, 100, 10**6):
        assert error_tail_exponent(n, m, N, "iv") == (q - n - m + 1) / 2  # just identified: no mean at any N
        assert not moment_exists(1, n, m, N, "iv")
    assert error_tail_exponent(n, m, 50, {"name": "iv", "lags": 3}) == (4 * m - n - m + 1) / 2
    assert error_tail_exponent(n, m, 9, {"name": "bayes", "prior_variance": 1.0, "noise_variance": 0.1}) == math.inf
    assert error_tail_exponent(n, m, 9, "bayes") == 8 * 8 / 2
    with pytest.raises(ParameterError, match="N"):
        error_tail_exponent(n, m, 8)
    with pytest.raises(ParameterError, match="N"):
        error_tail_exponent(n, m, 9, "iv")  # IV needs L + (L + 1) m + 1 = 10
    with pytest.raises(ParameterError, match="tls"):
        error_tail_exponent(n, m, 20, "tls")
    with pytest.raises(ParameterError, match="order"):
        moment_exists(0, n, m, 20)


def test_hill_recovers_a_pareto_exponent() -> None:
    rng = np.random.default_rng(0)
    for alpha in (0.5, 1.5, 3.0):
        x = rng.pareto(alpha, 20_000) + 1.0  # P(X > x) = x^(-alpha) for x >= 1
        h = hill_tail_exponent(x)
        assert h.k == 2000 and h.low < alpha < h.high
        assert h.alpha == pytest.approx(alpha, rel=0.08)
    with pytest.raises(ParameterError):
        hill_tail_exponent([1.0])
    with pytest.raises(ParameterError):
        hill_tail_exponent([1.0, -2.0, 3.0])
    with pytest.raises(ParameterError, match="k"):
        hill_tail_exponent([1.0, 2.0, 3.0], k=3)


@pytest.mark.parametrize("N", [5, 6, 7])
def test_rule_matches_the_monte_carlo_tail(N: int) -> None:
    # least squares on the Gaussian attack of a plant that is not a multiple of the identity: the
    # fitted tail of 20000 errors agrees with (N - n - m) / 2 (Hill's error about 5 % at k = 500)
    plant = LinearPlant(SMALL.A, SMALL.B, sigma_w2=SMALL.sigma_w2, sigma_x2=SMALL.sigma_x2)
    e = gaussian_attack_errors(plant, sample_sizes=[N], runs=20_000, sigma_u2=SMALL.sigma_u2, seed=N)[:, 0]
    h = hill_tail_exponent(e, k=500)
    assert h.alpha == pytest.approx(error_tail_exponent(2, 2, N), rel=0.15)


def test_summary_flags_a_mean_that_does_not_exist() -> None:
    rng = np.random.default_rng(1)
    x = rng.pareto(0.5, 200) + 1.0
    s = summarize_errors(x, tail_exponent=0.5)
    assert s.status == "does not exist" and not s.mean_ok
    assert s.mean_text().startswith("mean does not exist: tail exponent a = 0.5")
    assert s.median == pytest.approx(float(np.median(x)))
    assert s.quantiles[0.1] < s.median < s.quantiles[0.9]
    assert summarize_errors(x, tail_exponent=1.5).mean_text().startswith("mean unreliable: tail exponent a = 1.5")
    # without a rule the Hill interval finds the tail
    s2 = summarize_errors(x)
    assert s2.status == "unreliable" and "fitted tail exponent" in s2.flag()
    # light tails: the mean with its standard error
    y = rng.exponential(1.0, 200)
    s3 = summarize_errors(y, tail_exponent=10.0)
    assert s3.mean_ok and s3.flag() == "" and s3.mean_text() == f"{y.mean():.3g} ± {s3.se:.1g}"
    with pytest.raises(ParameterError):
        summarize_errors([np.nan, np.nan])
    with pytest.raises(ParameterError):
        summarize_errors([1.0, -1.0])
    with pytest.raises(ParameterError, match="tail_exponent"):
        summarize_errors([1.0, 2.0], tail_exponent=0.0)


def test_engine_summaries_use_the_rule() -> None:
    plant = LinearPlant(SMALL.A, SMALL.B, sigma_w2=SMALL.sigma_w2, sigma_x2=SMALL.sigma_x2)
    grid = [5, 7, 40]
    e = gaussian_attack_errors(plant, sample_sizes=grid, runs=60, sigma_u2=SMALL.sigma_u2, seed=0)
    ss = error_summaries(e, grid, n=2, m=2)
    assert [s.status for s in ss] == ["does not exist", "unreliable", "exists"]
    assert [s.tail_exponent for s in ss] == [0.5, 1.5, 18.0]
    assert ss[2].mean == pytest.approx(float(e[:, 2].mean()))
    with pytest.raises(ParameterError, match="sample_sizes"):
        error_summaries(e, [5, 7], n=2, m=2)


def test_compare_row_reports_the_median_where_the_mean_does_not_exist() -> None:
    from encctl_gym.agents.evaluate import Rollout
    from encctl_gym.experiments.compare.protocol import Curve
    from encctl_gym.experiments.compare.report import _error_cell
    from encctl_gym.experiments.compare.settings import make_setting
    from encctl_gym.experiments.compare.tables import security_row

    s = make_setting("small", 0, None, length=40)
    rng = np.random.default_rng(2)
    final = rng.pareto(0.5, 50) * 1e-3 + 1e-3
    grid = np.array([4, 5])
    means = np.array([1.0, final.mean()])
    c = Curve("gaussian", False, grid, means, 0.1 * means, 50, final, np.ones(50), 0.0)
    row = security_row(s, c)  # horizon N = 5 = n + m + 1: tail exponent 1/2
    assert row["mean_status"] == "does not exist" and row["median_at_horizon"] == pytest.approx(float(np.median(final)))
    cell = _error_cell(row)
    assert cell.startswith("median ") and "mean does not exist" in cell
    ok = security_row(
        s,
        Curve(
            "gaussian",
            False,
            np.array([10, 40]),
            np.array([1e-2, 2e-3]),
            np.array([1e-3, 1e-4]),
            50,
            rng.exponential(2e-3, 50),
            np.ones(50),
            0.0,
        ),
    )
    assert ok["mean_status"] == "exists" and _error_cell(ok).startswith(f"{ok['mean_error_at_horizon']:.3g} [")
    r = Rollout("gaussian", np.array([5]), final[:, None], final[:, None], final, np.ones(50), np.ones(50), np.ones(1), 0.0)
    assert r.summary_final(2, 2).status == "does not exist" and r.summary_final().status == "unreliable"


def test_bad_samples_are_refused_with_their_name() -> None:
    with pytest.raises(ParameterError, match="errors must be a numeric array"):
        summarize_errors("abc")
    with pytest.raises(ParameterError, match="1-d"):
        summarize_errors([[1.0, 2.0], [3.0, 4.0]])
    with pytest.raises(ParameterError, match="tail_exponent"):
        summarize_errors([1.0, 2.0], tail_exponent=[1.0, 2.0])
    with pytest.raises(ParameterError, match="samples must be a numeric array"):
        hill_tail_exponent("abc")
    with pytest.raises(ParameterError, match=r"sample_sizes\[0\]"):
        error_summaries(np.ones((3, 1)), [5.5], n=2, m=2)
