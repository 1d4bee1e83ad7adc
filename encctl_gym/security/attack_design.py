"""The best identification attack with a given input power: A-optimal experiment design.

This goes one step past the paper. Theorem thm:sic bounds the expected least-squares error
(eq:estimate, Definition def:error) of an adversary that injects i.i.d. Gaussian inputs. Its
proof shows ``E[epsilon(N)] = sigma_w2 / (m+n) tr E[(D D^T)^-1]`` and then applies the *scalar*
Jensen step ``tr(E[(D D^T)^-1]) >= (m+n)^2 / E[tr(D D^T)]``, which only sees the total power
``tr(Sigma)`` of the regressor ``z_t = [x_t; u_t]`` and not how it is spread over directions.

For a stationary attack with regressor covariance ``Sigma = E[z_t z_t^T]``, ``D D^T`` is about
``(N - 1) Sigma``, and (matrix Jensen, ``X -> X^-1`` is operator convex)
``E[(D D^T)^-1] >= (E[D D^T])^-1 = Sigma^-1 / (N - 1)``, so

    gamma_opt(N) = sigma_w2 tr(Sigma^-1) / ((n + m)(N - 1))

is a lower bound on ``E[epsilon(N)]`` that is also its large-``N`` limit. By the AM-HM
inequality ``tr(Sigma^-1) tr(Sigma) >= (n+m)^2``, with equality iff ``Sigma`` is a multiple of
the identity; for Gaussian inputs ``tr(Sigma) = sigma_w2 K`` (K the bracket of eq:sic2) and the
Gaussian ``gamma`` of this module is eq:sic2 multiplied by ``tr(Sigma^-1) tr(Sigma) / (n+m)^2
>= 1``: sharper (larger) than the paper's bound, and exact asymptotically.

An adversary choosing its inputs (Definition def:adversary, step 1) minimises
``tr(Sigma^-1)`` -- an A-optimal design -- over what it can achieve with the same average
power ``E|u_t|^2 <= m sigma_u2`` as the paper's Gaussian attack:

* ``closed_loop`` (``feedback=True``: the adversary sees the states in time, e.g. a malicious
  server after decryption, or any adversary simulating the plant): every ``Sigma >= 0`` with
  ``Sigma_xx = [A B] Sigma [A B]^T + sigma_w2 I`` and ``tr(Sigma_uu) <= m sigma_u2`` is
  achieved by ``u_t = K x_t + v_t``, ``K = Sigma_ux Sigma_xx^-1``, ``v_t ~ N(0, V)``,
  ``V = Sigma_uu - Sigma_ux Sigma_xx^-1 Sigma_xu`` (then ``A + B K`` is Schur stable because
  the Lyapunov equation has right-hand side ``B V B^T + sigma_w2 I > 0``).
* ``open_loop`` (``feedback=False``: inputs independent of the noise): ``x = x_u + x_w`` with
  the noise part fixed at ``sigma_w2 Psi_w`` and the input part ``M = cov([x_u; u]) >= 0``,
  ``M_xx = [A B] M [A B]^T``; ``Sigma = M + blkdiag(sigma_w2 Psi_w, 0)``. It is realised by
  ``u_t = K x_u,t + v_t`` where ``x_u`` is the input-driven state, which the adversary can
  simulate *only with a model of (A, B)*: ``gamma_opt`` is an oracle bound, as optimal
  experiment design always is. ``M`` may be singular (sinusoidal excitation, the classical
  open-loop optimum), then ``A + B K`` is only marginally stable.
* ``gaussian``: i.i.d. ``N(0, sigma_u2 I)`` inputs, ``Sigma = blkdiag(sigma_u2 Psi_u +
  sigma_w2 Psi_w, sigma_u2 I)`` in closed form (feasible for both sets above).

Hence ``gamma_closed_loop <= gamma_open_loop <= gamma_gaussian``. Only ``R_sigma =
sigma_u2 / sigma_w2`` matters: the programs are solved for ``Sigma / sigma_w2``. Solved with
cvxpy (Clarabel, SCS as fallback) as ``min tr(Y) s.t. [[Y, I], [I, Sigma]] >= 0``; cvxpy is
imported on first use.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._validation import check_bool, check_int, check_positive, check_schur_stable, check_system, format_value
from ..errors import ParameterError, ResourceLimitError, SolverError
from ..plant import Plant, as_plant
from .bayes_complexity import stationary_regressor_covariance
from .complexity import check_sample_size
from .design import SecurityDesign, design_for_sample_size
from .gramians import controllability_gramian, noise_gramian
from .sample_size import sample_size_for_rate
from .threat import IDENTIFICATION_FIELDS, ThreatModel

__all__ = [
    "AttackDesign",
    "optimal_attack_design",
    "gaussian_attack_design",
    "gamma_opt",
    "robust_security_design",
    "sdp_estimate",
    "KINDS",
    "SDP_MAX_DIMENSION",
]

KINDS: tuple[str, ...] = ("closed_loop", "open_loop", "gaussian")

#: Largest ``n + m`` for which :func:`optimal_attack_design` solves its SDP unless told otherwise.
#: Measured with Clarabel on the 2-core development machine (closed loop, one solve): n + m = 40:
#: 9 s, 0.54 GB; 48: 19 s, 0.99 GB; 56: 40 s, 1.7 GB (peak resident memory, baseline included);
#: the interior-point cost grows about as (n+m)^4.75 in time and (n+m)^4 in memory.
SDP_MAX_DIMENSION: int = 48

# reference point of the estimate (n + m = 56: 40 s and 1.6 GB above the 0.1 GB baseline)
_SDP_REF_DIM, _SDP_REF_SECONDS, _SDP_REF_GB = 56, 40.0, 1.6
# the estimate's domain: beyond 2^53 a dimension is no longer an exact float (and (p/56)^4.75
# would overflow float64 long before any real plant gets there)
_SDP_ESTIMATE_MAX_DIMENSION = 2**53


def sdp_estimate(dimension: int) -> tuple[float, float]:
    """Rough time (s) and memory (GB) of one A-optimal design SDP for ``n + m = dimension``.

    Extrapolated from the measurements quoted at :data:`SDP_MAX_DIMENSION` (2-core machine,
    Clarabel): time ``~ 40 s (p / 56)^4.75``, memory ``~ 1.6 GB (p / 56)^4``. An estimate for
    deciding before the solve starts, not a promise.

    Raises
    ------
    ParameterError
        If ``dimension`` is not an integer in ``[2, 2^53]``.
    """
    p = check_int("dimension", dimension, 2, _SDP_ESTIMATE_MAX_DIMENSION)
    ratio = p / _SDP_REF_DIM
    return _SDP_REF_SECONDS * ratio**4.75, _SDP_REF_GB * ratio**4


@dataclass(frozen=True)
class AttackDesign:
    """A stationary attack input design and its asymptotic identification error.

    Attributes
    ----------
    Sigma : ndarray, shape (n+m, n+m)
        Covariance of ``z_t = [x_t; u_t]``.
    K : ndarray, shape (m, n)
        Feedback gain of the policy ``u = K x + v`` (closed loop: on the measured state;
        open loop: on the simulated input-driven state; Gaussian: zero).
    V : ndarray, shape (m, m)
        Covariance of the innovation ``v`` (symmetric, PSD).
    trace_inv : float
        ``tr(Sigma^-1)``.
    sigma_u2, sigma_w2 : float
        Input power budget (per input channel) and noise variance.
    kind : str
        ``"closed_loop"``, ``"open_loop"`` or ``"gaussian"``.
    input_state_cov : ndarray or None
        Open loop: covariance ``S_u`` of the input-driven state ``x_u``; else None.
    """

    Sigma: np.ndarray
    K: np.ndarray
    V: np.ndarray
    trace_inv: float
    sigma_u2: float
    sigma_w2: float
    kind: str
    input_state_cov: np.ndarray | None = field(default=None)

    @property
    def n(self) -> int:
        """State dimension."""
        return int(self.K.shape[1])

    @property
    def m(self) -> int:
        """Input dimension."""
        return int(self.K.shape[0])

    @property
    def rate(self) -> float:
        """``c = sigma_w2 tr(Sigma^-1) / (n+m)``, so that ``gamma(N) = c / (N - 1)``."""
        return self.sigma_w2 * self.trace_inv / (self.n + self.m)

    def gamma(self, N: Any) -> float | np.ndarray:
        """``gamma_opt(N) = sigma_w2 tr(Sigma^-1) / ((n+m)(N-1))`` (module docstring).

        Parameters
        ----------
        N : int or array_like of int
            Sample size(s), integers >= 2.

        Returns
        -------
        float or ndarray
            Same shape as ``N``.
        """
        Nf, scalar = check_sample_size(N)
        val = self.rate / (Nf - 1.0)
        return float(val) if scalar else val


def _check_inputs(A: Any, B: Any, sigma_u2: Any, sigma_w2: Any) -> tuple[np.ndarray, np.ndarray, float, float]:
    A, B = check_system(A, B)
    check_schur_stable(A)
    return A, B, check_positive("sigma_u2", sigma_u2), check_positive("sigma_w2", sigma_w2)


def _policy(Sxx: np.ndarray, Sux: np.ndarray, Suu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``K = S_ux S_xx^+`` and ``V = S_uu - K S_xu`` (symmetrised, clipped PSD)."""
    K = Sux @ np.linalg.pinv(Sxx, rcond=1e-12, hermitian=True)
    V = Suu - K @ Sux.T
    V = 0.5 * (V + V.T)
    w, U = np.linalg.eigh(V)
    V = (U * np.clip(w, 0.0, None)) @ U.T
    return K, V


def gaussian_attack_design(A: Any, B: Any, *, sigma_u2: float, sigma_w2: float) -> AttackDesign:
    """The i.i.d. Gaussian attack of Theorem thm:sic in closed form (no solver).

    ``Sigma = blkdiag(sigma_u2 Psi_u + sigma_w2 Psi_w, sigma_u2 I)``, ``K = 0``,
    ``V = sigma_u2 I``. ``gamma(N) = sigma_w2 tr(Sigma^-1) / ((n+m)(N-1))`` is sharper than the
    Jensen step of thm:sic: that step replaces ``tr(Sigma^-1)`` by ``(n+m)^2 / tr(Sigma)``,
    which is smaller unless ``Sigma`` is a multiple of the identity (AM-HM inequality), so
    eq:sic2 <= this ``gamma`` and the ratio is ``tr(Sigma^-1) tr(Sigma) / (n+m)^2``.

    Parameters
    ----------
    A, B : array_like
        Plant of eq:system (``A`` Schur stable).
    sigma_u2, sigma_w2 : float
        Input and noise variances (> 0).

    Returns
    -------
    AttackDesign
        ``kind="gaussian"``.
    """
    A, B, su, sw = _check_inputs(A, B, sigma_u2, sigma_w2)
    n, m = B.shape
    Sigma = stationary_regressor_covariance(A, B, sigma_u2=su, sigma_w2=sw)
    Sxx = Sigma[:n, :n]
    trace_inv = float(np.trace(np.linalg.inv(Sxx)) + m / su)
    return AttackDesign(Sigma, np.zeros((m, n)), su * np.eye(m), trace_inv, su, sw, "gaussian")


_SOLVER_OPTIONS: dict[str, dict[str, Any]] = {
    "CLARABEL": {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10, "max_iter": 500},
    "SCS": {"eps_abs": 1e-9, "eps_rel": 1e-9, "max_iters": 200_000},
}


def _solve(prob: Any, solver: str | None) -> str:
    """Solve with the given solver, or Clarabel then SCS; return the solver used."""
    import cvxpy as cp

    candidates = [solver.upper()] if solver is not None else ["CLARABEL", "SCS"]
    installed = set(cp.installed_solvers())
    errors = []
    for name in candidates:
        if name not in installed:
            errors.append(f"{name}: not installed")
            continue
        try:
            with warnings.catch_warnings():
                # "Solution may be inaccurate": such solutions are checked by _validate instead.
                warnings.simplefilter("ignore", UserWarning)
                prob.solve(solver=name, **_SOLVER_OPTIONS.get(name, {}))
        except (cp.error.SolverError, ArithmeticError, ValueError) as exc:
            errors.append(f"{name}: {exc}")
            continue
        if prob.status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
            return name
        errors.append(f"{name}: status {prob.status}")
    raise SolverError("the A-optimal design SDP was not solved (" + "; ".join(errors) + ")")


def _validate(Sigma: np.ndarray, A: np.ndarray, B: np.ndarray, r: float, kind: str, M: np.ndarray | None, tol: float) -> None:
    """Check the (normalised) constraints; raise SolverError naming the violated one."""
    n, m = B.shape
    G = np.hstack([A, B])
    scale = max(1.0, float(np.abs(Sigma).max()))
    if np.linalg.eigvalsh(Sigma).min() < -tol * scale:
        raise SolverError(f"solver returned Sigma with eigenvalue {np.linalg.eigvalsh(Sigma).min():.3g} < 0")
    tr_uu = float(np.trace(Sigma[n:, n:]))
    if tr_uu > m * r * (1 + tol):
        raise SolverError(f"solver returned tr(Sigma_uu) = {tr_uu:.6g} above the budget {m * r:.6g}")
    if kind == "closed_loop":
        resid = np.abs(Sigma[:n, :n] - G @ Sigma @ G.T - np.eye(n)).max()
    else:
        assert M is not None
        if np.linalg.eigvalsh(M).min() < -tol * scale:
            raise SolverError("solver returned an input-driven covariance M that is not PSD")
        resid = np.abs(M[:n, :n] - G @ M @ G.T).max()
    if resid > tol * scale:
        raise SolverError(f"solver returned Sigma violating the stationarity constraint by {resid:.3g}")


def optimal_attack_design(
    A: Any,
    B: Any,
    *,
    sigma_u2: float,
    sigma_w2: float,
    feedback: bool = True,
    solver: str | None = None,
    tol: float = 1e-5,
    max_dimension: int | None = None,
) -> AttackDesign:
    """A-optimal attack input: minimise ``tr(Sigma^-1)`` under the input power ``m sigma_u2``.

    See the module docstring for the feasible sets. The SDP is solved for ``Sigma / sigma_w2``
    (depends on ``R_sigma`` only), then scaled back.

    Parameters
    ----------
    A, B : array_like
        Plant of eq:system (``A`` Schur stable).
    sigma_u2 : float
        Input power per channel (> 0): ``tr(Sigma_uu) <= m sigma_u2``, as the Gaussian attack.
    sigma_w2 : float
        Noise variance (> 0).
    feedback : bool, default True
        ``True``: closed-loop design (``kind="closed_loop"``); ``False``: open loop.
    solver : str, optional
        A cvxpy solver name; default Clarabel, then SCS if Clarabel fails.
    tol : float, default 1e-5
        Relative tolerance for checking the returned ``Sigma`` against the constraints.
    max_dimension : int, optional
        Largest ``n + m`` to attempt (default :data:`SDP_MAX_DIMENSION`); a larger plant is
        refused before the solve with the estimated time and memory (:func:`sdp_estimate`).

    Returns
    -------
    AttackDesign

    Raises
    ------
    UnstableSystemError
        If ``A`` is not Schur stable.
    ResourceLimitError
        If ``n + m`` exceeds ``max_dimension``.
    SolverError
        If the solver fails or returns a point violating the constraints beyond ``tol``.
    """
    A, B, su, sw = _check_inputs(A, B, sigma_u2, sigma_w2)
    feedback = check_bool("feedback", feedback)
    tol = check_positive("tol", tol)
    if solver is not None and not isinstance(solver, str):
        raise ParameterError(f"solver must be a cvxpy solver name, got {format_value(solver)}")
    n, m = B.shape
    _check_dimension(n + m, max_dimension)
    r = su / sw
    L, H, Q, F, P, psi_w = _normalised_coordinates(A, B, r)
    kind = "closed_loop" if feedback else "open_loop"
    S_value = _solve_design_program(H, Q, F, P, n, m, feedback, solver)
    if feedback:
        Sig_n = L @ S_value @ L.T
        M_n = None
    else:
        M_n = L @ S_value @ L.T
        M_n = 0.5 * (M_n + M_n.T)
        offset = np.zeros((n + m, n + m))
        offset[:n, :n] = psi_w
        Sig_n = M_n + offset
    if not np.all(np.isfinite(Sig_n)):
        raise SolverError("solver returned a non-finite Sigma")
    Sig_n = 0.5 * (Sig_n + Sig_n.T)
    _validate(Sig_n, A, B, r, kind, M_n, tol)
    w_min = np.linalg.eigvalsh(Sig_n).min()
    if w_min <= 0:
        raise SolverError(f"solver returned a singular Sigma (smallest eigenvalue {w_min:.3g})")
    Sigma = sw * Sig_n
    trace_inv = float(np.trace(np.linalg.inv(Sigma)))
    if feedback:
        K, V = _policy(Sigma[:n, :n], Sigma[n:, :n], Sigma[n:, n:])
        S_u = None
    else:
        assert M_n is not None  # the open-loop program solves for M
        Mv = sw * M_n
        K, V = _policy(Mv[:n, :n], Mv[n:, :n], Mv[n:, n:])
        S_u = Mv[:n, :n]
    return AttackDesign(Sigma, K, V, trace_inv, su, sw, kind, S_u)


def _check_dimension(p: int, max_dimension: int | None) -> None:
    """Refuse an SDP of ``n + m = p`` above ``max_dimension`` (default :data:`SDP_MAX_DIMENSION`)
    before the solve, with its estimated time and memory (:func:`sdp_estimate`)."""
    limit = SDP_MAX_DIMENSION if max_dimension is None else check_int("max_dimension", max_dimension, 2)
    if p > limit:
        secs, gb = sdp_estimate(p)
        raise ResourceLimitError(
            f"the A-optimal design SDP for n + m = {p} exceeds the limit n + m <= {limit}: estimated "
            f"{secs:.3g} s and {gb:.3g} GB for one solve (time grows as (n+m)^4.75, memory as (n+m)^4); "
            "raise max_dimension to attempt it"
        )


def _normalised_coordinates(
    A: np.ndarray, B: np.ndarray, r: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(L, H, Q, F, P, Psi_w)`` of the normalised program at ``R_sigma = r``.

    ``Sigma_hat = Sigma / sigma_w2`` depends on ``r`` only. We write ``Sigma_hat = L S L^T`` with
    ``L = blkdiag(chol(r Psi_u + Psi_w), sqrt(r) I)``, the Cholesky factor of the Gaussian
    design, so that the Gaussian attack is ``S = I`` and every scale is O(1)::

        stationarity  S_xx = H S H^T + Q,  H = Lx^-1 [A B] L,  Q = Lx^-1 Lx^-T
        budget        tr(S_uu) <= m
        objective     tr(Sigma_hat^-1) = tr(F S^-1 F^T),  F = L^-T  (via [[Y, F], [F^T, S]] >= 0).

    ``F`` is scaled to unit Frobenius norm (the Gaussian design's objective is its square);
    ``P = blkdiag(Lx^-1 Psi_w Lx^-T, 0)`` is the noise part of the open-loop ``S``.
    """
    n, m = B.shape
    p = n + m
    psi_u, psi_w = controllability_gramian(A, B), noise_gramian(A)
    Lx = np.linalg.cholesky(r * psi_u + psi_w)
    sr = float(np.sqrt(r))
    L = np.zeros((p, p))
    L[:n, :n] = Lx
    L[n:, n:] = sr * np.eye(m)
    Lx_inv = np.linalg.inv(Lx)
    H = Lx_inv @ np.hstack([A, B]) @ L
    Q = Lx_inv @ Lx_inv.T
    Q = 0.5 * (Q + Q.T)
    F = np.linalg.inv(L).T
    f_scale = float(np.sqrt(np.trace(F @ F.T)))  # objective of the Gaussian design is f_scale^2
    F = F / f_scale
    P = np.zeros((p, p))
    P[:n, :n] = Lx_inv @ psi_w @ Lx_inv.T
    P = 0.5 * (P + P.T)
    return L, H, Q, F, P, psi_w


def _solve_design_program(
    H: np.ndarray, Q: np.ndarray, F: np.ndarray, P: np.ndarray, n: int, m: int, feedback: bool, solver: str | None
) -> np.ndarray:
    """Solve the normalised SDP (:func:`_normalised_coordinates`); return ``S`` (closed loop) or
    the input part ``N`` of ``S = N + P`` (open loop)."""
    import cvxpy as cp

    p = n + m
    Y = cp.Variable((p, p), symmetric=True)
    if feedback:
        S = cp.Variable((p, p), symmetric=True)
        cons = [S[:n, :n] == H @ S @ H.T + Q, cp.trace(S[n:, n:]) <= m]
        S_expr = S
    else:
        S = cp.Variable((p, p), symmetric=True)
        cons = [S >> 0, S[:n, :n] == H @ S @ H.T, cp.trace(S[n:, n:]) <= m]
        S_expr = S + P
    lmi = cp.bmat([[Y, F], [F.T, S_expr]])
    cons.append(0.5 * (lmi + lmi.T) >> 0)
    prob = cp.Problem(cp.Minimize(cp.trace(Y)), cons)
    _solve(prob, solver)
    return np.asarray(S.value, dtype=float)


def gamma_opt(
    N: Any, A: Any, B: Any, *, sigma_u2: float, sigma_w2: float, feedback: bool = True, solver: str | None = None
) -> float | np.ndarray:
    """``gamma_opt(N)`` of the A-optimal attack (closed loop by default); see the module docstring.

    Parameters
    ----------
    N : int or array_like of int
        Sample size(s) >= 2.
    A, B : array_like
        Plant (``A`` Schur stable).
    sigma_u2, sigma_w2 : float
        Input power and noise variance (> 0).
    feedback : bool, default True
        Closed- or open-loop design.
    solver : str, optional
        cvxpy solver name.

    Returns
    -------
    float or ndarray
    """
    check_sample_size(N)
    return optimal_attack_design(A, B, sigma_u2=sigma_u2, sigma_w2=sigma_w2, feedback=feedback, solver=solver).gamma(N)


def _check_design_fits(design: Any, A: np.ndarray, B: np.ndarray, su: float, sw: float, kind: str) -> None:
    """Refuse a precomputed design made for another kind, shape, variances or plant."""
    n, m = B.shape
    if not isinstance(design, AttackDesign):
        raise ParameterError(f"design must be an AttackDesign, got {format_value(design)}")
    if design.kind != kind or design.K.shape != (m, n):
        raise ParameterError(
            f"design of kind {design.kind!r} and K shape {design.K.shape} does not fit kind {kind!r} and (n, m) = ({n}, {m})"
        )
    for name, mine, theirs in (("sigma_u2", su, design.sigma_u2), ("sigma_w2", sw, design.sigma_w2)):
        if not np.isclose(mine, theirs, rtol=1e-12, atol=0.0):
            raise ParameterError(f"design was made for {name} = {theirs!r}, not {name} = {mine!r}")
    Sig_n = np.asarray(design.Sigma, dtype=float) / sw
    M_n = None
    if kind == "open_loop":
        offset = np.zeros_like(Sig_n)
        offset[:n, :n] = noise_gramian(A)
        M_n = Sig_n - offset
    try:
        _validate(Sig_n, A, B, su / sw, "open_loop" if kind == "open_loop" else "closed_loop", M_n, 1e-5)
    except SolverError as exc:
        raise ParameterError(f"design does not fit this plant (A, B): {exc}") from None


def robust_security_design(
    plant: Plant | tuple[Any, Any],
    threat: ThreatModel,
    *,
    kind: str = "closed_loop",
    design: AttackDesign | None = None,
    solver: str | None = None,
) -> SecurityDesign:
    """Theorem thm:opt_sec with ``gamma_opt`` in place of eq:sic2: robust to the input design.

    ``N*`` is the smallest ``N`` with ``gamma_opt(N) < gamma_c``,
    ``floor(sigma_w2 tr(Sigma^-1) / ((n+m) gamma_c)) + 2``; ``lam*`` and ``k*`` follow as in
    eq:opt_sec and eq:opt_key. (``tr(Sigma^-1)`` comes from a numerical solve, so a tie at an
    exact integer is not meaningful here.)

    Parameters
    ----------
    plant : Plant or (A, B)
        Plant (``A`` Schur stable).
    threat : ThreatModel
        Input power and noise variance, ``gamma_c``, ``tau_c``, ``Upsilon`` (``sigma_x2`` is
        recorded in the result, not used by ``gamma_opt``).
    kind : {"closed_loop", "open_loop", "gaussian"}
        Which attack design to guard against.
    design : AttackDesign, optional
        A precomputed design of the same ``kind`` (skips the solve).
    solver : str, optional
        cvxpy solver name.

    Returns
    -------
    SecurityDesign
        ``method`` equal to ``kind``.
    """
    if not isinstance(kind, str) or kind not in KINDS:
        raise ParameterError(f"unknown kind {format_value(kind)}; expected one of {', '.join(KINDS)}")
    if not isinstance(threat, ThreatModel):
        raise ParameterError(f"robust_security_design: threat must be a ThreatModel, got {format_value(threat)}")
    threat.require(*IDENTIFICATION_FIELDS)
    p = as_plant(plant)
    A, B, su, sw = p.A, p.B, float(threat.sigma_u2), float(threat.sigma_w2)
    n, m = p.n, p.m
    if design is None:
        if kind == "gaussian":
            design = gaussian_attack_design(A, B, sigma_u2=su, sigma_w2=sw)
        else:
            design = optimal_attack_design(A, B, sigma_u2=su, sigma_w2=sw, feedback=kind == "closed_loop", solver=solver)
    else:
        _check_design_fits(design, A, B, su, sw, kind)
    N_star = sample_size_for_rate(design.rate, threat.gamma_c)
    return design_for_sample_size(
        kind,
        N_star,
        design.gamma,
        threat,
        m=m,
        n=n,
        tr_psi_u=float(np.trace(controllability_gramian(A, B))),
        tr_psi_w=float(np.trace(noise_gramian(A))),
    )
