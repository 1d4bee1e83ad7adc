"""Attackers that keep the loop looking normal: additive, sparse and malleability-only (issue 30).

Every attacker of :mod:`agents.baselines` replaces the controller's input by its own
(Definition def:adversary, ``injection="replace"``), so the closed-loop innovation
``r = x[t+1] - (A + B Phi) x[t]`` carries ``B (a - Phi x)`` in full and the detectors of
:mod:`encctl_gym.loop.detection` see the missing feedback. The attackers here keep ``Phi x``:

==================================  =================================================================
attacker                            the input the plant applies
==================================  =================================================================
:class:`AdditiveAttacker`           ``Phi x + d``, ``d ~ N(0, sigma_d2 I)`` white. ``injection="add"``:
``"additive"``                      the server's honest output plus ``d`` (on ElGamal the products are
                                    read with the period's key and ``sk_0``: ``decipher_delay=0``).
                                    ``injection="replace"``: the forgery of ``Phi x_hat + d``, with
                                    ``Phi`` read from ``Enc(pk_0, Phi)`` (one more key) and ``x_hat``
                                    the delivered state (delay 0) or its prediction (delay > 0,
                                    :class:`StatePredictor`: the attacker's own least-squares model)
:class:`SparseAttacker`             honest (``add``: nothing added; ``replace``: ``Phi x_hat``
``"sparse"``                        replayed) except on a fraction ``q`` of the steps, where every
                                    input gets ``+-level u_max`` (``add``) or is forged to it
                                    (``replace``): a few injections at the input bound
:class:`MalleabilityAttacker`       ``injection="scale"`` (no key at all): row ``i`` of the honest
``"malleability"``                  output multiplied by ``c`` in {0, 1, c+} (c+ the smallest
                                    integer >= 2 in the plaintext group, :func:`~encctl_gym.loop
                                    .injection.scale_gain`), so ``u_i = c (Phi x)_i``; on a fraction
                                    ``q`` of (row, step) pairs, 0 with probability ``(c+ - 1)/c+``
                                    and ``c+`` with ``1/c+`` (mean gain 1: zero-mean excitation
                                    ``delta (Phi x)_i`` with ``E[delta^2] = c+ - 1``)
==================================  =================================================================

What a keyless server can do to ElGamal's output is set out in ``docs/stealth.md``: raising a
summand ciphertext to a power ``k`` encrypts ``P^k`` (decoded as ``Delta^(2k - 2)`` times a
product: useless beyond ``k`` in {0, 1}); multiplying two summands encrypts ``P P'`` (the same);
multiplying by a known plaintext ``c`` in G scales the summand (:class:`MalleabilityAttacker`);
substituting a summand by a public-key encryption (the forgery) or moving summands between the
rows of one period; summands of another period are refused by the plant (their recorded step).
No keyless manipulation adds a chosen ``d`` to ``Phi x``: that needs the additive homomorphism
(the Paillier scheme's ``add`` multiplies by ``Enc(d)`` and needs no key, so there the
:class:`AdditiveAttacker` with ``injection="add"`` *is* the malleability-only attacker).

The excitation each class adds is white with second moment ``Sigma_d`` (:meth:`excitation_covariance`),
which is what :mod:`encctl_gym.security.stealth` turns into the KL divergence the detectors see
and the information the attacker gains.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from encctl_gym._validation import check_positive, check_probability
from encctl_gym.envs.config import AttackParams
from encctl_gym.errors import ParameterError
from encctl_gym.loop.injection import scale_gain
from encctl_gym.loop.output_feedback import controller_matrix
from encctl_gym.registry import Registry

from .base import Attacker

__all__ = ["StatePredictor", "AdditiveAttacker", "SparseAttacker", "MalleabilityAttacker", "STEALTH_ATTACKERS", "SIGNAL"]

#: The action magnitude a :class:`MalleabilityAttacker` sends: in ``scale`` mode only the sign of
#: an entry counts (:func:`~encctl_gym.loop.injection.scale_multipliers`), and this keeps the
#: environment's energy charge negligible (1e-6 of ``u_max^2`` per entry).
SIGNAL = 1e-3
#: Pairs per unknown of a row of ``[A B]`` before :class:`StatePredictor` trusts its estimate (a
#: least-squares fit from about ``n + m`` closed-loop pairs with a small excitation is too poor to
#: predict with: its predictions drove the forged inputs to the bound in a trial run).
MIN_PAIRS_PER_UNKNOWN = 5


class StatePredictor:
    """The attacker's prediction of ``x_t`` from the state delivered ``d`` steps ago (batched).

    ``x_hat_t = A_hat^d x_{t-d} + sum_i A_hat^(t-1-i) B_hat u_i`` with ``(A_hat, B_hat)`` the
    least-squares estimate (eq:estimate) from the pairs delivered so far (the observation's
    ``x_j`` and ``u_{j-1}`` with the previous ``x_{j-1}``), refitted at every delivery once
    :data:`MIN_PAIRS_PER_UNKNOWN` ``(n + m)`` pairs are in (before, it predicts persistence:
    ``A_hat = I``, ``B_hat = 0``); the prediction is clipped to the encoder's range ``x_bound``.
    With ``d = 0`` it returns the delivered state itself. Nothing of the true plant is read.
    """

    def __init__(self, attacker: Attacker, K: int) -> None:
        p = attacker.params
        self.n, self.m, self.d = p.n, p.m, int(p.decipher_delay or 0)
        self.x_bound = float(p.x_bound)
        self.layout = attacker.layout
        q = self.n + self.m
        self.gram = np.zeros((K, q, q))
        self.cross = np.zeros((K, q, self.n))
        self.pairs = 0
        self.theta = np.concatenate([np.broadcast_to(np.eye(self.n), (K, self.n, self.n)), np.zeros((K, self.m, self.n))], axis=1)
        self.prev: np.ndarray | None = None
        self.inputs: list[np.ndarray] = []  # own applied inputs (plant units), one (K, m) per step

    def _learn(self, obs: np.ndarray) -> None:
        lay = self.layout
        if obs[0, lay.flag] < 0.5:
            return
        x = obs[:, lay.state].astype(float)
        if self.prev is not None:
            z = np.concatenate([self.prev, obs[:, lay.input].astype(float)], axis=1)
            self.gram += z[:, :, None] * z[:, None, :]
            self.cross += z[:, :, None] * x[:, None, :]
            self.pairs += 1
            if self.pairs >= MIN_PAIRS_PER_UNKNOWN * (self.n + self.m):
                self.theta = np.linalg.solve(self.gram + 1e-12 * np.eye(self.n + self.m), self.cross)
        self.prev = x

    def predict(self, obs: np.ndarray, k: int) -> np.ndarray:
        """``x_hat_k`` for step ``k`` from the observation of that step."""
        self._learn(obs)
        x = obs[:, self.layout.state].astype(float)
        if self.d == 0:
            return x
        j = k - self.d
        if j < 0:
            return np.zeros_like(x)
        A_t, B_t = self.theta[:, : self.n, :], self.theta[:, self.n :, :]  # x_next^T = x^T A^T + u^T B^T
        for u in self.inputs[j:k]:
            x = np.einsum("ki,kij->kj", x, A_t) + np.einsum("ki,kij->kj", u, B_t)
        return np.clip(x, -self.x_bound, self.x_bound)

    def record(self, u: np.ndarray) -> None:
        self.inputs.append(np.asarray(u, dtype=float))


class _KeepsFeedback(Attacker):
    """What the additive and the sparse attacker share: the injection mode, ``Phi`` and the prediction."""

    modes: tuple[str, ...] = ("add", "replace")

    def __init__(self, params: AttackParams) -> None:
        super().__init__(params)
        if params.injection not in self.modes:
            raise ParameterError(f"the {self.name} attacker needs injection in {self.modes}, got injection={params.injection!r}")
        self.add = params.injection == "add"
        if not self.add and params.decipher_delay is None:
            raise ParameterError(
                f"the {self.name} attacker with injection='replace' forges Phi x from delivered states; "
                "decipher_delay='end' delivers none (use an integer delay or injection='add')"
            )
        self.needs_states = not self.add
        #: the controller, read from Enc(pk_0, Phi) with sk_0 (one more key than the samples)
        self.Phi = np.asarray(controller_matrix(params.loop), dtype=float)

    def _start(self, K: int) -> None:
        self._k = 0
        self._pred = None if self.add else StatePredictor(self, K)

    def _deviation(self, K: int) -> np.ndarray:
        """The excitation of this step, plant units, shape (K, m)."""
        raise NotImplementedError

    def _act(self, obs: np.ndarray) -> np.ndarray:
        d = self._deviation(obs.shape[0])
        if self.add:
            a = self.to_action(d)
        else:
            assert self._pred is not None
            x_hat = self._pred.predict(obs, self._k)
            a = np.clip(self.to_action(x_hat @ self.Phi.T + d), -1.0, 1.0)
            self._pred.record(a * self.params.u_max)
        self._k += 1
        return a

    def excitation_covariance(self) -> np.ndarray:
        """``Sigma_d``: the second moment of the white excitation per step, (m, m)."""
        raise NotImplementedError


class AdditiveAttacker(_KeepsFeedback):
    """``Phi x + d`` with white Gaussian ``d ~ N(0, sigma_d2 I)`` (module docstring).

    Parameters
    ----------
    params : AttackParams
        With ``injection`` ``"add"`` or ``"replace"`` (then an integer ``decipher_delay``).
    sigma_d2 : float, optional
        Excitation variance per input (plant units); default ``ratio * sigma_u2``.
    ratio : float, default 1e-3
        ``sigma_d2 / sigma_u2`` when ``sigma_d2`` is not given.
    """

    name = "additive"

    def __init__(self, params: AttackParams, sigma_d2: float | None = None, ratio: float = 1e-3) -> None:
        super().__init__(params)
        self.sigma_d2 = (
            check_positive("sigma_d2", sigma_d2) if sigma_d2 is not None else check_positive("ratio", ratio) * params.sigma_u2
        )
        self.name = f"additive({self.sigma_d2 / params.sigma_u2:.3g} sigma_u2)"

    def _deviation(self, K: int) -> np.ndarray:
        return math.sqrt(self.sigma_d2) * self.rng.standard_normal((K, self.params.m))

    def excitation_covariance(self) -> np.ndarray:
        return self.sigma_d2 * np.eye(self.params.m)


class SparseAttacker(_KeepsFeedback):
    """Honest on most steps; on a fraction ``q`` of them every input gets ``s level u_max``
    (``s`` a random sign per input): added to ``Phi x`` (``add``) or forged in its place (``replace``).

    Parameters
    ----------
    params : AttackParams
    q : float, default 0.05
        Probability that a step is injected, in (0, 1].
    level : float, default 1.0
        The injection's magnitude as a fraction of the input bound ``u_max``, in (0, 1].
    """

    name = "sparse"

    def __init__(self, params: AttackParams, q: float = 0.05, level: float = 1.0) -> None:
        super().__init__(params)
        self.q = _fraction("q", q)
        self.level = _fraction("level", level)
        self.name = f"sparse(q={self.q:g}, {self.level:g} u_max)"
        self.injected: np.ndarray = np.zeros(0, dtype=int)  # injected steps per copy (sized by _start)

    def _start(self, K: int) -> None:
        super()._start(K)
        self.injected = np.zeros(K, dtype=int)  # injected steps per copy
        self._hit = np.zeros(K, dtype=bool)

    def _deviation(self, K: int) -> np.ndarray:
        m = self.params.m
        self._hit = self.rng.random(K) < self.q
        self.injected += self._hit
        signs = 2.0 * self.rng.integers(0, 2, size=(K, m)) - 1.0
        return np.where(self._hit[:, None], self.level * self.params.u_max * signs, 0.0)

    def _act(self, obs: np.ndarray) -> np.ndarray:
        if self.add:
            return super()._act(obs)
        d = self._deviation(obs.shape[0])
        assert self._pred is not None
        x_hat = self._pred.predict(obs, self._k)
        u = np.where(self._hit[:, None], d, x_hat @ self.Phi.T)  # the injected steps forge the bound itself
        a = np.clip(self.to_action(u), -1.0, 1.0)
        self._pred.record(a * self.params.u_max)
        self._k += 1
        return a

    def excitation_covariance(self) -> np.ndarray:
        """``q (level u_max)^2 I`` (``add``; under ``replace`` the injected steps also drop ``Phi x``)."""
        return self.q * (self.level * self.params.u_max) ** 2 * np.eye(self.params.m)


class MalleabilityAttacker(Attacker):
    """The keyless malleable server (``injection="scale"``; module docstring).

    Parameters
    ----------
    params : AttackParams
        With ``injection="scale"`` (an ElGamal scheme).
    q : float, default 0.1
        Probability that a row is manipulated at a step, in (0, 1].
    """

    name = "malleability"

    def __init__(self, params: AttackParams, q: float = 0.1) -> None:
        super().__init__(params)
        if params.injection != "scale":
            raise ParameterError(f"the malleability attacker needs injection='scale', got injection={params.injection!r}")
        self.q = _fraction("q", q)
        #: the multiplier above one, from the public group (the attacker knows p)
        self.gain = scale_gain(params.loop.group())
        self.name = f"malleability(q={self.q:g}, c+={self.gain})"

    def _act(self, obs: np.ndarray) -> np.ndarray:
        K, m = obs.shape[0], self.params.m
        hit = self.rng.random((K, m)) < self.q
        up = self.rng.random((K, m)) < 1.0 / self.gain  # mean gain 1: P(c+) = 1/c+, P(0) = 1 - 1/c+
        return np.where(hit, np.where(up, SIGNAL, -SIGNAL), 0.0)

    @property
    def delta_second_moment(self) -> float:
        """``E[delta^2] = q (c+ - 1)`` of the gain deviation ``delta = c - 1`` per row and step."""
        return self.q * (self.gain - 1)


def _fraction(name: str, value: Any) -> float:
    v = check_probability(name, value)
    if v == 0.0:
        raise ParameterError(f"{name} must lie in (0, 1], got {value}")
    return v


#: The stealthy attackers by name (classes: ``STEALTH_ATTACKERS.build("sparse", params=p, q=0.02)``).
STEALTH_ATTACKERS: Registry[type[Attacker]] = Registry(
    "stealthy attacker",
    {"additive": AdditiveAttacker, "sparse": SparseAttacker, "malleability": MalleabilityAttacker},  # type: ignore[arg-type]
)
