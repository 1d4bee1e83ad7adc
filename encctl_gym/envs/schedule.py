"""What an episode costs before it runs: how it batches its work (:class:`EpisodeSchedule`) and
the memory it allocates (:func:`episode_bytes`, :func:`check_episode_memory`, checked before
anything is sized by the parameters)."""

from __future__ import annotations

from dataclasses import dataclass

from .._validation import check_int, check_positive, format_value
from ..resources import check_memory
from .config import AttackParams
from .layout import ObservationLayout

__all__ = ["EpisodeSchedule", "episode_bytes", "check_episode_memory"]


@dataclass(frozen=True)
class EpisodeSchedule:
    """How the episode batches its work (the numbers do not depend on ``chunk`` or
    ``gram_batch``; ``refresh`` and ``cond_limit`` set when the exact solve re-anchors the recursion).

    Attributes
    ----------
    chunk : int
        Noise is drawn from each copy's generator in chunks of this many periods.
    refresh : int
        Every copy's recursive least squares is re-anchored to the exact solve after this many columns.
    cond_limit : float
        A copy starts its recursion once the condition number of its scaled Gram matrix is below this.
    gram_batch : int
        With a helper thread, the Gram catch-up is handed over once it lags this many columns.
    """

    chunk: int = 256
    refresh: int = 1024
    cond_limit: float = 1e8
    gram_batch: int = 64

    def __post_init__(self) -> None:
        check_int("chunk", self.chunk, minimum=1)
        check_int("refresh", self.refresh, minimum=1)
        check_positive("cond_limit", self.cond_limit)
        check_int("gram_batch", self.gram_batch, minimum=1)


def episode_bytes(params: AttackParams, num_envs: int, schedule: EpisodeSchedule | None = None) -> int:
    """Bytes an episode of ``num_envs`` copies allocates (an estimate with a 5 % margin).

    The data of the attack (states and inputs of the horizon), the running least squares, the
    noise chunks, the per-copy generators and the tables over the sample size. Without the margin
    this sum is within 0.5 % of the measured peak (growth of VmHWM over a warm process) of the
    vector environment of the paper-example preset at 500, 2000 and 10000 copies (0.234, 0.934
    and 4.667 GiB against 0.233, 0.937 and 4.689 GiB); the margin of 5 % covers that and the
    allocator's slack, so work that fits is not refused (a margin of a half refused 10000 copies
    under a 6 GiB address-space limit although they peak at 5.3 GiB).
    """
    sch = schedule if schedule is not None else EpisodeSchedule()
    n, m, N, K = params.n, params.m, params.horizon, int(num_envs)
    d, H = n + m, params.input_history
    per_copy = (
        N * d  # X, U
        + 2 * d * (d + n)  # GC, Q
        + 3 * d
        + 2 * n
        + 2  # scratch
        + 3 * sch.chunk * n  # noise: drawn, in use, ahead
        + H * m
        + 4 * m
        + 2 * n
        + 8  # history, actions and buffers, energy, eps, reward
        + (ObservationLayout.of(params).dim + 8 * 2) // 2  # observation (float32) and info per step
    )
    generators = 2048  # a numpy Generator with its bit generator, per copy
    tables = 4 * (N + 1)
    return 21 * (8 * (K * per_copy + tables) + K * generators) // 20  # integers: exact for any K


def check_episode_memory(
    params: AttackParams, num_envs: int, schedule: EpisodeSchedule | None = None, memory_limit: int | None = None
) -> None:
    """Refuse an episode whose :func:`episode_bytes` exceed ``memory_limit`` (default
    :data:`encctl_gym.resources.MEMORY_LIMIT`), before anything is allocated."""
    p = params
    check_memory(
        f"an episode of num_envs = {format_value(num_envs)} copies, horizon N = {p.horizon}, n = {p.n}, m = {p.m}, "
        f"input_history = {p.input_history}",
        episode_bytes(p, num_envs, schedule),
        memory_limit,
        "the estimate includes a 5 % margin over the arrays' sizes; use fewer copies, a shorter attack (max_samples) "
        "or a shorter input_history",
    )
