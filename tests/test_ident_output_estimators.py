"""N4SID and PO-MOESP behind the estimator protocol (issue 34 item 10): ``make_estimator("n4sid")``
on states (batch, grid of sample sizes, online) and on outputs (online in the environment), each
against the subspace functions of ``encctl_gym.ident.subspace`` run on the same data."""

from __future__ import annotations

import numpy as np
import pytest

from encctl_gym.envs import EncryptedLTIAttackEnv
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ParameterError
from encctl_gym.ident import Estimator, estimation_error, estimator_names, make_estimator
from encctl_gym.ident.output_estimators import output_estimator
from encctl_gym.ident.subspace import markov_error, moesp, n4sid

A = np.array([[0.8, 0.2], [0.0, 0.5]])
B = np.array([[1.0], [0.5]])


def _states(R: int = 3, N: int = 300, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    x = np.zeros((R, N, 2))
    u = rng.standard_normal((R, N - 1, 1))
    for t in range(N - 1):
        x[:, t + 1] = x[:, t] @ A.T + u[:, t] @ B.T + 0.1 * rng.standard_normal((R, 2))
    return x, u


@pytest.mark.parametrize(("name", "method"), [("n4sid", n4sid), ("moesp", moesp)])
def test_a_subspace_estimator_on_states_is_the_method_in_the_plants_basis(name, method):
    est = make_estimator(name)
    assert isinstance(est, Estimator) and name in estimator_names() and est.name == name
    x, u = _states()
    theta = est.fit(x, u)
    # independently: the method on y = x, then the basis where its C is the identity
    raw = method(u, x[:, :-1], 2, block_rows=4)
    for r in range(3):
        Ci = np.linalg.inv(raw.C[r])
        np.testing.assert_allclose(theta[r, :, :2], raw.C[r] @ raw.A[r] @ Ci, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(theta[r, :, 2:], raw.C[r] @ raw.B[r], rtol=1e-9, atol=1e-12)
    ls = make_estimator("ls").fit(x, u)
    err = estimation_error(A, B, theta[:, :, :2], theta[:, :, 2:])
    assert np.all(err < 0.01) and np.all(err < 10 * estimation_error(A, B, ls[:, :, :2], ls[:, :, 2:]) + 1e-3)


def test_the_grid_and_the_online_copies_give_the_batch_fit():
    est = make_estimator("n4sid")
    x, u = _states()
    grid = est.prefix_estimates(x, u, [60, 300])
    np.testing.assert_array_equal(grid[:, 1], est.fit(x, u))
    np.testing.assert_array_equal(grid[:, 0], est.fit(x[:, :60], u[:, :59]))
    est.start(3, 2, 1)
    for j in range(1, 60):
        est.update(np.concatenate([x[:, j - 1], u[:, j - 1]], axis=1), x[:, j])
        assert est.ready == (j + 1 >= est.min_sample_size(2, 1))
    np.testing.assert_array_equal(est.estimate(), grid[:, 0])
    np.testing.assert_array_equal(est.error(A, B), estimation_error(A, B, grid[:, 0, :, :2], grid[:, 0, :, 2:]))
    with pytest.raises(ParameterError, match="too small"):
        est.fit(x[:, :10], u[:, :9])


@pytest.mark.parametrize("name", ["n4sid", "moesp"])
def test_the_environment_on_outputs_runs_the_subspace_method_on_the_delivered_data(name):
    cfg = {"preset": "small-output", "observe": "output", "max_samples": 120, "key_length": 64, "x_bound": 64.0,
           "estimator": name}  # fmt: skip
    env = EncryptedLTIAttackEnv(config=cfg)
    env.reset(seed=11)
    for a in np.random.default_rng(8).uniform(-0.4, 0.4, (120, 2)):
        _, _, te, tr, info = env.step(a)
        if te or tr:
            break
    y, u = env.episode.delivered_data()
    p = env.params
    N = y.shape[1] - 1  # the last output's input was not applied when it was delivered
    method = {"n4sid": n4sid, "moesp": moesp}[name]
    want = markov_error((p.A, p.B, p.C, np.zeros((1, 2))), method(u[0, :N], y[0, :N], 2, block_rows=4), 20)
    assert info["epsilon"] == pytest.approx(want, rel=1e-9)
    assert info["epsilon"] < 0.05
    env.close()


def test_only_the_output_estimators_are_taken_with_outputs():
    assert output_estimator("n4sid").name == "n4sid" and output_estimator({"name": "moesp", "block_rows": 5}).block_rows == 5
    with pytest.raises(ParameterError, match="N4SID"):
        output_estimator("iv")
    cfg = {"preset": "small-output", "observe": "output", "max_samples": 60}
    assert resolve_params({**cfg, "estimator": "moesp"}).estimator == "moesp"
    with pytest.raises(ParameterError, match="N4SID"):
        resolve_params({**cfg, "estimator": "forgetting"})
