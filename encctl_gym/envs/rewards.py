"""Rewards of ``EncryptedLTIAttack-v0``, one class each, picked by name (the ``reward`` key).

A reward sees the episode around the delivery of each step: :meth:`Reward.begin` before it,
:meth:`Reward.on_delivery` when samples were delivered (after the estimate and the Gram matrix
are updated), :meth:`Reward.end` after it, which returns the reward of every copy. A new reward
is a new class in :data:`REWARDS`; the episode has no branch per reward.

``fused`` rewards are also computed by the compiled steady-state step of the ideal backend
(:func:`encctl_gym.envs._kernels.step_fused`, which writes the same numbers); the others run the
step's general path. ``needs_gram`` rewards read the Gram matrix ``G`` of the delivered
regressors after every delivery, so the episode keeps it up to date for them.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..registry import Registry
from . import _kernels as kern

__all__ = ["Reward", "GramReward", "LogErrorReward", "LogDetReward", "AOptimalityReward", "REWARDS"]


class Reward:
    """Base class of the rewards (see the module docstring)."""

    name = "reward"
    fused = False
    needs_gram = False

    def __init__(self, params: Any, num_envs: int) -> None:
        self.params = params
        self.K = num_envs

    def reset(self, core: Any) -> None:
        """A new episode starts (before its first delivery)."""

    def begin(self, core: Any) -> None:
        """Before a step's delivery."""

    def on_delivery(self, core: Any) -> None:
        """Samples were delivered: the estimate, its error and the Gram matrix are up to date."""

    def end(self, core: Any) -> np.ndarray:
        """After a step's delivery: the reward of every copy, shape (K,)."""
        raise NotImplementedError


class LogErrorReward(Reward):
    """``log eps_before - log eps_after``: the decrease of ``log epsilon`` (Definition def:error)
    of the least-squares estimate on the delivered data; the return telescopes to
    ``log eps_0 - log eps_final``."""

    name = "log_error"
    fused = True

    def begin(self, core: Any) -> None:
        self._before = core.eps.copy()

    def end(self, core: Any) -> np.ndarray:
        out = np.empty(self.K)
        kern.log_ratio(self._before, core.eps, out)  # the same log as the fused kernels
        return out


class GramReward(Reward):
    """A reward that is the change, at each delivery, of a function of the Gram matrix ``G`` of the
    delivered regressors (``needs_gram``): a subclass gives the value before any delivery
    (:meth:`initial`) and after one (:meth:`measure`), and ``sign`` (+1: an increase is
    rewarded, -1: a decrease)."""

    needs_gram = True
    sign = 1.0

    def __init__(self, params: Any, num_envs: int) -> None:
        super().__init__(params, num_envs)
        self._d = params.n + params.m
        self._delta = params.logdet_regularization
        self.value = np.full(num_envs, self.initial())

    def initial(self) -> float:
        """The value of every copy before its first delivery."""
        raise NotImplementedError

    def measure(self, G: np.ndarray) -> np.ndarray:
        """The value for the Gram matrices ``G`` (K, d, d) of the copies."""
        raise NotImplementedError

    def reset(self, core: Any) -> None:
        self.value = np.full(self.K, self.initial())

    def begin(self, core: Any) -> None:
        self._before = self.value.copy()

    def on_delivery(self, core: Any) -> None:
        self.value = self.measure(core.G)

    def end(self, core: Any) -> np.ndarray:
        return self.sign * (self.value - self._before)


class LogDetReward(GramReward):
    """The increase of ``log det(G + delta I)`` of the regressor Gram matrix ``G`` of the delivered
    data (D-optimality; an attacker can compute it without knowing ``(A, B)``);
    ``delta = logdet_regularization``."""

    name = "logdet"

    def initial(self) -> float:
        return self._d * math.log(self._delta)

    def measure(self, G: np.ndarray) -> np.ndarray:
        sign, value = np.linalg.slogdet(G + self._delta * np.eye(self._d))
        bad = ~((sign > 0) & np.isfinite(value))
        if bad.any():  # delta I lost to rounding next to a singular G: log det from the clipped eigenvalues
            lam = np.clip(np.linalg.eigvalsh(G[bad]), 0.0, None)
            value[bad] = np.log(lam + self._delta).sum(axis=-1)
        return value


class AOptimalityReward(GramReward):
    """The decrease of ``log tr((G + delta I)^-1)``: A-optimality of the delivered regressors.

    For least squares with white noise, the error of Definition def:error given the regressors is
    ``E[epsilon | D] = sigma_w2 tr(G^-1) / (n + m)`` (the first steps of the proof of Theorem
    thm:sic, before its Jensen step), so this reward is the decrease of the log of the expected
    error of the current estimate: it tracks the quantity an attacker wants to make small with
    far less variance than the realised error (``log_error``), and an attacker can compute it
    without knowing ``(A, B)``. ``delta = logdet_regularization`` keeps it finite before ``G`` is
    invertible; the return telescopes to ``log(d / delta) - log tr((G_N + delta I)^-1)``.
    """

    name = "a_optimality"
    sign = -1.0

    def initial(self) -> float:
        ratio = self._d / self._delta
        # a subnormal delta makes d / delta overflow: the same log, as a difference
        return math.log(ratio) if math.isfinite(ratio) else math.log(self._d) - math.log(self._delta)

    def measure(self, G: np.ndarray) -> np.ndarray:
        lam = np.clip(np.linalg.eigvalsh(G), 0.0, None)  # G is PSD; clip rounding below 0
        with np.errstate(divide="ignore", over="ignore"):
            value = np.log((1.0 / (lam + self._delta)).sum(axis=-1))
        bad = ~np.isfinite(value)
        if bad.any():  # 1 / (0 + delta) overflows for a subnormal delta: log-sum-exp of -log(lam + delta)
            value[bad] = np.logaddexp.reduce(-np.log(lam[bad] + self._delta), axis=-1)
        return value


#: Rewards by the name the ``reward`` configuration key gives.
REWARDS: Registry[type[Reward]] = Registry("reward", [LogErrorReward, LogDetReward, AOptimalityReward], error=ConfigError)
