"""agents.stealth through the environment: every class on the ideal and the ElGamal backend (the
same inputs, bit for bit), the innovation the detectors see against security.stealth, the keyless
row gains of injection='scale', and the one-line errors."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import encctl_gym  # noqa: F401  (registers the environment)
from encctl_gym.agents.evaluate import elgamal_config
from encctl_gym.agents.stealth import STEALTH_ATTACKERS, AdditiveAttacker, MalleabilityAttacker, SparseAttacker
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ParameterError
from encctl_gym.experiments.compare.attackers import ATTACKERS, DEFAULT_ATTACKERS
from encctl_gym.loop.backend import lqr_gain
from encctl_gym.security.stealth import innovation_covariance

ENV = "encctl_gym/EncryptedLTIAttack-v0"

CASES = [
    ("additive", "add", 0, {"ratio": 1e-2}),
    ("additive", "replace", 0, {"ratio": 1e-2}),
    ("additive", "replace", 2, {"ratio": 1e-2}),
    ("sparse", "add", 0, {"q": 0.2, "level": 0.5}),
    ("sparse", "replace", 0, {"q": 0.2, "level": 0.5}),
    ("malleability", "scale", 0, {"q": 0.3}),
]


def _play(cfg, name, opts, seed=5):
    env = gym.make(ENV, config=cfg)
    att = STEALTH_ATTACKERS.build(name, params=env.unwrapped.params, **opts)
    obs, _ = env.reset(seed=seed)
    att.reset(seed)
    states, inputs = [obs[:4].copy()], []
    while True:
        obs, _, term, trunc, info = env.step(att.act(obs))
        states.append(obs[:4].copy())
        inputs.append(obs[4:8].copy())
        if term or trunc:
            return np.array(states), np.array(inputs), info


@pytest.mark.parametrize(("name", "injection", "delay", "opts"), CASES)
def test_every_class_runs_through_both_backends_alike(name, injection, delay, opts):
    base = {"preset": "paper-example", "decipher_delay": delay, "injection": injection, "gamma_opt": False}
    cfg_e = elgamal_config(base, 40, key_length=64)
    cfg_i = {k: v for k, v in cfg_e.items() if k not in ("crypto", "crypto_seed")}
    xi, ui, info_i = _play(cfg_i, name, opts)
    xe, ue, info_e = _play(cfg_e, name, opts)
    assert len(ui) == 40
    assert np.array_equal(ui, ue) and np.array_equal(xi, xe)
    assert info_i["epsilon"] == info_e["epsilon"]


def test_additive_innovation_has_the_closed_form_covariance():
    """x_{t+1} - A_cl x_t of an additive attack (ideal backend, delivered states) against
    sigma_w2 I + B Sigma_d B^T: the covariance the KL of security.stealth is computed from."""
    p = resolve_params({"preset": "paper-example", "decipher_delay": 0, "injection": "add", "max_samples": 4000})
    cfg = {"preset": "paper-example", "decipher_delay": 0, "injection": "add", "max_samples": 4000, "gamma_opt": False}
    x, _, _ = _play(cfg, "additive", {"sigma_d2": 1.0}, seed=3)
    A_cl = p.A - p.B @ lqr_gain(p.A, p.B)
    r = x[1:] - x[:-1] @ A_cl.T
    S1 = innovation_covariance(p.B, p.sigma_w2, np.eye(4))
    se = np.sqrt((S1 * S1 + np.outer(np.diag(S1), np.diag(S1))) / len(r))  # Wishart entries' s.e.
    assert np.all(np.abs(np.cov(r.T) - S1) < 5 * se + 1e-3)


def test_malleability_applies_row_gains_in_zero_one_and_c_plus():
    cfg = {"preset": "paper-example", "decipher_delay": 0, "injection": "scale", "max_samples": 300, "gamma_opt": False}
    p = resolve_params(cfg)
    att = MalleabilityAttacker(p, q=0.5)
    x, u, _ = _play(cfg, "malleability", {"q": 0.5})
    honest = x[:-1] @ (-lqr_gain(p.A, p.B)).T
    sep = np.abs(honest) > 0.15  # the candidates c (Phi x)_i lie 0.15 apart, beyond the encoding's error
    gains = np.array([0.0, 1.0, float(att.gain)])
    err = np.abs(u[..., None] - gains * honest[..., None])[sep]  # (entries, 3)
    assert np.all(err.min(axis=1) < 0.03)
    assert set(np.argmin(err, axis=1)) == {0, 1, 2}
    assert att.delta_second_moment == pytest.approx(0.5 * (att.gain - 1))


def test_sparse_honest_steps_pass_every_audit():
    for injection in ("add", "replace"):
        cfg = {"preset": "paper-example", "decipher_delay": 0, "injection": injection, "max_samples": 200, "gamma_opt": False}
        _, u, info = _play({**cfg, "defender": {"name": "audit", "rate": 1.0}}, "sparse", {"q": 1e-12})
        assert len(u) == 200 and not info["detected"]
        _, _, info = _play({**cfg, "defender": {"name": "audit", "rate": 1.0}}, "sparse", {"q": 1.0, "level": 0.5})
        assert info["detected"]


def test_errors_are_one_line_parameter_errors():
    add = resolve_params({"preset": "paper-example", "decipher_delay": 0, "injection": "add"})
    rep_end = resolve_params({"preset": "paper-example", "decipher_delay": "end"})
    passing = resolve_params({"preset": "paper-example", "injection": "pass"})
    with pytest.raises(ParameterError, match="injection='scale'"):
        MalleabilityAttacker(add)
    with pytest.raises(ParameterError, match="decipher_delay='end'"):
        AdditiveAttacker(rep_end)
    with pytest.raises(ParameterError, match="injection in"):
        SparseAttacker(passing)
    with pytest.raises(ParameterError, match="q must lie in"):
        SparseAttacker(add, q=0.0)
    with pytest.raises(ParameterError, match="sigma_d2"):
        AdditiveAttacker(add, sigma_d2=-1.0)
    import encctl_gym.loop.paillier_scheme  # noqa: F401  (registers "paillier")

    with pytest.raises(ParameterError, match="scale"):
        resolve_params({"preset": "paper-example", "scheme": "paillier", "injection": "scale"})
    with pytest.raises(ParameterError, match="unknown injection"):
        resolve_params({"preset": "paper-example", "injection": "stealth"})


def test_registered_for_compare_without_changing_its_default():
    assert {"additive", "sparse"} <= set(ATTACKERS) and DEFAULT_ATTACKERS == ("gaussian", "prbs", "colored", "optimal")
    assert set(STEALTH_ATTACKERS) == {"additive", "sparse", "malleability"}
