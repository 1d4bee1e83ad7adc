"""Builders of probe cases: a function's parameters crossed with the bad values of their kinds,
single cases, command lines and hostile files."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .harness import CLASSES, Case, CliRun, Lazy, NotApplicable, api, resolve, run_cli
from .values import bad_values, label

__all__ = ["bad_args", "case", "cli", "cli_valid", "Target", "FILES", "write_file", "GROUP64", "TOY"]

Target = str | Callable[[dict[str, Any]], Any]


def _call(target: Target, kwargs: dict[str, Any], needs: Sequence[str]) -> Any:
    if isinstance(target, str):
        fn = api(target, *needs)
        return fn(**kwargs)
    return target(kwargs)


def bad_args(
    area: str,
    target: Target,
    valid: Mapping[str, Any],
    spec: Mapping[str, str | list[tuple[Any, str]]],
    *,
    name: str | None = None,
    drawn: int = 2,
    slow: bool = False,
    timeout: float | None = None,
    expect: str = "error",
) -> list[Case]:
    """One case per parameter of ``spec`` and bad value of its kind: ``target(**valid)`` with that
    one parameter replaced, which must raise an error of the package's hierarchy.

    The first value of each failure class of a parameter is a default case; the others are
    marked slow (``-m slow``), so the default run probes every parameter for every class.

    ``target`` is an :func:`~.harness.api` path (``"encctl_gym.crypto.elgamal:keygen"``; the
    parameters of ``valid`` and ``spec`` must exist, else the case is n/a) or a function of the
    keyword arguments. Values of ``valid`` may be :class:`~.harness.Lazy` (built in the child).
    """
    fname = name or (target.rsplit(":", 1)[-1] if isinstance(target, str) else "call")
    out: list[Case] = []
    for param, kind in spec.items():
        values = bad_values(kind, drawn) if isinstance(kind, str) else kind
        shown: set[str] = set()  # the first value of each class is in the default run, the others in -m slow
        for value, cls in values:
            representative = cls not in shown
            shown.add(cls)
            needs = tuple(dict.fromkeys([*valid, param]))

            def run(_: Path, param: str = param, value: Any = value, needs: tuple[str, ...] = needs) -> Any:
                kwargs = resolve(dict(valid))
                kwargs[param] = resolve(value)
                return _call(target, kwargs, needs)

            out.append(
                Case(
                    f"{area}/{fname}({param}={label(value)})",
                    area,
                    cls,
                    run,
                    expect=expect,
                    slow=slow or not representative,
                    timeout=timeout,
                )
            )
    return out


def case(area: str, name: str, kind: str, run: Callable[[Path], Any], **kw: Any) -> Case:
    """One case (``run(scratch)``); keyword arguments as :class:`~.harness.Case`."""
    return Case(f"{area}/{name}", area, kind, run, **kw)


def cli(
    area: str,
    name: str,
    argv: Sequence[Any] | Callable[[Path], Sequence[Any]],
    kind: str = "traceback",
    *,
    check_options: bool = True,
    expect: str = "cli-error",
    **kw: Any,
) -> Case:
    """A bad command line: ``encctl_gym.cli.main(argv)`` must print one line to stderr and exit 2.

    ``argv`` may be a function of the scratch directory (to write the files it names).
    """

    def run(tmp: Path) -> CliRun:
        args = argv(tmp) if callable(argv) else argv
        return run_cli(list(args), check_options=check_options)

    return Case(f"{area}/{name}", area, kind, run, expect=expect, **kw)


def cli_valid(
    area: str,
    name: str,
    argv: Sequence[Any] | Callable[[Path], Sequence[Any]],
    check: Callable[[CliRun], Any],
    kind: str = "silent",
    **kw: Any,
) -> Case:
    """A valid command line: exit code 0 and ``check(run)``."""

    def run(tmp: Path) -> CliRun:
        args = argv(tmp) if callable(argv) else argv
        return run_cli(list(args))

    return Case(f"{area}/{name}", area, kind, run, expect="result", check=check, **kw)


# --------------------------------------------------------------------------- shared objects
def _group64() -> Any:
    return api("encctl_gym.crypto.group:get_group")(64)


def _toy() -> Any:
    return api("encctl_gym.crypto.group:GroupParams")(23, 11, 4)


GROUP64 = Lazy(_group64, "<64-bit group>")
TOY = Lazy(_toy, "<group (23, 11, 4)>")


# --------------------------------------------------------------------------- hostile files
def _alias_bomb() -> str:
    lines = ["a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 9)]
    return "\n".join(lines) + "\nA: *a8\nB: [[1]]\n"


def _npz(tmp: Path, name: str, **arrays: Any) -> Path:
    path = tmp / name
    np.savez(path, **arrays)
    return path


#: name -> (file name, content); content is text, bytes, or a function of the directory that
#: writes the file and returns its path. Every one is a bad plant, config or records file.
FILES: dict[str, tuple[str, Any]] = {
    "missing": ("missing.yaml", None),
    "directory": ("adir.yaml", lambda tmp: (tmp / "adir.yaml").mkdir() or tmp / "adir.yaml"),
    "empty": ("empty.yaml", ""),
    "broken_yaml": ("broken.yaml", "A: [[0.5, 0.1], [0.0\nB: : :\n  - ]"),
    "hostile_yaml": ("hostile.yaml", "A: !!python/object/apply:os.getcwd []\nB: [[1.0], [0.0]]\n"),
    "hostile_yaml_name": ("hostile2.yaml", "!!python/name:os.system\n"),
    "top_level_list": ("list.yaml", "- 1\n- 2\n"),
    "top_level_scalar": ("scalar.yaml", "42\n"),
    "alias_bomb": ("bomb.yaml", _alias_bomb()),
    "deep_nesting_yaml": ("deep.yaml", "A: " + "[" * 5000 + "]" * 5000 + "\nB: [[1]]\n"),
    "deep_nesting_json": ("deep.json", '{"A": ' + "[" * 100000 + "]" * 100000 + ', "B": [[1]]}'),
    "digits_401": ("digits.json", '{"A": [[' + "9" * 401 + ', 0], [0, 0.5]], "B": [[1], [0]]}'),
    "digits_5000": ("digits5000.json", '{"A": [[' + "9" * 5000 + ', 0], [0, 0.5]], "B": [[1], [0]]}'),
    "nan_json": ("nan.json", '{"A": [[NaN, 0], [0, 0.5]], "B": [[1], [0]]}'),
    "infinity_json": ("inf.json", '{"A": [[Infinity, 0], [0, 0.5]], "B": [[1], [0]]}'),
    "strings_matrix": ("strings.json", '{"A": [["a", "b"], ["c", "d"]], "B": [[1], [0]]}'),
    "bool_matrix": ("bools.json", '{"A": [[true, false], [false, true]], "B": [[1], [0]]}'),
    "ragged": ("ragged.json", '{"A": [[0.5, 0.1], [0.0]], "B": [[1], [0]]}'),
    "non_square": ("nonsq.json", '{"A": [[0.5, 0.1, 0], [0.0, 0.3, 0]], "B": [[1], [0]]}'),
    "unstable": ("unstable.json", '{"A": [[1.5, 0], [0, 0.3]], "B": [[1], [0]]}'),
    "b_rows": ("brows.json", '{"A": [[0.5, 0], [0, 0.3]], "B": [[1], [0], [0]]}'),
    "missing_b": ("nob.json", '{"A": [[0.5, 0], [0, 0.3]]}'),
    "unknown_key": ("unknown.json", '{"A": [[0.5, 0], [0, 0.3]], "B": [[1], [0]], "sigma_q2": 1}'),
    "bad_variance": ("badvar.json", '{"A": [[0.5, 0], [0, 0.3]], "B": [[1], [0]], "sigma_u2": -1}'),
    "string_variance": ("strvar.json", '{"A": [[0.5, 0], [0, 0.3]], "B": [[1], [0]], "sigma_u2": "abc"}'),
    "bad_tau": ("badtau.json", '{"A": [[0.5, 0], [0, 0.3]], "B": [[1], [0]], "tau_c": "5 parsecs"}'),
    "huge_variance": ("hugevar.json", '{"A": [[0.5, 0], [0, 0.3]], "B": [[1], [0]], "sigma_w2": ' + "9" * 401 + "}"),
    "binary_junk": ("junk.json", bytes(range(256)) * 4),
    "utf16": ("utf16.json", '{"A": [[0.5]], "B": [[1]]}'.encode("utf-16")),
    "oversized": ("big.json", lambda tmp: _oversized(tmp)),
    "unknown_suffix": ("plant.txt", '{"A": [[0.5]], "B": [[1]]}'),
    "npz_complex": ("complex.npz", lambda tmp: _npz(tmp, "complex.npz", A=np.array([[0.5, 0.1j], [0, 0.3]]), B=np.ones((2, 1)))),
    "npz_object": (
        "object.npz",
        lambda tmp: _npz(tmp, "object.npz", A=np.array([[0.5, None], [0, 0.3]], dtype=object), B=np.ones((2, 1))),
    ),
    "npz_strings": ("strings.npz", lambda tmp: _npz(tmp, "strings.npz", A=np.array([["a", "b"], ["c", "d"]]), B=np.ones((2, 1)))),
    "npz_missing_b": ("nob.npz", lambda tmp: _npz(tmp, "nob.npz", A=0.5 * np.eye(2))),
    "npz_nan": ("nan.npz", lambda tmp: _npz(tmp, "nan.npz", A=np.array([[np.nan, 0], [0, 0.3]]), B=np.ones((2, 1)))),
    "npz_corrupt": ("corrupt.npz", b"PK\x03\x04" + b"\x00" * 64 + b"garbage"),
    "npz_not_zip": ("notzip.npz", b"this is not a zip file"),
}


def _oversized(tmp: Path) -> Path:
    path = tmp / "big.json"
    with path.open("w") as f:
        f.write('{"A": [[0.5]], "B": [[1]], "pad": "')
        f.seek(80 * 2**20)  # a sparse file: 80 MiB on paper, nothing on disk
        f.write('"}')
    return path


def write_file(tmp: Path, which: str) -> Path:
    """Write the hostile file ``which`` of :data:`FILES` into ``tmp`` and return its path."""
    fname, content = FILES[which]
    if content is None:
        return tmp / fname
    if callable(content):
        return Path(content(tmp))
    path = tmp / fname
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    return path


def write_json(tmp: Path, fname: str, data: Any) -> Path:
    """``data`` as a JSON file in ``tmp``."""
    path = tmp / fname
    path.write_text(json.dumps(data))
    return path


def check_classes(cases: Iterable[Case]) -> None:
    """Every case names a known class (raises ``ValueError``)."""
    for c in cases:
        if c.kind not in CLASSES:
            raise ValueError(c.name)


def not_applicable(why: str) -> None:
    """Raise :class:`~.harness.NotApplicable`."""
    raise NotApplicable(why)
