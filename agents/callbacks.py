"""stable-baselines3 callbacks of ``encctl-gym train``: attack metrics, progress, learning curve.

* :class:`AttackMetricsCallback` logs each finished training episode's outcome to TensorBoard.
* :class:`ProgressCallback` draws a progress bar over environment steps that never passes its
  total (an algorithm may run past the requested steps to finish a rollout; the bar then grows
  its total to the steps really done, at the end).
* :class:`LearningCurveCallback` is stable-baselines3's ``EvalCallback`` (periodic evaluation,
  ``best_model.zip``) that also records the final identification error ``epsilon`` of every
  evaluation episode, on the same environment seeds at every evaluation (common random
  numbers, so the curve's steps are not seed noise), and writes it as a
  :class:`agents.curves.LearningCurve` after every evaluation. It evaluates once before
  training too, so a curve starts at the untrained policy.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback, EvalCallback

from .curves import LearningCurve

__all__ = ["AttackMetricsCallback", "ProgressCallback", "LearningCurveCallback"]


class AttackMetricsCallback(BaseCallback):
    """Logs the attack's outcome at every episode end: final epsilon, (N - 1) epsilon
    (comparable with the design rates), epsilon / gamma(N), and the average input power."""

    def _on_step(self) -> bool:
        for info in self.locals.get("infos", ()):
            if "epsilon" in info and "terminal_observation" in info:
                eps, N = info["epsilon"], info["samples_delivered"]
                self.logger.record_mean("attack/final_log10_epsilon", math.log10(eps))
                self.logger.record_mean("attack/final_epsilon_x_N-1", eps * (N - 1))
                self.logger.record_mean("attack/epsilon_over_gamma", eps / info["gamma"])
                self.logger.record_mean("attack/average_power", info["average_power"])
        return True


class ProgressCallback(BaseCallback):
    """A tqdm bar over environment steps; without a TTY it prints a line every 30 s.

    Parameters
    ----------
    total : int
        The requested training steps.
    desc : str
        Label of the bar.
    status : callable, optional
        ``status()`` -> str, shown after the bar's counts (tqdm's postfix) whenever it changes:
        the stopping rule's state (:meth:`agents.stopping.OracleStopper.status`), since the bar
        counts to a budget the rule may stop short of.
    """

    def __init__(self, total: int, desc: str, status: Callable[[], str] | None = None) -> None:
        super().__init__()
        self.total, self.desc = int(total), desc
        self.status = status
        self.bar: Any = None
        self._shown = ""

    def _show_status(self) -> None:
        if self.status is None:
            return
        text = self.status()
        if text != self._shown:
            self._shown = text
            self.bar.set_postfix_str(text, refresh=False)

    def _on_training_start(self) -> None:
        from tqdm import tqdm

        tty = sys.stderr.isatty()
        self.bar = tqdm(
            total=self.total,
            desc=self.desc,
            unit="step",
            mininterval=0.5 if tty else 30.0,
            dynamic_ncols=tty,
            file=sys.stderr,
            ascii=not tty,
        )
        self._show_status()

    def _on_step(self) -> bool:
        self._show_status()
        self.bar.update(min(self.num_timesteps, self.total) - self.bar.n)
        return True

    def _on_training_end(self) -> None:
        if self.bar is None:
            return
        done = max(self.num_timesteps, self.bar.n)
        if done > self.bar.total:  # the last rollout ran past the request: say so, do not overshoot
            self.bar.total = done
        self._show_status()
        self.bar.update(done - self.bar.n)
        self.bar.close()


class LearningCurveCallback(EvalCallback):
    """``EvalCallback`` that records the evaluation episodes' final ``epsilon`` (module docstring).

    Parameters
    ----------
    eval_env : VecEnv
        The evaluation environment (its copies all play one episode per evaluation).
    curve : LearningCurve
        An empty curve holding the references (``N``, ``gamma``, ``gamma_opt``) and labels;
        evaluations are appended to it.
    curve_path : path
        Where the curve is written after every evaluation (``.npz``).
    eval_seed : int
        Environment seed of every evaluation (the same episodes each time).
    on_evaluation : callable, optional
        Called with the curve after every evaluation; returning False stops training.
    **kwargs
        Passed to ``EvalCallback`` (``n_eval_episodes``, ``eval_freq``, ``log_path``,
        ``best_model_save_path``, ``deterministic``, ``verbose``).
    """

    def __init__(
        self,
        eval_env: Any,
        *,
        curve: LearningCurve,
        curve_path: str | Path,
        eval_seed: int,
        on_evaluation: Callable[[LearningCurve], bool] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(eval_env, **kwargs)
        self.on_evaluation = on_evaluation
        self.curve = curve
        self.curve_path = Path(curve_path)
        self.eval_seed = int(eval_seed)
        self._finals: list[float] = []

    def _log_success_callback(self, locals_: dict[str, Any], globals_: dict[str, Any]) -> None:
        super()._log_success_callback(locals_, globals_)
        if locals_["done"] and "epsilon" in locals_["info"]:
            self._finals.append(float(locals_["info"]["epsilon"]))

    def _evaluation_due(self) -> bool:
        return self.eval_freq > 0 and self.n_calls % self.eval_freq == 0

    def _on_training_start(self) -> None:
        self._on_step()  # n_calls == 0: one evaluation of the untrained policy

    def _on_step(self) -> bool:
        if not self._evaluation_due():
            return True
        self.eval_env.seed(self.eval_seed)
        self._finals = []
        keep_going = super()._on_step()
        if self._finals:
            self.curve.append(self.num_timesteps, np.asarray(self._finals))
            self.curve.save(self.curve_path)
            if self.on_evaluation is not None and self.on_evaluation(self.curve) is False:
                keep_going = False
        return keep_going
