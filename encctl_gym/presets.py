"""The paper's systems as named presets.

One place for the systems of Section "Numerical Simulation", so the environment, the ``design``
command and the experiments all mean the same plant by the same name.

=================  ==========================================================================
name               system
=================  ==========================================================================
paper-example      design example: Psi_w = 2I, Psi_u = 0.5I, R_sigma = 100 (n = m = 4),
                   gamma_c = 1e-6, tau_c = 10 years, Upsilon = 442e15 FLOPS (Fugaku)
fig1-a ... fig1-i  Figure 1: A = 0.7071 I, B = I, sigma_w2 x sigma_u2 in {0.1, 1, 10}^2,
                   panels in the paper's order (a) = (0.1, 0.1), (b) = (0.1, 1), ...
fig2-psi<v>        Figure 2: Psi_w = 2I, R_sigma = 100, Psi_u = v I, v in {2, 1, 0.5, 0.3, 0.2,
                   0.1}; A = I/sqrt(2) and B = b I with b = sqrt(v (1 - 1/2))
small              n = m = 2 system for quick training runs (not from the paper), gamma_c = 1e-3
small-output       ``small`` measured through ``C = [1 0]`` with ``sigma_v2 = 0.01`` (one output)
=================  ==========================================================================

The design example fixes only the ratio R_sigma = sigma_u2 / sigma_w2 = 100; its absolute
variances here (sigma_w2 = 0.1, sigma_u2 = 10) are those of Figure 1 (c), which has the same ratio.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .registry import Registry
from .units import SECONDS_PER_YEAR

__all__ = [
    "SystemPreset",
    "PRESETS",
    "get_preset",
    "preset_names",
    "SECONDS_PER_YEAR",
    "FUGAKU_FLOPS",
    "PAPER_DESIGN_PARAMETERS",
    "PAPER_VARIANCES",
    "PAPER_DESIGN_EXAMPLE",
    "PAPER_REPORTED",
    "DESIGN_FIELDS",
    "design_defaults",
]

# --------------------------------------------------------------------------- the paper's constants
# One home for every number the paper states (Section "Numerical Simulation"); the presets, the
# ``design`` command, the security module and the experiments all read them from here.

#: Supercomputer Fugaku, the paper's adversary computer (FLOPS).
FUGAKU_FLOPS = 442e15
#: The design parameters of the design example: gamma_c, tau_c = 10 years (s), Upsilon (FLOPS).
PAPER_DESIGN_PARAMETERS: dict[str, float] = {"gamma_c": 1e-6, "tau_c": 31536e4, "upsilon": FUGAKU_FLOPS}
#: Variances: the design example fixes only R_sigma = 100; these are Figure 1 (c)'s (same ratio),
#: and sigma_x2 = 1 as in all of the paper's simulations.
PAPER_VARIANCES: dict[str, float] = {"sigma_u2": 10.0, "sigma_w2": 0.1, "sigma_x2": 1.0}
#: The design example from its Gramian traces (Psi_w = 2I, Psi_u = 0.5I, n = m = 4).
PAPER_DESIGN_EXAMPLE: dict[str, float | int] = {
    "tr_psi_u": 2,
    "tr_psi_w": 8,
    "m": 4,
    "n": 4,
    **PAPER_VARIANCES,
    **PAPER_DESIGN_PARAMETERS,
}
#: What the paper reports for its design example: shown beside computed values, never used to compute them.
PAPER_REPORTED: dict[str, int] = {"N_star": 13159, "lam_star": 74, "k_star": 712}
#: The design parameters a plant needs besides A and B.
DESIGN_FIELDS: tuple[str, ...] = ("sigma_u2", "sigma_w2", "sigma_x2", "gamma_c", "tau_c", "upsilon")


@dataclass(frozen=True)
class SystemPreset:
    """A plant of eq:system with its noise and attack variances and the design parameters."""

    name: str
    description: str
    A: np.ndarray
    B: np.ndarray
    sigma_w2: float
    sigma_u2: float
    sigma_x2: float = PAPER_VARIANCES["sigma_x2"]
    gamma_c: float = PAPER_DESIGN_PARAMETERS["gamma_c"]
    tau_c: float = PAPER_DESIGN_PARAMETERS["tau_c"]
    upsilon: float = PAPER_DESIGN_PARAMETERS["upsilon"]
    extra: dict = field(default_factory=dict)
    #: output matrix of ``y = C x + v`` (``None``: the state is measured) and the variance of ``v``
    C: np.ndarray | None = None
    sigma_v2: float = 0.0

    @property
    def n(self) -> int:
        return int(self.A.shape[0])

    @property
    def m(self) -> int:
        return int(self.B.shape[1])

    @property
    def r_sigma(self) -> float:
        return self.sigma_u2 / self.sigma_w2

    def plant(self) -> Any:
        """The plant as the value object :class:`~encctl_gym.plant.Plant` (with ``C`` and
        ``sigma_v2`` when the preset measures outputs)."""
        from .plant import Plant

        return Plant(self.A, self.B, C=self.C, sigma_v2=self.sigma_v2)


def _diag_system(a: float, b: float, n: int = 4) -> tuple[np.ndarray, np.ndarray]:
    return a * np.eye(n), b * np.eye(n)


def _build() -> dict[str, SystemPreset]:
    presets: dict[str, SystemPreset] = {}
    half = math.sqrt(0.5)  # exactly 1/sqrt(2), so Psi_w = I / (1 - 1/2) = 2I
    A, B = _diag_system(half, 0.5)
    presets["paper-example"] = SystemPreset(
        "paper-example",
        "design example of Section 'Numerical Simulation': Psi_w = 2I, Psi_u = 0.5I, R_sigma = 100",
        A,
        B,
        sigma_w2=PAPER_VARIANCES["sigma_w2"],
        sigma_u2=PAPER_VARIANCES["sigma_u2"],
    )
    variances = [0.1, 1.0, 10.0]
    letters = "abcdefghi"
    k = 0
    for sw in variances:
        for su in variances:
            A, B = _diag_system(0.7071, 1.0)
            name = f"fig1-{letters[k]}"
            presets[name] = SystemPreset(
                name,
                f"Figure 1 ({letters[k]}): A = 0.7071 I, B = I, sigma_w2 = {sw}, sigma_u2 = {su}, R_sigma = {su / sw:g}",
                A,
                B,
                sigma_w2=sw,
                sigma_u2=su,
            )
            k += 1
    for psi_u in [2.0, 1.0, 0.5, 0.3, 0.2, 0.1]:
        b = math.sqrt(psi_u * (1 - half * half))
        A, B = _diag_system(half, b)
        name = f"fig2-psi{psi_u:g}"
        presets[name] = SystemPreset(
            name,
            f"Figure 2: Psi_w = 2I, Psi_u = {psi_u:g} I (A = I/sqrt(2), B = {b:.6g} I), R_sigma = 100",
            A,
            B,
            sigma_w2=0.1,
            sigma_u2=10.0,
            extra={"psi_u": psi_u},
        )
    presets["small"] = SystemPreset(
        "small",
        "n = m = 2 system for quick training runs (not from the paper)",
        np.array([[0.6, 0.2], [-0.1, 0.5]]),
        np.array([[1.0, 0.0], [0.3, 0.8]]),
        sigma_w2=0.1,
        sigma_u2=1.0,
        gamma_c=1e-3,
    )
    presets["small-output"] = SystemPreset(
        "small-output",
        "the 'small' plant measured through its first state only (C = [1 0], sigma_v2 = 0.01)",
        presets["small"].A,
        presets["small"].B,
        sigma_w2=0.1,
        sigma_u2=1.0,
        gamma_c=1e-3,
        C=np.array([[1.0, 0.0]]),
        sigma_v2=0.01,
    )
    return presets


#: The presets by name (:class:`~encctl_gym.registry.Registry`).
PRESETS: Registry[SystemPreset] = Registry("preset", _build())


def preset_names() -> list[str]:
    """Names of the built-in presets."""
    return PRESETS.names()


def get_preset(name: str) -> SystemPreset:
    """Return the preset ``name``, raising :class:`ParameterError` for an unknown name (or a non-string)."""
    return PRESETS.lookup(name)


def design_defaults() -> dict[str, float]:
    """The design parameters of the paper's design example (preset ``paper-example``), by
    :data:`DESIGN_FIELDS`: the defaults of ``encctl-gym design`` and of plant files."""
    p = PRESETS["paper-example"]
    return {key: getattr(p, key) for key in DESIGN_FIELDS}
