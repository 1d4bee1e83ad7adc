"""Players of the game (encctl_gym.agents.game): the static baselines' schedules by hand count, the frozen
opponent's single-agent view (Gymnasium's checker, replayed seeds) and paired play; one short
real best response each with PPO and ARS (slow)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pettingzoo")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from encctl_gym.agents import GaussianAttacker  # noqa: E402
from encctl_gym.agents.evaluate import budget_config, env_config  # noqa: E402
from encctl_gym.agents.game import (  # noqa: E402
    ConstantNoise,
    DetectorAudit,
    FrozenOpponent,
    NoDefence,
    PassThrough,
    Population,
    RandomAudit,
    RotateEvery,
    ScheduledAttacker,
    play,
)
from encctl_gym.envs.config import resolve_params  # noqa: E402
from encctl_gym.errors import ParameterError  # noqa: E402

N = 40
CFG = budget_config(env_config({"preset": "paper-example"}), N)
P = resolve_params(CFG)


def test_a_timed_attacker_injects_in_bursts_with_the_energy_of_a_full_one():
    inner, timed = GaussianAttacker(P), ScheduledAttacker(GaussianAttacker(P), period=4, duty=1)
    timed.reset(7)
    obs = np.zeros(timed.attacker.layout.dim, dtype=np.float32)
    acts = np.array([timed.act(obs) for _ in range(12)])
    assert acts[:, -1].tolist() == [1.0, -1.0, -1.0, -1.0] * 3
    inner.reset(np.random.SeedSequence(7).spawn(2)[0])  # the inner attacker's stream, as reset draws it
    want = np.clip(np.array([inner.act(obs) for _ in range(12)]) * 2.0, -1, 1)  # 1 / sqrt(1/4)
    assert np.allclose(acts[:, :-1], want)


def test_a_sparse_attacker_injects_at_the_rate_q():
    sparse = ScheduledAttacker(GaussianAttacker(P), q=0.25)
    sparse.reset(1)
    obs = np.zeros(sparse.attacker.layout.dim, dtype=np.float32)
    flags = np.array([sparse.act(obs)[-1] for _ in range(4000)])
    assert abs(np.mean(flags > 0) - 0.25) < 4 * np.sqrt(0.25 * 0.75 / 4000)
    assert sparse.name == "gaussian/sparse(0.25)"


@pytest.mark.parametrize(
    "make, text",
    [
        (lambda: ScheduledAttacker(GaussianAttacker(P), q=1.5), "q"),
        (lambda: ScheduledAttacker(GaussianAttacker(P), period=4), "period and duty"),
        (lambda: ScheduledAttacker(GaussianAttacker(P), period=4, duty=5), "duty"),
        (lambda: RandomAudit(1.2), "p"),
        (lambda: ConstantNoise(0.0), "level"),
        (lambda: Population([]), "at least one"),
        (lambda: FrozenOpponent("server", NoDefence(), CFG), "side"),
    ],
)
def test_bad_players_are_refused_naming_the_value(make, text):
    with pytest.raises(ParameterError, match=text):
        make()


def test_the_static_defenders_act_as_documented():
    obs = np.zeros(P.n + P.m + 3, dtype=np.float32)
    assert NoDefence().act(obs).tolist() == [-1.0, -1.0, -1.0, -1.0]  # audit, noise, rotate, verify: all off
    assert ConstantNoise(0.5).act(obs).tolist() == [-1.0, 0.5, -1.0, -1.0]
    rot = RotateEvery(3)
    rot.reset()
    assert [rot.act(obs)[2] for _ in range(7)] == [-1.0, -1.0, 1.0, -1.0, -1.0, 1.0, -1.0]
    chi2 = DetectorAudit(P.n, P.m)
    assert chi2.act(obs)[0] == -1.0
    obs[P.n + P.m] = 1.5  # the statistic over its threshold
    assert chi2.act(obs)[0] == 1.0
    for p, want in ((0.0, 0.0), (1.0, 1.0)):
        d = RandomAudit(p)
        d.reset(0)
        assert np.mean([d.act(obs)[0] > 0 for _ in range(50)]) == want


@pytest.mark.parametrize("side", ["attacker", "defender"])
def test_the_frozen_opponent_is_a_gymnasium_environment_that_replays_a_seed(side):
    opponent = RandomAudit(0.2) if side == "attacker" else ScheduledAttacker(GaussianAttacker(P), q=0.5)
    env = FrozenOpponent(side, opponent, CFG)
    check_env(env, skip_render_check=True)
    runs = []
    for _ in range(2):
        obs, _ = env.reset(seed=5)
        env.action_space.seed(3)
        traj = [obs]
        done = False
        while not done:
            obs, r, term, trunc, info = env.step(env.action_space.sample())
            traj.append(np.r_[obs, r])
            done = term or trunc
        runs.append(np.concatenate(traj))
        assert "opponent" in info
    assert np.array_equal(runs[0], runs[1])


def test_play_pairs_the_episodes_and_counts_what_it_reports():
    att = ScheduledAttacker(GaussianAttacker(P))
    a = play(att, NoDefence(), CFG, episodes=3, seed=10)
    b = play(att, NoDefence(), CFG, episodes=3, seed=10)
    assert np.array_equal(a.epsilon, b.epsilon) and a.samples.tolist() == [N] * 3 and a.detected.tolist() == [0.0] * 3
    assert np.allclose(a.defender_return, -a.attacker_return)  # no costs, no detection
    # the pass-through attacker plays the same noise: it never meets a detection, even audited every step
    c = play(PassThrough(P.m), RandomAudit(1.0), CFG, episodes=3, seed=10)
    assert c.detected.tolist() == [0.0] * 3 and np.allclose(c.cost, 0.01 * (N - 1))


@pytest.mark.slow
@pytest.mark.parametrize("algo", ["ppo", "ars"])
def test_a_short_best_response_trains_and_plays(algo):
    from encctl_gym.agents.game_training import train_side

    player, curve = train_side("defender", ScheduledAttacker(GaussianAttacker(P)), CFG, algo=algo, steps=1024, seed=0)
    assert len(curve.returns) > 0 and np.all(np.diff(curve.timesteps) > 0)
    out = play(ScheduledAttacker(GaussianAttacker(P)), player, CFG, episodes=2)
    assert np.all(np.isfinite(out.defender_return))


def test_the_rllib_game_without_ray_names_the_extra(monkeypatch):
    import sys

    from encctl_gym.agents import rllib_game
    from encctl_gym.errors import EncctlError

    monkeypatch.setitem(sys.modules, "ray", None)
    with pytest.raises(EncctlError, match=r"pip install 'encctl-gym\[ray\]'"):
        rllib_game.game_ppo_config(CFG)


def test_the_rllib_game_trains_both_sides_one_iteration():
    pytest.importorskip("ray.rllib")
    from encctl_gym.agents.rllib_game import train_game

    rows = train_game({**CFG, "rules": {"audit_cost": 0.02}}, iterations=1, train_batch_size=128, minibatch_size=64, num_epochs=1)
    assert len(rows) == 1 and rows[0]["env_steps"] >= 128


@pytest.mark.slow
def test_the_game_experiment_writes_its_tables_and_curves(tmp_path):
    from encctl_gym.experiments import game as experiment

    fig = tmp_path / "curves.png"
    args = ["--N", "32", "--episodes", "2", "--steps", "256", "--rounds", "1", "--algo", "ars", "--out", str(tmp_path)]
    assert experiment.main([*args, "--figure", str(fig)]) == 0
    text = (tmp_path / "game_ars.md").read_text()
    assert "Exploitability" in text and "| chi2 |" in text and fig.exists()
    assert len((tmp_path / "game_ars_cells.csv").read_text().splitlines()) == 1 + 7 * 8


def test_the_game_experiment_refuses_a_bad_option_in_one_line(capsys):
    from encctl_gym.experiments import game as experiment

    with pytest.raises(SystemExit) as exc:
        experiment.main(["--N", "4"])
    assert exc.value.code == 2 and "N" in capsys.readouterr().err
