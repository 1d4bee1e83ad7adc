"""A helper thread owned by an environment: work that no step waits for runs beside the step.

The native vector environment hands two kinds of work to it (see
:class:`~encctl_gym.envs.episode.EpisodeCore`): drawing the next chunk of process noise, and
bringing the Gram matrices up to date for the next exact refresh. The compiled kernels release
the GIL, so on a machine with a spare core this work is free. It changes where the work runs,
never what it computes.

Lifecycle: the thread starts on the first :meth:`HelperThread.submit` and stops at
:meth:`HelperThread.close` (the environment's ``close``), or when the object is garbage
collected. After ``os.fork`` the child holds the object but not its thread: the next ``submit``
in the child starts a new one (the process id is checked under the lock). Pickling and deep
copies give a helper that has not started (a thread cannot be copied).
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

__all__ = ["HelperThread"]


class HelperThread:
    """One worker thread with its own lock, started on first use.

    Parameters
    ----------
    name : str
        Prefix of the thread's name (shown by debuggers and ``threading.enumerate()``).
    """

    def __init__(self, name: str = "encctl-gym-helper") -> None:
        self.name = name
        self._lock = threading.Lock()
        self._pool: ThreadPoolExecutor | None = None
        self._pid = os.getpid()

    @property
    def started(self) -> bool:
        """True if the thread of this process is running."""
        return self._pool is not None and self._pid == os.getpid()

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future:
        """Run ``fn(*args)`` on the thread; return its future (its exception is re-raised by ``result()``)."""
        if self._pid != os.getpid():  # forked child: the parent's thread is not ours
            self._lock = threading.Lock()
            self._pool = None
            self._pid = os.getpid()
        with self._lock:
            if self._pool is None:
                self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix=self.name)
            return self._pool.submit(fn, *args)

    def close(self, wait: bool = True) -> None:
        """Stop the thread (after the work already submitted, if ``wait``); a later submit starts a new one."""
        with self._lock:
            pool, self._pool = self._pool, None
        if pool is not None and self._pid == os.getpid():
            pool.shutdown(wait=wait)

    def __getstate__(self) -> dict[str, Any]:
        return {"name": self.name}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(state["name"])  # type: ignore[misc]

    def __del__(self) -> None:
        pool = getattr(self, "_pool", None)
        if pool is not None and getattr(self, "_pid", None) == os.getpid():
            pool.shutdown(wait=False)

    def __repr__(self) -> str:
        return f"HelperThread(name={self.name!r}, started={self.started})"
