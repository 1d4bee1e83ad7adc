"""Deciphering-cost models: what breaking the keys of one group costs (def:sdt, eq:opt_key, beyond).

Definition def:sdt charges ``2^lambda`` operations for every key, and eq:opt_key turns
``lambda`` into a key length through the GNFS running time
``Omega(k) = exp((64/9)^(1/3) (ln 2^k)^(1/3) (ln ln 2^k)^(2/3))``. Real attacks on a prime field
differ in two ways, and each model of this module makes one set of assumptions explicit. A
model maps a key length ``k`` (bits of p) to a :class:`KeyBreakCost`: the operations for the
*first* key of a group and for *each further* key of the same group (dynamic-key ElGamal changes
the secret key every period but never p). :mod:`~encctl_gym.security.deciphering` turns that
into the sample deciphering time ``tau(N)``; :mod:`~encctl_gym.security.key_length` into the
smallest safe key length.

==================  ===============================================  =========================
model               first key / each further key (operations)        valid key lengths
==================  ===============================================  =========================
``paper``           ``2^lam`` / ``2^lam``, ``lam = log2 Omega(k) - c``  40 ... 65536 bits
                    (Definition def:sdt, eq:opt_key); an explicit
                    integer ``lam`` is exact, as in the paper
``precomputation``  ``C_pre + C_key`` / ``C_key``, ``C_pre = Omega(k)   40 ... 65536 bits
                    2^-c`` (the index-calculus precomputation depends
                    on p only), ``C_key = C_pre 2^-r(k)``
``generic``         ``sqrt(pi q / 2)`` / the same (Pollard rho in the   16 ... 65536 bits
                    order-q subgroup, q = (p-1)/2 >= 2^(k-2))
==================  ===============================================  =========================

``c`` is the optional o(1) correction of the GNFS formula in bits (``gnfs_correction``, default 0:
the paper's numbers). The formula drops the o(1) term of ``L_p[1/3, (64/9)^(1/3) + o(1)]``;
against the records it is 8 to 12 bits too high (``security/data/deciphering_records.json``:
DLP-768 8.2, DLP-240 10.2, RSA-250 11.8 bits, counting one clock cycle as one operation). The
documented alternative is ``c = 11.91`` (:data:`GUILLEVIC_CORRECTION`, after A. Guillevic, as
CryptographicEstimators uses it), which puts the formula within 8 bits of every row of NIST SP
800-57 (see :func:`~encctl_gym.security.records.nist_key_length`).

``r(k)`` is the ratio (in bits) between the precomputation and one further logarithm,
calibrated on the records with both phases in core time (by default the 768-bit record: 5300
core-years, then 2 core-days per logarithm, ``r = 19.88``), linear between calibration points
and constant beyond them. A further key costs at least one operation.

Valid ranges (outside them every function raises :class:`~encctl_gym.errors.ModelRangeError`):

* Key lengths of the GNFS models start at 40 bits: below about 38 bits Pollard rho in the order-q
  subgroup (``sqrt(pi 2^(k-2) / 2)`` operations) is cheaper than the formula's value, so the
  formula is no longer the fastest known attack that eq:opt_key asks for (:data:`GNFS_MIN_KEY_LENGTH`).
  The generic model holds from 16 bits (a subgroup of at least 2^14 elements). Key lengths end at
  65536 bits (:data:`MAX_KEY_LENGTH`), four times NIST's largest (15360): enough for every
  security level up to 481 bits under the GNFS formula, and a bound before any code generates a
  group.
* A security parameter lies in ``[1, 2048]`` bits (:data:`LAMBDA_MAX`): ``2^lam`` is then an exact
  integer of at most 2049 bits, and Theorem thm:opt_sec never asks for more, since ``Upsilon``
  and ``tau_c`` are finite float64 numbers (``Upsilon tau_c < 2^2048``).
* A GNFS correction is finite, ``>= 0`` and below ``log2 Omega(40) = 18.70`` bits, so that the
  corrected cost stays above one operation over the whole range.

One module per job, every public name re-exported here:

* :mod:`.formulas` - the constants and formulas (GNFS ``Omega(k)``, Pollard rho, the checks of a
  correction and of a security parameter, the paper's ``lam`` of a budget).
* :mod:`.base` - :class:`KeyBreakCost` and :class:`CostModel`, the one base of every model (a new
  model subclasses it: ``break_cost`` and ``describe``; the key-length search is shared).
* :mod:`.models` - the shipped models ``paper``, ``precomputation``, ``generic``, and eq:opt_key's
  :func:`minimum_key_length`.
* :mod:`.factoring` - the factoring family (Paillier moduli): ``gnfs``, ``factory``
  (Coppersmith), ``batch-nfs`` (Bernstein-Lange) beside the ``paper`` baseline, in their own
  registry :data:`FACTORING_MODELS`.
* :mod:`.registry` - :data:`DECIPHERING_MODELS` (name -> class) and :func:`deciphering_model`,
  which builds one by name (the ``--cost-model`` option of ``encctl-gym design``); a model's
  options are the parameters of its constructor.
"""

from __future__ import annotations

from . import base, factoring, formulas, models, registry
from .base import *  # noqa: F403
from .factoring import *  # noqa: F403
from .formulas import *  # noqa: F403
from .models import *  # noqa: F403
from .registry import *  # noqa: F403

#: The public names of the modules above (each module's ``__all__``).
__all__ = [*formulas.__all__, *base.__all__, *models.__all__, *registry.__all__, *factoring.__all__]
