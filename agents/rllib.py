"""Training on a cluster with Ray RLlib (the optional ``[ray]`` extra).

RLlib runs a Gymnasium environment unchanged: :func:`register` registers a creator
(:func:`make_env`, which builds ``encctl_gym/EncryptedLTIAttack-v0`` through
``gymnasium.make``) under :data:`ENV_NAME` with ``ray.tune.registry.register_env``, and every
env runner of the cluster builds its own copies from the same configuration mapping. The
learned policy sees the environment's full observation and its reward (``reward`` in the
configuration), exactly as the single environment defines them.

:func:`ppo_config` returns an RLlib ``PPOConfig`` for that environment; :func:`train_ppo`
connects to a cluster (``address="auto"`` for a running one; ``None`` starts a local Ray
instance), trains for some iterations and returns one summary per iteration. For example::

    from encctl_gym.agents.rllib import train_ppo
    rows = train_ppo({"preset": "paper-example", "gamma_opt": False}, iterations=50,
                     address="auto", num_env_runners=32)

The stable-baselines3 path (:mod:`agents.train`) stays the one the package's results come from:
on one machine its native vector environment steps all copies in one compiled call, which an
RLlib env runner (one Python ``step`` per copy) does not.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from encctl_gym.errors import EncctlError

__all__ = [
    "ENV_NAME",
    "make_env",
    "register",
    "register_factory",
    "ppo_config",
    "with_ppo_hyperparameters",
    "train_ppo",
    "run_training",
]

#: The name the environment is registered under in RLlib.
ENV_NAME = "encctl_gym/EncryptedLTIAttack-v0"


def _require_rllib() -> Any:
    try:
        import ray
        from ray.rllib.algorithms.ppo import PPOConfig  # noqa: F401
    except ModuleNotFoundError as exc:
        raise EncctlError(
            f"encctl_gym.agents.rllib needs Ray RLlib (module {exc.name!r} is missing); install the extra: pip install 'encctl-gym[ray]'"
        ) from exc
    return ray


def register_factory(name: str, factory: Callable[[Any], Any]) -> str:
    """Register ``factory`` (env config -> environment) with RLlib under ``name``; return the name."""
    _require_rllib()
    from ray.tune.registry import register_env

    register_env(name, factory)
    return name


def with_ppo_hyperparameters(
    config: Any, *, train_batch_size: int, minibatch_size: int, num_epochs: int, gamma: float, lr: float, seed: int | None
) -> Any:
    """``config`` (a ``PPOConfig``) with PPO's batch, minibatch, epochs per batch, discount and
    learning rate, the torch framework and, unless ``None``, RLlib's seed."""
    config = config.training(
        train_batch_size=int(train_batch_size),
        minibatch_size=int(minibatch_size),
        num_epochs=int(num_epochs),
        gamma=float(gamma),
        lr=float(lr),
    ).framework("torch")
    return config if seed is None else config.debugging(seed=int(seed))


def run_training(
    build_config: Callable[[], Any], iterations: int, address: str | None, summary: Callable[[dict[str, Any]], dict[str, Any]]
) -> list[dict[str, Any]]:
    """Train the algorithm of ``build_config()`` for ``iterations`` iterations on Ray (joining
    ``address``, or a local instance started and stopped here); one row per iteration:
    ``iteration``, ``env_steps`` (lifetime), ``seconds`` and what ``summary`` reads from RLlib's
    result."""
    ray = _require_rllib()
    from encctl_gym._validation import check_int

    iterations = check_int("iterations", iterations, minimum=1)
    started = not ray.is_initialized()
    if started:
        ray.init(address=address, include_dashboard=False, log_to_driver=False)
    algo = build_config().build_algo()
    rows = []
    try:
        for i in range(iterations):
            r = algo.train()
            rows.append(
                {
                    "iteration": i + 1,
                    "env_steps": int(r.get("num_env_steps_sampled_lifetime", 0)),
                    **summary(r),
                    "seconds": float(r.get("time_this_iter_s", float("nan"))),
                }
            )
    finally:
        algo.stop()
        if started:
            ray.shutdown()
    return rows


def make_env(env_config: Mapping[str, Any]) -> Any:
    """The environment for one RLlib env runner: ``gymnasium.make`` of the registered id with
    ``env_config`` (any mapping, such as RLlib's ``EnvContext``) as its configuration."""
    import gymnasium as gym

    from encctl_gym.envs import ENV_ID

    return gym.make(ENV_ID, config=dict(env_config))


def register(name: str = ENV_NAME) -> str:
    """Register :func:`make_env` with RLlib under ``name``; return the name."""
    return register_factory(name, make_env)


def ppo_config(
    env_config: Mapping[str, Any],
    *,
    num_env_runners: int = 0,
    num_envs_per_env_runner: int = 1,
    train_batch_size: int = 4096,
    minibatch_size: int = 256,
    num_epochs: int = 10,
    gamma: float = 0.999,
    lr: float = 3e-4,
    seed: int | None = 0,
) -> Any:
    """An RLlib ``PPOConfig`` for the attack environment (registered by :func:`register`).

    Parameters
    ----------
    env_config : mapping
        The environment configuration (``encctl_gym.envs.default_config()`` keys), checked here
        before any worker starts.
    num_env_runners, num_envs_per_env_runner : int
        Sampling workers (0: sample in the driver) and environment copies per worker.
    train_batch_size, minibatch_size, num_epochs, gamma, lr : number
        PPO's batch, minibatch, epochs per batch, discount and learning rate.
    seed : int, optional
        RLlib's seed of the workers' environments and the learner.
    """
    _require_rllib()
    from ray.rllib.algorithms.ppo import PPOConfig

    from encctl_gym.envs.config import resolve_params

    resolve_params(dict(env_config))  # a bad configuration fails here, not in a remote worker
    cfg = (
        PPOConfig()
        .environment(register(), env_config=dict(env_config))
        .env_runners(num_env_runners=int(num_env_runners), num_envs_per_env_runner=int(num_envs_per_env_runner))
    )
    return with_ppo_hyperparameters(
        cfg,
        train_batch_size=train_batch_size,
        minibatch_size=minibatch_size,
        num_epochs=num_epochs,
        gamma=gamma,
        lr=lr,
        seed=seed,
    )


def train_ppo(
    env_config: Mapping[str, Any], *, iterations: int, address: str | None = None, **kwargs: Any
) -> list[dict[str, Any]]:
    """Train PPO with RLlib for ``iterations`` iterations; one summary per iteration.

    Parameters
    ----------
    env_config : mapping
        The environment configuration.
    iterations : int
        Training iterations (each samples ``train_batch_size`` steps).
    address : str, optional
        A Ray cluster to join (``"auto"``: the running one); ``None`` starts a local instance,
        stopped at the end.
    **kwargs
        Passed to :func:`ppo_config`.

    Returns
    -------
    list of dict
        ``iteration``, ``env_steps`` (lifetime), ``episode_return_mean`` (the mean telescoped
        ``log eps_0 - log eps_N`` of the episodes finished in that iteration, ``None`` if none)
        and ``seconds``.
    """
    return run_training(
        lambda: ppo_config(env_config, **kwargs),
        iterations,
        address,
        lambda r: {"episode_return_mean": r.get("env_runners", {}).get("episode_return_mean")},
    )
