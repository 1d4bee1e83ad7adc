"""The records of a comparison: one attacker's :class:`Curve` and everything one run measured,
:class:`Result` (built by :func:`~experiments.compare.protocol.compute`, read by the tables,
plots and reports).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .settings import Setting

__all__ = ["Curve", "Result"]


@dataclass
class Curve:
    """Mean error of one attacker against N, with the per-episode finals.

    Attributes
    ----------
    attacker : str
    oracle : bool
        The attacker knows (A, B).
    N, mean, se : ndarray (P,)
        Grid of attack lengths, mean final error of the attacks of that length and its standard error.
    episodes : int
    final, power : ndarray (E,)
        Final error and average power of each episode at the horizon (the last grid point).
    seconds : float
    along_N, along_mean, along_se, along_energy : ndarray, optional
        With delivered states: the running estimate within one full-length attack and the mean
        fraction of the episode's energy budget spent so far.
    covariance : ndarray, optional
        The regressor covariance the attacks at the horizon realised
        (:attr:`agents.evaluate.Rollout.covariance`; its design efficiency is
        :func:`agents.evaluate.design_efficiency`).
    """

    attacker: str
    oracle: bool
    N: np.ndarray
    mean: np.ndarray
    se: np.ndarray
    episodes: int
    final: np.ndarray
    power: np.ndarray
    seconds: float
    along_N: np.ndarray | None = None
    along_mean: np.ndarray | None = None
    along_se: np.ndarray | None = None
    along_energy: np.ndarray | None = None
    covariance: np.ndarray | None = None


@dataclass
class Result:
    """Everything one comparison measured.

    Attributes
    ----------
    settings : list of Setting
    curves : dict
        ``(system, delay)`` -> the curves of that setting's attackers, in play order.
    security, bounds : list of dict
        Rows of :func:`~experiments.compare.tables.security_row` (one per attacker and
        setting) and :func:`~experiments.compare.tables.bound_rows` (the references).
    seconds : float
    elgamal : list of dict
        Rows of :func:`elgamal_check`.
    seed : int
        Environment seeds ``seed, seed + 1, ...`` of every attacker.
    """

    settings: list[Setting]
    curves: dict[tuple[str, Any], list[Curve]]
    security: list[dict[str, Any]]
    bounds: list[dict[str, Any]]
    seconds: float
    elgamal: list[dict[str, Any]] = field(default_factory=list)
    seed: int = 0
