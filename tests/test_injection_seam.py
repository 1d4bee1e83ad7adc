"""The injection seam (issue 29): ``injection = "replace" | "add" | "pass"`` in the single
environment, the vector environment and the game, implemented once per backend, both backends
bit-identical; with ``add`` and a zero action the episode is the honest loop's bit for bit."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from episodes import rollout

from encctl_gym.envs.encrypted_lti_attack import EncryptedLTIAttackEnv
from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv
from encctl_gym.errors import ParameterError
from encctl_gym.loop.injection import INJECTIONS, added_row, addition

BASE = {"preset": "small", "gamma_opt": False, "key_length": 64, "max_samples": 24, "warmup_steps": 3, "crypto_seed": 5}


def _play(config: dict[str, Any], actions: str = "random", seed: int = 3) -> np.ndarray:
    return np.array(rollout(EncryptedLTIAttackEnv(config=config), seed=seed, action_seed=1, actions=actions))


@pytest.mark.parametrize("crypto", ["ideal", "elgamal"])
def test_add_with_a_zero_action_is_the_honest_loop(crypto: str) -> None:
    cfg = {**BASE, "crypto": crypto, "decipher_delay": 0}
    honest = _play({**cfg, "injection": "pass"})
    assert honest.shape[0] == 25
    np.testing.assert_array_equal(_play({**cfg, "injection": "add"}, actions="zero"), honest)
    assert not np.array_equal(_play({**cfg, "injection": "add"}), honest)  # an addition moves the loop
    assert not np.array_equal(_play({**cfg, "injection": "replace"}), honest)


@pytest.mark.parametrize("injection", INJECTIONS)
@pytest.mark.parametrize("scheme", ["modified", "static"])
def test_both_backends_agree_bit_for_bit_under_every_mode(injection: str, scheme: str) -> None:
    cfg = {**BASE, "injection": injection, "scheme": scheme, "decipher_delay": 0}
    if scheme == "static":
        cfg["max_samples"] = 24
    np.testing.assert_array_equal(_play({**cfg, "crypto": "ideal"}), _play({**cfg, "crypto": "elgamal"}))


def test_pass_spends_no_energy_and_records_no_own_input() -> None:
    for mode, spent in (("pass", False), ("replace", True)):
        env = EncryptedLTIAttackEnv(config={**BASE, "injection": mode, "input_history": 2})
        env.reset(seed=0)
        for _ in range(3):
            obs, _, _, _, info = env.step(np.ones(env.action_space.shape, dtype=np.float32))
        lay = env.params.layout
        assert (info["input_energy"] > 0.0) is spent and bool(obs[lay.energy_fraction] > 0.0) is spent
        assert bool(np.any(obs[lay.history] != 0.0)) is spent


def test_the_vector_environment_takes_the_mode() -> None:
    cfg = {**BASE, "injection": "add", "decipher_delay": 0}
    venv = EncryptedLTIAttackVectorEnv(2, config=cfg)
    venv.reset(seed=3)
    obs, *_ = venv.step(np.zeros((2, venv.single_action_space.shape[0]), dtype=np.float32))
    single = EncryptedLTIAttackEnv(config={**cfg, "injection": "pass"})
    single.reset(seed=3)
    assert obs.shape == (2, single.observation_space.shape[0])
    venv.close()


def test_addition_moves_the_first_product_by_rint_delta_a_times_ecd_one() -> None:
    assert addition(0.5, 4096.0, 4096) == 2048 * 4096
    assert added_row([10, 20, 30], -0.25, 8.0, 8, lambda v: v) == [10 - 16, 20, 30]
    assert added_row([10, 20], 0.0, 8.0, 8, lambda v: v + 1) == [11, 20]  # the scheme's nearest plaintext


@pytest.mark.parametrize(
    "config, text",
    [
        ({"injection": "covert"}, "injection"),
        ({"injection": "add", "decipher_delay": 2}, "decipher_delay=0"),
        ({"injection": "add", "observe": "output", "preset": "small-output"}, "observe='output'"),
    ],
)
def test_a_mode_the_loop_cannot_run_is_refused(config: dict[str, Any], text: str) -> None:
    with pytest.raises(ParameterError, match=text):
        EncryptedLTIAttackEnv(config={**BASE, **config})


def test_the_game_takes_the_mode_and_its_pass_flag_is_the_same_honest_loop() -> None:
    pytest.importorskip("pettingzoo")
    from encctl_gym.multiagent.game import EncryptedControlGame

    cfg = {**BASE, "decipher_delay": 0}

    def play(injection: str, flag: float) -> np.ndarray:
        game = EncryptedControlGame(config={**cfg, "injection": injection})
        game.reset(seed=2)
        m = game.action_space("attacker").shape[0] - 1
        out = []
        for _ in range(10):
            acts = {
                "attacker": np.array([0.0] * m + [flag], dtype=np.float32),
                "defender": np.full(game.action_space("defender").shape, -1.0, dtype=np.float32),
            }
            obs, *_ = game.step(acts)
            out.append(obs["attacker"])
        return np.array(out)

    honest = play("replace", -1.0)  # the pass flag: the honest loop whatever the mode
    np.testing.assert_array_equal(play("add", 1.0), honest)  # add of a zero action: the same loop
    np.testing.assert_array_equal(play("pass", 1.0), honest)
    assert not np.array_equal(play("replace", 1.0), honest)  # a forged zero input is not the controller's
