"""Former home of :func:`run_tasks` and :func:`child_seeds`, now :mod:`encctl_gym.parallel`.

Kept as an import path for one version; import from :mod:`encctl_gym.parallel` instead.
"""

from __future__ import annotations

from .. import parallel
from ..parallel import *  # noqa: F403
from ..parallel import CONNECT_TIMEOUT  # noqa: F401  (a constant tests set)

__all__ = list(parallel.__all__)
