"""Defender policies with real levers: input noise, random audits, a chi-squared and a CUSUM detector.

Each is a :class:`~encctl_gym.loop.defender.DefenderPolicy` (registered in ``DEFENDERS`` by name,
with its options from a mapping such as ``{"name": "audit", "rate": 5e-4}``) built on the
analysis of :mod:`encctl_gym.security.defenses` and the checks of :mod:`encctl_gym.loop.detection`:

* ``"noise"`` (:class:`NoiseDefender`): adds ``d ~ N(0, sigma_d2 I)`` to the input the plant
  applies at every attack step; to the attacker it is extra process noise ``B d`` (the episode
  applies it so), which :func:`~encctl_gym.security.defenses.sic_with_input_noise` accounts for.
* ``"audit"`` (:class:`AuditDefender`): with probability ``rate`` per step the plant side compares
  the input it decoded last step with its own ``Phi x`` and stops the attack on a difference
  beyond the encoding's error (:func:`audit_tolerance`).
* ``"chi2"`` (:class:`DetectorDefender`): the window chi-squared test on the closed-loop
  innovation with a false-alarm rate per step; it needs no controller computation of its own.
* ``"cusum"`` (:class:`CusumDefender`): Page's CUSUM on the same innovation, tuned for a
  covariance inflation ``variance_ratio``, with a false-alarm rate per step.

The plant side knows ``A``, ``B`` and the controller ``Phi`` (the loop's LQR gain,
:func:`~encctl_gym.loop.backend.lqr_gain`): the policies take them from the resolved parameters in
:meth:`group`. Every copy of a batch runs in lockstep, so an alarm in one copy ends the attack
of all (the environment's ``info["detected"]``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .._validation import check_int, check_nonnegative, check_positive
from ..errors import ParameterError
from .backend import lqr_gain, table_limit
from .defender import DEFENDERS, DefenderAction, DefenderBase, PlantView
from .detection import Audit, ChiSquaredDetector, CusumDetector, check_audit_rate
from .spec import LoopSpec

__all__ = ["AuditDefender", "CusumDefender", "DetectorDefender", "NoiseDefender", "audit_tolerance"]


def audit_tolerance(Phi: np.ndarray, x: np.ndarray, delta: float, max_shift: int = 0) -> np.ndarray:
    """The largest ``|u_i - (Phi x)_i|`` the encoding explains, per copy and input, shape (K, m).

    The loop encodes ``Phi`` and ``x`` as the subgroup elements nearest ``round(Delta .)``: each
    integer is off by at most ``e = 1/2 + max_shift`` (the residue table's largest shift). It
    decodes ``sum_j (Delta Phi_ij + e1)(Delta x_j + e2) / Delta^2``, which differs from
    ``(Phi x)_i`` by at most ``e (sum_j |Phi_ij| + sum_j |x_j|) / Delta + n e^2 / Delta^2``.
    """
    n = Phi.shape[1]
    e = 0.5 + max_shift
    row = np.abs(Phi).sum(axis=1)  # (m,)
    col = np.abs(x).sum(axis=1, keepdims=True)  # (K, 1)
    return e * (row[None, :] + col) / delta + n * e * e / (delta * delta)


class _PlantSidePolicy(DefenderBase):
    """What every policy here shares: the plant's matrices and controller from ``group``."""

    name = "plant-side"

    def group(self, params: LoopSpec) -> Any:
        self.A = np.asarray(params.A, dtype=float)
        self.B = np.asarray(params.B, dtype=float)
        self.Phi = -lqr_gain(self.A, self.B)
        self.delta = float(params.delta)
        self.sigma_w2 = float(params.sigma_w2)
        group = params.group()
        self._rounding = params.encryption().rounding
        self._limit = table_limit(params, self.Phi)
        self.max_shift = self._rounding(group, self._limit).max_shift  # cached: the loop's own table
        return group

    def on_new_group(self, group: Any) -> None:
        """The loop moved to ``group`` (group rotation, :mod:`encctl_gym.loop.rotation`): the
        encoding's error bound takes that group's largest shift."""
        self.max_shift = self._rounding(group, self._limit).max_shift

    def reset(self, K: int, n: int, m: int, rngs: Sequence[np.random.Generator]) -> None:
        self.K, self.rngs = K, rngs
        self._x_prev: np.ndarray | None = None


class NoiseDefender(_PlantSidePolicy):
    """Input noise ``N(0, sigma_d2 I)`` at every attack step (registry name ``"noise"``).

    Parameters
    ----------
    sigma_d2 : float
        Variance of the noise (>= 0).
    """

    name = "noise"

    def __init__(self, sigma_d2: float = 0.0) -> None:
        self.sigma_d2 = check_nonnegative("sigma_d2", sigma_d2)

    def act(self, view: PlantView) -> DefenderAction | None:
        if self.sigma_d2 == 0.0:
            return None
        m = self.B.shape[1]
        d = np.stack([rng.normal(scale=np.sqrt(self.sigma_d2), size=m) for rng in self.rngs[: self.K]])
        return DefenderAction(input_noise=d)

    def __repr__(self) -> str:
        return f"NoiseDefender(sigma_d2={self.sigma_d2!r})"


class AuditDefender(_PlantSidePolicy):
    """Random audits of the decoded input against the plant side's own ``Phi x`` (``"audit"``).

    Parameters
    ----------
    rate : float
        Audit probability per step and copy, in [0, 1] (``minimum_audit_rate`` gives the rate
        that stops an attacker before ``N*``).
    """

    name = "audit"

    def __init__(self, rate: float = 5e-4) -> None:
        self.rate = check_audit_rate(rate, "rate")

    def reset(self, K: int, n: int, m: int, rngs: Sequence[np.random.Generator]) -> None:
        super().reset(K, n, m, rngs)
        self._audit = Audit(self.Phi, self.rate, rngs)

    @property
    def audits(self) -> int:
        """Audits run in the current episode (over all copies)."""
        return self._audit.audits

    def act(self, view: PlantView) -> DefenderAction | None:
        x_prev, self._x_prev = self._x_prev, np.array(view.state, dtype=float)
        if x_prev is None or self.rate == 0.0:
            return None
        tolerance = audit_tolerance(self.Phi, x_prev, self.delta, self.max_shift)
        caught = self._audit.check(x_prev, view.last_input, tolerance)
        return DefenderAction(end=True) if caught.any() else None

    def __repr__(self) -> str:
        return f"AuditDefender(rate={self.rate!r})"


class _InnovationDefender(_PlantSidePolicy):
    """A test on ``x[t+1] - (A + B Phi) x[t]`` that ends the attack on its first alarm."""

    def _detector(self, n: int, K: int) -> Any:
        raise NotImplementedError

    def reset(self, K: int, n: int, m: int, rngs: Sequence[np.random.Generator]) -> None:
        super().reset(K, n, m, rngs)
        self.detector = self._detector(n, K)

    def act(self, view: PlantView) -> DefenderAction | None:
        x, x_prev = np.array(view.state, dtype=float), self._x_prev
        self._x_prev = x
        if x_prev is None:
            return None
        return DefenderAction(end=True) if self.detector.update(x_prev, x).any() else None


def _check_false_alarm_rate(rate: Any) -> float:
    rate = check_positive("false_alarm_rate", rate)
    if rate >= 1:
        raise ParameterError(f"false_alarm_rate must lie in (0, 1), got {rate}")
    return rate


class DetectorDefender(_InnovationDefender):
    """The window chi-squared test on ``x[t+1] - (A + B Phi) x[t]`` (registry name ``"chi2"``).

    Parameters
    ----------
    window : int
        Innovations per window.
    false_alarm_rate : float
        Target probability of an alarm per step without an attack.
    """

    name = "chi2"

    def __init__(self, window: int = 10, false_alarm_rate: float = 1e-4) -> None:
        self.window = check_int("window", window, minimum=1, maximum=10**6)
        self.false_alarm_rate = _check_false_alarm_rate(false_alarm_rate)

    def _detector(self, n: int, K: int) -> ChiSquaredDetector:
        return ChiSquaredDetector(
            self.A + self.B @ self.Phi,
            self.sigma_w2 * np.eye(n),
            window=self.window,
            false_alarm_rate=self.false_alarm_rate,
            num_loops=K,
        )

    def __repr__(self) -> str:
        return f"DetectorDefender(window={self.window!r}, false_alarm_rate={self.false_alarm_rate!r})"


class CusumDefender(_InnovationDefender):
    """Page's CUSUM on ``x[t+1] - (A + B Phi) x[t]`` (registry name ``"cusum"``).

    Parameters
    ----------
    false_alarm_rate : float
        Target alarm rate per step without an attack.
    variance_ratio : float
        The inflation ``c > 1`` of the innovation covariance the test is tuned for.
    """

    name = "cusum"

    def __init__(self, false_alarm_rate: float = 1e-4, variance_ratio: float = 2.0) -> None:
        self.false_alarm_rate = _check_false_alarm_rate(false_alarm_rate)
        self.variance_ratio = check_positive("variance_ratio", variance_ratio)
        if self.variance_ratio <= 1:
            raise ParameterError(f"variance_ratio must be > 1, got {variance_ratio}")

    def _detector(self, n: int, K: int) -> CusumDetector:
        return CusumDetector(
            self.A + self.B @ self.Phi,
            self.sigma_w2 * np.eye(n),
            false_alarm_rate=self.false_alarm_rate,
            variance_ratio=self.variance_ratio,
            num_loops=K,
        )

    def __repr__(self) -> str:
        return f"CusumDefender(false_alarm_rate={self.false_alarm_rate!r}, variance_ratio={self.variance_ratio!r})"


DEFENDERS.update({"noise": NoiseDefender, "audit": AuditDefender, "chi2": DetectorDefender, "cusum": CusumDefender})


class CombinedDefender(DefenderBase):
    """Several policies at once (registry name ``"all"``: ``{"name": "all", "policies": [...]}``;
    the config keys ``audit_probability`` and ``defense_noise_sigma2`` add theirs this way).

    The loop's group is the first policy's; every policy sees every step. The actions merge: the
    input noises add up, the attack ends if any policy ends it, and at most one policy may move the
    loop to a new group. The first policy draws from the defender's own streams, each further one
    from streams spawned from them (``DefenderStreams``), so the policies' draws are independent
    and a combination of one policy draws exactly what that policy draws alone.

    Parameters
    ----------
    policies : sequence
        Policies or their specifications (names, mappings, objects), at least one.
    """

    name = "all"

    def __init__(self, policies: Sequence[Any] = ()) -> None:
        from .defender import make_defender

        if isinstance(policies, (str, bytes)) or not isinstance(policies, Sequence) or len(policies) == 0:
            raise ParameterError(f"policies must be a non-empty list of defender policies, got {policies!r}")
        self.policies = [make_defender(p) for p in policies]
        self.rotates = any(p.rotates for p in self.policies)

    @property
    def tally(self) -> Any:
        """The first policy's group-generation tally (``None`` when none generates groups)."""
        return next((p.tally for p in self.policies if p.tally is not None), None)

    def group(self, params: LoopSpec) -> Any:
        groups = [p.group(params) for p in self.policies]
        return groups[0]

    def reset(self, K: int, n: int, m: int, rngs: Sequence[np.random.Generator]) -> None:
        from .defender import DefenderStreams

        for i, p in enumerate(self.policies):
            p.reset(K, n, m, rngs if i == 0 else DefenderStreams(rngs))

    def act(self, view: PlantView) -> DefenderAction | None:
        from .defender import check_defender_action

        actions = [p.act(view) for p in self.policies]
        taken = [a for a in actions if a is not None]
        if not taken:
            return None
        noise: np.ndarray | None = None
        end = False
        new_group = None
        for a in taken:
            if a.input_noise is not None:
                d, _ = check_defender_action(
                    DefenderAction(input_noise=a.input_noise), view.state.shape[0], view.last_input.shape[-1]
                )
                noise = d if noise is None else noise + d
            end = end or a.end
            if a.new_group is not None:
                if new_group is not None:
                    raise ParameterError("two combined defender policies moved the loop to a new group in one step")
                new_group = a.new_group
        return DefenderAction(input_noise=noise, end=end, new_group=new_group)

    def on_new_group(self, group: Any) -> None:
        for p in self.policies:
            p.on_new_group(group)

    def close(self) -> None:
        for p in self.policies:
            p.close()

    def __repr__(self) -> str:
        return f"CombinedDefender({self.policies!r})"


DEFENDERS.update({"all": CombinedDefender})
