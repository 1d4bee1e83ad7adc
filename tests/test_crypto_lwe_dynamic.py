"""The dynamic controller on encrypted state (encctl_gym.crypto.lwe_dynamic): the conversion to a
nilpotent integer state matrix computes the same inputs, the encrypted run equals the plaintext
integer recursion bit for bit, and the noise bound stops growing (the state stays decryptable)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from encctl_gym.crypto import lwe
from encctl_gym.crypto import lwe_dynamic as D
from encctl_gym.errors import EncodingOverflowError, ParameterError

# the package's ``small-output`` plant (n = m = 2, C = [1 0]) with an observer-based controller
A = np.array([[0.6, 0.2], [-0.1, 0.5]])
B = np.array([[1.0, 0.0], [0.3, 0.8]])
C = np.array([[1.0, 0.0]])


def observer_controller() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    P = scipy.linalg.solve_discrete_are(A, B, np.eye(2), np.eye(2))
    K = -np.linalg.solve(np.eye(2) + B.T @ P @ B, B.T @ P @ A)
    Po = scipy.linalg.solve_discrete_are(A.T, C.T, np.eye(2), np.eye(1))
    L = (A @ Po @ C.T) @ np.linalg.inv(C @ Po @ C.T + np.eye(1))
    return A + B @ K - L @ C, L, K


def test_conversion_is_nilpotent_and_equivalent() -> None:
    F, G, H = observer_controller()
    form = D.integer_state_form(F, G, H)
    assert np.array_equal(form.S, np.eye(2, k=1))
    assert np.allclose(form.H[0], [1.0, 0.0])  # the re-encrypted output is the first state
    rng = np.random.default_rng(0)
    z, zc = np.zeros(2), np.zeros(2)
    for y in rng.normal(size=(30, 1)):
        u, uc = H @ z, form.H @ zc
        assert np.allclose(u, uc, atol=1e-12)
        z, zc = F @ z + G @ y, form.S @ zc + form.G @ y + form.R @ uc[[0]]
    with pytest.raises(ParameterError, match="observable"):
        D.integer_state_form(np.eye(2), np.ones((2, 1)), np.array([[1.0, 0.0]]))


def test_encrypted_run_equals_the_plaintext_recursion_and_stays_decryptable() -> None:
    F, G, H = observer_controller()
    params = lwe.LWEParams(n=64, q=2**55, t=2**29, eta=2)
    ctl = D.LWEDynamicController(params, F, G, H, 2**8, 2**8, 2**8, 20.0, rng=3)
    rng = np.random.default_rng(1)
    x = rng.normal(size=2)
    ys, us, bounds = [], [], []
    for _ in range(200):
        y = C @ x
        u = ctl.step(y)
        ys.append(y)
        us.append(u)
        bounds.append(max(ctl.z.noise_bound))
        x = A @ x + B @ u + rng.normal(0.0, 0.1, 2)
    assert np.array_equal(D.plaintext_twin(ctl, np.array(ys)), np.array(us))
    assert bounds[-1] == bounds[10] <= params.max_noise  # the bound is constant after n_z steps
    assert np.abs(x).max() < 5.0  # the loop is stable through the encrypted controller
    with pytest.raises(EncodingOverflowError, match="steady-state noise"):
        D.LWEDynamicController(lwe.LWEParams(n=64, q=2**40, t=2**20), F, G, H, 2**8, 2**8, 2**8, 20.0, rng=3)
