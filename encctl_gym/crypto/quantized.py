"""The quantised twin of the encrypted linear controller psi = Phi xi (Definition def:ec, eq:ec).

What the encrypted controller computes follows from integers alone: Phi and xi are encoded to
the signed integers of Definition def:ec (the integers whose residues the plant encrypts), the
products and row sums are exact in Z (``Sum`` of eq:ec; a row sum never wraps modulo p, which
the constructor checks for every ``|xi_j| <= x_bound``), and the sums are decoded with
``Delta**2``. The plant parties (:mod:`.plant_side`) encode with it and decode with it, so the
encrypted loop and this twin agree bit for bit.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_nonnegative, format_value
from ..errors import EncodingOverflowError, ParameterError
from .encoding import Encoder

__all__ = ["QuantizedLinearController"]


class QuantizedLinearController:
    """psi = Phi xi with exactly the quantisation of the encrypted controller (no ciphertexts).

    Phi and xi are encoded to the signed integers of Definition def:ec (the same integers
    whose residues the plant encrypts), multiplied and summed in Z, and decoded with
    ``Delta**2``. :class:`~.controller.EncryptedLinearController` decrypts to the same floats,
    bit for bit; the plant parties use it for their encoding, and the environment's ideal
    backend (:mod:`encctl_gym.loop.ideal`) is tested against it.

    Parameters
    ----------
    Phi : array_like, shape (alpha, beta)
        Controller parameter (finite).
    encoder : Encoder
        Encoder (group, Delta, max_shift) for Phi and the state.
    x_bound : float
        Declared bound on the controller input: ``|xi_j| <= x_bound``.

    Attributes
    ----------
    phi_int : numpy.ndarray of object, shape (alpha, beta)
        The signed integers encoding Phi.
    state_encoder : Encoder
        ``encoder`` restricted to the range ``|x| <= x_bound``.

    Raises
    ------
    ParameterError
        If Phi is not a finite 2-D array or ``x_bound`` is negative or not finite.
    EncodingOverflowError
        If, for some ``|xi_j| <= x_bound``, a product or a row sum could reach ``(p-1)/2``
        in magnitude (it would wrap modulo p), or Phi itself is not representable.
    """

    def __init__(self, Phi: Any, encoder: Encoder, x_bound: float) -> None:
        if not isinstance(encoder, Encoder):
            raise ParameterError(f"encoder must be an Encoder, got {format_value(encoder)}")
        phi = as_finite_array("Phi", Phi)
        if phi.ndim == 1:
            phi = phi.reshape(1, -1)
        if phi.ndim != 2:
            raise ParameterError(f"Phi must be a 2-D matrix, got shape {phi.shape}")
        self.Phi = phi
        self.alpha, self.beta = phi.shape
        self.encoder = encoder
        self.group = encoder.group
        self.x_bound = check_nonnegative("x_bound", x_bound)
        self.state_encoder = Encoder(encoder.group, encoder.delta, x_bound=self.x_bound, max_shift=encoder.max_shift)
        self.phi_int = encoder.encode_signed_array(phi)
        # Worst case over |xi_j| <= x_bound: |w_xi| <= round(Delta x_bound) + max_shift.
        w_max = self.state_encoder.max_abs_signed(self.x_bound)
        half = self.group.half
        for i in range(self.alpha):
            row_abs = sum(abs(w) for w in self.phi_int[i])
            if row_abs * w_max >= half:
                raise EncodingOverflowError(
                    f"row {i} of Phi can overflow: sum_j |Ecd(Phi_{i}j)| * (round(Delta x_bound) "
                    f"+ max_shift) = {row_abs * w_max} >= (p-1)/2 for a {self.group.bits}-bit "
                    f"group (Delta = {encoder.delta!r}, x_bound = {self.x_bound!r}); use a "
                    f"larger group or a smaller Delta or x_bound"
                )
        self._phi_rows = [[int(w) for w in row] for row in self.phi_int]

    def encode_state(self, x: Any) -> list[int]:
        """The signed integers encoding the controller input xi (checks shape, type, NaN, range)."""
        xi = as_finite_array("x", x)  # refuses complex, boolean and text entries
        if xi.size != self.beta or (xi.ndim > 1 and max(xi.shape) != xi.size):
            raise ParameterError(f"x must have {self.beta} entries, got shape {np.shape(x)}")
        xi = xi.reshape(self.beta)
        return [int(w) for w in self.state_encoder.encode_signed_array(xi)]

    def row_sums(self, w_xi: Sequence[int]) -> list[int]:
        """``Sum`` of eq:ec over the integer products: ``sum_j w_Phi_ij w_xi_j`` in Z."""
        return [sum(a * b for a, b in zip(row, w_xi)) for row in self._phi_rows]

    def decode_row_sums(self, sums: Sequence[int]) -> np.ndarray:
        """Decode integer row sums with ``Delta**2`` (exactly rounded floats)."""
        return self.encoder.decode_signed_array(np.asarray(list(sums), dtype=object), power=2)

    def compute(self, x: Any) -> np.ndarray:
        """The controller output psi = Dcd(Sum(Ecd(Phi) Ecd(x)); Delta^2), shape (alpha,)."""
        return self.decode_row_sums(self.row_sums(self.encode_state(x)))

    __call__ = compute

    def __repr__(self) -> str:
        return (
            f"QuantizedLinearController(alpha={self.alpha}, beta={self.beta}, encoder={self.encoder!r}, x_bound={self.x_bound!r})"
        )
