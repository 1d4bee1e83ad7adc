"""When to stop training: a rule on the learning curve against the oracle, and a budget scaled to the plant.

A fixed step count is the wrong default for a user's own plant: on a plant whose optimal
design gains little over the Gaussian attack the objective is flat, its random-search
gradient is noisy, and a budget that suffices on the design example ends short of the optimum.
:class:`StoppingRule` instead reads the learning curve (:mod:`agents.curves`: every evaluation
plays the same ``K`` environment seeds) next to the oracle (the A-optimal design of
:mod:`encctl_gym.security.attack_design`, :class:`agents.optimal.OptimalDesignAttacker`) played
once on the same seeds, so that every evaluation gives ``K`` paired log ratios
``log eps_policy - log eps_oracle`` (:func:`agents.resolution.paired_resolution`). After every
evaluation (from the ``min_evaluations``-th on) it stops when either

* **reached**: the upper end of the 95 % interval of the paired ratio to the oracle is at most
  ``1 + tolerance`` (the policy is within ``tolerance`` of the optimal design, with
  confidence, on the evaluation seeds); or
* **plateau**: over the last ``window`` evaluations the mean log ratio's least-squares slope,
  at the pessimistic end of its 95 % t interval, projected over another ``window``
  evaluations, promises less than ``plateau_gain`` of improvement (the curve is flat: more
  steps at this rate buy less than ``plateau_gain``).

Otherwise training runs to its budget (``budget``: the ceiling). :func:`plant_budget` scales that
ceiling to the plant: ``iterations_per_gain / log(gamma_gauss / gamma_opt)`` iterations of the
algorithm (the smaller the optimum's gain over the Gaussian attack, the flatter the objective),
each of ``steps_per_iteration`` environment steps, capped by ``n_timesteps``.

Every decision is a :class:`StoppingDecision` (its reason, the numbers behind it), recorded in
the run's ``run.json`` and printed by ``encctl-gym train``; while training runs, the progress bar
(which counts to the budget, a ceiling) shows the last decision in brief
(:meth:`OracleStopper.status`: the ratio to the oracle against its bar, and what the plateau test
promises), so a run that stops short of its bar says why it may.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from encctl_gym.errors import ConfigError

from .resolution import LEVEL, paired_resolution

__all__ = ["RULES", "StoppingRule", "StoppingDecision", "decide", "plant_budget", "OracleStopper"]

#: Values of the ``stopping.rule`` config entry.
RULES = ("none", "oracle")


@dataclass(frozen=True)
class StoppingRule:
    """The stopping rule (module docstring).

    Attributes
    ----------
    tolerance : float
        Stop when the 95 % interval of the paired ratio to the oracle lies below ``1 + tolerance``.
    window : int
        Evaluations in the plateau test (>= 3).
    plateau_gain : float
        Stop when the curve's slope over the window, at the pessimistic end of its interval,
        promises less than this relative gain over another window.
    min_evaluations : int
        No decision before this many evaluations (the first is the untrained policy).
    """

    tolerance: float = 0.02
    window: int = 20
    plateau_gain: float = 0.02
    min_evaluations: int = 4

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tolerance) and self.tolerance >= 0):
            raise ConfigError(f"stopping.tolerance must be >= 0, got {self.tolerance!r}")
        if not (math.isfinite(self.plateau_gain) and self.plateau_gain >= 0):
            raise ConfigError(f"stopping.plateau_gain must be >= 0, got {self.plateau_gain!r}")
        if int(self.window) < 3:
            raise ConfigError(f"stopping.window must be >= 3 (a slope and its interval), got {self.window!r}")
        if int(self.min_evaluations) < 2:
            raise ConfigError(f"stopping.min_evaluations must be >= 2, got {self.min_evaluations!r}")


@dataclass(frozen=True)
class StoppingDecision:
    """One decision of :func:`decide`.

    Attributes
    ----------
    stop : bool
    reason : str
        ``"reached"``, ``"plateau"``, or ``"continue"`` (and ``"budget"`` when training ran to
        its budget, set by :class:`OracleStopper`).
    message : str
        The decision in words, with its numbers.
    evaluation, timestep : int
        Index (0 = untrained) and training step of the evaluation decided on.
    ratio, low, high : float
        Paired ratio to the oracle at that evaluation and its 95 % interval.
    slope, slope_pessimistic : float or None
        Mean log ratio per evaluation over the window (least squares) and the end of its 95 %
        interval most favourable to further training (None before a full window).
    """

    stop: bool
    reason: str
    message: str
    evaluation: int
    timestep: int
    ratio: float
    low: float
    high: float
    slope: float | None = None
    slope_pessimistic: float | None = None

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    def status(self, rule: StoppingRule) -> str:
        """The decision in a few words for a progress bar: the ratio to the oracle with its
        interval against the bar ``1 + tolerance``, and where the plateau test stands."""
        head = f"oracle ratio {self.ratio:.3f} [{self.low:.3f}, {self.high:.3f}] (stops at <= {1 + rule.tolerance:.3f})"
        if self.reason == "continue" and self.evaluation + 1 < rule.min_evaluations:
            return f"{head}; evaluation {self.evaluation + 1} of {rule.min_evaluations} before a decision"
        if self.slope_pessimistic is None:
            return f"{head}; plateau test at {rule.window} evaluations ({self.evaluation + 1} so far)"
        gain = -self.slope_pessimistic * rule.window
        return (
            f"{head}; another {rule.window} evaluations may gain {100 * math.expm1(max(gain, 0.0)):.1f} % "
            f"(plateau below {100 * rule.plateau_gain:g} %)" + ("" if self.reason == "continue" else f": stop ({self.reason})")
        )


def _slope_interval(y: np.ndarray) -> tuple[float, float]:
    """Least-squares slope of ``y`` against ``0, 1, ...`` and the lower end of its t interval."""
    from scipy.stats import t as student_t

    x = np.arange(y.size, dtype=float)
    x -= x.mean()
    b = float(np.dot(x, y - y.mean()) / np.dot(x, x))
    resid = y - y.mean() - b * x
    dof = y.size - 2
    s2 = float(np.dot(resid, resid)) / dof
    se = math.sqrt(s2 / float(np.dot(x, x)))
    return b, b - float(student_t.ppf(0.5 + LEVEL / 2, dof)) * se


def decide(rule: StoppingRule, timesteps: Any, log_ratios: Any) -> StoppingDecision:
    """Decide on the learning curve so far (module docstring).

    Parameters
    ----------
    rule : StoppingRule
    timesteps : array_like (T,)
        Training step of each evaluation.
    log_ratios : array_like (T, K)
        ``log eps_policy - log eps_oracle`` of each evaluation's ``K`` paired episodes (K >= 2).

    Returns
    -------
    StoppingDecision
    """
    d = np.asarray(log_ratios, dtype=float)
    ts = np.asarray(timesteps)
    if d.ndim != 2 or d.shape[0] != ts.size or d.shape[0] < 1 or d.shape[1] < 2:
        raise ConfigError(f"log_ratios must be (evaluations, episodes >= 2) with one timestep each, got {d.shape}")
    T = d.shape[0]
    last = paired_resolution(np.exp(d[-1]), np.ones(d.shape[1]))
    base: dict[str, Any] = {
        "evaluation": T - 1,
        "timestep": int(ts[-1]),
        "ratio": last.estimate,
        "low": last.low,
        "high": last.high,
    }
    where = f"after {int(ts[-1])} steps: ratio to the oracle {last.estimate:.3f} [{last.low:.3f}, {last.high:.3f}]"
    if T < rule.min_evaluations:
        return StoppingDecision(
            False, "continue", f"{where}; {T} of {rule.min_evaluations} evaluations before a decision", **base
        )
    if last.high <= 1.0 + rule.tolerance:
        return StoppingDecision(
            True, "reached", f"{where}: within {100 * rule.tolerance:g} % of the optimal design with 95 % confidence", **base
        )
    if T < rule.window:
        return StoppingDecision(False, "continue", f"{where}; {T} of {rule.window} evaluations for the plateau test", **base)
    slope, pessimistic = _slope_interval(d[-rule.window :].mean(axis=1))
    gain = -pessimistic * rule.window  # log improvement over another window at the favourable end
    slopes: dict[str, Any] = {"slope": slope, "slope_pessimistic": pessimistic}
    text = (
        f"{where}; slope over the last {rule.window} evaluations {slope:+.4f} per evaluation (log ratio; "
        f"95 % interval down to {pessimistic:+.4f})"
    )
    if gain < math.log1p(rule.plateau_gain):
        return StoppingDecision(
            True,
            "plateau",
            f"{text}: another {rule.window} evaluations would gain less than {100 * rule.plateau_gain:g} % (plateau)",
            **base,
            **slopes,
        )
    return StoppingDecision(False, "continue", f"{text}: still improving", **base, **slopes)


def plant_budget(gamma_gauss: float, gamma_opt: float, *, iterations_per_gain: float, steps_per_iteration: int, cap: int) -> int:
    """The training budget scaled to the plant (module docstring).

    ``ceil(iterations_per_gain / log(gamma_gauss / gamma_opt)) * steps_per_iteration``, at most
    ``cap`` (and ``cap`` when the optimum gains nothing over the Gaussian attack).
    """
    gain = math.log(gamma_gauss / gamma_opt) if gamma_opt > 0 and gamma_gauss > 0 else 0.0
    if not (iterations_per_gain > 0 and steps_per_iteration >= 1):
        raise ConfigError(
            f"stopping.iterations_per_gain must be > 0 and the steps per iteration >= 1, got {iterations_per_gain!r}, "
            f"{steps_per_iteration!r}"
        )
    if gain <= 0:
        return int(cap)
    return int(min(cap, math.ceil(iterations_per_gain / gain) * int(steps_per_iteration)))


@dataclass
class OracleStopper:
    """The ``on_evaluation`` hook of :func:`agents.train.train` that applies a :class:`StoppingRule`.

    Parameters
    ----------
    rule : StoppingRule
    oracle_epsilon : ndarray (K,)
        The oracle's final errors on the evaluation seeds (episode ``k`` on seed ``eval.seed + k``).
    log : callable, optional
        Called with the message of the decision that stops (printing).
    oracle_name : str
        The oracle's name, for the record.
    """

    rule: StoppingRule
    oracle_epsilon: np.ndarray
    log: Any = None
    oracle_name: str = "oracle"
    decisions: list[StoppingDecision] = field(default_factory=list)

    def __call__(self, curve: Any) -> bool:
        """Decide on ``curve`` (an :class:`agents.curves.LearningCurve`); False stops training."""
        d = np.log(curve.epsilon) - np.log(np.asarray(self.oracle_epsilon, dtype=float))[None, :]
        decision = decide(self.rule, curve.timesteps, d)
        self.decisions.append(decision)
        if self.log is not None and decision.stop:
            self.log(f"stopping rule: stop ({decision.reason}) {decision.message}")
        return not decision.stop

    def status(self) -> str:
        """Where the rule stands, for the progress bar (:meth:`StoppingDecision.status` of the
        last decision): the bar counts to the budget, a ceiling the rule may stop short of."""
        if not self.decisions:
            return "stopping rule: the budget is a ceiling; first evaluation pending"
        return "stopping rule: " + self.decisions[-1].status(self.rule)

    def final(self) -> StoppingDecision | None:
        """The last decision; a run that never stopped ends with reason ``"budget"``."""
        if not self.decisions:
            return None
        last = self.decisions[-1]
        if last.stop:
            return last
        return StoppingDecision(
            **{**last.as_dict(), "stop": True, "reason": "budget", "message": last.message + "; budget spent"}
        )
