"""Registration of ``encctl_gym/EncryptedLTIAttack-v0`` with Gymnasium, in one place.

``import encctl_gym`` must not import gymnasium (the pure-math and crypto layers are used
without it, and importing it costs time), yet ``gymnasium.make`` must find the environment
after ``import encctl_gym`` in either import order. So :func:`register_when_gymnasium_loads`
registers at once if gymnasium is already imported, and otherwise waits for gymnasium's own
import to finish (a finder on ``sys.meta_path`` that wraps gymnasium's loader once and then
removes itself). Registration names the entry points as strings, so it imports none of the
environment's modules either.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import sys
from collections.abc import Sequence
from types import ModuleType
from typing import Any

__all__ = ["ENV_ID", "register_envs", "register_when_gymnasium_loads"]

ENV_ID = "encctl_gym/EncryptedLTIAttack-v0"
_ENTRY_POINT = "encctl_gym.envs.encrypted_lti_attack:EncryptedLTIAttackEnv"
_VECTOR_ENTRY_POINT = "encctl_gym.envs.vector:EncryptedLTIAttackVectorEnv"


def register_envs() -> None:
    """Register ``encctl_gym/EncryptedLTIAttack-v0`` (single and native vector entry points); idempotent."""
    import gymnasium as gym

    if ENV_ID not in gym.registry:
        gym.register(id=ENV_ID, entry_point=_ENTRY_POINT, vector_entry_point=_VECTOR_ENTRY_POINT)


class _RegisterAfterImport(importlib.abc.Loader):
    """Runs gymnasium's own loader, then :func:`register_envs`."""

    def __init__(self, loader: Any) -> None:
        self._loader = loader

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType | None:
        return self._loader.create_module(spec)

    def exec_module(self, module: ModuleType) -> None:
        self._loader.exec_module(module)
        register_envs()


class _GymnasiumWatcher(importlib.abc.MetaPathFinder):
    """Finds gymnasium like the other finders do, with a loader that registers afterwards."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None = None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if fullname != "gymnasium":
            return None
        sys.meta_path.remove(self)  # once is enough, and the lookup below must not find us
        for finder in sys.meta_path:
            find = getattr(finder, "find_spec", None)
            spec = find(fullname, path, target) if find is not None else None
            if spec is not None:
                if spec.loader is not None:
                    spec.loader = _RegisterAfterImport(spec.loader)
                return spec
        return None


def register_when_gymnasium_loads() -> None:
    """Register now if gymnasium is imported, else as soon as it is (see the module docstring)."""
    if "gymnasium" in sys.modules:
        register_envs()
    elif not any(isinstance(f, _GymnasiumWatcher) for f in sys.meta_path):
        sys.meta_path.insert(0, _GymnasiumWatcher())
