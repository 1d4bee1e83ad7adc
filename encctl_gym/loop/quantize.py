"""The exact fixed-point arithmetic of the encrypted loop, compiled (numba), for the ideal backend.

The encrypted controller's numbers (Definition def:ec, eq:ec) follow from integers alone:
``Ecd(v)`` is the signed integer of the order-q subgroup element nearest to ``round(Delta v)``
(the residue table of :mod:`encctl_gym.crypto.residue_table` gives its offset), products and
sums are exact in Z, and decoding divides by ``Delta`` or ``Delta^2``. The two stages here are
the ideal backend's per-period work in that arithmetic, written once and used both by
:class:`~encctl_gym.loop.ideal.IdealLoop` (through the batched wrappers) and, inlined, by the
environment's fused step (:mod:`encctl_gym.envs._kernels`):

* :func:`_collect`: the deciphered state ``Dcd(Ecd(x))`` an adversary reads after breaking the
  state ciphertexts;
* :func:`_forge`: the input the plant decodes from the adversary's forged output ciphertexts,
  ``(Ecd(a) Ecd(1) + (n - 1) Ecd(0)^2) / Delta^2``. Its big-integer reference is
  :func:`encctl_gym.attacks.forgery.injection_value`, which the tests compare it with.

Both work on a range of copies ``k0 <= k < k1`` with each copy's arithmetic in a fixed order, so
copy ``k`` of a batch computes bit for bit what a lone copy computes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from .._jit import install_compile_notice

install_compile_notice()  # one line on stderr before the first compile (encctl_gym._jit)

__all__ = ["Quantization", "OK", "STATE_OVERFLOW", "forge_inputs", "collect_states"]

# status codes of the compiled stages
OK = 0
STATE_OVERFLOW = 1


class Quantization(NamedTuple):
    """Everything the compiled stages need of the loop's fixed-point arithmetic.

    The kernels take it as a plain tuple (``tuple(q)``: numba dispatches plain tuples as fast
    as separate arguments) and unpack it in this field order.

    Attributes
    ----------
    delta : float
        The scaling factor Delta of Definition def:ec.
    offsets : numpy.ndarray of int16
        ``nearest(v) = v + offsets[v + limit]``: the residue table's offsets to the nearest
        subgroup element, for ``|v| <= limit``.
    limit : int
        Largest ``|round(Delta v)|`` the table covers.
    one : int
        ``Ecd(1)``, the signed integer encoding 1.
    zero2 : int
        ``Ecd(0)^2`` (0 is not in the group; its nearest member is 1).
    n_cols : int
        Columns of the controller's output matrix (beta = n): a forged row sums ``n_cols`` products.
    x_bound : float
        The encoder's declared state range ``|x| <= x_bound``.
    """

    delta: float
    offsets: np.ndarray
    limit: int
    one: int
    zero2: int
    n_cols: int
    x_bound: float


@njit(inline="always")
def _forge(k0, k1, m, quant, a_buf, q_buf, U, u_at):
    """The input the plant decodes from the forged output, ``(Ecd(a) Ecd(1) + (n - 1) Ecd(0)^2) /
    Delta^2``, into ``a_buf`` and ``U[u_at]``. ``|a| <= u_max`` lies inside the table by
    construction (:func:`encctl_gym.loop.backend.table_limit`), so no range check is needed."""
    delta, offset, limit, one, zero2, n_cols, x_bound = quant
    dd = delta * delta
    for k in range(k0, k1):
        for j in range(m):
            i = np.int64(np.rint(a_buf[k, j] * delta))
            q_buf[k, j] = i + offset[i + limit]
            a_buf[k, j] = (q_buf[k, j] * one + (n_cols - 1) * zero2) / dd
            U[u_at, k, j] = a_buf[k, j]


@njit(inline="always")
def _collect(k0, k1, n, quant, x, X, collect_at, qx_buf):
    """The deciphered state ``Dcd(Ecd(x))`` into ``X[collect_at]``; STATE_OVERFLOW if an entry
    leaves the encoder's declared range ``|x| <= x_bound`` (NaN included) or the table."""
    delta, offset, limit, one, zero2, n_cols, x_bound = quant
    for k in range(k0, k1):
        for i in range(n):
            v = x[k, i]
            if not abs(v) <= x_bound:
                return STATE_OVERFLOW
            q = np.int64(np.rint(v * delta))
            if q > limit or q < -limit:
                return STATE_OVERFLOW
            qx_buf[k, i] = q + offset[q + limit]
        for i in range(n):
            X[collect_at, k, i] = qx_buf[k, i] / delta
    return OK


@njit(cache=True, nogil=True)
def forge_inputs(quant, a, q_buf, out):
    """Batched :func:`_forge`: ``out[k]`` is the input the plant decodes for the forged ``a[k]``
    (``a`` (K, m) is overwritten with it too)."""
    _forge(0, a.shape[0], a.shape[1], quant, a, q_buf, out.reshape((1,) + out.shape), 0)


@njit(cache=True, nogil=True)
def collect_states(quant, x, q_buf, out):
    """Batched :func:`_collect`: ``out[k] = Dcd(Ecd(x[k]))``; returns a status code."""
    return _collect(0, x.shape[0], x.shape[1], quant, x, out.reshape((1,) + out.shape), 0, q_buf)
