"""Training with stable-baselines3: the VecEnv adapter, train --quick end to end, what a run
directory holds, save/load, the learning curve, the progress bar, evaluate RUN_DIR."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from encctl_gym import cli
from encctl_gym.agents import ColoredGaussianAttacker, GaussianAttacker, OptimalDesignAttacker, rollout
from encctl_gym.agents.curves import load_learning_curve, plot_learning_curves, reference_designs
from encctl_gym.agents.evaluate import budget_config
from encctl_gym.agents.runs import read_run
from encctl_gym.agents.sb3 import SB3Attacker, SB3VecEnv, load_attacker
from encctl_gym.envs.config import resolve_params
from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv
from encctl_gym.errors import ConfigError, ParameterError

SMALL = {"preset": "small", "gamma_opt": False}
PLANT = {"A": [[0.6, 0.2], [0.0, 0.5]], "B": [[1.0, 0.0], [0.3, 1.0]]}


# ------------------------------------------------------------------ the VecEnv adapter
def test_sb3_vecenv_follows_the_native_vector_env_and_autoresets():
    K = 3
    venv = SB3VecEnv(SMALL, K, "full")
    native = EncryptedLTIAttackVectorEnv(K, config=SMALL)
    venv.seed(5)
    obs = venv.reset()
    nobs, _ = native.reset(seed=5)
    assert np.array_equal(obs, nobs)
    rng = np.random.default_rng(0)
    H = venv.params.horizon
    for t in range(H):
        a = rng.uniform(-0.3, 0.3, (K, venv.params.m)).astype(np.float32)
        obs, r, done, infos = venv.step(a)
        nobs, nr, te, tr, ninfo = native.step(a)
        assert np.allclose(r, nr)
        if t < H - 1:
            assert not done.any() and np.array_equal(obs, nobs) and infos[0] == {}
    assert done.all()
    for i, info in enumerate(infos):
        assert np.array_equal(info["terminal_observation"], nobs[i])
        assert info["epsilon"] == pytest.approx(ninfo["epsilon"][i])
        assert info["TimeLimit.truncated"] == bool(tr[i] and not te[i])
    assert not np.array_equal(obs, nobs)  # the returned observation is the next episode's first


def test_sb3_vecenv_observation_modes_and_reward_scaling():
    full = SB3VecEnv(SMALL, 2, "full")
    blind = SB3VecEnv(SMALL, 2, "blind")
    scaled = SB3VecEnv(SMALL, 2, "full", reward_scaling="samples")
    native = EncryptedLTIAttackVectorEnv(2, config=SMALL)
    p = full.params
    assert blind.observation_space.shape == (p.input_history * p.m + 2,)
    for v in (full, blind, scaled):
        v.seed(1)
        v.reset()
    native.reset(seed=[1, 2])
    a = np.full((2, p.m), 0.2, dtype=np.float32)
    for _ in range(p.n + p.m + 3):
        o_full, r_full, _, _ = full.step(a)
        o_blind, _, _, _ = blind.step(a)
        _, r_scaled, _, _ = scaled.step(a)
        *_, info = native.step(a)
    assert np.array_equal(o_blind, o_full[:, blind.obs_idx])
    assert np.allclose(r_scaled, r_full * info["samples_delivered"], rtol=1e-6)
    with pytest.raises(ParameterError):
        SB3VecEnv(SMALL, 2, "full", reward_scaling="bogus")


# ------------------------------------------------------------------ train --quick on a plant file
@pytest.fixture(scope="module")
def ppo_run(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("train")
    plant = tmp / "plant2.json"
    plant.write_text(json.dumps(PLANT))
    rc = cli.main(
        [
            "train",
            "--algo",
            "ppo",
            "--system",
            str(plant),
            "--quick",
            "--out",
            str(tmp / "runs"),
            "--no-progress",
            "--set",
            "env.sigma_w2=0.2",
            "--set",
            "horizon=64",
            "--n-timesteps",
            "1500",
        ]
    )
    assert rc == 0
    return tmp / "runs" / "ppo_plant2_d0_full_s0-quick"


def test_train_quick_writes_a_complete_run(ppo_run, capsys):
    for f in (
        "model.zip",
        "best_model.zip",
        "vecnormalize.npz",
        "evaluations.npz",
        "run.json",
        "learning_curve.npz",
        "learning_curve.png",
    ):
        assert (ppo_run / f).exists(), f
    assert (ppo_run / "learning_curve.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert any((ppo_run / "tb").rglob("events.out.tfevents.*"))
    run = read_run(ppo_run)
    meta = run.meta
    assert run.algo == "ppo" and run.system == "plant2" and run.custom_plant and meta["status"] == "finished"
    assert run.env["A"] == PLANT["A"] and run.env["sigma_w2"] == 0.2
    # PPO collects whole rollouts (128 steps x 4 copies): 1500 requested -> 1536 done, and said so
    assert meta["n_timesteps"] == 1500 and meta["timesteps_done"] == 1536
    params = resolve_params(run.env)
    assert params.horizon == 64 and np.array_equal(params.A, np.array(PLANT["A"]))


def test_final_evaluation_numbers_are_reproduced_by_direct_rollouts(ppo_run):
    """The Gaussian and learned errors recorded in run.json equal rollouts on the same seeds."""
    meta = read_run(ppo_run).meta
    ev = meta["final_evaluation"]
    cfg = dict(read_run(ppo_run).env)
    params = resolve_params(cfg)
    g = rollout(GaussianAttacker(params), cfg, episodes=ev["episodes"], seed=ev["seed"], record=False)
    assert ev["gaussian"]["mean_epsilon"] == g.mean_final()
    for which in ("final", "best"):
        r = rollout(load_attacker(ppo_run, which=which), cfg, episodes=ev["episodes"], seed=ev["seed"], record=False)
        assert ev[which]["mean_epsilon"] == r.mean_final()
        d = np.log(r.final_epsilon) - np.log(g.final_epsilon)
        assert ev[which]["mean_log_ratio"] == pytest.approx(d.mean(), rel=1e-12)
    el = ev["elgamal"]  # the learned policy ran through real ElGamal ciphertexts
    assert el["key_length"] == 64 and el["N"] == 20 and np.isfinite(el["mean_epsilon"]) and el["mean_epsilon"] > 0


def test_saved_and_loaded_policy_gives_identical_actions(ppo_run):
    """Two loads of the saved run, reset with the same seed, act identically step by step
    (the policy samples from torch's global generator, so the two play one after the other)."""
    cfg = dict(read_run(ppo_run).env)

    def play(att):
        native = EncryptedLTIAttackVectorEnv(5, config=cfg)
        obs, _ = native.reset(seed=3)
        att.reset(seed=11)
        acts = []
        for _ in range(6):
            acts.append(att.act(obs))
            obs, *_ = native.step(acts[-1])
        return np.stack(acts), obs

    a1, a2 = load_attacker(ppo_run), load_attacker(ppo_run)
    assert isinstance(a1, SB3Attacker) and not a1.vecnormalize.training
    x1, obs = play(a1)
    x2, _ = play(a2)
    assert np.array_equal(x1, x2) and x1.shape == (6, 5, 2) and np.all(np.abs(x1) <= 1)
    assert not np.array_equal(x1[0], x1[1])
    # the deterministic policy is the mean: the same for any seed, and not the sampled action
    d1 = load_attacker(ppo_run, deterministic=True)
    d2 = load_attacker(ppo_run, deterministic=True)
    d1.reset(seed=1)
    d2.reset(seed=2)
    assert np.array_equal(d1.act(obs), d2.act(obs))
    a1.reset(seed=1)
    assert not np.array_equal(a1.act(obs), d1.act(obs))


def test_learning_curve_holds_the_evaluations_and_its_references(ppo_run, tmp_path):
    curve = load_learning_curve(ppo_run)
    meta = read_run(ppo_run).meta
    ev = meta["config"]["eval"]
    params = resolve_params(read_run(ppo_run).env)
    design, gauss = reference_designs(params, "full")
    assert design.kind == "closed_loop"
    assert curve.N == 64 and curve.gamma_opt == design.gamma(64) and curve.gamma_gauss == gauss.gamma(64)
    assert curve.gamma == params.gamma(64)
    # one evaluation before training and one every eval.freq steps (2048 > 1536: none more)
    assert list(curve.timesteps) == [0] and curve.epsilon.shape == (1, ev["episodes"])
    assert np.all(curve.epsilon > 0)
    r, lo, hi = curve.ratio()
    assert r[0] == pytest.approx(curve.epsilon.mean() / design.gamma(64)) and lo[0] < r[0] < hi[0]
    assert meta["learning_curve"]["last_ratio_to_gamma_opt"] == pytest.approx(r[-1])
    # several runs in one figure
    other = load_learning_curve(ppo_run)
    other.seed = 1
    other.append(1536, curve.epsilon[0] * 0.9)
    png = plot_learning_curves([curve, other, ppo_run], tmp_path / "curves.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ConfigError):
        other.append(2000, np.ones(3))  # another number of episodes
    (tmp_path / "broken.npz").write_bytes(b"nope")
    with pytest.raises(ConfigError, match="cannot read learning curve"):
        load_learning_curve(tmp_path / "broken.npz")


def test_a_second_run_of_the_same_name_gets_a_new_directory_or_overwrites(ppo_run, tmp_path):
    from encctl_gym.agents.config import load_config
    from encctl_gym.agents.train import train

    cfg = load_config("ppo", "small", quick=True)
    cfg.update(n_timesteps=64, n_envs=2)
    cfg["hyperparams"].update(n_steps=32, batch_size=64, n_epochs=1)
    cfg["eval"].update(freq=10_000, episodes=2)
    first = train(cfg, out=tmp_path, progress=False, tensorboard=False, name="r")
    (first / "marker").write_text("old run")
    second = train(cfg, out=tmp_path, progress=False, tensorboard=False, name="r")
    assert second == tmp_path / "r-2" and (first / "marker").exists()
    third = train(cfg, out=tmp_path, progress=False, tensorboard=False, name="r", overwrite=True)
    assert third == first and not (first / "marker").exists() and (first / "model.zip").exists()


def test_progress_bar_never_passes_its_total():
    from stable_baselines3 import PPO

    from encctl_gym.agents.callbacks import ProgressCallback

    seen: list[tuple[int, int]] = []

    class Spy(ProgressCallback):
        def _on_step(self) -> bool:
            ok = super()._on_step()
            seen.append((self.bar.n, self.bar.total))
            return ok

    venv = SB3VecEnv(SMALL, 4, "full")
    model = PPO("MlpPolicy", venv, n_steps=16, batch_size=64, n_epochs=1, seed=0, device="cpu")
    spy = Spy(100, "t")
    model.learn(total_timesteps=100, callback=spy)
    assert model.num_timesteps == 128  # two rollouts of 16 x 4
    assert max(n for n, _ in seen) == 100 and all(n <= t for n, t in seen)
    assert (spy.bar.n, spy.bar.total) == (128, 128)  # grown at the end to the steps really done


@pytest.mark.parametrize("algo", ["sac", "recurrent_ppo"])
def test_train_quick_sac_and_recurrent_ppo(tmp_path, algo):
    rc = cli.main(
        [
            "train",
            "--algo",
            algo,
            "--preset",
            "small",
            "--quick",
            "--out",
            str(tmp_path),
            "--no-progress",
            "--no-tensorboard",
            "--set",
            "eval.elgamal.episodes=0",
            "--set",
            "horizon=32",
        ]
    )
    assert rc == 0
    (run_dir,) = list(tmp_path.iterdir())
    run = read_run(run_dir)
    ev = run.meta["final_evaluation"]
    cfg = dict(run.env)
    g = rollout(GaussianAttacker(resolve_params(cfg)), cfg, episodes=ev["episodes"], seed=ev["seed"], record=False)
    assert ev["gaussian"]["mean_epsilon"] == g.mean_final()
    r = rollout(load_attacker(run_dir, which="final"), cfg, episodes=ev["episodes"], seed=ev["seed"], record=False)
    assert ev["final"]["mean_epsilon"] == r.mean_final() and r.N[-1] == 32
    assert "elgamal" not in ev
    curve = load_learning_curve(run_dir)
    assert curve.design_kind == ("open_loop" if algo == "recurrent_ppo" else "closed_loop")


def test_recurrent_attacker_keeps_and_resets_its_state():
    """A tiny RecurrentPPO model (not trained) wrapped as an attacker: the LSTM state is carried
    between steps, per copy, and cleared by reset."""
    from sb3_contrib import RecurrentPPO

    venv = SB3VecEnv(SMALL, 2, "blind")
    model = RecurrentPPO(
        "MlpLstmPolicy", venv, n_steps=8, batch_size=16, policy_kwargs={"lstm_hidden_size": 4}, seed=0, device="cpu"
    )
    att = SB3Attacker(model, params=venv.params, observation="blind", name="rppo")
    cfg = budget_config({"preset": "small", "gamma_opt": False, "decipher_delay": "end"}, 20)
    params = resolve_params(cfg)
    native = EncryptedLTIAttackVectorEnv(4, config=cfg)
    obs, _ = native.reset(seed=0)
    att.reset(seed=1)
    a0 = att.act(obs)
    assert att._state is not None and a0.shape == (4, params.m)
    h_before = np.array(att._state[0]).copy()
    obs, *_ = native.step(a0)
    att.act(obs)
    assert not np.array_equal(np.array(att._state[0]), h_before)  # the state moved on
    att.reset(seed=1)
    assert att._state is None
    r1 = rollout(att, cfg, episodes=4, seed=0, record=False)
    r2 = rollout(att, cfg, episodes=4, seed=0, record=False)
    assert np.array_equal(r1.final_epsilon, r2.final_epsilon)  # reset(seed) restarts the LSTM and the sampling


# ------------------------------------------------------------------ evaluate RUN_DIR
def test_evaluate_prints_the_compare_table_on_paired_seeds(ppo_run, tmp_path, capsys):
    out = tmp_path / "ev"
    rc = cli.main(
        ["evaluate", str(ppo_run), "--episodes", "6", "--points", "2", "--seed", "7", "--out", str(out), "--no-progress"]
    )
    assert rc == 0
    text = capsys.readouterr()
    assert "warning" not in text.err
    table = [line for line in text.out.splitlines() if line.startswith("| plant2 ")]
    assert [line.split(" | ")[2] for line in table[:4]] == ["gaussian", "colored(rho=0.5)", "optimal-cl (oracle)", "ppo"]
    with (out / "security.csv").open(newline="") as fh:
        rows = {r["attacker"]: r for r in csv.DictReader(fh)}
    cfg = budget_config({k: v for k, v in read_run(ppo_run).env.items() if k not in ("tau_c", "security_parameter")}, 64)
    params = resolve_params(cfg)
    for name, att in (
        ("gaussian", GaussianAttacker(params)),
        ("colored(rho=0.5)", ColoredGaussianAttacker(params, 0.5)),
        ("optimal-cl", OptimalDesignAttacker(params)),
    ):
        r = rollout(att, cfg, episodes=6, seed=7, record=False)
        assert float(rows[name]["mean_error_at_horizon"]) == pytest.approx(r.mean_final(), rel=1e-12), name
    learned = rollout(load_attacker(ppo_run, which="best", params=params), cfg, episodes=6, seed=7, record=False)
    assert float(rows["ppo"]["mean_error_at_horizon"]) == pytest.approx(learned.mean_final(), rel=1e-12)
    g = rollout(GaussianAttacker(params), cfg, episodes=6, seed=7, record=False)
    ratio = np.exp(np.mean(np.log(learned.final_epsilon) - np.log(g.final_epsilon)))
    assert float(rows["ppo"]["ratio_to_gaussian"]) == pytest.approx(ratio, rel=1e-12)
    assert int(rows["ppo"]["horizon"]) == 64
    oracle = rollout(OptimalDesignAttacker(params), cfg, episodes=6, seed=7, record=False)
    to_oracle = np.exp(np.mean(np.log(learned.final_epsilon) - np.log(oracle.final_epsilon)))
    margin = [line for line in text.out.splitlines() if line.startswith("plant2, delay 0, N = 64: ppo / optimal-cl: ")]
    assert margin and margin[0].split(": ")[2].startswith(f"{to_oracle:.3f} [") and "6 episodes resolve +-" in margin[0]
    assert (out / "summary.md").read_text().count("* plant2, delay 0, N = 64: ppo") == 4
    assert (
        cli.main(
            ["evaluate", str(ppo_run), "--episodes", "2", "--points", "1", "--deterministic", "--out", str(out), "--no-progress"]
        )
        == 0
    )
    assert "warning: --deterministic" in capsys.readouterr().err
    assert cli.main(["evaluate", str(ppo_run), "--delays", "end"]) == 2
    assert "cannot play with decipher_delay 'end'" in capsys.readouterr().err


# ------------------------------------------------------------------ normalisation statistics without pickles
def _copy_run(src: Path, dst: Path) -> Path:
    import shutil

    return Path(shutil.copytree(src, dst, ignore=shutil.ignore_patterns("tb", "evaluation")))


def test_the_normalisation_statistics_are_arrays_and_load_as_sb3_saved_them(ppo_run, tmp_path):
    from stable_baselines3.common.vec_env import VecNormalize

    from encctl_gym.agents.sb3 import load_vecnormalize, save_vecnormalize

    run = read_run(ppo_run)
    with np.load(ppo_run / "vecnormalize.npz", allow_pickle=False) as z:  # plain arrays: loads without pickles
        assert z["obs_mean"].shape == z["obs_var"].shape and z["obs_count"] > 0
    venv = SB3VecEnv(run.env, 1, run.observation, features=run.features)
    ours = load_vecnormalize(ppo_run / "vecnormalize.npz", venv)
    ours.save(str(tmp_path / "vn.pkl"))  # SB3's own pickle of the same statistics
    theirs = VecNormalize.load(str(tmp_path / "vn.pkl"), venv)
    obs = np.random.default_rng(0).normal(size=(3, *venv.observation_space.shape)) * 10
    assert np.array_equal(ours.normalize_obs(obs), theirs.normalize_obs(obs))
    for attr in ("clip_obs", "clip_reward", "gamma", "epsilon", "norm_obs", "norm_reward"):
        assert getattr(ours, attr) == getattr(theirs, attr), attr
    again = load_vecnormalize(save_vecnormalize(theirs, tmp_path / "again.npz"), venv)
    assert np.array_equal(again.obs_rms.var, theirs.obs_rms.var) and again.ret_rms.count == theirs.ret_rms.count


class _RunsCode:
    """A pickle payload that leaves a marker file when it is unpickled."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self):  # type: ignore[no-untyped-def]
        return (Path.write_text, (self.marker, "ran"))


def test_an_old_run_with_a_pickle_is_refused_unless_the_caller_opts_in(ppo_run, tmp_path, capsys):
    import pickle

    from stable_baselines3.common.vec_env import VecNormalize

    from encctl_gym.agents.sb3 import load_vecnormalize

    old = _copy_run(ppo_run, tmp_path / "old")
    run = read_run(old)
    vn = load_vecnormalize(old / "vecnormalize.npz", SB3VecEnv(run.env, 1, run.observation, features=run.features))
    (old / "vecnormalize.npz").unlink()
    vn.save(str(old / "vecnormalize.pkl"))  # what older versions wrote
    with pytest.raises(ConfigError, match="allow_pickle=True"):
        load_attacker(old)
    assert isinstance(load_attacker(old, allow_pickle=True).vecnormalize, VecNormalize)

    marker = tmp_path / "marker"
    (old / "vecnormalize.pkl").write_bytes(pickle.dumps(_RunsCode(marker)))
    with pytest.raises(ConfigError, match="--allow-pickle"):
        load_attacker(old)
    assert cli.main(["evaluate", str(old), "--episodes", "2", "--points", "1", "--no-progress",
                     "--out", str(tmp_path / "ev")]) == 2  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert "--allow-pickle" in err and len(err.splitlines()) == 1
    assert not marker.exists()  # nothing was unpickled


def _plant_a_pickle_in_the_model(run_dir: Path, marker: Path) -> None:
    """Rewrite ``model.zip`` with its ``data`` entry's ``policy_class`` replaced by a payload
    that writes ``marker`` when stable-baselines3's loader unpickles it."""
    import base64
    import pickle
    import zipfile

    path = run_dir / "model.zip"
    with zipfile.ZipFile(path) as z:
        entries = {name: z.read(name) for name in z.namelist()}
    data = json.loads(entries["data"])
    data["policy_class"] = {
        ":type:": "<class 'abc.ABCMeta'>",
        ":serialized:": base64.b64encode(pickle.dumps(_RunsCode(marker))).decode(),
    }
    entries["data"] = json.dumps(data).encode()
    with zipfile.ZipFile(path, "w") as z:
        for name, raw in entries.items():
            z.writestr(name, raw)


def test_a_model_archive_is_loaded_without_unpickling_its_data(ppo_run, tmp_path, capsys):
    """``model.zip``'s ``data`` entry holds cloudpickled objects that stable-baselines3's loader
    unpickles: the run is rebuilt from its config and given the weights only (issue 34, item 24)."""
    run = _copy_run(ppo_run, tmp_path / "planted")
    marker = tmp_path / "marker"
    _plant_a_pickle_in_the_model(run, marker)
    att, ref = load_attacker(run, deterministic=True), load_attacker(ppo_run, deterministic=True)
    assert not marker.exists()  # nothing was unpickled
    obs = np.random.default_rng(0).normal(size=(4, *att.model.observation_space.shape)).astype(np.float32)
    att.reset(seed=0)
    ref.reset(seed=0)
    assert np.array_equal(att.act(obs), ref.act(obs))  # the same weights act the same
    assert cli.main(["evaluate", str(run), "--episodes", "2", "--points", "1", "--no-progress",
                     "--out", str(tmp_path / "ev")]) == 0  # fmt: skip
    assert not marker.exists()
    # a run whose config cannot rebuild its model is refused, naming the opt-in, and nothing runs
    meta = json.loads((run / "run.json").read_text())
    meta["config"]["hyperparams"]["policy_kwargs"]["net_arch"] = [3]
    (run / "run.json").write_text(json.dumps(meta))
    with pytest.raises(ConfigError, match="allow_pickle=True"):
        load_attacker(run)
    assert not marker.exists()


def test_a_bad_env_in_run_json_is_blamed_on_run_json(ppo_run, tmp_path):
    bad = _copy_run(ppo_run, tmp_path / "bad")
    meta = json.loads((bad / "run.json").read_text())
    meta["env"]["sigma_w2"] = -1.0
    (bad / "run.json").write_text(json.dumps(meta))
    params = resolve_params(read_run(ppo_run).env)  # the caller's own, valid environment
    with pytest.raises(ConfigError, match=r"run\.json: its env does not make an environment: sigma_w2") as info:
        load_attacker(bad, params=params)
    assert "vecnormalize" not in str(info.value)


@pytest.mark.parametrize("lags", [10**5, 4096])
def test_evaluate_refuses_a_run_whose_estimator_does_not_fit_in_one_line(ppo_run, tmp_path, capsys, lags):
    big = _copy_run(ppo_run, tmp_path / "iv")
    meta = json.loads((big / "run.json").read_text())
    meta["env"]["estimator"] = {"name": "iv", "lags": lags}
    (big / "run.json").write_text(json.dumps(meta))
    rc = cli.main(["evaluate", str(big), "--episodes", "64", "--points", "1", "--no-progress", "--out", str(tmp_path / "ev")])
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert "lags" in err or "iv(lags=4096) estimator's moments" in err
    assert len(err.splitlines()) == 1 and "Traceback" not in err
