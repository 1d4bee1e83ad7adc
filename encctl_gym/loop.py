"""The closed loop behind the plant's input: encrypted controller, or an adversary's injection.

Two interchangeable backends with one interface, used by the attack environment:

* :class:`IdealLoop` (``crypto="ideal"``): the exact encode / quantise / multiply / sum /
  decode arithmetic of the encrypted controller (Definition def:ec, eq:ec), without big
  integers. Quantisation uses the same group and the same nearest-member rule as the encoder
  (through :class:`~encctl_gym.crypto.residue_table.ResidueTable`), so it is bit-identical to
  decrypting real ciphertexts. Batched over any number of copies.
* :class:`ElGamalLoop` (``crypto="elgamal"``): real dynamic-key ElGamal ciphertexts, keys
  updated every period, with the modified evaluation/decryption of Definition def:modification
  (``scheme="modified"``), the conventional token-based dynamic key (``"token"``) or one fixed
  key pair (``"static"``). One copy.

Per sampling period: :meth:`collect_state` (the plant encrypts ``x_t``; the adversary breaks the
ciphertext and reads ``Dcd(Ecd(x_t))``), then :meth:`control` (warm-up: the encrypted
controller computes ``u_t = Phi x_t``) or :meth:`inject` (attack: the adversary forges the input
ciphertext from public keys only and the plant decrypts it), then :meth:`tick` (key update).

The forged input. The plant decrypts an ``m x n`` matrix of product ciphertexts, sums each row
and decodes with ``Delta^2`` (eq:ec). To make row ``i`` read ``a_i``, the adversary puts the
product ``Ecd(1) Ecd(a_i)`` in column 0 and ``Ecd(0) Ecd(0)`` in the others; the plant
then applies ``u_i = (Ecd(a_i) Ecd(1) + (n - 1) Ecd(0)^2) / Delta^2``, i.e. ``a_i`` quantised
at ``1/Delta`` plus a known offset of ``(n - 1)/Delta^2`` (0 is not in the group; its nearest
member is 1).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import scipy.linalg

from .errors import ParameterError

__all__ = ["lqr_gain", "IdealLoop", "ElGamalLoop", "make_loop", "table_limit"]


def lqr_gain(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Discrete-time LQR gain ``K`` (``u = -K x``, Q = I, R = I) for the warm-up controller."""
    P = scipy.linalg.solve_discrete_are(A, B, np.eye(A.shape[0]), np.eye(B.shape[1]))
    return np.linalg.solve(np.eye(B.shape[1]) + B.T @ P @ B, B.T @ P @ A)


def table_limit(params: Any, Phi: np.ndarray) -> int:
    """Largest ``|round(Delta v)|`` the loop must quantise: states, inputs, controller entries."""
    span = max(params.x_bound, params.u_max, float(np.abs(Phi).max()) if Phi.size else 0.0, 1.0)
    return int(math.ceil(params.delta * span)) + 1


class IdealLoop:
    """Exact fixed-point arithmetic of the encrypted loop without ciphertexts (batched)."""

    def __init__(self, params: Any, group: Any) -> None:
        from .crypto.residue_table import residue_table

        self.delta = float(params.delta)
        self.n, self.m = params.n, params.m
        self.Phi = -lqr_gain(params.A, params.B)
        self.table = residue_table(int(group.p), table_limit(params, self.Phi))
        self.Phi_int = self.encode_int(self.Phi)
        self._one = int(self.encode_int(np.array(1.0)))
        self._zero2 = int(self.encode_int(np.array(0.0))) ** 2

    def encode_int(self, v: np.ndarray) -> np.ndarray:
        """Signed integer of the subgroup element that encodes ``v`` (Definition def:ec).

        Raises EncodingOverflowError for a value outside the declared range."""
        return self.table.nearest(np.rint(np.asarray(v, dtype=np.float64) * self.delta).astype(np.int64))

    def _encode_in_range(self, v: np.ndarray) -> np.ndarray:
        # for values already bounded by construction (clipped actions): no range check
        i = np.rint(v * self.delta).astype(np.int64)
        return i + self.table.offset_at(i)

    def start_episode(self) -> None:
        pass

    def collect_state(self, x: np.ndarray) -> np.ndarray:
        return self.encode_int(x) / self.delta

    def control(self, x: np.ndarray) -> np.ndarray:
        xi = self.encode_int(x)  # (K, n)
        return (self.Phi_int[None] * xi[:, None, :]).sum(-1) / (self.delta * self.delta)

    def inject(self, a: np.ndarray) -> np.ndarray:
        # |a| <= u_max by the actuator bound, inside the table range (table_limit)
        return (self._encode_in_range(a) * self._one + (self.n - 1) * self._zero2) / (self.delta * self.delta)

    def tick(self) -> None:
        pass


def make_loop(params: Any) -> Any:
    """The loop backend selected by ``params.crypto``."""
    from .crypto.group import get_group

    group = get_group(params.key_length)
    if params.crypto == "ideal":
        return IdealLoop(params, group)
    if params.crypto == "elgamal":
        return ElGamalLoop(params, group)
    raise ParameterError(f"unknown crypto backend {params.crypto!r}")


class ElGamalLoop:  # filled in below once the crypto controller API is fixed
    def __init__(self, params: Any, group: Any) -> None:
        raise ParameterError("the elgamal backend is not available yet")
