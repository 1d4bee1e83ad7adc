"""The cost of the primal uSVP attack on LWE: block size from the GSA condition, core-SVP bits.

For LWE the security parameter is a dimension ``n``, a modulus ``q`` and the widths of the
secret and the error, and the attacker's work is lattice reduction. This module implements the
estimate of E. Alkim, L. Ducas, T. Poppelmann, P. Schwabe, "Post-quantum key exchange - a new
hope", USENIX Security 2016, Section 6 (ADPS16):

* **Lattice**: with ``m`` of the available samples ``b = A s + e``, the embedding lattice
  ``{(x, y, z) in Z^{m+n+1} : x = A y - z b mod q}`` (Bai-Galbraith form) of dimension
  ``d = m + n + 1`` and volume ``q^m`` contains ``(e, s, 1)``. When the secret is narrower or
  wider than the error, the secret coordinates are rescaled by ``nu = sigma_e / sigma_s`` so that
  every coordinate has width ``sigma_e``: the volume becomes ``q^m nu^n``.
* **Success condition** (ADPS16 Section 6.3, under the geometric series assumption): BKZ with
  block size ``beta`` recovers the vector when the projection of the short vector on the last
  ``beta`` Gram-Schmidt directions, about ``sigma_e sqrt(beta)``, is shorter than the
  ``(d - beta)``-th Gram-Schmidt norm ``delta^(2 beta - d - 1) Vol^(1/d)``::

      sigma_e sqrt(beta) <= delta(beta)^(2 beta - d - 1) Vol^(1/d)

  with the root Hermite factor ``delta(beta) = ((pi beta)^(1/beta) beta / (2 pi e))^(1/(2 (beta - 1)))``
  (Chen's thesis, 2013). The attacker picks ``m`` (at most the samples available) to minimise
  ``beta``.
* **Core-SVP cost**: one SVP call in dimension ``beta``, ``2^(c beta)`` operations with
  :data:`CORE_SVP_EXPONENTS`: classical sieving ``c = log2 sqrt(3/2) = 0.292`` (Becker, Ducas,
  Gama, Laarhoven, SODA 2016), quantum sieving ``log2 sqrt(13/9) = 0.265`` (Laarhoven's thesis,
  2015), and ADPS16's "best plausible" lower bound ``log2 sqrt(4/3) = 0.2075``. The core-SVP
  model ignores the number of SVP calls and the memory: it is a conservative lower bound.

Small block sizes (used to compare with measured BKZ on small dimensions): Chen's formula for
``delta`` is only meaningful for larger block sizes (it is above the measured values up to
about 80); below :data:`FORMULA_FROM` the module interpolates ``log delta`` linearly between the
experimental values of N. Gama and P. Q. Nguyen, "Predicting lattice reduction", Eurocrypt 2008
(LLL, i.e. ``beta = 2``: 1.0219; BKZ-20: 1.0128; BKZ-28: 1.0109) and the formula at
:data:`FORMULA_FROM`.

Pure mathematics: imports no cryptography (STYLE: the security analysis stands beside it).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ..._validation import check_int, check_positive, format_value
from ...errors import ModelRangeError, ParameterError
from ..exact import pow2
from .base import CostModel, KeyBreakCost

__all__ = [
    "CORE_SVP_EXPONENTS",
    "GAMA_NGUYEN_DELTA",
    "LWEParameterSet",
    "PrimalEstimate",
    "root_hermite_factor",
    "primal_usvp_succeeds",
    "primal_usvp_estimate",
    "binomial_sigma",
    "smallest_secure_dimension",
    "key_costs",
    "STANDARD_PARAMETER_SETS",
    "PrimalUSVPModel",
]

#: Exponent ``c`` of the core-SVP cost ``2^(c beta)`` per model (module docstring).
CORE_SVP_EXPONENTS: Mapping[str, float] = {
    "classical": math.log2(math.sqrt(3 / 2)),
    "quantum": math.log2(math.sqrt(13 / 9)),
    "plausible": math.log2(math.sqrt(4 / 3)),
}

#: Root Hermite factors measured by Gama and Nguyen (Eurocrypt 2008, Section 3): block size -> delta.
GAMA_NGUYEN_DELTA: Mapping[int, float] = {2: 1.0219, 20: 1.0128, 28: 1.0109}

#: Largest lattice dimension (and block size) modelled.
MAX_BLOCK_SIZE = 16384


def _chen(beta: int) -> float:
    return ((math.pi * beta) ** (1 / beta) * beta / (2 * math.pi * math.e)) ** (1 / (2 * (beta - 1)))


#: Block size from which Chen's formula is used: the first beta >= 50 where it falls below the
#: largest block size measured by Gama and Nguyen (below, the formula is above that measurement,
#: i.e. not even monotone in the data: 1.0121 at beta = 50 against 1.0109 measured at 28).
FORMULA_FROM = next(b for b in range(50, MAX_BLOCK_SIZE) if _chen(b) < GAMA_NGUYEN_DELTA[max(GAMA_NGUYEN_DELTA)])


def root_hermite_factor(beta: int) -> float:
    """``delta(beta)``: Chen's formula from :data:`FORMULA_FROM`, the experimental values of
    Gama and Nguyen interpolated (in ``log delta``) below it (module docstring). ``beta >= 2``."""
    beta = check_int("beta", beta, minimum=2, maximum=MAX_BLOCK_SIZE)
    if beta >= FORMULA_FROM:
        return _chen(beta)
    points = sorted(GAMA_NGUYEN_DELTA.items()) + [(FORMULA_FROM, _chen(FORMULA_FROM))]
    for (b0, d0), (b1, d1) in zip(points, points[1:]):
        if b0 <= beta <= b1:
            w = (beta - b0) / (b1 - b0)
            return math.exp((1 - w) * math.log(d0) + w * math.log(d1))
    raise AssertionError("unreachable: the points cover [2, FORMULA_FROM]")


def binomial_sigma(eta: int) -> float:
    """Standard deviation ``sqrt(eta / 2)`` of the centred binomial distribution ``B_eta``."""
    return math.sqrt(check_int("eta", eta, minimum=1) / 2)


@dataclasses.dataclass(frozen=True)
class LWEParameterSet:
    """An LWE instance family as the attacker sees it (the lattice-estimator's value object).

    Attributes
    ----------
    name : str
    n : int
        Dimension of the secret.
    q : int
        Modulus.
    sigma_s, sigma_e : float
        Standard deviations of the secret and of the error entries.
    m_max : int
        Samples available to the attacker (rows of the public matrix).
    source : str
        Where the published estimate comes from (empty for the package's own instances).
    published : mapping
        The published figures (``beta``, ``classical``, ``quantum``, ...), shown beside the
        computed ones and used by the tests only.
    """

    name: str
    n: int
    q: int
    sigma_s: float
    sigma_e: float
    m_max: int
    source: str = ""
    published: Mapping[str, float] = dataclasses.field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "n", check_int("n", self.n, minimum=1))
        object.__setattr__(self, "q", check_int("q", self.q, minimum=2))
        object.__setattr__(self, "m_max", check_int("m_max", self.m_max, minimum=1))
        object.__setattr__(self, "sigma_s", check_positive("sigma_s", self.sigma_s))
        object.__setattr__(self, "sigma_e", check_positive("sigma_e", self.sigma_e))
        if self.n + self.m_max + 1 > MAX_BLOCK_SIZE:
            raise ModelRangeError(
                f"{self.name}: lattice dimension n + m_max + 1 = {self.n + self.m_max + 1} is beyond the modelled "
                f"range (at most {MAX_BLOCK_SIZE})"
            )


@dataclasses.dataclass(frozen=True)
class PrimalEstimate:
    """The cheapest primal uSVP attack: block size, samples used, lattice dimension, costs in bits."""

    parameters: LWEParameterSet
    beta: int
    m: int
    d: int

    def bits(self, model: str = "classical") -> float:
        """``c beta`` for the core-SVP model ``model`` (:data:`CORE_SVP_EXPONENTS`)."""
        if model not in CORE_SVP_EXPONENTS:
            raise ParameterError(f"core-SVP model must be one of {sorted(CORE_SVP_EXPONENTS)}, got {format_value(model)}")
        return CORE_SVP_EXPONENTS[model] * self.beta

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary."""
        return {
            "name": self.parameters.name,
            "beta": self.beta,
            "m": self.m,
            "d": self.d,
            **{model: self.bits(model) for model in CORE_SVP_EXPONENTS},
        }


def _margin(p: LWEParameterSet, beta: int, m: np.ndarray) -> np.ndarray:
    # log(RHS) - log(LHS) of the success condition, for every m (natural logarithms)
    d = m + p.n + 1
    log_vol = m * math.log(p.q) + p.n * math.log(p.sigma_e / p.sigma_s)
    rhs = (2 * beta - d - 1) * math.log(root_hermite_factor(beta)) + log_vol / d
    return rhs - (math.log(p.sigma_e) + 0.5 * math.log(beta))


def primal_usvp_succeeds(p: LWEParameterSet, m: int, beta: int) -> bool:
    """Whether BKZ-``beta`` on the embedding lattice with ``m`` samples meets the GSA success
    condition of ADPS16 (module docstring); ``beta <= d``."""
    m = check_int("m", m, minimum=1, maximum=p.m_max)
    beta = check_int("beta", beta, minimum=2, maximum=m + p.n + 1)
    return bool(_margin(p, beta, np.array([m]))[0] >= 0)


def _best_m(p: LWEParameterSet, beta: int) -> int | None:
    # the m <= m_max with beta <= d that meets the condition with the widest margin (None: none does)
    m = np.arange(max(1, beta - p.n - 1), p.m_max + 1)
    if m.size == 0:
        return None
    margin = _margin(p, beta, m)
    best = int(np.argmax(margin))
    return int(m[best]) if margin[best] >= 0 else None


def primal_usvp_estimate(p: LWEParameterSet) -> PrimalEstimate:
    """The smallest block size ``beta`` for which some ``m <= m_max`` meets the success condition
    (a scan of every ``beta``, each over every ``m``, vectorised).

    Raises
    ------
    ModelRangeError
        If no block size up to the full lattice dimension meets it (too few samples for a
        unique shortest vector).
    """
    if not isinstance(p, LWEParameterSet):
        raise ParameterError(f"p must be an LWEParameterSet, got {format_value(p)}")
    for beta in range(2, p.n + p.m_max + 2):
        m = _best_m(p, beta)
        if m is not None:
            return PrimalEstimate(p, beta, m, m + p.n + 1)
    raise ModelRangeError(
        f"{p.name}: no block size up to d = {p.n + p.m_max + 1} meets the primal uSVP condition with at most "
        f"{p.m_max} samples (the error is too wide for a unique short vector)"
    )


def key_costs(est: PrimalEstimate, *, shared_matrix: bool, model: str = "classical") -> tuple[float, float]:
    """``(first, later)``: the bits charged for the first key and for each further key of a key
    sequence (key rotation), the lattice analogue of the discrete-logarithm precomputation.

    A fresh public matrix per key: every key is a primal attack of its own (``first = later =``
    the core-SVP bits of ``est``). A matrix shared by the keys (only ``s`` and ``e`` rotate): the
    attacker reduces the lattice of ``A`` once, and each further key is one Babai nearest plane
    on the reduced basis, ``d^2`` operations in dimension ``d = m + n`` (measured with
    :mod:`encctl_gym.cryptanalysis.lattice_lwe`'s ``bdd`` breaker, ``docs/lwe.md``). The first
    key's figure is then a lower bound: decoding by Babai needed larger block sizes than the
    primal attack in every measurement (n <= 100). A later key never costs more than a fresh
    primal attack (the attacker can always run one): ``later = min(first, 2 log2 d)``.
    """
    first = est.bits(model)
    if not shared_matrix:
        return first, first
    return first, min(first, 2 * math.log2(est.parameters.n + est.m))


def smallest_secure_dimension(
    modulus_of: Callable[[int], int], sigma: float, bits: float, *, model: str = "classical", n_max: int = 4096
) -> tuple[int, PrimalEstimate]:
    """The smallest dimension ``n`` (``m = n`` samples, secret and error of width ``sigma``) whose
    primal uSVP core-SVP cost under ``model`` reaches ``bits``, when the modulus is
    ``modulus_of(n)`` (a scheme's modulus grows with n through its noise bound); bisection, the
    cost being taken as non-decreasing in n.

    Raises
    ------
    ModelRangeError
        If even ``n_max`` falls short.
    """
    bits = check_positive("bits", bits)
    sigma = check_positive("sigma", sigma)

    def estimate(n: int) -> PrimalEstimate:
        return primal_usvp_estimate(LWEParameterSet(f"n={n}", n, modulus_of(n), sigma, sigma, n))

    top = estimate(check_int("n_max", n_max, minimum=2))
    if top.bits(model) < bits:
        raise ModelRangeError(f"even n = {n_max} gives only {top.bits(model):.1f} < {bits:g} bits ({model} core-SVP)")
    lo, hi, best = 1, n_max, top
    while hi - lo > 1:
        mid = (lo + hi) // 2
        e = estimate(mid)
        if e.bits(model) >= bits:
            hi, best = mid, e
        else:
            lo = mid
    return hi, best


def _kyber(k: int, eta: int, source: str, published: Mapping[str, float]) -> LWEParameterSet:
    # module-LWE of rank k over Z_q[X]/(X^256 + 1) as LWE in dimension 256 k; the key-recovery attack
    # uses at most the 256 k public-key samples plus the 256 k of one ciphertext (the Kyber team's
    # convention: m <= 256 (k + 1))
    return LWEParameterSet(
        f"Kyber-{256 * k}", 256 * k, 3329, binomial_sigma(eta), binomial_sigma(eta), 256 * (k + 1), source, published
    )


_KYBER_R3 = (
    "CRYSTALS-Kyber, Algorithm Specifications and Supporting Documentation, version 3.01/3.02 "
    "(Avanzi, Bos, Ducas, Kiltz, Lepoint, Lyubashevsky, Schanck, Schwabe, Seiler, Stehle, 2021)"
)
_NEWHOPE_NIST = (
    "NewHope, Algorithm Specifications and Supporting Documentation, version 1.0 (2018), Section 4.2.5 "
    "(Alkim, Avanzi, Bos, Ducas, de la Piedra, Poppelmann, Schwabe, Stebila)"
)

#: Standard parameter sets with their published primal core-SVP estimates (keys: ``classical``,
#: ``quantum``, and ``beta`` where published). See ``docs/lwe.md`` for how each figure was checked.
STANDARD_PARAMETER_SETS: Mapping[str, LWEParameterSet] = {
    p.name: p
    for p in (
        # Kyber-512 round 3 (eta1 = 3 for s and e): 118 bits, 112 without the rounding noise of the
        # ciphertext (the spec's change log); the key attack modelled here has no rounding noise
        _kyber(2, 3, _KYBER_R3, {"classical": 118, "quantum": 107}),
        _kyber(3, 2, _KYBER_R3, {"classical": 183, "quantum": 166}),
        _kyber(4, 2, _KYBER_R3, {"classical": 256, "quantum": 232}),
        # NewHope-512 (ring-LWE, n = 512, q = 12289, binomial k = 8: sigma = 2); one public key: m <= n
        LWEParameterSet("NewHope-512", 512, 12289, 2.0, 2.0, 512, _NEWHOPE_NIST, {"classical": 112, "quantum": 101}),
    )
}


class PrimalUSVPModel(CostModel):
    """A deciphering-cost model of an LWE scheme for the key-length design (eq:opt_key): the key
    length is the dimension ``n``, and breaking one key costs the primal uSVP attack's core-SVP
    operations ``2^(c beta)`` (:func:`primal_usvp_estimate`, ``m <= n`` samples of a public key,
    secret and error of width ``sigma``, modulus ``modulus_of(n)``).

    A scheme binds ``modulus_of`` (its modulus for a dimension) and the core-SVP model; the
    security parameter of a dimension is its first key's bits. With ``shared_matrix`` the keys
    share one public matrix and every key after the first costs one nearest-plane decoding
    (:func:`key_costs`).

    Parameters
    ----------
    modulus_of : callable
        ``n -> q``.
    sigma : float
        Width of the secret and of the error.
    core_svp : str
        A model of :data:`CORE_SVP_EXPONENTS`.
    shared_matrix : bool
        Whether the keys share their public matrix.
    """

    key_length_range = (2, 4096)
    FORMULA = "2^(c beta), beta the smallest block size meeting the GSA condition of the primal uSVP attack (ADPS16)"

    def __init__(
        self, modulus_of: Callable[[int], int], sigma: float, core_svp: str = "classical", *, shared_matrix: bool = False
    ) -> None:
        if core_svp not in CORE_SVP_EXPONENTS:
            raise ParameterError(f"core_svp must be one of {sorted(CORE_SVP_EXPONENTS)}, got {format_value(core_svp)}")
        self.modulus_of, self.sigma, self.core_svp = modulus_of, check_positive("sigma", sigma), core_svp
        self.shared_matrix = bool(shared_matrix)
        self._estimates: dict[int, PrimalEstimate] = {}

    def estimate(self, n: int) -> PrimalEstimate:
        """The primal estimate at dimension ``n`` (cached)."""
        n = check_int("n", n, minimum=self.key_length_range[0], maximum=self.key_length_range[1])
        if n not in self._estimates:
            q = int(self.modulus_of(n))
            self._estimates[n] = primal_usvp_estimate(LWEParameterSet(f"n={n}", n, q, self.sigma, self.sigma, n))
        return self._estimates[n]

    def security_parameter_of_key_length(self, key_length: int) -> float:
        """The first key's core-SVP bits at dimension ``key_length``."""
        return self.estimate(key_length).bits(self.core_svp)

    def break_cost(self, key_length: int) -> KeyBreakCost:
        first, later = key_costs(self.estimate(key_length), shared_matrix=self.shared_matrix, model=self.core_svp)
        return KeyBreakCost(self.name, pow2(first), pow2(later), key_length=int(key_length), security_parameter=first)

    def key_length_for_security_parameter(self, lam: Any) -> int:
        """The smallest dimension whose first key costs at least ``2^lam`` (:func:`smallest_secure_dimension`)."""
        n, _ = smallest_secure_dimension(
            self.modulus_of, self.sigma, float(lam), model=self.core_svp, n_max=self.key_length_range[1]
        )
        return n

    def cost_of_security_parameter(self, lam: Any) -> KeyBreakCost:
        return self.break_cost(self.key_length_for_security_parameter(lam))

    def describe(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "family": "lattice",
            "formula": self.FORMULA,
            "core_svp": self.core_svp,
            "exponent": CORE_SVP_EXPONENTS[self.core_svp],
            "sigma": self.sigma,
            "shared_matrix": self.shared_matrix,
            "source": "Alkim, Ducas, Poppelmann, Schwabe, USENIX Security 2016, Section 6",
            "key_length_range": list(self.key_length_range),
        }
