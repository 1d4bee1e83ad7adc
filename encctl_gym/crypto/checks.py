"""Checks shared by the keys, tokens and ciphertexts of the schemes (Examples ex:elgamal,
ex:dyn_elgamal, Definition def:modification) and by the algorithms that combine them.

One home for the rules that every scheme module applies alike:

* the integer and time-step fields of the frozen dataclasses (:func:`integer_field`,
  :func:`step_field`, :func:`group_field`);
* the type of an argument (:func:`check_instance`);
* the group: keys, tokens and ciphertexts carry the :class:`~.group.GroupParams` they belong
  to, and an operation that combines them refuses objects of different groups with
  :class:`~encctl_gym.errors.KeyMismatchError` (:func:`check_same_group`,
  :func:`check_group_of`) instead of returning a wrong plaintext;
* membership of a ciphertext component in G (:func:`check_component`).
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

from .._validation import format_value
from ..errors import CiphertextError, KeyMismatchError, ParameterError
from . import arith
from .group import GroupParams

__all__ = [
    "integer_field",
    "step_field",
    "group_field",
    "check_instance",
    "check_same_group",
    "check_group_of",
    "check_component",
    "check_ciphertext_matrix",
    "check_ciphertext_of",
]

_MPZ = type(arith.mpz(0))


def integer_field(obj: Any, name: str, err: type) -> None:
    """Store the field ``name`` of the frozen dataclass ``obj`` as a Python int.

    Accepts ``int``, ``gmpy2.mpz`` and NumPy integers; raises ``err`` (naming the class, the
    field and the value) for anything else, booleans included.
    """
    value = getattr(obj, name)
    if type(value) is int:  # fast path (hot in the control loop)
        return
    if type(value) is _MPZ:
        object.__setattr__(obj, name, int(value))
        return
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, np.integer)):
        raise err(f"{type(obj).__name__}.{name} must be an integer, got {format_value(value)}")
    object.__setattr__(obj, name, int(value))


def step_field(obj: Any, name: str, err: type, optional: bool) -> None:
    """Store the time-step field ``name`` of ``obj`` as an int >= 0 (``None`` allowed if ``optional``)."""
    value = getattr(obj, name)
    if value is None and optional:
        return
    if type(value) is int and value >= 0:  # fast path
        return
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, np.integer)) or value < 0:
        raise err(f"{type(obj).__name__}.{name} must be a time step >= 0, got {format_value(value)}")
    object.__setattr__(obj, name, int(value))


def group_field(obj: Any, err: type) -> GroupParams:
    """Check that ``obj.group`` is a :class:`GroupParams`; return it."""
    group = obj.group
    if type(group) is not GroupParams and not isinstance(group, GroupParams):
        raise err(f"{type(obj).__name__}.group must be a GroupParams, got {format_value(group)}")
    return group


def check_instance(value: Any, cls: type, name: str) -> None:
    """Raise :class:`ParameterError` unless ``value`` is a ``cls`` (the message names both)."""
    if not isinstance(value, cls):
        raise ParameterError(f"{name} must be a {cls.__name__}, got {type(value).__name__}: {format_value(value)}")


def check_same_group(a: Any, b: Any, what: str = "keys") -> GroupParams:
    """Return the common group of two keys (or tokens, ciphertexts).

    Raises
    ------
    KeyMismatchError
        If their groups differ.
    """
    if a.group is not b.group and a.group != b.group:
        raise KeyMismatchError(f"{what} belong to different groups: {a.group!r} and {b.group!r}")
    return a.group


def check_group_of(obj: Any, group: GroupParams, what: str = "ciphertext") -> None:
    """Raise :class:`KeyMismatchError` unless ``obj`` (a ciphertext or token) belongs to ``group``."""
    if obj.group is not group and obj.group != group:
        raise KeyMismatchError(f"{what} belongs to the group {obj.group!r}, the key to the group {group!r}")


def check_component(group: GroupParams, c: int, name: str) -> None:
    """Raise :class:`CiphertextError` unless the ciphertext component ``c`` lies in G.

    One Jacobi symbol for safe-prime groups (see :meth:`GroupParams.contains`).
    """
    if not 0 < c < group.p:
        raise CiphertextError(f"ciphertext component {name} = {arith.format_int(c)} is outside [1, p)")
    if not group.contains(c):
        raise CiphertextError(f"ciphertext component {name} = {arith.format_int(c)} is not in the subgroup G")


def check_ciphertext_matrix(name: str, mat: Any, cls: type, shape: tuple[int, int] | None = None) -> list[list[Any]]:
    """``mat`` as a list of rows after checking it is a non-empty rectangular matrix of ``cls``.

    The shape check of every party that receives a matrix of ciphertexts (the controller
    parameter at a server, the server's output at the plant of eq:ec).

    Raises
    ------
    CiphertextError
        For something that is not a matrix, ragged rows, another ``shape`` or another entry type.
    """
    try:
        rows = [list(r) for r in mat]
    except TypeError as exc:
        raise CiphertextError(f"{name} must be a matrix of {cls.__name__}, got {type(mat).__name__}") from exc
    if not rows or not rows[0] or any(len(r) != len(rows[0]) for r in rows):
        raise CiphertextError(f"{name} must be a non-empty rectangular matrix, got row lengths {[len(r) for r in rows]}")
    if shape is not None and (len(rows), len(rows[0])) != shape:
        raise CiphertextError(f"{name} must have shape {shape}, got {(len(rows), len(rows[0]))}")
    for r in rows:
        for c in r:
            if not isinstance(c, cls):
                raise CiphertextError(f"{name} must contain {cls.__name__} entries, got {type(c).__name__}")
    return rows


def check_ciphertext_of(group: GroupParams, ct: Any, cls: type, components: tuple[str, ...], description: str) -> Any:
    """``ct`` after checking it is a ``cls`` of ``group`` whose ``components`` all lie in G.

    The check of every ciphertext type (:func:`~.elgamal.check_ciphertext`,
    :func:`~.modified.check_modified_ciphertext`).

    Raises
    ------
    CiphertextError
        For another type (named by ``description``) or a component outside G.
    KeyMismatchError
        If ``ct`` belongs to another group.
    """
    if not isinstance(ct, cls):
        raise CiphertextError(f"expected {description}, got {format_value(ct)}")
    check_group_of(ct, group)
    for name in components:
        check_component(group, getattr(ct, name), name)
    return ct
