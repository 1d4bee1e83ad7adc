"""The compiled online form of the moment estimators (ident.compiled.MomentKernels): the episode
runs Bayes, forgetting and instrumental variables on it, with the estimates of the
column-by-column update of the same estimator (to 1e-10 relative) on a seeded episode."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import encctl_gym  # noqa: F401  (registers the environment)
from encctl_gym.envs import ENV_ID
from encctl_gym.envs.steps import CompiledIdealStep
from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv
from encctl_gym.ident import make_estimator
from encctl_gym.ident.compiled import MomentKernels, ProvidesKernels

BASE = {"preset": "paper-example", "gamma_opt": False, "max_samples": 120}
SPECS = ["bayes", "forgetting", {"name": "forgetting", "forgetting_factor": 0.95}, "iv", {"name": "iv", "lags": 2}]


def generic(spec):
    """The same estimator without its compiled form: the episode updates it column by column."""
    est = make_estimator(spec)
    est.__class__ = type(f"ColumnByColumn{type(est).__name__}", (type(est),), {"online_kernels": None})
    assert not isinstance(est, ProvidesKernels)
    return est


def trajectories(env, steps, K):
    """Per step: the estimates ``(K, n, n + m)`` (NaN before any) and epsilon of every copy."""
    env.reset(seed=3)
    core = env.unwrapped.episode if hasattr(env, "unwrapped") else env.episode
    rng = np.random.default_rng(8)
    out = []
    for _ in range(steps):
        a = rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
        _, _, te, tr, _ = env.step(a)
        if core.kernels is not None:
            theta = core.kernels.theta.copy()
        else:
            est = core.estimator
            theta = est.estimate() if est.ready else np.full_like(core.kernels_theta_shape, np.nan)
        out.append((theta, core.eps.copy()))
        if np.any(te) or np.any(tr):
            break
    return out


@pytest.mark.parametrize("spec", SPECS, ids=str)
@pytest.mark.parametrize("K", [1, 3])
def test_the_compiled_form_gives_the_column_by_column_estimates(spec, K):
    def make(est):
        cfg = {**BASE, "estimator": est}
        return gym.make(ENV_ID, config=cfg) if K == 1 else EncryptedLTIAttackVectorEnv(num_envs=K, config=cfg)

    fast, slow = make(spec), make(generic(spec))
    fcore = fast.unwrapped.episode if K == 1 else fast.episode
    score = slow.unwrapped.episode if K == 1 else slow.episode
    assert isinstance(fcore.kernels, MomentKernels) and fcore.estimator is None
    assert type(fcore.stepper) is CompiledIdealStep and score.kernels is None
    n, d = fcore.n, fcore.d
    score.kernels_theta_shape = np.empty((K, n, d))
    got, want = trajectories(fast, 119, K), trajectories(slow, 119, K)
    assert len(got) == len(want) == 119
    compared = 0
    for (tg, eg), (tw, ew) in zip(got, want, strict=True):
        assert np.array_equal(np.isnan(tg), np.isnan(tw))
        ok = ~np.isnan(tw)
        if ok.any():
            scale = np.abs(tw[ok]).max()
            assert np.abs(tg[ok] - tw[ok]).max() <= 1e-10 * scale
            compared += 1
        np.testing.assert_allclose(eg, ew, rtol=1e-10, atol=0)
    assert compared > 90  # the estimates exist for most of the episode
