"""encctl-gym: adversarial experiments on encrypted control systems.

Layers import downward only; ``docs/architecture.md`` draws them module by module.

Implements K. Teranishi and K. Kogiso, "Optimal Security Parameter for Encrypted Control
Systems Against Eavesdropper and Malicious Server" (arXiv 2303.13059).
"""

from __future__ import annotations

from .errors import (
    BreakerError,
    BreakerLimitError,
    BreakerTimeoutError,
    BudgetError,
    CiphertextError,
    ConfigError,
    EncctlError,
    EncodingOverflowError,
    GroupError,
    KeyMismatchError,
    ModelRangeError,
    OptionalDependencyError,
    ParameterError,
    PlaintextError,
    ResourceLimitError,
    ShapeError,
    SolverError,
    UnstableSystemError,
)

__version__ = "0.1.0"

__all__ = [
    "__version__",
    "EncctlError",
    "ParameterError",
    "ShapeError",
    "UnstableSystemError",
    "GroupError",
    "KeyMismatchError",
    "PlaintextError",
    "CiphertextError",
    "EncodingOverflowError",
    "SolverError",
    "BudgetError",
    "ConfigError",
    "ModelRangeError",
    "ResourceLimitError",
    "BreakerError",
    "BreakerLimitError",
    "BreakerTimeoutError",
    "OptionalDependencyError",
]


from .registration import register_when_gymnasium_loads

# gymnasium.make finds encctl_gym/EncryptedLTIAttack-v0 after `import encctl_gym`, whichever
# of the two is imported first; importing this package does not import gymnasium.
register_when_gymnasium_loads()
