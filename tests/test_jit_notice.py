"""No silent start (issue 35 item 3): one line on stderr before numba compiles a kernel of the
package, nothing when the kernel comes from the cache, nothing for someone else's function."""

from __future__ import annotations

import os
import subprocess
import sys

from encctl_gym import _jit

# compiles one small kernel of the package (the moment estimators' row update)
CHILD = """
import numpy as np
from encctl_gym.ident import _moment_kernels as mk
X, U, M = np.zeros((5, 1, 2)), np.zeros((5, 1, 1)), np.zeros((1, 5, 5))
mk.add_rows(X, U, 1, 4, M, 1.0, 0)
"""


def _run(cache_dir, notice: str | None) -> str:
    env = {k: v for k, v in os.environ.items() if k != _jit.NOTICE_ENV}
    env["NUMBA_CACHE_DIR"] = str(cache_dir)
    if notice is not None:
        env[_jit.NOTICE_ENV] = notice
    out = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, env=env, check=True, timeout=300)
    return out.stderr


def test_the_first_compile_says_so_and_a_cached_kernel_does_not(tmp_path):
    first = _run(tmp_path / "cache", None)
    assert first.splitlines() == [_jit.notice_text(False)]
    assert _run(tmp_path / "cache", None) == ""  # loaded from the cache: numba raises no compile event
    assert _run(tmp_path / "other", "0") == ""  # silenced


def test_one_line_per_kind_and_none_for_foreign_functions(monkeypatch, capsys):
    monkeypatch.setitem(_jit._state, "announced", set())
    monkeypatch.delenv(_jit.NOTICE_ENV, raising=False)

    class Dispatcher:
        def __init__(self, module: str, parallel: bool) -> None:
            self.py_func = type("F", (), {"__module__": module})
            self.targetoptions = {"parallel": parallel}

    _jit._on_compile(Dispatcher("someone.else", False))
    assert capsys.readouterr().err == ""
    for _ in range(3):
        _jit._on_compile(Dispatcher("encctl_gym.envs._kernels", False))
    _jit._on_compile(Dispatcher("encctl_gym.envs._kernels", True))
    _jit._on_compile(Dispatcher("encctl_gym.envs._kernels", True))
    assert capsys.readouterr().err.splitlines() == [_jit.notice_text(False), _jit.notice_text(True)]


def test_every_module_that_compiles_kernels_installs_the_notice():
    """Every module of the package that imports numba's njit calls install_compile_notice at import."""
    from pathlib import Path

    root = Path(_jit.__file__).parent
    kernels = [p for p in root.rglob("*.py") if "from numba import" in p.read_text()]
    assert len(kernels) >= 3
    missing = [str(p.relative_to(root)) for p in kernels if "\ninstall_compile_notice()" not in p.read_text()]
    assert missing == []
