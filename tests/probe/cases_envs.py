"""Probe cases of the environments (:mod:`encctl_gym.envs`): every configuration key, reset seeds and
options, actions, the vector environment; and their security properties (no party holds
another's randomness, nothing unpaid is observed, breakers refused before any work)."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np

from .build import bad_args, case
from .cases_crypto import _walk
from .harness import Case, NotApplicable, SecurityFinding, api, needs_config
from .values import BAD, HUGE, HUGER, INF, NAN, explicit

E = "envs"
V = "vector"
BASE = {"preset": "small", "gamma_opt": False}
ENV = "encctl_gym.envs.encrypted_lti_attack:EncryptedLTIAttackEnv"
VEC = "encctl_gym.envs.vector:EncryptedLTIAttackVectorEnv"
A2 = np.array([[0.6, 0.2], [-0.1, 0.5]])
B2 = np.array([[1.0, 0.0], [0.3, 0.8]])


def _make(config: dict[str, Any], **kwargs: Any) -> Any:
    needs_config(*[k for k in config if k not in ("bogus_key",)])
    return api(ENV)(config=config, **kwargs)


def _play(config: dict[str, Any], steps: int = 3) -> Any:
    """Make, reset and step: a bad configuration must raise somewhere in these."""
    env = _make(config)
    env.reset(seed=0)
    for _ in range(steps):
        _, _, term, trunc, info = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
        if term or trunc:
            break
    return info


def _finite_rewards(config: dict[str, Any]) -> None:
    env = _make(config)
    env.reset(seed=0)
    for t in range(40):
        _, r, term, trunc, _ = env.step(np.full(env.action_space.shape, 0.5, dtype=np.float32))
        assert np.isfinite(r), f"reward {r} at step {t}"
        if term or trunc:
            break


def _config_cases() -> list[Case]:
    def play(kw: dict[str, Any]) -> Any:
        return _play({**BASE, **kw})

    spec: dict[str, Any] = {
        "preset": explicit(["bogus", "", ["small"], 3, {"name": "small"}, b"small"]),
        "A": [(v, c) for v, c in BAD["matrix"] if v is not None] + explicit([np.array([[1.5, 0], [0, 0.5]]), np.eye(3) * 0.5]),
        "B": explicit(
            [
                np.ones((3, 2)),
                np.array([[1 + 1j, 0], [0, 1]]),
                np.array([[NAN, 0], [0, 1]]),
                "abc",
                np.ones((2, 2, 1)),
                np.zeros((2, 0)),
            ]
        ),
        "sigma_w2": "pos?",
        "sigma_x2": "nonneg?",
        "sigma_u2": "pos?",
        "scheme": "name",
        "adversary": "name",
        "security_parameter": [(v, c) for v, c in BAD["pos"] if v is not None] + explicit([1e12, 2.0**53, 1e300], "hang"),
        "key_length": [(v, c) for v, c in BAD["int"] if v is not None]
        + explicit([1e308, 10**308, 2**40], "hang")
        + explicit([39, 10], "silent"),
        "upsilon": "pos?",
        "tau_c": [(v, c) for v, c in BAD["duration"] if v is not None] + explicit([1e-300, 1e-30, "1e-300s"], "silent"),
        "gamma_c": "pos?",
        "max_samples": [(v, c) for v, c in BAD["int"] if v is not None and not (isinstance(v, int) and v > 10**300)],
        "decipher_delay": explicit([-1, 2.5, "soon", "END", np.array([1, 2]), True, NAN, [3], 3 + 0j]),
        "warmup_steps": BAD["int0"] + explicit([10**9, 10**12, HUGE], "hang"),
        "estimator": explicit(
            [
                "bogus",
                {"name": "bogus"},
                {"name": "bayes", "bogus": 1},
                3,
                {"name": "forgetting", "forgetting_factor": 2.0},
                {},
                {"name": "bayes", "prior_variance": -1.0},
                ["ls"],
                {"name": "iv", "lags": -1},
            ]
        ),
        "reward": "name",
        "logdet_regularization": BAD["pos"],
        "crypto": "name",
        "delta": BAD["pos"] + explicit([2.5, 0.5, 1e300, 2**200], "silent"),
        "x_bound": BAD["pos"] + explicit([2e4, 1e6, 1e300], "hang"),
        "action_scale": BAD["pos"] + explicit([1e308, 1e300], "silent"),
        "input_history": BAD["int0"] + explicit([10**9, 10**7, HUGE], "hang"),
        "gamma_opt": "bool",
        "crypto_seed": "seed?",
        "deciphering_model": "name?",  # None: the scheme's baseline model
        "gnfs_correction": explicit(["bogus", NAN, -1.0, HUGE, 1e308, True, None]),
        "deciphering_clock": explicit(["bogus", 3, None, "MODEL"]),
        "bogus_key": explicit([1], "silent"),
    }
    out = bad_args(E, play, {}, spec, name="config", drawn=1)
    # keys the issue names, with the settings they need
    elg = {**BASE, "crypto": "elgamal", "key_length": 64, "max_samples": 20}
    out += bad_args(
        E,
        lambda kw: _play({**elg, "breaker": "index-calculus", **kw}),
        {},
        {
            "breaker_time_limit": explicit([-1.0, 0.0, NAN, "abc", True, HUGE, None, "5 parsecs"]),
            "deciphering_clock": explicit(["bogus", 3]),
        },
        name="config(breaker)",
        drawn=0,
    )
    out += bad_args(
        E,
        lambda kw: _play({**BASE, **kw}),
        {},
        {
            "breaker": explicit(["bogus", 3, ["bsgs"], "index-calculus"]),  # the last needs crypto="elgamal"
            "deciphering_clock": explicit(["measured"]),
        },
        name="config(ideal)",
        drawn=0,
    )
    for breaker in ("bsgs", "index-calculus", "rho", "rho-multi", "token-chain"):
        out.append(
            case(
                E,
                f"config(breaker={breaker}, key_length=712) refused before any work",
                "hang",
                lambda _, b=breaker: _make({**BASE, "crypto": "elgamal", "key_length": 712, "max_samples": 20, "breaker": b}),
                timeout=30,
            )
        )
    out.append(
        case(
            E,
            "config(deciphering_clock=measured, no max_samples)",
            "silent",
            lambda _: _play(
                {**BASE, "crypto": "elgamal", "key_length": 64, "breaker": "index-calculus", "deciphering_clock": "measured"}
            ),
        )
    )
    out.append(
        case(
            E,
            "config(security_parameter=128) works or is refused quickly",
            "hang",
            lambda _: _play({**BASE, "security_parameter": 128}),
            expect="either",
            timeout=30,
        )
    )
    out.append(
        case(
            E,
            "config(key_length=3000, ideal) works or is refused quickly",
            "hang",
            lambda _: _play({**BASE, "key_length": 3000}),
            expect="either",
            timeout=30,
        )
    )
    out.append(
        case(
            E,
            "config(upsilon=tau_c=1e300) works or is refused quickly",
            "hang",
            lambda _: _play({**BASE, "upsilon": 1e300, "tau_c": 1e300}),
            expect="either",
            timeout=30,
        )
    )
    out.append(
        case(
            E,
            "config(security_parameter and key_length disagree)",
            "silent",
            lambda _: _play({**BASE, "security_parameter": 74, "key_length": 2048}),
        )
    )
    out.append(case(E, "config(A without B)", "silent", lambda _: _play({**BASE, "preset": None, "A": A2})))
    for reward in ("logdet", "a_optimality"):
        for reg in (1e-300, 1e-320, 5e-324):
            out.append(
                case(
                    E,
                    f"config(reward={reward}, logdet_regularization={reg:g}) gives finite rewards or an error",
                    "silent",
                    lambda _, r=reward, g=reg: _finite_rewards({**BASE, "reward": r, "logdet_regularization": g}),
                    expect="either",
                )
            )
    out.append(case(E, "config(preset=None, nothing else)", "silent", lambda _: _play({**BASE, "preset": None})))
    out.append(case(E, "config(max_samples below n+m+1 with gamma)", "silent", lambda _: _play({**BASE, "max_samples": 0})))
    # the configuration argument itself
    out += bad_args(
        E,
        lambda kw: api(ENV)(**kw),
        {"config": BASE},
        {
            "config": explicit(["abc", [1, 2], {1: 2}, 42, ("preset", "small")], "traceback"),
            "render_mode": explicit(["bogus", 3, "human", ["rgb_array"]]),
            "bogus_kwarg": explicit([1], "silent"),
        },
        name="EncryptedLTIAttackEnv",
        drawn=0,
    )
    return out


def _reset_step_cases() -> list[Case]:
    out: list[Case] = []

    def reset(kw: dict[str, Any]) -> Any:
        env = _make(dict(BASE))
        return env.reset(**kw)

    out += bad_args(
        E,
        reset,
        {},
        {
            "seed": explicit([True, False, -1, 2.5, "a", [1, 2], NAN, 3 + 0j, np.array([1, 2])]),
            "options": explicit(
                [
                    "abc",
                    {"bogus": 1},
                    {"x0": np.array([1 + 1j, 0])},
                    {"x0": np.zeros(3)},
                    {"x0": np.array([NAN, 0.0])},
                    {"x0": "abc"},
                    {"noise": np.zeros((5, 7))},
                    {"noise": np.zeros((10**3, 2), dtype=complex)},
                    {"noise": "abc"},
                    [1],
                    {"x0": np.array([HUGE, 0], dtype=object)},
                    {"noise": np.full((10**4, 2), NAN)},
                ]
            ),
        },
        name="reset",
        drawn=0,
    )

    def step(kw: dict[str, Any]) -> Any:
        env = _make(dict(BASE))
        env.reset(seed=0)
        return env.step(**kw)

    actions = explicit(
        [
            np.array([NAN, 0.0], dtype=np.float32),
            np.array([INF, 0.0]),
            np.array([0.5 + 1j, 0.0]),
            np.array(["a", "b"]),
            "ab",
            np.zeros(3),
            None,
            np.array([2.0, 0.0]),
            {"a": 1},
            np.array([0.1, None], dtype=object),
            [0.1, "x"],
            np.array([True, False]),
            0.5,
            [HUGE, 0],
            np.zeros((2, 2)),
        ]
    )
    out += bad_args(E, step, {}, {"action": actions}, name="step", drawn=0)

    def step_before_reset(_: Path) -> Any:
        return _make(dict(BASE)).step(np.zeros(2, dtype=np.float32))

    def step_after_end(_: Path) -> Any:
        env = _make({**BASE, "max_samples": 8})
        env.reset(seed=0)
        for _ in range(100):
            _, _, term, trunc, _ = env.step(np.zeros(2, dtype=np.float32))
            if term or trunc:
                break
        return env.step(np.zeros(2, dtype=np.float32))

    out.append(case(E, "step before reset", "silent", step_before_reset))
    out.append(case(E, "step after the episode ended", "silent", step_after_end))
    return out


def _vector_cases() -> list[Case]:
    out: list[Case] = []

    def make(kw: dict[str, Any]) -> Any:
        env = api(VEC)(**{"num_envs": 2, "config": dict(BASE), "helper_thread": False, **kw})
        try:
            env.reset(seed=0)
            env.step(np.zeros((env.num_envs, 2), dtype=np.float32))
        finally:
            env.close()

    out += bad_args(
        V,
        make,
        {},
        {
            "num_envs": BAD["int"] + explicit([10**6, 10**9], "hang"),
            "config": explicit(["abc", [1], {"preset": "bogus"}, {"bogus_key": 1}, {"gamma_opt": "no"}, {"x_bound": 2e4}]),
            "max_episode_steps": explicit([0, -1, 2.5, "a", True, NAN]),
            "parallel": explicit(["no", 0, 1, None, NAN]),
            "helper_thread": explicit(["no", 0, 1, None, 3.5, "abc"]),
        },
        name="EncryptedLTIAttackVectorEnv",
        drawn=0,
    )
    out.append(
        case(
            V,
            "EncryptedLTIAttackVectorEnv(num_envs=10**6) refused with an estimate",
            "hang",
            lambda _: api(VEC)(num_envs=10**6, config={"preset": "paper-example", "gamma_opt": False}, helper_thread=False),
            timeout=30,
        )
    )

    def reset(kw: dict[str, Any]) -> Any:
        env = api(VEC)(num_envs=2, config=dict(BASE), helper_thread=False)
        try:
            return env.reset(**kw)
        finally:
            env.close()

    out += bad_args(
        V,
        reset,
        {},
        {
            "seed": explicit([True, -1, 2.5, "a", [1, 2, 3], [1, "a"], [True, False], NAN]),
            "options": explicit(["abc", {"bogus": 1}, {"x0": np.zeros((3, 2))}, {"x0": np.full((2, 2), 1j)}]),
        },
        name="vector.reset",
        drawn=0,
    )

    def step(kw: dict[str, Any]) -> Any:
        env = api(VEC)(num_envs=2, config=dict(BASE), helper_thread=False)
        try:
            env.reset(seed=0)
            return env.step(**kw)
        finally:
            env.close()

    out += bad_args(
        V,
        step,
        {},
        {
            "actions": explicit(
                [
                    np.zeros((2, 3)),
                    np.zeros(2),
                    np.zeros((3, 2)),
                    np.full((2, 2), NAN),
                    np.full((2, 2), 1j),
                    np.array([["a", "b"], ["c", "d"]]),
                    None,
                    "ab",
                    np.full((2, 2), 2.0),
                    [[0.1, None], [0, 0]],
                ]
            )
        },
        name="vector.step",
        drawn=0,
    )

    def step_before_reset(_: Path) -> Any:
        env = api(VEC)(num_envs=2, config=dict(BASE), helper_thread=False)
        try:
            return env.step(np.zeros((2, 2), dtype=np.float32))
        finally:
            env.close()

    out.append(case(V, "vector.step before reset", "silent", step_before_reset))
    return out


# --------------------------------------------------------------------------- security
def _random_sources(obj: Any) -> list[Any]:
    rs = api("encctl_gym.crypto.arith:RandomSource")
    found: list[Any] = []
    seen: set[int] = set()
    todo = [obj]
    while todo:
        o = todo.pop()
        if id(o) in seen or isinstance(o, (str, bytes, int, float, np.ndarray, type)):
            continue
        seen.add(id(o))
        if isinstance(o, rs):
            found.append(o)
            continue
        if isinstance(o, dict):
            todo.extend(o.values())
        elif isinstance(o, (list, tuple)):
            todo.extend(o)
        elif type(o).__module__.startswith("encctl_gym"):
            todo.extend(getattr(o, s) for s in getattr(type(o), "__slots__", ()) if hasattr(o, s))
            todo.extend(getattr(o, "__dict__", {}).values())
    return found


def _first_draws(src: Any, k: int = 4) -> tuple[int, ...]:
    clone = copy.deepcopy(src)
    return tuple(int(clone.below(2**64)) for _ in range(k))


def _server_randomness(scheme: str, seed: int | None) -> Any:
    def run(_: Path) -> None:
        env = _make(
            {
                **BASE,
                "crypto": "elgamal",
                "key_length": 64,
                "max_samples": 20,
                "scheme": scheme,
                "crypto_seed": seed,
                **({"adversary": "server"} if scheme == "token" else {}),
            }
        )
        env.reset(seed=0)
        env.step(np.zeros(2, dtype=np.float32))
        loop = getattr(env.unwrapped, "loop", None) or getattr(env.unwrapped, "_loop", None)
        server, plant = getattr(loop, "server", None), getattr(loop, "plant", None)
        if server is None or plant is None:
            raise NotApplicable("no loop.server / loop.plant")
        s_src, p_src = _random_sources(server), _random_sources(plant)
        shared = [s for s in s_src if any(s is p for p in p_src)]
        if shared:
            raise SecurityFinding(f"the {scheme} server holds the plant's own random source {shared[0]!r}")
        if seed is not None:
            plant_draws = {_first_draws(p) for p in p_src if not getattr(p, "secure", False)}
            for s in s_src:
                if not getattr(s, "secure", False) and _first_draws(s) in plant_draws:
                    raise SecurityFinding(f"the {scheme} server's random stream repeats the plant's draws")
        sk_cls = api("encctl_gym.crypto.elgamal:SecretKey")
        held = _walk(server, (sk_cls,))
        if held:
            raise SecurityFinding(f"the {scheme} server holds a secret key: {held[:2]}")

    return run


def _parties_distinct_streams(_: Path) -> None:
    """With one crypto_seed, every party's stream is different (none can recompute another's)."""
    env = _make({**BASE, "crypto": "elgamal", "key_length": 64, "max_samples": 20, "crypto_seed": 123})
    loop = getattr(env.unwrapped, "loop", None) or getattr(env.unwrapped, "_loop", None)
    sources = getattr(loop, "random_sources", None)
    if not isinstance(sources, dict):
        raise NotApplicable("no loop.random_sources")
    draws = {name: _first_draws(src) for name, src in sources.items()}
    if len(set(draws.values())) != len(draws):
        raise SecurityFinding(f"two parties share a random stream: {sorted(draws)}")


def _blind_until_end(_: Path) -> None:
    env = _make({**BASE, "decipher_delay": "end", "max_samples": 30})
    obs, _ = env.reset(seed=0)
    n, m = env.unwrapped.params.n, env.unwrapped.params.m
    for t in range(200):
        if np.any(obs[: n + m + 1] != 0):
            raise SecurityFinding(f"with decipher_delay='end' the observation at step {t} holds state data {obs[: n + m + 1]}")
        obs, _, term, trunc, _ = env.step(np.full(m, 0.3, dtype=np.float32))
        if term or trunc:
            return


def _delay_respected(_: Path) -> None:
    """With decipher_delay = d the state x_j is observed at step j + d, never before."""
    d = 3
    env = _make({**BASE, "decipher_delay": d, "max_samples": 25})
    obs, _ = env.reset(seed=0)
    n = env.unwrapped.params.n
    true_states = []
    core = env.unwrapped.episode
    for t in range(20):
        obs, _, term, trunc, _ = env.step(np.full(2, 0.2, dtype=np.float32))
        if term or trunc:
            break
        delivered = int(core.delivered) if np.ndim(core.delivered) == 0 else int(np.asarray(core.delivered).ravel()[0])
        collected = int(core.collected) if np.ndim(core.collected) == 0 else int(np.asarray(core.collected).ravel()[0])
        if delivered > max(0, collected - d):
            raise SecurityFinding(f"step {t}: {delivered} samples delivered of {collected} collected with delay {d}")
        true_states.append(obs[:n].copy())


def _privileged_documented(_: Path) -> None:
    doc = api(ENV).__doc__ or ""
    if "rivileged" not in doc or "epsilon" not in doc:
        raise SecurityFinding("the environment's docstring does not mark the plant-dependent info (epsilon, ...) as privileged")


def _security_cases() -> list[Case]:
    S = "security"
    out = [
        case(
            E,
            f"the {s} server holds none of the plant's randomness (crypto_seed={seed})",
            S,
            _server_randomness(s, seed),
            expect="result",
        )
        for s in ("modified", "token", "static")
        for seed in (123, None)
    ]
    out += [
        case(E, "each party has its own stream under one crypto_seed", S, _parties_distinct_streams, expect="result"),
        case(E, "decipher_delay='end': nothing delivered before the end", S, _blind_until_end, expect="result"),
        case(E, "decipher_delay=3: no sample delivered early", S, _delay_respected, expect="result"),
        case(E, "privileged info is documented", S, _privileged_documented, expect="result"),
    ]
    return out


def _valid_cases() -> list[Case]:
    def budget(_: Path) -> None:
        env = _make({"preset": "paper-example", "gamma_opt": False, "scheme": "static", "max_samples": 50})
        p = env.unwrapped.params
        assert (p.security_parameter, p.key_length) == (74, 712) or p.key_length == 712, (p.security_parameter, p.key_length)

    def ideal_equals_elgamal(_: Path) -> None:
        cfg = {**BASE, "key_length": 64, "max_samples": 15, "crypto_seed": 3}
        traj = []
        for crypto in ("ideal", "elgamal"):
            env = _make({**cfg, "crypto": crypto})
            obs, _ = env.reset(seed=4)
            rows = [obs]
            for _ in range(10):
                obs, *_ = env.step(np.array([0.3, -0.2], dtype=np.float32))
                rows.append(obs)
            traj.append(np.array(rows))
        assert np.array_equal(traj[0], traj[1])

    return [
        case(E, "valid: the paper example's key length", "silent", budget, expect="result"),
        case(E, "valid: ideal and ElGamal backends agree bit for bit", "silent", ideal_equals_elgamal, expect="result"),
    ]


def cases() -> list[Case]:
    """Every environment case."""
    return [*_config_cases(), *_reset_step_cases(), *_vector_cases(), *_security_cases(), *_valid_cases()]


_ = HUGER
