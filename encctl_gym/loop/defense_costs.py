"""The defender's cost terms on the reference machine, for the design of
:mod:`encctl_gym.security.defense_design` (which, as mathematics, imports no cryptography).

* one modular exponentiation at ``k`` bits: the measured per-size model
  :func:`encctl_gym.crypto.group.modular_exponentiation_seconds`;
* one safe-prime search: :func:`encctl_gym.crypto.group.estimate_generation_seconds`;
* one audit: the plant side's own check, measured here (:func:`measure_local_control_seconds`).

:func:`design_loop_defenses` runs the design with them and the loop's controller
(``Phi = -lqr_gain(A, B)``, :func:`~encctl_gym.loop.backend.lqr_gain`).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from .._validation import check_int, check_nonnegative
from ..crypto.group import estimate_generation_seconds, modular_exponentiation_seconds
from ..plant import as_plant
from ..security.defense_design import DefenderCosts, design_defenses
from ..security.threat import ThreatModel
from .backend import lqr_gain
from .detection import Audit

__all__ = ["design_loop_defenses", "measure_local_control_seconds", "reference_defender_costs"]


def measure_local_control_seconds(n: int, m: int, repeats: int = 2000) -> float:
    """The measured time of one audit: the plant side computes ``Phi x`` itself and compares it
    with the decrypted input (:class:`~encctl_gym.loop.detection.Audit` at rate 1, one loop).
    The median over ``repeats`` calls, in seconds."""
    n = check_int("n", n, minimum=1)
    m = check_int("m", m, minimum=1)
    repeats = check_int("repeats", repeats, minimum=1, maximum=10**7)
    rng = np.random.default_rng(0)
    Phi, x = rng.standard_normal((m, n)), rng.standard_normal((1, n))
    audit = Audit(Phi, 1.0, [np.random.default_rng(1)], tolerance=1e-9)
    u = x @ Phi.T
    times = np.empty(repeats)
    for i in range(repeats):
        t0 = time.perf_counter()
        audit.check(x, u)
        times[i] = time.perf_counter() - t0
    return float(np.median(times))


def reference_defender_costs(n: int, m: int, *, local_control_seconds: float | None = None) -> DefenderCosts:
    """The cost terms of the module docstring for an ``n``-state, ``m``-input loop (the audit is
    measured unless ``local_control_seconds`` is given)."""
    local = (
        measure_local_control_seconds(n, m)
        if local_control_seconds is None
        else check_nonnegative("local_control_seconds", local_control_seconds)
    )
    return DefenderCosts(n, m, modular_exponentiation_seconds, estimate_generation_seconds, local)


def design_loop_defenses(plant: Any, threat: ThreatModel, *, local_control_seconds: float | None = None, **options: Any) -> Any:
    """:func:`~encctl_gym.security.defense_design.design_defenses` with the reference machine's
    costs and the loop's LQR controller; ``options`` are its keywords (``rotate_every``,
    ``audit_rate``, ``detection_delta``, ``sigma_d2``, ``cost_models``, ...); ``verify``
    (``{"name", "params"}``) adds the check of
    :func:`~encctl_gym.security.verification_design.design_verification`, measured."""
    p = as_plant(plant)
    costs = reference_defender_costs(p.n, p.m, local_control_seconds=local_control_seconds)
    verify = options.pop("verify", None)  # --verify (issue 33): the check priced per step
    design = design_defenses(p, threat, costs=costs, controller=-lqr_gain(p.A, p.B), **options)
    if verify is None:
        return design
    from ..security.verification_design import design_verification
    from .verification import measure_check_seconds

    return design_verification(design, costs, verify, check_seconds=measure_check_seconds(p.m, p.n))
