"""What the adversary of Definition def:adversary does with the cryptography.

* :mod:`.forgery` -- step 1: forge the input ciphertexts that make the plant apply an input of
  the adversary's choosing, from public keys only.
* :mod:`.decipherer` -- step 2 in the loop: the exponent that decrypts the state ciphertexts the
  adversary paid for, read from the plant (the simulated break) or recovered by a real breaker.

This layer sits above :mod:`encctl_gym.crypto` (and beside :mod:`encctl_gym.cryptanalysis`, the
key breakers of step 2); the closed loop (:mod:`encctl_gym.loop`) and the attackers use it.
"""

from __future__ import annotations

from . import decipherer, forgery
from .decipherer import *  # noqa: F401,F403
from .forgery import *  # noqa: F401,F403

__all__ = [*forgery.__all__, *decipherer.__all__]
