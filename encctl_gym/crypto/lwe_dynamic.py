"""A dynamic controller whose state stays encrypted under LWE: integer state matrix, output re-encryption.

The controller ``z_{t+1} = F z_t + G y_t``, ``u_t = H z_t`` (z of dimension n_z) is run by the
server on ``Enc(z)`` for an unbounded time in the way of J. Kim, H. Shim, K. Han, "Dynamic
controller that operates over homomorphically encrypted data for infinite time horizon", IEEE
TAC 2023: the plant re-encrypts one controller output ``v_t = h z_t`` (a row ``h`` of ``H``)
and sends it back, so that the state update may be rewritten with ``F - R h`` in place of ``F``;
with an integer state matrix no scale accumulates, since the server only multiplies by integers.

The choice of ``R`` here (one of the possible conversions, stated): ``R`` places every
eigenvalue of ``F - R h`` at 0 (Ackermann's formula for the deadbeat observer), and the
coordinates ``z' = O z`` with the observability matrix ``O = [h; h F_bar; ...; h F_bar^{n_z - 1}]``
make ``F_bar' = O (F - R h) O^{-1}`` the upper shift matrix (ones above the diagonal, since
``F_bar^{n_z} = 0``): integer and nilpotent. The converted controller::

    z'_{t+1} = S z'_t + (O G) y_t + (O R) v_t,   u_t = (H O^{-1}) z'_t,   v_t = h z_t

computes the same inputs as the original one (exactly, before quantisation). Because ``S`` is
nilpotent, the noise of ``Enc(z')`` is a sum over the last n_z steps only: its worst-case bound
(tracked by :mod:`encctl_gym.crypto.lwe`) stops growing after n_z steps, and
:class:`LWEDynamicController` checks the bound of that steady state once, at construction.

Scales: ``y_int = round(Delta_y y)``, ``v_int = round(Delta_y v)`` (the plant's re-encryption),
``G_int = round(Delta_G O G)``, ``R_int = round(Delta_G O R)``, so the state message is at scale
``Delta_G Delta_y``; ``H_int = round(Delta_H H O^{-1})`` puts ``u`` at ``Delta_H Delta_G Delta_y``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, check_positive, format_value
from ..errors import EncodingOverflowError, ParameterError, ShapeError
from . import lwe
from .arith import RngLike

__all__ = ["IntegerStateForm", "integer_state_form", "LWEDynamicController", "plaintext_twin"]


class IntegerStateForm:
    """The converted controller ``(S, G', R', H')`` of the module docstring, with the row ``h``."""

    def __init__(self, S: np.ndarray, G: np.ndarray, R: np.ndarray, H: np.ndarray, row: int) -> None:
        self.S, self.G, self.R, self.H, self.row = S, G, R, H, row


def integer_state_form(F: Any, G: Any, H: Any, row: int = 0, max_condition: float = 1e8) -> IntegerStateForm:
    """Convert ``(F, G, H)`` to the nilpotent integer state matrix form (module docstring).

    Raises
    ------
    ShapeError
        If the shapes do not fit.
    ParameterError
        If ``(F, h)`` is not observable (the observability matrix's condition number exceeds
        ``max_condition``), naming it.
    """
    F, G, H = as_finite_array("F", F, ndim=2), as_finite_array("G", G, ndim=2), as_finite_array("H", H, ndim=2)
    nz = F.shape[0]
    if F.shape != (nz, nz) or G.shape[0] != nz or H.shape[1] != nz:
        raise ShapeError(f"F must be square, G have {nz} rows and H {nz} columns; got {F.shape}, {G.shape}, {H.shape}")
    row = check_int("row", row, minimum=0, maximum=H.shape[0] - 1)
    h = H[row : row + 1]
    obs = np.vstack([h @ np.linalg.matrix_power(F, k) for k in range(nz)])
    cond = float(np.linalg.cond(obs))
    if not cond <= max_condition:
        raise ParameterError(
            f"(F, H[{row}]) is not observable enough: the observability matrix has condition {cond:.3g} > {max_condition:g}"
        )
    # Ackermann: R = p(F) O^-1 e_n with p(s) = s^nz places every eigenvalue of F - R h at 0
    e_last = np.zeros((nz, 1))
    e_last[-1, 0] = 1.0
    R = np.linalg.matrix_power(F, nz) @ np.linalg.solve(obs, e_last)
    Fbar = F - R @ h
    obs_bar = np.vstack([h @ np.linalg.matrix_power(Fbar, k) for k in range(nz)])
    return IntegerStateForm(np.eye(nz, k=1), obs_bar @ G, obs_bar @ R, H @ np.linalg.inv(obs_bar), row)


class LWEDynamicController:
    """The converted controller run on encrypted state (module docstring).

    Parameters
    ----------
    params : LWEParams
    F, G, H : arrays
        The controller (``z+ = F z + G y``, ``u = H z``), with ``(F, H[row])`` observable.
    delta_y, delta_g, delta_h : float
        Scales of the measurement (and the re-encrypted output), of ``G``/``R``, and of ``H``.
    y_bound : float
        Largest ``|y_j|`` and ``|v|`` the plant encrypts.
    rng : RandomSource, numpy Generator or None
        The plant's randomness.

    Raises
    ------
    EncodingOverflowError
        If the steady-state noise or message bound does not fit the parameters.
    """

    def __init__(
        self, params: lwe.LWEParams, F: Any, G: Any, H: Any, delta_y: float, delta_g: float, delta_h: float,
        y_bound: float, *, row: int = 0, rng: RngLike = None,
    ) -> None:  # fmt: skip
        self.form = integer_state_form(F, G, H, row)
        self.params = params
        self.dy, self.dg, self.dh = (
            check_positive(n, v) for n, v in (("delta_y", delta_y), ("delta_g", delta_g), ("delta_h", delta_h))
        )
        self.y_bound = check_positive("y_bound", y_bound)
        self.S = self.form.S.astype(np.int64)
        self.G_int, self.R_int = lwe.encode(self.form.G, self.dg), lwe.encode(self.form.R, self.dg)
        self.H_int = lwe.encode(self.form.H, self.dh)
        self.update = np.hstack([self.S, self.G_int, self.R_int])  # [S | G_int | R_int] on (z, y, v)
        self._stream = lwe.ByteStream(rng, "lwe dynamic controller")
        self.pk, self._sk = lwe.keygen(params, self._stream)
        self._check_steady_state()
        self.z = lwe.encrypt(self.pk, np.zeros(self.S.shape[0], dtype=np.int64), self._stream)

    def _check_steady_state(self) -> None:
        # the bound recursion of (noise, message) of Enc(z'), iterated past the nilpotency index
        p, nz = self.params, self.S.shape[0]
        y_msg = int(round(self.dy * self.y_bound))
        ny, nv = self.G_int.shape[1], self.R_int.shape[1]
        noise, msg = [p.fresh_noise_bound] * nz, [0] * nz
        absU = np.abs(self.update).astype(object)
        for _ in range(nz + 1):
            noise = list(absU @ np.array(noise + [p.fresh_noise_bound] * (ny + nv), dtype=object))
            msg = list(absU @ np.array(msg + [y_msg] * (ny + nv), dtype=object))
        absH = np.abs(self.H_int).astype(object)
        bounds = [int(v) for v in absH @ np.array(noise, dtype=object)], [int(v) for v in absH @ np.array(msg, dtype=object)]
        for name, worst, limit in (
            ("noise", max(max(noise), max(bounds[0])), p.max_noise),
            ("message", max(max(msg), max(bounds[1])), p.max_message),
        ):
            if worst > limit:
                raise EncodingOverflowError(
                    f"the encrypted controller state's steady-state {name} bound {worst} exceeds the parameters' limit {limit}; "
                    "use a larger q (noise) or t (message), or smaller scales"
                )

    def _encrypt_signal(self, w: Any, name: str) -> lwe.LWECiphertext:
        w = as_finite_array(name, w, ndim=1)
        if float(np.abs(w).max(initial=0.0)) > self.y_bound:
            raise EncodingOverflowError(f"{name} = {format_value(w)} is outside |.| <= y_bound = {self.y_bound:g}")
        return lwe.encrypt(self.pk, lwe.encode(w, self.dy), self._stream)

    def output(self) -> np.ndarray:
        """Server ``Enc(u) = H_int Enc(z')``; plant Dec and Dcd: the input ``u_t``."""
        ct_u = lwe.linear_combination(self.H_int, self.z)
        return lwe.decrypt(self._sk, ct_u).astype(np.float64) / (self.dh * self.dg * self.dy)

    def step(self, y: Any) -> np.ndarray:
        """One period: the input ``u_t`` from the encrypted state, then the state update with
        ``Enc(y_t)`` and the re-encrypted ``v_t = u_t[row]``."""
        y = as_finite_array("y", y, ndim=1)
        if y.shape[0] != self.G_int.shape[1]:
            raise ShapeError(f"y must have {self.G_int.shape[1]} entries, got {y.shape[0]}")
        u = self.output()
        stacked = lwe.concatenate(self.z, self._encrypt_signal(y, "y"), self._encrypt_signal(u[[self.form.row]], "v"))
        self.z = lwe.linear_combination(self.update, stacked)
        return u


def plaintext_twin(ctl: LWEDynamicController, ys: Any) -> np.ndarray:
    """The same integer recursion without encryption (the reference of the tests): the inputs
    ``u_t`` for the measurements ``ys`` (shape (T, p))."""
    z = np.zeros(ctl.S.shape[0], dtype=object)
    out = []
    scale = ctl.dh * ctl.dg * ctl.dy
    for y in np.asarray(ys, dtype=float):
        u_int = ctl.H_int.astype(object) @ z
        u = np.array([float(v) for v in u_int]) / scale
        out.append(u)
        stacked = np.concatenate([z, lwe.encode(y, ctl.dy).astype(object), lwe.encode(u[[ctl.form.row]], ctl.dy).astype(object)])
        z = ctl.update.astype(object) @ stacked
    return np.array(out)
