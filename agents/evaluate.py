"""Run attackers through the environment and record the identification error along the way.

:func:`rollout` plays ``episodes`` episodes of one attacker. On the ideal backend it steps them
in batches through the native vector environment (one ``act`` per step for the whole batch);
on the ElGamal backend it plays them one at a time through the single environment (real
ciphertexts, one copy). Episode ``e`` is always seeded with ``seed + e``, so two attackers
evaluated with the same ``seed`` face the same initial states and the same process noise.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from encctl_gym._validation import check_int
from encctl_gym.envs.config import resolve_params
from encctl_gym.errors import ParameterError
from encctl_gym.ident.tails import ErrorSummary, error_tail_exponent, summarize_errors

from .base import Attacker

__all__ = ["Rollout", "rollout", "env_config", "budget_config", "elgamal_config", "design_efficiency"]


def env_config(config: dict[str, Any] | None = None, **overrides: Any) -> dict[str, Any]:
    """An environment configuration with ``gamma_opt`` off unless asked for (it costs an SDP)."""
    cfg = {"gamma_opt": False}
    cfg.update(config or {})
    cfg.update(overrides)
    return cfg


def budget_config(config: dict[str, Any], N: int) -> dict[str, Any]:
    """``config`` with an attack of exactly ``N`` samples set by the deciphering budget.

    Keeps the key (its length, or the security parameter, and so the cost of every sample
    under the configured deciphering model) and shortens the defense period to half a
    per-key cost past ``tau(N)``: ``tau_c = (N + 1/2) 2^lambda / Upsilon`` under the paper's
    model, ``tau(N) + C_key / (2 Upsilon)`` under a model with a precomputation. The episode
    then ends by *termination* after ``N`` samples and the observed budget fraction is the
    fraction of the attack's deciphering time spent, as in a full attack. (``max_samples``
    would cut the episode instead, with the budget fraction stuck near 0.) Schemes where one
    break reveals every sample have no deciphering budget: there ``max_samples = N`` is used.

    Parameters
    ----------
    config : dict
        Environment configuration.
    N : int
        Attack length (>= n + m + 1).

    Returns
    -------
    dict
    """
    N = check_int("N", N, minimum=2)
    base = resolve_params(env_config(config))
    cfg = dict(config)
    if not base.independent_keys:
        cfg["max_samples"] = N
        return cfg
    cfg.pop("max_samples", None)
    if cfg.get("key_length") is None:  # pin the key the configuration resolved to
        if base.deciphering_model == base.loop.encryption().baseline_model:
            cfg["security_parameter"] = base.security_parameter
        else:
            cfg.pop("security_parameter", None)
            cfg["key_length"] = base.key_length
    if base.cost.first == base.cost.next:  # every key alike: (N + 1/2) keys
        cfg["tau_c"] = (N + 0.5) * base.sample_cost
    else:
        cfg["tau_c"] = float(base.deciphering_time(N)) + 0.5 * base.next_sample_cost
    got = resolve_params(env_config(cfg)).horizon
    if got != N:  # pragma: no cover - guards the arithmetic above
        raise ParameterError(f"budget_config: expected a horizon of {N}, got {got}")
    return cfg


def elgamal_config(config: dict[str, Any], N: int, *, key_length: int = 64, crypto_seed: int | None = 0) -> dict[str, Any]:
    """``config`` on the real ElGamal backend with a small key, for an attack of ``N`` samples.

    The key length sets the cost of a sample under the configured deciphering model (lambda =
    log2 Omega(k) under the paper's, eq:opt_key read backwards), so the deciphering budget is
    set again for ``N`` samples (:func:`budget_config`): the attack has the same length and the
    observed budget fractions the same meaning as on the ideal backend. ``crypto_seed`` makes
    the ciphertexts reproducible (unsafe for deployment; this is a simulation).
    """
    cfg = {k: v for k, v in config.items() if k not in ("security_parameter", "max_samples", "crypto", "crypto_seed")}
    cfg["key_length"] = check_int("key_length", key_length, minimum=16)
    cfg = budget_config(cfg, N)
    cfg.update(crypto="elgamal", crypto_seed=crypto_seed)
    return cfg


@dataclass
class Rollout:
    """The record of ``E`` episodes of one attacker (all of the same length ``T`` steps).

    Attributes
    ----------
    attacker : str
        The attacker's name.
    N : ndarray (T,)
        Samples delivered after each step (the ``N`` of ``epsilon(N)``).
    epsilon : ndarray (E, T)
        ``info["epsilon"]`` after each step (the error of the current estimate, Definition
        def:error; with ``decipher_delay="end"`` it changes only at the last step).
    energy : ndarray (E, T)
        ``info["input_energy"]`` after each step: the input energy spent so far (the budget is
        ``m sigma_u2 N`` for the whole attack, so an attacker may spend it unevenly).
    final_epsilon, average_power, input_energy : ndarray (E,)
        At the end of each episode.
    gamma : ndarray (T,)
        ``gamma(N)`` of eq:sic at ``N``.
    seconds : float
        Wall time.
    covariance : ndarray (n+m, n+m) or None
        With ``rollout(..., covariance=True)``: the regressor covariance of the delivered data,
        ``sum_e D_e D_e^T / sum_e (N_e - 1)`` over the episodes (``D`` of eq:data, columns
        ``z_t = [x_t; u_t]``), the ``Sigma`` of :mod:`encctl_gym.security.attack_design` that
        the attack realised.
    """

    attacker: str
    N: np.ndarray
    epsilon: np.ndarray
    energy: np.ndarray
    final_epsilon: np.ndarray
    average_power: np.ndarray
    input_energy: np.ndarray
    gamma: np.ndarray
    seconds: float
    crypto: str = "ideal"
    extra: dict[str, Any] = field(default_factory=dict)
    covariance: np.ndarray | None = None

    @property
    def episodes(self) -> int:
        return int(self.final_epsilon.size)

    def mean_final(self) -> float:
        return float(self.final_epsilon.mean())

    def se_final(self) -> float:
        return float(self.final_epsilon.std(ddof=1) / np.sqrt(self.episodes)) if self.episodes > 1 else float("nan")

    def summary_final(self, n: int | None = None, m: int | None = None) -> ErrorSummary:
        """Median, quantiles and the status of the mean of the final errors
        (:func:`encctl_gym.ident.tails.summarize_errors`; with ``n`` and ``m`` the least-squares
        tail rule at the final ``N``, which assumes inputs with a density, else only the Hill check)."""
        N = int(self.N[-1])
        rule = error_tail_exponent(n, m, N) if n is not None and m is not None and N > n + m else None
        return summarize_errors(self.final_epsilon, tail_exponent=rule)


def rollout(
    attacker: Attacker,
    config: dict[str, Any],
    *,
    episodes: int,
    seed: int = 0,
    batch: int | None = None,
    record: bool = True,
    progress: Any = None,
    covariance: bool = False,
) -> Rollout:
    """Play ``episodes`` episodes of ``attacker`` and record ``epsilon`` after every step.

    Parameters
    ----------
    attacker : Attacker
        Built for the same parameters (observation layout) as ``config``.
    config : dict
        Environment configuration (see :func:`encctl_gym.envs.config.default_config`).
    episodes : int
        Number of episodes (>= 1).
    seed : int
        Episode ``e`` resets the environment with ``seed + e``; the attacker's own randomness is
        seeded from ``seed`` and the batch index.
    batch : int, optional
        Copies stepped at once on the ideal backend (default: all episodes at once, at most 64).
    record : bool
        Keep ``epsilon`` after every step (else only the final values; ``epsilon`` is then
        ``(E, 1)``).
    progress : tqdm-like, optional
        ``progress.update(k)`` is called with the number of environment steps done.
    covariance : bool
        Also record the regressor covariance of the delivered data (:attr:`Rollout.covariance`).

    Returns
    -------
    Rollout
    """
    episodes = check_int("episodes", episodes, minimum=1)
    cfg = dict(config)
    params = resolve_params(cfg)
    if (params.n, params.m, params.input_history) != (attacker.params.n, attacker.params.m, attacker.params.input_history):
        raise ParameterError("the attacker was built for a different observation layout than this environment")
    t0 = time.perf_counter()
    tally = _Tally(params.n + params.m)
    if params.crypto == "ideal":
        B = min(episodes, 64) if batch is None else check_int("batch", batch, minimum=1)
        _play_batches(tally, attacker, cfg, B, episodes, seed, record=record, progress=progress, covariance=covariance)
    else:
        _play_single(tally, attacker, cfg, episodes, seed, record=record, progress=progress, covariance=covariance)
    N_steps = tally.N_steps
    assert N_steps is not None
    gamma = np.full(N_steps.shape, np.inf)
    ok = N_steps >= 2
    gamma[ok] = params.gamma(N_steps[ok])
    return Rollout(
        attacker=attacker.name,
        N=N_steps,
        epsilon=np.concatenate(tally.eps_rows, axis=0),
        energy=np.concatenate(tally.en_rows, axis=0),
        final_epsilon=np.concatenate(tally.finals),
        average_power=np.concatenate(tally.powers),
        input_energy=np.concatenate(tally.energies),
        gamma=gamma,
        seconds=time.perf_counter() - t0,
        crypto=params.crypto,
        covariance=tally.gram / tally.columns if covariance and tally.columns else None,
    )


class _Tally:
    """What :func:`rollout` collects episode by episode: the per-step rows, the final values
    and the Gram matrix of the delivered regressors ``z_t = [x_t; u_t]``."""

    def __init__(self, d: int) -> None:
        self.eps_rows: list[np.ndarray] = []
        self.en_rows: list[np.ndarray] = []
        self.finals: list[np.ndarray] = []
        self.powers: list[np.ndarray] = []
        self.energies: list[np.ndarray] = []
        self.gram = np.zeros((d, d))
        self.columns = 0
        self.N_steps: np.ndarray | None = None

    def add_gram(self, core: Any, take: int) -> None:
        """Add the first ``take`` copies' delivered data of an episode core."""
        X, U = core.delivered_data()
        Z = np.concatenate([X[:take, :-1], U[:take]], axis=2)
        self.gram = self.gram + np.einsum("eti,etj->ij", Z, Z)
        self.columns += Z.shape[0] * Z.shape[1]

    def add_finals(self, info: dict[str, Any], take: int | None) -> None:
        """The final error, average power and input energy (of the first ``take`` copies; None: one
        copy of the single environment)."""
        if take is None:
            self.finals.append(np.array([info["epsilon"]]))
            self.powers.append(np.array([info["average_power"]]))
            self.energies.append(np.array([info["input_energy"]]))
        else:
            self.finals.append(info["epsilon"][:take])
            self.powers.append(info["average_power"][:take])
            self.energies.append(info["input_energy"][:take])


def _play_batches(
    tally: _Tally,
    attacker: Attacker,
    cfg: dict[str, Any],
    B: int,
    episodes: int,
    seed: int,
    *,
    record: bool,
    progress: Any,
    covariance: bool,
) -> None:
    """The ideal backend: ``episodes`` episodes in batches of ``B`` copies of the vector environment."""
    from encctl_gym.envs.vector import EncryptedLTIAttackVectorEnv

    env = EncryptedLTIAttackVectorEnv(B, config=cfg)
    done_eps = 0
    chunk = 0
    while done_eps < episodes:
        obs, info = env.reset(seed=seed + done_eps)
        attacker.reset(seed=np.random.SeedSequence([seed, chunk]))
        eps_t, en_t, Ns = [], [], []
        while True:
            obs, _, te, tr, info = env.step(attacker.act(obs))
            if record:
                eps_t.append(info["epsilon"])
                en_t.append(info["input_energy"])
                Ns.append(int(info["samples_delivered"][0]))
            if progress is not None:
                progress.update(B)
            if te[0] or tr[0]:
                break
        take = min(B, episodes - done_eps)
        if covariance:
            tally.add_gram(env.episode, take)
        tally.eps_rows.append(np.stack(eps_t, axis=1)[:take] if record else info["epsilon"][:take, None])
        tally.en_rows.append(np.stack(en_t, axis=1)[:take] if record else info["input_energy"][:take, None])
        if tally.N_steps is None:
            tally.N_steps = np.array(Ns if record else [int(info["samples_delivered"][0])])
        tally.add_finals(info, take)
        done_eps += take
        chunk += 1


def _play_single(
    tally: _Tally,
    attacker: Attacker,
    cfg: dict[str, Any],
    episodes: int,
    seed: int,
    *,
    record: bool,
    progress: Any,
    covariance: bool,
) -> None:
    """A cryptographic backend: ``episodes`` episodes one at a time through the single environment."""
    from encctl_gym.envs import EncryptedLTIAttackEnv

    env1 = EncryptedLTIAttackEnv(config=cfg)
    for e in range(episodes):
        obs, info = env1.reset(seed=seed + e)
        attacker.reset(seed=np.random.SeedSequence([seed, e]))
        eps_t, en_t, Ns = [], [], []
        while True:
            obs, _, te1, tr1, info = env1.step(attacker.act(obs))
            if record:
                eps_t.append(info["epsilon"])
                en_t.append(info["input_energy"])
                Ns.append(info["samples_delivered"])
            if progress is not None:
                progress.update(1)
            if te1 or tr1:
                break
        if covariance:
            tally.add_gram(env1.episode, 1)
        tally.eps_rows.append(np.array(eps_t if record else [info["epsilon"]])[None])
        tally.en_rows.append(np.array(en_t if record else [info["input_energy"]])[None])
        if tally.N_steps is None:
            tally.N_steps = np.array(Ns if record else [info["samples_delivered"]])
        tally.add_finals(info, None)


def design_efficiency(covariance: np.ndarray, design: Any) -> float:
    """``tr(Sigma_opt^-1) / tr(Sigma^-1)``: how close a realised regressor covariance comes to
    the A-optimal design at the same input power (1 for the optimum, ``0.77`` for the Gaussian
    attack on the design example).

    The large-N error of least squares is ``sigma_w2 tr(Sigma^-1) / ((n + m)(N - 1))``, so this
    is the ratio of ``gamma_opt(N)`` to the error the realised ``Sigma`` implies: a measure of the
    attack *design* without the noise of the estimate's error (which needs hundreds of episodes
    to resolve a few per cent). ``Sigma`` from :func:`rollout` with ``covariance=True``,
    ``design`` an :class:`~encctl_gym.security.attack_design.AttackDesign`.
    """
    S = np.asarray(covariance, dtype=float)
    w = np.linalg.eigvalsh(0.5 * (S + S.T))
    if w.min() <= 0.0:
        return 0.0  # a singular regressor covariance: nothing identified in some direction
    return float(design.trace_inv / np.sum(1.0 / w))
