"""Features a learned attacker appends to its observation, computed on the attacker's side.

The environment's observation (:class:`encctl_gym.envs.layout.ObservationLayout`) holds what
the attacker has been delivered and its budgets. A *feature* is something more the attacker
computes for itself, from its own randomness or from the observations it has seen, and feeds to
its policy next to the observation columns of its mode. The same :class:`FeatureSet` computes
the features in training (:class:`agents.sb3.SB3VecEnv`) and when a trained policy plays
(:class:`agents.sb3.SB3Attacker`), so both see the same numbers; a run records the names in its
configuration (``features``).

=========  ===============================================================================
name       feature
=========  ===============================================================================
``dither`` ``m`` fresh draws of ``N(0, 1)`` per step (clipped at 8): the attacker's private
           randomness as an input of its policy. A *deterministic* policy of
           ``(observation, xi)`` is a stochastic attacker, and a linear one,
           ``u = K x + L xi``, contains the optimal stationary attack ``u = K x + v``,
           ``v ~ N(0, V)`` of :mod:`encctl_gym.security.attack_design` exactly (``L L^T = V``).
           It is what lets a learner that searches over deterministic policies (ARS) excite
           the plant: a deterministic ``u = K x`` leaves the regressor ``[x; u]`` rank
           deficient.
=========  ===============================================================================

A new feature is a subclass of :class:`Feature` and a row of :data:`FEATURES`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from encctl_gym.errors import ConfigError, ParameterError
from encctl_gym.registry import Registry

__all__ = ["Feature", "DitherFeature", "FEATURES", "FeatureSet", "check_features"]


class Feature:
    """One feature: ``dim`` columns per copy, with a state that starts again every episode.

    Parameters
    ----------
    params : AttackParams
        The environment's resolved parameters.
    """

    name = "feature"

    def __init__(self, params: Any) -> None:
        self.params = params

    @property
    def dim(self) -> int:
        """Number of columns."""
        raise NotImplementedError

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Finite ``(low, high)`` of the columns (float32), for the observation space."""
        raise NotImplementedError

    def reset(self, rngs: Sequence[np.random.Generator], groups: np.ndarray) -> None:
        """A new episode for every copy; copy ``k`` draws from ``rngs[groups[k]]``."""

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        """The columns ``(K, dim)`` for full observations ``obs`` ``(K, obs_dim)``."""
        raise NotImplementedError


class DitherFeature(Feature):
    """``m`` draws of ``N(0, 1)`` per copy and step, clipped at :attr:`CLIP` (module docstring).

    Copies that share a random generator (a *group*: the same episode seed, see
    :meth:`FeatureSet.reset`) see the same draws: the common random numbers of a paired
    comparison.
    """

    name = "dither"
    #: Draws are clipped at +-CLIP (a bounded observation space; P(|z| > 8) = 1.2e-15).
    CLIP = 8.0

    def __init__(self, params: Any) -> None:
        super().__init__(params)
        self.m = int(params.m)
        self._rngs: Sequence[np.random.Generator] = (np.random.default_rng(),)
        self._groups = np.zeros(1, dtype=np.int64)

    @property
    def dim(self) -> int:
        return self.m

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        hi = np.full(self.m, self.CLIP, dtype=np.float32)
        return -hi, hi

    def reset(self, rngs: Sequence[np.random.Generator], groups: np.ndarray) -> None:
        self._rngs, self._groups = rngs, groups

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        K = obs.shape[0]
        if len(self._rngs) == 1:
            z = self._rngs[0].standard_normal((K, self.m))
        else:
            draws = np.stack([g.standard_normal(self.m) for g in self._rngs])
            z = draws[self._groups[:K]]
        return np.clip(z, -self.CLIP, self.CLIP)


#: Features by the name a configuration's ``features`` list gives.
FEATURES: Registry[type[Feature]] = Registry("feature", [DitherFeature], error=ConfigError)


def check_features(names: Any, where: str = "features") -> list[str]:
    """A list of distinct names of :data:`FEATURES`; :class:`ConfigError` naming the bad entry."""
    if names is None:
        return []
    if not isinstance(names, (list, tuple)) or not all(isinstance(n, str) for n in names):
        raise ConfigError(f"{where} must be a list of feature names, got {names!r}")
    for n in names:
        try:
            FEATURES.lookup(n)
        except ConfigError as exc:
            raise ConfigError(f"{where}: {exc}") from None
    if len(set(names)) != len(names):
        raise ConfigError(f"{where} names a feature twice: {list(names)!r}")
    return list(names)


class FeatureSet:
    """The features of one policy, in order: their columns are appended after the observation's.

    Parameters
    ----------
    names : sequence of str
        Keys of :data:`FEATURES` (may be empty: then nothing is appended).
    params : AttackParams
        The environment's resolved parameters.
    """

    def __init__(self, names: Sequence[str], params: Any) -> None:
        self.names = check_features(list(names))
        self.features = [FEATURES[n](params) for n in self.names]

    def __bool__(self) -> bool:
        return bool(self.features)

    @property
    def dim(self) -> int:
        """Columns appended."""
        return sum(f.dim for f in self.features)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """``(low, high)`` of the appended columns (float32; empty without features)."""
        if not self.features:
            return np.zeros(0, np.float32), np.zeros(0, np.float32)
        lows, highs = zip(*(f.bounds() for f in self.features))
        return np.concatenate(lows).astype(np.float32), np.concatenate(highs).astype(np.float32)

    def reset(self, K: int, *, rng: np.random.Generator | None = None, seeds: Sequence[int] | None = None) -> None:
        """Start the features' episodes for ``K`` copies.

        With ``seeds`` (one per copy, the environment seeds of the copies) every copy draws from
        a generator seeded by its seed, and copies with the same seed draw the same numbers;
        otherwise all copies draw from ``rng`` (default: fresh entropy).
        """
        if seeds is not None:
            seeds = [int(s) for s in seeds]
            if len(seeds) != K:
                raise ParameterError(f"FeatureSet.reset: {len(seeds)} seeds for {K} copies")
            unique, groups = np.unique(np.asarray(seeds, dtype=np.int64), return_inverse=True)
            rngs = [np.random.default_rng(np.random.SeedSequence([int(s), 0x6665])) for s in unique]
        else:
            rngs, groups = [rng if rng is not None else np.random.default_rng()], np.zeros(K, dtype=np.int64)
        for f in self.features:
            f.reset(rngs, np.asarray(groups, dtype=np.int64))

    def append(self, obs: np.ndarray, selected: np.ndarray) -> np.ndarray:
        """``selected`` (the mode's columns of ``obs``) with the features of ``obs`` appended (float32)."""
        if not self.features:
            return selected
        cols = [np.asarray(selected, dtype=np.float32)] + [np.asarray(f(obs), dtype=np.float32) for f in self.features]
        return np.ascontiguousarray(np.concatenate(cols, axis=1))
