"""Verification of the server's output: the keyed linear check (any scheme, the multiplicative
ElGamal loop's defender ``"linear-check"``) and the linearly homomorphic MAC of the additive
Paillier scheme, with real integers and real ciphertexts (the bounds and the argument are in
:mod:`encctl_gym.security.verification`).

**The keyed linear check** (:class:`KeyedLinearCheck`, Freivalds' check over the integers). On the
multiplicative scheme the server returns the products ``P_ij = E_ij X_j`` under encryption and the
plant sums them after decryption (``Sum`` of eq:ec); on the additive one it returns the row sums.
Either way the plant ends with the integers ``S_i`` it decodes with ``Delta^2``. The plant side
keeps ``r`` (uniform in ``{1..R}^m``, never sent) and ``w = r^T E`` and accepts iff
``r^T S = w^T X``: ``n + m`` integer products per step, no ciphertext, nothing sent, so the check
reveals nothing to the server but its verdict (a failure ends the attack). It needs what the
plant side has anyway: the state it encrypted and ``E`` (on ElGamal the decrypted products
``P_ij / X_j`` show ``E`` to the plant whatever it holds).

What the server could compute homomorphically instead (a tag row ``Enc(c)``, ``c ~ r^T E``,
evaluated against ``Enc(X)`` like Phi's rows) would give the plant ``c_j X_j`` after decryption,
which it can form from ``c`` and ``X`` in ``n`` products without the server: on this loop a
server-side tag costs ``n`` decryptions more and checks nothing more.

**The MAC** (:class:`PaillierMac`) is for a verifier that does not hold ``E``: the plant side keeps
``alpha``, ``gamma``, ``delta = E gamma mod n`` (provisioned once) and a fresh ``rho_t`` and
``beta_t`` per step; it sends ``Enc(alpha X_j + rho_t gamma_j)`` beside ``Enc(X_j)`` and
``Enc(beta_t)``; the server evaluates the tag rows with the same plaintext coefficients
(:func:`evaluate_tags`). Without ``rho_t`` (one ``gamma`` for every step) the MAC is broken by
the homomorphism itself: the difference of two steps' tagged states is ``Enc(alpha (X(t) -
X(s)))``, and :func:`forge_across_steps` passes with probability 1.

:class:`LinearCheckDefender` runs the keyed linear check in the environment: every attack step it
checks the input the plant decoded last step against the state it encrypted then (the integers
``S`` recovered exactly from the decoded input), and ends the attack at the first failure.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from .._validation import check_int, format_value
from ..errors import ParameterError
from ..security.verification import check_secret_range, linear_check_pass_bound, mac_pass_bound
from .defender import DEFENDERS, DefenderAction, PlantView
from .defenses import _PlantSidePolicy
from .spec import LoopSpec

__all__ = [
    "KeyedLinearCheck",
    "LinearCheckDefender",
    "MacDefender",
    "verifier_for",
    "check_exact_sums",
    "PaillierMac",
    "evaluate_tags",
    "forge_across_steps",
    "uniform_below",
    "row_sums_of",
    "measure_check_seconds",
]

#: Integers below this are recovered exactly from their decoded double (``|S| < 2^52``).
EXACT_SUM_LIMIT = 1 << 52


def check_exact_sums(what: str, E: Any, delta: float, x_bound: float, max_shift: int = 0) -> None:
    """Refuse an encoding whose row sums ``S = E X`` could reach ``2^52``: a check that reads
    them back from the decoded input (:func:`row_sums_of`) would no longer see them exactly."""
    x_max = int(round(delta * x_bound)) + max_shift + 1
    if max(sum(abs(int(v)) for v in row) for row in E) * x_max >= EXACT_SUM_LIMIT:
        raise ParameterError(
            f"{what} recovers the row sums from the decoded input exactly only below 2^52; "
            f"Delta = {delta:g} with x_bound = {x_bound:g} exceeds it"
        )


def uniform_below(rng: Any, bound: int) -> int:
    """A uniform integer in ``[0, bound)`` from ``rng`` (a NumPy generator, or anything with
    ``below(bound)`` like :class:`~encctl_gym.crypto.arith.RandomSource`), by rejection of
    uniform bit strings (unbiased for every ``bound``)."""
    bound = check_int("bound", bound, minimum=1)
    below = getattr(rng, "below", None)
    if callable(below):
        return int(below(bound))
    bits = (bound - 1).bit_length()
    if bits == 0:
        return 0
    nbytes = (bits + 7) // 8
    mask = (1 << bits) - 1
    while True:
        v = int.from_bytes(rng.bytes(nbytes), "little") & mask
        if v < bound:
            return v


class KeyedLinearCheck:
    """Freivalds' check ``r^T S = (r^T E) X`` over the integers (module docstring).

    Parameters
    ----------
    E : matrix of int, shape (m, n)
        The signed integers of Phi (``QuantizedLinearController.phi_int``, ``Phi_bar`` of Paillier).
    secret_range : int
        ``R >= 2``: each ``r_i`` is uniform in ``{1, ..., R}``.
    rng : numpy.random.Generator or RandomSource
        The plant side's own stream.

    Attributes
    ----------
    epsilon : float
        The largest probability that a falsified step passes (:func:`~encctl_gym.security.verification.linear_check_pass_bound`).
    """

    def __init__(self, E: Any, secret_range: int, rng: Any) -> None:
        rows = [[int(v) for v in row] for row in E]
        if not rows or not rows[0] or any(len(r) != len(rows[0]) for r in rows):
            raise ParameterError(f"E must be a non-empty rectangular integer matrix, got {format_value(E)}")
        self.R = check_secret_range("secret_range", secret_range)
        self.m, self.n = len(rows), len(rows[0])
        self._r = [1 + uniform_below(rng, self.R) for _ in range(self.m)]
        self.rekey(rows)
        self.epsilon = linear_check_pass_bound(self.m, self.R)

    def rekey(self, E: Any) -> None:
        """``w = r^T E`` for a new encoding of Phi (a new group), the same ``r``."""
        rows = [[int(v) for v in row] for row in E]
        self._w = [sum(ri * row[j] for ri, row in zip(self._r, rows)) for j in range(self.n)]

    def passes(self, sums: Sequence[int], X: Sequence[int]) -> bool:
        """Whether the decrypted row sums ``S'`` agree with the encoded state ``X``: ``r^T S' = w^T X``.

        Raises
        ------
        ParameterError
            For sums or a state of another length.
        """
        if len(sums) != self.m or len(X) != self.n:
            raise ParameterError(f"the check takes {self.m} row sums and {self.n} state integers, got {len(sums)} and {len(X)}")
        lhs = sum(ri * int(s) for ri, s in zip(self._r, sums))
        return lhs == sum(wj * int(x) for wj, x in zip(self._w, X))

    def __repr__(self) -> str:
        return f"KeyedLinearCheck(m={self.m}, n={self.n}, secret_range={self.R})"


def row_sums_of(u: Any, delta: int) -> list[int]:
    """The integers ``S`` a decoded input ``u = Dcd(S; Delta^2)`` came from: ``round(u Delta^2)``
    in exact rational arithmetic (exact for ``|S| < 2^52``, where the decoder's one rounding to
    a double loses less than half a unit)."""
    d2 = int(delta) ** 2
    return [round(Fraction(float(v)) * d2) for v in np.asarray(u, dtype=float).ravel()]


class _ExactCheckPolicy(_PlantSidePolicy):
    """What the exact checks share: every attack step, each copy's decoded input ``u_{k-1}``
    checked against the state ``x_{k-1}`` the plant encrypted then (:meth:`_passes`, one per
    check), the counts, and the end of the attack at the first failure."""

    checks: int
    failures: int

    def _passes(self, k: int, x_prev: np.ndarray, sums: list[int]) -> bool:
        raise NotImplementedError

    def caught(self, x_prev: np.ndarray, last_input: np.ndarray) -> bool:
        """Check every copy's decoded input ``u_{k-1}`` against its state ``x_{k-1}``; whether any
        failed (the game's ``"verify"`` lever calls it at the steps the defender asks for)."""
        failed = False
        for k in range(self.K):
            ok = self._passes(k, x_prev[k], row_sums_of(last_input[k], int(self.delta)))
            self.checks += 1
            self.failures += not ok
            failed = failed or not ok
        return failed

    def act(self, view: PlantView) -> DefenderAction | None:
        x_prev, self._x_prev = self._x_prev, np.array(view.state, dtype=float)
        if x_prev is None:
            return None
        return DefenderAction(end=True) if self.caught(x_prev, view.last_input) else None


class LinearCheckDefender(_ExactCheckPolicy):
    """The keyed linear check at every attack step (registry name ``"linear-check"``).

    Before the period of step ``k`` it checks the input the plant decoded at step ``k - 1``
    against the state ``x_{k-1}`` it encrypted then, each copy with its own ``r``; a failure in
    any copy ends the attack (``info["detected"]``). The integers of the check are those of the
    loop's own encoding (the scheme's quantization on the loop's group), so an honest server never
    fails it, on either backend.

    Parameters
    ----------
    secret_range : int, default 2**64
        ``R``: a falsified step passes with probability at most ``1 / R`` (``m >= 2``), never
        (``m = 1``).

    Raises
    ------
    ParameterError
        For ``R < 2``, a loop that sends outputs (the controller's input is then ``[x_c; y]``,
        not the state the plant view holds), or an encoding whose row sums could reach ``2^52``.
    """

    name = "linear-check"

    def __init__(self, secret_range: int = 1 << 64) -> None:
        self.secret_range = check_secret_range("secret_range", secret_range)
        self.checks = self.failures = 0

    def group(self, params: LoopSpec) -> Any:
        if params.observe != "state":
            raise ParameterError(
                f"the linear check verifies the state-feedback loop; observe = {params.observe!r} is not supported"
            )
        group = super().group(params)
        self._params = params
        self._quantize(group)
        return group

    def _quantize(self, group: Any) -> None:
        scheme = self._params.encryption()
        encoder = scheme.encoder(group, self.delta)
        self.quantization = scheme.quantization(self.Phi, encoder, float(self._params.x_bound), float(self._params.u_max))
        E = getattr(self.quantization, "phi_int", None)
        if E is None:  # Paillier quantises Phi in the plant's parties; its check is security.verification.PaillierMac
            raise ParameterError(f"the linear check verifies the ElGamal schemes' quantised Phi; scheme {scheme.name!r} has none")
        check_exact_sums("the linear check", E, self.delta, float(self._params.x_bound), int(self.max_shift))

    def on_new_group(self, group: Any) -> None:
        super().on_new_group(group)
        self._quantize(group)
        for check in getattr(self, "_checks", []):
            check.rekey(self.quantization.phi_int)

    def reset(self, K: int, n: int, m: int, rngs: Sequence[np.random.Generator]) -> None:
        super().reset(K, n, m, rngs)
        self._checks = [KeyedLinearCheck(self.quantization.phi_int, self.secret_range, rngs[i]) for i in range(K)]
        self.checks = self.failures = 0

    @property
    def epsilon(self) -> float:
        """The largest probability that one falsified step passes."""
        return linear_check_pass_bound(self.B.shape[1], self.secret_range)

    def _passes(self, k: int, x_prev: np.ndarray, sums: list[int]) -> bool:
        return self._checks[k].passes(sums, self.quantization.encode_state(x_prev))

    def __repr__(self) -> str:
        return f"LinearCheckDefender(secret_range={self.secret_range!r})"


DEFENDERS.update({"linear-check": LinearCheckDefender})


# ---------------------------------------------------------------------- the Paillier MAC
class PaillierMac:
    """The plant side of the linearly homomorphic MAC on Paillier's scheme (module docstring of
    :mod:`encctl_gym.security.verification`).

    Parameters
    ----------
    sk : PaillierSecretKey
        The plant's key (the tags are under the loop's own key).
    E : matrix of int, shape (m, n)
        ``Phi_bar``; used once, for ``delta = E gamma mod n`` (the provisioning), then dropped.
    alpha_range : int, optional
        ``A``: ``alpha`` uniform in ``{1, ..., A}`` (default ``n - 1``: every unit-size residue).
    rng : RandomSource or numpy.random.Generator
        The plant side's stream (secrets and encryption randomness).
    """

    def __init__(self, sk: Any, E: Any, rng: Any, alpha_range: int | None = None) -> None:
        self.sk, self.pk = sk, sk.public
        n = self.pk.n
        self.A = n - 1 if alpha_range is None else check_secret_range("alpha_range", alpha_range)
        if self.A >= n:
            raise ParameterError(f"alpha_range must be below the modulus n, got {format_value(self.A)}")
        rows = [[int(v) for v in row] for row in E]
        self.m, self.n = len(rows), len(rows[0])
        self._rng = rng
        self._alpha = 1 + uniform_below(rng, self.A)
        self._gamma = [uniform_below(rng, n) for _ in range(self.n)]
        self._delta = [sum(e * g for e, g in zip(row, self._gamma)) % n for row in rows]
        self._beta: list[int] | None = None
        self._rho = 0
        self.epsilon = mac_pass_bound(self.A, self.pk.bits)

    def tag_state(self, X: Sequence[int]) -> tuple[list[Any], list[Any]]:
        """What the plant sends this step beside ``Enc(X_j)``: ``Enc(alpha X_j + rho_t gamma_j)``
        and ``Enc(beta_t,i)`` (``n + m`` encryptions), with this step's fresh ``rho_t`` and
        ``beta_t``, which replace the last step's."""
        from ..crypto.paillier import encrypt_with_secret

        n = self.pk.n
        if len(X) != self.n:
            raise ParameterError(f"the MAC takes {self.n} state integers, got {len(X)}")
        self._rho = uniform_below(self._rng, n)
        self._beta = [uniform_below(self._rng, n) for _ in range(self.m)]
        tagged = [
            encrypt_with_secret(self.sk, (self._alpha * int(x) + self._rho * g) % n, self._rng) for x, g in zip(X, self._gamma)
        ]
        masks = [encrypt_with_secret(self.sk, b, self._rng) for b in self._beta]
        return tagged, masks

    def passes(self, rows: Sequence[Any], tags: Sequence[Any]) -> bool:
        """``Dec(tau_i) = alpha Dec(c_i) + rho_t delta_i + beta_t,i (mod n)`` for every row, with
        this step's ``rho_t`` and ``beta_t`` (``2 m`` decryptions); before any :meth:`tag_state`
        nothing passes."""
        from ..crypto.paillier import decrypt

        if len(rows) != self.m:
            return False
        return self.passes_sums([decrypt(self.sk, c) for c in rows], tags)

    def passes_sums(self, sums: Sequence[int], tags: Sequence[Any]) -> bool:
        """:meth:`passes` for rows the plant has decrypted already: ``sums`` are the integers
        ``S_i`` (signed or reduced modulo ``n``: the check is modulo ``n``); ``m`` decryptions."""
        from ..crypto.paillier import decrypt

        if self._beta is None or len(sums) != self.m or len(tags) != self.m:
            return False
        n = self.pk.n
        for S, t, d, b in zip(sums, tags, self._delta, self._beta):
            if decrypt(self.sk, t) != (self._alpha * int(S) + self._rho * d + b) % n:
                return False
        return True

    def __repr__(self) -> str:
        return f"PaillierMac(m={self.m}, n={self.n}, alpha_range={self.A}, modulus_bits={self.pk.bits})"


def evaluate_tags(E: Any, tagged: Sequence[Any], masks: Sequence[Any]) -> list[Any]:
    """The server's tag rows ``tau_i = sum_j E_ij Enc(alpha X_j + gamma_j) + Enc(beta_t,i)``
    (Paillier's Eval with the plaintext coefficients it holds; ``m n`` exponentiations)."""
    out = []
    for row, mask in zip(E, masks):
        acc = mask
        for e, ct in zip(row, tagged):
            acc = acc + ct * int(e)
        out.append(acc)
    return out


def forge_across_steps(
    rows: Sequence[Any],
    tags: Sequence[Any],
    now: tuple[Sequence[Any], Sequence[Any]],
    before: tuple[Sequence[Any], Sequence[Any]],
    K: Any,
) -> tuple[list[Any], list[Any]]:
    """The cross-step forgery of the MAC (no key): ``u' = Phi x_t + K (x_t - x_s)``.

    ``now`` and ``before`` are the ciphertexts the plant sent at steps ``t`` and ``s``: the states
    ``Enc(X_j)`` and the tagged states. The server adds ``K (Enc(X(t)) - Enc(X(s)))`` to the rows
    and ``K`` times the difference of the tagged states to the tags. With one ``gamma`` for every
    step (a MAC without a per-step factor), the difference of two tagged states is
    ``Enc(alpha (X(t) - X(s)))``: ``gamma`` cancels and the forgery passes with probability 1
    whatever ``alpha`` is. Any ``u' = sum_s K_s x_s`` with ``sum_s K_s = Phi`` is such a forgery,
    which includes another controller of the state's history. With the per-step ``rho_t`` of
    :class:`PaillierMac` the difference leaves ``(rho_t - rho_s) gamma``, which the server cannot
    remove, and the forgery passes with at most the MAC's ``epsilon``.
    """
    (x_now, tag_now), (x_before, tag_before) = now, before
    K = [[int(v) for v in row] for row in K]
    if len(K) != len(rows) or any(len(row) != len(x_now) for row in K):
        raise ParameterError(f"K must have shape ({len(rows)}, {len(x_now)}), got {format_value(K)}")

    def moved(base: Sequence[Any], a: Sequence[Any], b: Sequence[Any]) -> list[Any]:
        out = []
        for c, row in zip(base, K):
            for k, ca, cb in zip(row, a, b):
                if k:
                    c = c + ca * k + cb * (-k)
            out.append(c)
        return out

    return moved(rows, x_now, x_before), moved(tags, tag_now, tag_before)


class MacDefender(_ExactCheckPolicy):
    """The linearly homomorphic MAC at every attack step, on the Paillier loop (registry name
    ``"mac"``; :class:`PaillierMac`, bound in :mod:`encctl_gym.security.verification`).

    Each episode draws one Paillier key of the loop's modulus length for the tags (KeyGen from
    the defender's first stream) and, per copy, the MAC's secrets. Every attack step it checks
    the input the plant decoded at step ``k - 1``: the plant tags the state ``X(k - 1)`` it
    encrypted then (``Enc(alpha X_j + rho gamma_j)`` and ``Enc(beta)``, real ciphertexts), the
    server evaluates the tag rows with ``Phi_bar`` (:func:`evaluate_tags`), and the plant checks
    them against the row sums it decrypted (read back exactly from the decoded input,
    :func:`row_sums_of`). A failure in any copy ends the attack. The injection modes of the
    environment (replace, add, scale) forge the rows and forward the tags the server computed;
    an attacker that forges tags too is measured in ``experiments/integrity.py``.

    Parameters
    ----------
    alpha_range : int, optional
        ``A``: ``alpha`` uniform in ``{1..A}`` (default ``n - 1``); a falsified step passes with
        probability at most ``1 / A + 2 / p_min``.

    Raises
    ------
    ParameterError
        For a loop that is not the Paillier scheme's state-feedback loop, ``A < 2``, or an
        encoding whose row sums could reach ``2^52``.
    """

    name = "mac"

    def __init__(self, alpha_range: int | None = None) -> None:
        self.alpha_range = None if alpha_range is None else check_secret_range("alpha_range", alpha_range)
        self.checks = self.failures = 0

    def group(self, params: LoopSpec) -> Any:
        if params.observe != "state":
            raise ParameterError(f"the MAC verifies the state-feedback loop; observe = {params.observe!r} is not supported")
        scheme = params.encryption()
        if scheme.name != "paillier":
            raise ParameterError(f"the MAC verifies the paillier scheme's loop, not {scheme.name!r} (use linear-check)")
        group = super().group(params)
        self.bits = int(group.key_length)
        self.encoder = scheme.encoder(group, self.delta)
        self.E = [[self.encoder.quantize(v) for v in row] for row in self.Phi.tolist()]
        check_exact_sums("the MAC", self.E, self.delta, float(params.x_bound))
        return group

    def reset(self, K: int, n: int, m: int, rngs: Sequence[np.random.Generator]) -> None:
        from ..crypto.paillier import keygen

        super().reset(K, n, m, rngs)
        _, self.sk = keygen(self.bits, rng=rngs[0])
        if self.alpha_range is not None and self.alpha_range >= self.sk.public.n:
            raise ParameterError(f"alpha_range must be below the modulus n, got {format_value(self.alpha_range)}")
        self._macs = [PaillierMac(self.sk, self.E, rngs[i], alpha_range=self.alpha_range) for i in range(K)]
        self.checks = self.failures = 0

    @property
    def epsilon(self) -> float:
        """The largest probability that one falsified step passes."""
        n = self.sk.public.n if hasattr(self, "sk") else 1 << (self.bits - 1)  # before a reset: n's lower bound
        return mac_pass_bound(self.alpha_range or n - 1, self.bits)

    def _passes(self, k: int, x_prev: np.ndarray, sums: list[int]) -> bool:
        """Tag the state ``x_{k-1}``, evaluate the tag rows, check them against the row sums."""
        mac = self._macs[k]
        tagged, masks = mac.tag_state(self.encoder.quantize_array(x_prev))
        return mac.passes_sums(sums, evaluate_tags(self.E, tagged, masks))

    def __repr__(self) -> str:
        return f"MacDefender(alpha_range={self.alpha_range!r})"


DEFENDERS.update({"mac": MacDefender})


def verifier_for(params: LoopSpec, secret_range: int) -> LinearCheckDefender | MacDefender:
    """The plant side's exact check for the loop of ``params``: the MAC on the Paillier scheme,
    the keyed linear check (range ``secret_range``) on the ElGamal schemes; set up for ``params``
    (its :meth:`group` called), so a loop the check cannot verify is refused here."""
    check: LinearCheckDefender | MacDefender
    check = MacDefender() if params.encryption().name == "paillier" else LinearCheckDefender(secret_range)
    check.group(params)
    return check


def measure_check_seconds(m: int, n: int, *, secret_range: int = 1 << 64, entry_bits: int = 24, repeats: int = 2000) -> float:
    """The median time of one keyed linear check of an ``m x n`` controller whose integers have
    ``entry_bits`` bits (the plant side's added work per step), in seconds."""
    m = check_int("m", m, minimum=1)
    n = check_int("n", n, minimum=1)
    repeats = check_int("repeats", repeats, minimum=1, maximum=10**7)
    rng = np.random.default_rng(0)
    lim = 1 << check_int("entry_bits", entry_bits, minimum=1, maximum=4096)
    E = [[uniform_below(rng, lim) for _ in range(n)] for _ in range(m)]
    X = [uniform_below(rng, lim) for _ in range(n)]
    S = [sum(e * x for e, x in zip(row, X)) for row in E]
    check = KeyedLinearCheck(E, secret_range, rng)
    times = np.empty(repeats)
    for i in range(repeats):
        t0 = time.perf_counter()
        check.passes(S, X)
        times[i] = time.perf_counter() - t0
    return float(np.median(times))
