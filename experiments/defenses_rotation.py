"""Group rotation on the design example (the rotation rows of :mod:`encctl_gym.experiments.defenses`,
``--rotation``): the key length each rotation period needs under the precomputation and paper
models, and one episode per period through real ElGamal at 64 bits with a real breaker (one
precomputation per group, counted and timed)."""

from __future__ import annotations

from fractions import Fraction
from typing import Any

import numpy as np

from encctl_gym.presets import get_preset
from encctl_gym.security.defenses import noise_defense_design
from encctl_gym.security.threat import ThreatModel

__all__ = ["ROTATION_PERIODS", "rotation_rows", "format_rotation"]


#: Rotation periods of the rotation rows (``None``: ``K = N*``, one group for the whole attack).
ROTATION_PERIODS: tuple[int | None, ...] = (1, 10, 100, None)


def rotation_rows(samples: int = 200, seed: int = 0, breaker: str = "index-calculus") -> dict[str, list[dict[str, Any]]]:
    """Group rotation on the design example: the key length it needs, and the loop measured.

    ``design``: per ``K`` of :data:`ROTATION_PERIODS`, ``k*`` under the precomputation model
    charged per group (:func:`~encctl_gym.security.rotation.rotated_minimum_key_length`) and under
    the paper model, the plant side's cost per step amortised over ``K`` (``n m / K`` encryptions,
    their bytes, and the generation of one ``k*``-bit group, by the package's time model and
    measured once here).

    ``measured``: one episode of ``samples`` samples per ``K`` through real ElGamal at 64 bits
    with ``breaker`` and the Gaussian attacker (``crypto_seed = seed``): the groups met, the
    breaker's precomputations (counted on its cost records) and their seconds, the seconds per key,
    and what the plant side spent.
    """
    from encctl_gym.security.key_length import defense_budget

    p = get_preset("paper-example")
    N_star = int(noise_defense_design(p.plant(), ThreatModel.of(p), sigma_d2=0.0).N_star)
    budget = defense_budget(p.tau_c, p.upsilon)
    design = _design_rows(p, N_star, budget, seed)
    measured = [_measured_row(p, K, N_star, samples, seed, breaker) for K in ROTATION_PERIODS]
    return {"design": design, "measured": measured}


def _design_rows(p: Any, N_star: int, budget: Fraction, seed: int) -> list[dict[str, Any]]:
    """The ``design`` rows of :func:`rotation_rows`, one per ``K`` of :data:`ROTATION_PERIODS`."""
    import time as _time

    from encctl_gym.crypto.group import estimate_generation_seconds, generate_safe_prime_group
    from encctl_gym.loop.provisioning import provisioning_bytes
    from encctl_gym.security.cost_models import PaperModel, PrecomputationModel
    from encctl_gym.security.rotation import rotated_minimum_key_length

    n, m = p.A.shape[0], p.B.shape[1]
    design: list[dict[str, Any]] = []
    for K in ROTATION_PERIODS:
        every = N_star if K is None else K
        k_pre = rotated_minimum_key_length(PrecomputationModel(), N_star, every, budget)
        k_paper = rotated_minimum_key_length(PaperModel(), N_star, every, budget)
        t0 = _time.perf_counter()
        group = generate_safe_prime_group(k_pre, rng=seed + every)
        generated = _time.perf_counter() - t0
        design.append(
            {
                "K": every,
                "label": f"N* = {N_star}" if K is None else str(K),
                "k_star_precomputation": k_pre,
                "k_star_paper": k_paper,
                "encryptions_per_step": n * m / every,
                "bytes_per_step": provisioning_bytes(group, n * m) / every,
                "generation_model_seconds": estimate_generation_seconds(k_pre),
                "generation_seconds": generated,
            }
        )
    return design


def _measured_row(p: Any, K: int | None, N_star: int, samples: int, seed: int, breaker: str) -> dict[str, Any]:
    """One ``measured`` row of :func:`rotation_rows`: an episode of the Gaussian attacker with the
    group rotated every ``K`` samples (``None``: ``N*``)."""
    import time as _time

    import gymnasium as gym

    import encctl_gym  # noqa: F401  (registers the environment)
    from encctl_gym.agents import GaussianAttacker

    every = N_star if K is None else K
    config = {
        "preset": "paper-example",
        "crypto": "elgamal",
        "key_length": 64,
        "breaker": breaker,
        "deciphering_model": "precomputation",
        "max_samples": samples,
        "rotate_group_every": every,
        "crypto_seed": seed,
        "gamma_opt": False,
    }
    env = gym.make("encctl_gym/EncryptedLTIAttack-v0", config=config)
    att = GaussianAttacker(env.unwrapped.params)  # type: ignore[attr-defined]
    obs, info = env.reset(seed=seed)
    att.reset(seed=seed)
    steps, t0 = 0, _time.perf_counter()
    while True:
        obs, _, term, trunc, info = env.step(att.act(obs[None])[0])
        steps += 1
        if term or trunc:
            break
    wall = _time.perf_counter() - t0
    loop = env.unwrapped.episode.loop  # type: ignore[attr-defined]
    costs = list(loop.decipherer.costs)
    pre = [c.seconds for method, c in costs if method == "precomputation"]
    keys = [c.seconds for method, c in costs if method != "precomputation"]
    row = {
        "K": every,
        "label": f"N* = {N_star}" if K is None else str(K),
        "samples": int(info["samples_collected"]),
        "groups": int(info["groups"]),
        "groups_expected": -(-int(info["samples_collected"]) // every),
        "precomputations": int(info["breaker_precomputations"]),
        "precomputation_seconds": float(sum(pre)),
        "seconds_per_key": float(np.mean(keys)) if keys else float("nan"),
        "breaker_seconds": float(loop.deciphering_seconds),
        "encryptions": int(info["provisioning_encryptions"]),
        "bytes": int(info["provisioning_bytes"]),
        "generation_seconds": float(info["group_generation_seconds"]),
        "generation_model_seconds": float(info["group_generation_model_seconds"]),
        "wait_seconds": float(info["group_wait_seconds"]),
        "seconds_per_step": wall / steps,
        "error_over_gamma_c": float(info["epsilon"]) / p.gamma_c,
    }
    env.close()
    return row


def format_rotation(rows: dict[str, list[dict[str, Any]]]) -> str:
    """Both rotation tables as markdown."""
    out = [
        "| K | k* (precomputation model, per group) | k* (paper model) | encryptions per step | bytes per step "
        "| group generation at k* bits: model / measured (s) |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows["design"]:
        out.append(
            f"| {r['label']} | {r['k_star_precomputation']} | {r['k_star_paper']} | {r['encryptions_per_step']:.4g} | "
            f"{r['bytes_per_step']:.4g} | {r['generation_model_seconds']:.3g} / {r['generation_seconds']:.3g} |"
        )
    out += [
        "",
        "| K | samples | groups (ceil(N/K)) | breaker precomputations | precomputation s (total) | s per key "
        "| breaker s (total) | encryptions re-provisioned | bytes | generation s: measured / model | waited s | s per step |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows["measured"]:
        out.append(
            f"| {r['label']} | {r['samples']} | {r['groups']} ({r['groups_expected']}) | {r['precomputations']} | "
            f"{r['precomputation_seconds']:.3g} | {r['seconds_per_key']:.2g} | {r['breaker_seconds']:.3g} | "
            f"{r['encryptions']} | {r['bytes']} | {r['generation_seconds']:.3g} / {r['generation_model_seconds']:.3g} | "
            f"{r['wait_seconds']:.2g} | {r['seconds_per_step']:.3g} |"
        )
    return "\n".join(out)
