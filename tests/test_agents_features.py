"""Observation features of learned attackers (agents.features): the dither columns, their
seeding (common random numbers), the VecEnv and the attacker computing the same columns."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("stable_baselines3")

from encctl_gym.agents.config import load_config, validate_config
from encctl_gym.agents.features import FEATURES, DitherFeature, FeatureSet, check_features
from encctl_gym.agents.sb3 import SB3VecEnv
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ConfigError

SMALL = {"preset": "small", "gamma_opt": False}


def test_dither_columns_follow_the_selected_ones():
    venv = SB3VecEnv(SMALL, 3, "no_budget", features=["dither"])
    plain = SB3VecEnv(SMALL, 3, "no_budget")
    m = venv.params.m
    assert venv.observation_space.shape[0] == plain.observation_space.shape[0] + m
    assert np.all(venv.observation_space.high[-m:] == DitherFeature.CLIP)
    venv.seed(4)
    plain.seed(4)
    o, p = venv.reset(), plain.reset()
    assert np.array_equal(o[:, :-m], p)  # the mode's columns unchanged, the draws appended
    a = np.zeros((3, m), np.float32)
    for _ in range(3):
        o, *_ = venv.step(a)
        p, *_ = plain.step(a)
        assert np.array_equal(o[:, :-m], p)


def test_copies_with_one_seed_draw_the_same_numbers_and_others_do_not():
    venv = SB3VecEnv(SMALL, 4, "full", features=["dither"])
    m = venv.params.m
    o = venv.reset_episodes([7, 8, 7, 8])
    draws = [o[:, -m:]]
    for _ in range(5):
        o, *_ = venv.step(np.full((4, m), 0.1, np.float32))
        draws.append(o[:, -m:])
    d = np.stack(draws)
    assert np.array_equal(d[:, 0], d[:, 2]) and np.array_equal(d[:, 1], d[:, 3])
    assert not np.allclose(d[:, 0], d[:, 1])
    again = SB3VecEnv(SMALL, 1, "full", features=["dither"]).reset_episodes([7])
    assert np.array_equal(again[0, -m:], d[0, 0])  # a seed fixes the draws, whatever the batch


@settings(max_examples=25, deadline=None)
@given(K=st.integers(1, 6), seed=st.integers(0, 2**31 - 1), steps=st.integers(1, 30))
def test_dither_is_standard_normal_bounded_and_reproducible(K, seed, steps):
    p = resolve_params(SMALL)
    fs = FeatureSet(["dither"], p)
    obs = np.zeros((K, 3))
    out = []
    for _trial in range(2):
        fs.reset(K, rng=np.random.default_rng(seed))
        out.append(np.stack([fs.append(obs, np.zeros((K, 0), np.float32)) for _ in range(steps)]))
    assert out[0].shape == (steps, K, p.m) and out[0].dtype == np.float32
    assert np.array_equal(out[0], out[1])
    assert np.all(np.abs(out[0]) <= DitherFeature.CLIP)


def test_dither_moments():
    p = resolve_params(SMALL)
    fs = FeatureSet(["dither"], p)
    fs.reset(64, rng=np.random.default_rng(0))
    z = np.concatenate([fs.append(np.zeros((64, 1)), np.zeros((64, 0), np.float32)) for _ in range(400)])
    assert abs(z.mean()) < 0.01 and abs(z.var() - 1.0) < 0.02  # 51200 draws: se 0.0044 and 0.0063


def test_feature_names_are_checked():
    assert check_features(None) == [] and check_features(["dither"]) == ["dither"]
    assert set(FEATURES) == {"dither"}
    for bad, needle in ((["gram?"], "unknown feature 'gram?'"), ("dither", "must be a list"), (["dither", "dither"], "twice")):
        with pytest.raises(ConfigError, match=needle.replace("?", r"\?")):
            check_features(bad)
    cfg = load_config("ppo", "small", quick=True)
    cfg["features"] = ["nope"]
    with pytest.raises(ConfigError, match="features: unknown feature 'nope'; choose one of dither"):
        validate_config(cfg)
