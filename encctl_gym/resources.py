"""Bounds on what a call may allocate, checked before allocating.

Every place that sizes an allocation from user input estimates the bytes first and refuses too
much with :class:`~encctl_gym.errors.ResourceLimitError`, naming the estimate: the episode's
arrays here (:func:`check_memory`), the residue table in its own module
(:func:`encctl_gym.crypto.residue_table.residue_table_bytes`). A bad value is a clear error,
never a process killed for memory.
"""

from __future__ import annotations

from ._validation import check_int, format_value
from .errors import ResourceLimitError

__all__ = ["MEMORY_LIMIT", "check_memory"]

#: Default largest allocation (bytes) of one structure; pass ``limit`` to allow more.
MEMORY_LIMIT = 8 * 2**30


def check_memory(what: str, need: int, limit: int | None = None, advice: str = "") -> None:
    """Raise :class:`ResourceLimitError` if ``need`` bytes exceed ``limit`` (default :data:`MEMORY_LIMIT`).

    Parameters
    ----------
    what : str
        What would be allocated, with the values that size it (named in the message).
    need : int
        Estimated bytes.
    limit : int, optional
        Largest allowed bytes.
    advice : str
        How to make it smaller (appended to the message).
    """
    cap = MEMORY_LIMIT if limit is None else check_int("memory_limit", limit, minimum=1)
    if need > cap:
        msg = f"{what} needs about {_gib(need)} GiB, above the limit of {_gib(cap)} GiB (memory_limit)"
        raise ResourceLimitError(msg + (f"; {advice}" if advice else ""))


def _gib(nbytes: int) -> str:
    """``nbytes`` in GiB for a message, also beyond the float range (an estimate of 10^400 bytes)."""
    try:
        return f"{nbytes / 2**30:.3g}"
    except OverflowError:
        return format_value(int(nbytes) // 2**30)
