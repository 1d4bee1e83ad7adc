"""encctl-gym: adversarial experiments on encrypted control systems.

Layers import downward only; ``docs/architecture.md`` draws them module by module.

Implements K. Teranishi and K. Kogiso, "Optimal Security Parameter for Encrypted Control
Systems Against Eavesdropper and Malicious Server" (arXiv 2303.13059).
"""

from __future__ import annotations

from . import errors
from .errors import *  # noqa: F401,F403  (the error hierarchy, at the top level)

__version__ = "0.1.0"

__all__ = ["__version__", *errors.__all__]


from .registration import register_when_gymnasium_loads

# gymnasium.make finds encctl_gym/EncryptedLTIAttack-v0 after `import encctl_gym`, whichever
# of the two is imported first; importing this package does not import gymnasium.
register_when_gymnasium_loads()
