"""The closed loop behind the plant's input: encrypted controller, or an adversary's injection.

Backends implement :class:`~encctl_gym.loop.backend.LoopBackend` and are picked by name
(:data:`BACKENDS`, the environment's ``crypto`` key):

* ``"ideal"`` (:class:`~encctl_gym.loop.ideal.IdealLoop`): the exact encode / quantise /
  multiply / sum / decode arithmetic of the encrypted controller without big integers, batched,
  with the compiled stages of :mod:`encctl_gym.loop.quantize`;
* ``"elgamal"`` (:class:`~encctl_gym.loop.elgamal.ElGamalLoop`): real dynamic-key ElGamal
  ciphertexts, one copy.

Both use the group of :func:`~encctl_gym.loop.backend.loop_group`, so their trajectories agree
bit for bit.
"""

from __future__ import annotations

from typing import Any

from ..errors import ParameterError
from .backend import LoopBackend, loop_group, lqr_gain, table_limit
from .elgamal import ElGamalLoop
from .ideal import IdealLoop
from .quantize import Quantization

__all__ = [
    "LoopBackend",
    "BACKENDS",
    "make_loop",
    "IdealLoop",
    "ElGamalLoop",
    "Quantization",
    "loop_group",
    "lqr_gain",
    "table_limit",
]

#: Backends by the name the environment's ``crypto`` key gives.
BACKENDS: dict[str, type] = {"ideal": IdealLoop, "elgamal": ElGamalLoop}


def make_loop(params: Any) -> LoopBackend:
    """The backend selected by ``params.crypto``, on the group of :func:`loop_group`."""
    try:
        backend = BACKENDS[params.crypto]
    except KeyError:
        raise ParameterError(f"unknown crypto backend {params.crypto!r}; choose one of {', '.join(BACKENDS)}") from None
    return backend(params, loop_group(params.key_length))
