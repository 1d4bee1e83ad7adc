"""The attack episode, batched over K independent copies.

One implementation serves both :class:`~encctl_gym.envs.EncryptedLTIAttackEnv` (K = 1) and the
native vector environment (K copies stepped at once), so the two have the same semantics by
construction. All copies share the horizon and the delivery schedule, so they run in lockstep:
time indices are plain integers, only the data differ. The per-step arithmetic is in the
compiled kernels of :mod:`encctl_gym.envs._kernels`, whose arithmetic for each copy runs in a
fixed order, so copy ``i`` of a batch computes bit for bit what a single environment seeded the
same way computes; the rare exact re-solves (batched LAPACK) are per matrix too.

Per sampling period ``k`` of the attack (Definition def:adversary):

1. the plant's state ciphertext ``ct_x_k`` is collected and paid for (``2^lambda / Upsilon``
   seconds, Definition def:sdt, when the scheme gives every sample its own key);
2. samples whose delay has passed are delivered: state ``x_j`` with the input ``u_{j-1}``;
   each delivered state adds the regression column ``([x_{j-1}; u_{j-1}], x_j)`` of eq:data
   to the attacker's estimator (least squares: recursive, by Sherman-Morrison, re-anchored to
   the exact solve of eq:estimate from the running Gram matrices every ``schedule.refresh``
   columns and at the end);
3. the defender (:mod:`encctl_gym.loop.defender`) decides on what the plant side knows: noise
   ``v_k`` on the input it applies, or the end of the attack (the default does neither);
4. the agent acts; its input is held to the energy budget, forged into the input ciphertext,
   decrypted by the plant (``u_k``) and applied: ``x_{k+1} = A x_k + B (u_k + v_k) + w_k``.

How a step runs is chosen once, when the episode is built (:mod:`encctl_gym.envs.steps`): the
backend called period by period; the period in one compiled call when the backend exposes its
arithmetic (:attr:`~encctl_gym.loop.backend.LoopBackend.quantization`, the ideal backend); and,
when the reward and the estimator have compiled forms too (a ``fused`` reward; an estimator
whose :meth:`online_kernels` are fused, :mod:`encctl_gym.ident.compiled`), the steady state in
one compiled call per step. An estimator without kernels is updated column by column.

Work that no step waits for can run on a :class:`~encctl_gym.envs.helper.HelperThread` (the
compiled kernels release the GIL): drawing the next ``schedule.chunk`` periods of noise, and
bringing the Gram matrices up to date, which the steady-state step leaves behind and only the
exact refresh needs. It changes where that work runs, not what it computes: the numbers are the
same with or without it (tested).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from concurrent.futures import Future
from typing import Any

import numpy as np

from .._validation import as_finite_array, check_int, format_value
from ..errors import EncodingOverflowError, ParameterError, ShapeError
from ..ident.compiled import OnlineKernels, ProvidesKernels
from ..ident.registry import make_estimator
from ..loop import LoopBackend
from ..loop.assembly import defender_for
from ..loop.defender import DefenderPolicy, DefenderStreams, PlantView, check_defender_action, make_defender
from ..loop.injection import injection_code
from ..loop.provisioning import RotationRecord
from ..loop.rotation import move_loop, rotation_info
from . import _kernels as kern
from .config import AttackParams
from .episode_work import HelperWork
from .helper import HelperThread
from .layout import ObservationLayout, info_dict
from .rewards import REWARDS
from .schedule import EpisodeSchedule, check_episode_memory
from .steps import EpisodeArrays, KernelConstants, StepStrategy, choose_step

__all__ = ["EpisodeCore", "attack_design_for"]


def attack_design_for(p: AttackParams) -> Any:
    """The optimal attack design behind ``info["gamma_opt"]`` (security.attack_design): closed
    loop when states are delivered in time (``decipher_delay = 0``), open loop otherwise."""
    from ..security.attack_design import optimal_attack_design

    return optimal_attack_design(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2, feedback=p.decipher_delay == 0)


class EpisodeCore(HelperWork):
    """State and dynamics of K attack episodes stepped in lockstep.

    Parameters
    ----------
    params : AttackParams
        Resolved environment parameters.
    loop : LoopBackend
        Closed-loop backend (:mod:`encctl_gym.loop`).
    design : AttackDesign or None
        Source of ``gamma_opt`` in the info.
    num_envs : int
        K.
    parallel : bool
        Spread the copies of a steady-state step over the cores (same numbers).
    helper : HelperThread or None
        Draw the next chunk of noise and catch up the Gram matrices on this thread while the
        copies are stepped (same numbers: the same work in the same order, only elsewhere).
    schedule : EpisodeSchedule, optional
        Batching of the work (default :class:`EpisodeSchedule`).
    memory_limit : int, optional
        Refuse, before allocating anything, an episode whose :func:`episode_bytes` exceed this
        many bytes (default :data:`encctl_gym.resources.MEMORY_LIMIT`).
    defender : DefenderPolicy, optional
        The plant side's policy (:mod:`encctl_gym.loop.defender`), called before every attack
        step; default: the one ``params.defender`` names (the fixed defender unless configured).

    Public state (for training, evaluation and tests; privileged where it involves the true
    plant or undelivered data): :attr:`done`, :attr:`collected`, :attr:`delivered`,
    :attr:`eps` (the error of every copy's current estimate, a function of the true ``(A, B)``),
    :meth:`delivered_data` (what the attacker has deciphered and received, float64).

    Randomness: the noise of chunk ``c + 1`` is drawn from every copy's generator as soon as
    chunk ``c`` is taken into use, if the episode reaches it, with or without the helper thread;
    so the draws, and hence the numbers, are the same either way.
    """

    def __init__(
        self,
        params: AttackParams,
        loop: LoopBackend,
        design: Any = None,
        num_envs: int = 1,
        *,
        parallel: bool = False,
        helper: HelperThread | None = None,
        schedule: EpisodeSchedule | None = None,
        memory_limit: int | None = None,
        defender: DefenderPolicy | None = None,
    ) -> None:
        p = self.p = params
        self.loop = loop
        self.K = K = check_int("num_envs", num_envs, minimum=1)
        if K > 1 and not loop.batched:
            raise ParameterError(f"the {p.crypto} backend steps one copy, got num_envs = {K}")
        self.schedule = sch = schedule if schedule is not None else EpisodeSchedule()
        check_episode_memory(p, K, sch, memory_limit)
        n, m, N = p.n, p.m, p.horizon
        self.n, self.m, self.d = n, m, n + m
        self.layout = ObservationLayout.of(p)
        self._A = np.ascontiguousarray(p.A)
        self._B = np.ascontiguousarray(p.B)
        self._theta_true = np.hstack([p.A, p.B])  # (n, n+m)
        self._c = n * (n + m)  # Definition def:error
        self._eps0 = float(np.sum(self._theta_true**2)) / self._c  # error of the estimate [A B] = 0
        self._sw = math.sqrt(p.sigma_w2)
        self._sx = math.sqrt(p.sigma_x2)
        self._build_tables(design)
        # the per-copy arrays the kernels write, by name (steps.EpisodeArrays): collected
        # (deciphered) states X and applied inputs U, time-major (the data of all copies for one
        # period are contiguous); the recursive least squares [P | Theta_hat^T] in Q, P by its
        # upper triangle, copies innermost: entry (a, b) of every copy is row a (d + n) + b
        s = self.state = EpisodeArrays.allocate(K, n, m, N, p.input_history)
        self.X, self.U, self.Q, self.eps = s.X, s.U, s.Q, s.eps
        s.eps[:] = self._eps0
        # regressor Gram matrix G of the delivered data and cross term C = sum z x_next^T, kept
        # as [G | C] with the copies innermost (see _kernels); G and C are views of it, (K, d, .)
        self._GC = np.zeros((self.d * (self.d + n), K))
        self.G, self.C = self._gram_views()
        self._gram_scratch = np.zeros((self.d + n, K))  # add_gram's, apart from the step's (the helper runs it)
        self.gram_upto = 1  # G and C hold the columns j < gram_upto (the fused step lets them lag)
        self.dims = kern.dims(n, m, p.input_history * m)  # the sizes, as the kernels take them
        self.reward = REWARDS[p.reward](p, K)
        self._build_estimator(sch)
        self.collected = 0  # samples collected and paid for
        self.expired = False  # out of time: the measured deciphering time passed tau_c, or end_out_of_time()
        self.delivered = 0  # samples delivered to the agent
        self.new = False
        self.done = False
        self.obs_out: np.ndarray | None = None  # observation written by the fused step, not yet handed out
        self._act = np.zeros((K, m))  # the actions of the current step, float64
        self.obs_shape = (K, self.layout.dim)
        self.obs_at = self.layout.offsets
        self.consts = KernelConstants(
            self._A, self._B, np.ascontiguousarray(self._theta_true.T), float(self._c), p.u_max, p.energy_budget
        )
        # what the compiled kernels take (see _kernels): built once, the arrays are never rebound
        self.kernel_consts, self.kernel_arrays = self.consts.kernel_tuple(), s.kernel_tuple()
        # how a step runs, chosen once: the ideal backend's steady state is one compiled call
        q = loop.quantization
        fused = q is not None and self.reward.fused and self.kernels is not None and self.kernels.fused
        self.input_history = p.input_history
        #: the episode's injection mode (:mod:`encctl_gym.loop.injection`), as the steps take it
        self.injection = injection_code(p.injection)
        self.stepper: StepStrategy = choose_step(self, q, fused, parallel, self.injection)
        # the other party: the plant side's decisions, each step, on what the plant knows
        self.defender = defender_for(p.loop) if defender is None else make_defender(defender)
        self._rotates = bool(self.defender.rotates)  # the info carries the rotation fields
        self.plant_view = PlantView(s.x, s.U, self._attack_step)
        self.stopped = False  # the defender ended the attack
        #: the group rotations of the episode (loop.rotation): every episode starts on the loop's first group
        self.rotation = RotationRecord()
        self._first_group = getattr(loop, "group", None)
        self._build_noise(sch, helper)
        self._rngs: list[np.random.Generator] = []
        self.history: list[tuple[int, float]] = []  # (N delivered, epsilon) of copy 0, for render

    def _build_tables(self, design: Any) -> None:
        """The tables over the sample size N = 0..horizon: gamma (eq:sic), gamma_opt of the
        design, the deciphering time (Definition def:sdt) and their Python-float copies."""
        p, N = self.p, self.p.horizon
        Ns = np.arange(N + 1)
        self.gamma_table = np.full(N + 1, np.inf)
        self.gamma_table[2:] = p.gamma(Ns[2:])  # eq:sic
        self.has_gamma_opt = design is not None
        self.gamma_opt_table = np.full(N + 1, np.inf)
        if design is not None:
            self.gamma_opt_table[2:] = design.gamma(Ns[2:])
        # Definition def:sdt, under the model; with the measured clock, filled as the keys are broken
        self._measured = p.deciphering_clock == "measured"
        self.time_table = np.zeros(N + 1) if self._measured else np.asarray(p.deciphering_time(Ns), dtype=np.float64)
        self.time_frac = self.time_table / p.tau_c
        # the same tables as Python floats, for the per-step info scalars
        self._gamma_list, self._time_list = self.gamma_table.tolist(), self.time_table.tolist()
        self._gamma_opt_list = self.gamma_opt_table.tolist()

    def _build_estimator(self, sch: EpisodeSchedule) -> None:
        """The attacker's estimator: compiled kernels on the episode's arrays when it provides
        them, else the estimator itself (updated column by column)."""
        p, s, K = self.p, self.state, self.K
        # the attacker's estimator: one that provides kernels (least squares, fused; Bayes,
        # forgetting, IV: moment kernels) runs compiled on the episode's arrays; any other is
        # updated column by column (encctl_gym.ident)
        est = make_estimator(p.estimator)
        self.kernels: OnlineKernels | None = (
            est.online_kernels(K, self._A, self._B, s.Q, sch.refresh, sch.cond_limit)
            if isinstance(est, ProvidesKernels)
            else None
        )
        self.estimator = est if self.kernels is None else None

    def _build_noise(self, sch: EpisodeSchedule, helper: HelperThread | None) -> None:
        """The process-noise chunks (drawn ahead, with or without the helper thread)."""
        p, K, n = self.p, self.K, self.n
        C = sch.chunk
        self._noise_draws = np.zeros((K, C, n))  # each copy's chunk, as its generator draws it
        self._noise = np.zeros((C, K, n))  # period-major, like X: one period's noise is contiguous
        self._noise_next = np.zeros((C, K, n))  # the chunk drawn ahead
        self._noise_pos = C
        self._noise_ahead = False  # _noise_next holds (or is being filled with) the next chunk
        self._chunks = 0  # chunks taken into use this episode
        self._periods = p.warmup_steps + p.horizon  # noise samples an episode uses
        self._given_noise: np.ndarray | None = None  # (K, periods, n) from reset(noise=...)
        self.helper = helper
        self._noise_future: Future | None = None
        self._gram_future: Future | None = None

    def end_out_of_time(self) -> None:
        """End the attack at the next step as out of time (``terminated``, not detected): for a
        caller that keeps its own deciphering clock, e.g. the game's per-group clock
        (:mod:`encctl_gym.multiagent.clock`). A reset clears it."""
        self.expired = True

    def close(self) -> None:
        """The helper's work finished, and the defender's own resources released (its optional
        ``close``, e.g. the rotating defender's group pool)."""
        self.wait()
        self.defender.close()

    def _gram_views(self) -> tuple[np.ndarray, np.ndarray]:
        """G and C as views of ``[G | C]`` (``_GC``), shape (K, d, d) and (K, d, n)."""
        gc = self._GC.reshape(self.d, self.d + self.n, self.K).transpose(2, 0, 1)
        return gc[:, :, : self.d], gc[:, :, self.d :]

    def __getstate__(self) -> dict[str, Any]:
        """Pickling and deep copies see the helper's work finished (a future cannot be copied).
        The views G and C are left out: a copy would make them arrays of their own, which the
        kernels (writing ``_GC``) no longer update; :meth:`__setstate__` makes them again."""
        self.wait()
        state = self.__dict__.copy()
        del state["G"], state["C"]
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self.G, self.C = self._gram_views()

    # ----------------------------------------------------------------- reset
    def _given(self, name: str, value: Any, shape: tuple[int, ...]) -> np.ndarray:
        """A user-given array (``x0`` or ``noise``) of shape ``shape``, or ``shape[1:]`` for K = 1."""
        arr = as_finite_array(name, value)
        if self.K == 1 and arr.shape == shape[1:]:
            arr = arr[None]
        if arr.shape != shape:
            want = shape[1:] if self.K == 1 else shape
            raise ShapeError(f"{name} must have shape {want}, got {arr.shape}")
        return np.array(arr, dtype=np.float64)

    def reset(self, rng: np.random.Generator | Sequence[np.random.Generator], *, x0: Any = None, noise: Any = None) -> np.ndarray:
        """Start new episodes for all copies; return the observations, shape (K, obs_dim).

        ``rng`` is one generator (K = 1) or one per copy; all draws of copy ``i`` come from
        ``rng[i]`` in a fixed order (x_0, then the noise of every period).

        Parameters
        ----------
        x0 : array_like, shape (K, n) (or (n,) for K = 1), optional
            The initial states instead of draws from ``N(0, sigma_x2 I)``.
        noise : array_like, shape (K, T, n) (or (T, n) for K = 1), optional
            The process noise ``w_0 .. w_{T-1}`` of the episode (warm-up periods first), instead
            of draws from ``N(0, sigma_w2 I)``; ``T = warmup_steps + horizon``. Replaying the
            same disturbance for two attackers gives paired comparisons (common random numbers).
        """
        rngs = [rng] if isinstance(rng, np.random.Generator) else list(rng)
        if len(rngs) != self.K:
            raise ParameterError(f"expected {self.K} random generators, got {len(rngs)}")
        x0_arr = None if x0 is None else self._given("x0", x0, (self.K, self.n))
        given = None if noise is None else self._given("noise", noise, (self.K, self._periods, self.n))
        self.wait()  # the helper may still be drawing from the old generators or adding to G
        self._rngs = rngs
        self._given_noise = given
        self.obs_out = None
        for i, g in enumerate(rngs):
            draw = g.standard_normal(self.n) * self._sx
            self.state.x[i] = draw if x0_arr is None else x0_arr[i]
        self._noise_pos = self.schedule.chunk
        self._noise_ahead = False
        self._chunks = 0
        if getattr(self.loop, "group", None) is not self._first_group:  # back to the first group (rotation)
            move_loop(self.loop, self.stepper, self._first_group)
        self.rotation = RotationRecord()
        self.loop.start_episode()
        for _ in range(self.p.warmup_steps):  # normal operation under the encrypted controller (eq:ec)
            kern.plant_step(self.dims, self.state.x, self.loop.control(self.state.x), self._draw_noise(), self._A, self._B)
        self.X[:] = 0.0
        self.U[:] = 0.0
        self._GC[:] = 0.0
        self.gram_upto = 1
        if self.kernels is not None:
            self.kernels.reset()
        self.state.hist[:] = 0.0
        self.state.energy[:] = 0.0
        self.eps[:] = self._eps0
        if self.estimator is not None:
            self.estimator.start(self.K, self.n, self.m)
        self.reward.reset(self)
        self.collected = self.delivered = 0
        self.expired = False
        self.stopped = False
        self.done = False
        self.history = []
        self.defender.reset(self.K, self.n, self.m, DefenderStreams(rngs))
        self.collect_next()
        self.new = self._deliver(final=False)
        return self.observation()

    # ----------------------------------------------------------------- data
    def delivered_data(self) -> tuple[np.ndarray, np.ndarray]:
        """What the attacker has deciphered and received so far, in float64.

        Returns
        -------
        states : numpy.ndarray, shape (K, N, n)
            The delivered states ``x_0 .. x_{N-1}`` (``N`` = :attr:`delivered`).
        inputs : numpy.ndarray, shape (K, max(N - 1, 0), m)
            The inputs ``u_0 .. u_{N-2}`` that led to them (the attacker's own, as the plant
            decoded them): with the states, the data matrices of eq:data.
        """
        N = self.delivered
        return self.X[:N].transpose(1, 0, 2).copy(), self.U[: max(N - 1, 0)].transpose(1, 0, 2).copy()

    # ----------------------------------------------------------------- step
    def collect_next(self) -> None:
        """Collect and pay for the state ciphertext of the current period.

        With the measured clock the time paid is what the breaker took so far this episode; a
        sample whose break ends past ``tau_c`` came too late: it is not counted, and the episode
        has :attr:`expired`.
        """
        self.X[self.collected] = self.loop.collect_state(self.state.x)
        if self._measured:
            spent = self.loop.deciphering_seconds
            if spent > self.p.tau_c:
                self.expired = True
                return
            self.time_table[self.collected + 1] = spent
            self.time_frac[self.collected + 1] = spent / self.p.tau_c
            self._time_list[self.collected + 1] = spent
        self.collected += 1

    def raise_overflow(self) -> None:
        raise EncodingOverflowError(
            f"state {self.state.x.tolist()} leaves the encoder's declared range |x| <= {self.p.x_bound} (x_bound)"
        )

    def target_of(self, collected: int) -> int:
        """Number of samples delivered once ``collected`` are paid for (before the end)."""
        delay = self.p.decipher_delay
        if delay is None:  # "end": nothing before the attack ends
            return 0
        return max(collected - delay, 0)

    def _deliver(self, final: bool) -> bool:
        """Deliver paid samples whose delay has passed; update the estimate and its error."""
        target = self.collected if final else self.target_of(self.collected)
        if target <= self.delivered:
            return False
        first = max(self.delivered, 1)
        kernels = self.kernels
        if (
            kernels is not None
            and kernels.all_ready
            and not final
            and not self.reward.needs_gram
            and kernels.since_refresh + target - first < kernels.refresh
        ):  # steady state: columns, the compiled estimate and its error
            self._sync_gram(first)
            kernels.add_columns(self.dims, self.X, self.U, first, target, self._GC)
            self.gram_upto = target
            kernels.steady_error(self.dims, self.eps)
            kernels.since_refresh += target - first
            self.delivered = target
            self.history.append((target, float(self.eps[0])))
            return True
        self._sync_gram(first)
        if target > first:
            if kernels is not None:
                kernels.add_columns(self.dims, self.X, self.U, first, target, self._GC)
            else:  # the Gram matrices alone (the rewards read them), as the columns would add them
                kern.add_gram(self.dims, self.X, self.U, first, target, self._GC, self._gram_scratch)
            self.gram_upto = target
        self.delivered = target
        if self.estimator is not None:
            self._estimate(first, target)
        self.reward.on_delivery(self)
        if kernels is not None:
            kernels.settle(self.dims, self.G, self.C, target - first, self.delivered, final, self.eps)
        self.history.append((self.delivered, float(self.eps[0])))
        return True

    def _estimate(self, first: int, target: int) -> None:
        """The configured (not least-squares) estimator takes the columns ``first <= j < target``;
        epsilon is the error of its estimate once it has one (and where it is defined: the
        instruments of ``iv`` can still be singular), that of the previous estimate before."""
        est = self.estimator
        assert est is not None
        for j in range(first, target):
            est.update(np.concatenate([self.X[j - 1], self.U[j - 1]], axis=1), self.X[j])
        if est.ready:
            err = est.error(self.p.A, self.p.B)
            if np.isinf(err).any():  # NaN: no estimate yet (kept stale); inf: an estimate whose error overflowed
                from ..errors import SolverError

                raise SolverError(
                    f"the {getattr(est, 'label', type(est).__name__)} estimator's error overflowed float64 (epsilon = inf) after {target} samples "
                    f"(copy {int(np.argmax(np.isinf(err)))}): its estimate is too far from any plant to measure"
                )
            ok = np.isfinite(err)
            self.eps[ok] = err[ok]

    def check_actions(self, action: Any) -> np.ndarray:
        """Validate actions: shape (K, m) (or (m,) for K = 1), finite, inside [-1, 1]. Returns
        them in float64, in a buffer of the episode's own (the caller's array is never changed)."""
        a = action
        if not (isinstance(a, np.ndarray) and a.dtype.char in "fd"):  # float32 and float64 are read as they are
            try:
                a = np.asarray(a)
                if a.dtype.kind not in "iuf":  # booleans, complex numbers, strings and objects are refused
                    raise TypeError(a.dtype)
                a = a.astype(np.float64)
            except (TypeError, ValueError, OverflowError):
                raise ParameterError(f"action must be a real numeric array, got {format_value(action)}") from None
        if a.ndim < 2:
            a = a.reshape(1, -1)
        if a.shape != (self.K, self.m):
            want = (self.m,) if self.K == 1 else (self.K, self.m)
            raise ParameterError(f"action must have shape {want}, got {np.shape(action)}")
        code = kern.load_actions(a, self._act)
        if code:
            what = "finite" if code == 1 else "inside the action space [-1, 1]"
            raise ParameterError(f"action must be {what}, got {np.asarray(action).tolist()}")
        return self._act

    def step(self, action: Any, *, injection: str | None = None) -> tuple[np.ndarray, bool, bool]:
        """Apply the actions of all copies. Returns (rewards (K,), terminated, truncated).

        ``injection`` (every copy at once): this step's mode of :data:`~encctl_gym.loop.injection.INJECTIONS`
        instead of the episode's (``params.injection``); the game passes ``"pass"`` for a step in
        which the attacker injects nothing: the plant applies the encrypted controller's own input
        ``u_k = Phi x_k`` (eq:ec), ``action`` is still checked but unused, no energy is spent, and
        the regression column is closed-loop data (``u`` a function of ``x``).
        """
        if not self._rngs:
            raise ParameterError("step() called before reset(); call reset() first")
        if self.done:
            raise ParameterError("step() called after the episode ended; call reset() first")
        mode = self.injection if injection is None else injection_code(injection)
        act = self.check_actions(action)
        w = self._draw_noise()
        ended = self.collected >= self.p.horizon or self.expired
        decision = self.defender.act(self.plant_view)
        if decision is not None:
            noise, stop = check_defender_action(decision, self.K, self.m)
            if noise is not None:  # u + v applied, u recorded: to the attacker, process noise B v
                w = w + noise @ self.consts.B.T
            if stop:
                self.stopped = ended = True
            if decision.new_group is not None:  # group rotation: the period runs in the new group
                group = self.p.loop.encryption().check_fresh(decision.new_group, getattr(self.loop, "group", None))
                self.rotation.add(move_loop(self.loop, self.stepper, group))
        return self.stepper.step(act, w, ended, mode)

    def _attack_step(self) -> int:
        """The attack step about to run (0 at the first): its input goes to ``U[collected - 1]``."""
        return self.collected - 1

    def finish_step(self, ended: bool) -> tuple[np.ndarray, bool, bool]:
        """What follows the period of a step on every path: the delivery (all paid samples if
        the attack has ``ended``), the estimate and the reward. Returns (rewards (K,),
        terminated, truncated)."""
        self.reward.begin(self)
        self.new = self._deliver(final=ended)
        reward = self.reward.end(self)
        self.done = ended
        out_of_time = self.p.budget_limited or self.expired or self.stopped
        return reward, ended and out_of_time, ended and not out_of_time

    # ----------------------------------------------------------------- observation and info
    def observation(self) -> np.ndarray:
        """Observations of all copies, shape (K, obs_dim), float32 (layout:
        :class:`~encctl_gym.envs.layout.ObservationLayout`), in a new array: the one the fused
        step wrote, if not yet handed out, else filled now."""
        obs, self.obs_out = self.obs_out, None
        if obs is None:
            obs = np.empty(self.obs_shape, dtype=np.float32)
            kern.fill_observation(
                self.dims,
                obs,
                self.obs_at,
                self.X,
                self.U,
                self.delivered - 1,
                float(self.new),
                self.state.hist,
                float(self.time_frac[self.collected]),
                self.state.energy,
                self.consts.budget,
            )
        return obs

    def _shared_info(self) -> tuple[float, float, float, float, int, int]:
        """The info entries all copies share (:func:`~encctl_gym.envs.layout.info_dict`)."""
        collected, N = self.collected, self.delivered
        return (
            self._gamma_list[N],
            self._time_list[collected],
            float(max(collected, 1) * self.m),
            self._gamma_opt_list[N],
            collected,
            N,
        )

    def info_arrays(self) -> dict[str, np.ndarray]:
        """Info of every copy as new arrays of shape (K,) (:func:`~encctl_gym.envs.layout.info_dict`)."""
        info = info_dict(self.eps.copy(), self.state.energy.copy(), self._shared_info(), self.has_gamma_opt, self.K, self.stopped)
        if self._rotates or self.rotation.rotations:
            for key, value in self._rotation_info().items():
                info[key] = np.full(self.K, value)
        return info

    def _rotation_info(self) -> dict[str, Any]:
        return rotation_info(self.rotation, self.defender, self.loop, self.p.breaker is not None)

    def info(self) -> dict[str, Any]:
        """Info of copy 0 as Python scalars (single environment).

        ``epsilon`` is the error (Definition def:error) of the attacker's current estimate: the
        least squares estimate once ``n + m`` columns are delivered, ``[A B] = 0`` before.
        """
        info = info_dict(
            float(self.eps[0]), float(self.state.energy[0]), self._shared_info(), self.has_gamma_opt, detected=self.stopped
        )
        if self._rotates or self.rotation.rotations:  # the rotation fields (none otherwise: no cost per step)
            info.update(self._rotation_info())
        return info
