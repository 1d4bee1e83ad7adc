"""The attacker interface shared by every attacker, hand-written or learned.

An attacker is the adversary of Definition def:adversary seen from the environment
``encctl_gym/EncryptedLTIAttack-v0``: it reads the observation (delivered decrypted data, its own
past inputs, the budgets spent) and returns the injected input in action units
``a_t / u_max`` with ``u_max = action_scale * sigma_u``.

Every attacker is built from the environment's resolved parameters (:class:`AttackParams`),
either directly, ``GaussianAttacker(params)``, or from an environment,
``GaussianAttacker.from_env(env)`` (single or vector environment, wrapped or not). ``act``
takes one observation ``(obs_dim,)`` or a batch ``(K, obs_dim)`` from the native vector
environment and returns actions of the matching shape, always inside ``[-1, 1]``; stateful
attackers keep one state per copy, created on the first ``act`` after ``reset``.

Observation layout: :class:`encctl_gym.envs.layout.ObservationLayout` (``self.layout``) names
the slices, and :func:`observation_indices` gives the columns of the observation *modes* learned
attackers are trained on (``"full"``, ``"no_budget"``, ``"blind"``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any

import numpy as np

from encctl_gym.envs.config import AttackParams
from encctl_gym.envs.layout import OBSERVATION_MODES, ObservationLayout
from encctl_gym.errors import ParameterError

__all__ = ["Attacker", "OBSERVATION_MODES", "observation_indices", "params_of"]


def params_of(env: Any) -> AttackParams:
    """The :class:`AttackParams` of a single or vector environment (wrapped or not)."""
    for obj in (env, getattr(env, "unwrapped", None)):
        p = getattr(obj, "params", None)
        if isinstance(p, AttackParams):
            return p
    raise ParameterError(f"{type(env).__name__} carries no AttackParams (is it an EncryptedLTIAttack environment?)")


def observation_indices(params: AttackParams, mode: str) -> np.ndarray:
    """Columns of the observation a learned attacker sees in ``mode`` (``"full"``,
    ``"no_budget"``, ``"blind"``): :meth:`ObservationLayout.columns` of the environment's layout."""
    return ObservationLayout.of(params).columns(mode)


class Attacker(ABC):
    """An identification attacker: ``reset(seed)`` then ``act(obs)`` once per step.

    Parameters
    ----------
    params : AttackParams
        The environment's resolved parameters (``env.unwrapped.params``).

    Attributes
    ----------
    name : str
        Short label used in tables and plots.
    oracle : bool
        True if the attacker uses the true ``(A, B)`` (an upper reference, not a realistic
        attacker).
    needs_states : bool
        True if the attacker's policy reads delivered states (it is meaningless with
        ``decipher_delay="end"``, where nothing is delivered before the end).
    """

    name: str = "attacker"
    oracle: bool = False
    needs_states: bool = False

    def __init__(self, params: AttackParams) -> None:
        if not isinstance(params, AttackParams):
            raise ParameterError(f"params must be AttackParams, got {type(params).__name__}")
        self.params = params
        self.layout = ObservationLayout.of(params)
        self.rng = np.random.default_rng()
        self._batch: int | None = None

    @classmethod
    def from_env(cls, env: Any, **kwargs: Any) -> Attacker:
        """Build the attacker for ``env`` (single or vector, wrapped or not)."""
        return cls(params_of(env), **kwargs)

    # ------------------------------------------------------------------ interface
    def reset(self, seed: int | np.random.SeedSequence | None = None) -> None:
        """Start a new episode; ``seed`` fixes the attacker's own randomness."""
        self.rng = np.random.default_rng(seed)
        self._batch = None

    def act(self, obs: Any) -> np.ndarray:
        """Actions for one observation ``(obs_dim,)`` or a batch ``(K, obs_dim)``.

        Returns
        -------
        numpy.ndarray, float32
            Shape ``(m,)`` or ``(K, m)``, inside ``[-1, 1]``.
        """
        o = np.asarray(obs, dtype=np.float64)
        single = o.ndim == 1
        if single:
            o = o[None]
        if o.ndim != 2 or o.shape[1] != self.layout.dim:
            raise ParameterError(
                f"observation must have shape ({self.layout.dim},) or (K, {self.layout.dim}), got {np.shape(obs)}"
            )
        if self._batch is None:
            self._batch = o.shape[0]
            self._start(self._batch)
        elif o.shape[0] != self._batch:
            raise ParameterError(f"batch size changed from {self._batch} to {o.shape[0]} without reset()")
        a = np.clip(np.asarray(self._act(o), dtype=np.float64), -1.0, 1.0).astype(np.float32)
        return a[0] if single else a

    # ------------------------------------------------------------------ for subclasses
    def _start(self, K: int) -> None:
        """Initialise per-copy state for a batch of ``K`` (called on the first ``act``)."""

    @abstractmethod
    def _act(self, obs: np.ndarray) -> np.ndarray:
        """Actions ``(K, m)`` (action units, clipped by :meth:`act`) for observations ``(K, obs_dim)``."""

    # ------------------------------------------------------------------ helpers
    @property
    def sigma_u(self) -> float:
        return float(np.sqrt(self.params.sigma_u2))

    def to_action(self, u: np.ndarray) -> np.ndarray:
        """Input in plant units to action units (``u / u_max``), not yet clipped."""
        return np.asarray(u) / self.params.u_max

    def __repr__(self) -> str:
        return f"{type(self).__name__}(name={self.name!r})"
