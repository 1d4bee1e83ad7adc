"""Former home of :func:`run_tasks` and :func:`child_seeds`, now :mod:`encctl_gym.parallel`.

Kept as an import path for one version; import from :mod:`encctl_gym.parallel` instead.
"""

from __future__ import annotations

from ..parallel import CONNECT_TIMEOUT, child_seeds, run_tasks

__all__ = ["child_seeds", "run_tasks", "CONNECT_TIMEOUT"]
