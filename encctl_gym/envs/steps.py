"""The episode's numeric state and the three ways a step runs, one class each.

:class:`EpisodeArrays` and :class:`KernelConstants` hold, by name, what the compiled kernels of
:mod:`encctl_gym.envs._kernels` read and write; the kernels take them as plain tuples (numba
dispatches a plain tuple as fast as separate arguments), built once per episode by
:meth:`EpisodeArrays.kernel_tuple` and :meth:`KernelConstants.kernel_tuple` in the order the
kernels unpack them. Nothing reads those tuples by position outside the kernels.

A :class:`StepStrategy` runs the period of one attack step (energy budget, the input under the
injection mode of :mod:`encctl_gym.loop.injection`, plant, own-input history, collected state)
on a :class:`StepContext` (the episode's arrays, counters and closing operations, by public
name); the episode picks one when it is built (:func:`choose_step`), never per step:

* :class:`GenericStep`: the loop backend is called period by period (any backend, e.g. ElGamal);
* :class:`CompiledIdealStep`: the backend exposes its arithmetic
  (:attr:`~encctl_gym.loop.backend.LoopBackend.quantization`), and the period is one compiled call;
* :class:`FusedStep`: as :class:`CompiledIdealStep`, and the reward and the estimator have
  compiled forms too, so the steady state (every copy's recursion started, no exact refresh
  due) runs period, delivery, estimate, error, reward and observation in one compiled call.

The three compute the same numbers (tested): a strategy is a speed, not a semantics.
"""

from __future__ import annotations

from dataclasses import astuple, dataclass
from typing import Any, Protocol

import numpy as np

from ..errors import ParameterError
from ..loop.injection import PASS, REPLACE
from . import _kernels as kern

__all__ = [
    "EpisodeArrays",
    "KernelConstants",
    "StepContext",
    "StepStrategy",
    "GenericStep",
    "CompiledIdealStep",
    "FusedStep",
    "choose_step",
]


@dataclass(frozen=True)
class KernelConstants:
    """What the kernels read and never change (``consts`` of :mod:`encctl_gym.envs._kernels`).

    Attributes
    ----------
    A, B : numpy.ndarray
        The true plant of eq:system, C-contiguous.
    theta_true_T : numpy.ndarray, shape (n + m, n)
        ``[A B]^T``, against which Definition def:error scores the estimate.
    c : float
        ``n (n + m)``, the normaliser of Definition def:error.
    u_max : float
        The actuator bound of an action of 1.
    budget : float
        The input energy budget of the attack.
    """

    A: np.ndarray
    B: np.ndarray
    theta_true_T: np.ndarray
    c: float
    u_max: float
    budget: float

    def kernel_tuple(self) -> tuple[Any, ...]:
        """The fields as the kernels take them, in their order."""
        return astuple(self)


@dataclass(frozen=True, eq=False)
class EpisodeArrays:
    """The per-copy arrays the kernels write (``arrays`` of :mod:`encctl_gym.envs._kernels`);
    built once per episode and never rebound, so the kernel tuple stays valid.

    Attributes
    ----------
    x : (K, n)
        The plant's state.
    energy : (K,)
        Input energy spent.
    X : (N, K, n), U : (N, K, m)
        Collected (deciphered) states and applied inputs, time-major.
    hist : (K, H m)
        The agent's own last inputs, newest first.
    Q : (d (d + n), K)
        Recursive least squares ``[P | Theta_hat^T]``, copies innermost.
    eps : (K,)
        The error of every copy's current estimate.
    reward : (K,)
        The reward the fused step writes.
    a_buf : (K, m)
        The energy-limited (and, once forged, decoded) input of the current step.
    q_buf : (K, m) int64, qx_buf : (K, n) int64
        Encoded input and state of the current step.
    sc : (2 d + n + 2, K)
        Scratch of the steady-state recursion.
    """

    x: np.ndarray
    energy: np.ndarray
    X: np.ndarray
    U: np.ndarray
    hist: np.ndarray
    Q: np.ndarray
    eps: np.ndarray
    reward: np.ndarray
    a_buf: np.ndarray
    q_buf: np.ndarray
    qx_buf: np.ndarray
    sc: np.ndarray

    @classmethod
    def allocate(cls, K: int, n: int, m: int, horizon: int, history: int) -> EpisodeArrays:
        """Zeroed arrays for ``K`` copies of an ``n``-state, ``m``-input plant."""
        d = n + m
        return cls(
            x=np.zeros((K, n)),
            energy=np.zeros(K),
            X=np.zeros((horizon, K, n)),
            U=np.zeros((horizon, K, m)),
            hist=np.zeros((K, history * m)),
            Q=np.zeros((d * (d + n), K)),
            eps=np.zeros(K),
            reward=np.zeros(K),
            a_buf=np.zeros((K, m)),
            q_buf=np.zeros((K, m), dtype=np.int64),
            qx_buf=np.zeros((K, n), dtype=np.int64),
            sc=np.zeros((2 * d + n + 2, K)),
        )

    def kernel_tuple(self) -> tuple[np.ndarray, ...]:
        """The arrays as the kernels take them, in their order (the same objects, not copies)."""
        return tuple(getattr(self, name) for name in self.__dataclass_fields__)


class StepContext(Protocol):
    """What a step strategy reads and advances of its episode (:class:`~encctl_gym.envs.episode.EpisodeCore`,
    :class:`~encctl_gym.envs.output_episode.OutputEpisode`): the arrays and constants the kernels
    take, the loop backend, the progress counters and the few operations a period ends with. A
    strategy reads nothing else."""

    state: EpisodeArrays
    consts: KernelConstants
    kernel_consts: tuple[Any, ...]
    kernel_arrays: tuple[np.ndarray, ...]
    dims: Any
    loop: Any
    input_history: int
    collected: int
    delivered: int
    expired: bool
    new: bool
    kernels: Any
    helper: Any
    schedule: Any
    history: list[tuple[int, float]]
    gram_upto: int
    obs_shape: tuple[int, int]
    obs_at: tuple[int, int, int, int, int, int]
    time_frac: np.ndarray
    obs_out: np.ndarray | None

    def collect_next(self) -> None:
        """Collect (encrypt, pay for and decipher) the next state into ``X``."""

    def raise_overflow(self) -> None:
        """Raise the encoder's overflow for the current state."""

    def target_of(self, collected: int) -> int:
        """The samples delivered once ``collected`` are collected (the deciphering delay)."""

    def gram_behind(self, upto: int) -> None:
        """Catch the Gram matrices up to column ``upto`` (on the helper thread, if any)."""

    def finish_step(self, ended: bool) -> tuple[np.ndarray, bool, bool]:
        """Delivery, estimate and reward after the period."""


def backend_period(core: StepContext, act: np.ndarray, w: np.ndarray, ended: bool, injection: int) -> bool:
    """One period through the backend's own methods (any backend, any injection mode): energy
    budget, :meth:`~encctl_gym.loop.backend.LoopBackend.period_input`, plant, own-input history,
    key update, collected state. ``PASS`` injects nothing: no energy is spent and the own-input
    history takes zeros. Returns whether the attack has ended (:meth:`StepStrategy.period`)."""
    s, c = core.state, core.consts
    if injection == PASS:
        act[:] = 0.0
    kern.energy_budget(core.dims, act, c.u_max, s.energy, c.budget, s.a_buf)
    u = np.ascontiguousarray(core.loop.period_input(s.a_buf, s.x, injection), dtype=np.float64)
    s.U[core.collected - 1] = u
    kern.plant_step(core.dims, s.x, u, w, c.A, c.B)
    if core.input_history:
        kern.shift_history(core.dims, s.hist, act)
    core.loop.tick()
    if not ended:
        core.collect_next()
        ended = core.expired  # the measured clock passed tau_c: the attack is over now
    return ended


class StepStrategy:
    """How the period of one step runs (see the module docstring); bound to one episode.

    :meth:`step` is the whole step: the period (:meth:`period`), then the delivery, the
    estimate and the reward, which the episode does the same way for every strategy.
    """

    name = "step"

    def __init__(self, core: StepContext) -> None:
        self.core = core

    def period(self, act: np.ndarray, w: np.ndarray, ended: bool, injection: int = REPLACE) -> bool:
        """Apply the energy-limited input ``act`` under the injection mode (``REPLACE``: forged;
        :mod:`encctl_gym.loop.injection`) with noise ``w``; collect the next state unless ``ended``.
        Returns whether the attack has ended (``ended``, or the measured clock passed ``tau_c``
        in this period)."""
        raise NotImplementedError

    def step(self, act: np.ndarray, w: np.ndarray, ended: bool, injection: int = REPLACE) -> tuple[np.ndarray, bool, bool]:
        """The step: the period, then what follows it (:meth:`StepContext.finish_step`)."""
        core = self.core
        core.obs_out = None
        ended = self.period(act, w, ended, injection)
        return core.finish_step(ended)


class GenericStep(StepStrategy):
    """The backend called period by period (:meth:`~encctl_gym.loop.backend.LoopBackend.period_input`
    under any injection mode, :meth:`~encctl_gym.loop.backend.LoopBackend.tick`, then the state
    collected). ``PASS`` injects nothing: no energy is spent and the own-input history takes
    zeros."""

    name = "generic"

    def period(self, act: np.ndarray, w: np.ndarray, ended: bool, injection: int = REPLACE) -> bool:
        return backend_period(self.core, act, w, ended, injection)


class CompiledIdealStep(StepStrategy):
    """The period in one compiled call, on the loop's fixed-point arithmetic
    (:func:`encctl_gym.envs._kernels.step_ideal`)."""

    name = "compiled-ideal"

    def __init__(self, core: StepContext, quant: tuple[Any, ...]) -> None:
        super().__init__(core)
        self.quant = quant

    def period(self, act: np.ndarray, w: np.ndarray, ended: bool, injection: int = REPLACE) -> bool:
        if injection != REPLACE:  # another mode this step (the game's pass-through): the backend's own
            return backend_period(self.core, act, w, ended, injection)
        core = self.core
        status = kern.step_ideal(
            core.dims,
            core.kernel_consts,
            core.kernel_arrays,
            self.quant,
            act,
            w,
            core.collected - 1,
            -1 if ended else core.collected,
        )
        if status == kern.STATE_OVERFLOW:
            core.raise_overflow()
        if not ended:
            core.collected += 1
        return ended


class FusedStep(CompiledIdealStep):
    """:class:`CompiledIdealStep`, with the steady state in one compiled call
    (:func:`encctl_gym.envs._kernels.step_fused`): period, delivery by recursive least squares,
    error, reward and observation. Outside the steady state (the start, an exact refresh, the
    end) the step is that of :class:`CompiledIdealStep`."""

    name = "fused"

    def __init__(self, core: StepContext, quant: tuple[Any, ...], parallel: bool = False) -> None:
        super().__init__(core, quant)
        self._kernel = kern.step_fused_parallel if parallel else kern.step_fused
        if core.kernels is None:
            raise ParameterError("the fused step needs an estimator with fused kernels (online_kernels)")
        self.kernels = core.kernels

    def step(self, act: np.ndarray, w: np.ndarray, ended: bool, injection: int = REPLACE) -> tuple[np.ndarray, bool, bool]:
        core = self.core
        kernels = self.kernels
        if not (kernels.all_ready and not ended and injection == REPLACE):
            return super().step(act, w, ended, injection)
        first = max(core.delivered, 1)
        target = core.target_of(core.collected + 1)
        if kernels.since_refresh + target - first >= kernels.refresh:
            return super().step(act, w, ended, injection)
        new = target > core.delivered
        obs = np.empty(core.obs_shape, dtype=np.float32)
        N, collected = (target if new else core.delivered), core.collected + 1
        status = self._kernel(
            core.dims,
            core.kernel_consts,
            core.kernel_arrays,
            self.quant,
            act,
            w,
            core.collected - 1,
            core.collected,
            first,
            target,
            obs,
            core.obs_at,
            N - 1,
            float(new),
            float(core.time_frac[collected]),
        )
        if status == kern.STATE_OVERFLOW:
            core.raise_overflow()
        core.collected += 1
        core.new = new
        if new:
            kernels.since_refresh += target - first
            core.delivered = target
            core.history.append((target, float(core.state.eps[0])))
            if core.helper is not None and target - core.gram_upto >= core.schedule.gram_batch:
                core.gram_behind(target)
        core.obs_out = obs
        return core.state.reward.copy(), False, False


def choose_step(
    core: StepContext, quantization: Any, fused: bool, parallel: bool = False, injection: int = REPLACE
) -> StepStrategy:
    """The strategy of an episode, chosen once: :class:`FusedStep` when the backend exposes its
    arithmetic (``quantization``) and ``fused`` (the reward and the estimator have compiled
    steady states), :class:`CompiledIdealStep` with the arithmetic alone, :class:`GenericStep`
    otherwise, and for an episode whose injection mode is not ``REPLACE`` (the compiled period
    is the forgery's; the backend's :meth:`period_input` does the others)."""
    if quantization is None or injection != REPLACE:
        return GenericStep(core)
    quant = tuple(quantization)
    if fused:
        return FusedStep(core, quant, parallel)
    return CompiledIdealStep(core, quant)
