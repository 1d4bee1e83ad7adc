"""Sample deciphering time (Definition def:sdt) for the three key-handling schemes.

``tau(N, lambda) = 2^lambda N / Upsilon`` is the time an adversary with an ``Upsilon``-FLOPS
computer needs to break the ``N`` ciphertexts it uses for identification, when every
ciphertext is under its own key and breaking one key costs ``2^lambda`` operations
(Definition def:bit_sec). How many keys really have to be broken depends on the scheme and on
the adversary:

============  ==============  ======================================================  ===========
scheme        adversary       why                                                     tau
============  ==============  ======================================================  ===========
``static``    either          one fixed key pair: one break reveals every ciphertext   tau(1, lam)
                              (Remark after Definition def:security)
``token``     ``server``      the server holds the update tokens: sk_{t+1} = sk_t + d  tau(1, lam)
                              (Proposition prop:vulnerability)
``token``     ``eavesdropper``tokens are secret (Proposition prop:impossibility)       tau(N, lam)
``modified``  either          Definition def:modification: no token leaves the plant   tau(N, lam)
============  ==============  ======================================================  ===========

Units: ``tau`` and ``tau_c`` in seconds, ``Upsilon`` in floating point operations per second.

The security parameter ``lam`` is either an integer >= 1 (the usual case; computations are then
exact rational arithmetic, with the float inputs read as their shortest decimal representation,
so ``442e15`` means 442 * 10^15 exactly) or a real number > 0 (then ``2^lam`` is evaluated in
floating point and comparisons can be off by rounding at exact ties).
"""

from __future__ import annotations

import math
import numbers
from fractions import Fraction
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_positive
from ..errors import ParameterError

__all__ = [
    "SCHEMES",
    "ADVERSARIES",
    "sample_deciphering_time",
    "sample_deciphering_time_exact",
    "per_sample_cost",
    "max_affordable_samples",
    "keys_to_break",
    "exact_number",
    "check_security_parameter",
]

SCHEMES: tuple[str, ...] = ("modified", "token", "static")
ADVERSARIES: tuple[str, ...] = ("eavesdropper", "server")


def exact_number(name: str, value: Any, *, positive: bool = True) -> Fraction:
    """Convert a real number to an exact :class:`~fractions.Fraction`.

    Integers and fractions are taken as they are; floats are read as their shortest decimal
    representation (``repr``), so ``1e-6`` becomes ``1/1000000`` and ``442e15`` becomes
    ``442 * 10**15``: the number the user typed, not its binary approximation.

    Parameters
    ----------
    name : str
        Name of the value in error messages.
    value : int, float, Fraction or numpy scalar
        The value; must be finite (and > 0 if ``positive``).
    positive : bool, default True
        Require ``value > 0``.

    Returns
    -------
    Fraction

    Raises
    ------
    ParameterError
        If ``value`` is not a finite real number (or not positive when required).
    """
    if isinstance(value, Fraction):
        frac = value
    elif isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"{name} must be a real number, got {value!r}")
    elif isinstance(value, (numbers.Integral, np.integer)):
        frac = Fraction(int(value))
    else:
        v = float(value)
        if not math.isfinite(v):
            raise ParameterError(f"{name} must be finite, got {value!r}")
        frac = Fraction(repr(v))
    if positive and frac <= 0:
        raise ParameterError(f"{name} must be > 0, got {value!r}")
    return frac


def check_security_parameter(lam: Any) -> int | float:
    """Validate a security parameter: an integer >= 1, or a real number > 0.

    Integral floats (``74.0``) are returned as ``int``.

    Raises
    ------
    ParameterError
        If ``lam`` is not a positive finite number (or is an integer < 1).
    """
    if isinstance(lam, (numbers.Integral, np.integer)) and not isinstance(lam, bool):
        return check_int("lam", lam, 1)
    v = check_positive("lam", lam)
    return int(v) if v.is_integer() and v >= 1 else v


def keys_to_break(N: int, scheme: str = "modified", adversary: str = "eavesdropper") -> int:
    """Number of keys the adversary must break to read ``N`` ciphertexts.

    Parameters
    ----------
    N : int
        Number of ciphertexts (>= 1).
    scheme : {"modified", "token", "static"}
        Key handling (see the module table).
    adversary : {"eavesdropper", "server"}
        Adversary type of Figure fig:adversary.

    Returns
    -------
    int
        ``N`` when every sample has an independent key, ``1`` when one break reveals all
        (static keys; token scheme against a malicious server, Proposition prop:vulnerability).

    Raises
    ------
    ParameterError
        For an unknown scheme or adversary (named in the message).
    """
    N = check_int("N", N, 1)
    return N if _independent_keys(scheme, adversary) else 1


def _independent_keys(scheme: str, adversary: str) -> bool:
    if scheme not in SCHEMES:
        raise ParameterError(f"unknown scheme {scheme!r}; expected one of {', '.join(SCHEMES)}")
    if adversary not in ADVERSARIES:
        raise ParameterError(f"unknown adversary {adversary!r}; expected one of {', '.join(ADVERSARIES)}")
    if scheme == "static":
        return False
    if scheme == "token":
        return adversary == "eavesdropper"
    return True


def sample_deciphering_time_exact(
    N: int, lam: int, upsilon: Any, *, scheme: str = "modified", adversary: str = "eavesdropper"
) -> Fraction:
    """Exact sample deciphering time (Definition def:sdt) for an integer ``lam``.

    Parameters
    ----------
    N : int
        Number of ciphertexts used for identification (>= 1).
    lam : int
        Security parameter (bits), integer >= 1.
    upsilon : float
        Adversary's computing speed in FLOPS (> 0).
    scheme, adversary : str
        See :func:`keys_to_break`.

    Returns
    -------
    Fraction
        ``2^lam * keys / Upsilon`` seconds, ``keys = keys_to_break(N, scheme, adversary)``.
    """
    lam_v = check_security_parameter(lam)
    if not isinstance(lam_v, int):
        raise ParameterError(f"lam must be an integer for the exact deciphering time, got {lam!r}")
    ups = exact_number("upsilon", upsilon)
    return Fraction(2**lam_v * keys_to_break(N, scheme, adversary)) / ups


def sample_deciphering_time(
    N: Any, lam: Any, upsilon: Any, *, scheme: str = "modified", adversary: str = "eavesdropper"
) -> float | np.ndarray:
    """Sample deciphering time of Definition def:sdt, ``tau(N, lam) = 2^lam N / Upsilon``.

    With ``scheme="static"``, or ``scheme="token"`` against ``adversary="server"``, one break
    reveals every sample and the time is ``tau(1, lam)`` whatever ``N`` (Remark after
    Definition def:security, Proposition prop:vulnerability).

    Parameters
    ----------
    N : int or array_like of int
        Number of ciphertexts (>= 1).
    lam : int or float
        Security parameter in bits (integer >= 1 or real > 0).
    upsilon : float
        Adversary's computing speed in FLOPS (> 0).
    scheme : {"modified", "token", "static"}, default "modified"
    adversary : {"eavesdropper", "server"}, default "eavesdropper"

    Returns
    -------
    float or ndarray
        Seconds, same shape as ``N``; times beyond the float range are ``inf``.

    Raises
    ------
    ParameterError
        For a bad ``N``, ``lam``, ``upsilon``, scheme or adversary.
    """
    lam_v = check_security_parameter(lam)
    ups = check_positive("upsilon", upsilon)
    independent = _independent_keys(scheme, adversary)
    if np.ndim(N) == 0:
        n_keys = keys_to_break(N.item() if isinstance(N, np.ndarray) else N, scheme, adversary)
        if isinstance(lam_v, int):
            try:
                return float(sample_deciphering_time_exact(n_keys, lam_v, upsilon))
            except OverflowError:
                return math.inf
        with np.errstate(over="ignore"):
            return float(np.exp2(lam_v) * n_keys / ups)
    arr = as_finite_array("N", N)
    if not np.all(arr == np.round(arr)) or np.any(arr < 1):
        raise ParameterError(f"N must contain integers >= 1, got {np.asarray(N)!r}")
    keys = arr if independent else np.ones_like(arr)
    with np.errstate(over="ignore"):
        return np.exp2(float(lam_v)) * keys / ups


def per_sample_cost(lam: Any, upsilon: Any) -> float:
    """Time to break one ciphertext, ``2^lam / Upsilon`` seconds (Definition def:sdt with N = 1).

    Parameters
    ----------
    lam : int or float
        Security parameter (integer >= 1 or real > 0).
    upsilon : float
        FLOPS (> 0).

    Returns
    -------
    float
        Seconds (``inf`` beyond the float range).
    """
    return sample_deciphering_time(1, lam, upsilon)


def max_affordable_samples(
    tau_c: Any, lam: Any, upsilon: Any, *, scheme: str = "modified", adversary: str = "eavesdropper"
) -> int | float:
    """Largest sample size ``N`` with ``tau(N, lam) <= tau_c`` (Definitions def:sdt, def:security).

    Parameters
    ----------
    tau_c : float
        Defense period in seconds (> 0).
    lam : int or float
        Security parameter (integer >= 1: exact; real > 0: floating point).
    upsilon : float
        FLOPS (> 0).
    scheme, adversary : str
        See :func:`keys_to_break`.

    Returns
    -------
    int or float
        ``floor(Upsilon tau_c / 2^lam)`` when every sample has its own key (0 if even one sample
        is out of reach); when one break reveals every sample, ``float('inf')`` if
        ``tau(1, lam) <= tau_c`` else ``0``.
    """
    lam_v = check_security_parameter(lam)
    tau = exact_number("tau_c", tau_c)
    ups = exact_number("upsilon", upsilon)
    independent = _independent_keys(scheme, adversary)
    if isinstance(lam_v, int):
        budget = ups * tau / 2**lam_v  # exact: number of breakable keys
        if independent:
            return math.floor(budget)
        return math.inf if budget >= 1 else 0
    log_budget = math.log2(float(ups)) + math.log2(float(tau)) - lam_v
    if independent:
        if log_budget < 1000:
            return math.floor(2.0**log_budget) if log_budget >= 0 else 0
        k = math.floor(log_budget)  # beyond the float range: 53 significant bits, then zeros
        return int(2.0 ** (log_budget - k) * 2**52) * 2 ** (k - 52)
    return math.inf if log_budget >= 0 else 0
