"""Probe cases of the key breakers (:mod:`encctl_gym.cryptanalysis`), the estimators
(:mod:`encctl_gym.ident`) and the Monte Carlo engine (:mod:`encctl_gym.sim`, :mod:`encctl_gym.parallel`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .build import GROUP64, bad_args, case
from .harness import Case, Lazy, SecurityFinding, api
from .values import BAD, HUGE, HUGER, INF, NAN, explicit, label

C = "cryptanalysis"
I = "ident"  # noqa: E741
S = "sim"
CA = "encctl_gym.cryptanalysis"
GROUP32 = Lazy(lambda: api("encctl_gym.crypto.group:generate_safe_prime_group")(32, rng=5), "<32-bit group>")
GROUP712 = Lazy(lambda: api("encctl_gym.crypto.group:get_group")(712), "<712-bit group>")


def _h(group: Any, s: int = 12345) -> int:
    return int(pow(group.g, s, group.p))


def _cryptanalysis() -> list[Case]:
    out: list[Case] = []
    out += bad_args(
        C, f"{CA}.registry:get_breaker", {"name": "bsgs"}, {"name": explicit(["bogus", "", 3, None, ["bsgs"], "BSGS"])}, drawn=0
    )
    for name in ("bsgs", "rho", "rho-multi", "index-calculus", "token-chain"):
        out += bad_args(
            C,
            lambda kw, n=name: api(f"{CA}.registry:get_breaker")(n, **kw),
            {},
            {
                "max_bits": explicit([-1, 0, 2.5, "a", True]),
                "rng": explicit(["seed", 2.5, [1]], "traceback"),
                "bogus_option": explicit([1], "silent"),
            },
            name=f"get_breaker({name})",
            drawn=0,
        )
    out += bad_args(
        C,
        f"{CA}.bsgs:BabyStepGiantStep",
        {},
        {"baby_steps": explicit([0, -1, 2.5, "a", True]), "max_table": explicit([0, -1, 2.5, "a"])},
        drawn=0,
    )
    out += bad_args(C, f"{CA}.index_calculus:IndexCalculus", {}, {"bound": explicit([0, 1, -1, 2.5, "a", True])}, drawn=0)
    out += bad_args(C, f"{CA}.rho:MultiLogRho", {}, {"table_walks": explicit([-1, 2.5, "a"])}, drawn=0)
    for cls, opt, values in (
        ("bsgs:BabyStepGiantStep", "baby_steps", (10**12, HUGE)),
        ("bsgs:BabyStepGiantStep", "max_table", (10**15,)),
        ("index_calculus:IndexCalculus", "bound", (10**12, HUGE)),
        ("rho:MultiLogRho", "table_walks", (10**12,)),
    ):
        for v in values:
            out.append(
                case(
                    C,
                    f"{cls.split(':')[1]}({opt}={label(v)}).precompute(32-bit group) bounded",
                    "hang",
                    lambda _, c=cls, o=opt, v=v: api(f"{CA}.{c}")(**{o: v}).precompute(resolve_group(GROUP32)),
                    expect="either",
                    timeout=30,
                )
            )
    out += bad_args(C, f"{CA}.token_chain:TokenChain", {}, {"inner": explicit(["bogus", "token-chain", 3])}, drawn=0)

    def precompute(kw: dict[str, Any]) -> Any:
        b = api(f"{CA}.registry:get_breaker")(kw.pop("breaker", "bsgs"))
        return b.precompute(**{"group": api("encctl_gym.crypto.group:get_group")(64), **kw})

    out += bad_args(
        C,
        precompute,
        {},
        {
            "group": explicit(["abc", None, 64, GROUP712, {"p": 23}], "traceback"),
            "time_limit": explicit([-1.0, 0.0, NAN, "a", True, HUGE]),
        },
        name="Breaker.precompute",
        drawn=0,
    )
    for name in ("bsgs", "rho", "index-calculus"):
        out.append(
            case(
                C,
                f"{name}.precompute(712-bit group) refused before any work",
                "hang",
                lambda _, n=name: api(f"{CA}.registry:get_breaker")(n).precompute(api("encctl_gym.crypto.group:get_group")(712)),
                timeout=30,
            )
        )

    def break_key(kw: dict[str, Any]) -> Any:
        grp = api("encctl_gym.crypto.group:get_group")(64)
        pre = api(f"{CA}.registry:get_breaker")("bsgs").precompute(grp)
        return pre.break_key(**{"h": _h(grp), **kw})

    nonmember = Lazy(
        lambda: next(v for v in range(2, 200) if not api("encctl_gym.crypto.group:get_group")(64).contains(v)), "<non-member>"
    )
    out += bad_args(
        C,
        break_key,
        {},
        {
            "h": explicit([0, -4, 2**64, 2.5, "4", None, True, nonmember, HUGER]),
            "time_limit": explicit([-1.0, NAN, "a"]),
            "rng": explicit(["seed", 2.5], "traceback"),
        },
        name="Precomputation.break_key",
        drawn=0,
    )

    def sequence(kw: dict[str, Any]) -> Any:
        grp = resolve_group(GROUP32)
        return api(f"{CA}.sequence:break_sequence")(**{"breaker": "bsgs", "group": grp, "hs": [_h(grp, 5), _h(grp, 7)], **kw})

    out += bad_args(
        C,
        sequence,
        {},
        {
            "breaker": explicit(["bogus", 3, None]),
            "hs": explicit(["abc", None, [0], ["x"], [2.5], 42, [[1, 2]]], "traceback"),
            "tokens": explicit(["abc", [1, 2], [None]], "traceback"),
            "time_limit": explicit([-1.0, NAN, "a"]),
            "n_jobs": explicit([0, -5, 2.5, "a"]),
            "chunks": explicit([0, -1, 2.5, "a"]),
            "seed": explicit([-1, 2.5, "a"]),
            "scheduler": explicit([3, "tcp://"], "traceback"),
            "group": explicit(["abc", 64]),
        },
        name="break_sequence",
        drawn=0,
    )
    out += bad_args(
        C,
        f"{CA}.smoothness:FactorBase",
        {"bound": 100},
        {"bound": explicit([0, 1, -1, 2.5, "a", None, True, 10**12, HUGE], "hang")},
        drawn=0,
    )
    out += bad_args(
        C,
        f"{CA}.smoothness:dickman_rho",
        {"u": 2.0},
        {"u": explicit([NAN, -1.0, INF, "a", None, 1e308, HUGE, 2 + 1j], "hang")},
        drawn=0,
        timeout=30,
    )
    out += bad_args(
        C,
        f"{CA}.smoothness:rational_reconstruction",
        {"y": 5, "p": 101},
        {"p": explicit([0, -101, 1, 2.5, "a", None]), "y": explicit([2.5, "a", None]), "bound": explicit([0, -1, 2.5, "a"])},
        drawn=0,
    )
    out += bad_args(
        C, f"{CA}.base:check_element", {"group": GROUP64, "h": 4}, {"h": explicit([0, 2**64, 2.5, "4", None, nonmember])}, drawn=0
    )
    out += bad_args(
        C,
        f"{CA}.base:Deadline",
        {"time_limit": 1.0, "what": "x"},
        {"time_limit": explicit([-1.0, NAN, "a", True, HUGE])},
        drawn=0,
    )

    def verify_wrong(_: Path) -> Any:
        grp = api("encctl_gym.crypto.group:get_group")(64)
        return api(f"{CA}.base:verify_exponent")(grp, _h(grp, 5), 6, "probe")

    out.append(case(C, "verify_exponent with a wrong exponent", "security", verify_wrong))

    def recovered_checked(_: Path) -> None:
        grp = resolve_group(GROUP32)
        for name in ("bsgs", "rho", "index-calculus"):
            key = api(f"{CA}.registry:get_breaker")(name, rng=1).precompute(grp).break_key(_h(grp, 987654321), rng=2)
            if pow(grp.g, int(key.s), grp.p) != _h(grp, 987654321):
                raise SecurityFinding(f"{name} returned an exponent that fails g^s = h")

    out.append(case(C, "valid: every breaker's exponent satisfies g^s = h", "silent", recovered_checked, expect="result"))

    # Found while hardening the cases above: the cost model, the factor-base tests, the linear
    # algebra, options given with an instance (silently ignored), and more of break_sequence.
    for fn in ("cost_model", "relation_probability"):
        out += bad_args(
            C,
            f"{CA}.index_calculus:{fn}",
            {"bits": 64, "bound": 100.0},
            {"bits": explicit([HUGE, "a", None, 1], "traceback"), "bound": explicit([1, 0.5, "a", NAN], "traceback")},
            drawn=0,
        )
    out += bad_args(
        C, f"{CA}.index_calculus:choose_bound", {"bits": 64}, {"bits": explicit([HUGE, "a", 1], "traceback")}, drawn=0
    )
    out += bad_args(
        C,
        lambda kw: api(f"{CA}.smoothness:FactorBase")(100).factor(**kw),
        {},
        {"x": explicit([2.5, 6.0 + 0j])},
        name="FactorBase.factor",
        drawn=0,
    )
    out += bad_args(
        C,
        lambda kw: api(f"{CA}.smoothness:FactorBase")(100).is_smooth(**kw),
        {},
        {"x": explicit(["a", None, 2.5], "traceback")},
        name="FactorBase.is_smooth",
        drawn=0,
    )
    out += bad_args(
        C,
        f"{CA}.linalg:solve_mod_prime",
        {"rows": [{0: 3}], "rhs": [1], "ncols": 1, "q": 7},
        {
            "q": explicit([0, 1, 2.5, "a"], "traceback"),
            "ncols": explicit([-1, 1.5, "a"], "traceback"),
            "rows": explicit([[{5: 1}], [{-1: 1}]], "traceback"),
        },
        drawn=0,
    )
    out.append(
        case(
            C,
            "get_breaker(instance, max_bits=20) refused, not ignored",
            "silent",
            lambda _: api(f"{CA}.registry:get_breaker")(api(f"{CA}.rho:PollardRho")(), max_bits=20),
        )
    )
    out.append(
        case(
            C,
            "TokenChain(instance, max_bits=20) refused, not ignored",
            "silent",
            lambda _: api(f"{CA}.token_chain:TokenChain")(api(f"{CA}.rho:PollardRho")(), max_bits=20),
        )
    )
    out += bad_args(
        C,
        sequence,
        {},
        {"pre": explicit([3, "abc"], "traceback"), "progress": explicit(["no", 1]), "tokens": explicit([5], "traceback")},
        name="break_sequence",
        drawn=0,
    )
    out += bad_args(
        C, f"{CA}.rho:MultiLogRho", {}, {"table_walks": explicit([HUGE, 10**12], "hang")}, name="MultiLogRho(no group)", drawn=0
    )

    def one_key_rho(bits: int) -> Any:
        grp = api("encctl_gym.crypto.group:get_group")(bits)
        return api(f"{CA}.registry:get_breaker")("rho", max_bits=100_000).precompute(grp).break_key(_h(grp))

    out.append(
        case(
            C, "rho(max_bits=100000) on the 712-bit group refused before any work", "hang", lambda _: one_key_rho(712), timeout=30
        )
    )
    return out


def resolve_group(g: Any) -> Any:
    from .harness import resolve

    return resolve(g) if g is not None else api("encctl_gym.crypto.group:get_group")(64)


def _traj(N: int = 40, n: int = 2, m: int = 1, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    A = np.array([[0.5, 0.1], [0.0, 0.3]])
    B = np.array([[1.0], [0.5]])
    x = np.zeros((N, n))
    u = rng.normal(size=(N, m))
    for t in range(N - 1):
        x[t + 1] = A @ x[t] + B @ u[t] + 0.1 * rng.normal(size=n)
    return x, u


def _ident() -> list[Case]:
    out: list[Case] = []
    x, u = _traj()
    traj_bad = explicit(
        [
            x + 1j,
            np.full_like(x, NAN),
            x[:2],
            x[:, :1].ravel(),
            "abc",
            None,
            x.astype(str),
            np.zeros((0, 2)),
            x[None, None],
            np.full((40, 2), None, dtype=object),
        ]
    )
    out += bad_args(
        I,
        "encctl_gym.ident.least_squares:least_squares",
        {"x": x, "u": u},
        {"x": traj_bad, "u": explicit([u + 1j, u[:10], np.full_like(u, INF), "abc", None, u.astype(bool)])},
        drawn=0,
    )
    out += bad_args(
        I,
        "encctl_gym.ident.least_squares:data_matrices",
        {"x": x, "u": u},
        {"x": traj_bad[:6], "u": explicit([u[:5], u + 1j])},
        drawn=0,
    )
    out += bad_args(
        I, "encctl_gym.ident.least_squares:RecursiveLeastSquares", {"n": 2, "m": 1}, {"n": "int", "m": "int"}, drawn=0
    )

    def rls_update(kw: dict[str, Any]) -> Any:
        rls = api("encctl_gym.ident.least_squares:RecursiveLeastSquares")(2, 1)
        return rls.update(**kw)

    import inspect

    def rls_params() -> list[str]:
        try:
            return list(inspect.signature(api("encctl_gym.ident.least_squares:RecursiveLeastSquares").update).parameters)[1:]
        except Exception:  # noqa: BLE001
            return []

    params = rls_params()
    if len(params) >= 3:
        rls_valid = {params[0]: np.zeros(2), params[1]: np.zeros(1), params[2]: np.zeros(2)}
        for p in params[:3]:
            out += bad_args(
                I,
                lambda kw, v=rls_valid: rls_update({**v, **kw}),
                {},
                {p: explicit([np.zeros(5), np.array([NAN, 0.0]), np.array([1j, 0.0]), "ab", None])},
                name="RecursiveLeastSquares.update",
                drawn=0,
            )
    A2, B2 = np.array([[0.5, 0.1], [0.0, 0.3]]), np.array([[1.0], [0.5]])
    ie = "encctl_gym.ident.grid:identification_errors"
    valid = {"x": x, "u": u, "A": A2, "B": B2, "sample_sizes": [10, 20, 40]}
    out += bad_args(
        I,
        ie,
        valid,
        {
            "sample_sizes": explicit(
                [[0, 10], [2, 10], [10, 50], [10.5], "abc", None, [], [[10, 20]], [NAN], [HUGE], [True, 10]]
            ),
            "method": explicit(["bogus", 3, None]),
            "estimator": explicit(["bogus", 3, {"name": "bogus"}]),
            "A": explicit([np.eye(3), A2 + 1j]),
        },
        drawn=0,
    )
    out += bad_args(
        I,
        "encctl_gym.ident.registry:make_estimator",
        {"spec": "ls"},
        {"spec": explicit(["bogus", 3, {"name": "bogus"}, {"name": "bayes", "bogus": 1}, {}, ["ls"], {"name": 3}])},
        drawn=0,
    )
    out += bad_args(
        I,
        lambda kw: api("encctl_gym.ident.registry:make_estimator")("bayes", **kw),
        {},
        {
            "prior_variance": explicit([-1.0, 0.0, NAN, "a", INF]),
            "noise_variance": explicit([-1.0, NAN, "a"]),
            "prior_mean": explicit([np.zeros(7), NAN, "a", 1j]),
        },
        name="make_estimator(bayes)",
        drawn=0,
    )
    out += bad_args(
        I,
        lambda kw: api("encctl_gym.ident.registry:make_estimator")("forgetting", **kw),
        {},
        {"forgetting_factor": explicit([0.0, -0.5, 1.5, NAN, "a", True, None])},
        name="make_estimator(forgetting)",
        drawn=0,
    )
    out += bad_args(
        I,
        lambda kw: api("encctl_gym.ident.registry:make_estimator")("iv", **kw),
        {},
        {"lags": explicit([-1, 0, 2.5, "a", True])},
        name="make_estimator(iv)",
        drawn=0,
    )

    def fit(name: str) -> Any:
        def call(kw: dict[str, Any]) -> Any:
            est = api("encctl_gym.ident.registry:make_estimator")(name)
            return est.fit(**{"x": x, "u": u, **kw})

        return call

    for name in ("ls", "bayes", "forgetting", "iv"):
        out += bad_args(
            I,
            fit(name),
            {},
            {"x": explicit([x + 1j, np.full_like(x, NAN), x[:2], "abc"]), "u": explicit([u[:3], u + 1j])},
            name=f"{name}.fit",
            drawn=0,
        )
    out += bad_args(
        I,
        "encctl_gym.ident.error:estimation_error",
        {"A": A2, "B": B2, "A_hat": A2, "B_hat": B2},
        {"A_hat": explicit([np.eye(3), A2 + 1j, "abc"]), "B_hat": explicit([np.ones((3, 1)), None])},
        drawn=0,
    )
    out += bad_args(
        I,
        "encctl_gym.ident.least_squares:solve_normal_equations",
        {"G": np.eye(3), "C": np.ones((3, 2))},
        {
            "G": explicit([np.eye(2), np.eye(3) * 1j, "abc", np.eye(3)[None, None]]),
            "C": explicit([np.ones((2, 2)), None, np.ones((3, 2)) * 1j]),
        },
        drawn=0,
    )
    return out


def _sim() -> list[Case]:
    out: list[Case] = []
    A2, B2 = np.array([[0.5, 0.1], [0.0, 0.3]]), np.array([[1.0], [0.5]])
    lp = "encctl_gym.sim.plant:LinearPlant"
    out += bad_args(
        S, lp, {"A": A2, "B": B2, "sigma_w2": 0.1}, {"A": BAD["matrix"][:8], "sigma_w2": "pos", "sigma_x2": "nonneg"}, drawn=0
    )
    plant = Lazy(lambda: api(lp)(A2, B2, sigma_w2=0.1), "<plant>")
    out += bad_args(
        S,
        "encctl_gym.sim.plant:simulate",
        {"plant": plant, "inputs": np.zeros((10, 1)), "rng": 0},
        {
            "inputs": explicit([np.zeros((10, 1)) + 1j, np.full((10, 1), NAN), np.zeros((10, 3)), "abc", None, np.zeros((0, 1))]),
            "rng": explicit([-1, 2.5, "a", [1.5]], "traceback"),
            "x0": explicit([np.zeros(3), np.array([1j, 0]), np.array([NAN, 0]), "ab"]),
            "plant": explicit(["abc", None, A2], "traceback"),
        },
        drawn=0,
    )
    out += bad_args(
        S,
        "encctl_gym.sim.plant:simulate_gaussian_attack",
        {"plant": plant, "N": 20, "runs": 3, "sigma_u2": 1.0, "seed": 0},
        {
            "N": BAD["int"] + explicit([10**9, 10**12], "hang"),
            "runs": explicit([0, -1, 2.5, "a", 10**9, 10**12], "hang"),
            "sigma_u2": explicit([-1.0, NAN, "a", HUGE]),
            "seed": explicit([-1, 2.5, "a"]),
        },
        drawn=0,
    )
    out += bad_args(
        S,
        "encctl_gym.sim.montecarlo:gaussian_attack_errors",
        {"plant": plant, "sample_sizes": [10, 20], "runs": 3, "sigma_u2": 1.0, "seed": 0},
        {
            "sample_sizes": explicit([[0], [1, 2], [10**9], "abc", [], [NAN]], "hang"),
            "runs": explicit([0, -1, 10**9], "hang"),
            "method": explicit(["bogus", 3]),
        },
        drawn=0,
    )
    out += bad_args(
        S,
        "encctl_gym.sim.montecarlo:log_grid",
        {"N_min": 10, "N_max": 1000, "points": 5},
        {
            "N_min": explicit([0, -1, 2000, 2.5, "a", NAN]),
            "N_max": explicit([5, NAN, "a", HUGE]),
            "points": explicit([0, -1, 2.5, 10**12, "a"]),
        },
        drawn=0,
    )
    out += bad_args(
        S,
        "encctl_gym.parallel:child_seeds",
        {"seed": 0, "n": 3},
        {"seed": explicit([-1, 2.5, "a", True, [1.5]]), "n": explicit([-1, 2.5, "a", 10**12, HUGE], "hang")},
        drawn=0,
    )
    out += bad_args(
        S,
        "encctl_gym.parallel:run_tasks",
        {"func": lambda t, s: t, "tasks": [1, 2], "seed": 0, "n_jobs": 1},
        {
            "n_jobs": explicit([0, -5, 2.5, "a", True]),
            "backend": explicit(["bogus", 3]),
            "scheduler": explicit([3, ["x"]], "traceback"),
            "func": explicit(["abc", None], "traceback"),
            "tasks": explicit([None, 3], "traceback"),
        },
        drawn=0,
    )
    return out


def cases() -> list[Case]:
    """Every breaker, estimator and engine case."""
    return [*_cryptanalysis(), *_ident(), *_sim()]
