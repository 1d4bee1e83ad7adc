"""The measured sample deciphering time: real key breakers against Definition def:sdt.

The paper charges every sample of a dynamic-key sequence (Example ex:dyn_elgamal) a full break:
``tau(N, lambda) = N 2^lambda / Upsilon`` (Definition def:sdt), i.e. ``tau(N) = N T_first`` with
``T_first`` the time to break one key of a group from scratch. This experiment breaks keys for
real with every breaker of :data:`encctl_gym.cryptanalysis.BREAKERS` and measures:

* for one dynamic-key sequence per (breaker, bit length): the time ``tau(N)`` to break its first
  N = 1, 2, 4, ..., N_max keys (the precomputation once, then key after key);
* on ``fresh`` other groups of the same size: the single-key time ``T_first`` (precomputation +
  one key);
* the fit ``tau(N) = T_0 + N T_1`` (least squares over the N of the grid), and ``T_1 / T_first``:
  1 is the paper's model, near 0 means that after the first key every further key is almost free.

The sizes run (:data:`FULL_PLAN`) go from 32 bits to where each breaker's cost on this machine
(2 cores, about ten minutes in all) stops it: the generic breakers (bsgs, rho, rho-multi) near
48 bits, PARI and the index calculus at 96 bits. Each (breaker, size) is one task of
:func:`encctl_gym.parallel.run_tasks` (joblib processes; PARI needs a process's main thread, so
not Dask). Times are of this machine and are not reproducible elsewhere; the keys are
(seeded groups and sequences, every key checked g^s = h and against the true secret).

CSV ``deciphering_time.csv``, one row per measurement, columns:

============  ==============================================================================
breaker       registry name (``bsgs``, ``rho``, ``rho-multi``, ``pari``, ``index-calculus``,
              ``token-chain``; the token chain's first key by the index calculus)
bits          bit length of p
kind          ``sequence`` (N keys of one dynamic-key sequence) or ``fresh`` (one key of a fresh
              group: a T_first sample)
group         0 for the sequence's group, 1, 2, ... for the fresh groups
N             number of keys broken so far (1 for ``fresh``)
tau           CPU seconds to break those N keys, precomputation included:
              ``T_pre + t_1 + ... + t_N``
precompute    CPU seconds of the precomputation (once per group)
key_seconds   CPU seconds of the N-th key alone
tau_wall      ``tau`` in wall-clock seconds (``precompute_wall``, ``key_wall`` likewise)
operations    the N-th key's operation counts, ``name=value`` separated by ``;``
p             the group's p in hexadecimal
============  ==============================================================================

Times are the CPU time of the process that breaks the keys (``time.process_time``), because
the machine is shared with other jobs whose load inflates wall-clock times; the wall-clock
columns are kept beside them (they agree on an idle machine).

CSV ``deciphering_time_fit.csv``, one row per (breaker, bits), from the CPU times: ``T_first``
(mean over the fresh groups), ``T_0``, ``T_1`` (the fit), ``ratio`` (``T_1 / T_first``),
``N_max``, ``precompute`` (the sequence group's), ``fresh`` (number of fresh groups), and
``T_first_wall``, ``T_1_wall``, ``ratio_wall`` from the wall-clock times.

``deciphering_lp_fit.txt``: the first key's CPU time of the index calculus and of PARI fitted to
``L_p[1/2, c]`` from 64 bits (:func:`experiments.deciphering_models.fit_lp_half`: a and c with
95% intervals), also drawn in ``deciphering_models.png``.

Usage: ``python experiments/deciphering_time.py [--quick] [--out DIR] [--seed S] [--n-jobs J]``
(also ``encctl-gym reproduce --only deciphering``). ``--large`` adds the index calculus at 112 and
128 bits (:data:`LARGE_PLAN`, about 6 minutes of CPU more); ``--breakers NAME ...`` measures only
those breakers' plans; with ``--from-csv PATH`` as well, the measured rows replace those of the
same (breaker, bits) in the recorded file and the rest is kept::

    python experiments/deciphering_time.py --from-csv docs/figures/deciphering_time.csv
        --breakers index-calculus --large --out docs/figures
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np

from encctl_gym.cryptanalysis import get_breaker, pari_available
from encctl_gym.cryptanalysis.keys import key_sequence
from encctl_gym.cryptanalysis.sequence import break_sequence
from encctl_gym.crypto import arith
from encctl_gym.crypto.group import generate_safe_prime_group
from encctl_gym.errors import BreakerError, ParameterError
from encctl_gym.experiments.common import add_common_arguments, ensure_out_dir, entry_point
from encctl_gym.experiments.deciphering_models import format_lp_fits, lp_fits, model_curves, plot_models
from encctl_gym.parallel import child_seeds, run_tasks
from encctl_gym.plotting import save_figure

__all__ = [
    "Plan",
    "FULL_PLAN",
    "QUICK_PLAN",
    "LARGE_PLAN",
    "select_plan",
    "merge_rows",
    "COLUMNS",
    "FIT_COLUMNS",
    "n_grid",
    "measure",
    "compute",
    "fit",
    "write_csv",
    "read_csv",
    "plot",
    "model_curves",
    "plot_models",
    "add_arguments",
    "run",
    "main",
]

#: Columns of ``deciphering_time.csv`` (see the module docstring).
COLUMNS = (
    "breaker",
    "bits",
    "kind",
    "group",
    "N",
    "tau",
    "precompute",
    "key_seconds",
    "tau_wall",
    "precompute_wall",
    "key_wall",
    "operations",
    "p",
)
#: Columns of ``deciphering_time_fit.csv``.
FIT_COLUMNS = (
    "breaker",
    "bits",
    "T_first",
    "T_0",
    "T_1",
    "ratio",
    "N_max",
    "precompute",
    "fresh",
    "T_first_wall",
    "T_1_wall",
    "ratio_wall",
)


@dataclasses.dataclass(frozen=True)
class Plan:
    """One measurement: ``keys`` keys of one sequence and ``fresh`` fresh groups of ``bits`` bits."""

    breaker: str
    bits: int
    keys: int
    fresh: int


def _plans(breaker: str, sizes: Sequence[tuple[int, int, int]]) -> tuple[Plan, ...]:
    return tuple(Plan(breaker, b, k, f) for b, k, f in sizes)


#: The full run: (bits, N_max, fresh groups) per breaker, up to about ten minutes on 2 cores.
#: The generic breakers get more fresh groups: a rho walk's length varies a lot from key to key.
FULL_PLAN: tuple[Plan, ...] = (
    _plans("bsgs", ((32, 64, 8), (36, 64, 8), (40, 64, 8), (44, 64, 8), (48, 8, 2)))
    + _plans("rho", ((32, 64, 8), (36, 64, 8), (40, 64, 8), (44, 64, 8), (48, 8, 6)))
    + _plans("rho-multi", ((32, 64, 8), (36, 64, 8), (40, 64, 8), (44, 64, 8), (48, 64, 4)))
    + _plans(
        "pari",
        ((32, 64, 3), (40, 64, 3), (48, 64, 3), (56, 64, 3), (64, 64, 3), (72, 64, 3), (80, 64, 3), (88, 32, 2), (96, 8, 2)),
    )
    + _plans(
        "index-calculus",
        ((32, 64, 3), (40, 64, 3), (48, 64, 3), (56, 64, 3), (64, 64, 3), (72, 64, 3), (80, 64, 3), (88, 64, 2), (96, 64, 1)),
    )
    + _plans("token-chain", ((32, 64, 1), (48, 64, 1), (64, 64, 1), (80, 64, 1)))
)
#: The index calculus's large sizes (``--large``): about 30 s of CPU for the first key at 112 bits
#: and 4 to 5 minutes at 128 (one sequence, no fresh group: T_first is the sequence's first key).
LARGE_PLAN: tuple[Plan, ...] = _plans("index-calculus", ((112, 16, 1), (128, 8, 0)))
#: A smoke test of a few seconds (``--quick``; run by ``reproduce --quick`` in the tests).
QUICK_PLAN: tuple[Plan, ...] = tuple(
    Plan(b, bits, 8, 1) for b in ("bsgs", "rho", "rho-multi", "pari", "index-calculus", "token-chain") for bits in (24, 32)
)


def select_plan(quick: bool, large: bool, breakers: Sequence[str] | None) -> list[Plan]:
    """The plans of a run: :data:`QUICK_PLAN` or :data:`FULL_PLAN`, with :data:`LARGE_PLAN` if
    ``large``, restricted to ``breakers`` (all when ``None``).

    Raises
    ------
    ParameterError
        For ``quick`` with ``large``, an unknown breaker, or a selection with no plan.
    """
    if quick and large:
        raise ParameterError("--large measures the large sizes and --quick a smoke test: choose one")
    plan = list(QUICK_PLAN if quick else FULL_PLAN) + (list(LARGE_PLAN) if large else [])
    if breakers is not None:
        known = sorted({p.breaker for p in FULL_PLAN})
        unknown = [b for b in breakers if b not in known]
        if unknown:
            raise ParameterError(f"--breakers: unknown {', '.join(map(repr, unknown))}; choose from {', '.join(known)}")
        plan = [p for p in plan if p.breaker in breakers]
    if not plan:
        raise ParameterError("the plan is empty")
    return plan


def merge_rows(recorded: Sequence[dict[str, Any]], measured: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """``recorded`` rows with those of every (breaker, bits) measured anew replaced by ``measured``
    (the recorded order kept, new sizes after their breaker's rows)."""
    new = {(r["breaker"], int(r["bits"])) for r in measured}
    kept = [r for r in recorded if (r["breaker"], int(r["bits"])) not in new]
    order = list(dict.fromkeys(r["breaker"] for r in [*recorded, *measured]))
    out = []
    for breaker in order:
        rows = [r for r in kept if r["breaker"] == breaker] + [r for r in measured if r["breaker"] == breaker]
        out += sorted(rows, key=lambda r: int(r["bits"]))  # stable: a size's rows keep their order
    return out


def n_grid(keys: int) -> list[int]:
    """``1, 2, 4, ...`` up to ``keys`` (and ``keys`` itself)."""
    out = [1 << i for i in range(int(keys).bit_length()) if 1 << i <= keys]
    return out + ([keys] if out[-1] != keys else [])


def _rng(seed: np.random.SeedSequence, i: int) -> arith.RandomSource:
    child = np.random.SeedSequence(seed.entropy, spawn_key=(*seed.spawn_key, i))
    return arith.seeded_random(int(child.generate_state(1, np.uint64)[0]))


def _ops(ops: Any) -> str:
    return ";".join(f"{k}={int(v)}" for k, v in dict(ops).items())


def _breaker(name: str, rng: arith.RandomSource) -> Any:
    return get_breaker(name, inner="index-calculus", rng=rng) if name == "token-chain" else get_breaker(name, rng=rng)


def _rows(plan: Plan, kind: str, index: int, report: Any, grid: Sequence[int]) -> list[dict[str, Any]]:
    tau, tau_wall = report.tau("cpu"), report.tau("wall")
    pre = report.precomputation
    rows = []
    for n in grid:
        cost = report.keys[n - 1].cost
        rows.append(
            {
                "breaker": plan.breaker,
                "bits": plan.bits,
                "kind": kind,
                "group": index,
                "N": n,
                "tau": float(tau[n - 1]),
                "precompute": pre.cpu_seconds,
                "key_seconds": cost.cpu_seconds,
                "tau_wall": float(tau_wall[n - 1]),
                "precompute_wall": pre.seconds,
                "key_wall": cost.seconds,
                "operations": _ops(cost.operations),
                "p": hex(report.group.p),
            }
        )
    return rows


def measure(plan: Plan, seed: np.random.SeedSequence) -> list[dict[str, Any]]:
    """Run one plan: break ``plan.keys`` keys of one sequence, and one key on each fresh group.

    Returns
    -------
    list of dict
        Rows with the :data:`COLUMNS`.
    """
    group = generate_safe_prime_group(plan.bits, rng=_rng(seed, 0))
    hs, secrets, tokens = key_sequence(group, plan.keys, _rng(seed, 1))
    breaker = _breaker(plan.breaker, _rng(seed, 2))
    report = break_sequence(breaker, group, hs, tokens=tokens if plan.breaker == "token-chain" else None)
    if report.secrets != secrets:  # never expected: every key is checked g^s = h
        raise BreakerError(f"{plan.breaker}: a recovered key differs from the sequence's secret key")
    rows = _rows(plan, "sequence", 0, report, n_grid(plan.keys))
    for i in range(1, plan.fresh + 1):
        fresh = generate_safe_prime_group(plan.bits, rng=_rng(seed, 10 * i))
        (h,), (s,), _ = key_sequence(fresh, 1, _rng(seed, 10 * i + 1))
        one = break_sequence(_breaker(plan.breaker, _rng(seed, 10 * i + 2)), fresh, [h])
        if one.secrets != [s]:
            raise BreakerError(f"{plan.breaker}: a recovered key differs from the fresh group's secret key")
        rows += _rows(plan, "fresh", i, one, [1])
    return rows


def compute(
    plan: Sequence[Plan] = FULL_PLAN, *, seed: int = 0, n_jobs: int = -1, scheduler: Any = None, progress: bool = False
) -> list[dict[str, Any]]:
    """Run every plan (one task each, the longest first) and return the rows of the CSV.

    Plans of the ``pari`` breaker are left out when cypari is not installed (a note on stderr).

    Parameters
    ----------
    plan
        The measurements (:data:`FULL_PLAN` or :data:`QUICK_PLAN`).
    seed
        Master seed; plan ``i`` gets child ``i`` (its groups, keys and attack randomness).
    n_jobs, scheduler, progress
        See :func:`encctl_gym.parallel.run_tasks`.
    """
    plan = list(plan)
    if not plan:
        raise ParameterError("the plan is empty")
    if not pari_available() and any(p.breaker == "pari" for p in plan):
        print(
            "deciphering_time: cypari is not installed, the 'pari' breaker is skipped (pip install 'encctl-gym[cryptanalysis]')",
            file=sys.stderr,
        )
        plan = [p for p in plan if p.breaker != "pari"]
    # Largest sizes first, so that the long tasks do not end up last on one worker; plan i keeps
    # child seed i of the original order whatever the order of execution.
    order = sorted(range(len(plan)), key=lambda i: -plan[i].bits)
    seeds = child_seeds(seed, len(plan))
    done = run_tasks(
        _measure_task,
        [(plan[i], seeds[i]) for i in order],
        seed=seed,
        n_jobs=n_jobs,
        scheduler=scheduler,
        progress=progress,
        desc="deciphering time",
    )
    rows_per_plan: list[list[dict[str, Any]]] = [[] for _ in plan]
    for i, rows in zip(order, done):
        rows_per_plan[i] = rows
    return [row for rows in rows_per_plan for row in rows]


def _measure_task(task: tuple[Plan, np.random.SeedSequence], _: np.random.SeedSequence) -> list[dict[str, Any]]:
    return measure(*task)


def _fit_one(seq: Sequence[dict[str, Any]], fresh: Sequence[dict[str, Any]], column: str) -> tuple[float, float, float]:
    n = np.array([int(r["N"]) for r in seq], dtype=float)
    tau = np.array([float(r[column]) for r in seq])
    if n.size >= 2:
        t1, t0 = np.polyfit(n, tau, 1)
    else:
        t0, t1 = (float(tau[0]) if tau.size else float("nan")), float("nan")
    t_first = float(np.mean([float(r[column]) for r in fresh])) if fresh else (float(tau[0]) if tau.size else float("nan"))
    return t_first, float(t0), float(t1)


def fit(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per (breaker, bits): ``T_first`` (mean of the fresh groups), the least-squares fit
    ``tau(N) = T_0 + N T_1`` of the sequence, and ``T_1 / T_first``; from the CPU times, and
    (``*_wall``) from the wall-clock times.

    Returns
    -------
    list of dict
        Rows with the :data:`FIT_COLUMNS`, in the order of first appearance.
    """
    keys = list(dict.fromkeys((r["breaker"], int(r["bits"])) for r in rows))
    out = []
    for breaker, bits in keys:
        mine = [r for r in rows if r["breaker"] == breaker and int(r["bits"]) == bits]
        seq = sorted((r for r in mine if r["kind"] == "sequence"), key=lambda r: int(r["N"]))
        fresh = [r for r in mine if r["kind"] == "fresh"]
        t_first, t0, t1 = _fit_one(seq, fresh, "tau")
        w_first, _, w1 = _fit_one(seq, fresh, "tau_wall")
        out.append(
            {
                "breaker": breaker,
                "bits": bits,
                "T_first": t_first,
                "T_0": t0,
                "T_1": t1,
                "ratio": t1 / t_first if t_first > 0 else float("nan"),
                "N_max": max((int(r["N"]) for r in seq), default=0),
                "precompute": float(seq[0]["precompute"]) if seq else float("nan"),
                "fresh": len(fresh),
                "T_first_wall": w_first,
                "T_1_wall": w1,
                "ratio_wall": w1 / w_first if w_first > 0 else float("nan"),
            }
        )
    return out


def write_csv(rows: Sequence[dict[str, Any]], path: str | Path, columns: Sequence[str] = COLUMNS) -> Path:
    """Write rows (floats with 17 significant digits) to ``path``."""
    path = Path(path)
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(columns)
        for r in rows:
            w.writerow(repr(float(r[c])) if isinstance(r[c], float) else str(r[c]) for c in columns)
    return path


def _same_values(a: Sequence[dict[str, Any]], b: Sequence[dict[str, Any]], columns: Sequence[str]) -> bool:
    """Whether two tables hold the same values: floats within a relative 1e-9 (a fit redone on
    another machine's BLAS changes the last digits, not the value), NaN equal to NaN."""
    if len(a) != len(b):
        return False
    for ra, rb in zip(a, b, strict=True):
        for c in columns:
            x, y = ra.get(c), rb.get(c)
            if isinstance(x, float) or isinstance(y, float):
                try:
                    fx, fy = float(x), float(y)  # type: ignore[arg-type]
                except (TypeError, ValueError):
                    return False
                if not (math.isclose(fx, fy, rel_tol=1e-9, abs_tol=0.0) or (math.isnan(fx) and math.isnan(fy))):
                    return False
            elif str(x) != str(y):
                return False
    return True


def _write_csv_if_changed(rows: Sequence[dict[str, Any]], path: Path, columns: Sequence[str]) -> Path:
    """Write ``rows`` to ``path`` unless the file already holds the same values (so that a
    redraw ``--from-csv`` changes no data file)."""
    if path.is_file():
        try:
            if _same_values(read_csv(path), rows, columns):
                return path
        except (OSError, ValueError, csv.Error):
            pass  # unreadable or of another layout: overwrite it
    return write_csv(rows, path, columns)


def read_csv(path: str | Path) -> list[dict[str, Any]]:
    """Read ``deciphering_time.csv`` (or the fit CSV) back, numbers as int or float."""
    with Path(path).open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    ints = {"bits", "group", "N", "N_max", "fresh"}
    floats = {
        "tau",
        "precompute",
        "key_seconds",
        "tau_wall",
        "precompute_wall",
        "key_wall",
        "T_first",
        "T_0",
        "T_1",
        "ratio",
        "T_first_wall",
        "T_1_wall",
        "ratio_wall",
    }
    for r in rows:
        for k in list(r):
            if k in ints:
                r[k] = int(r[k])
            elif k in floats:
                r[k] = float(r[k])
    return rows


def plot(rows: Sequence[dict[str, Any]], path: str | Path) -> Path:
    """Two panels from the rows of :func:`compute`: measured ``tau(N)`` against the paper's
    ``N T_first`` (one panel per breaker, a curve per size), and ``T_1 / T_first`` against the
    bit length."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fits = fit(rows)
    breakers = list(dict.fromkeys(r["breaker"] for r in rows))
    ncols = 3
    nrows = -(-len(breakers) // ncols) + 1
    fig = plt.figure(figsize=(13, 3.6 * nrows))
    grid = fig.add_gridspec(nrows, ncols)
    for k, breaker in enumerate(breakers):
        ax = fig.add_subplot(grid[k // ncols, k % ncols])
        sizes = sorted({f["bits"] for f in fits if f["breaker"] == breaker})
        colors = plt.cm.viridis(np.linspace(0, 0.9, max(len(sizes), 1)))
        for color, bits in zip(colors, sizes):
            seq = sorted(
                (r for r in rows if r["breaker"] == breaker and r["bits"] == bits and r["kind"] == "sequence"),
                key=lambda r: r["N"],
            )
            n = np.array([r["N"] for r in seq])
            t_first = next(f["T_first"] for f in fits if f["breaker"] == breaker and f["bits"] == bits)
            ax.loglog(n, [r["tau"] for r in seq], "o-", color=color, ms=3, lw=1.4, label=f"{bits} bits")
            ax.loglog(n, n * t_first, "--", color=color, lw=0.9)
        ax.set_title(f"{breaker}: measured $\\tau(N)$ (solid) vs $N\\,T_{{first}}$ (dashed)", fontsize=9)
        ax.set_xlabel("keys broken $N$")
        ax.set_ylabel("CPU seconds")
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=7, ncol=2, frameon=False)
    ax = fig.add_subplot(grid[nrows - 1, :])
    for breaker in breakers:
        mine = sorted((f for f in fits if f["breaker"] == breaker), key=lambda f: f["bits"])
        ratio = np.array([f["ratio"] for f in mine])
        ax.semilogy([f["bits"] for f in mine], np.where(ratio > 0, ratio, np.nan), "o-", label=breaker)
    ax.axhline(1.0, color="k", lw=0.8, ls=":", label="paper (Definition def:sdt): $T_1 = T_{first}$")
    ax.set_xlabel("bit length of $p$")
    ax.set_ylabel("$T_1 / T_{first}$")
    ax.set_title("cost of each further key relative to breaking one key from scratch", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, ncol=4, frameon=False)
    fig.tight_layout()
    path = Path(path)
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path


def format_table(fits: Sequence[dict[str, Any]]) -> str:
    """The measured table: bits, breaker, T_first, T_1, T_1 / T_first, and each breaker's largest size."""
    largest: dict[str, int] = {}
    for f in fits:
        largest[f["breaker"]] = max(largest.get(f["breaker"], 0), f["bits"])
    lines = [f"{'bits':>5}  {'breaker':<15} {'T_first (s)':>12} {'T_1 (s)':>12} {'T_1/T_first':>12} {'N_max':>6} {'largest':>8}"]
    for f in sorted(fits, key=lambda f: (f["breaker"], f["bits"])):
        lines.append(
            f"{f['bits']:>5}  {f['breaker']:<15} {f['T_first']:12.4g} {f['T_1']:12.4g} {f['ratio']:12.3g} "
            f"{f['N_max']:>6} {largest[f['breaker']]:>8}"
        )
    return "\n".join(lines)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Command-line options (``--out --quick --seed --n-jobs --scheduler --no-progress --from-csv``)."""
    add_common_arguments(parser)
    parser.add_argument(
        "--from-csv",
        default=None,
        metavar="PATH",
        help="redraw the figures and the table from a recorded deciphering_time.csv instead of measuring "
        "(with --large or --breakers: measure those and replace their rows of the recorded file)",
    )
    parser.add_argument(
        "--large",
        action="store_true",
        help="also measure the index calculus at 112 and 128 bits (LARGE_PLAN: about 6 minutes of CPU)",
    )
    parser.add_argument("--breakers", nargs="+", default=None, metavar="NAME", help="measure only these breakers' plans")


def run(args: argparse.Namespace) -> int:
    """Compute (or read ``--from-csv``), save ``deciphering_time.csv``, ``deciphering_time_fit.csv``,
    ``deciphering_time.png`` and ``deciphering_models.png``; print the table."""
    out = ensure_out_dir(args.out)
    t0 = time.perf_counter()
    source = getattr(args, "from_csv", None)
    large, breakers = getattr(args, "large", False), getattr(args, "breakers", None)
    measuring = source is None or large or breakers is not None
    plan = select_plan(args.quick, large, breakers) if measuring else []
    recorded: list[dict[str, Any]] = []
    if source is not None:
        if not Path(source).is_file():
            raise ParameterError(f"--from-csv: no such file {source!r}")
        recorded = read_csv(source)
    rows = recorded
    if measuring:
        measured = compute(plan, seed=args.seed, n_jobs=args.n_jobs, scheduler=args.scheduler, progress=not args.no_progress)
        rows = merge_rows(recorded, measured)
    elapsed = time.perf_counter() - t0
    fits = fit(rows)
    csv_path = _write_csv_if_changed(rows, out / "deciphering_time.csv", COLUMNS)
    fit_path = _write_csv_if_changed(fits, out / "deciphering_time_fit.csv", FIT_COLUMNS)
    png_path = plot(rows, out / "deciphering_time.png")
    models_path = plot_models(rows, fits, out / "deciphering_models.png")
    lp_text = format_lp_fits(lp_fits(fits))
    lp_path = out / "deciphering_lp_fit.txt"
    lp_path.write_text(lp_text + "\n")
    how = (
        f" (read from {source})"
        if source and not measuring
        else (f" ({len(plan)} plans measured, the rest from {source})" if source else "")
    )
    print(f"Deciphering time: {len(rows)} rows in {elapsed:.1f} s" + how)
    print(format_table(fits))
    print(lp_text)
    for path in (csv_path, fit_path, png_path, models_path, lp_path):
        print(f"  wrote {path}")
    return 0


main = entry_point("deciphering_time", __doc__, add_arguments, run)


if __name__ == "__main__":
    sys.exit(main())
