"""Native batched vector environment for ``EncryptedLTIAttack-v0`` (ideal backend).

Steps ``num_envs`` copies at once through the same :class:`EpisodeCore` as the single
environment, in the compiled kernels of :mod:`encctl_gym.envs._kernels`. Copy ``i`` seeded by ``reset(seed=s)`` draws from ``np_random(s + i)``, as
gymnasium's ``SyncVectorEnv`` would seed it, so it reproduces a single environment reset with
``seed = s + i`` bit for bit. All copies share the horizon, so their episodes end together;
autoreset follows gymnasium's default next-step mode (the step after an episode ends resets
every copy and returns reward 0).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .._validation import check_int, format_value
from ..errors import ParameterError
from .builder import build_episode
from .config import AttackParams, resolve_params
from .encrypted_lti_attack import check_seed, reset_options
from .episode import EpisodeCore
from .helper import HelperThread
from .output_episode import OutputEpisode
from .schedule import EpisodeSchedule

__all__ = ["EncryptedLTIAttackVectorEnv"]


class EncryptedLTIAttackVectorEnv(VectorEnv):
    """``num_envs`` copies of :class:`~encctl_gym.envs.EncryptedLTIAttackEnv` stepped at once.

    Parameters
    ----------
    num_envs : int
        Number of copies.
    config, **kwargs
        As for the single environment; only ``crypto="ideal"`` is batched.
    parallel : bool, default False
        Spread the copies of the steady-state step over the cores (numba ``prange``). The
        numbers are identical. Only the compiled step is spread (the noise draws, the Gram
        catch-up and the Python around the step are not), so whether it pays depends on the
        machine: on the 2-core development machine it was slower than the default (which
        leaves the second core to the helper thread) in every run of
        ``benchmarks/bench_env.py``, hence off by default.
    helper_thread : bool or HelperThread, default True
        Draw the next chunk of noise and catch up the Gram matrices of the exact refresh on a
        helper thread while the copies are stepped (the compiled kernels release the GIL). The
        numbers are identical; ``False`` keeps all the work on the calling thread. A
        :class:`~encctl_gym.envs.helper.HelperThread` given here is used (and closed by
        :meth:`close`); ``True`` makes one of the environment's own.
    schedule : EpisodeSchedule, optional
        How the work is batched (see the single environment).
    memory_limit : int, optional
        Bytes the copies may allocate (default :data:`encctl_gym.resources.MEMORY_LIMIT`,
        8 GiB); a larger batch is refused before anything is allocated.

    ``info`` holds one array of shape ``(num_envs,)`` per key of the single environment's info
    (privileged keys as documented there). ``reset(options={"x0": (K, n), "noise": (K, T, n)})``
    replays given initial states and noise.
    """

    metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        num_envs: int = 1,
        config: dict[str, Any] | None = None,
        max_episode_steps: int | None = None,
        parallel: bool = False,
        helper_thread: bool | HelperThread = True,
        schedule: EpisodeSchedule | None = None,
        memory_limit: int | None = None,
        **kwargs: Any,
    ) -> None:
        self.num_envs = check_int("num_envs", num_envs, minimum=1)
        if max_episode_steps is not None:
            raise ParameterError(
                f"the attack length is set by tau_c or max_samples, not max_episode_steps (got {format_value(max_episode_steps)})"
            )
        if not isinstance(parallel, (bool, np.bool_)):
            raise ParameterError(f"parallel must be a bool, got {format_value(parallel)}")
        if not isinstance(helper_thread, (bool, np.bool_, HelperThread)):
            raise ParameterError(f"helper_thread must be a bool or a HelperThread, got {format_value(helper_thread)}")
        params = resolve_params(config, **kwargs)
        _check_vector(params)
        if isinstance(helper_thread, HelperThread):
            self.helper: HelperThread | None = helper_thread
        else:
            self.helper = HelperThread() if helper_thread else None
        built = build_episode(
            params, num_envs=self.num_envs, schedule=schedule, memory_limit=memory_limit, parallel=parallel, helper=self.helper
        )
        self.params: AttackParams = built.params
        p = self.params
        self.single_action_space = spaces.Box(-1.0, 1.0, (p.m,), np.float32)
        self.single_observation_space = spaces.Box(*p.observation_bounds(), dtype=np.float32)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.design = built.design
        self._core = built.core
        self._rngs: list[np.random.Generator] | None = None
        self._needs_reset = False

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        if seed is not None or self._rngs is None:
            if isinstance(seed, (list, tuple)):
                if len(seed) != self.num_envs:
                    raise ParameterError(f"expected {self.num_envs} seeds, got {len(seed)}")
                seeds = [check_seed(s) for s in seed]
            else:
                first = check_seed(seed)
                seeds = [None if first is None else first + i for i in range(self.num_envs)]
            self._rngs = [seeding.np_random(s)[0] for s in seeds]
            self._np_random, self._np_random_seed = seeding.np_random(seed if isinstance(seed, int) else None)
        obs = self._core.reset(self._rngs, **reset_options(options))
        self._needs_reset = False
        return obs, self._core.info_arrays()

    @property
    def episode(self) -> EpisodeCore | OutputEpisode:
        """The batched episode's state (privileged; see the single environment's ``episode``):
        an :class:`~encctl_gym.envs.output_episode.OutputEpisode` with ``observe="output"``."""
        return self._core

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if self._rngs is None:
            raise ParameterError("call reset() before step()")
        if self._needs_reset:  # next-step autoreset: every copy ended on the previous step
            obs, info = self.reset()
            zeros = np.zeros(self.num_envs, dtype=bool)
            return obs, np.zeros(self.num_envs), zeros, zeros.copy(), info
        reward, terminated, truncated = self._core.step(actions)
        self._needs_reset = terminated or truncated
        flags = np.zeros((2, self.num_envs), dtype=bool)  # the copies end together
        flags[0] = terminated
        flags[1] = truncated
        return self._core.observation(), reward, flags[0], flags[1], self._core.info_arrays()

    def close_extras(self, **kwargs: Any) -> None:
        self._core.close()
        if self.helper is not None:
            self.helper.close()


def _check_vector(p: AttackParams) -> None:
    """The vector environment's refusals: it batches the ideal backend (on states or outputs)."""
    if p.crypto != "ideal":
        raise ParameterError(f"the vector environment batches the ideal backend only, got crypto={format_value(p.crypto)}")
