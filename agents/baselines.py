"""Open-loop excitation baselines: the paper's Gaussian attack, random binary and AR(1) inputs.

All three have average power ``sigma_u2`` per channel (the environment's energy budget) and do
not read the observation, so they behave the same for every ``decipher_delay``.
"""

from __future__ import annotations

import math

import numpy as np

from encctl_gym.envs.config import AttackParams
from encctl_gym.errors import ParameterError

from .base import Attacker

__all__ = ["GaussianAttacker", "PRBSAttacker", "ColoredGaussianAttacker"]


class GaussianAttacker(Attacker):
    """The paper's attacker (Theorem thm:sic): i.i.d. ``u_t ~ N(0, sigma_u2 I)``.

    In action units ``N(0, I / action_scale^2)``, clipped to the action box ``[-1, 1]``
    (at ``action_scale`` standard deviations: with the default 4 the clipping removes a
    fraction 1.1e-4 of the power).
    """

    name = "gaussian"

    def _act(self, obs: np.ndarray) -> np.ndarray:
        K = obs.shape[0]
        return self.to_action(self.sigma_u * self.rng.standard_normal((K, self.params.m)))


class PRBSAttacker(Attacker):
    """Random binary inputs: each channel ``+sigma_u`` or ``-sigma_u`` with probability 1/2,
    independently at every step (the same power as the Gaussian attack, bounded amplitude)."""

    name = "prbs"

    def _act(self, obs: np.ndarray) -> np.ndarray:
        K = obs.shape[0]
        signs = 2.0 * self.rng.integers(0, 2, size=(K, self.params.m)) - 1.0
        return self.to_action(self.sigma_u * signs)


class ColoredGaussianAttacker(Attacker):
    """AR(1) Gaussian inputs ``u_t = rho u_{t-1} + sqrt(1 - rho^2) e_t``, ``e_t ~ N(0, sigma_u2 I)``.

    Started in the stationary distribution ``N(0, sigma_u2 I)``, so every ``u_t`` has variance
    ``sigma_u2`` (the same power as the Gaussian attack) and correlation ``rho^k`` at lag ``k``.

    Parameters
    ----------
    params : AttackParams
    rho : float, default 0.5
        Lag-one correlation, ``|rho| < 1``.
    """

    name = "colored"

    def __init__(self, params: AttackParams, rho: float = 0.5) -> None:
        super().__init__(params)
        rho = float(rho)
        if not (math.isfinite(rho) and abs(rho) < 1.0):
            raise ParameterError(f"rho must lie in (-1, 1), got {rho}")
        self.rho = rho
        self.name = f"colored(rho={rho:g})"
        self._u = np.zeros((1, params.m))

    def _start(self, K: int) -> None:
        self._u = self.sigma_u * self.rng.standard_normal((K, self.params.m))
        self._first = True

    def _act(self, obs: np.ndarray) -> np.ndarray:
        if self._first:  # u_0 from the stationary distribution
            self._first = False
        else:
            e = self.sigma_u * self.rng.standard_normal(self._u.shape)
            self._u = self.rho * self._u + math.sqrt(1.0 - self.rho**2) * e
        return self.to_action(self._u)
