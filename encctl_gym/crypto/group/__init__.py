"""Public parameters (p, q, g) of ElGamal encryption (Example ex:elgamal), one job per module.

* :mod:`.params` - :class:`GroupParams`, the value object: structural checks on construction,
  :meth:`~GroupParams.verify` (primality of p and q, order of g) once per process, JSON files.
* :mod:`.sieve` - the sieve of the safe-prime search (:func:`sieve_window`).
* :mod:`.shipped` - the pre-generated groups of :data:`SHIPPED_BITS` (:func:`shipped_group`).
* :mod:`.generation` - safe-prime generation bounded by its time model
  (:func:`estimate_generation_seconds`, :func:`generate_safe_prime_group`), and
  :func:`get_group` / :func:`as_group` (shipped if there is one, else generated).

Every public name is importable from here (``from encctl_gym.crypto.group import get_group``).
``python -m encctl_gym.crypto.group`` regenerates the shipped-group file.
"""

from __future__ import annotations

from . import generation, params, shipped, sieve
from .generation import *  # noqa: F403
from .params import *  # noqa: F403
from .shipped import *  # noqa: F403
from .sieve import *  # noqa: F403

#: The public names of the modules above (each module's ``__all__``).
__all__ = [*params.__all__, *sieve.__all__, *shipped.__all__, *generation.__all__]
