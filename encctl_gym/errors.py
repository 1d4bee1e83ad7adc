"""The error hierarchy of encctl-gym.

Every error the package raises on bad input derives from :class:`EncctlError`, so a caller can
catch the whole family at once. Each subclass also derives from the matching built-in
exception (``ValueError``, ``OverflowError``, ...) so code that already catches those keeps
working. Messages name the offending value.
"""

from __future__ import annotations

__all__ = [
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


class EncctlError(Exception):
    """Base class of every error raised by encctl-gym."""


class ParameterError(EncctlError, ValueError):
    """A parameter has a value outside its domain (negative variance, Delta <= 0, NaN, ...)."""


class ShapeError(ParameterError):
    """Arrays have shapes that do not fit together (A is not square, B has the wrong rows, ...)."""


class UnstableSystemError(ParameterError):
    """The system matrix A is not Schur stable (spectral radius >= 1)."""


class GroupError(ParameterError):
    """Group parameters (p, q, g) are invalid: not prime, wrong order, wrong generator."""


class KeyMismatchError(EncctlError, ValueError):
    """A key or ciphertext belongs to another group or another time step."""


class PlaintextError(EncctlError, ValueError):
    """A plaintext is not an element of the message space (the order-q subgroup)."""


class CiphertextError(EncctlError, ValueError):
    """A ciphertext has the wrong shape or components outside the group."""


class EncodingOverflowError(EncctlError, OverflowError):
    """A value, product or sum does not fit in the representable plaintext range."""


class SolverError(EncctlError, RuntimeError):
    """A numerical solver (Lyapunov, convex program) failed or returned an unusable result."""


class BudgetError(ParameterError):
    """A deciphering or energy budget is too small for the requested experiment."""


class ConfigError(ParameterError):
    """A configuration or system file cannot be read or has invalid content."""


class ModelRangeError(ParameterError):
    """A value lies outside the range where a formula or cost model holds (a key length below
    the GNFS crossover, a security parameter above the supported bound, ...); the message names
    the value and the range."""


class ResourceLimitError(ParameterError):
    """An input would need more time or memory than the package allows (a file above the size
    bound, YAML aliases expanding past the node bound, an SDP too large to solve, a safe prime
    too slow to generate, an episode or table too large to allocate); the message names the
    estimate and the bound."""


class BreakerError(SolverError):
    """A key breaker (:mod:`encctl_gym.cryptanalysis`) failed: no logarithm found, or a recovered
    exponent failed the check g^s = h (a breaker never returns an unchecked key)."""


class BreakerLimitError(ResourceLimitError):
    """A group is too large for a breaker; refused before any work, naming the limit and the
    expected time."""


class BreakerTimeoutError(BreakerError, TimeoutError):
    """A breaker call ran past its time limit and was stopped."""


class OptionalDependencyError(ConfigError, ImportError):
    """An optional dependency is not installed; the message names the extra that provides it."""
