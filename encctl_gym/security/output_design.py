"""The design of a plant measured through outputs, beside the state-measured design of the same plant.

There is no closed form for the expected error of subspace identification, so the design follows
an empirical sample identifying complexity (:mod:`encctl_gym.security.empirical`). For a plant
with sensors ``C`` and measurement noise ``sigma_v2`` (:class:`~encctl_gym.plant.Plant`),
:func:`output_design` computes, on one log grid of attack lengths ``N`` and one set of simulated
Gaussian attacks (:func:`~encctl_gym.sim.output.output_attack_errors`):

1. **the state-measured design** of the paper, eq:sic2 and Theorem thm:opt_sec
   (:func:`~encctl_gym.security.design.design_security_parameter`), and its empirical twin: least
   squares on the states (``C = I``, ``sigma_v2 = 0``), Definition def:error, fitted
   ``c / N^a`` and designed against ``gamma_c`` (:func:`~encctl_gym.security.empirical.empirical_design`);
2. **the accuracy target moved into a basis-free error**: the fitted Markov-parameter error
   (:func:`~encctl_gym.ident.subspace.markov_error`) of that same state least squares at the
   paper's ``N*``. Definition def:error needs the state basis, which a subspace estimate does not
   have; the target is the accuracy the paper's design protects, in an error both attackers share;
3. **the output-measured design**: the chosen estimator (N4SID, PO-MOESP or ARX) on ``y = C x + v``,
   fitted and designed against that target, ``N*``, ``lambda*`` and ``k*`` with the intervals the
   bootstrap carries to them. The target is a Monte Carlo estimate too: each bootstrap replicate
   of the output fit designs against the same replicate of the target (the two fits resample the
   same runs), so the intervals carry its spread (``reference=`` of
   :func:`~encctl_gym.security.empirical.empirical_design`).

``encctl-gym design plant.yaml --estimator n4sid`` prints :func:`format_output_design`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import check_int
from ..errors import ParameterError
from ..plant import Plant, as_plant
from .design import SecurityDesign, design_security_parameter
from .empirical import EmpiricalComplexity, EmpiricalDesign, empirical_design, fit_empirical_complexity
from .threat import ThreatModel

__all__ = ["OutputDesign", "output_design", "format_output_design", "output_design_grid"]


@dataclass(frozen=True)
class OutputDesign:
    """:func:`output_design`'s result (module docstring, steps 1 to 3).

    Attributes
    ----------
    estimator : str
        The output-side method.
    paper : SecurityDesign
        eq:sic2 design of the state-measured plant.
    state_fit, state_design : EmpiricalComplexity, EmpiricalDesign
        Least squares on the states, Definition def:error, against ``gamma_c``.
    target : float
        The Markov-parameter error of state least squares at the paper's ``N*`` (fitted); its
        bootstrap interval is ``output_design.target_interval``.
    output_fit : EmpiricalComplexity
        The estimator on the outputs, Markov-parameter error.
    output_design : EmpiricalDesign or None
        Its design against ``target``; ``None`` (with :attr:`note`) when the fitted error does
        not decrease.
    note : str
        Why there is no output design, else empty.
    p, sigma_v2 : int, float
        Output dimension and measurement noise of the plant.
    """

    estimator: str
    paper: SecurityDesign
    state_fit: EmpiricalComplexity
    state_design: EmpiricalDesign
    target: float
    output_fit: EmpiricalComplexity
    output_design: EmpiricalDesign | None
    note: str
    p: int
    sigma_v2: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""

        def fit(f: EmpiricalComplexity) -> dict[str, Any]:
            return {"a": f.a, "a_interval": list(f.a_interval), "c": f.c, "c_interval": list(f.c_interval), "runs": f.runs,
                    "N": f.N.tolist(), "mean": f.mean.tolist(), "low": f.low.tolist(), "high": f.high.tolist()}  # fmt: skip

        def des(d: EmpiricalDesign | None) -> dict[str, Any] | None:
            if d is None:
                return None
            return {"N_star": d.N_star, "N_star_interval": list(d.N_star_interval), "lambda_star": d.lambda_star,
                    "lambda_star_interval": list(d.lambda_star_interval), "k_star": d.k_star,
                    "k_star_interval": list(d.k_star_interval), "extrapolated": d.extrapolated}  # fmt: skip

        return {
            "estimator": self.estimator,
            "p": self.p,
            "sigma_v2": self.sigma_v2,
            "paper": {"N_star": self.paper.N_star, "lambda_star": self.paper.lam_star, "k_star": self.paper.k_star},
            "state_least_squares": {"fit": fit(self.state_fit), "design": des(self.state_design)},
            "markov_target": self.target,
            "markov_target_interval": None if self.output_design is None else list(self.output_design.target_interval or ()),
            "output": {"fit": fit(self.output_fit), "design": des(self.output_design), "note": self.note},
        }


def output_design_grid(N_star: int, points: int) -> np.ndarray:
    """The log grid of attack lengths from ``max(50, N* / 4)`` to ``2 N*`` (``points`` distinct sizes):
    around the paper's ``N*``, so that the designs interpolate rather than extrapolate."""
    points = check_int("points", points, minimum=3)
    smallest = max(50, N_star // 4)
    grid = np.unique(np.geomspace(smallest, max(2 * N_star, 4 * smallest), points).astype(int))
    if len(grid) < 3:
        raise ParameterError(f"the grid from {smallest} to 2 N* = {2 * N_star} has fewer than three sizes")
    return grid


def output_design(
    plant: Plant | tuple[Any, Any],
    threat: ThreatModel,
    *,
    estimator: str = "n4sid",
    runs: int = 20,
    points: int = 6,
    sample_sizes: Any = None,
    seed: int = 0,
    bootstrap: int = 1000,
    memory_limit: int | None = None,
) -> OutputDesign:
    """The empirical design of a plant measured through outputs (module docstring).

    Parameters
    ----------
    plant : Plant or (A, B)
        With ``C`` and ``sigma_v2`` (a plant without ``C`` is measured through ``C = I``).
    threat : ThreatModel
        Variances, ``gamma_c``, ``tau_c``, ``upsilon`` and the cost model.
    estimator : {"n4sid", "moesp", "arx"}
        :data:`~encctl_gym.sim.output.OUTPUT_ESTIMATORS`.
    runs : int
        Simulated attacks per ``N`` (>= 2).
    points : int
        Sizes of the default grid (:func:`output_design_grid`, up to twice the paper's ``N*``).
    sample_sizes : array_like of int, optional
        The grid instead.
    seed : int
        Seed of the attacks (the same trajectories for the state and the output fits).
    bootstrap : int
        Bootstrap resamples of the fits.
    memory_limit : int, optional
        Bytes the simulated attacks may hold (:func:`~encctl_gym.sim.output.output_attack_errors`:
        the estimators stream over chunks of runs; the trajectories are held whole).

    Raises
    ------
    ParameterError
        An unknown estimator, fewer than two runs, a grid the estimator's order does not fit in
        (too few samples for its windows), or the state fit's exponent not positive.
    ResourceLimitError
        When the attacks at the grid's largest ``N`` need more than ``memory_limit``, before any
        simulation.
    """
    from ..resources import check_memory
    from ..sim.output import check_output_estimator, check_sample_grid, output_attack_bytes, output_attack_errors
    from ..sim.plant import LinearPlant

    check_output_estimator(estimator)
    p = as_plant(plant)
    runs = check_int("runs", runs, minimum=2)
    t = threat.require("sigma_u2", "sigma_w2", "gamma_c")
    paper = design_security_parameter(p, t)
    grid = output_design_grid(paper.N_star, points) if sample_sizes is None else check_sample_grid(sample_sizes)
    sim_plant = LinearPlant(p.A, p.B, sigma_w2=t.sigma_w2, sigma_x2=t.sigma_x2)
    common = {"sample_sizes": grid, "runs": runs, "sigma_u2": t.sigma_u2, "seed": seed, "memory_limit": memory_limit}
    # both simulations' memory, then the outputs: a limit too small, or a grid too short for the
    # estimator's windows, fails before any other work
    need, _ = output_attack_bytes(runs, int(grid[-1]), p.n, p.m, p.n, "arx", p.n)
    check_memory(f"the state-measured reference ({runs} attacks of N = {int(grid[-1])} samples)", need, memory_limit,
                 "use fewer runs, a larger gamma_c (shorter attacks) or a larger memory limit")  # fmt: skip
    out = output_attack_errors(sim_plant, p.output_matrix(), sigma_v2=p.sigma_v2, estimator=estimator, **common)
    ref = output_attack_errors(sim_plant, np.eye(p.n), sigma_v2=0.0, estimator="arx", **common)
    state_fit = fit_empirical_complexity(grid, ref["state_ls"], bootstrap=bootstrap, seed=seed)
    state_design = empirical_design(state_fit, t)
    markov_fit = fit_empirical_complexity(grid, ref["state_ls_markov"], bootstrap=bootstrap, seed=seed)
    target = float(markov_fit(paper.N_star))
    output_fit = fit_empirical_complexity(grid, out["markov"], bootstrap=bootstrap, seed=seed)
    try:
        design: EmpiricalDesign | None = empirical_design(output_fit, t, reference=(markov_fit, paper.N_star))
        note = ""
    except ParameterError as exc:  # a rate that does not decrease: reported, not designed
        design, note = None, str(exc)
    return OutputDesign(estimator, paper, state_fit, state_design, target, output_fit, design, note, p.p, p.sigma_v2)


def _interval(v: int, iv: tuple[int, int]) -> str:
    return f"{v} [{iv[0]}, {iv[1]}]"


def format_output_design(d: OutputDesign) -> str:
    """The text the ``design`` command prints for :func:`output_design`."""
    level = f"{100 * d.state_fit.level:g} %"
    sd, od = d.state_design, d.output_design
    grid = d.state_fit.N
    lines = [
        f"Empirical design from outputs (y = C x + v, p = {d.p}, sigma_v2 = {d.sigma_v2:g}; {d.output_fit.runs} Gaussian "
        f"attacks per N on N = {int(grid[0])} .. {int(grid[-1])}, {len(grid)} sizes; intervals: {level} bootstrap)",
        f"  {'measured / estimator / error':46s} {'fit E[error] = c / N^a':34s} {'N*':>24s} {'lambda*':>14s} {'k*':>18s}",
        f"  {'state, eq:sic2 (the paper), def:error':46s} {'':34s} {d.paper.N_star:>24d} {d.paper.lam_star:>14d} "
        f"{d.paper.k_star:>18d}",
    ]

    def row(label: str, f: EmpiricalComplexity, des: EmpiricalDesign | None, note: str = "") -> str:
        rate = f"a = {f.a:.3f} [{f.a_interval[0]:.3f}, {f.a_interval[1]:.3f}], c = {f.c:.3g}"
        if des is None:
            return f"  {label:46s} {rate:34s}  no design: {note}"
        ext = " (extrapolated)" if des.extrapolated else ""
        return (
            f"  {label:46s} {rate:34s} {_interval(des.N_star, des.N_star_interval):>24s} "
            f"{_interval(des.lambda_star, des.lambda_star_interval):>14s} {_interval(des.k_star, des.k_star_interval):>18s}{ext}"
        )

    lines.append(row("state, least squares, def:error", d.state_fit, sd))
    lines.append(row(f"output, {d.estimator}, Markov error", d.output_fit, od, d.note))
    spread = ""
    if od is not None and od.target_interval is not None:
        spread = f" [{od.target_interval[0]:.4g}, {od.target_interval[1]:.4g}], carried into the output row's intervals"
    lines.append(
        f"  target in the Markov error: {d.target:.4g}{spread} (state least squares at the paper's N* = {d.paper.N_star})"
    )
    if od is not None:
        lines.append(
            f"  measuring outputs costs the attacker {od.N_star / d.paper.N_star:.2f}x the paper's N* and saves the defender "
            f"{d.paper.k_star - od.k_star} key bits (k* {od.k_star} against {d.paper.k_star})"
        )
    return "\n".join(lines)
