"""Bounds on what a call may allocate, checked before allocating.

Every place that sizes an allocation from user input estimates the bytes first and refuses too
much with :class:`~encctl_gym.errors.ResourceLimitError`, naming the estimate: the episode's
arrays here (:func:`check_memory`), the residue table in its own module
(:func:`encctl_gym.crypto.residue_table.residue_table_bytes`). A bad value is a clear error,
never a process killed for memory.

The default bound is :data:`MEMORY_LIMIT`, lowered to the address space the process may still
map when it runs under a limit (``ulimit -v``, ``RLIMIT_AS``: :func:`memory_headroom`), so an
allocation that would end in ``MemoryError`` is refused with its estimate instead.
"""

from __future__ import annotations

import math
import resource
from pathlib import Path

from ._validation import check_int
from .errors import ResourceLimitError

__all__ = ["MEMORY_LIMIT", "check_memory", "memory_headroom", "default_memory_limit", "format_bytes"]

#: Default largest allocation (bytes) of one structure; pass ``limit`` to allow more.
MEMORY_LIMIT = 8 * 2**30


def memory_headroom() -> int | None:
    """Bytes of address space this process may still map under its ``RLIMIT_AS`` soft limit
    (``None`` when there is no such limit, or it cannot be read)."""
    try:
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    except (OSError, ValueError):  # pragma: no cover - platforms without RLIMIT_AS
        return None
    if soft == resource.RLIM_INFINITY:
        return None
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmSize:"):
                return max(0, soft - int(line.split()[1]) * 1024)
    except OSError:  # pragma: no cover - no /proc
        return None
    return None  # pragma: no cover


def default_memory_limit() -> int:
    """:data:`MEMORY_LIMIT`, or less when :func:`memory_headroom` is smaller."""
    room = memory_headroom()
    return MEMORY_LIMIT if room is None else min(MEMORY_LIMIT, room)


def format_bytes(n: int | float) -> str:
    """A memory size in the most readable unit (``"512 MiB"``, ``"2.79e+06 GiB"``); an integer of
    any size (``10**400`` bytes is ``"10^400 bytes"``, rounded to a power of ten: an estimate
    beyond the float range)."""
    if isinstance(n, int) and n.bit_length() > 1000:
        return f"10^{(n.bit_length() - 1) * math.log10(2):.0f} bytes"
    v = float(n)
    for unit, size in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if v >= size:
            return f"{v / size:.3g} {unit}"
    return f"{v:.0f} bytes"


def check_memory(what: str, need: int, limit: int | None = None, advice: str = "") -> None:
    """Raise :class:`ResourceLimitError` if ``need`` bytes exceed ``limit`` (default
    :func:`default_memory_limit`: :data:`MEMORY_LIMIT`, or the address space left under a limit).

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
    if limit is None:
        cap = default_memory_limit()
        which = "memory_limit" if cap == MEMORY_LIMIT else "the address space left under this process's limit"
    else:
        cap, which = check_int("memory_limit", limit, minimum=1), "memory_limit"
    if need > cap:
        msg = f"{what} needs about {format_bytes(need)}, above the limit of {format_bytes(cap)} ({which})"
        raise ResourceLimitError(msg + (f"; {advice}" if advice else ""))
