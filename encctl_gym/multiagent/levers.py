"""The defender's levers in the game: what it may do each step, what it sees, what it pays.

The game (:mod:`encctl_gym.multiagent.game`) hands the defender's decision of a step to the
episode through the defender seam of :mod:`encctl_gym.loop.defender`: :class:`DefenderLevers`
is a :class:`~encctl_gym.loop.defender.DefenderPolicy` whose :meth:`~DefenderLevers.act`
carries out the decision the game received for this step (:meth:`DefenderLevers.decide`), on
the plant side's data only (the :class:`~encctl_gym.loop.defender.PlantView`).

The defender's action is a vector in ``[-1, 1]``, one entry per lever of :data:`LEVERS`:

* ``"audit"`` (> 0: audit): the plant side recomputes ``Phi x_{k-1}`` and compares it with the
  input ``u_{k-1}`` it decrypted last step (:class:`~encctl_gym.loop.detection.Audit`, the
  tolerance of :func:`~encctl_gym.loop.defenses.audit_tolerance`); a difference beyond the
  encoding's error ends the attack (detected). A step the attacker passed through (the
  controller's own input) never fails. Audits are limited by :attr:`GameRules.audit_budget`
  (per episode) and cost :attr:`GameRules.audit_cost` each.
* ``"noise"``: ``sigma_d2 = noise_max * clip(entry, 0, 1)``; ``d ~ N(0, sigma_d2 I)`` is added
  to the input the plant applies (drawn as :class:`~encctl_gym.loop.defenses.NoiseDefender`
  draws it). Its cost per step is ``noise_weight`` times the relative increase of the
  normal-operation quadratic cost, :func:`~encctl_gym.security.defenses.noise_defense_price`
  ``cost_increase / cost_base`` (linear in ``sigma_d2``).

* ``"rotate"`` (> 0: rotate now): the loop moves to a fresh safe-prime group of its size before
  this step's period (:mod:`encctl_gym.loop.rotation`: the groups come from
  :class:`~encctl_gym.loop.rotation.RotationGroups`, the same sequence as the ``"rotate"``
  defender's: from the plant's stream with ``crypto_seed`` set, from the episode's seed without), so the samples from the next one on lie in the new group and
  the attacker's deciphering pays for it (its cost model charges per group: the game's
  :class:`~encctl_gym.multiagent.clock.GroupClock`). Each rotation costs
  :attr:`GameRules.rotation_cost`.
* ``"verify"`` (> 0: verify): the keyed linear check of the input ``u_{k-1}`` the plant side
  decrypted last step against the state ``x_{k-1}`` it encrypted
  (:class:`~encctl_gym.loop.verification.LinearCheckDefender`, secret range
  :attr:`GameRules.verify_secret_range`, its own spawned streams): a falsified input fails it
  but with probability ``1 / R`` (never for one input), with no tolerance (unlike an audit), and
  ends the attack; an honest one never fails. On the Paillier scheme's loop the lever runs the
  linearly homomorphic MAC instead (:class:`~encctl_gym.loop.verification.MacDefender`: real tag
  ciphertexts, bound ``1 / A + 2 / p_min`` with ``A = n - 1``). Each check costs
  :attr:`GameRules.verify_cost`.

A new lever is one more name in :data:`LEVERS`, one more entry of the action, one more field
of :class:`Decision`, and its cost in :meth:`DefenderLevers.cost`.

The defender observes (:meth:`DefenderLevers.observation`) what the plant side has: its state
``x_k``, the input ``u_{k-1}`` it decrypted, its chi-squared detector's window statistic over
the threshold (:class:`~encctl_gym.loop.detection.ChiSquaredDetector` on the innovation with its
own noise ``B d`` removed, which the plant side knows), the fraction of its audit budget used and
the fraction of the attack's steps gone. Nothing of the attacker's (its estimate, the deciphered
samples, its energy or history) enters it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_bool, check_int, check_nonnegative, check_positive
from ..crypto.group import GroupParams
from ..errors import ParameterError
from ..loop.defender import DefenderAction, DefenderStreams, PlantView
from ..loop.defenses import _PlantSidePolicy, audit_tolerance
from ..loop.detection import Audit, ChiSquaredDetector
from ..loop.rotation import GenerationTally, GroupPool, RotationGroups, check_ahead
from ..loop.verification import LinearCheckDefender, MacDefender, verifier_for
from ..security.defenses import noise_defense_price
from ..security.verification import check_secret_range

__all__ = ["LEVERS", "GameRules", "Decision", "DefenderLevers"]

#: The defender's levers, in the order of its action's entries.
LEVERS: tuple[str, ...] = ("audit", "noise", "rotate", "verify")


@dataclass(frozen=True)
class GameRules:
    """The game's configuration beyond the environment's (every field checked).

    Attributes
    ----------
    audit_budget : int or None
        Audits the defender may run per episode (``None``: no limit); an audit asked for past
        the budget is not run and costs nothing.
    audit_cost : float
        The defender's cost per audit run.
    noise_max : float or None
        The largest ``sigma_d2`` the noise lever sets (``None``: the attacker's ``sigma_u2``).
    noise_weight : float
        The defender's cost per step of a relative increase of 1 of the normal-operation
        quadratic cost (``noise_defense_price``).
    detection_penalty : float
        Subtracted from the attacker's reward at the step it is detected.
    zero_sum : bool
        The defender's reward is minus the attacker's, and the attacker's includes the defender's
        costs (module :mod:`encctl_gym.multiagent.game`).
    window, false_alarm_rate : int, float
        The defender's chi-squared detector (its observed statistic is over the threshold of this
        false-alarm rate per step).
    rotation_cost : float
        The defender's cost per group rotation.
    rotation_ahead : int
        Groups the pool generates ahead (off the control path), at most
        :data:`~encctl_gym.loop.rotation.MAX_AHEAD`.
    verify_cost : float
        The defender's cost per keyed linear check (the ``"verify"`` lever).
    verify_secret_range : int
        ``R`` of the check: a falsified step passes with probability at most ``1 / R``.
    rotation : bool
        The rotate lever is live; ``False`` ignores its entry (a defender without rotation; a
        fresh 712-bit group takes about 0.1 s to generate, which a learner that rotates at random
        pays at every other step).
    """

    audit_budget: int | None = None
    audit_cost: float = 0.01
    noise_max: float | None = None
    noise_weight: float = 0.01
    detection_penalty: float = 1.0
    zero_sum: bool = False
    window: int = 10
    false_alarm_rate: float = 1e-3
    rotation_cost: float = 0.1
    rotation_ahead: int = 2
    rotation: bool = True
    verify_cost: float = 0.001
    verify_secret_range: int = 1 << 64

    def __post_init__(self) -> None:
        if self.audit_budget is not None:
            check_int("audit_budget", self.audit_budget, minimum=0)
        check_nonnegative("audit_cost", self.audit_cost)
        if self.noise_max is not None:
            check_nonnegative("noise_max", self.noise_max)
        check_nonnegative("noise_weight", self.noise_weight)
        check_nonnegative("detection_penalty", self.detection_penalty)
        check_bool("zero_sum", self.zero_sum)
        check_int("window", self.window, minimum=1, maximum=10**6)
        fa = check_positive("false_alarm_rate", self.false_alarm_rate)
        if fa >= 1:
            raise ParameterError(f"false_alarm_rate must lie in (0, 1), got {self.false_alarm_rate}")
        check_nonnegative("rotation_cost", self.rotation_cost)
        check_ahead("rotation_ahead", self.rotation_ahead)
        check_bool("rotation", self.rotation)
        check_nonnegative("verify_cost", self.verify_cost)
        check_secret_range("verify_secret_range", self.verify_secret_range)

    @classmethod
    def of(cls, spec: Any) -> GameRules:
        """Rules from ``None`` (the defaults), a :class:`GameRules` or a mapping of its fields."""
        if spec is None:
            return cls()
        if isinstance(spec, GameRules):
            return spec
        if not isinstance(spec, dict):
            raise ParameterError(f"game rules must be a GameRules or a dict, got {type(spec).__name__}")
        unknown = sorted(set(spec) - set(cls.__dataclass_fields__))
        if unknown:
            raise ParameterError(f"unknown game rule(s) {unknown}; known: {sorted(cls.__dataclass_fields__)}")
        return cls(**spec)


@dataclass(frozen=True)
class Decision:
    """The defender's decision of one step, decoded from its action.

    Attributes
    ----------
    audit : bool
        Audit last step's decrypted input.
    sigma_d2 : float
        Variance of the input noise this step.
    rotate : bool
        Move the loop to a fresh group before this step's period.
    verify : bool
        Run the keyed linear check on last step's decrypted input.
    """

    audit: bool = False
    sigma_d2: float = 0.0
    rotate: bool = False
    verify: bool = False


class DefenderLevers(_PlantSidePolicy):
    """The defender seam's adapter for the game: carries out the decision of each step.

    Parameters
    ----------
    rules : GameRules
        Budgets, costs and the detector.
    sigma_u2 : float
        The attacker's input variance: the noise lever's ceiling when ``rules.noise_max`` is None.
    """

    name = "game"

    def __init__(self, rules: GameRules, sigma_u2: float = 1.0) -> None:
        self.rules = rules
        self.noise_max = float(sigma_u2) if rules.noise_max is None else float(rules.noise_max)
        self._decision = Decision()

    # ------------------------------------------------------------- the seam
    def group(self, params: Any) -> Any:
        group = super().group(params)
        self.n, self.m = self.B.shape
        self.horizon = int(params.horizon)
        price = noise_defense_price(self.A, self.B, self.Phi, sigma_w2=self.sigma_w2, sigma_d2=1.0)
        self.unit_noise_price = price["cost_increase"] / price["cost_base"]  # per unit sigma_d2 (linear)
        self.groups: RotationGroups | None = None
        self.pool: GroupPool | None = None  # the episode's (RotationGroups.for_episode)
        if self.rules.rotation and isinstance(group, GroupParams) and group.is_safe_prime:  # as the "rotate" defender
            self.groups = RotationGroups(group.bits, params.crypto_seed, self.rules.rotation_ahead)
            self.pool = self.groups.fixed
        self._verifier: LinearCheckDefender | MacDefender | None = None
        self._no_verifier = ""
        try:  # the linear check on ElGamal, the MAC on Paillier
            self._verifier = verifier_for(params, self.rules.verify_secret_range)
        except ParameterError as exc:  # an output loop, or a Delta too large: the lever is off
            self._verifier, self._no_verifier = None, str(exc)
        return group

    def reset(self, K: int, n: int, m: int, rngs: Sequence[np.random.Generator]) -> None:
        super().reset(K, n, m, rngs)
        self._audit = Audit(self.Phi, 1.0, rngs)  # run only when the defender asks: every asked audit checks
        self.detector = ChiSquaredDetector(
            self.A + self.B @ self.Phi,
            self.sigma_w2 * np.eye(n),
            window=self.rules.window,
            false_alarm_rate=self.rules.false_alarm_rate,
            num_loops=K,
        )
        self._decision = Decision()
        self._noise_prev = np.zeros((K, m))
        self._x_seen: np.ndarray | None = None  # the state at the last observe()
        self.audits = 0  # audits run this episode
        self.rotations = 0  # groups moved to this episode
        self.rotated = False  # the loop moved at the last step
        self.tally = GenerationTally()  # read by the episode's rotation info
        self._next_group = 1
        if self.groups is not None:
            self.pool = self.groups.for_episode(rngs[0])
        if self.pool is not None and self.rules.rotation_ahead:
            self.pool.prefetch(1)
        self.audited = False  # an audit ran at the last step
        self.caught = False
        if self._verifier is not None:
            self._verifier.reset(K, n, m, DefenderStreams(rngs))  # its own streams: the other levers' draws are unchanged
        self.verified = False  # a check ran at the last step
        self.checks = 0  # checks run this episode

    def decide(self, action: Any) -> Decision:
        """Decode the defender's action (one entry per lever of :data:`LEVERS`, in [-1, 1]) as
        the decision of the coming step; returns it."""
        a = as_finite_array("defender action", action).reshape(-1)
        if a.shape != (len(LEVERS),):
            raise ParameterError(f"the defender's action must have shape ({len(LEVERS)},), got {np.shape(action)}")
        if np.any(np.abs(a) > 1.0 + 1e-6):
            raise ParameterError(f"the defender's action must lie in [-1, 1], got {a.tolist()}")
        rotate = self.rules.rotation and bool(a[2] > 0.0)
        if rotate and self.pool is None:
            raise ParameterError("the rotate lever needs a loop on a safe-prime group (a shipped or generated one)")
        if a[3] > 0.0 and self._verifier is None:
            raise ParameterError(f"the verify lever is off for this loop: {self._no_verifier}")
        sigma_d2 = self.noise_max * float(np.clip(a[1], 0.0, 1.0))
        self._decision = Decision(audit=bool(a[0] > 0.0), sigma_d2=sigma_d2, rotate=rotate, verify=bool(a[3] > 0.0))
        return self._decision

    def act(self, view: PlantView) -> DefenderAction | None:
        x_prev, self._x_prev = self._x_prev, np.array(view.state, dtype=float)
        dec = self._decision
        budget = self.rules.audit_budget
        self.audited = dec.audit and x_prev is not None and (budget is None or self.audits < budget)
        self.caught = False
        if self.audited:
            assert x_prev is not None
            tolerance = audit_tolerance(self.Phi, x_prev, self.delta, self.max_shift)
            self.caught = bool(self._audit.check(x_prev, view.last_input, tolerance).any())
            self.audits += 1
        self.verified = dec.verify and x_prev is not None
        if self.verified:
            assert x_prev is not None
            assert self._verifier is not None
            self.caught = self._verifier.caught(x_prev, view.last_input) or self.caught
            self.checks += 1
        noise = None
        if dec.sigma_d2 > 0.0:  # the draws of NoiseDefender
            noise = np.stack([rng.normal(scale=math.sqrt(dec.sigma_d2), size=self.m) for rng in self.rngs[: self.K]])
        self._noise_prev = np.zeros((self.K, self.m)) if noise is None else noise
        group = self._new_group() if self.rotates_at(view.step) else None
        self.rotated = group is not None
        if noise is None and not self.caught and group is None:
            return None
        return DefenderAction(input_noise=noise, end=self.caught, new_group=group)

    def rotates_at(self, step: int) -> bool:
        """Whether the decision of the coming attack step ``step`` moves the loop to a new group:
        it asks for a rotation and the step is not the last (no sample is collected after it)."""
        return self._decision.rotate and step + 1 < self.horizon

    def _new_group(self) -> GroupParams:
        """The next group of the pool (as :class:`~encctl_gym.loop.rotation.RotatingDefender` takes it)."""
        assert self.pool is not None
        group, waited = self.pool.get(self._next_group)
        t = self.tally
        t.groups += 1
        t.indices.append(self._next_group)
        t.seconds += self.pool.seconds[self._next_group]
        t.model_seconds += self.pool.model_seconds
        t.waited += waited
        self._next_group += 1
        self.rotations += 1
        self.on_new_group(group)  # the audit's error bound follows the new group's encoding
        if self._verifier is not None:
            self._verifier.on_new_group(group)  # so does the check's encoding of Phi
        return group

    def close(self) -> None:
        """Stop the group pool's worker."""
        if self.groups is not None:
            self.groups.close()

    # ------------------------------------------------------------- the game's side
    def cost(self) -> float:
        """The defender's cost of the last step: the audit run, the noise applied, the rotation, the check."""
        r = self.rules
        return (
            r.audit_cost * float(self.audited)
            + r.noise_weight * self.unit_noise_price * self._decision.sigma_d2
            + r.rotation_cost * float(self.rotated)
            + r.verify_cost * float(self.verified)
        )

    @property
    def decision(self) -> Decision:
        """The decision of the last (or coming) step."""
        return self._decision

    def observe(self, view: PlantView) -> np.ndarray:
        """What the plant side knows before the coming step, float32 (module docstring):
        ``[x_k, u_{k-1}, S / threshold, audits used / budget, step / horizon]``, length
        ``n + m + 3``. Called once per step (after :meth:`reset`, then after every step): it adds
        the innovation of the last period, ``x_k - (A + B Phi) x_{k-1} - B d_{k-1}``, to the
        detector's window."""
        x = np.array(view.state, dtype=float)
        if self._x_seen is not None:
            self.detector.update(self._x_seen, x - self._noise_prev @ self.B.T)
        self._x_seen = x
        budget = self.rules.audit_budget
        used = 0.0 if budget is None else (1.0 if budget == 0 else self.audits / budget)
        return np.concatenate(
            [
                np.asarray(view.state[0], dtype=float),
                np.asarray(view.last_input[0], dtype=float),
                [float(self.detector.statistic[0]) / self.detector.threshold, used, min(view.step, self.horizon) / self.horizon],
            ]
        ).astype(np.float32)

    def __repr__(self) -> str:
        return f"DefenderLevers({self.rules!r})"
