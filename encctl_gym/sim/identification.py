"""Former home of least-squares identification, now :mod:`encctl_gym.ident`.

Kept as an import path for one version; import from :mod:`encctl_gym.ident` instead.
"""

from __future__ import annotations

from ..ident.least_squares import *  # noqa: F403
from ..ident.least_squares import __all__  # noqa: F401  (the same public names)
