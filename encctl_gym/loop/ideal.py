"""The ideal backend (``crypto="ideal"``): the encrypted loop's exact arithmetic without ciphertexts.

The encode / quantise / multiply / sum / decode arithmetic of the encrypted controller
(Definition def:ec, eq:ec) without big integers. Quantisation uses the same group and the same
nearest-member rule as the encoder (through
:class:`~encctl_gym.crypto.residue_table.ResidueTable`), so it is bit-identical to decrypting
real ciphertexts (:class:`~encctl_gym.loop.elgamal.ElGamalLoop`). Batched over any number of
copies; the environment's compiled step runs its per-period arithmetic itself from
:attr:`IdealLoop.quantization`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import format_value
from ..errors import EncodingOverflowError, ResourceLimitError
from .backend import table_limit
from .injection import ADD, REPLACE, SCALE, added_row, scale_gain, scale_multipliers
from .output_feedback import controller_matrix
from .quantize import OK, Quantization, collect_states, forge_inputs
from .spec import LoopSpec

__all__ = ["IdealLoop", "MAX_TABLE_LIMIT"]

#: Largest ``|round(Delta v)|`` the ideal backend tabulates (:func:`~encctl_gym.loop.backend.table_limit`):
#: the table is built when the environment is made, at about a second per 10^6 entries on the
#: development machine, so 2^24 bounds that to seconds (the default x_bound = 256 and Delta = 4096
#: need about 2^20).
MAX_TABLE_LIMIT = 2**24


class IdealLoop:
    """Exact fixed-point arithmetic of the encrypted loop without ciphertexts (batched).

    Parameters
    ----------
    params : LoopSpec
        The environment's resolved parameters (A, B, Delta, x_bound, u_max).
    group : GroupParams
        The group whose order-q subgroup the encoder maps to (the scheme's public parameters, :meth:`~encctl_gym.loop.spec.LoopSpec.group`).
    """

    batched = True
    #: the group serves the quantisation's residue pattern only: no group of the key length is needed
    needs_key_length_group = False
    #: nothing is broken: the time charged is the cost model's
    deciphering_seconds = 0.0

    def __init__(self, params: LoopSpec, group: Any) -> None:

        self.delta = float(params.delta)
        self.x_bound = float(params.x_bound)
        self.Phi = controller_matrix(params)  # -K_lqr on x, or the output controller on [x_c; y]
        self.n, self.m = self.Phi.shape[1], params.m  # n: the controller's input xi (x, y or [x_c; y])
        self._params = params
        self._scheme = params.encryption()  # its encoder's rounding and plaintexts
        self._encoder: Any = None  # the scheme's encoder, built when an addition needs it
        self.use_group(group)

    def use_group(self, group: Any) -> None:
        """The quantisation of ``group`` (its residue table, ``Ecd(Phi)``, ``Ecd(1)``, ``Ecd(0)``)."""
        params = self._params
        self.group = group
        limit = table_limit(params, self.Phi)
        if limit > MAX_TABLE_LIMIT:
            raise ResourceLimitError(
                f"the quantisation table for x_bound = {format_value(params.x_bound)}, Delta = {format_value(params.delta)}, "
                f"u_max = {params.u_max:.4g} would tabulate |round(Delta v)| <= {format_value(limit)}, above "
                f"MAX_TABLE_LIMIT = 2^{MAX_TABLE_LIMIT.bit_length() - 1} (the table is built when the environment is made); "
                "use a smaller x_bound or delta"
            )
        try:
            self.table = self._scheme.rounding(group, limit)
        except ResourceLimitError as exc:
            raise ResourceLimitError(
                f"the quantisation table for x_bound = {params.x_bound}, Delta = {params.delta}, u_max = "
                f"{params.u_max:.4g} is too large ({exc}); use a smaller x_bound or delta"
            ) from None
        self.Phi_int = self.encode_int(self.Phi)
        self._encoder = None
        # the scheme's own check that its plaintext space holds this loop (the ciphertext backend's)
        self._scheme.quantization(self.Phi, self._scheme.encoder(group, self.delta), self.x_bound, params.u_max)
        self.quantization = Quantization(
            delta=self.delta,
            offsets=self.table.offsets,
            limit=self.table.limit,
            one=int(self.encode_int(np.array(1.0))),
            zero2=int(self.encode_int(np.array(0.0))) ** 2,
            n_cols=self.n,
            x_bound=self.x_bound,
        )
        self._quant = tuple(self.quantization)

    def encode_int(self, v: np.ndarray) -> np.ndarray:
        """Signed integer of the subgroup element that encodes ``v`` (Definition def:ec).

        Raises EncodingOverflowError for a value outside the declared range."""
        return self.table.nearest(np.rint(np.asarray(v, dtype=np.float64) * self.delta).astype(np.int64))

    def start_episode(self) -> None:
        pass

    def rotate_group(self, group: Any) -> Any:
        """Move to a fresh ``group`` (group rotation): its quantisation (:meth:`use_group`); returns
        the :class:`~encctl_gym.loop.provisioning.ProvisioningCost` the ElGamal loop has, counted
        (``n m`` encryptions of ``Ecd(Phi)``, :func:`~encctl_gym.loop.provisioning.provisioning_bytes`)."""
        import time

        from .provisioning import ProvisioningCost, provisioning_bytes

        t0 = time.perf_counter()
        self.use_group(group)
        return ProvisioningCost(self.n * self.m, provisioning_bytes(group, self.n * self.m), 1, time.perf_counter() - t0)

    def _overflow(self, x: np.ndarray) -> EncodingOverflowError:
        return EncodingOverflowError(f"state {np.asarray(x).tolist()} leaves the declared range |x| <= {self.x_bound} (x_bound)")

    def collect_state(self, x: np.ndarray) -> np.ndarray:
        """``Dcd(Ecd(x))``; raises EncodingOverflowError outside ``|x| <= x_bound`` (as the encoder does)."""
        x = np.ascontiguousarray(x, dtype=np.float64)
        out = np.empty_like(x)
        if collect_states(self._quant, x, np.empty(x.shape, dtype=np.int64), out) != OK:
            raise self._overflow(x)
        return out

    def control(self, x: np.ndarray) -> np.ndarray:
        """The quantised controller ``Dcd(Sum(Ecd(Phi) Ecd(x)); Delta^2)`` (eq:ec), products and sums in Z."""
        if not (np.abs(x) <= self.x_bound).all():  # the encoder's declared range (crypto raises alike)
            raise self._overflow(x)
        xi = self.encode_int(x)  # (K, n)
        return (self.Phi_int[None] * xi[:, None, :]).sum(-1) / (self.delta * self.delta)

    def inject(self, a: np.ndarray) -> np.ndarray:
        """The forged input as the plant decodes it (``|a| <= u_max``: inside the table)."""
        a = np.array(a, dtype=np.float64, order="C")
        out = np.empty_like(a)
        forge_inputs(self._quant, a, np.empty(a.shape, dtype=np.int64), out)
        return out

    def period_input(self, a: np.ndarray, x: np.ndarray, injection: int) -> np.ndarray:
        """The input the plant decodes this period under the injection mode (:mod:`~.injection`):
        :meth:`inject` (``REPLACE``), the controller's products of ``x`` (eq:ec) with ``a`` added
        by :func:`~encctl_gym.loop.injection.added_row` (``ADD``), or passed on (``PASS``): the
        same integers the ElGamal backend decrypts, so the same floats."""
        if injection == REPLACE:
            return self.inject(a)
        if not (np.abs(x) <= self.x_bound).all():
            raise self._overflow(x)
        products = self.Phi_int[None] * self.encode_int(x)[:, None, :]  # (K, m, n), int64 (|.| < 2^48)
        if injection == SCALE:
            return self._scaled(products.sum(-1), a)
        if injection != ADD:
            return products.sum(-1) / (self.delta * self.delta)
        if self._encoder is None:
            self._encoder = self._scheme.encoder(self.group, self.delta)
        scheme, enc, one = self._scheme, self._encoder, int(self.encode_int(np.array(1.0)))
        d2 = int(self.delta) ** 2
        u = np.empty((products.shape[0], self.m))
        for k, rows in enumerate(products.tolist()):
            for i, row in enumerate(rows):
                added = added_row(row, float(a[k, i]), self.delta, one, lambda v: scheme.nearest_plaintext(enc, v))
                u[k, i] = sum(added) / d2
        return u

    def _scaled(self, sums: np.ndarray, a: np.ndarray) -> np.ndarray:
        """``SCALE``: row ``i`` of the honest sums times ``c_i`` (:func:`~.injection.scale_multipliers`),
        the forged 0 (:meth:`inject`) where ``c_i = 0``; the integers the ElGamal plant decrypts."""
        gain = scale_gain(self.group)
        c = np.array([scale_multipliers(row, gain) for row in np.asarray(a, dtype=float)], dtype=np.int64)
        u = (c * sums) / (self.delta * self.delta)
        return np.where(c == 0, self.inject(np.zeros_like(u)), u)

    def tick(self) -> None:
        pass
