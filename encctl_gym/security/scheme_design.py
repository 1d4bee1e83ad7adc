"""The key size of any encryption scheme for the design's N* (eq:opt_key, through the scheme seam).

The paper designs the discrete-log key length k* for the sample identifying complexity N*
(Theorem thm:opt_sec, eq:opt_key): the smallest k such that breaking the keys of N* samples costs
more than the adversary's budget ``Upsilon tau_c``. Nothing in that rule is particular to
ElGamal: a scheme of the loop's scheme seam (:class:`~encctl_gym.loop.scheme.EncryptionScheme`)
brings its own deciphering-cost models (its ``cost_models``, :class:`~encctl_gym.security.cost_models.CostModel`
classes by name), the name of its baseline model and whether each sample is under its own key
(``independent_keys``). :func:`scheme_key_lengths` applies eq:opt_key under every model of the
scheme; ``encctl-gym design --scheme NAME`` prints it beside the paper's k*.

The security package imports no scheme: the caller resolves the scheme object (the design command
does it with :func:`encctl_gym.loop.scheme.make_scheme`).
"""

from __future__ import annotations

from typing import Any

from ..errors import ModelRangeError
from .key_length import build_model, design_key_length
from .threat import ThreatModel

__all__ = ["scheme_key_lengths", "format_scheme_key_lengths"]


def scheme_key_lengths(scheme: Any, N_star: int, threat: ThreatModel, *, gnfs_correction: float = 0.0) -> dict[str, Any]:
    """eq:opt_key under every cost model of ``scheme``: the smallest key size whose N* samples
    cost more than ``Upsilon tau_c`` (JSON-ready).

    Parameters
    ----------
    scheme : EncryptionScheme
        ``name``, ``family``, ``cost_models`` (a registry of cost-model classes),
        ``baseline_model`` and ``independent_keys(adversary)``.
    N_star : int
        The samples the adversary needs (the design's N*).
    threat : ThreatModel
        ``tau_c``, ``upsilon`` and the adversary.
    gnfs_correction : float
        Passed to the models that take it.

    Returns
    -------
    dict
        ``scheme``, ``family``, ``baseline``, ``N_star`` and ``designs``: per model name its
        :class:`~encctl_gym.security.key_length.KeyLengthDesign` as a dict, or ``{"error": ...}``
        when the answer lies outside the model's range.
    """
    designs: dict[str, Any] = {}
    for name in scheme.cost_models:
        model = build_model(name, gnfs_correction, registry=scheme.cost_models)
        try:
            designs[name] = design_key_length(N_star, threat.replace(cost_model=model), scheme=scheme).to_dict()
        except ModelRangeError as exc:
            designs[name] = {"error": str(exc)}
    return {
        "scheme": scheme.name,
        "family": scheme.family,
        "baseline": scheme.baseline_model,
        "adversary": threat.adversary,
        "N_star": int(N_star),
        "designs": designs,
    }


def format_scheme_key_lengths(res: dict[str, Any]) -> list[str]:
    """The lines of the ``design --scheme`` section."""
    lines = [
        "",
        f"  Scheme {res['scheme']} ({res['family']}): key size k* per cost model for N* = {res['N_star']} "
        f"({res['adversary']}; baseline {res['baseline']})",
        f"  {'model':<20}{'keys':>8}{'k*':>8}{'work(N*)':>10}{'first key':>11}{'next key':>10}",
    ]
    for name, d in res["designs"].items():
        if "error" in d:
            lines.append(f"  {name:<20}  {d['error']}")
            continue
        lines.append(
            f"  {name:<20}{d['keys']:>8d}{d['k_star']:>8d}{d['work_bits']:>10.3f}{d['first_key_bits']:>11.3f}{d['next_key_bits']:>10.3f}"
        )
    lines.append("  keys: keys the adversary must break for N* samples; work, first/next key: log2 operations.")
    return lines
