"""The measured defences through real ElGamal, and against a learned attacker (the ``--elgamal`` and
``--ars`` rows of :mod:`encctl_gym.experiments.defenses`).

* :func:`elgamal_rows`: every defender of
  :data:`~encctl_gym.experiments.defenses.MEASURED_DEFENDERS` through ``crypto="elgamal"`` at a
  64-bit key with the index-calculus breaker (every key the attacker pays for is broken for real,
  def:adversary; the states are decrypted with the recovered exponents only), against the
  Gaussian, AR(1) and optimal-design attackers on short attacks (``max_samples``). The same
  attacks (same seeds, same cap) run on the ideal backend next to it, so the two backends can be
  compared episode by episode. Per row: the detection rate (Wilson 95 % interval), the detection delay, the samples
  collected, the final error over ``gamma_c``, the breaker's precomputations charged (one per group
  and episode) and their seconds, the keys broken and the seconds per key, and the defender's own
  time per step against the undefended ElGamal step.
* :func:`ars_rows`: a learned attacker (a training run of :mod:`encctl_gym.agents.train`, trained
  without any defence) against every defender on the ideal backend, rows of the measured table
  (:func:`~encctl_gym.experiments.defenses.format_measured`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym.experiments.defenses_measured import MEASURED_DEFENDERS, _attackers, _defender_spec, _episodes, _iqr, measured_row
from encctl_gym.presets import get_preset

__all__ = ["ELGAMAL_ATTACKERS", "elgamal_rows", "format_elgamal", "ars_rows"]

ENV_ID = "encctl_gym/EncryptedLTIAttack-v0"

#: The attackers of the ElGamal rows (names of :func:`~encctl_gym.experiments.defenses._attackers`).
ELGAMAL_ATTACKERS: tuple[str, ...] = ("gaussian", "ar1", "optimal")


class _BreakTally:
    """The loop's decipherer with the cost records of every episode kept (its own ``costs`` only
    hold the current episode's): ``episodes[i]`` is the list of ``(method, cost)`` of the i-th
    episode started since the tally was installed."""

    def __init__(self, loop: Any) -> None:
        self.inner, self.loop = loop.decipherer, loop
        self.episodes: list[list[tuple[str, Any]]] = []
        loop.decipherer = self

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)

    def start_episode(self) -> None:
        self.inner.start_episode()
        self.episodes.append(self.inner.costs)  # the list the inner decipherer fills this episode

    def remove(self) -> None:
        self.loop.decipherer = self.inner


def _config(system: str, spec: Any, crypto: str, samples: int, seed: int, key_length: int, breaker: str, limit: float) -> dict:
    p = get_preset(system)
    config: dict[str, Any] = {
        "preset": system,
        "decipher_delay": 0,
        "defender": _defender_spec(spec, p),
        "key_length": key_length,
        "max_samples": samples,
        "crypto_seed": seed,
        "gamma_opt": False,
    }
    if crypto == "elgamal":
        config.update(crypto="elgamal", breaker=breaker, breaker_time_limit=limit)
    return config


def elgamal_rows(
    system: str = "paper-example",
    *,
    samples: int = 200,
    episodes: int = 3,
    seed: int = 0,
    attackers: tuple[str, ...] = ELGAMAL_ATTACKERS,
    key_length: int = 64,
    breaker: str = "index-calculus",
    breaker_time_limit: float = 60.0,
) -> list[dict[str, Any]]:
    """Every measured defender through real ElGamal with a real breaker, and the same attacks on
    the ideal backend.

    Parameters
    ----------
    system : str
        Preset name.
    samples : int
        ``max_samples`` of every attack (the attacks are truncated there).
    episodes : int
        Episodes per defender and attacker (environment seeds ``seed``, ``seed + 1``, ...).
    seed : int
        Seed of the episodes and ``crypto_seed`` of the loop.
    attackers : tuple of str
        Attackers of :func:`~encctl_gym.experiments.defenses._attackers`.
    key_length, breaker, breaker_time_limit
        The loop's key and the key breaker of :mod:`encctl_gym.cryptanalysis` (a breaker expected
        to take longer than ``breaker_time_limit`` seconds is refused when the environment is made).

    Returns
    -------
    list of dict
        One row per defender and attacker: ``elgamal`` (the measured table's row,
        :func:`~encctl_gym.experiments.defenses.measured_row`), ``ideal`` (the same on the ideal
        backend), ``same_as_ideal`` (episodes whose detection and samples collected agree on
        both backends), ``samples_total`` (collected, summed over the ElGamal episodes), ``precomputations`` (charged, summed over episodes), ``precomputation_seconds``
        (their seconds), ``keys`` (broken, summed), ``seconds_per_key``, ``breaker_seconds``.
    """
    import gymnasium as gym

    import encctl_gym  # noqa: F401  (registers the environment)

    p = get_preset(system)
    rows: list[dict[str, Any]] = []
    base: dict[tuple[str, str], float] = {}
    for label, spec in MEASURED_DEFENDERS:
        runs: dict[str, dict[str, Any]] = {}
        for crypto in ("ideal", "elgamal"):
            env = gym.make(ENV_ID, config=_config(system, spec, crypto, samples, seed, key_length, breaker, breaker_time_limit))
            horizon = env.unwrapped.params.horizon  # type: ignore[attr-defined]
            pool = _attackers(env)
            for name in attackers:
                tally = _BreakTally(env.unwrapped.episode.loop) if crypto == "elgamal" else None  # type: ignore[attr-defined]
                eps, per_step, defender_step = _episodes(env, pool[name], episodes, seed)
                if label == "none":
                    base[(crypto, name)] = per_step
                row = measured_row(system, label, name, eps, horizon, p.gamma_c, per_step, defender_step, base[(crypto, name)])
                runs.setdefault(name, {})[crypto] = (row, eps)
                if tally is not None:
                    tally.remove()
                    costs = [c for episode in tally.episodes[-episodes:] for c in episode]  # after _episodes' warm-up
                    pre = [c.seconds for method, c in costs if method == "precomputation"]
                    keys = [c.seconds for method, c in costs if method != "precomputation"]
                    runs[name]["breaker"] = {
                        "precomputations": len(pre),
                        "precomputation_seconds": float(np.mean(pre)) if pre else float("nan"),
                        "keys": len(keys),
                        "seconds_per_key": float(np.mean(keys)) if keys else float("nan"),
                        "breaker_seconds": float(sum(pre) + sum(keys)),
                    }
            env.close()
        for name in attackers:
            (ideal, ideal_eps), (elg, elg_eps) = runs[name]["ideal"], runs[name]["elgamal"]
            same = sum(a["detected"] == b["detected"] and a["samples"] == b["samples"] for a, b in zip(ideal_eps, elg_eps))
            total = sum(e["samples"] for e in elg_eps)
            rows.append({"elgamal": elg, "ideal": ideal, "same_as_ideal": same, "samples_total": total, **runs[name]["breaker"]})
    return rows


def format_elgamal(rows: list[dict[str, Any]]) -> str:
    """The ElGamal table as markdown."""
    out = [
        "| defender | attacker | detected [95 % CI] | detection delay, median [IQR] | samples collected, median [IQR] "
        "| final E[eps] / gamma_c, median [IQR] | ideal backend: detected / samples / E[eps] / gamma_c (medians) "
        "| episodes alike (detected, samples) | precomputations charged, s each | keys broken, s per key "
        "| defender's own time per step (us) | time per step (ms) / undefended |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        e, i = r["elgamal"], r["ideal"]
        lo, hi = e["detection_interval"]
        out.append(
            f"| {e['defender']} | {e['attacker']} | {e['detection_rate']:.0%} [{lo:.0%}, {hi:.0%}] | {_iqr(e['delay'], '.0f')} | "
            f"{_iqr(e['samples'], '.0f')} of {e['horizon']} | {_iqr(e['error_over_gamma_c'])} | "
            f"{i['detection_rate']:.0%} / {i['samples'][1]:.0f} / {i['error_over_gamma_c'][1]:.3g} | "
            f"{r['same_as_ideal']} of {e['episodes']} | {r['precomputations']}, {r['precomputation_seconds']:.2g} | "
            f"{r['keys']}, {r['seconds_per_key']:.2g} | {1e6 * e['defender_seconds_per_step']:.1f} | "
            f"{1e3 * e['seconds_per_step']:.2f} / {e['time_ratio']:.2f} |"
        )
    return "\n".join(out)


def ars_rows(
    run_dir: str | Path, system: str = "paper-example", *, episodes: int = 5, seed: int = 0, max_samples: int | None = None
) -> list[dict[str, Any]]:
    """A learned attacker trained without any defence against every defender of
    :data:`~encctl_gym.experiments.defenses.MEASURED_DEFENDERS`: rows of the measured table
    (ideal backend, ``decipher_delay = 0``, the system's own ``tau_c``; the environment's
    ``input_history`` is the run's, the observation layout its policy reads), attacker ``ars``;
    ``max_samples`` caps the attacks (``None``: the horizon ``tau_c`` buys).

    Raises
    ------
    ConfigError
        If ``run_dir`` is not a loadable training run (:func:`encctl_gym.agents.load_attacker`).
    """
    import gymnasium as gym

    import encctl_gym  # noqa: F401  (registers the environment)
    from encctl_gym.agents.runs import read_run
    from encctl_gym.errors import OptionalDependencyError

    p = get_preset(system)
    history = read_run(run_dir).env.get("input_history")  # a missing run is named before any extra is needed
    try:
        from encctl_gym.agents import load_attacker
    except ModuleNotFoundError as exc:
        raise OptionalDependencyError(
            f"playing a trained run needs the rl extra ({exc.name} is missing): pip install 'encctl-gym[rl]'"
        ) from None
    rows: list[dict[str, Any]] = []
    base = float("nan")
    for label, spec in MEASURED_DEFENDERS:
        config: dict[str, Any] = {"preset": system, "decipher_delay": 0, "defender": _defender_spec(spec, p), "gamma_opt": False}
        if history is not None:
            config["input_history"] = history
        if max_samples is not None:
            config["max_samples"] = max_samples
        env = gym.make(ENV_ID, config=config)
        params = env.unwrapped.params  # type: ignore[attr-defined]
        att = load_attacker(run_dir, params=params, name="ars")
        eps, per_step, defender_step = _episodes(env, att, episodes, seed)
        if label == "none":
            base = per_step
        rows.append(measured_row(system, label, "ars", eps, params.horizon, p.gamma_c, per_step, defender_step, base))
        env.close()
    return rows
