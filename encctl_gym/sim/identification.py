"""Former home of least-squares identification, now :mod:`encctl_gym.ident`.

Kept as an import path for one version; import from :mod:`encctl_gym.ident` instead.
"""

from __future__ import annotations

from ..ident import least_squares
from ..ident.least_squares import *  # noqa: F403

__all__ = list(least_squares.__all__)
