"""``encctl-gym crack``: break N keys of one dynamic-key sequence and time every key.

Usage::

    encctl-gym crack --scheme paillier --bits 96 --keys 4 [--breaker ecm] [--json]   (.paillier_cli)
    encctl-gym crack --scheme lwe --dimension 30 --keys 4 [--attack primal|bdd] [--json]   (.lattice_lwe)
    encctl-gym crack --bits 64 --keys 32 --breaker index-calculus [--json]
                     [--group auto|shipped|fresh] [--seed S] [--time-limit T]
                     [--scheduler local|tcp://host:port] [--n-jobs J] [--inner NAME]
                     [--save-precomputation PATH] [--load-precomputation PATH] [--no-progress]

The group is the shipped safe-prime group of that bit length (``--group auto`` when one is
shipped, or ``shipped``) or a fresh one from ``generate_safe_prime_group(bits, rng=seed)``
(``fresh``, or ``auto`` for sizes not shipped). The keys are one dynamic-key sequence of
Example ex:dyn_elgamal: KeyGen, then KeyUpd N - 1 times (seeded, so reproducible and unsafe for
deployment; the tokens go to the ``token-chain`` breaker only). The breaker's precomputation
runs once; the table lists each key's wall time, CPU time and operation counts, then
``T_first`` (precomputation + first key), the mean wall time of a later key and their ratio. Every recovered key
is checked (g^s = h) and compared with the sequence's secret key.

Work that cannot finish is refused in one line before it starts: more than :data:`~.keys.MAX_KEYS`
keys, a group beyond the breaker's ``--max-bits``, a first key that the breaker's cost
model expects to take more than a year whatever ``--max-bits`` says
(:data:`~encctl_gym.cryptanalysis.base.MAX_EXPECTED_SECONDS`), and a sequence expected to take
longer than ``--max-seconds`` (default :data:`DEFAULT_MAX_SECONDS`; the same estimate as the
environment's ``breaker_time_limit``). The estimate is printed before the work (on stderr with
``--json``).

The index calculus's precomputation can be kept (:mod:`.precomputation_file`):
``--save-precomputation PATH`` writes the solved factor base once it is done, and
``--load-precomputation PATH`` uses it in a later run on the same group (a file of another group
is refused in one line, naming what differs). Progress goes to stderr, one bar per phase
(relations, linear algebra, then the keys, each key one descent), with the time left from the rate
so far. Ctrl-C stops the run with one line and exit code 130; during the precomputation it first
saves the relations collected so far to the ``--save-precomputation`` file, and
``--load-precomputation`` of that file resumes the collection where it stopped.

With ``--scheduler`` (``local`` starts a Dask ``LocalCluster``; needs ``encctl-gym[dask]``) the
keys are split into chunks that run as tasks of :func:`encctl_gym.parallel.run_tasks`, each with
a copy of the precomputation; ``--n-jobs`` above 1 alone uses joblib processes.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

from .._validation import check_int, check_path_name, check_positive
from ..crypto import arith
from ..crypto.group import SHIPPED_BITS, GroupParams, generate_safe_prime_group, shipped_group
from ..errors import BreakerError, ParameterError
from ..parallel import check_n_jobs, check_scheduler
from .base import format_seconds
from .factoring_registry import FACTORERS
from .index_calculus import FactorBaseLogs
from .keys import MAX_KEYS, check_keys, key_sequence
from .lattice_lwe import add_lwe_arguments, crack_lwe
from .paillier_cli import run_paillier
from .precomputation_file import PrecomputationInterrupted
from .progress import PhaseBars
from .registry import BREAKERS, get_breaker
from .sequence import BreakReport, break_sequence

__all__ = ["add_arguments", "run", "crack_group", "DEFAULT_MAX_SECONDS"]

#: Default of ``crack --max-seconds``: the expected time of the whole sequence (the breaker's
#: cost model, :meth:`~encctl_gym.cryptanalysis.base.Breaker.check_time`) above which the work
#: is refused before it starts.
DEFAULT_MAX_SECONDS = 600.0


def crack_group(bits: int, source: str, seed: int) -> tuple[GroupParams, str]:
    """The group of ``encctl-gym crack``: ``(group, "shipped" | "fresh")``.

    Raises
    ------
    ParameterError
        For ``source="shipped"`` without a shipped group of that size, or an unknown source.
    """
    bits = check_int("bits", bits, minimum=2)
    if source not in ("auto", "shipped", "fresh"):
        raise ParameterError(f"--group must be auto, shipped or fresh, got {source!r}")
    if source == "shipped" or (source == "auto" and bits in SHIPPED_BITS):
        return shipped_group(bits), "shipped"
    return generate_safe_prime_group(bits, rng=arith.seeded_random(seed)), "fresh"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Register the options of ``encctl-gym crack``."""
    parser.add_argument("--bits", type=int, default=64, help="bit length of p (default 64)")
    parser.add_argument("--keys", type=int, default=32, help=f"number N of keys of the sequence (default 32, at most {MAX_KEYS})")
    parser.add_argument(
        "--scheme",
        default="elgamal",
        choices=("elgamal", "paillier", "lwe"),
        help="elgamal: one dynamic-key sequence of one group (default); paillier: fresh moduli, factored "
        "(.paillier_cli); lwe: LWE instances sharing one public matrix, by lattice reduction (.lattice_lwe)",
    )
    parser.add_argument(
        "--breaker",
        default=None,
        choices=[*BREAKERS, *FACTORERS],
        help="key breaker (default index-calculus; with --scheme paillier a factoring breaker, default ecm)",
    )
    parser.add_argument(
        "--inner",
        default="index-calculus",
        choices=[b for b in BREAKERS if b != "token-chain"],
        help="breaker of the first key for --breaker token-chain (default index-calculus)",
    )
    parser.add_argument(
        "--group",
        default="auto",
        choices=("auto", "shipped", "fresh"),
        help="shipped group of that size, or a fresh seeded one (default: shipped if there is one)",
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the group, the keys and the attack (default 0)")
    parser.add_argument(
        "--time-limit",
        dest="time_limit",
        type=float,
        default=None,
        metavar="T",
        help="seconds allowed for the precomputation and for each key (default: none)",
    )
    parser.add_argument(
        "--max-seconds",
        dest="max_seconds",
        type=float,
        default=DEFAULT_MAX_SECONDS,
        metavar="S",
        help=f"refuse, before any work, a job the breaker's cost model expects to take longer (default {DEFAULT_MAX_SECONDS:g})",
    )
    parser.add_argument(
        "--max-bits", dest="max_bits", type=int, default=None, help="override the breaker's size limit (bits of p)"
    )
    parser.add_argument(
        "--scheduler", default=None, help="run the keys as Dask tasks: 'local' or a scheduler address (needs encctl-gym[dask])"
    )
    parser.add_argument(
        "--n-jobs",
        dest="n_jobs",
        type=int,
        default=1,
        help="workers of the parallel path (default 1: keys in this process; -1: all cores)",
    )
    parser.add_argument(
        "--save-precomputation",
        dest="save_precomputation",
        default=None,
        metavar="PATH",
        help="index-calculus: write the precomputation to PATH (on Ctrl-C: the relations so far, to resume from)",
    )
    parser.add_argument(
        "--load-precomputation",
        dest="load_precomputation",
        default=None,
        metavar="PATH",
        help="index-calculus: use (or resume) the precomputation saved in PATH; it must be of this group",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    add_lwe_arguments(parser)


def _ops(ops: dict[str, int]) -> str:
    return " ".join(f"{k}={v}" for k, v in ops.items()) or "-"


def _check_save_path(args: argparse.Namespace) -> str | None:
    # The precomputation files are the index calculus's: refused for the others before any work.
    for option in ("save_precomputation", "load_precomputation"):
        if getattr(args, option) is not None and args.breaker != "index-calculus":
            raise ParameterError(
                f"--{option.replace('_', '-')} is for --breaker index-calculus (the precomputation saved is its factor base), "
                f"not {args.breaker}"
            )
    save = args.save_precomputation
    if save is not None:
        save = check_path_name("--save-precomputation", save)
        parent = Path(save).resolve().parent
        if not parent.is_dir():
            raise ParameterError(f"--save-precomputation {save!r}: the directory {str(parent)!r} does not exist")
        if Path(save).is_dir():
            raise ParameterError(f"--save-precomputation {save!r} is a directory, not a file")
    return save


def _interrupted(stop: PrecomputationInterrupted, save: str | None) -> int:
    # Ctrl-C during the precomputation: one line, the relations saved if asked, exit code 130.
    state = stop.state
    done = f"{len(state.relations)} relations after {format_seconds(state.cost.seconds)}"
    if save is not None:
        state.save(save)
        then = f"saved to {save}: rerun with --load-precomputation {save} to resume"
    else:
        then = "not saved (with --save-precomputation PATH a rerun can resume)"
    print(f"encctl-gym crack: interrupted in the {stop.phase}, {done}; {then}", file=sys.stderr)
    return 130


def _phase_lines(pre: Any, loaded: Any, saved: str | None) -> list[str]:
    # The time of each phase of the index calculus's precomputation, and where it came from or went.
    lines = []
    if isinstance(pre, FactorBaseLogs) and pre.phase_seconds:
        phases = ", ".join(
            f"{name.replace('_', ' ')} {format_seconds(pre.phase_seconds[name])} ({format_seconds(pre.phase_cpu_seconds.get(name, 0.0))} CPU)"
            for name in pre.phase_seconds
        )
        lines.append(f"phases (wall, CPU): {phases}; the descent is each key's time below")
        lines.append(f"factor base: {len(pre.logs)} primes up to {pre.bound}, {pre.solved} logarithms solved")
    if loaded is not None:
        lines.append(
            f"precomputation loaded from {loaded.path} in {format_seconds(loaded.read_seconds)} (read and checked: "
            "every logarithm, and the group); the time shown above is the file's"
        )
    if saved is not None:
        lines.append(f"precomputation saved to {saved}")
    return lines


def summary(report: BreakReport) -> dict[str, float]:
    """``T_first`` (precomputation + first key), the mean later key, their ratio, the total
    (NaN for the later key and the ratio of a one-key report; ``null`` in the JSON output)."""
    t = report.key_seconds()
    first = report.precomputation.seconds + float(t[0])
    later = float(t[1:].mean()) if t.size > 1 else float("nan")
    return {
        "T_first": first,
        "mean_later_key": later,
        "ratio": later / first if first > 0 else float("nan"),
        "total": float(report.tau()[-1]),
    }


def run(args: argparse.Namespace) -> int:
    """Build the group and the key sequence, break it, print the table (or JSON)."""
    if getattr(args, "scheme", "elgamal") == "paillier":
        return run_paillier(args, DEFAULT_MAX_SECONDS)
    if getattr(args, "scheme", "elgamal") == "lwe":
        return crack_lwe(args)
    if args.breaker is None:
        args.breaker = "index-calculus"
    if args.breaker not in BREAKERS:
        raise ParameterError(f"--breaker {args.breaker!r} is a factoring breaker: use it with --scheme paillier")
    if args.time_limit is not None:
        check_positive("--time-limit", args.time_limit)
    n = check_keys(args.keys, "--keys")
    seed = check_int("--seed", args.seed, minimum=0)
    kwargs: dict[str, Any] = {"rng": arith.seeded_random(seed + 2)}
    if args.max_bits is not None:
        kwargs["max_bits"] = args.max_bits
    if args.breaker == "token-chain":
        kwargs["inner"] = args.inner
    save = _check_save_path(args)
    if args.load_precomputation is not None:
        kwargs["precomputation"] = args.load_precomputation
    breaker = get_breaker(args.breaker, **kwargs)
    group, source = crack_group(args.bits, args.group, seed)
    check_scheduler(args.scheduler)  # every refusal comes before the estimate is printed
    check_n_jobs(args.n_jobs)
    advice = "raise --max-seconds, or use fewer --keys, a smaller --bits or another --breaker"
    max_seconds = check_positive("--max-seconds", args.max_seconds)
    first, per_key, total = breaker.check_time(group, max_seconds, keys=n, limit_name="--max-seconds", advice=advice)
    print(
        f"crack: {breaker.name} on the {group.bits}-bit group, {n} keys: expected about {format_seconds(total)} "
        f"on this machine ({format_seconds(first)} for the first key, then {format_seconds(per_key)} per key)",
        file=sys.stderr if args.json else sys.stdout,  # --json keeps stdout to the JSON document
        flush=True,
    )
    if save is not None and getattr(breaker, "uses_baby_steps", lambda g: False)(group):
        raise ParameterError(
            f"--save-precomputation: the {group.bits}-bit group's q is too small for relations, so the index calculus "
            "breaks it by baby-step giant-step, whose table is not saved (a factor base is)"
        )
    hs, secrets, tokens = key_sequence(group, n, arith.seeded_random(seed + 1))
    bars = PhaseBars(prefix=f"{breaker.name} ") if not args.no_progress and not args.json else None
    try:
        pre = breaker.precompute(group, time_limit=args.time_limit, progress=bars)
    except PrecomputationInterrupted as stop:
        if bars is not None:
            bars.close()
        return _interrupted(stop, save)
    finally:
        if bars is not None:
            bars.close()
    if save is not None:
        assert isinstance(pre, FactorBaseLogs)  # checked before the work
        pre.save(save)
    report = break_sequence(
        breaker,
        group,
        hs,
        pre=pre,
        tokens=tokens if args.breaker == "token-chain" else None,
        time_limit=args.time_limit,
        progress=not args.no_progress and not args.json,
        scheduler=args.scheduler,
        n_jobs=args.n_jobs,
        seed=seed,
    )
    if report.secrets != secrets:  # never expected: every key was checked against g^s = h
        raise BreakerError("a recovered key differs from the sequence's secret key")
    stats = summary(report)
    if args.json:
        out = report.to_dict()
        if isinstance(pre, FactorBaseLogs):
            out["phase_seconds"], out["phase_cpu_seconds"] = pre.phase_seconds, pre.phase_cpu_seconds
        # JSON has no NaN: a figure without a value (the later keys of a one-key run) is null.
        finite = {k: (v if math.isfinite(v) else None) for k, v in stats.items()}
        out.update({"bits": group.bits, "group_source": source, "keys_match": True, **finite})
        out["expected"] = {"T_first": first, "per_key": per_key, "total": total}  # the estimate printed before the work
        print(json.dumps(out, indent=1))
        return 0
    print(f"crack: {breaker.name} on a {group.bits}-bit {source} group (p = {group.p:#x}), {n} keys of one dynamic-key sequence")
    cost = report.precomputation
    print(f"precomputation: {format_seconds(cost.seconds)}  ({_ops(dict(cost.operations))})")
    for line in _phase_lines(pre, getattr(breaker, "loaded", None), save):
        print(line)
    print(f"{'t':>5}  {'seconds':>12}  {'cpu seconds':>12}  {'method':<15} operations")
    for i, key in enumerate(report.keys):
        print(
            f"{i:>5}  {key.cost.seconds:12.6f}  {key.cost.cpu_seconds:12.6f}  {key.method:<15} {_ops(dict(key.cost.operations))}"
        )
    later = "n/a" if n == 1 else format_seconds(stats["mean_later_key"])
    print(
        f"T_first = {format_seconds(stats['T_first'])} (precomputation + key 0), mean later key = {later}, "
        f"T_1 / T_first = {'n/a' if n == 1 else format(stats['ratio'], '.3g')}, total = {format_seconds(stats['total'])}"
    )
    print(f"all {n} keys checked (g^s = h) and equal to the sequence's secret keys")
    return 0


def main(argv: list[str] | None = None) -> int:  # pragma: no cover - use encctl-gym crack
    """Entry point of ``python -m encctl_gym.cryptanalysis.cli``."""
    from ..cli import main as cli_main

    return cli_main(["crack", *(sys.argv[1:] if argv is None else argv)])


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
