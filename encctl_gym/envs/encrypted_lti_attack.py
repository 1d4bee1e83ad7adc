"""``EncryptedLTIAttack-v0``: an identification attacker inside an encrypted control loop."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from .._validation import format_value
from ..errors import ParameterError
from ..loop import LoopBackend
from .builder import build_episode
from .config import AttackParams, default_config, resolve_params
from .episode import EpisodeCore
from .schedule import EpisodeSchedule

__all__ = ["EncryptedLTIAttackEnv", "reset_options", "check_seed"]

#: The keys ``reset(options=...)`` accepts (see :meth:`EpisodeCore.reset`).
RESET_OPTIONS = ("x0", "noise")


def check_seed(seed: Any) -> int | None:
    """A reset seed: ``None`` or a non-negative integer (not a bool)."""
    if seed is None:
        return None
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ParameterError(f"seed must be None or a non-negative integer, got {format_value(seed)}")
    return int(seed)


def reset_options(options: dict[str, Any] | None) -> dict[str, Any]:
    """The ``options`` of ``reset`` as keyword arguments of :meth:`EpisodeCore.reset`.

    Raises
    ------
    ParameterError
        For options that are not a dict or have keys other than ``x0`` and ``noise``.
    """
    if options is None:
        return {}
    if not isinstance(options, dict):
        raise ParameterError(f"reset options must be a dict, got {format_value(options)}")
    unknown = sorted(set(options) - set(RESET_OPTIONS))
    if unknown:
        raise ParameterError(f"unknown reset option(s) {format_value(unknown)}; known: {list(RESET_OPTIONS)}")
    return dict(options)


class EncryptedLTIAttackEnv(gym.Env):
    r"""An adversary identifying ``(A, B)`` of an encrypted control system.

    ## Description

    The plant ``x[t+1] = A x[t] + B u[t] + w[t]`` (eq:system) is controlled through the
    updatable homomorphic encryption of the paper (Teranishi & Kogiso, arXiv 2303.13059):
    dynamic-key ElGamal whose keys change every sampling period, with the *modified*
    evaluation/decryption of Definition def:modification so the controller server works without
    an update token (eq:ec). The agent is the adversary of Definition def:adversary: from the
    attack start ``t_s`` it injects ``u_t = a_t`` (its action), collects the state and input
    ciphertexts, pays computation time to break them and identifies ``(A, B)`` by least squares
    (eq:estimate). It sees decrypted data only once they have been paid for and delivered.

    Each collected sample costs ``2^lambda / Upsilon`` seconds of attacker computation
    (Definition def:sdt) under ``scheme="modified"`` (either adversary) and ``scheme="token"``
    with an eavesdropper; under ``"token"`` with a malicious server, and under ``"static"``
    keys, only the first sample costs anything (Proposition prop:vulnerability; Remark after
    Definition def:security). The budget is the defense period ``tau_c``.

    With ``crypto="elgamal"`` real ciphertexts go through the loop (keys updated every step;
    the injected input is forged from public keys only); with ``crypto="ideal"`` the same
    encode/quantize/decode arithmetic runs without big integers. For one seed both give the
    same trajectory bit for bit.

    ## Action Space

    ``Box(-1, 1, (m,), float32)``. The injected input is ``a_t = action * action_scale *
    sigma_u`` (an actuator bound of ``action_scale`` standard deviations), then held to an
    **energy budget**: over the episode ``sum_t ||a_t||^2 <= m sigma_u2 N`` (average power
    ``sigma_u2`` per channel, as in Theorem thm:sic). An input that would overdraw the remaining
    energy is scaled down to exhaust it exactly; afterwards inputs are zero. Every attacker is
    thus held to the same input energy over the attack. The budget covers the whole attack, so
    an attacker may front-load its energy: ``info["epsilon"]`` part-way through one attack
    compares attackers at unequal energy; to compare them at a sample size N, run attacks of
    length N (``agents.evaluate.budget_config``), as ``encctl-gym compare`` does. The energy
    used is ``info["input_energy"]``. Actions outside the box (beyond float32 rounding) or
    NaN raise :class:`~encctl_gym.errors.ParameterError`.

    | index | meaning                    | range   |
    |-------|----------------------------|---------|
    | 0..m-1| injected input / u_max      | [-1, 1] |

    ## Observation Space

    A flat ``float32`` vector of length ``n + m + 1 + H m + 2`` (``H = input_history``):

    | slice              | content                                                             |
    |--------------------|---------------------------------------------------------------------|
    | ``[0, n)``         | latest delivered decrypted state ``x_j`` (zeros before any)          |
    | ``[n, n+m)``       | delivered decrypted input ``u_{j-1}`` that led to ``x_j`` (zeros if none) |
    | ``n+m``            | 1.0 if a sample was delivered at this step, else 0.0                 |
    | next ``H m``       | the agent's own last ``H`` actions, newest first (action units)      |
    | ``-2``             | fraction of the deciphering budget ``tau_c`` spent                   |
    | ``-1``             | fraction of the input energy budget spent                            |

    Nothing not yet paid for and delivered ever enters the observation: with
    ``decipher_delay = d`` the state ``x_j`` appears at step ``j + d``; with ``"end"`` nothing
    is delivered before the attack ends (the agent knows only its own inputs). The layout is
    :class:`~encctl_gym.envs.layout.ObservationLayout` (slices, bounds, training modes). The
    same data in float64: ``env.unwrapped.episode.delivered_data()``.

    ## Rewards

    * ``reward="log_error"`` (default): the decrease of ``log epsilon`` (Definition def:error)
      of the least squares estimate on the delivered data against the true ``(A, B)``; before
      ``n + m`` regression columns the estimate is ``[A B] = 0``. The return telescopes to
      ``log epsilon_0 - log epsilon_final``.
    * ``reward="logdet"``: the increase of ``log det(G + delta I)`` of the regressor Gram
      matrix ``G`` of the delivered data, which an attacker can compute without ``(A, B)``
      (D-optimality).
    * ``reward="a_optimality"``: the decrease of ``log tr((G + delta I)^-1)`` (A-optimality):
      the log of the expected error of the current least-squares estimate given the delivered
      regressors, ``sigma_w2 tr(G^-1) / (n + m)``; low variance, computable without ``(A, B)``.

    ## Starting State

    ``x_0 ~ N(0, sigma_x2 I)``; with ``warmup_steps > 0`` the plant first runs under an
    encrypted LQR controller (eq:ec) and the attack starts from the state reached. The first
    sample (``x_{t_s}``) is collected and paid for at reset.

    ## Episode End

    ``terminated`` when the next sample can no longer be paid for within ``tau_c``: the
    deciphering budget is part of the environment's state (its spent fraction is observed) and
    no reward can follow, so this is a true terminal state. ``truncated`` when ``max_samples``
    ends the attack first: a cap from outside the attacker's problem. Without ``max_samples``, a
    budget that buys more than ``MAX_DEFAULT_HORIZON`` = 2^20 samples (short keys: 64 bits buy
    about 9e18) is capped there, with a warning when the environment is made
    (``params.horizon_capped``), and the episode is truncated at that length. Either way all paid
    samples are delivered in the final observation. ``N`` samples mean ``N`` actions.

    ## Arguments

    ``gymnasium.make("encctl_gym/EncryptedLTIAttack-v0", config={...}, render_mode=None,
    **overrides)``. See :func:`encctl_gym.envs.config.default_config` for every key
    (preset, A, B, variances, scheme, adversary, security_parameter or key_length, upsilon,
    tau_c, max_samples, decipher_delay, warmup_steps, reward, crypto, delta, ...).
    A plant of one's own, ``config={"A": A, "B": B}``, takes the values it does not give
    (variances, ``gamma_c``, ``tau_c``, ``upsilon``) from ``preset`` (default
    ``"paper-example"``) with a warning naming them; ``preset=None`` completes nothing, and
    every value must then be given (the same rule as ``encctl-gym train --system FILE``).
    ``schedule`` (:class:`~encctl_gym.envs.episode.EpisodeSchedule`) sets how the work is
    batched (noise chunks, exact-refresh period); the default is what the benchmarks measure.

    ``reset(seed=..., options={"x0": x0, "noise": w})`` replays a given initial state
    ``x0`` (n,) and process noise ``w`` (warmup_steps + horizon, n) instead of drawing them:
    the same disturbance for two attackers (common random numbers).

    ## Info

    | key                 | meaning                                                          |
    |---------------------|------------------------------------------------------------------|
    | ``epsilon``         | error (Definition def:error) of the least-squares estimate on the delivered data; before ``n + m`` regression columns that of the estimate ``[A B] = 0`` |
    | ``gamma``           | gamma(N) of eq:sic at the delivered N (``inf`` for N < 2)        |
    | ``gamma_opt``       | the optimal attack design's gamma at N (when ``gamma_opt=True``) |
    | ``samples_collected``, ``samples_delivered`` | N paid for, N delivered                 |
    | ``deciphering_time``| seconds of attacker computation spent (Definition def:sdt)       |
    | ``input_energy``, ``average_power`` | energy spent, and per input channel and step     |
    | ``detected``        | the defender stopped the attack (:mod:`encctl_gym.loop.defenses`) |
    | ``groups``, ``group_rotations``, ... | with group rotation only (``rotate_group_every``): the groups used, the encryptions and bytes re-provisioned, the group generation and wait seconds, and with a breaker its precomputations (:func:`encctl_gym.loop.rotation.rotation_info`) |

    **Privileged**: ``epsilon``, ``gamma`` and ``gamma_opt`` are functions of the true plant
    ``(A, B)`` (``epsilon`` from the start: at reset it is ``||[A B]||_F^2 / (n (n + m))``,
    even with ``decipher_delay="end"``), and so are ``env.unwrapped.params``, ``.design``,
    ``.episode`` and ``.loop`` (which holds the plant's keys). They are for training and
    evaluation, not something the attacker observes; an attacker acts on the observation only.

    ## Version History

    * v0: initial version.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(
        self,
        config: dict[str, Any] | None = None,
        render_mode: str | None = None,
        *,
        schedule: EpisodeSchedule | None = None,
        **kwargs: Any,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ParameterError(
                f"unknown render_mode {format_value(render_mode)}; choose one of {self.metadata['render_modes']}"
            )
        self.render_mode = render_mode
        built = build_episode(resolve_params(config, **kwargs), schedule=schedule)
        self.params: AttackParams = built.params
        p = self.params
        self._loop = built.loop
        self.action_space = spaces.Box(-1.0, 1.0, (p.m,), np.float32)
        self.observation_space = spaces.Box(*p.observation_bounds(), dtype=np.float32)
        self.design = built.design
        self._core: Any = built.core

    @staticmethod
    def default_config() -> dict[str, Any]:
        """The default configuration (see :func:`encctl_gym.envs.config.default_config`)."""
        return default_config()

    @property
    def loop(self) -> LoopBackend:
        """The closed loop backend (ideal or ElGamal) behind the plant's input (privileged)."""
        return self._loop

    @property
    def episode(self) -> EpisodeCore:
        """The episode's state (privileged: the true plant and undelivered data): ``done``,
        ``collected``, ``delivered``, ``delivered_data()``."""
        return self._core

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=check_seed(seed))
        obs = self._core.reset(self.np_random, **reset_options(options))
        return obs[0], self._core.info()

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        core = self._core
        reward, terminated, truncated = core.step(action)
        return core.observation()[0], float(reward[0]), terminated, truncated, core.info()

    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array":
            return None
        from .render import render_error_curve

        return render_error_curve(self._core, self.params, self.design)

    def close(self) -> None:
        """Release the episode's resources (a rotating defender's group pool, see :meth:`EpisodeCore.close`)."""
        self._core.close()
        super().close()
