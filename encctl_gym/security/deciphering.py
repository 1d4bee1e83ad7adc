"""Sample deciphering time (Definition def:sdt) for the three key-handling schemes and every cost model.

``tau(N, lambda) = 2^lambda N / Upsilon`` is the time an adversary with an ``Upsilon``-FLOPS
computer needs to break the ``N`` ciphertexts it uses for identification, when every ciphertext
is under its own key and breaking one key costs ``2^lambda`` operations (Definition def:bit_sec).
How many keys really have to be broken depends on the scheme and on the adversary:

============  ==============  ======================================================  ===========
scheme        adversary       why                                                     keys
============  ==============  ======================================================  ===========
``static``    either          one fixed key pair: one break reveals every ciphertext   1
                              (Remark after Definition def:security)
``token``     ``server``      the server holds the update tokens: sk_{t+1} = sk_t + d  1
                              (Proposition prop:vulnerability)
``token``     ``eavesdropper``tokens are secret (Proposition prop:impossibility)       N
``modified``  either          Definition def:modification: no token leaves the plant   N
============  ==============  ======================================================  ===========

What one key costs is a *cost model* (:mod:`~encctl_gym.security.cost_models`): the paper's
``2^lambda`` for every key, an index-calculus precomputation carried by the first key and a
cheap descent for every later one, or Pollard rho. Every function here takes, in the place of
``lam``, either a security parameter (the paper's model, exactly as in def:sdt) or a
:class:`~encctl_gym.security.cost_models.KeyBreakCost` from any model (:func:`break_cost`): with
``keys`` keys to break, the cumulative work is ``W = first + (keys - 1) next`` operations and
``tau(N) = W / Upsilon``.

For the environment (``deciphering_model`` configuration key)::

    cost = break_cost("precomputation", key_length=1024)      # or break_cost("paper", security_parameter=74)
    tau = sample_deciphering_time(np.arange(horizon + 1), cost, upsilon, scheme=..., adversary=...)
    N_max = max_affordable_samples(tau_c, cost, upsilon, scheme=..., adversary=...)

``tau[0] = 0``, ``tau[1]`` carries any precomputation, and ``N_max`` is the largest ``N`` with
``tau(N) <= tau_c`` (``inf`` when one break reveals every sample and is affordable). Under the
precomputation model ``N_max`` is usually astronomically large (a further key costs 2^-20 of the
first), so an environment horizon is then set by ``max_samples``.

Units: ``tau`` and ``tau_c`` in seconds, ``Upsilon`` in operations (floating point operations)
per second.

Exactness: ``max_affordable_samples`` and :func:`sample_deciphering_time_exact` use rational
arithmetic, with ``tau_c`` and ``Upsilon`` read by the decimal rule of
:mod:`~encctl_gym.security.exact` (``442e15`` is 442 * 10^15) and costs as exact fractions (an
integer ``lam`` gives exactly ``2^lam``; a real cost ``2^x`` is the exact value of its float
mantissa, see :func:`~encctl_gym.security.exact.pow2`). Times returned as floats are the exact
values rounded once (scalars) or ``tau(1) + (keys - 1) tau_next`` in float64 (arrays).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, Protocol, runtime_checkable

import numpy as np

from .._validation import as_finite_array, check_int, format_value
from ..errors import ParameterError
from .cost_models import DECIPHERING_MODELS, KeyBreakCost, PaperModel, check_security_parameter, deciphering_model
from .exact import decimal_fraction, exact_number

__all__ = [
    "KEY_HANDLINGS",
    "ADVERSARIES",
    "DECIPHERING_MODELS",
    "KeyBreakCost",
    "break_cost",
    "deciphering_model",
    "sample_deciphering_time",
    "sample_deciphering_time_exact",
    "per_sample_cost",
    "max_affordable_samples",
    "keys_to_break",
    "independent_keys",
    "KeyExposure",
    "exact_number",
    "check_security_parameter",
]

#: The paper's key handlings (the module table); a scheme object answers for itself.
KEY_HANDLINGS: tuple[str, ...] = ("modified", "token", "static")
ADVERSARIES: tuple[str, ...] = ("eavesdropper", "server")


@runtime_checkable
class KeyExposure(Protocol):
    """What a scheme tells the budget: whether each sample is under its own key for an adversary
    (the scheme seam's :meth:`~encctl_gym.loop.scheme.EncryptionScheme.independent_keys`)."""

    def independent_keys(self, adversary: str) -> bool:
        """True if every sample is under its own key, False if one break reveals every sample."""


def independent_keys(scheme: str | KeyExposure = "modified", adversary: str = "eavesdropper") -> bool:
    """Whether every sample is under its own key for this adversary (else one break reveals all).

    Parameters
    ----------
    scheme : str or KeyExposure
        One of the paper's schemes :data:`KEY_HANDLINGS` (the module table), or a scheme object that
        answers for itself (``scheme.independent_keys(adversary)``, the scheme seam of
        :mod:`encctl_gym.loop.scheme`).
    adversary : {"eavesdropper", "server"}

    Raises
    ------
    ParameterError
        For an unknown scheme or adversary (named in the message).
    """
    exposure = not isinstance(scheme, (str, type)) and isinstance(scheme, KeyExposure)
    if not exposure and (not isinstance(scheme, str) or scheme not in KEY_HANDLINGS):
        raise ParameterError(f"unknown scheme {format_value(scheme)}; expected one of {', '.join(KEY_HANDLINGS)}")
    if not isinstance(adversary, str) or adversary not in ADVERSARIES:
        raise ParameterError(f"unknown adversary {format_value(adversary)}; expected one of {', '.join(ADVERSARIES)}")
    if exposure:
        return bool(scheme.independent_keys(adversary))  # type: ignore[union-attr]
    if scheme == "static":
        return False
    if scheme == "token":
        return adversary == "eavesdropper"
    return True


def keys_to_break(N: int, scheme: str | KeyExposure = "modified", adversary: str = "eavesdropper") -> int:
    """Number of keys the adversary must break to read ``N`` ciphertexts.

    Parameters
    ----------
    N : int
        Number of ciphertexts (>= 0).
    scheme : {"modified", "token", "static"}
        Key handling (see the module table).
    adversary : {"eavesdropper", "server"}
        Adversary type of Figure fig:adversary.

    Returns
    -------
    int
        ``N`` when every sample has an independent key, ``min(N, 1)`` when one break reveals all
        (static keys; token scheme against a malicious server, Proposition prop:vulnerability).

    Raises
    ------
    ParameterError
        For a bad ``N``, an unknown scheme or adversary (named in the message).
    """
    N = check_int("N", N, 0)
    return N if independent_keys(scheme, adversary) else min(N, 1)


def break_cost(model: Any = "paper", *, key_length: Any = None, security_parameter: Any = None, **options: Any) -> KeyBreakCost:
    """The cost of breaking keys under a model, for a key length or (paper model) a security parameter.

    Parameters
    ----------
    model : str or CostModel, default "paper"
        A name of :data:`DECIPHERING_MODELS` or a built model.
    key_length : int, optional
        Bits of p.
    security_parameter : int or float, optional
        ``lam`` (paper model only; an integer is exact, as in def:sdt).
    **options
        Model options (``gnfs_correction``, ``calibration``).

    Returns
    -------
    KeyBreakCost

    Raises
    ------
    ParameterError
        Unless exactly one of ``key_length`` and ``security_parameter`` is given, or for a
        security parameter under a model other than ``paper``.
    ModelRangeError
        For a key length or security parameter outside the model's range.
    """
    m = deciphering_model(model, **options)
    if (key_length is None) == (security_parameter is None):
        raise ParameterError("give exactly one of key_length and security_parameter")
    if security_parameter is not None:
        if not isinstance(m, PaperModel):
            raise ParameterError(
                f"a security parameter defines the cost only under the paper model; the {m.name} model needs key_length"
            )
        return m.cost_of_security_parameter(security_parameter)
    return m.break_cost(check_int("key_length", key_length))


def _cost(lam: Any) -> KeyBreakCost:
    if isinstance(lam, KeyBreakCost):
        return lam
    return PaperModel().cost_of_security_parameter(lam)


def sample_deciphering_time_exact(
    N: int, lam: Any, upsilon: Any, *, scheme: str | KeyExposure = "modified", adversary: str = "eavesdropper"
) -> Fraction:
    """Exact sample deciphering time (Definition def:sdt).

    Parameters
    ----------
    N : int
        Number of ciphertexts used for identification (>= 0).
    lam : int or KeyBreakCost
        Security parameter (an integer in ``[1, 2048]``; a real ``lam`` has no exact ``2^lam``)
        or a cost from :func:`break_cost`.
    upsilon : float
        Adversary's computing speed in FLOPS (> 0).
    scheme, adversary : str
        See :func:`keys_to_break`.

    Returns
    -------
    Fraction
        ``W(keys) / Upsilon`` seconds (``2^lam keys / Upsilon`` for a security parameter).
    """
    if not isinstance(lam, KeyBreakCost):
        lam_v = check_security_parameter(lam)
        if not isinstance(lam_v, int):
            raise ParameterError(f"lam must be an integer for the exact deciphering time, got {format_value(lam)}")
    cost = _cost(lam)
    ups = decimal_fraction("upsilon", upsilon)
    return cost.operations(keys_to_break(N, scheme, adversary)) / ups


def _to_float(x: Fraction) -> float:
    try:
        return float(x)
    except OverflowError:
        return math.inf


def sample_deciphering_time(
    N: Any, lam: Any, upsilon: Any, *, scheme: str | KeyExposure = "modified", adversary: str = "eavesdropper"
) -> float | np.ndarray:
    """Sample deciphering time of Definition def:sdt, ``tau(N, lam) = 2^lam N / Upsilon``, or under a model.

    With ``scheme="static"``, or ``scheme="token"`` against ``adversary="server"``, one break
    reveals every sample and the time is ``tau(1)`` for every ``N >= 1`` (Remark after
    Definition def:security, Proposition prop:vulnerability). ``tau(0) = 0``.

    Parameters
    ----------
    N : int or array_like of int
        Number of ciphertexts (>= 0).
    lam : int, float or KeyBreakCost
        Security parameter in bits (integer in ``[1, 2048]`` or real in ``(0, 2048]``), or a cost
        from :func:`break_cost` (any model; the first key carries any precomputation).
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
    cost = _cost(lam)
    ups = decimal_fraction("upsilon", upsilon)
    independent = independent_keys(scheme, adversary)
    if np.ndim(N) == 0:
        n_keys = keys_to_break(N.item() if isinstance(N, np.ndarray) else N, scheme, adversary)
        return _to_float(cost.operations(n_keys) / ups)
    arr = as_finite_array("N", N)
    if not np.all(arr == np.round(arr)) or np.any(arr < 0):
        raise ParameterError(f"N must contain integers >= 0, got {format_value(np.asarray(N))}")
    keys = arr if independent else np.minimum(arr, 1.0)
    t_first, t_next = _to_float(cost.first / ups), _to_float(cost.next / ups)
    with np.errstate(over="ignore", invalid="ignore"):
        if cost.first == cost.next:  # every key alike (the paper's model): N 2^lam / Upsilon, one rounding
            return np.where(keys > 0, keys * t_first, 0.0)
        out = np.zeros_like(keys)
        out[keys >= 1] = t_first
        later = keys > 1
        out[later] = t_first + (keys[later] - 1.0) * t_next
    return out


def per_sample_cost(lam: Any, upsilon: Any) -> float:
    """Time to break the first ciphertext, ``2^lam / Upsilon`` seconds (Definition def:sdt with N = 1).

    Parameters
    ----------
    lam : int, float or KeyBreakCost
        Security parameter, or a cost (then the first key's time, precomputation included).
    upsilon : float
        FLOPS (> 0).

    Returns
    -------
    float
        Seconds (``inf`` beyond the float range).
    """
    return float(sample_deciphering_time(1, lam, upsilon))


def max_affordable_samples(
    tau_c: Any, lam: Any, upsilon: Any, *, scheme: str | KeyExposure = "modified", adversary: str = "eavesdropper"
) -> int | float:
    """Largest sample size ``N`` with ``tau(N) <= tau_c`` (Definitions def:sdt, def:security), exactly.

    Parameters
    ----------
    tau_c : float
        Defense period in seconds (> 0).
    lam : int, float or KeyBreakCost
        Security parameter (the paper's model) or a cost from :func:`break_cost`.
    upsilon : float
        FLOPS (> 0).
    scheme, adversary : str
        See :func:`keys_to_break`.

    Returns
    -------
    int or float
        With independent keys: 0 if even the first key is out of reach, else
        ``1 + floor((Upsilon tau_c - first) / next)`` (``floor(Upsilon tau_c / 2^lam)`` for a
        security parameter). When one break reveals every sample: ``float('inf')`` if the first
        break is affordable, else ``0``.
    """
    cost = _cost(lam)
    budget = decimal_fraction("upsilon", upsilon) * decimal_fraction("tau_c", tau_c)
    independent = independent_keys(scheme, adversary)
    if cost.first > budget:
        return 0
    if not independent:
        return math.inf
    return 1 + math.floor((budget - cost.first) / cost.next)
