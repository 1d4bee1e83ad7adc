"""The A-optimal attack input of :mod:`encctl_gym.security.attack_design` as a policy.

An **oracle**: it needs the true ``(A, B)`` (to solve the design SDP, and for the open-loop and
delayed variants also to simulate the plant). It is the reference a learned attacker should
approach, not a realistic attacker.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from encctl_gym.envs.config import AttackParams
from encctl_gym.errors import ParameterError
from encctl_gym.security.attack_design import AttackDesign, optimal_attack_design

from .base import Attacker

__all__ = ["OptimalDesignAttacker", "psd_sqrt"]


def psd_sqrt(S: np.ndarray) -> np.ndarray:
    """The symmetric square root ``L = U diag(sqrt(w)) U^T`` (``L L^T = S``) of a symmetric PSD
    matrix, eigenvalues clipped at 0.

    The symmetric root is unique and continuous in ``S``; the factor ``U diag(sqrt(w))`` alone
    is not: where eigenvalues coincide (the design example's ``V`` is a multiple of the identity)
    the eigenvectors ``U`` are any basis, chosen by the rounding of the solver's last digits and
    by the LAPACK build, and so would be the attacker's inputs for a given seed.
    """
    S = 0.5 * (np.asarray(S, dtype=float) + np.asarray(S, dtype=float).T)
    w, U = np.linalg.eigh(S)
    L = (U * np.sqrt(np.clip(w, 0.0, None))) @ U.T
    return 0.5 * (L + L.T)


class OptimalDesignAttacker(Attacker):
    """The linear policy ``u = K x + v``, ``v ~ N(0, V)``, of the A-optimal attack design.

    * ``decipher_delay = 0`` (closed loop, ``feedback=True``): ``x`` is the state just delivered,
      ``x_t`` itself. This realises the design's regressor covariance ``Sigma`` exactly.
    * ``decipher_delay = d > 0``: the closed-loop gain on the model prediction
      ``x_hat_t = A^d x_{t-d} + sum A^(t-1-i) B u_i`` (an approximation: the prediction misses
      the last ``d`` noises, so ``Sigma`` differs from the design's).
    * ``decipher_delay = "end"`` (open loop, ``feedback=False``): ``x`` is the input-driven state
      ``x_u`` that the attacker simulates from its own inputs, ``x_u <- A x_u + B u``, started in
      its stationary distribution ``N(0, S_u)``.

    Parameters
    ----------
    params : AttackParams
    design : AttackDesign, optional
        A precomputed design of the right kind (skips the SDP, ~0.2 s).
    feedback : bool, optional
        Force the closed- (True) or open-loop (False) design; default from ``decipher_delay``.
    """

    oracle = True

    def __init__(self, params: AttackParams, design: AttackDesign | None = None, feedback: bool | None = None) -> None:
        super().__init__(params)
        if feedback is None:
            feedback = params.decipher_delay is not None
        if feedback and params.decipher_delay is None:
            raise ParameterError("the closed-loop design needs delivered states; with decipher_delay='end' use feedback=False")
        kind = "closed_loop" if feedback else "open_loop"
        if design is None:
            design = optimal_attack_design(
                params.A, params.B, sigma_u2=params.sigma_u2, sigma_w2=params.sigma_w2, feedback=feedback
            )
        elif design.kind != kind or design.K.shape != (params.m, params.n):
            raise ParameterError(
                f"design of kind {design.kind!r} does not fit a {kind} attacker with (n, m) = ({params.n}, {params.m})"
            )
        self.design = design
        self.feedback = feedback
        self.needs_states = feedback
        self.name = "optimal-cl" if feedback else "optimal-ol"
        self._K = np.asarray(design.K, dtype=float)
        self._Lv = psd_sqrt(design.V)
        self._Lu = psd_sqrt(design.input_state_cov) if design.input_state_cov is not None else None
        self._A, self._B = params.A, params.B

    @classmethod
    def from_env(cls, env: Any, **kwargs: Any) -> OptimalDesignAttacker:
        """From an environment; reuses the environment's own design when it computed one."""
        from .base import params_of

        p = params_of(env)
        design = getattr(getattr(env, "unwrapped", env), "design", None)
        feedback = kwargs.get("feedback", p.decipher_delay is not None)
        if design is not None and design.kind == ("closed_loop" if feedback else "open_loop") and "design" not in kwargs:
            kwargs["design"] = design
        return cls(p, **kwargs)

    def _start(self, K: int) -> None:
        n, m = self.params.n, self.params.m
        self._k = 0
        self._inputs: list[np.ndarray] = []  # own applied inputs, plant units
        if self.feedback:
            self._x = np.zeros((K, n))
        else:
            z = self.rng.standard_normal((K, n))
            self._x = z @ self._Lu.T if self._Lu is not None else np.zeros((K, n))
        self._m = m

    def _state(self, obs: np.ndarray) -> np.ndarray:
        """The state the gain acts on (see the class docstring)."""
        if not self.feedback:
            return self._x
        d = self.params.decipher_delay
        assert d is not None  # a feedback attacker needs delivered states (checked in __init__)
        j = self._k - d  # index of the latest delivered state
        if d == 0:
            return obs[:, self.layout.state]
        if j < 0:  # nothing delivered yet: predict from x_0 = E[x_0] = 0
            x = np.zeros((obs.shape[0], self.params.n))
            start = 0
        else:
            x = obs[:, self.layout.state].astype(float)
            start = j
        for u in self._inputs[start : self._k]:
            x = x @ self._A.T + u @ self._B.T
        return x

    def _act(self, obs: np.ndarray) -> np.ndarray:
        x = self._state(obs)
        v = self.rng.standard_normal((obs.shape[0], self._m)) @ self._Lv.T
        u = x @ self._K.T + v
        a = np.clip(self.to_action(u), -1.0, 1.0)
        u_applied = a * self.params.u_max
        if self.feedback:
            if self.params.decipher_delay:
                self._inputs.append(u_applied)
        else:
            self._x = self._x @ self._A.T + u_applied @ self._B.T
        self._k += 1
        return a
