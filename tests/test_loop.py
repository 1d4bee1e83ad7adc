"""The loop backends: one interface, and the compiled fixed-point stages against their
big-integer references (the encoder and the forged injection of the crypto layer)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from encctl_gym.attacks.forgery import injection_value
from encctl_gym.crypto.encoding import Encoder
from encctl_gym.crypto.quantized import QuantizedLinearController
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import EncodingOverflowError, ParameterError
from encctl_gym.loop import BACKENDS, ElGamalLoop, IdealLoop, LoopBackend, make_loop, make_scheme

SMALL = {"preset": "small", "gamma_opt": False, "key_length": 128}


@pytest.fixture(scope="module")
def ideal() -> IdealLoop:
    return make_loop(resolve_params(SMALL).loop)


@pytest.fixture(scope="module")
def encoder() -> Encoder:
    return Encoder(make_scheme("modified").public_parameters(128), 4096.0)


def test_every_backend_implements_the_protocol():
    for name in BACKENDS:
        loop = make_loop(resolve_params({**SMALL, "crypto": name, "max_samples": 20}).loop)
        assert isinstance(loop, LoopBackend)
        assert loop.batched == (name == "ideal") and (loop.quantization is not None) == (name == "ideal")
    with pytest.raises(ParameterError, match="one copy"):
        from encctl_gym.envs.episode import EpisodeCore

        p = resolve_params({**SMALL, "crypto": "elgamal", "max_samples": 20})
        EpisodeCore(p, make_loop(p.loop), num_envs=2)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1.0, 1.0, allow_nan=False), min_size=2, max_size=2), st.integers(1, 6))
def test_compiled_forgery_equals_the_big_integer_injection_value(ideal, encoder, a_units, batch):
    """The ideal loop's compiled _forge gives exactly the float the plant decodes from the
    forged ciphertexts (crypto.controller.injection_value), for every copy of a batch."""
    p = resolve_params(SMALL)
    a = np.tile(np.asarray(a_units) * p.u_max, (batch, 1))
    got = ideal.inject(a)
    want = injection_value(a[0], encoder, p.n)
    assert got.shape == (batch, p.m) and all(np.array_equal(row, want) for row in got)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-200.0, 200.0, allow_nan=False), min_size=2, max_size=2))
def test_compiled_collect_equals_the_encoder_round_trip(ideal, encoder, x):
    got = ideal.collect_state(np.asarray([x]))
    want = [encoder.decode(encoder.encode(v)) for v in x]
    assert got.tolist() == [want]


def test_quantised_controller_equals_the_big_integer_twin(ideal, encoder):
    twin = QuantizedLinearController(ideal.Phi, encoder, ideal.x_bound)
    xs = np.random.default_rng(0).normal(0.0, 3.0, (20, 2))
    assert np.array_equal(ideal.control(xs), np.stack([twin.compute(x) for x in xs]))


def test_ideal_loop_refuses_a_state_outside_x_bound(ideal):
    with pytest.raises(EncodingOverflowError, match="x_bound"):
        ideal.collect_state(np.array([[ideal.x_bound * 1.01, 0.0]]))
    with pytest.raises(EncodingOverflowError, match="x_bound"):
        ideal.control(np.array([[np.nan, 0.0]]))


def _held(obj) -> list:
    names = list(getattr(obj, "__dict__", {})) + [n for c in type(obj).__mro__ for n in getattr(c, "__slots__", ())]
    return [getattr(obj, n) for n in names if hasattr(obj, n)]


@pytest.mark.parametrize("scheme", ["modified", "token", "static"])
def test_parties_of_the_elgamal_loop_hold_independent_randomness(scheme):
    """No party is handed another's random source, and the seeded streams differ."""
    p = resolve_params({**SMALL, "crypto": "elgamal", "scheme": scheme, "crypto_seed": 123, "max_samples": 20})
    loop = ElGamalLoop(p, make_scheme("modified").public_parameters(128))
    loop.start_episode()
    sources = loop.random_sources
    draws = {name: tuple(src.below(2**62) for _ in range(4)) for name, src in sources.items()}
    assert len(set(draws.values())) == len(sources) == 4  # plant, server, adversary, breaker
    assert not any(h is sources["plant"] or h is sources["adversary"] for h in _held(loop.server))
    assert not any(h is sources["server"] or h is sources["adversary"] for h in _held(loop.plant))
