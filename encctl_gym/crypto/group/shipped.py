"""The pre-generated safe-prime groups of :data:`SHIPPED_BITS`, stored in ``crypto/data/groups.json``
(made with :func:`~.generation.generate_safe_prime_group`); :func:`shipped_group` verifies them
once per process (primality of p and q, order of g) and caches the result.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path
from typing import Any

from ..._validation import check_int
from ...errors import GroupError, ParameterError
from .params import GroupParams

__all__ = ["SHIPPED_BITS", "shipped_group"]

#: Bit lengths of the groups shipped in ``crypto/data/groups.json``.
SHIPPED_BITS: tuple[int, ...] = (64, 128, 256, 512, 712, 1024, 2048)

_DATA_FILE = Path(__file__).resolve().parent.parent / "data" / "groups.json"


@lru_cache(maxsize=1)
def _shipped_data() -> dict[int, dict[str, Any]]:
    try:
        data = json.loads(_DATA_FILE.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise GroupError(f"cannot read the shipped groups from {_DATA_FILE}: {exc}") from exc
    return {int(entry["bits"]): entry for entry in data["groups"]}


def shipped_group(bits: int) -> GroupParams:
    """Return the pre-generated safe-prime group of ``bits`` bits (verified once per process).

    Parameters
    ----------
    bits : int
        One of :data:`SHIPPED_BITS`.

    Raises
    ------
    ParameterError
        If no group of that size is shipped.
    GroupError
        If the stored group fails verification.
    """
    bits = check_int("bits", bits)
    data = _shipped_data()
    if bits not in data:
        raise ParameterError(f"no shipped group of {bits} bits; shipped sizes: {sorted(data)}")
    group = GroupParams.from_dict(data[bits])
    if group.bits != bits:
        raise GroupError(f"shipped group labelled {bits} bits has {group.bits} bits")
    return group.verify()
