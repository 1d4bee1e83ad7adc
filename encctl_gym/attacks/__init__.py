"""What the adversary of Definition def:adversary does with the cryptography.

* :mod:`.forgery` -- step 1: forge the input ciphertexts that make the plant apply an input of
  the adversary's choosing, from public keys only.

This layer sits above :mod:`encctl_gym.crypto` (and beside :mod:`encctl_gym.cryptanalysis`, the
key breakers of step 2); the closed loop (:mod:`encctl_gym.loop`) and the attackers use it.
"""

from __future__ import annotations

from .forgery import forge, forge_injection, forge_injection_token, injection_integers, injection_value

__all__ = ["forge", "forge_injection", "forge_injection_token", "injection_integers", "injection_value"]
