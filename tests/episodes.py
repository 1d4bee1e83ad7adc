"""One home for the tests' episode rollout: reset, then uniform random (or zero) actions until the
episode ends or ``steps`` actions have been taken; the observations come back in order.

Imported by the tests as ``from episodes import rollout`` (pytest puts ``tests/`` on the path, as
for ``probe``).
"""

from __future__ import annotations

from typing import Any

import numpy as np


def rollout(env: Any, *, seed: int, action_seed: int, steps: int | None = None, actions: str = "random") -> list[np.ndarray]:
    """Observations of one episode of ``env`` from ``reset(seed=seed)``; the actions are drawn
    from ``default_rng(action_seed)`` uniform on [-1, 1] (``actions="zero"``: all zero)."""
    if actions not in ("random", "zero"):
        raise ValueError(f"actions must be 'random' or 'zero', got {actions!r}")
    obs, _ = env.reset(seed=seed)
    out, rng = [obs], np.random.default_rng(action_seed)
    taken = 0
    while steps is None or taken < steps:
        a = rng.uniform(-1, 1, env.action_space.shape) if actions == "random" else np.zeros(env.action_space.shape)
        obs, _, term, trunc, _ = env.step(a.astype(np.float32))
        out.append(obs)
        taken += 1
        if term or trunc:
            break
    return out
