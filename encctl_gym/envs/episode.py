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
   to recursive least squares (Sherman-Morrison), which is re-anchored to the exact solve of
   eq:estimate from the running Gram matrices every ``_REFRESH`` columns and at the end;
3. the agent acts; its input is held to the energy budget, forged into the input ciphertext,
   decrypted by the plant (``u_k``) and applied: ``x_{k+1} = A x_k + B u_k + w_k``.

Work that no step waits for can run on a helper thread (one per process, shared; the compiled
kernels release the GIL): drawing the next ``_CHUNK`` periods of noise, and bringing the Gram
matrices up to date, which the steady-state step leaves behind and only the exact refresh
needs. It changes where that work runs, not what it computes: the numbers are the same with
or without it (tested).
"""

from __future__ import annotations

import math
import os
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, Callable, Sequence

import numpy as np

from ..errors import EncodingOverflowError, ParameterError
from . import _kernels as kern
from .config import AttackParams

__all__ = ["EpisodeCore", "attack_design_for"]

#: noise is drawn from each copy's generator in chunks of this many periods
_CHUNK = 256
#: every copy's recursive least squares is re-anchored to the exact solve after this many columns
_REFRESH = 1024
#: a copy starts its recursion once the condition number of its scaled Gram matrix is below this
_COND_LIMIT = 1e8
#: with a helper thread, the Gram catch-up is handed over once it lags this many columns
_GRAM_BATCH = 64

_helper_pool: ThreadPoolExecutor | None = None


def _helper() -> ThreadPoolExecutor:
    """The process's helper thread: one worker, shared by every episode, started on first use."""
    global _helper_pool
    if _helper_pool is None:
        _helper_pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="encctl-gym-helper")
    return _helper_pool


def _forget_helper() -> None:
    """After a fork the child holds the pool but not its thread: start a new one on next use."""
    global _helper_pool
    _helper_pool = None


os.register_at_fork(after_in_child=_forget_helper)


def _condition(Gs: np.ndarray) -> np.ndarray:
    """2-norm condition numbers of symmetric positive semidefinite matrices (..., d, d), from
    their eigenvalues (``inf`` where singular)."""
    lam = np.linalg.eigvalsh(Gs)
    lo, hi = lam[..., 0], lam[..., -1]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(lo > 0.0, hi / np.where(lo > 0.0, lo, 1.0), np.inf)


def _pinv_psd(G: np.ndarray) -> np.ndarray:
    """Moore-Penrose pseudo-inverses of symmetric positive semidefinite matrices (..., d, d),
    from their eigendecompositions; eigenvalues below ``d * eps * max`` count as zero (NumPy's
    default cut-off for ``pinv``)."""
    lam, V = np.linalg.eigh(G)
    keep = lam > G.shape[-1] * np.finfo(float).eps * lam[..., -1:]
    inv = np.where(keep, 1.0 / np.where(keep, lam, 1.0), 0.0)
    return (V * inv[..., None, :]) @ np.swapaxes(V, -1, -2)


def attack_design_for(p: AttackParams) -> Any:
    """The optimal attack design behind ``info["gamma_opt"]`` (security.attack_design): closed
    loop when states are delivered in time (``decipher_delay = 0``), open loop otherwise."""
    from ..security.attack_design import optimal_attack_design

    return optimal_attack_design(p.A, p.B, sigma_u2=p.sigma_u2, sigma_w2=p.sigma_w2, feedback=p.decipher_delay == 0)


class EpisodeCore:
    """State and dynamics of K attack episodes stepped in lockstep.

    Parameters
    ----------
    params : AttackParams
        Resolved environment parameters.
    loop : object
        Closed-loop backend (:mod:`encctl_gym.loop`) with ``start_episode``, ``control``,
        ``collect_state``, ``inject`` and ``tick``.
    design : AttackDesign or None
        Source of ``gamma_opt`` in the info.
    num_envs : int
        K.
    parallel : bool
        Spread the copies of a steady-state step over the cores (same numbers).
    helper_thread : bool
        Draw the next chunk of noise and catch up the Gram matrices on a helper thread while
        the copies are stepped (same numbers: the same work in the same order, only elsewhere).

    Randomness: the noise of chunk ``c + 1`` (``_CHUNK`` periods) is drawn from every copy's
    generator as soon as chunk ``c`` is taken into use, if the episode reaches it, with or
    without the helper thread; so the draws, and hence the numbers, are the same either way.
    """

    def __init__(
        self,
        params: AttackParams,
        loop: Any,
        design: Any = None,
        num_envs: int = 1,
        parallel: bool = False,
        helper_thread: bool = False,
    ) -> None:
        p = self.p = params
        self.loop = loop
        self.K = K = int(num_envs)
        n, m, N = p.n, p.m, p.horizon
        self.n, self.m, self.d = n, m, n + m
        self._A = np.ascontiguousarray(p.A)
        self._B = np.ascontiguousarray(p.B)
        self._theta_true = np.hstack([p.A, p.B])  # (n, n+m)
        self._c = n * (n + m)  # Definition def:error
        self._eps0 = float(np.sum(self._theta_true**2)) / self._c  # error of the estimate [A B] = 0
        self._sw = math.sqrt(p.sigma_w2)
        self._sx = math.sqrt(p.sigma_x2)
        self._logdet0 = self.d * math.log(p.logdet_regularization)
        self._reg = p.logdet_regularization * np.eye(self.d)
        # tables over the sample size N = 0..horizon
        Ns = np.arange(N + 1)
        self.gamma_table = np.full(N + 1, np.inf)
        self.gamma_table[2:] = p.gamma(Ns[2:])  # eq:sic
        self.has_gamma_opt = design is not None
        self.gamma_opt_table = np.full(N + 1, np.inf)
        if design is not None:
            self.gamma_opt_table[2:] = design.gamma(Ns[2:])
        keys = Ns if p.independent_keys else np.minimum(Ns, 1)
        self.time_table = keys * p.sample_cost  # Definition def:sdt
        self._time_frac = self.time_table / p.tau_c
        # per-copy data: collected (deciphered) states and applied inputs
        # time-major: the data of all copies for one period are contiguous
        self.X = np.zeros((N, K, n))  # collected (deciphered) states x_0 .. x_{N-1}
        self.U = np.zeros((N, K, m))  # applied inputs u_0 .. u_{N-1}
        # regressor Gram matrix G of the delivered data and cross term C = sum z x_next^T, kept
        # as [G | C] with the copies innermost (see _kernels); G and C are views of it, (K, d, .)
        self._GC = np.zeros((self.d * (self.d + n), K))
        gc = self._GC.reshape(self.d, self.d + n, K).transpose(2, 0, 1)
        self.G, self.C = gc[:, :, : self.d], gc[:, :, self.d :]
        self._gram_scratch = np.zeros((self.d + n, K))  # add_gram's, apart from the step's (the helper runs it)
        # recursive least squares [P | Theta_hat^T], P by its upper triangle; copies innermost:
        # entry (a, b) of every copy is row a (d + n) + b (see _kernels)
        self.Q = np.zeros((self.d * (self.d + n), K))
        self._rls_scratch = np.zeros((2 * self.d + n + 2, K))
        self.ready = np.zeros(K, dtype=bool)  # recursion started (well-conditioned Gram matrix)
        self._gram_upto = 1  # G and C hold the columns j < _gram_upto (the fused step lets them lag)
        self._since_refresh = 0
        self.x = np.zeros((K, n))
        self.hist = np.zeros((K, p.input_history * m))
        self._dims = kern.dims(n, m, p.input_history * m)  # the sizes, as the kernels take them
        self.energy = np.zeros(K)
        self.eps = np.full(K, self._eps0)
        self.logdet = np.full(K, self._logdet0)
        self.collected = 0  # samples collected and paid for
        self.delivered = 0  # samples delivered to the agent
        self.new = False
        self.done = False
        self._obs_out: np.ndarray | None = None  # observation written by the fused step, not yet handed out
        self._info_out: tuple[np.ndarray, np.ndarray] | None = None  # and the info arrays (two buffers), likewise
        self._info_in_step = K > 1
        self._info_unread = (*self._info_buffers(), 0.0, 0.0, 1.0, 0.0, 0, 0)
        self._act = np.zeros((K, m))  # the actions of the current step, float64
        self._obs_shape = (K, p.obs_dim)
        self._a = np.zeros((K, m))
        self._qa = np.zeros((K, m), dtype=np.int64)
        self._qx = np.zeros((K, n), dtype=np.int64)
        self._theta_true_T = np.ascontiguousarray(self._theta_true.T)
        self._cf = float(self._c)
        self._horizon = p.horizon
        self._reward = np.zeros(K)
        self._step_fused = kern.step_fused_parallel if parallel else kern.step_fused
        self._u_max = p.u_max
        self._budget = p.energy_budget
        self._logdet = p.reward == "logdet"
        self._all_ready = False
        # the ideal backend's step is one fused compiled call
        self._fused = getattr(loop, "fused_parameters", None)
        self._noise_draws = np.zeros((K, _CHUNK, n))  # each copy's chunk, as its generator draws it
        self._noise = np.zeros((_CHUNK, K, n))  # period-major, like X: one period's noise is contiguous
        self._noise_next = np.zeros((_CHUNK, K, n))  # the chunk drawn ahead
        self._noise_pos = _CHUNK
        self._noise_ahead = False  # _noise_next holds (or is being filled with) the next chunk
        self._chunks = 0  # chunks taken into use this episode
        self._periods = p.warmup_steps + p.horizon  # noise samples an episode uses
        self._use_helper = bool(helper_thread)
        self._noise_future: Future | None = None
        self._gram_future: Future | None = None
        self._rngs: list[np.random.Generator] = []
        self.history: list[tuple[int, float]] = []  # (N delivered, epsilon) of copy 0, for render

    # ----------------------------------------------------------------- helper thread
    def _run(self, fn: Callable[..., Any], *args: Any) -> Future | None:
        """``fn(*args)`` on the helper thread (returns its future) or, without one, now."""
        if self._use_helper:
            return _helper().submit(fn, *args)
        fn(*args)
        return None

    def _wait_noise(self) -> None:
        if self._noise_future is not None:
            future, self._noise_future = self._noise_future, None
            future.result()  # re-raises what the helper raised

    def _wait_gram(self) -> None:
        if self._gram_future is not None:
            future, self._gram_future = self._gram_future, None
            future.result()

    def wait(self) -> None:
        """Wait for the helper thread's work on this episode (noise drawn ahead, Gram catch-up)."""
        self._wait_noise()
        self._wait_gram()

    def __getstate__(self) -> dict[str, Any]:
        """Pickling and deep copies see the helper's work finished (a future cannot be copied)."""
        self.wait()
        return self.__dict__.copy()

    # ----------------------------------------------------------------- randomness
    def _fill_noise(self, dst: np.ndarray) -> None:
        """Draw the next ``_CHUNK`` periods of noise of every copy, into ``dst`` (C, K, n)."""
        for i, rng in enumerate(self._rngs):
            rng.standard_normal(out=self._noise_draws[i])
        kern.interleave_noise(self._noise_draws, self._sw, dst)

    def _take_chunk(self) -> None:
        """Take the next noise chunk into use (the one drawn ahead, else draw it now), then draw
        the one after it ahead if the episode will reach it."""
        if self._noise_ahead:
            self._wait_noise()
            self._noise, self._noise_next = self._noise_next, self._noise
        else:
            self._fill_noise(self._noise)
        self._chunks += 1
        self._noise_pos = 0
        self._noise_ahead = self._chunks * _CHUNK < self._periods
        if self._noise_ahead:
            self._noise_future = self._run(self._fill_noise, self._noise_next)

    def _draw_noise(self) -> np.ndarray:
        if self._noise_pos >= _CHUNK:
            self._take_chunk()
        w = self._noise[self._noise_pos]
        self._noise_pos += 1
        return w

    # ----------------------------------------------------------------- reset
    def reset(self, rng: np.random.Generator | Sequence[np.random.Generator]) -> np.ndarray:
        """Start new episodes for all copies; return the observations, shape (K, obs_dim).

        ``rng`` is one generator (K = 1) or one per copy; all draws of copy ``i`` come from
        ``rng[i]`` in a fixed order (x_0, then the noise of every period).
        """
        rngs = [rng] if isinstance(rng, np.random.Generator) else list(rng)
        if len(rngs) != self.K:
            raise ParameterError(f"expected {self.K} random generators, got {len(rngs)}")
        self.wait()  # the helper may still be drawing from the old generators or adding to G
        self._rngs = rngs
        self._obs_out = self._info_out = None
        for i, g in enumerate(rngs):
            self.x[i] = g.standard_normal(self.n) * self._sx
        self._noise_pos = _CHUNK
        self._noise_ahead = False
        self._chunks = 0
        self.loop.start_episode()
        for _ in range(self.p.warmup_steps):  # normal operation under the encrypted controller (eq:ec)
            kern.plant_step(self._dims, self.x, self.loop.control(self.x), self._draw_noise(), self._A, self._B)
        self.X[:] = 0.0
        self.U[:] = 0.0
        self._GC[:] = 0.0
        self.ready[:] = False
        self._gram_upto = 1
        self._all_ready = False
        self._since_refresh = 0
        self.hist[:] = 0.0
        self.energy[:] = 0.0
        self.eps[:] = self._eps0
        self.logdet[:] = self._logdet0
        self.collected = self.delivered = 0
        self.done = False
        self.history = []
        self._collect()
        self.new = self._deliver(final=False)
        return self.observation()

    # ----------------------------------------------------------------- step
    def _collect(self) -> None:
        """Collect and pay for the state ciphertext of the current period."""
        self.X[self.collected] = self.loop.collect_state(self.x)
        self.collected += 1

    def _sync_gram(self, upto: int) -> None:
        """Bring G and C up to the columns j < ``upto`` (the fused step leaves them behind)."""
        self._wait_gram()
        if upto > self._gram_upto:
            kern.add_gram(self._dims, self.X, self.U, self._gram_upto, upto, self._GC, self._gram_scratch)
            self._gram_upto = upto

    def _gram_behind(self, upto: int) -> None:
        """Hand the Gram catch-up of the columns j < ``upto`` to the helper thread, unless it
        is still busy with the previous one. The columns are final: rows of X and U only ever
        get written once, ahead of the columns that read them."""
        if self._gram_future is not None:
            if not self._gram_future.done():
                return
            self._wait_gram()
        first, self._gram_upto = self._gram_upto, upto
        self._gram_future = _helper().submit(
            kern.add_gram, self._dims, self.X, self.U, first, upto, self._GC, self._gram_scratch
        )

    def _overflow(self) -> None:
        raise EncodingOverflowError(
            f"state {self.x.tolist()} leaves the encoder's declared range |x| <= {self.p.x_bound} (x_bound)"
        )

    def _target(self, collected: int) -> int:
        """Number of samples delivered once ``collected`` are paid for (before the end)."""
        delay = self.p.decipher_delay
        if delay is None:  # "end": nothing before the attack ends
            return 0
        return max(collected - delay, 0)

    def _deliver(self, final: bool) -> bool:
        """Deliver paid samples whose delay has passed; update the estimate and its error."""
        target = self.collected if final else self._target(self.collected)
        if target <= self.delivered:
            return False
        first = max(self.delivered, 1)
        if (
            self._all_ready
            and not final
            and self.p.reward != "logdet"
            and self._since_refresh + target - first < _REFRESH
        ):  # steady state: columns, recursive least squares and error in one compiled call
            self._sync_gram(first)
            kern.add_columns(self._dims, self.X, self.U, first, target, self._GC, self.Q, self.ready)
            self._gram_upto = target
            kern.estimation_error(self._dims, self.Q, self._theta_true_T, self._cf, self.ready, self.eps)
            self._since_refresh += target - first
            self.delivered = target
            self.history.append((target, float(self.eps[0])))
            return True
        self._sync_gram(first)
        if target > first:
            kern.add_columns(self._dims, self.X, self.U, first, target, self._GC, self.Q, self.ready)
            self._gram_upto = target
        self.delivered = target
        if self.p.reward == "logdet":
            self.logdet = np.linalg.slogdet(self.G + self._reg)[1]
        if self.delivered - 1 >= self.d:
            self._since_refresh += target - first
            if final or self._since_refresh >= _REFRESH:  # exact solve: bounds drift; final = eq:estimate
                stale = np.ones(self.K, dtype=bool)
                self._since_refresh = 0
            else:
                stale = ~self.ready
            if stale.any():
                rows = np.nonzero(stale)[0]
                theta_hat_T = self._refresh(rows)
                self.eps[rows] = ((theta_hat_T - self._theta_true_T) ** 2).sum(axis=(1, 2)) / self._c
            kern.estimation_error(self._dims, self.Q, self._theta_true_T, self._cf, self.ready & ~stale, self.eps)
            self._all_ready = bool(self.ready.all())
        self.history.append((self.delivered, float(self.eps[0])))
        return True

    def _refresh(self, rows: np.ndarray) -> np.ndarray:
        """Exact least squares (eq:estimate) for the copies ``rows`` from the running Gram matrices.

        A copy whose Jacobi-scaled Gram matrix is well conditioned (condition number below
        ``_COND_LIMIT``) solves ``G [P | Theta_hat^T] = [I | C]`` and (re)starts its recursion
        from the solution; any other copy gets the minimum-norm least-squares solution
        ``pinv(G) C`` of eq:estimate and stays non-recursive. A started recursion is re-anchored
        without a new check: G only grows, by positive semidefinite terms, so its smallest
        eigenvalue never falls. Called for copies that are not yet recursive, and for every copy
        each ``_REFRESH`` columns to bound rounding drift. Returns Theta_hat^T of those copies,
        shape (len(rows), n + m, n).
        """
        d = self.d
        G, C = self.G[rows], self.C[rows]
        ok = self.ready[rows]  # a copy: the ones already recursive stay so
        if not ok.all():
            fresh = ~ok
            g = G[fresh]
            s = 1.0 / np.sqrt(np.maximum(np.einsum("kii->ki", g), 1e-300))
            ok[fresh] = _condition(g * s[:, :, None] * s[:, None, :]) < _COND_LIMIT
        sol = np.zeros((len(rows), d, d + self.n))
        if ok.any():
            g, c = G[ok], C[ok]
            s = 1.0 / np.sqrt(np.einsum("kii->ki", g))  # Jacobi scaling
            rhs = np.concatenate((np.broadcast_to(np.eye(d), g.shape) * s[:, :, None], c * s[:, :, None]), axis=2)
            try:
                sol[ok] = np.linalg.solve(g * s[:, :, None] * s[:, None, :], rhs) * s[:, :, None]
            except np.linalg.LinAlgError:  # cannot happen to a well-conditioned matrix; never crash on it
                ok[:] = False
        if not ok.all():
            bad = ~ok
            sol[bad, :, d:] = _pinv_psd(G[bad]) @ C[bad]
        self.Q[:, rows[ok]] = sol[ok].reshape(-1, d * (d + self.n)).T
        self.ready[rows] = ok
        return sol[:, :, d:]

    def check_actions(self, action: Any) -> np.ndarray:
        """Validate actions: shape (K, m) (or (m,) for K = 1), finite, inside [-1, 1]. Returns
        them in float64, in a buffer of the episode's own (the caller's array is never changed)."""
        a = action
        if not (isinstance(a, np.ndarray) and a.dtype.char in "fd"):  # float32 and float64 are read as they are
            a = np.asarray(a, dtype=np.float64)
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

    def step(self, action: Any) -> tuple[np.ndarray, bool, bool]:
        """Apply the actions of all copies. Returns (rewards (K,), terminated, truncated)."""
        if self.done:
            raise ParameterError("step() called after the episode ended; call reset() first")
        p = self.p
        act = self.check_actions(action)
        w = self._draw_noise()
        ended = self.collected >= self._horizon
        if self._fused is not None and self._all_ready and not ended and not self._logdet:
            # steady state of the ideal backend: period, delivery, recursive LS and error in one call
            first = max(self.delivered, 1)
            target = self._target(self.collected + 1)
            if self._since_refresh + target - first < _REFRESH:
                new = target > self.delivered
                obs = np.empty(self._obs_shape, dtype=np.float32)
                N, collected = (target if new else self.delivered), self.collected + 1
                # the vector env's info arrays are written by the same call; a single env, whose
                # info is Python scalars, gives it buffers it does not read
                info_args = self._info_unread
                if self._info_in_step:
                    info_args = (*self._info_buffers(), *self._info_scalars(collected, N))
                status = self._step_fused(
                    self._dims, act, self._u_max, self.energy, self._budget, *self._fused, self.x, self._A, self._B, w,
                    self.X, self.U, self.collected - 1, self.collected, self.hist,
                    self._a, self._qa, self._qx,
                    first, target, self.Q, self._rls_scratch, self._theta_true_T, self._cf, self.eps,
                    self._reward, obs, N - 1, float(new), float(self._time_frac[collected]),
                    *info_args,
                )
                if status == kern.STATE_OVERFLOW:
                    self._overflow()
                self.collected += 1
                self.new = new
                if new:
                    self._since_refresh += target - first
                    self.delivered = target
                    self.history.append((target, float(self.eps[0])))
                    if self._use_helper and target - self._gram_upto >= _GRAM_BATCH:
                        self._gram_behind(target)
                self._obs_out = obs
                if self._info_in_step:
                    self._info_out = (info_args[0], info_args[1])
                return self._reward.copy(), False, False
        self._obs_out = self._info_out = None
        if self._fused is not None:  # ideal backend: one compiled call
            status = kern.step_ideal(
                self._dims, act, self._u_max, self.energy, self._budget, *self._fused, self.x, self._A, self._B, w,
                self.X, self.U, self.collected - 1, -1 if ended else self.collected, self.hist,
                self._a, self._qa, self._qx,
            )
            if status == kern.STATE_OVERFLOW:
                self._overflow()
            if not ended:
                self.collected += 1
        else:
            kern.energy_budget(self._dims, act, self._u_max, self.energy, self._budget, self._a)
            u = self.loop.inject(self._a)
            self.U[self.collected - 1] = u
            kern.plant_step(self._dims, self.x, u, w, self._A, self._B)
            if p.input_history:
                kern.shift_history(self._dims, self.hist, act)
            self.loop.tick()
            if not ended:
                self._collect()
        if p.reward == "logdet":
            before = self.logdet.copy()
            self.new = self._deliver(final=ended)
            reward = self.logdet - before
        else:  # decrease of log epsilon
            before = self.eps.copy()
            self.new = self._deliver(final=ended)
            reward = np.empty(self.K)
            kern.log_ratio(before, self.eps, reward)
        self.done = ended
        return reward, ended and p.budget_limited, ended and not p.budget_limited

    # ----------------------------------------------------------------- observation and info
    def observation(self) -> np.ndarray:
        """Observations of all copies, shape (K, obs_dim), float32 (see the class docstring), in
        a new array: the one the fused step wrote, if not yet handed out, else filled now."""
        obs, self._obs_out = self._obs_out, None
        if obs is None:
            obs = np.empty(self._obs_shape, dtype=np.float32)
            kern.fill_observation(
                self._dims, obs, self.X, self.U, self.delivered - 1, float(self.new), self.hist,
                float(self._time_frac[self.collected]), self.energy, self._budget,
            )
        return obs

    def _info_buffers(self) -> tuple[np.ndarray, np.ndarray]:
        return np.empty((6 if self.has_gamma_opt else 5, self.K)), np.empty((2, self.K), dtype=np.int64)

    def _info_scalars(self, collected: int, N: int) -> tuple[float, float, float, float, int, int]:
        """The info entries shared by all copies, as :func:`kern.fill_info` takes them."""
        return (
            float(self.gamma_table[N]), float(self.time_table[collected]), float(max(collected, 1) * self.m),
            float(self.gamma_opt_table[N]), collected, N,
        )

    def info_arrays(self) -> dict[str, np.ndarray]:
        """Info of every copy as arrays of shape (K,) (keys as in :meth:`info`): rows of two new
        buffers, one float and one integer, filled by the fused step or, if it did not run, now."""
        bufs, self._info_out = self._info_out, None
        if bufs is None:
            bufs = self._info_buffers()
            kern.fill_info(*bufs, self.eps, self.energy, *self._info_scalars(self.collected, self.delivered))
        f, counts = bufs
        info = {
            "epsilon": f[0],
            "gamma": f[1],
            "samples_collected": counts[0],
            "samples_delivered": counts[1],
            "deciphering_time": f[2],
            "input_energy": f[3],
            "average_power": f[4],
        }
        if self.has_gamma_opt:
            info["gamma_opt"] = f[5]
        return info

    def info(self) -> dict[str, Any]:
        """Info of copy 0 as Python scalars (single environment).

        ``epsilon`` is the error (Definition def:error) of the attacker's current estimate: the
        least squares estimate once ``n + m`` columns are delivered, ``[A B] = 0`` before.
        """
        N = self.delivered
        info = {
            "epsilon": float(self.eps[0]),
            "gamma": float(self.gamma_table[N]),
            "samples_collected": self.collected,
            "samples_delivered": N,
            "deciphering_time": float(self.time_table[self.collected]),
            "input_energy": float(self.energy[0]),
            "average_power": float(self.energy[0]) / (max(self.collected, 1) * self.m),
        }
        if self.has_gamma_opt:
            info["gamma_opt"] = float(self.gamma_opt_table[N])
        return info
