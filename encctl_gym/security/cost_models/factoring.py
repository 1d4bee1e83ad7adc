"""Deciphering-cost models of the factoring family (Paillier keys): what breaking the keys costs
when every key is its own modulus ``n`` of k bits.

A fresh Paillier key is a fresh modulus, so nothing an attacker computes for one modulus
factors the next, except through the two published amortisations below. Every model maps the
modulus length k to a :class:`~.base.KeyBreakCost` (operations for the first key and for each
further key), like the discrete-log models of this package, so the same
:meth:`~.base.CostModel.minimum_key_length` designs the modulus. All use
``L_n[1/3, c] = exp(c (ln n)^(1/3) (ln ln n)^(2/3))`` with ``n = 2^k`` (:func:`l_third_bits`) and
the optional o(1) correction ``gnfs_correction`` in bits, subtracted from every exponent alike
(an assumption: the sources give the o(1) of none of them).

======================  ===========================================================  =============================
model                   first key / each further key                                 source
======================  ===========================================================  =============================
``paper``               ``2^lam`` / ``2^lam``, ``lam = log2 Omega(k) - c``             the paper's eq:opt_key (its
                        (:class:`~.models.PaperModel`, the baseline)                  Omega *is* the factoring GNFS)
``gnfs``                ``L[1/3, (64/9)^(1/3)]`` / the same: one GNFS per modulus     Buhler, Lenstra, Pomerance 1993
``factory``             ``L[1/3, 2.008] + L[1/3, 1.639]`` / ``L[1/3, 1.639]``:        Coppersmith, J. Cryptology 6
                        one precomputation for every modulus of about k bits           (1993), factorization factory
``batch-nfs``           ``L[1/3, 2.204]`` / ``L[1/3, 1.704]``: a circuit that          Bernstein, Lange, SAC 2014,
                        factors a batch of ``L^0.5`` keys in time ``L^1.022`` on       "Batch NFS" (area-time metric)
                        area ``L^1.181``; its area-time per key is ``L^1.704``
======================  ===========================================================  =============================

Notes
-----
* ``batch-nfs`` counts the area-time product (price-performance), the metric of its source; in
  that metric one key by the best single-key circuit costs ``L^1.976``
  (:data:`SINGLE_KEY_AT_CONSTANT`), not the ``L^1.923`` operations of ``gnfs``. The first key
  carries a whole batch (``L^(1.704 + 0.5)``), so ``first + (N - 1) next`` is within a factor
  two of the batch's cost ``ceil(N / L^0.5) L^2.204`` for every N.
* The records of ``security/data/deciphering_records.json`` marked ``"factoring"`` (RSA-240,
  RSA-250) are single-key NFS runs: :func:`factoring_record_gaps` compares every model's per-key
  cost with them (the GNFS formula without correction is about 12 bits above both, the
  ``guillevic`` correction brings it within about 0.5 bit). No factory or batch computation
  at a cryptographic size has been published, so those two models have no record to meet;
  their constants are their sources' asymptotic exponents.
"""

from __future__ import annotations

import math
from typing import Any

from ...errors import ModelRangeError
from ...registry import Registry
from ..exact import pow2
from ..records import RecordSet, default_records
from .base import CostModel, KeyBreakCost
from .formulas import GNFS_CONSTANT, GNFS_MIN_KEY_LENGTH, MAX_KEY_LENGTH, _key_lengths, check_gnfs_correction
from .models import PaperModel

__all__ = [
    "FACTORY_PRECOMPUTATION_CONSTANT",
    "FACTORY_PER_KEY_CONSTANT",
    "BATCH_NFS_PER_KEY_CONSTANT",
    "BATCH_NFS_BATCH_EXPONENT",
    "SINGLE_KEY_AT_CONSTANT",
    "l_third_bits",
    "GnfsFactoringModel",
    "FactorizationFactoryModel",
    "BatchNfsModel",
    "FACTORING_MODELS",
    "factoring_model",
    "factoring_record_gaps",
    "design_modulus_lengths",
]

#: Coppersmith's factorization factory: the precomputation's constant of ``L[1/3, c]``.
FACTORY_PRECOMPUTATION_CONSTANT = 2.008
#: Coppersmith's factorization factory: the per-modulus constant after the precomputation.
FACTORY_PER_KEY_CONSTANT = 1.639
#: Bernstein-Lange batch NFS: area-time product per key, ``L^1.704``.
BATCH_NFS_PER_KEY_CONSTANT = 1.704
#: Bernstein-Lange batch NFS: a batch holds ``L^0.5`` keys.
BATCH_NFS_BATCH_EXPONENT = 0.5
#: Bernstein-Lange: the best area-time product known for a single key, ``L^1.976``.
SINGLE_KEY_AT_CONSTANT = 1.976

_LN2 = math.log(2.0)


def l_third_bits(k: Any, c: float) -> float:
    """``log2 L_n[1/3, c]`` for ``n = 2^k``: ``c (ln n)^(1/3) (ln ln n)^(2/3) / ln 2``.

    Raises
    ------
    ModelRangeError
        For a key length outside ``[40, 65536]`` bits.
    """
    kf, _ = _key_lengths(k, GNFS_MIN_KEY_LENGTH, MAX_KEY_LENGTH, "the L[1/3] formulas")
    ln_n = float(kf) * _LN2
    # x ** (1/3), not math.cbrt: the package supports Python 3.10, whose math has no cbrt
    return c * ln_n ** (1.0 / 3.0) * (math.log(ln_n) ** 2) ** (1.0 / 3.0) / _LN2


class _LThirdModel(CostModel):
    """A model of two ``L[1/3]`` terms: a precomputation (possibly none) and a per-key cost."""

    key_length_range = (GNFS_MIN_KEY_LENGTH, MAX_KEY_LENGTH)
    #: (precomputation constant or None, per-key constant, formula text, source)
    PRE: float | None = None
    PER_KEY: float = GNFS_CONSTANT
    FORMULA = ""
    SOURCE = ""

    def __init__(self, gnfs_correction: Any = 0.0) -> None:
        self.gnfs_correction = check_gnfs_correction(gnfs_correction)

    def break_cost(self, key_length: int) -> KeyBreakCost:
        c = self.gnfs_correction
        key = pow2(max(0.0, l_third_bits(key_length, self.PER_KEY) - c))
        pre = None if self.PRE is None else pow2(max(0.0, l_third_bits(key_length, self.PRE) - c))
        first = key if pre is None else pre + key
        return KeyBreakCost(self.name, first, key, key_length=int(key_length), precomputation=pre, gnfs_correction=c)

    def describe(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "family": "factoring",
            "formula": self.FORMULA,
            "constants": {"precomputation": self.PRE, "per_key": self.PER_KEY},
            "source": self.SOURCE,
            "gnfs_correction": self.gnfs_correction,
            "key_length_range": list(self.key_length_range),
        }


class GnfsFactoringModel(_LThirdModel):
    """One general number field sieve per modulus: ``L[1/3, (64/9)^(1/3)]`` for every key."""

    name = "gnfs"
    FORMULA = "each key L_n[1/3, (64/9)^(1/3)] 2^-c (a fresh modulus per key: nothing shared)"
    SOURCE = "J. P. Buhler, H. W. Lenstra Jr., C. Pomerance, Factoring integers with the number field sieve, LNM 1554 (1993)"


class FactorizationFactoryModel(_LThirdModel):
    """Coppersmith's factorization factory: one precomputation ``L[1/3, 2.008]`` for all moduli of
    about k bits, then ``L[1/3, 1.639]`` per modulus."""

    name = "factory"
    PRE = FACTORY_PRECOMPUTATION_CONSTANT
    PER_KEY = FACTORY_PER_KEY_CONSTANT
    FORMULA = "first key L[1/3, 2.008] + L[1/3, 1.639], each further key L[1/3, 1.639] (all 2^-c)"
    SOURCE = "D. Coppersmith, Modifications to the number field sieve, Journal of Cryptology 6 (1993) 169-180"


class BatchNfsModel(_LThirdModel):
    """Bernstein-Lange batch NFS in the area-time metric: a batch of ``L^0.5`` keys for
    ``L^2.204``, i.e. ``L^1.704`` per key (module docstring)."""

    name = "batch-nfs"
    PRE = BATCH_NFS_PER_KEY_CONSTANT + BATCH_NFS_BATCH_EXPONENT  # one batch (break_cost: first = the batch)
    PER_KEY = BATCH_NFS_PER_KEY_CONSTANT
    FORMULA = "first key L[1/3, 2.204] (one batch of L^0.5 keys), each further key L[1/3, 1.704] (area-time, 2^-c)"
    SOURCE = "D. J. Bernstein, T. Lange, Batch NFS, SAC 2014, LNCS 8781, pp. 38-58"

    def break_cost(self, key_length: int) -> KeyBreakCost:
        c = self.gnfs_correction
        batch = pow2(max(0.0, l_third_bits(key_length, BATCH_NFS_PER_KEY_CONSTANT + BATCH_NFS_BATCH_EXPONENT) - c))
        key = pow2(max(0.0, l_third_bits(key_length, self.PER_KEY) - c))
        return KeyBreakCost(self.name, batch, key, key_length=int(key_length), precomputation=batch - key, gnfs_correction=c)


#: The factoring family's cost models by name; ``paper`` (:class:`~.models.PaperModel`) is the
#: baseline (eq:opt_key's Omega is the factoring GNFS).
FACTORING_MODELS: Registry[type[CostModel]] = Registry(
    "factoring deciphering model", [PaperModel, GnfsFactoringModel, FactorizationFactoryModel, BatchNfsModel]
)


def factoring_model(name: Any = "paper", **options: Any) -> CostModel:
    """Build a factoring-family model by name (:data:`FACTORING_MODELS`)."""
    if isinstance(name, CostModel):
        return name
    model: CostModel = FACTORING_MODELS.build(name, **options)
    return model


def factoring_record_gaps(model: CostModel, records: RecordSet | None = None) -> list[dict[str, Any]]:
    """For each factoring record with core time and a clock rate: the model's per-key bits at
    the record's modulus length minus the record's ``log2`` clock cycles (positive: the model
    charges more than the record spent).

    Raises
    ------
    ModelRangeError
        If no record of the set is a usable factoring record.
    """
    recs = default_records() if records is None else records
    rows = []
    for r in recs.records:
        ops = r.log2_operations
        if r.problem != "factoring" or ops is None:
            continue
        model_bits = model.break_cost(r.key_length).next_bits
        rows.append(
            {
                "record": r.name,
                "key_length": r.key_length,
                "record_bits": ops,
                "model_bits": model_bits,
                "gap_bits": model_bits - ops,
            }
        )
    if not rows:
        raise ModelRangeError("no factoring record with core time and a clock rate in the records set")
    return rows


def design_modulus_lengths(keys: int, budget: Any, names: Any = None, **options: Any) -> dict[str, int]:
    """eq:opt_key per model: the smallest modulus length k with ``operations(keys) > budget``
    (the paper model: its integer ``lam*``, Theorem thm:opt_sec), for each model of ``names``
    (default: every model of :data:`FACTORING_MODELS`), built with ``options``."""
    out = {}
    for name in FACTORING_MODELS if names is None else names:
        out[name] = factoring_model(name, **options).minimum_key_length(keys, budget)
    return out
