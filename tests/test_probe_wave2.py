"""Bad inputs found by the held-out probe after the first hardening wave: each must end in a
package error naming the value (or a correct result), never a built-in exception, a hang, an
unbounded allocation or a silent wrong number."""

from __future__ import annotations

import pytest

from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import EncctlError, ResourceLimitError

HUGE_BUDGET = {"preset": "small", "max_samples": 30, "upsilon": 1e300, "tau_c": 1e300}


@pytest.mark.parametrize("extra", [{"key_length": 3072}, {"crypto": "elgamal", "key_length": 2049}])
def test_a_sample_budget_beyond_the_float_range_gives_the_requested_horizon(extra: dict) -> None:
    # Upsilon * tau_c = 1e600 FLOP buys an integer number of samples far beyond float range.
    params = resolve_params({**HUGE_BUDGET, **extra})
    assert params.horizon == 30
    assert not params.budget_limited
    assert params.budget_samples > 10**500


def test_a_sample_budget_beyond_the_float_range_without_max_samples_is_the_budget() -> None:
    params = resolve_params({**HUGE_BUDGET, "max_samples": None, "key_length": 3072})
    assert params.budget_limited
    assert params.horizon == params.budget_samples > 10**500


def test_an_environment_with_a_budget_beyond_the_float_range_is_refused_for_its_memory() -> None:
    import gymnasium as gym

    from encctl_gym.registration import ENV_ID

    with pytest.raises(ResourceLimitError, match="max_samples"):
        gym.make(ENV_ID, config={**HUGE_BUDGET, "max_samples": None, "key_length": 3072})
    assert issubclass(ResourceLimitError, EncctlError)
