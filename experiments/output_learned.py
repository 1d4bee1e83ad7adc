"""A learned attacker on outputs: ARS trained with ``observe="output"``, against the open-loop attacks.

The plant is the ``small-output`` preset (the ``small`` plant seen through its first state,
``sigma_v2 = 0.01``); attacks of ``N`` samples. A linear policy on the observation
``[y_j | u_{j-1} | new | own inputs | budget fractions]``, extended by the attacker's private
dither (``m`` draws of ``N(0, 1)`` per step, :class:`agents.features.DitherFeature`, seeded by the
episode seed: without it a deterministic linear policy only feeds the outputs back, and the
closed-loop data do not identify the plant), is trained by paired ARS
(:class:`agents.ars.PairedARS`: every candidate of an iteration plays the same episodes) on the
``log_error`` reward, the decrease of the log Markov-parameter error of the environment's online
ARX least squares (:mod:`encctl_gym.envs.output_episode`). Then the learned policy, the Gaussian
attack of Theorem thm:sic and PRBS play the same evaluation episodes (common random numbers:
the same environment seeds), and the table gives the final Markov error of each and the paired
difference of its logarithm against the Gaussian attack.

    python -m encctl_gym.experiments.output_learned [--iterations 25] [--samples 200] [--episodes 40] [--out docs/results/output_identification]

Writes ``output_learned.md``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from encctl_gym.envs import EncryptedLTIAttackEnv

CONFIG = {"preset": "small-output", "observe": "output", "x_bound": 64.0, "gamma_opt": False}
N_DELTA = 4
TRAIN_EPISODES = 2


class Dithered(gym.ObservationWrapper):
    """The environment's observation with the attacker's dither appended (module docstring)."""

    def __init__(self, env: Any) -> None:
        from encctl_gym.agents.features import DitherFeature

        super().__init__(env)
        self.feature = DitherFeature(env.unwrapped.params)
        lo, hi = self.feature.bounds()
        space = env.observation_space
        self.observation_space = gym.spaces.Box(
            np.concatenate([space.low, lo]), np.concatenate([space.high, hi]), dtype=np.float32
        )

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        self.feature.reset([np.random.default_rng(seed)], np.zeros(1, dtype=np.int64))
        return super().reset(seed=seed, options=options)

    def observation(self, observation: np.ndarray) -> np.ndarray:
        return np.concatenate([observation, self.feature(observation[None])[0]]).astype(np.float32)


def _episode(env: Any, act: Any, seed: int) -> float:
    """Final Markov error of one attack played by ``act(obs)`` on the environment seed ``seed``."""
    obs, info = env.reset(seed=seed)
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(act(obs))
        done = terminated or truncated
    return float(info["epsilon"])


def train(samples: int, iterations: int, seed: int) -> Any:
    """PairedARS on the output environment for ``iterations`` iterations; the trained model."""
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv

    from encctl_gym.agents.ars import PairedARS

    cfg = {**CONFIG, "max_samples": samples}
    venv = DummyVecEnv([lambda: Monitor(Dithered(EncryptedLTIAttackEnv(config=cfg)))])
    model = PairedARS(
        "LinearPolicy", venv, n_delta=N_DELTA, n_eval_episodes=TRAIN_EPISODES, learning_rate=0.02, delta_std=0.05, seed=seed
    )
    model.learn(total_timesteps=iterations * (2 * N_DELTA + 1) * TRAIN_EPISODES * samples)
    return model


def evaluate(model: Any, samples: int, episodes: int, seed: int) -> dict[str, np.ndarray]:
    """Final Markov errors of the learned policy, the Gaussian attack and PRBS on the same seeds."""
    from encctl_gym.agents.baselines import GaussianAttacker, PRBSAttacker

    env = EncryptedLTIAttackEnv(config={**CONFIG, "max_samples": samples})
    learned_env = Dithered(EncryptedLTIAttackEnv(config={**CONFIG, "max_samples": samples}))
    params = env.params
    out: dict[str, list[float]] = {"learned (ARS)": [], "gaussian": [], "prbs": []}
    for e in range(episodes):
        env_seed = seed + 1000 + e
        out["learned (ARS)"].append(_episode(learned_env, lambda o: model.predict(o, deterministic=True)[0], env_seed))
        for name, cls in (("gaussian", GaussianAttacker), ("prbs", PRBSAttacker)):
            attacker = cls(params)
            attacker.reset(seed=env_seed)
            out[name].append(_episode(env, attacker.act, env_seed))
    return {k: np.array(v) for k, v in out.items()}


def format_table(errors: dict[str, np.ndarray], samples: int, iterations: int, seconds: float, command: str) -> str:
    """Markdown: mean and median final error per attacker and the paired log difference to Gaussian."""
    base = np.log(errors["gaussian"])
    lines = [
        "# A learned attacker on outputs\n",
        f"Command: `{command}` (preset small-output, N = {samples}, {len(base)} evaluation episodes on the same seeds; "
        f"ARS: {iterations} iterations, {N_DELTA} directions, {TRAIN_EPISODES} paired episodes each, {seconds:.0f} s of training).\n",
        "| attacker | mean Markov error | median | mean log(error / gaussian's) [95 %] |",
        "|---|---|---|---|",
    ]
    for name, e in errors.items():
        d = np.log(e) - base
        half = 1.96 * d.std(ddof=1) / np.sqrt(len(d)) if len(d) > 1 else float("nan")
        diff = "0 (reference)" if name == "gaussian" else f"{d.mean():+.3f} [{d.mean() - half:+.3f}, {d.mean() + half:+.3f}]"
        lines.append(f"| {name} | {e.mean():.4g} | {np.median(e):.4g} | {diff} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m encctl_gym.experiments.output_learned", description=__doc__.splitlines()[0])
    parser.add_argument("--iterations", type=int, default=25, help="ARS iterations (default 25)")
    parser.add_argument("--samples", type=int, default=200, help="attack length N (default 200)")
    parser.add_argument("--episodes", type=int, default=40, help="evaluation episodes (default 40)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("results/output_identification"))
    args = parser.parse_args(argv)
    if args.iterations < 1 or args.samples < 20 or args.episodes < 2:
        print("output_learned: --iterations >= 1, --samples >= 20 and --episodes >= 2 are needed", file=sys.stderr)
        return 2
    start = time.perf_counter()
    model = train(args.samples, args.iterations, args.seed)
    seconds = time.perf_counter() - start
    errors = evaluate(model, args.samples, args.episodes, args.seed)
    shown = " ".join(argv if argv is not None else sys.argv[1:])
    text = format_table(
        errors, args.samples, args.iterations, seconds, f"python -m encctl_gym.experiments.output_learned {shown}".strip()
    )
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "output_learned.md"
    path.write_text(text)
    print(text + f"  wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
