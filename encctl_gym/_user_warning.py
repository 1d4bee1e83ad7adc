"""Warnings attributed to the user's line, not to the package or to Gymnasium.

A fixed ``stacklevel`` is right for one call path only: the same warning raised while an
environment is built points at the package's own frames when the environment is constructed
directly, and into ``gymnasium/envs/registration.py`` when it comes from ``gymnasium.make`` (issue
34, item 7). :func:`warn_user` walks the stack instead, past every frame of ``encctl_gym`` (with
its applications ``encctl_gym.agents`` and ``encctl_gym.experiments``), of Gymnasium and of the
import machinery, and issues the warning at the first other frame (what Python 3.12's
``warnings.warn(..., skip_file_prefixes=...)`` does; the package supports 3.10). Filters and the
once-per-location registry then work on the user's module and line, as for any warning.
"""

from __future__ import annotations

import os
import sys
import warnings
from types import FrameType

__all__ = ["warn_user", "internal_prefixes", "user_frame"]

#: Packages whose frames are never the user's line.
INTERNAL_PACKAGES: tuple[str, ...] = ("encctl_gym", "encctl_gym.agents", "encctl_gym.experiments", "gymnasium")


def internal_prefixes() -> tuple[str, ...]:
    """The directories (with a trailing separator) of :data:`INTERNAL_PACKAGES` that are loaded."""
    prefixes: list[str] = []
    for name in INTERNAL_PACKAGES:
        module = sys.modules.get(name)
        for folder in getattr(module, "__path__", ()) or ():
            prefixes.append(os.path.join(os.path.normcase(os.path.abspath(folder)), ""))
    return tuple(prefixes)


def _is_internal(filename: str, prefixes: tuple[str, ...]) -> bool:
    if filename.startswith("<frozen "):  # importlib's bootstrap (a warning raised during an import)
        return True
    return os.path.normcase(os.path.abspath(filename)).startswith(prefixes)


def user_frame(start: FrameType | None) -> FrameType | None:
    """The first frame from ``start`` outwards that lies outside the package and Gymnasium (None
    when every frame does)."""
    prefixes = internal_prefixes()
    frame = start
    while frame is not None and _is_internal(frame.f_code.co_filename, prefixes):
        frame = frame.f_back
    return frame


def warn_user(message: str, category: type[Warning] = UserWarning) -> None:
    """Issue ``message`` as ``category`` at the user's line (:func:`user_frame` of the caller)."""
    frame = user_frame(sys._getframe(1))
    if frame is None:  # called from the package alone (no user frame): the caller's line
        warnings.warn(message, category, stacklevel=2)
        return
    module_globals = frame.f_globals
    registry = module_globals.setdefault("__warningregistry__", {})
    warnings.warn_explicit(
        message,
        category,
        frame.f_code.co_filename,
        frame.f_lineno,
        module=module_globals.get("__name__", "<string>"),
        registry=registry,
        module_globals=module_globals,
    )
