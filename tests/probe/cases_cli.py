"""Probe cases of the command line (:func:`encctl_gym.cli.main`): every subcommand with bad arguments
and bad files. Each must print exactly one line to stderr and exit with code 2.

``train``, ``evaluate`` and ``compare`` belong to the agents' engineer (``owner="agents"``): their
failures are reported, not fixed, on the probe's branch.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .build import FILES, cli, cli_valid, write_file, write_json
from .harness import Case, CliRun

K = "cli"
NUMBERS_BAD = ["abc", "nan", "inf", "-1", "0", "1e400", "9" * 401, "", "1e-6e3", "0x10"]
RL = ("torch", "stable_baselines3", "encctl_gym.agents.train")


def _design() -> list[Case]:
    out: list[Case] = []
    P = ["design", "--preset", "small", "--json"]
    for opt in ("--gamma-c", "--upsilon", "--sigma-u2", "--sigma-w2"):
        for v in NUMBERS_BAD:
            out.append(cli(K, f"design {opt} {v[:12]!r}", [*P, opt, v], "silent"))
    for v in ("-1", "nan", "abc", "1e400"):
        out.append(cli(K, f"design --sigma-x2 {v!r}", [*P, "--sigma-x2", v], "silent"))
    for v in ("abc", "-5y", "1e-300", "0", "nan", "5 parsecs", "9" * 5000, "1e400y", "infs", "10y10y", "1e-20"):
        out.append(cli(K, f"design --tau-c {v[:12]!r}", [*P, "--tau-c", v], "silent"))
    out.append(
        cli(
            K,
            "design paper-example --tau-c 1e-300 (the issue)",
            ["design", "--preset", "paper-example", "--tau-c", "1e-300"],
            "silent",
        )
    )
    for v in ("bogus", "", "['small']", "small,fig1-a"):
        out.append(cli(K, f"design --preset {v!r}", ["design", "--preset", v], "silent"))
    for v in ("bogus", "3"):
        out.append(cli(K, f"design --solver {v!r}", [*P, "--solver", v, "--sdp-max-dim", "48"], "traceback"))
    for v in ("-1", "0", "abc", "2.5"):
        out.append(cli(K, f"design --sdp-max-dim {v!r}", [*P, "--sdp-max-dim", v], "silent"))
    for v in ("bogus", "paper,bogus", "", ",", "all,all,bogus"):
        out.append(cli(K, f"design --cost-model {v!r}", [*P, "--cost-model", v], "silent"))
    for v in ("abc", "nan", "-1", "1e400", "100"):
        out.append(cli(K, f"design --gnfs-correction {v!r}", [*P, "--cost-model", "paper", "--gnfs-correction", v], "silent"))
    out.append(cli(K, "design --complexity bogus", [*P, "--complexity", "bogus"], "traceback"))
    for v in ("0", "-1", "abc", "2.5", "9" * 401, "1e308", "10", "100000000"):
        out.append(cli(K, f"design --key-length {v[:12]!r}", [*P, "--cost-model", "paper", "--key-length", v], "silent"))
    for which in (
        "missing",
        "directory",
        "empty",
        "top_level_list",
        "deep_nesting_json",
        "digits_5000",
        "nan_json",
        "binary_junk",
        "oversized",
        "broken_yaml",
        "hostile_yaml",
    ):
        out.append(
            cli(
                K,
                f"design --calibration {which}",
                lambda tmp, w=which: [*P, "--cost-model", "precomputation", "--calibration", write_file(tmp, w)],
                "traceback",
            )
        )
    for which in FILES:
        out.append(
            cli(
                K,
                f"design FILE={which}",
                lambda tmp, w=which: ["design", write_file(tmp, w), "--json"],
                "hang" if which in ("alias_bomb", "oversized", "deep_nesting_json", "deep_nesting_yaml") else "traceback",
            )
        )
    out.append(
        cli(
            K,
            "design FILE and --preset",
            lambda tmp: ["design", write_json(tmp, "p.json", {"A": [[0.5]], "B": [[1]]}), "--preset", "small"],
            "silent",
        )
    )
    out.append(
        cli(
            K,
            "design FILE with a 200-state plant",
            lambda tmp: ["design", _big_plant(tmp, 200), "--json"],
            "hang",
            expect="either",
            timeout=120,
            slow=True,
        )
    )
    out.append(cli(K, "design --bogus-option", ["design", "--bogus-option"], check_options=False))
    out.append(cli(K, "design --tau-c (no value)", ["design", "--tau-c"], check_options=False))
    out.append(
        cli_valid(
            K, "valid: design --preset paper-example --json", ["design", "--preset", "paper-example", "--json"], _design_json_ok
        )
    )
    return out


def _big_plant(tmp: Path, n: int) -> Path:
    import numpy as np

    A = 0.5 * np.eye(n) + 0.1 * np.eye(n, k=1)
    return write_json(tmp, "big.json", {"A": A.tolist(), "B": np.eye(n).tolist()})


def _design_json_ok(run: CliRun) -> None:
    data = json.loads(run.stdout)
    text = json.dumps(data)
    assert "13159" in text and "712" in text, text[:300]


def _reproduce() -> list[Case]:
    out: list[Case] = []
    base = ["reproduce", "--quick", "--no-progress", "--only", "design"]
    for v in ("-1", "abc", "2.5"):
        out.append(cli(K, f"reproduce --seed {v[:12]!r}", [*base, "--seed", v], "silent"))
    for v in ("0", "abc", "-5", "2.5"):
        out.append(cli(K, f"reproduce --n-jobs {v!r}", [*base, "--n-jobs", v], "silent"))
    out.append(cli(K, "reproduce --only bogus", ["reproduce", "--quick", "--only", "bogus"]))
    out.append(cli(K, "reproduce --scheduler bogus", [*base, "--scheduler", "bogus"], "traceback"))
    out.append(cli(K, "reproduce --out an existing file", lambda tmp: [*base, "--out", _touch(tmp / "afile")], "traceback"))
    out.append(cli(K, "reproduce --out under a file", lambda tmp: [*base, "--out", _touch(tmp / "afile2") / "sub"], "traceback"))
    out.append(cli(K, "reproduce --out /proc (not writable)", [*base, "--out", "/proc/encctl-probe"], "traceback"))
    return out


def _touch(p: Path) -> Path:
    p.write_text("x")
    return p


def _crack() -> list[Case]:
    out: list[Case] = []
    base = ["crack", "--no-progress", "--json"]
    for v in ("0", "1", "-5", "abc", "2.5", "9" * 401, "4096", "100000"):
        out.append(cli(K, f"crack --bits {v[:12]!r}", [*base, "--bits", v, "--keys", "2"], "silent", timeout=30))
    out.append(
        cli(
            K,
            "crack --bits 712 (index calculus) refused before any work",
            [*base, "--bits", "712", "--keys", "2"],
            "hang",
            timeout=30,
        )
    )
    out.append(
        cli(
            K,
            "crack --bits 712 --breaker bsgs refused before any work",
            [*base, "--bits", "712", "--keys", "2", "--breaker", "bsgs"],
            "hang",
            timeout=30,
        )
    )
    for v in ("0", "-1", "abc", "2.5", "9" * 401, "1000000000000"):
        out.append(cli(K, f"crack --keys {v[:12]!r}", [*base, "--bits", "32", "--keys", v], "silent", timeout=30))
    for opt, vals in (("--breaker", ("bogus",)), ("--inner", ("bogus",)), ("--group", ("bogus",))):
        for v in vals:
            out.append(cli(K, f"crack {opt} {v}", [*base, opt, v]))
    for v in ("-1", "abc", "2.5"):
        out.append(cli(K, f"crack --seed {v[:12]!r}", [*base, "--bits", "32", "--keys", "2", "--seed", v], "silent"))
    for v in ("-1", "0", "abc", "nan", "5 parsecs", "1e400"):
        out.append(cli(K, f"crack --time-limit {v!r}", [*base, "--bits", "32", "--keys", "2", "--time-limit", v], "silent"))
    for v in ("-1", "abc", "2.5"):
        out.append(cli(K, f"crack --max-bits {v!r}", [*base, "--bits", "32", "--keys", "2", "--max-bits", v], "silent"))
    out.append(
        cli(
            K,
            "crack --max-bits 100000 --bits 712 refused or bounded",
            [*base, "--bits", "712", "--keys", "1", "--max-bits", "100000", "--breaker", "rho"],
            "hang",
            timeout=30,
        )
    )
    for v in ("0", "abc", "-5"):
        out.append(cli(K, f"crack --n-jobs {v!r}", [*base, "--bits", "32", "--keys", "2", "--n-jobs", v], "silent"))
    out.append(
        cli(K, "crack --scheduler bogus", [*base, "--bits", "32", "--keys", "2", "--scheduler", "bogus"], "traceback", timeout=30)
    )
    out.append(
        cli(K, "crack --breaker token-chain --inner token-chain", [*base, "--breaker", "token-chain", "--inner", "token-chain"])
    )
    out.append(
        cli_valid(K, "valid: crack --bits 32 --keys 3", [*base, "--bits", "32", "--keys", "3", "--breaker", "bsgs"], _crack_ok)
    )
    for breaker in ("rho-multi", "pari"):
        out.append(
            cli(
                K,
                f"crack --breaker {breaker} --max-bits 100000 --bits 712 refused",
                [*base, "--bits", "712", "--keys", "1", "--max-bits", "100000", "--breaker", breaker],
                "hang",
                timeout=30,
            )
        )
    out.append(cli(K, "crack --scheduler tcp:// (no address)", [*base, "--bits", "32", "--keys", "2", "--scheduler", "tcp://"]))
    out.append(
        cli_valid(
            K,
            "valid: crack --keys 1 --json is strict JSON",
            [*base, "--bits", "32", "--keys", "1", "--breaker", "bsgs"],
            _crack_strict_json,
        )
    )
    return out


def _crack_strict_json(run: CliRun) -> None:
    def refuse(constant: str) -> None:
        raise AssertionError(f"the JSON holds {constant}, which is not JSON")

    data = json.loads(run.stdout, parse_constant=refuse)
    assert len(data["keys"]) == 1 and data["keys_match"] is True, run.stdout[:300]


def _crack_ok(run: CliRun) -> None:
    data = json.loads(run.stdout)
    assert "keys" in json.dumps(data), run.stdout[:300]


# --------------------------------------------------------------------------- agents' subcommands (reported)
def _agent(name: str, argv: Any, kind: str = "traceback", **kw: Any) -> Case:
    return cli("agents", name, argv, kind, owner="agents", warm=RL, slow=True, **kw)


def _train_base(tmp: Path) -> list[Any]:
    return [
        "train",
        "--algo",
        "ppo",
        "--preset",
        "small",
        "--quick",
        "--n-timesteps",
        "64",
        "--n-envs",
        "1",
        "--no-progress",
        "--no-tensorboard",
        "--no-final-eval",
        "--out",
        tmp / "runs",
    ]


def _train() -> list[Case]:
    out: list[Case] = []
    out.append(_agent("train --algo bogus", ["train", "--algo", "bogus"]))
    out.append(_agent("train --preset bogus", lambda tmp: [*_train_base(tmp), "--preset", "bogus"], "silent"))
    for opt, vals in (
        ("--n-timesteps", ("0", "-1", "abc", "9" * 401)),
        ("--n-envs", ("0", "-1", "abc", "1000000")),
        ("--seed", ("-1", "abc", "2.5")),
        ("--verbose", ("abc", "7", "-1")),
    ):
        for v in vals:
            out.append(_agent(f"train {opt} {v[:12]!r}", lambda tmp, o=opt, v=v: [*_train_base(tmp), o, v], "silent", timeout=90))
    for which in (
        "missing",
        "broken_yaml",
        "hostile_yaml",
        "hostile_yaml_name",
        "top_level_list",
        "top_level_scalar",
        "alias_bomb",
        "digits_401",
        "binary_junk",
        "oversized",
        "deep_nesting_yaml",
    ):
        out.append(
            _agent(
                f"train --config {which}",
                lambda tmp, w=which: [*_train_base(tmp), "--config", write_file(tmp, w)],
                "hang" if which in ("alias_bomb", "oversized") else "traceback",
                timeout=90,
            )
        )
        out.append(
            _agent(
                f"train --system {which}",
                lambda tmp, w=which: [*_train_base(tmp), "--system", write_file(tmp, w)],
                "hang" if which in ("alias_bomb", "oversized") else "traceback",
                timeout=90,
            )
        )
    for which in ("unknown_key.yaml", "bad_hyper.yaml"):
        text = {"unknown_key.yaml": "bogus_section:\n  x: 1\n", "bad_hyper.yaml": "hyperparams:\n  learning_rate: abc\n"}[which]
        out.append(
            _agent(
                f"train --config {which}",
                lambda tmp, w=which, t=text: [*_train_base(tmp), "--config", _write(tmp / w, t)],
                "silent",
                timeout=90,
            )
        )
    for setting in (
        "policy_kwargs.activation_fn=bogus",
        "bogus.key=1",
        "env.max_samples=abc",
        "env.bogus=1",
        "hyperparams.gamma=2.5",
        "hyperparams.learning_rate=-1",
        "noequals",
        "=1",
        "env.gamma_opt=maybe",
        "hyperparams.n_steps=0",
        "env.x_bound=2e4",
        "hyperparams.batch_size=" + "9" * 401,
        "n_timesteps=!!python/object/apply:os.getcwd []",
        # found while fixing the above: seeds NumPy cannot take, counts no float holds, networks no memory holds
        "seed=4294967296",
        "eval.seed=" + "9" * 401,
        "horizon=" + "9" * 401,
        "eval.final_episodes=" + "9" * 401,
        "n_envs=" + "9" * 401,
        "eval.elgamal.key_length=100000",
        "hyperparams.policy_kwargs.net_arch=[100000000]",
    ):
        out.append(
            _agent(f"train --set {setting[:40]}", lambda tmp, s=setting: [*_train_base(tmp), "--set", s], "silent", timeout=90)
        )
    out.append(_agent("train --out an existing file", lambda tmp: [*_train_base(tmp)[:-1], _touch(tmp / "afile")], timeout=90))
    out.append(
        _agent("train --name ../escape", lambda tmp: [*_train_base(tmp), "--name", "../../escape"], "security", timeout=90)
    )
    out.append(
        _agent("train --name /abs", lambda tmp: [*_train_base(tmp), "--name", "/tmp/encctl-probe-abs"], "security", timeout=90)
    )
    out += _tune()
    return out


def _tune() -> list[Case]:
    """``tune`` (agents/tune.py) shares train's configuration and the CLI's one-line path."""
    out: list[Case] = []
    base = lambda tmp: ["tune", "--algo", "ars", "--preset", "small", "--quick", "--no-progress", "--out", tmp / "tune"]  # noqa: E731
    out.append(_agent("tune --algo bogus", ["tune", "--algo", "bogus"]))
    for opt, vals in (
        ("--trials", ("0", "-1", "abc", "9" * 401)),
        ("--episodes", ("1", "abc", "9" * 401)),
        ("--seed", ("-1", "abc", "4294967296")),
        ("--n-timesteps", ("0", "9" * 401)),
    ):
        for v in vals:
            out.append(_agent(f"tune {opt} {v[:12]!r}", lambda tmp, o=opt, v=v: [*base(tmp), o, v], "silent", timeout=90))
    for setting in ("bogus.key=1", "hyperparams.n_delta=0", "noequals"):
        out.append(_agent(f"tune --set {setting}", lambda tmp, s=setting: [*base(tmp), "--set", s], "silent", timeout=90))
    out.append(
        _agent(
            "tune --config deep_nesting_yaml",
            lambda tmp: [*base(tmp), "--config", write_file(tmp, "deep_nesting_yaml")],
            timeout=90,
        )
    )
    out.append(_agent("tune --out an existing file", lambda tmp: [*base(tmp)[:-1], _touch(tmp / "afile")], timeout=90))
    return out


def _write(p: Path, text: str) -> Path:
    p.write_text(text)
    return p


def _run_dir(tmp: Path, meta: Any, model: bytes | None = None, name: str = "run") -> Path:
    d = tmp / name
    d.mkdir()
    if meta is not None:
        (d / "run.json").write_text(meta if isinstance(meta, str) else json.dumps(meta))
    if model is not None:
        (d / "model.zip").write_bytes(model)
        (d / "best_model.zip").write_bytes(model)
    return d


_META = {
    "algo": "ppo",
    "observation": "full",
    "env": {"preset": "small", "max_samples": 20},
    "system": "small",
    "seed": 0,
    "config": {"algo": "ppo", "system": "small"},
}
_RUNS: dict[str, Callable[[Path], Path]] = {
    "no run.json": lambda tmp: _run_dir(tmp, None, b"x"),
    "broken run.json": lambda tmp: _run_dir(tmp, "{not json", b"x"),
    "run.json a list": lambda tmp: _run_dir(tmp, [1, 2], b"x"),
    "run.json missing algo": lambda tmp: _run_dir(tmp, {"observation": "full", "env": {}}, b"x"),
    "run.json unknown algo": lambda tmp: _run_dir(tmp, {**_META, "algo": "bogus"}, b"x"),
    "run.json bad env": lambda tmp: _run_dir(tmp, {**_META, "env": {"preset": "bogus"}}, b"x"),
    "run.json env x_bound 2e4": lambda tmp: _run_dir(tmp, {**_META, "env": {"preset": "small", "x_bound": 2e4}}, b"x"),
    "run.json 5000 digits": lambda tmp: _run_dir(
        tmp, '{"algo": "ppo", "observation": "full", "env": {}, "seed": ' + "9" * 5000 + "}", b"x"
    ),
    "run.json deep nesting": lambda tmp: _run_dir(
        tmp, '{"algo": "ppo", "observation": "full", "env": ' + "[" * 100000 + "]" * 100000 + "}", b"x"
    ),
    "corrupt model.zip": lambda tmp: _run_dir(tmp, _META, b"PK\x03\x04" + b"\x00" * 40 + b"garbage"),
    "model.zip not a zip": lambda tmp: _run_dir(tmp, _META, b"not a zip at all"),
    "no model.zip": lambda tmp: _run_dir(tmp, _META, None),
    "run dir is a file": lambda tmp: _touch(tmp / "runfile"),
    "run dir missing": lambda tmp: tmp / "nope",
}


def _evaluate() -> list[Case]:
    out: list[Case] = []
    for name, make in _RUNS.items():
        out.append(
            _agent(
                f"evaluate RUN_DIR={name}",
                lambda tmp, mk=make: ["evaluate", mk(tmp), "--episodes", "1", "--no-progress", "--out", tmp / "ev"],
                timeout=90,
            )
        )
    good_meta = lambda tmp: _run_dir(tmp, _META, b"PK\x03\x04" + b"\x00" * 40)  # noqa: E731
    for opt, vals in (
        ("--episodes", ("0", "-1", "abc")),
        ("--systems", ("bogus", "")),
        ("--delays", ("abc", "-1", "2.5", "")),
        ("--samples", ("0", "-1", "abc", "9" * 401)),
        ("--points", ("0", "-1", "abc", "100000000")),
        ("--seed", ("-1", "abc")),
        ("--elgamal-episodes", ("-1", "abc")),
        ("--which", ("bogus",)),
    ):
        for v in vals:
            out.append(
                _agent(
                    f"evaluate {opt} {v!r}",
                    lambda tmp, o=opt, v=v: ["evaluate", good_meta(tmp), o, v, "--no-progress", "--out", tmp / "ev"],
                    "silent",
                    timeout=90,
                )
            )
    return out


def _compare() -> list[Case]:
    out: list[Case] = []
    base = lambda tmp: ["compare", "--quick", "--episodes", "1", "--no-progress", "--elgamal-episodes", "0", "--out", tmp / "cmp"]  # noqa: E731
    for opt, vals in (
        ("--delays", ("abc", "-1", "2.5", "", "0,abc")),
        ("--systems", ("bogus", "", "small,bogus")),
        ("--attackers", ("bogus", "", "gaussian,bogus")),
        ("--episodes", ("0", "-1", "abc", "1000000000000")),
        ("--max-samples", ("0", "-1", "abc", "9" * 401)),
        ("--points", ("0", "-1", "abc", "100000000")),
        ("--seed", ("-1", "abc")),
        ("--elgamal-episodes", ("-1", "abc")),
        ("--which", ("bogus",)),
    ):
        for v in vals:
            out.append(_agent(f"compare {opt} {v[:12]!r}", lambda tmp, o=opt, v=v: [*base(tmp), o, v], "silent", timeout=120))
    for name in ("broken run.json", "corrupt model.zip", "run.json a list", "run dir missing", "run.json deep nesting"):
        out.append(_agent(f"compare --runs {name}", lambda tmp, n=name: [*base(tmp), "--runs", _RUNS[n](tmp)], timeout=120))
    out.append(_agent("compare --out an existing file", lambda tmp: [*base(tmp)[:-1], _touch(tmp / "afile")], timeout=120))
    return out


def _top() -> list[Case]:
    return [
        cli_valid(K, "valid: --version", ["--version"], lambda r: None),
        cli(K, "bogus subcommand", ["bogus"], check_options=False),
    ]


def cases() -> list[Case]:
    """Every command-line case (the agents' subcommands are marked ``owner="agents"``)."""
    out = [*_top(), *_design(), *_reproduce(), *_crack()]
    agents = [*_train(), *_evaluate(), *_compare()]
    return out + agents
