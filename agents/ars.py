"""Augmented Random Search on paired episodes: every candidate of an iteration plays the same ones.

ARS (Mania, Guy and Recht 2018, sb3-contrib's :class:`sb3_contrib.ARS`) improves a
deterministic policy by playing ``2 n_delta`` perturbed copies of its weights,
``theta +- delta_std * delta_i``, and stepping along ``sum_i (R_i+ - R_i-) delta_i``. Its
returns here are the telescoped reward of one attack, e.g. ``log(d / delta) - log tr((G_N +
delta I)^-1)`` for ``reward="a_optimality"``: the (log) A-optimality criterion of the attack, a
smooth function of the weights *for a fixed draw of the process noise and of the policy's own
randomness*. :class:`PairedARS` uses that:

* **Common random numbers.** In one iteration every candidate plays the same ``n_eval_episodes``
  episodes: the same environment seeds (initial states, process noise) and the same draws of the
  attacker's private randomness (the ``dither`` feature of :mod:`agents.features`). The
  difference ``R_i+ - R_i-`` then measures the perturbation, not the noise: on the design example
  (N = 256, 8 episodes) a change of the feedback gain by 0.05 moves the paired difference by
  0.088 with a standard deviation of 0.002 across seeds. Each iteration draws new seeds.
* **Batched.** With the native vector environment (:class:`agents.vec_env.SB3VecEnv`) all
  candidates and the current policy play at once, ``(2 n_delta + 1) n_eval_episodes`` copies
  stepped together, the candidates' networks evaluated in one vectorised call.
* **Normalisation frozen within an iteration.** The observation statistics (``VecNormalize``)
  are those of the iteration's start for every candidate and are then updated from the
  observations of the current (unperturbed) policy, which plays the same episodes first in the
  batch.
* **Step rule.** ``step_rule="ars"`` is ARS's step, ``learning_rate / (n_top sigma_R)`` times
  the sum over the ``n_top`` best directions (its length does not shrink near an optimum, so use
  a decaying ``learning_rate`` schedule such as ``lin_0.02``); ``"adam"`` (default) feeds the
  antithetic estimate of the gradient, ``sum_i (R_i+ - R_i-) delta_i / (2 n_delta delta_std)``,
  to Adam with step ``learning_rate``.

The step counter counts every environment step played (the base class counts each step once
per copy of the vector environment, ``n_envs`` times too many), and the callbacks are called
once per ``n_envs`` of them, as for the other algorithms; a callback that returns False stops
training after the current iteration (the base class ignores it).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
import torch as th
from gymnasium import spaces
from sb3_contrib import ARS
from sb3_contrib.ars.policies import ARSPolicy
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.evaluation import evaluate_policy
from stable_baselines3.common.policies import BasePolicy
from stable_baselines3.common.type_aliases import GymEnv, Schedule

from encctl_gym.errors import ConfigError

from .vec_env import SB3VecEnv

__all__ = ["PairedARS", "STEP_RULES"]

#: The step rules of :class:`PairedARS`.
STEP_RULES = ("adam", "ars")


def _sb3_vec_env(env: Any) -> Any:
    """The :class:`agents.vec_env.SB3VecEnv` under a stack of VecEnv wrappers, or None."""
    while env is not None:
        if isinstance(env, SB3VecEnv):
            return env
        env = getattr(env, "venv", None)
    return None


class PairedARS(ARS):
    """ARS whose candidates of one iteration play the same episodes (module docstring).

    Parameters are those of :class:`sb3_contrib.ARS` (``policy``, ``env``, ``n_delta``,
    ``n_top``, ``learning_rate``, ``delta_std``, ``zero_policy``, ``n_eval_episodes``,
    ``policy_kwargs``, ...), and:

    step_rule : {"adam", "ars"}
        How the weights move along the estimated gradient (module docstring).
    adam_betas : list of two floats
        Adam's decay rates of the first and second moments (``step_rule="adam"``).
    """

    policy_aliases: ClassVar[dict[str, type[BasePolicy]]] = ARS.policy_aliases
    weights: th.Tensor  # type: ignore[assignment]  # the flat policy parameters; sb3-contrib declares None

    def __init__(
        self,
        policy: str | type[ARSPolicy],
        env: GymEnv | str,
        n_delta: int = 8,
        n_top: int | None = None,
        learning_rate: float | Schedule = 0.02,
        delta_std: float | Schedule = 0.05,
        zero_policy: bool = True,
        alive_bonus_offset: float = 0,
        n_eval_episodes: int = 1,
        step_rule: str = "adam",
        adam_betas: list[float] | tuple[float, float] = (0.9, 0.999),
        policy_kwargs: dict[str, Any] | None = None,
        stats_window_size: int = 100,
        tensorboard_log: str | None = None,
        seed: int | None = None,
        verbose: int = 0,
        device: th.device | str = "cpu",
        _init_setup_model: bool = True,
    ) -> None:
        if step_rule not in STEP_RULES:
            raise ConfigError(f"step_rule must be one of {', '.join(STEP_RULES)}, got {step_rule!r}")
        betas = tuple(float(b) for b in adam_betas)
        if len(betas) != 2 or not all(0.0 <= b < 1.0 for b in betas):
            raise ConfigError(f"adam_betas must be two numbers in [0, 1), got {adam_betas!r}")
        self.step_rule = step_rule
        self.adam_betas = betas
        self._adam: dict[str, Any] | None = None
        self._paired_env: Any = None
        self._continue = True
        super().__init__(
            policy,
            env,
            n_delta=n_delta,
            n_top=n_top,
            learning_rate=learning_rate,
            delta_std=delta_std,
            zero_policy=zero_policy,
            alive_bonus_offset=alive_bonus_offset,
            n_eval_episodes=n_eval_episodes,
            policy_kwargs=policy_kwargs,
            stats_window_size=stats_window_size,
            tensorboard_log=tensorboard_log,
            seed=seed,
            verbose=verbose,
            device=device,
            _init_setup_model=_init_setup_model,
        )

    def _excluded_save_params(self) -> list[str]:
        return [*super()._excluded_save_params(), "_paired_env"]

    # ------------------------------------------------------------------ seeds of an iteration
    def _iteration_seed(self) -> int:
        """Environment seed of the next iteration's episodes (from torch's generator, seeded by ``seed``)."""
        return int(th.randint(0, 2**31 - 1, (1,)).item())

    # ------------------------------------------------------------------ evaluation
    def evaluate_candidates(self, candidate_weights: th.Tensor, callback: BaseCallback, async_eval: Any) -> th.Tensor:
        """Mean return of every candidate over the iteration's common episodes."""
        if async_eval is not None:
            raise ConfigError("PairedARS evaluates its candidates in one batch; async_eval is not supported")
        seed = self._iteration_seed()
        base = _sb3_vec_env(self.env)
        if base is not None and isinstance(self.action_space, spaces.Box):
            returns, played = self._evaluate_batched(base, candidate_weights, seed)
        else:
            returns, played = self._evaluate_sequential(candidate_weights, seed)
        assert self.env is not None  # set by the constructor (SB3 keeps it Optional for loading)
        n_envs = max(int(self.env.num_envs), 1)
        callback.on_rollout_start()
        for _ in range(max(played // n_envs, 1)):
            self.num_timesteps += n_envs
            if callback.on_step() is False:
                self._continue = False
        callback.on_rollout_end()
        return returns

    def learn(  # type: ignore[override]  # sb3-contrib's ARS.learn adds async_eval before progress_bar
        self,
        total_timesteps: int,
        callback: Any = None,
        log_interval: int = 1,
        tb_log_name: str = "ARS",
        reset_num_timesteps: bool = True,
        async_eval: Any = None,
        progress_bar: bool = False,
    ) -> PairedARS:
        """As :meth:`sb3_contrib.ARS.learn`, and a callback returning False stops training."""
        total_steps, callback = self._setup_learn(total_timesteps, callback, reset_num_timesteps, tb_log_name, progress_bar)
        callback.on_training_start(locals(), globals())
        self._continue = True
        while self.num_timesteps < total_steps and self._continue:
            self._update_current_progress_remaining(self.num_timesteps, total_timesteps)
            self._do_one_update(callback, async_eval)
            if log_interval is not None and self._n_updates % log_interval == 0:
                self.dump_logs()
        callback.on_training_end()
        return self

    def _paired(self, base: Any, copies: int) -> Any:
        env = self._paired_env
        if env is None or env.num_envs != copies:
            env = SB3VecEnv(base.config, copies, base.observation, base.reward_scaling, features=base.feature_names)
            self._paired_env = env
        return env

    def _evaluate_batched(self, base: Any, candidate_weights: th.Tensor, seed: int) -> tuple[th.Tensor, int]:
        from torch.func import functional_call, vmap

        P, E = int(candidate_weights.shape[0]), int(self.n_eval_episodes)
        weights = th.cat([candidate_weights, self.weights[None]], dim=0)  # the current policy plays last
        env = self._paired(base, (P + 1) * E)
        names, shapes, sizes = [], [], []
        for name, p in self.policy.named_parameters():
            names.append(name)
            shapes.append(p.shape)
            sizes.append(p.numel())
        chunks = th.split(weights.to(self.device, th.float32), sizes, dim=1)
        params = {n: c.reshape(P + 1, *s) for n, c, s in zip(names, chunks, shapes)}
        policy = self.policy

        def act(p: dict[str, th.Tensor], x: th.Tensor) -> th.Tensor:
            return functional_call(policy, p, (x,))

        batched = vmap(act)
        vn = self._vec_normalize_env
        obs = env.reset_episodes([seed + e for e in range(E)] * (P + 1))
        total = np.zeros((P + 1) * E)
        centre_obs = []
        steps = 0
        while True:
            o = vn.normalize_obs(obs) if vn is not None else obs
            if vn is not None:
                centre_obs.append(obs[P * E :])
            with th.no_grad():
                a = batched(params, th.as_tensor(np.asarray(o, np.float32)).reshape(P + 1, E, -1)).reshape((P + 1) * E, -1)
            obs, reward, dones, _ = env.step(a.cpu().numpy())
            total += reward
            steps += 1
            if dones.any():
                break
        if vn is not None and vn.training:
            vn.obs_rms.update(np.concatenate(centre_obs, axis=0))
        centre = total[P * E :]
        self._mimic_monitor_wrapper(centre, np.full(E, steps))
        self.logger.record("rollout/centre_return", float(centre.mean()))
        returns = th.as_tensor(total[: P * E].reshape(P, E).mean(axis=1), dtype=th.float32)
        return returns, (P + 1) * E * steps

    def _evaluate_sequential(self, candidate_weights: th.Tensor, seed: int) -> tuple[th.Tensor, int]:
        """Any other environment: one candidate after the other, each after ``env.seed(seed)``."""
        import copy

        returns = th.zeros(self.pop_size)
        policy = copy.deepcopy(self.policy)
        vn = self._vec_normalize_env
        training = vn.training if vn is not None else False
        played = 0
        try:
            for i in range(self.pop_size):
                if vn is not None:
                    vn.training = training and i == 0
                policy.load_from_vector(candidate_weights[i].cpu())  # type: ignore[arg-type]  # SB3 accepts a tensor
                assert self.env is not None
                self.env.seed(seed)
                rew, lens = evaluate_policy(
                    policy, self.env, n_eval_episodes=self.n_eval_episodes, return_episode_rewards=True, warn=False
                )
                returns[i] = float(np.mean(rew))
                played += int(np.sum(lens))
                self._mimic_monitor_wrapper(np.asarray(rew), np.asarray(lens))
        finally:
            if vn is not None:
                vn.training = training
        return returns, played

    # ------------------------------------------------------------------ update
    def _do_one_update(self, callback: BaseCallback, async_eval: Any) -> None:
        if self.step_rule == "ars":
            super()._do_one_update(callback, async_eval)
            return
        delta_std = self.delta_std_schedule(self._current_progress_remaining)
        lr = self.lr_schedule(self._current_progress_remaining)
        deltas = th.normal(mean=0.0, std=1.0, size=(self.n_delta, self.n_params), device=self.device)
        candidates = th.cat([self.weights + delta_std * deltas, self.weights - delta_std * deltas])
        with th.no_grad():
            R = self.evaluate_candidates(candidates, callback, async_eval)
        grad = ((R[: self.n_delta] - R[self.n_delta :]).to(deltas) @ deltas) / (2.0 * delta_std * self.n_delta)
        if self._adam is None:
            self._adam = {"m": th.zeros_like(grad), "v": th.zeros_like(grad), "t": 0}
        st, (b1, b2) = self._adam, self.adam_betas
        st["t"] += 1
        st["m"] = b1 * st["m"] + (1.0 - b1) * grad
        st["v"] = b2 * st["v"] + (1.0 - b2) * grad * grad
        m_hat = st["m"] / (1.0 - b1 ** st["t"])
        v_hat = st["v"] / (1.0 - b2 ** st["t"])
        self.weights = self.weights + lr * m_hat / (v_hat.sqrt() + 1e-8)
        self.policy.load_from_vector(self.weights.cpu())  # type: ignore[arg-type]  # SB3 accepts a tensor
        self.logger.record("train/iterations", self._n_updates, exclude="tensorboard")
        self.logger.record("train/delta_std", delta_std)
        self.logger.record("train/learning_rate", lr)
        self.logger.record("train/gradient_norm", float(grad.norm()))
        self.logger.record("rollout/return_std", float(R.std()))
        self._n_updates += 1
