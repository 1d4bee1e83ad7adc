"""Key sequences to break: one dynamic-key sequence of Example ex:dyn_elgamal (KeyGen, then
KeyUpd ``n - 1`` times) with its secrets and update tokens, bounded by :data:`MAX_KEYS`.

Used by ``encctl-gym crack`` (:mod:`.cli`), the deciphering-time experiment, the benchmarks and
the tests; the breakers themselves never see a secret key.
"""

from __future__ import annotations

from typing import Any

from .._validation import check_int, format_value
from ..crypto import arith
from ..crypto.dyn_elgamal import key_update
from ..crypto.elgamal import keygen
from ..crypto.group import GroupParams
from ..errors import ResourceLimitError
from .base import format_bytes

__all__ = ["key_sequence", "check_keys", "MAX_KEYS"]

#: Largest number of keys of one sequence (``encctl-gym crack``, the experiments): the sequence, its tokens, the report and its
#: JSON are held in memory, about 3 KB per key (measured: 55 MB more for 20000 keys than for 1000,
#: 64-bit group, ``--json``), so 10^5 keys take about 0.3 GB (the paper's N* = 13159 fits).
MAX_KEYS = 100_000
_BYTES_PER_KEY = 3000


def check_keys(n: object, name: str = "keys") -> int:
    """Return the number of keys ``n`` after checking ``1 <= n <=`` :data:`MAX_KEYS`; ``name``
    is the name of the value in the error message.

    Raises
    ------
    ParameterError
        If ``n`` is not an integer >= 1.
    ResourceLimitError
        If ``n`` exceeds :data:`MAX_KEYS` (the message names the memory it would take).
    """
    n = check_int(name, n, minimum=1)
    if n > MAX_KEYS:
        raise ResourceLimitError(
            f"{name} = {format_value(n)} would hold about {format_bytes(n * _BYTES_PER_KEY)} of keys, tokens and "
            f"report in memory; the limit is {MAX_KEYS} keys (MAX_KEYS)"
        )
    return n


def key_sequence(group: GroupParams, n: int, rng: arith.RngLike) -> tuple[list[int], list[int], list[Any]]:
    """One dynamic-key sequence (Example ex:dyn_elgamal): KeyGen, then KeyUpd ``n - 1`` times.

    Parameters
    ----------
    group : GroupParams
    n : int
        Number of keys, ``1 <= n <=`` :data:`MAX_KEYS`.
    rng : None, int, RandomSource or numpy.random.Generator
        Randomness of KeyGen and KeyUpd (a seed is reproducible and unsafe for deployment).

    Returns
    -------
    (list of int, list of int, list of UpdateToken)
        The public-key elements h_0..h_{n-1}, the secret exponents, and the n - 1 tokens.
    """
    n = check_keys(n)
    src = arith.as_random_source(rng)
    pk, sk = keygen(group, rng=src)
    hs, secrets, tokens = [pk.h], [sk.s], []
    for _ in range(n - 1):
        pk, sk, token = key_update(pk, sk, rng=src)
        hs.append(pk.h)
        secrets.append(sk.s)
        tokens.append(token)
    return hs, secrets, tokens
