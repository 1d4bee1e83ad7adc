"""The probe's harness: cases, outcome classes and bounded children.

A :class:`Case` states what a call must do: ``expect="error"`` (the input is invalid: an error of
:mod:`encctl_gym.errors` is due), ``"result"`` (the input is valid: a result is due, checked by
``check``), ``"either"`` (a clear package error or a correct result), ``"cli-error"`` (a command
line that must print one line to stderr and exit with code 2). Its outcome is ``ok`` or one of
the failure classes of the issue:

============  =================================================================================
class         what happened
============  =================================================================================
hang          no result within the timeout, ``MemoryError``, or the child was killed (memory cap,
              ``bad_alloc``, a signal): the call never returns or exhausts memory
silent        a result where an error is due, or a wrong result (``check`` failed)
traceback     an exception that is not an ``EncctlError`` (or an ``EncctlError`` for a valid
              input); a command line that does not print exactly one line to stderr with exit
              code 2
security      a security property is violated (:class:`SecurityFinding`)
============  =================================================================================

A case whose public name, parameter, configuration key or subcommand option does not exist in the
checkout under test is ``n/a`` (:class:`NotApplicable`, raised by :func:`api`, :func:`needs_config`
and the command-line runner): the probe runs unchanged against older checkouts.

Every case runs in a forked child: :func:`run_cases` forks one child for a list of cases, which
reports each case as it finishes (per-case attribution); a case that passes its timeout or
kills its child is recorded and a fresh child takes the remaining cases. The child's address
space is capped before each case at what it maps then plus :data:`EXTRA_MEMORY`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import gc
import importlib
import inspect
import io
import multiprocessing as mp
import os
import resource
import shutil
import signal
import sys
import tempfile
import time
import traceback
import warnings
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

__all__ = [
    "CLASSES",
    "OUTCOMES",
    "EXPECTS",
    "TIMEOUT_S",
    "EXTRA_MEMORY",
    "Case",
    "Result",
    "CliRun",
    "Lazy",
    "NotApplicable",
    "SecurityFinding",
    "WrongResult",
    "api",
    "needs_config",
    "resolve",
    "run_cli",
    "execute",
    "run_cases",
    "run_bounded",
    "fork_available",
]

#: The failure classes of the probe.
CLASSES: tuple[str, ...] = ("security", "hang", "silent", "traceback")
#: Every outcome of a case.
OUTCOMES: tuple[str, ...] = ("ok", *CLASSES, "n/a")
#: What a case may expect.
EXPECTS: tuple[str, ...] = ("error", "result", "either", "cli-error")

TIMEOUT_S = 60.0  # generous for a loaded 2-core machine; a case takes well under a second alone
EXTRA_MEMORY = 512 * 2**20  # address space a case may add to what its child maps when it starts
WARM_TIMEOUT_S = 300.0  # importing the modules a batch needs (torch, stable-baselines3)


class NotApplicable(Exception):
    """A name the case needs does not exist in the checkout under test."""


class SecurityFinding(AssertionError):
    """A security property is violated (related keys, shared randomness, a cross-group decryption
    that returns a number, degenerate keys accepted, ...)."""


class WrongResult(AssertionError):
    """A valid input gave a wrong result."""


@dataclasses.dataclass(frozen=True)
class Lazy:
    """A value built in the child (groups, keys, environments): ``factory()``."""

    factory: Callable[[], Any]
    label: str = "<lazy>"

    def __repr__(self) -> str:
        return self.label


def resolve(value: Any) -> Any:
    """``value`` with every :class:`Lazy` inside dicts, lists and tuples built."""
    if isinstance(value, Lazy):
        return value.factory()
    if isinstance(value, dict):
        return {k: resolve(v) for k, v in value.items()}
    if isinstance(value, list):
        return [resolve(v) for v in value]
    if isinstance(value, tuple):
        return tuple(resolve(v) for v in value)
    return value


def _import(module: str) -> Any:
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        missing = exc.name or module
        if module == missing or module.startswith(missing + "."):
            raise NotApplicable(f"no module {module}") from None
        raise


def api(path: str, *params: str) -> Any:
    """The object at ``"package.module:name.attr"``; :class:`NotApplicable` if the module, the name or
    one of the parameters ``params`` of the callable does not exist in this checkout."""
    module, _, attrs = path.partition(":")
    obj = _import(module)
    for attr in attrs.split(".") if attrs else ():
        if not hasattr(obj, attr):
            raise NotApplicable(f"no {path}")
        obj = getattr(obj, attr)
    if params:
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):  # pragma: no cover - builtins
            return obj
        names = set(sig.parameters)
        missing = [p for p in params if p not in names]
        if missing:
            raise NotApplicable(f"{path} has no parameter {missing}")
    return obj


def needs_config(*keys: str) -> None:
    """:class:`NotApplicable` unless every key is in the environment's ``default_config()``."""
    default = api("encctl_gym.envs.config:default_config")()
    missing = [k for k in keys if k not in default]
    if missing:
        raise NotApplicable(f"no configuration key {missing}")


@dataclasses.dataclass(frozen=True)
class Case:
    """One probe case.

    Parameters
    ----------
    name : str
        Unique, readable (``area/function(param=value)``).
    area : str
        The layer probed: crypto, security, envs, vector, cryptanalysis, ident, sim, cli, agents.
    kind : str
        The class of :data:`CLASSES` the case was written to catch.
    run : callable
        ``run(scratch)`` with a fresh scratch directory (also the working directory).
    expect : str
        One of :data:`EXPECTS`.
    check : callable, optional
        ``check(result)`` for a result: raises ``AssertionError`` (silent), :class:`SecurityFinding`
        (security) when the result is wrong.
    slow : bool
        Part of ``-m slow`` only.
    timeout : float, optional
        Seconds allowed (default :data:`TIMEOUT_S`).
    warm : tuple of str
        Modules the child imports before its first case (not counted against a case's time or
        memory: torch, stable-baselines3).
    owner : str
        Who fixes a failure: ``"library"`` or ``"agents"`` (the agents' engineer; failures there
        are reported, not fixed, on this branch).
    """

    name: str
    area: str
    kind: str
    run: Callable[[Path], Any]
    expect: str = "error"
    check: Callable[[Any], Any] | None = None
    slow: bool = False
    timeout: float | None = None
    warm: tuple[str, ...] = ()
    owner: str = "library"

    def __post_init__(self) -> None:
        if self.kind not in CLASSES:
            raise ValueError(f"case {self.name}: unknown class {self.kind!r}")
        if self.expect not in EXPECTS:
            raise ValueError(f"case {self.name}: unknown expectation {self.expect!r}")


@dataclasses.dataclass(frozen=True)
class Result:
    """The outcome of one case: ``outcome`` in :data:`OUTCOMES`, a ``detail`` and the seconds taken."""

    name: str
    outcome: str
    detail: str = ""
    seconds: float = 0.0


@dataclasses.dataclass(frozen=True)
class CliRun:
    """What a command line did: exit code, stdout and the non-empty stderr lines."""

    rc: int
    stdout: str
    stderr_lines: tuple[str, ...]


def run_cli(argv: Sequence[str], *, check_options: bool = True) -> CliRun:
    """``encctl_gym.cli.main(argv)`` with stdout and stderr captured (``SystemExit`` is its code).

    With ``check_options``, a subcommand or an option (``--name``) that the checkout's parser does
    not know makes the case :class:`NotApplicable` (set it to False for cases that pass an unknown
    option on purpose).
    """
    cli = api("encctl_gym.cli:main")
    commands = api("encctl_gym.cli:SUBCOMMANDS")
    argv = [str(a) for a in argv]
    if check_options and argv and not argv[0].startswith("-"):
        if argv[0] not in commands:
            raise NotApplicable(f"no subcommand {argv[0]!r}")
        _check_options(argv[0], argv[1:])
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = cli(argv)
        except SystemExit as exc:  # argparse, --help
            code = exc.code
            rc = code if isinstance(code, int) else (0 if code is None else 1)
    lines = tuple(line for line in err.getvalue().splitlines() if line.strip())
    return CliRun(int(rc) if isinstance(rc, int) else -1, out.getvalue(), lines)


@functools.cache
def _known_options(command: str) -> frozenset[str]:
    build = api("encctl_gym.cli:build_parser")
    parser = build(command)
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")  # noqa: SLF001
    return frozenset(sub.choices[command]._option_string_actions)  # noqa: SLF001


def _check_options(command: str, args: Sequence[str]) -> None:
    known = _known_options(command)
    for a in args:
        if a.startswith("--"):
            opt = a.split("=", 1)[0]
            if opt not in known:
                raise NotApplicable(f"{command} has no option {opt}")


# --------------------------------------------------------------------------- running one case
def _short(text: str, limit: int = 1500) -> str:
    return text if len(text) <= limit else text[: limit // 2] + " ... " + text[-limit // 2 :]


def _classify_cli(case: Case, run: CliRun) -> tuple[str, str]:
    said = " | ".join(run.stderr_lines)[:600]
    if case.expect == "cli-error":
        if run.rc == 2 and len(run.stderr_lines) == 1 and "Traceback" not in said:
            return "ok", said
        if run.rc == 0:
            return "silent", f"exit code 0 for a bad input; stderr: {said!r}; stdout: {run.stdout[-300:]!r}"
        return "traceback", f"exit code {run.rc} with {len(run.stderr_lines)} stderr line(s): {said!r}"
    if run.rc != 0:
        if case.expect == "either" and run.rc == 2 and len(run.stderr_lines) == 1:
            return "ok", said
        return "traceback", f"exit code {run.rc} for a valid command line: {said!r}"
    return "", ""


def execute(case: Case, scratch: Path) -> tuple[str, str]:
    """Run ``case`` here (in the child) and classify what it did; returns ``(outcome, detail)``."""
    from encctl_gym.errors import EncctlError

    try:
        result = case.run(scratch)
        if isinstance(result, CliRun):
            outcome, detail = _classify_cli(case, result)
            if outcome:
                return outcome, detail
        if case.expect == "error":
            from encctl_gym._validation import format_value

            return "silent", f"returned {format_value(result)} where an error is due"
        if case.check is not None:
            case.check(result)
        return "ok", ""
    except NotApplicable as exc:
        return "n/a", str(exc)
    except MemoryError:
        return "hang", "MemoryError (the memory cap)"
    except SecurityFinding as exc:
        return "security", _short(str(exc))
    except (WrongResult, AssertionError) as exc:
        return "silent", _short(f"wrong result: {exc}")
    except EncctlError as exc:
        text = str(exc)
        if "\n" in text.strip() or not text.strip():
            return "traceback", _short(f"{type(exc).__name__} without a one-line message: {text!r}")
        if case.expect in ("error", "either"):
            return "ok", _short(f"{type(exc).__name__}: {text}", 400)
        return "traceback", _short(f"refused a valid input: {type(exc).__name__}: {text}")
    except RecursionError as exc:
        return "traceback", _short(f"RecursionError: {exc}")
    except BaseException as exc:  # noqa: BLE001 - every other exception is the finding
        if isinstance(exc, KeyboardInterrupt):
            raise
        tail = traceback.format_exc()[-900:]
        return "traceback", _short(f"{type(exc).__name__}: {str(exc)[:300]}\n{tail}")


# --------------------------------------------------------------------------- children
def fork_available() -> bool:
    """Whether bounded children can be forked here (Linux with /proc)."""
    return sys.platform == "linux" and "fork" in mp.get_all_start_methods() and Path("/proc/self/status").exists()


def _vm_size() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmSize:"):
            return int(line.split()[1]) * 1024
    raise RuntimeError("no VmSize")  # pragma: no cover


def _cap_memory(extra: int) -> None:
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    want = _vm_size() + extra
    if hard != resource.RLIM_INFINITY:
        want = min(want, hard)
    resource.setrlimit(resource.RLIMIT_AS, (want, hard))


def _uncap_memory() -> None:
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (hard, hard))


def _batch_child(cases: Sequence[Case], conn: Any, extra: int, scratch_root: str) -> None:
    try:
        os.setsid()  # its own process group: a timeout kills whatever it started too
    except OSError:  # pragma: no cover
        pass
    devnull = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(devnull, fd)
    try:
        warm = list(dict.fromkeys(m for c in cases for m in c.warm))
        for module in warm:
            with contextlib.suppress(Exception):
                importlib.import_module(module)
        import encctl_gym.errors  # noqa: F401 - execute needs it

        gc.freeze()  # what the child inherited is never collected: the collection after each case stays cheap
        conn.send(("ready",))
        for i, case in enumerate(cases):
            scratch = Path(scratch_root) / f"case{os.getpid()}_{i}"
            scratch.mkdir(parents=True, exist_ok=True)
            os.chdir(scratch)
            t0 = time.perf_counter()
            out, err = io.StringIO(), io.StringIO()
            with warnings.catch_warnings(record=True):
                warnings.simplefilter("always")
                with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                    try:
                        _cap_memory(extra)
                        outcome, detail = execute(case, scratch)
                    finally:
                        _uncap_memory()
            conn.send((case.name, outcome, detail, time.perf_counter() - t0))
            gc.collect()
    except BaseException:  # noqa: BLE001 - the parent sees a dead child
        pass
    finally:
        with contextlib.suppress(Exception):
            conn.close()
        os._exit(0)


def _kill(proc: Any) -> None:
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(proc.pid, signal.SIGKILL)  # the child's own group (it called setsid)
    with contextlib.suppress(Exception):
        proc.kill()
    proc.join()


def run_cases(
    cases: Sequence[Case],
    *,
    timeout: float | None = None,
    extra_memory: int = EXTRA_MEMORY,
    on_result: Callable[[Result], None] | None = None,
) -> dict[str, Result]:
    """Run ``cases`` in forked children, one child for as many cases as it survives.

    Parameters
    ----------
    cases : sequence of Case
    timeout : float, optional
        Seconds per case when the case sets none (default :data:`TIMEOUT_S`).
    extra_memory : int
        Address space each case may add to its child's (bytes).
    on_result : callable, optional
        Called with each :class:`Result` as it arrives.

    Returns
    -------
    dict
        Case name -> :class:`Result`.
    """
    names = [c.name for c in cases]
    if len(set(names)) != len(names):
        dup = sorted({n for n in names if names.count(n) > 1})
        raise ValueError(f"duplicate case names: {dup[:5]}")
    results: dict[str, Result] = {}

    def record(res: Result) -> None:
        results[res.name] = res
        if on_result is not None:
            on_result(res)

    ctx = mp.get_context("fork")
    scratch_root = tempfile.mkdtemp(prefix="encctl-probe-")
    pending = list(cases)
    try:
        while pending:
            parent, child = ctx.Pipe(duplex=False)
            proc = ctx.Process(target=_batch_child, args=(pending, child, extra_memory, scratch_root), daemon=True)
            proc.start()
            child.close()
            done = 0
            try:
                if not parent.poll(WARM_TIMEOUT_S) or parent.recv() != ("ready",):
                    raise EOFError
            except (EOFError, OSError):
                _kill(proc)
                for case in pending:
                    record(Result(case.name, "hang", "the child did not start (importing its modules)"))
                break
            for case in pending:
                limit = case.timeout or timeout or TIMEOUT_S
                t0 = time.perf_counter()
                if not parent.poll(limit):
                    _kill(proc)
                    record(Result(case.name, "hang", f"no result within {limit:g} s", time.perf_counter() - t0))
                    done += 1
                    break
                try:
                    name, outcome, detail, seconds = parent.recv()
                except (EOFError, OSError):
                    proc.join(5)
                    code = proc.exitcode
                    why = f"killed by signal {-code}" if code is not None and code < 0 else f"exit code {code}"
                    record(
                        Result(
                            case.name, "hang", f"the child died ({why}): memory exhausted or a crash", time.perf_counter() - t0
                        )
                    )
                    _kill(proc)
                    done += 1
                    break
                record(Result(name, outcome, detail, seconds))
                done += 1
            else:
                proc.join(10)
                if proc.is_alive():  # pragma: no cover
                    _kill(proc)
            parent.close()
            pending = pending[done:]
    finally:
        shutil.rmtree(scratch_root, ignore_errors=True)
    return results


def run_bounded(fn: Callable[[], Any], *, timeout: float | None = None) -> tuple[str, str]:
    """Run one call ``fn()`` in a bounded child (the probe's first form, kept for its tests).

    Returns ``("ok", "")`` for a return, ``("package", message)`` for an ``EncctlError``,
    ``("hang", "")`` past the timeout or when the child dies, ``("MemoryError", "")``, or
    ``("traceback", detail)`` for another exception.
    """
    case = Case("run_bounded", "any", "hang", lambda _: fn(), expect="either", timeout=timeout)
    res = run_cases([case])[case.name]
    if res.outcome == "hang":
        return ("MemoryError", "") if res.detail.startswith("MemoryError") else ("hang", "")
    if res.outcome == "ok":
        return ("package", res.detail) if res.detail else ("ok", "")
    return (res.outcome, res.detail)


def iter_batches(cases: Iterable[Case], key: Callable[[Case], Any]) -> dict[Any, list[Case]]:
    """Cases grouped by ``key`` (e.g. the area), in first-seen order."""
    out: dict[Any, list[Case]] = {}
    for c in cases:
        out.setdefault(key(c), []).append(c)
    return out
