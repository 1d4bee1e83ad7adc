"""Key breakers: real discrete-logarithm attacks on the keys of dynamic-key ElGamal.

A layer beside :mod:`encctl_gym.crypto` (it imports only ``crypto.arith``, ``crypto.group``,
``errors`` and ``_validation``) that measures what Definition def:sdt's sample deciphering time
``tau(N, lambda) = N 2^lambda / Upsilon`` charges for: breaking N keys of one group.

* :mod:`.base` - the interface: :class:`Breaker` (``precompute(group)`` once per group),
  :class:`Precomputation` (``break_key(h)`` per key, checked g^s = h), :class:`Cost`,
  :class:`RecoveredKey`.
* :mod:`.registry` - :data:`BREAKERS`, name -> class: ``bsgs``, ``rho``, ``rho-multi``,
  ``pari`` (optional extra ``cryptanalysis``), ``index-calculus``, ``token-chain``;
  :func:`get_breaker`.
* :mod:`.sequence` - :func:`break_sequence` and its :class:`BreakReport` (the measured tau(N)).
* :mod:`.smoothness`, :mod:`.relations`, :mod:`.linalg` - factor base, smoothness tests,
  rational reconstruction, Dickman's rho; the index calculus's relations (lattice sieve); linear
  algebra modulo q on python-flint.
* :mod:`.precomputation_file` - the index calculus's precomputation saved to a file and loaded
  checked against its group (:func:`load_precomputation`, :class:`PrecomputationInterrupted`).
* :mod:`.progress` - progress of the phases (:class:`PhaseBars`, silent by default).
* :mod:`.cli` - the ``encctl-gym crack`` command.
"""

from __future__ import annotations

from .base import Breaker, Cost, Deadline, Precomputation, RecoveredKey, check_element, verify_exponent
from .bsgs import BabyStepGiantStep
from .index_calculus import IndexCalculus
from .pari import PariZnlog, pari_available
from .precomputation_file import PrecomputationInterrupted, SavedPrecomputation, load_precomputation
from .progress import PhaseBars
from .registry import BREAKERS, get_breaker
from .rho import MultiLogRho, PollardRho
from .sequence import BreakReport, break_sequence
from .smoothness import FactorBase, dickman_rho, rational_reconstruction
from .token_chain import TokenChain

__all__ = [
    "Breaker",
    "Precomputation",
    "Cost",
    "RecoveredKey",
    "Deadline",
    "check_element",
    "verify_exponent",
    "BREAKERS",
    "get_breaker",
    "BreakReport",
    "break_sequence",
    "BabyStepGiantStep",
    "PollardRho",
    "MultiLogRho",
    "PariZnlog",
    "pari_available",
    "IndexCalculus",
    "TokenChain",
    "load_precomputation",
    "SavedPrecomputation",
    "PrecomputationInterrupted",
    "PhaseBars",
    "FactorBase",
    "dickman_rho",
    "rational_reconstruction",
]
