"""Breaking Paillier keys: factor the modulus, rebuild ``(lambda, mu)``, check by decrypting.

A factorer (:mod:`.factoring`) returns ``n = p q`` (checked); :func:`break_paillier_key` turns
it into the secret key of Paillier's Scheme 1 (:func:`~encctl_gym.crypto.paillier.secret_key_from_factors`:
``lambda = lcm(p-1, q-1)``, ``mu = lambda^-1 mod n``) and checks it the way that matters to an
eavesdropper: a fresh random plaintext encrypted under the public key decrypts to itself with
the recovered key (:class:`~encctl_gym.errors.BreakerError` otherwise). Under rotation every key
is a fresh modulus (:func:`paillier_key_sequence`), so :func:`break_paillier_sequence` pays the
whole factorisation for each key: nothing is shared between keys.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from .._validation import check_int, format_value
from ..crypto import arith
from ..crypto.arith import RngLike
from ..crypto.paillier import PaillierPublicKey, PaillierSecretKey, decrypt, encrypt, keygen, secret_key_from_factors
from ..errors import BreakerError, ParameterError
from .factoring import Factorer, Factorization

__all__ = [
    "RecoveredPaillierKey",
    "PaillierBreakReport",
    "break_paillier_key",
    "paillier_key_sequence",
    "break_paillier_sequence",
]


@dataclasses.dataclass(frozen=True)
class RecoveredPaillierKey:
    """A recovered Paillier secret key (checked by decrypting) and its factorisation with its cost."""

    public: PaillierPublicKey
    secret: PaillierSecretKey = dataclasses.field(repr=False)
    factorization: Factorization = dataclasses.field(repr=False)

    @property
    def seconds(self) -> float:
        """Wall time of the factorisation."""
        return self.factorization.cost.seconds


def break_paillier_key(
    factorer: Factorer, pk: Any, *, time_limit: float | None = None, rng: RngLike = None
) -> RecoveredPaillierKey:
    """Factor ``pk.n`` with ``factorer`` and return the checked secret key.

    Raises
    ------
    ParameterError
        If ``pk`` is not a :class:`PaillierPublicKey` or ``factorer`` not a :class:`Factorer`.
    BreakerLimitError, BreakerTimeoutError, BreakerError
        From the factorer; BreakerError also if the rebuilt key fails the decryption check.
    """
    if not isinstance(pk, PaillierPublicKey):
        raise ParameterError(f"pk must be a PaillierPublicKey, got {format_value(pk)}")
    if not isinstance(factorer, Factorer):
        raise ParameterError(f"factorer must be a Factorer, got {format_value(factorer)}")
    src = arith.as_random_source(rng, "paillier-break") if rng is not None else arith.secure_random()
    fac = factorer.factor(pk.n, time_limit=time_limit, rng=src.spawn("factor"))
    try:
        sk = secret_key_from_factors(pk, fac.p, fac.q)
    except ParameterError as exc:
        raise BreakerError(f"{factorer.name}: the factors of n do not make a Paillier key ({exc})") from None
    m = src.below(pk.n)
    if decrypt(sk, encrypt(pk, m, src)) != m:  # pragma: no cover - guarded by the factor check
        raise BreakerError(f"{factorer.name}: the recovered key fails the decryption check")
    return RecoveredPaillierKey(pk, sk, fac)


def paillier_key_sequence(bits: int, keys: int, rng: RngLike) -> list[tuple[PaillierPublicKey, PaillierSecretKey]]:
    """``keys`` independent Paillier keys of ``bits`` bits: one rotation schedule's moduli."""
    keys = check_int("keys", keys, 1)
    src = arith.as_random_source(rng, "paillier-key-sequence")
    return [keygen(bits, src) for _ in range(keys)]


@dataclasses.dataclass(frozen=True)
class PaillierBreakReport:
    """The keys of a sequence, each recovered with its own factorisation."""

    factorer: str
    bits: int
    keys: tuple[RecoveredPaillierKey, ...]

    def key_seconds(self) -> np.ndarray:
        """Wall seconds of each key's factorisation."""
        return np.array([k.seconds for k in self.keys])

    def tau(self) -> np.ndarray:
        """Cumulative seconds after each key (the measured sample deciphering time, def:sdt)."""
        return np.cumsum(self.key_seconds())

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (no secrets)."""
        return {
            "factorer": self.factorer,
            "bits": self.bits,
            "keys": [{"n": hex(k.public.n), **k.factorization.cost.to_dict()} for k in self.keys],
            "tau": self.tau().tolist(),
        }


def break_paillier_sequence(
    factorer: Factorer, pks: list[PaillierPublicKey], *, time_limit: float | None = None, rng: RngLike = None
) -> PaillierBreakReport:
    """Break every key of ``pks`` (one factorisation each), in order."""
    src = arith.as_random_source(rng, "paillier-break-sequence")
    done = tuple(break_paillier_key(factorer, pk, time_limit=time_limit, rng=src.spawn(f"key-{i}")) for i, pk in enumerate(pks))
    return PaillierBreakReport(factorer.name, pks[0].bits if pks else 0, done)
