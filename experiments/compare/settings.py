"""The settings of the comparison: a system in one observation setting, with its bounds.

A :class:`Setting` is what every attacker of one comparison faces: the environment
configuration (a preset, or a plant given by its matrices), the decipher delay (``0``: states
delivered in time, an adaptive attacker; ``"end"``: the paper's blind attacker), the evaluated
attack length (the ``tau_c`` budget at the preset's lambda, or an evaluation cap reached by a
shorter defense period at the same lambda, so the budget fractions an attacker observes keep
their meaning: :func:`agents.evaluate.budget_config`), and the references at that length: the
paper's ``gamma(N)`` (eq:sic), the A-optimal design's ``gamma_opt(N)`` and the Gaussian attack's
exact rate (:mod:`encctl_gym.security.attack_design`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from encctl_gym._validation import format_value
from encctl_gym.agents.evaluate import budget_config
from encctl_gym.envs.config import AttackParams, resolve_params
from encctl_gym.errors import ConfigError
from encctl_gym.security.attack_design import AttackDesign, gaussian_attack_design, optimal_attack_design
from encctl_gym.sim.montecarlo import log_grid

__all__ = ["DEFAULT_SYSTEMS", "DELAYS", "DEFAULT_CAP", "Setting", "make_setting", "system_entry", "length_grid", "parse_delays"]

#: The design example and two Figure 1 panels at the extremes of R_sigma (100 and 0.01).
DEFAULT_SYSTEMS = ("paper-example", "fig1-c", "fig1-g")
#: The two observation settings: states delivered in time, and blind until the end.
DELAYS: tuple[Any, ...] = (0, "end")
#: Evaluation cap: no system is attacked longer than the design example's budget (7379 at lam* = 74).
DEFAULT_CAP = 7379


@dataclass(frozen=True)
class Setting:
    """One system in one observation setting, with its bounds.

    Attributes
    ----------
    system : str
        Label (a preset name, or the name of a plant file).
    delay : int or "end"
        ``decipher_delay`` of the environment.
    config : dict
        Environment configuration of the evaluated attack (capped horizon).
    params : AttackParams
        Its resolved parameters.
    base : AttackParams
        Of the system's own configuration: its tau_c, Upsilon and gamma_c define the security design.
    design : AttackDesign
        The optimal design (closed loop for an integer delay, open loop for ``"end"``).
    gauss : AttackDesign
        The Gaussian attack's exact asymptotic rate.
    capped : bool
        The horizon was set by the evaluation (a cap or an exact length), not by the system's tau_c.
    """

    system: str
    delay: Any
    config: dict[str, Any]
    params: AttackParams
    base: AttackParams
    design: AttackDesign
    gauss: AttackDesign
    capped: bool

    @property
    def label(self) -> str:
        return f"{self.system} / delay {self.delay}"

    @property
    def key(self) -> tuple[str, Any]:
        """``(system, delay)``: the key of this setting's curves in a result."""
        return (self.system, self.delay)


def make_setting(
    system: str, delay: Any, cap: int | None, *, config: dict[str, Any] | None = None, length: int | None = None
) -> Setting:
    """The configuration and bounds of one system in one observation setting.

    Parameters
    ----------
    system : str
        A preset name, or the label of ``config``.
    delay : int or "end"
        ``decipher_delay``.
    cap : int, optional
        Evaluation cap on the attack length (``None``: the tau_c budget).
    config : dict, optional
        The system's environment configuration (default ``{"preset": system}``); keys that set
        the attack length (``tau_c``, ``max_samples``) are the system's own budget.
    length : int, optional
        An exact attack length instead (shorter or longer than the budget; ``cap`` is then not
        used), set through the defense period at the same lambda.
    """
    cfg: dict[str, Any] = dict(config) if config is not None else {"preset": system}
    cfg.update(decipher_delay=delay, gamma_opt=False)
    base = resolve_params(cfg)
    target = length if length is not None else (cap if cap is not None and base.horizon > cap else None)
    capped = target is not None and target != base.horizon
    if target is not None and capped:  # another defense period, same lambda: the budget fractions keep their meaning
        cfg = budget_config(cfg, int(target))
    p = resolve_params(cfg)
    design = optimal_attack_design(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2, feedback=p.decipher_delay is not None)
    gauss = gaussian_attack_design(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2)
    return Setting(system, delay, cfg, p, base, design, gauss, capped)


def system_entry(entry: str) -> tuple[str, dict[str, Any] | None]:
    """A system named on the command line (``--systems``): a preset name, or a plant file.

    A name of :data:`encctl_gym.presets.PRESETS` is that preset (configuration ``None``: the
    preset's own); anything else that is an existing path or ends like a plant file
    (:data:`encctl_gym.plant_file.SUFFIXES`) is read as a plant file by the reader of ``train
    --system`` (:func:`agents.config.plant_config`; the values the file does not give are the
    design example's), labelled by the file's stem as ``train`` labels its runs.

    Returns
    -------
    (label, config)
        The system's label and its environment configuration (``None`` for a preset).

    Raises
    ------
    ConfigError
        A plant file that cannot be read (naming the file), or a name that is neither a preset
        nor a plant file.
    """
    from pathlib import Path

    from encctl_gym.agents.config import plant_config
    from encctl_gym.envs.config import completion_preset
    from encctl_gym.plant_file import SUFFIXES
    from encctl_gym.presets import PRESETS, preset_names

    if entry in PRESETS:
        return entry, None
    path = Path(entry)
    if path.exists() or path.suffix.lower() in SUFFIXES:
        return path.stem, plant_config(path, completion_preset({}))  # the environment's rule for the missing values
    raise ConfigError(
        f"unknown preset {entry!r}, and no plant file of that name; choose a preset ({', '.join(preset_names())}) "
        f"or a plant file ({', '.join(SUFFIXES)})"
    )


def length_grid(params: AttackParams, points: int) -> np.ndarray:
    """Attack lengths of the curves: a log grid of ``points`` sizes from ``2 (n + m) + 1`` to the horizon.

    Raises
    ------
    ConfigError
        If ``points`` exceeds the horizon N: a grid of distinct lengths up to N has at most N
        points (and a larger request would allocate its float grid before merging it).
    """
    if isinstance(points, (int, np.integer)) and not isinstance(points, bool) and points > params.horizon:
        raise ConfigError(
            f"points = {format_value(points)} attack lengths exceed the horizon N = {params.horizon}: "
            f"a grid of distinct lengths up to N has at most N points"
        )
    return log_grid(min(2 * (params.n + params.m) + 1, params.horizon), params.horizon, points)


def parse_delays(text: str) -> tuple[Any, ...]:
    """Comma-separated decipher delays (non-negative integers or ``end``) for the command line.

    Raises
    ------
    ConfigError
        For an entry that is neither (``--delays abc``), or an empty list.
    """
    out: list[Any] = []
    for item in text.split(","):
        v = item.strip()
        if v == "end":
            out.append("end")
        elif v.isdigit():
            out.append(int(v))
        else:
            raise ConfigError(f"decipher delay {v!r} in {text!r} is neither a non-negative integer nor 'end'")
    if not out:
        raise ConfigError("no decipher delay given")
    return tuple(dict.fromkeys(out))
