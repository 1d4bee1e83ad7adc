"""One line on stderr before numba compiles the package's kernels, so that a first run is never silent.

The kernels (:mod:`encctl_gym.envs._kernels`, :mod:`encctl_gym.ident._moment_kernels`,
:mod:`encctl_gym.ident._rls_kernels`, :mod:`encctl_gym.loop.quantize`,
:mod:`encctl_gym.cryptanalysis.lattice_sieve`) are compiled on first use and cached on disk
(``cache=True``); the first run after an install, or after numba's cache is gone, compiles them.
Measured on a 2-core machine with an empty ``NUMBA_CACHE_DIR``: ``encctl-gym compare --quick``
took 17.7 s of CPU against 7.3 s with the cache (about 10 s of compiling); 400 steps of a
parallel vector environment of 1024 copies (``gym.make_vec(..., parallel=True)``, whose fused
prange step compiles on its first steady-state step) took 22.5 s of CPU against 2.3 s (about 20 s).

Each kernel module calls :func:`install_compile_notice` at import. It registers a listener on
numba's ``numba:compile`` event, which numba raises only when a function is about to be compiled
(after a cache miss, never when the cache is loaded). The listener prints one line the first time
in the process that a serial kernel compiles, and one more the first time a parallel one does
(``parallel=True``, the vector environment's prange step). ``ENCCTL_GYM_JIT_NOTICE=0`` silences it
(the test suite sets it, so that no test's captured stderr depends on the state of the cache).
"""

from __future__ import annotations

import os
import sys
from typing import Any

__all__ = ["NOTICE_ENV", "install_compile_notice", "notice_text"]

#: The environment variable that silences the notice when ``"0"``.
NOTICE_ENV = "ENCCTL_GYM_JIT_NOTICE"

_state: dict[str, Any] = {"installed": False, "announced": set()}


def notice_text(parallel: bool) -> str:
    """The line printed before the first compile of a serial (or a parallel) kernel."""
    if parallel:
        return (
            "encctl-gym: compiling the parallel vector step with numba (first use after an install: about 20 s of CPU "
            "measured on a 2-core machine; cached afterwards) ..."
        )
    return (
        "encctl-gym: compiling numba kernels (first run after an install: about 10 s of CPU measured on a 2-core "
        "machine; cached afterwards) ..."
    )


def _on_compile(dispatcher: Any) -> None:
    if os.environ.get(NOTICE_ENV, "1").strip() == "0":
        return
    module = str(getattr(getattr(dispatcher, "py_func", None), "__module__", ""))
    if not module.startswith("encctl_gym."):
        return  # someone else's function: not ours to announce
    parallel = bool(getattr(dispatcher, "targetoptions", {}).get("parallel"))
    kind = "parallel" if parallel else "serial"
    if kind in _state["announced"]:
        return
    _state["announced"].add(kind)
    print(notice_text(parallel), file=sys.stderr, flush=True)


def install_compile_notice() -> None:
    """Register the listener once per process (every kernel module calls this at import)."""
    if _state["installed"]:
        return
    from numba.core import event

    class _Notice(event.Listener):
        def on_start(self, ev: Any) -> None:
            data = ev.data if isinstance(ev.data, dict) else {}
            _on_compile(data.get("dispatcher"))

        def on_end(self, ev: Any) -> None:
            pass

    event.register("numba:compile", _Notice())
    _state["installed"] = True
