"""The attack episode of ``observe="output"``: the plant sends ``y = C x + v``, and so the attacker
deciphers outputs, never states.

The loop (:mod:`encctl_gym.loop.output_feedback`) runs on outputs: during the warm-up the encrypted
controller (a static output feedback or the dynamic LQG controller, ``controller=...``) computes
the input from the output ciphertexts; from the attack start the adversary forges the input
ciphertexts as in the state case. Per sampling period ``k`` of the attack (Definition
def:adversary, the same budget rules as :class:`~encctl_gym.envs.episode.EpisodeCore`):

1. the plant measures ``y_k = C x_k + v_k`` (``v_k ~ N(0, sigma_v2 I)``, drawn by the plant from
   the copy's generator after the process noise of that period) and encrypts it; the
   adversary collects and pays for the ciphertext (``2^lambda / Upsilon`` seconds, Definition
   def:sdt, under the same schedule and delay as the state case);
2. delivered outputs, with the attacker's own inputs, feed its online estimator
   (:func:`~encctl_gym.ident.output_estimators.output_estimator` of the ``estimator`` key):
   ``"ls"``, **least squares on an ARX model** ``y[t] = sum_{k<=q} a_k y[t-k] + b_k u[t-k]``
   with ``q = ceil(n / p) + 1`` lags (enough for a plant of order ``n``;
   :func:`~encctl_gym.ident.subspace.arx` on the delivered data, kept online as the Gram matrix
   of its regressors and solved exactly at each delivery once it has full rank), or the
   subspace methods ``"n4sid"`` and ``"moesp"`` at the plant's order ``n``, refitted on all the
   delivered data at each delivery (``O(N)`` work a delivery);
3. the agent acts under the energy budget, the plant decrypts and applies the forged input.

``epsilon`` (``info``, privileged) is the **Markov-parameter error**
(:func:`~encctl_gym.ident.subspace.markov_error`, ``L = MARKOV_LENGTH``) of the estimate against
the true ``(A, B, C, 0)``; the estimate ``0`` (``epsilon = 1``) until the estimator has one (ARX:
the scaled Gram matrix of the regressors has a condition number below :data:`COND_LIMIT`; the
subspace methods: enough samples for their windows), and a copy whose fit fails keeps its
previous ``epsilon``.
The reward ``log_error`` is its decrease, ``log epsilon_{k-1} - log epsilon_k``: the basis-free
error replaces Definition def:error, which needs the state. ``gamma`` and ``gamma_opt`` stay
those of the state-measured attack (eq:sic and the optimal design), as references.

The observation is the layout of :class:`~encctl_gym.envs.layout.ObservationLayout` with ``p``
in place of ``n``: ``[y_j | u_{j-1} | new | own inputs | time fraction | energy fraction]``.
Nothing of the state enters it: the plant side hands the loop ``y`` only.

Scope: copies are batched (``K`` generators; the vector environment steps them); only the fixed
defender (the others act on states), the ``log_error`` reward and the estimators on outputs
(ARX least squares, N4SID, PO-MOESP) are available with outputs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .._validation import as_finite_array, format_value
from ..errors import ParameterError, ShapeError
from ..ident.output_estimators import ARX_COND_LIMIT, output_estimator
from ..loop.output_feedback import CONTROLLERS, OutputLoop, loop_controller
from . import _kernels as kern
from .layout import ObservationLayout, info_dict

__all__ = ["OBSERVE", "MARKOV_LENGTH", "OutputEpisode", "resolve_output"]

#: What the plant sends and the attacker deciphers (the environment's ``observe`` key).
OBSERVE: tuple[str, ...] = ("state", "output")
#: ``L`` of the Markov-parameter error behind ``epsilon`` with outputs.
MARKOV_LENGTH = 20
#: A copy's ARX estimate is taken once the condition number of its regressors' Gram matrix,
#: scaled to unit diagonal, is below this (:data:`encctl_gym.ident.output_estimators.ARX_COND_LIMIT`).
COND_LIMIT = ARX_COND_LIMIT


def resolve_output(
    cfg: Mapping[str, Any], preset: Any, A: np.ndarray, B: np.ndarray, *, estimator: Any, reward: str, defender: Any
) -> dict[str, Any]:
    """The checked ``observe``, ``C``, ``sigma_v2`` and ``controller`` of a configuration
    (keyword arguments of :class:`~encctl_gym.envs.config.AttackParams`).

    With ``observe="state"`` the state is sent (a preset's ``C`` is not used) and giving ``C`` or
    ``sigma_v2`` is an error. With ``"output"``: ``C`` and ``sigma_v2`` from the configuration,
    else the preset's, else ``C = I`` and ``sigma_v2 = 0``; checked by :class:`~encctl_gym.plant.Plant`
    (shape, observability of ``(A, C)``, ``sigma_v2 >= 0``).

    Raises
    ------
    ParameterError
        As above, and for an estimator other than ``"ls"``, a reward other than ``"log_error"``
        or a defender other than ``"fixed"`` with outputs.
    """
    from ..plant import Plant

    observe = cfg["observe"]
    if not isinstance(observe, str) or observe not in OBSERVE:
        raise ParameterError(f"unknown observe {format_value(observe)}; choose one of {', '.join(OBSERVE)}")
    if observe == "state":
        given = [k for k in ("C", "sigma_v2") if cfg[k] is not None]
        if given:
            raise ParameterError(
                f"{', '.join(given)} given with observe='state': the plant sends outputs only with observe='output'"
            )
        return {}
    C = cfg["C"] if cfg["C"] is not None else getattr(preset, "C", None)
    sv = cfg["sigma_v2"] if cfg["sigma_v2"] is not None else getattr(preset, "sigma_v2", 0.0)
    plant = Plant(A, B, C=np.eye(A.shape[0]) if C is None else C, sigma_v2=sv)
    controller = cfg["controller"]
    if not isinstance(controller, str) or controller not in CONTROLLERS:
        raise ParameterError(f"unknown controller {format_value(controller)}; choose one of {', '.join(CONTROLLERS)}")
    output_estimator(estimator)  # ARX least squares, N4SID or PO-MOESP; any other is refused here
    if reward != "log_error":
        raise ParameterError(f"with observe='output' the reward is 'log_error' (of the Markov-parameter error), got {reward!r}")
    if not (isinstance(defender, str) and defender == "fixed"):
        raise ParameterError(f"with observe='output' only the fixed defender is available, got {format_value(defender)}")
    for key in ("audit_probability", "defense_noise_sigma2", "rotate_group_every"):
        if cfg.get(key) is not None:
            raise ParameterError(
                f"with observe='output' only the fixed defender is available, got {key} = {format_value(cfg[key])}"
            )
    return {"observe": "output", "C": plant.C, "sigma_v2": plant.sigma_v2, "controller": controller}


class OutputEpisode:
    """K attack episodes on a plant measured through outputs (module docstring), in lockstep.

    The same interface as :class:`~encctl_gym.envs.episode.EpisodeCore` for the environment:
    :meth:`reset`, :meth:`step`, :meth:`observation`, :meth:`info`, :meth:`delivered_data`,
    :meth:`close`, :attr:`done`, :attr:`collected`, :attr:`delivered`, :attr:`eps`.
    """

    def __init__(self, params: Any, loop: Any, design: Any = None, num_envs: int = 1, defender: Any = None) -> None:
        p = self.p = params
        self.defender = defender
        if params.C is None:
            raise ParameterError("OutputEpisode needs observe='output' parameters (C is None)")
        self.K = K = int(num_envs)
        if K > 1 and not loop.batched:
            raise ParameterError(f"the {p.crypto} backend steps one copy, got num_envs = {K}")
        self.loop = loop
        self.controller = loop_controller(p.loop)
        self.closed_loop = OutputLoop(loop, self.controller)
        n, m = p.n, p.m
        self.n, self.m = n, m
        self.C = np.asarray(p.C)
        self.p_out = q = int(self.C.shape[0])
        self._A, self._B = np.ascontiguousarray(p.A), np.ascontiguousarray(p.B)
        self._sw, self._sv, self._sx = math.sqrt(p.sigma_w2), math.sqrt(p.sigma_v2), math.sqrt(p.sigma_x2)
        self.layout = ObservationLayout(q, m, p.input_history)
        self.dims = kern.dims(n, m, p.input_history * m)
        self.estimator = output_estimator(p.estimator)
        self.lags = -(-n // q) + 1  # the ARX estimator's lags (its regressors)
        self._true = (p.A, p.B, self.C, np.zeros((q, m)))
        N = p.horizon
        self.Y = np.zeros((N, K, q))
        self.U = np.zeros((N, K, m))
        self.x = np.zeros((K, n))
        self.energy = np.zeros(K)
        self.hist = np.zeros((K, p.input_history * m))
        self._act = np.zeros((K, m))
        self._a = np.zeros((K, m))
        self.eps = np.ones(K)
        Ns = np.arange(N + 1)
        self._gamma = np.full(N + 1, np.inf)
        self._gamma[2:] = p.gamma(Ns[2:])
        self.has_gamma_opt = design is not None
        self._gamma_opt = np.full(N + 1, np.inf)
        if design is not None:
            self._gamma_opt[2:] = design.gamma(Ns[2:])
        self._time = np.asarray(p.deciphering_time(Ns), dtype=np.float64)
        self._rngs: list[np.random.Generator] = []
        self._given_noise: np.ndarray | None = None
        self._period = 0
        self.collected = self.delivered = 0
        self.new = False
        self.done = False
        self.stopped = False
        self.history: list[tuple[int, float]] = []

    # ----------------------------------------------------------------- randomness and the plant
    def _given(self, name: str, value: Any, shape: tuple[int, ...]) -> np.ndarray:
        arr = as_finite_array(name, value)
        if self.K == 1 and arr.shape == shape[1:]:
            arr = arr[None]
        if arr.shape != shape:
            raise ShapeError(f"{name} must have shape {shape[1:] if self.K == 1 else shape}, got {arr.shape}")
        return np.array(arr, dtype=np.float64)

    def _noise(self) -> tuple[np.ndarray, np.ndarray]:
        """The process noise ``w`` and measurement noise ``v`` of the current period, per copy."""
        t = self._period
        self._period += 1
        if self._given_noise is not None:
            w = self._given_noise[:, t]
        else:
            w = np.stack([g.standard_normal(self.n) * self._sw for g in self._rngs])
        v = np.stack([g.standard_normal(self.p_out) * self._sv for g in self._rngs])
        return w, v

    def _measure(self, v: np.ndarray) -> np.ndarray:
        """``y = C x + v``: what the plant's sensors read (and encrypt)."""
        return self.x @ self.C.T + v

    # ----------------------------------------------------------------- reset
    def reset(self, rng: np.random.Generator | Sequence[np.random.Generator], *, x0: Any = None, noise: Any = None) -> np.ndarray:
        """New episodes; draws per copy in a fixed order: ``x_0``, then each period ``w`` and ``v``."""
        rngs = [rng] if isinstance(rng, np.random.Generator) else list(rng)
        if len(rngs) != self.K:
            raise ParameterError(f"expected {self.K} random generators, got {len(rngs)}")
        x0_arr = None if x0 is None else self._given("x0", x0, (self.K, self.n))
        T = self.p.warmup_steps + self.p.horizon
        self._given_noise = None if noise is None else self._given("noise", noise, (self.K, T, self.n))
        self._rngs = rngs
        self._period = 0
        for i, g in enumerate(rngs):
            draw = g.standard_normal(self.n) * self._sx
            self.x[i] = draw if x0_arr is None else x0_arr[i]
        self.closed_loop.start(self.K)
        for _ in range(self.p.warmup_steps):  # normal operation on outputs (loop.output_feedback)
            w, v = self._noise()
            u = self.closed_loop.control(self._measure(v))
            kern.plant_step(self.dims, self.x, u, w, self._A, self._B)
        self.Y[:] = 0.0
        self.U[:] = 0.0
        self.estimator.start_outputs(self.K, self.n, self.p_out, self.m)
        self.energy[:] = 0.0
        self.hist[:] = 0.0
        self.eps[:] = 1.0
        self.collected = self.delivered = 0
        self.done = self.stopped = False
        self.history = []
        self._wv = self._noise()  # the first attack period's (w, v): its v is measured now
        self.collect_next()
        self.new = self._deliver(final=False)
        return self.observation()

    # ----------------------------------------------------------------- the attack
    def collect_next(self) -> None:
        """The plant encrypts ``y_k``; the adversary collects and pays for it (``Dcd(Ecd(y_k))``)."""
        self.Y[self.collected] = self.closed_loop.collect(self._measure(self._wv[1]))
        self.collected += 1

    def _deliver(self, final: bool) -> bool:
        delay = self.p.decipher_delay
        target = self.collected if final else (0 if delay is None else max(self.collected - delay, 0))
        if target <= self.delivered:
            return False
        self.delivered = target
        self._estimate()
        self.history.append((self.delivered, float(self.eps[0])))
        return True

    def _estimate(self) -> None:
        """``epsilon`` of the estimator's estimate on the delivered data, where it has one."""
        if not self.estimator.deliver_outputs(self.Y, self.U, self.delivered):
            return
        err = self.estimator.output_error(self._true, MARKOV_LENGTH)
        ok = np.isfinite(err)
        self.eps[ok] = err[ok]

    def check_actions(self, action: Any) -> np.ndarray:
        """Actions of shape (K, m) (or (m,) for K = 1), finite, inside [-1, 1], as float64."""
        try:
            a = np.asarray(action, dtype=np.float64)
        except (TypeError, ValueError):
            raise ParameterError(f"action must be a real numeric array, got {format_value(action)}") from None
        a = a.reshape(1, -1) if a.ndim < 2 else a
        if a.shape != (self.K, self.m):
            raise ParameterError(
                f"action must have shape {(self.m,) if self.K == 1 else (self.K, self.m)}, got {np.shape(action)}"
            )
        code = kern.load_actions(a, self._act)
        if code:
            raise ParameterError(
                f"action must be {'finite' if code == 1 else 'inside the action space [-1, 1]'}, got {a.tolist()}"
            )
        return self._act

    def step(self, action: Any) -> tuple[np.ndarray, bool, bool]:
        """One attack period. Returns (rewards (K,), terminated, truncated)."""
        if not self._rngs:
            raise ParameterError("step() called before reset(); call reset() first")
        if self.done:
            raise ParameterError("step() called after the episode ended; call reset() first")
        act = self.check_actions(action)
        ended = self.collected >= self.p.horizon
        w = self._wv[0]
        kern.energy_budget(self.dims, act, self.p.u_max, self.energy, self.p.energy_budget, self._a)
        u = self.closed_loop.inject(self._a)
        self.U[self.collected - 1] = u
        kern.plant_step(self.dims, self.x, u, w, self._A, self._B)
        if self.p.input_history:
            kern.shift_history(self.dims, self.hist, act)
        self.loop.tick()
        if not ended:
            self._wv = self._noise()
            self.collect_next()
        before = np.log(self.eps)
        self.new = self._deliver(final=ended)
        reward = before - np.log(self.eps)
        self.done = ended
        return reward, ended and self.p.budget_limited, ended and not self.p.budget_limited

    def close(self) -> None:
        """Release the defender's resources (its ``close``; the fixed defender holds none), as
        :meth:`EpisodeCore.close <encctl_gym.envs.episode.EpisodeCore.close>`. Idempotent."""
        if self.defender is not None:
            self.defender.close()

    # ----------------------------------------------------------------- what the attacker sees
    def delivered_data(self) -> tuple[np.ndarray, np.ndarray]:
        """Delivered outputs ``(K, N, p)`` and the inputs ``(K, max(N - 1, 0), m)`` that led to them."""
        N = self.delivered
        return self.Y[:N].transpose(1, 0, 2).copy(), self.U[: max(N - 1, 0)].transpose(1, 0, 2).copy()

    def observation(self) -> np.ndarray:
        """``[y_j | u_{j-1} | new | own inputs | time fraction | energy fraction]`` (K, dim), float32."""
        lay, j = self.layout, self.delivered - 1
        obs = np.zeros((self.K, lay.dim))
        if j >= 0:
            obs[:, lay.state] = self.Y[j]
        if j >= 1:
            obs[:, lay.input] = self.U[j - 1]
        obs[:, lay.flag] = float(self.new)
        obs[:, lay.history] = self.hist
        obs[:, lay.time_fraction] = self._time[self.collected] / self.p.tau_c
        obs[:, lay.energy_fraction] = self.energy / self.p.energy_budget
        return obs.astype(np.float32)

    def _shared(self) -> tuple[float, float, float, float, int, int]:
        c, N = self.collected, self.delivered
        return (float(self._gamma[N]), float(self._time[c]), float(max(c, 1) * self.m), float(self._gamma_opt[N]), c, N)

    def info(self) -> dict[str, Any]:
        """Info of copy 0 (``epsilon``: the Markov-parameter error of the ARX estimate, privileged)."""
        return info_dict(float(self.eps[0]), float(self.energy[0]), self._shared(), self.has_gamma_opt)

    def info_arrays(self) -> dict[str, np.ndarray]:
        """Info of every copy as arrays of shape (K,)."""
        return info_dict(self.eps.copy(), self.energy.copy(), self._shared(), self.has_gamma_opt, self.K)
