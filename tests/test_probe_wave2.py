"""Bad inputs found by the held-out probe after the first hardening wave: each must end in a
package error naming the value (or a correct result), never a built-in exception, a hang, an
unbounded allocation or a silent wrong number."""

from __future__ import annotations

from typing import Any

import numpy as np
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


def test_a_sample_budget_beyond_the_float_range_without_max_samples_caps_the_horizon() -> None:
    from encctl_gym.envs.config import MAX_DEFAULT_HORIZON

    params = resolve_params({**HUGE_BUDGET, "max_samples": None, "key_length": 3072})
    assert params.budget_samples > 10**500
    assert params.horizon_capped and params.horizon == MAX_DEFAULT_HORIZON


def test_an_environment_with_a_budget_beyond_the_float_range_is_made_with_the_capped_horizon() -> None:
    import gymnasium as gym

    from encctl_gym.envs.config import MAX_DEFAULT_HORIZON
    from encctl_gym.registration import ENV_ID

    with pytest.warns(UserWarning, match="2\\^20|1048576|cap"):
        env = gym.make(ENV_ID, config={**HUGE_BUDGET, "max_samples": None, "key_length": 3072, "gamma_opt": False})
    assert env.unwrapped.params.horizon == MAX_DEFAULT_HORIZON
    assert issubclass(ResourceLimitError, EncctlError)


def _no_generation(bits: int) -> None:
    raise AssertionError(f"a {bits}-bit safe-prime group was generated")


def test_the_ideal_backend_never_generates_a_group_above_the_shipped_sizes(monkeypatch: pytest.MonkeyPatch) -> None:
    # lambda = 128 at Upsilon = 1e30, tau_c = 1e10 s asks for a key of more than 2048 bits.
    import encctl_gym.loop.elgamal_scheme as backend
    from encctl_gym.crypto.group import SHIPPED_BITS
    from encctl_gym.loop import IdealLoop, make_loop

    monkeypatch.setattr(backend, "_generated_group", _no_generation)
    params = resolve_params({"security_parameter": 128, "upsilon": 1e30, "tau_c": 1e10})
    assert params.key_length > max(SHIPPED_BITS)
    loop = make_loop(params.loop)
    assert isinstance(loop, IdealLoop)
    assert loop.table.p.bit_length() == max(SHIPPED_BITS)


def test_the_elgamal_backend_still_asks_for_the_group_of_its_key_length(monkeypatch: pytest.MonkeyPatch) -> None:
    import encctl_gym.loop.elgamal_scheme as backend
    from encctl_gym.loop import make_loop

    asked: list[int] = []

    def record(bits: int) -> None:
        asked.append(bits)
        raise ResourceLimitError("recorded")

    monkeypatch.setattr(backend, "_generated_group", record)
    params = resolve_params({"security_parameter": 128, "upsilon": 1e30, "tau_c": 1e10, "crypto": "elgamal"})
    with pytest.raises(ResourceLimitError, match="recorded"):
        make_loop(params.loop)
    assert asked == [params.key_length]


@pytest.mark.parametrize("bad", [10**400, "0.5", True, float("nan"), 0.0, 1.5, -(10**400)])
def test_a_forgetting_factor_that_is_not_a_real_number_in_0_1_is_refused(bad: object) -> None:
    from encctl_gym.errors import ParameterError
    from encctl_gym.ident import make_estimator

    with pytest.raises(ParameterError, match="forgetting_factor"):
        make_estimator({"name": "forgetting", "forgetting_factor": bad})


def test_a_forgetting_factor_in_0_1_is_kept() -> None:
    import numpy as np

    from encctl_gym.ident import make_estimator

    assert make_estimator({"name": "forgetting", "forgetting_factor": np.float32(0.5)}).forgetting_factor == 0.5
    assert make_estimator({"name": "forgetting", "forgetting_factor": 1}).forgetting_factor == 1.0


def test_iv_lags_beyond_the_bound_are_refused_when_the_estimator_is_made() -> None:
    from encctl_gym.errors import ParameterError
    from encctl_gym.ident import make_estimator
    from encctl_gym.ident.instrumental import MAX_LAGS

    assert make_estimator({"name": "iv", "lags": MAX_LAGS}).lags == MAX_LAGS
    with pytest.raises(ParameterError, match="lags"):
        make_estimator({"name": "iv", "lags": 10**5})
    with pytest.raises(ParameterError, match="lags"):
        resolve_params({"preset": "small", "estimator": {"name": "iv", "lags": 10**5}})


def test_an_estimator_whose_moments_do_not_fit_is_refused_before_allocating() -> None:
    from encctl_gym.ident import make_estimator
    from encctl_gym.ident.instrumental import MAX_LAGS

    est = make_estimator({"name": "iv", "lags": MAX_LAGS})
    # 10^4 copies of (2 * 8200^2) float64 moments: about 10 TB, refused with the sizes named
    with pytest.raises(ResourceLimitError, match="K = 10000 copies"):
        est.start(10_000, 2, 2)
    assert est.online_bytes(3, 2, 2) == 3 * est.online_bytes(1, 2, 2)
    small = make_estimator({"name": "iv", "lags": 64})
    small.start(10_000, 2, 2)  # 10^4 copies of 136 features fit (about 3 GiB is not allocated up front)
    assert small.num_copies == 10_000


# ------------------------------------------------------------------ plant files that are not regular files
def test_a_directory_given_as_a_plant_file_is_called_a_directory(tmp_path) -> None:
    from encctl_gym.errors import ConfigError
    from encctl_gym.plant_file import load_plant_file

    (tmp_path / "plant.json").mkdir()
    with pytest.raises(ConfigError, match="is a directory"):
        load_plant_file(tmp_path / "plant.json")
    with pytest.raises(ConfigError, match="does not exist"):
        load_plant_file(tmp_path / "missing.json")


def test_a_fifo_given_as_a_plant_file_is_refused_without_opening_it(tmp_path) -> None:
    import os

    from encctl_gym.errors import ConfigError
    from encctl_gym.plant_file import load_plant_file

    if not hasattr(os, "mkfifo"):
        pytest.skip("no named pipes on this platform")
    fifo = tmp_path / "plant.json"
    os.mkfifo(fifo)  # opening it for reading would block: no writer ever comes
    with pytest.raises(ConfigError, match=r"is not a regular file: it is a FIFO"):
        load_plant_file(fifo)


def test_a_device_given_as_a_plant_file_is_called_a_device() -> None:
    import os

    from encctl_gym.errors import ConfigError
    from encctl_gym.plant_file import load_plant_file

    if not os.path.exists("/dev/null"):
        pytest.skip("no /dev/null")
    with pytest.raises(ConfigError, match="is not a regular file: it is a character device"):
        load_plant_file("/dev/null")


def test_the_cli_says_a_directory_is_a_directory(tmp_path, capsys) -> None:
    from encctl_gym import cli

    (tmp_path / "plant.json").mkdir()
    assert cli.main(["design", str(tmp_path / "plant.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert "is a directory" in err and len(err.splitlines()) == 1


# ------------------------------------------------------------------ eq:opt_key's real range of lambda
def test_minimum_key_length_states_the_security_parameters_it_reaches() -> None:
    from encctl_gym.errors import ModelRangeError
    from encctl_gym.security.cost_models import MAX_KEY_LENGTH, PaperModel, gnfs_log2_complexity, minimum_key_length

    low, high = PaperModel().security_parameter_range()
    assert high == pytest.approx(float(gnfs_log2_complexity(MAX_KEY_LENGTH, 0.0)), abs=1e-12)
    assert 481 < high < 482  # the formula at 65536 bits
    assert minimum_key_length(481) <= MAX_KEY_LENGTH
    for lam in (482, 2048):
        with pytest.raises(ModelRangeError, match=rf"lam <= log2 Omega\({MAX_KEY_LENGTH}\) - c = {high:.3f} bits"):
            minimum_key_length(lam)
    c_low, c_high = PaperModel(10.0).security_parameter_range()  # a correction lowers both ends by c
    assert (c_low, c_high) == pytest.approx((low - 10.0, high - 10.0), abs=1e-9)


# ------------------------------------------------------------------ an estimation error that overflows is loud
def test_a_bayes_prior_whose_error_overflows_is_refused() -> None:
    import numpy as np

    from encctl_gym.errors import ParameterError
    from encctl_gym.ident import make_estimator

    with pytest.raises(ParameterError, match="prior_mean's squared entries overflow"):
        make_estimator({"name": "bayes", "prior_mean": np.full((2, 4), 1e200)})
    with pytest.raises(ParameterError, match="prior_mean"):
        resolve_params({"preset": "small", "estimator": {"name": "bayes", "prior_mean": np.full((2, 4), 1e200).tolist()}})
    assert make_estimator({"name": "bayes", "prior_mean": np.full((2, 4), 1e100)}).prior_mean.max() == 1e100


def _bayes_episode(path: str) -> tuple[Any, Any]:
    """An environment with Bayes on the column-by-column path (``generic``) or on its compiled
    form (``compiled``), and a function that makes every estimate's error that of ``theta``."""
    import gymnasium as gym
    import numpy as np

    from encctl_gym.ident.bayes import BayesianLeastSquares
    from encctl_gym.registration import ENV_ID

    est: Any = "bayes"
    if path == "generic":
        est = type("ColumnByColumnBayes", (BayesianLeastSquares,), {"online_kernels": None})()
    env = gym.make(ENV_ID, config={"preset": "small", "estimator": est, "max_samples": 12, "gamma_opt": False})
    core = env.unwrapped.episode

    def force(value: float) -> None:
        if path == "generic":
            core.estimator.error = lambda A, B: np.full(1, value)
        else:
            core.kernels.estimator.online_solve = lambda M, columns, n, m: np.full((1, n, n + m), value)

    return env, force


@pytest.mark.parametrize("path", ["generic", "compiled"])
def test_an_estimation_error_that_overflows_ends_the_episode_loudly(path: str) -> None:
    from encctl_gym.errors import SolverError

    env, force = _bayes_episode(path)
    env.reset(seed=0)
    force(np.inf if path == "generic" else 1e200)  # an estimate too far from the plant to measure
    with pytest.raises(SolverError, match=r"error overflowed float64 \(epsilon = inf\)"):
        for _ in range(12):
            env.step(env.action_space.sample())


@pytest.mark.parametrize("path", ["generic", "compiled"])
def test_an_estimator_without_an_estimate_yet_keeps_the_previous_error(path: str) -> None:
    env, force = _bayes_episode(path)
    _, info0 = env.reset(seed=0)
    force(np.nan)  # NaN: no estimate for this copy
    for _ in range(3):
        _, _, _, _, info = env.step(env.action_space.sample())
    assert info["epsilon"] == info0["epsilon"]


# ------------------------------------------------------------------ a tight memory estimate
@pytest.mark.parametrize("num_envs", [100, 400])
def test_the_episode_memory_estimate_covers_the_measured_peak_within_ten_percent(num_envs: int) -> None:
    import tracemalloc

    import gymnasium as gym
    import numpy as np

    from encctl_gym.envs.schedule import episode_bytes
    from encctl_gym.registration import ENV_ID

    cfg = {"gamma_opt": False, "max_samples": 2000}

    def play(k: int) -> gym.vector.VectorEnv:
        env = gym.make_vec(ENV_ID, num_envs=k, config=cfg)
        env.reset(seed=0)
        a = np.zeros(env.action_space.shape, dtype=np.float32)
        for _ in range(100):
            env.step(a)
        return env

    play(2).close()  # compile and warm up outside the measurement
    tracemalloc.start()
    try:
        env = play(num_envs)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    env.close()
    estimate = episode_bytes(resolve_params(cfg), num_envs)
    assert peak <= estimate <= 1.10 * peak, (peak, estimate)  # a margin of a half fails the upper bound


def test_the_memory_refusal_states_the_margin() -> None:
    from encctl_gym.envs.schedule import check_episode_memory

    with pytest.raises(ResourceLimitError, match="5 % margin"):
        check_episode_memory(resolve_params({"gamma_opt": False}), 10_000, memory_limit=2**30)
