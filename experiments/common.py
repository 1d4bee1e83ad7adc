"""Shared pieces of the reproduction scripts: the grid of sample sizes, the tidy result table
(CSV), the command-line options and the log-log panel plot.

A figure's numbers come from a ``compute(...)`` function (called by the tests too) that returns
a :class:`Table`; plotting only reads the table.
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from encctl_gym.errors import ParameterError
from encctl_gym.plotting import save_figure
from encctl_gym.sim.montecarlo import log_grid

__all__ = [
    "system_preset",
    "GridConfig",
    "FULL",
    "QUICK",
    "Table",
    "add_common_arguments",
    "grid_config",
    "figure_seed",
    "ensure_out_dir",
    "write_recorded_table",
]

#: CSV columns, in order.
COLUMNS = ("figure", "panel", "sigma_w2", "sigma_u2", "r_sigma", "psi_u", "N", "run", "error", "gamma", "bound")


@dataclass(frozen=True)
class GridConfig:
    """Monte Carlo size: sample sizes on a log grid from ``n + m + 1`` to ``N_max``, ``runs`` each."""

    N_max: int
    points: int
    runs: int

    def grid(self, n: int, m: int) -> np.ndarray:
        """The grid of sample sizes for an ``n``-state, ``m``-input plant."""
        return log_grid(n + m + 1, self.N_max, self.points)


#: The paper's size: 50 identifications per N, N up to 10^4.
FULL = GridConfig(N_max=10_000, points=30, runs=50)
#: Smoke test: a few seconds.
QUICK = GridConfig(N_max=500, points=8, runs=8)


def grid_config(quick: bool) -> GridConfig:
    """:data:`QUICK` or :data:`FULL`."""
    return QUICK if quick else FULL


def figure_seed(seed: int, figure: int) -> np.random.SeedSequence:
    """The seed of figure ``figure``: child ``figure`` of ``SeedSequence(seed)``.

    Figures get independent streams, so Figure 2 (a) does not reuse the random numbers of a
    panel of Figure 1 with the same seed.
    """
    ss = np.random.SeedSequence(int(seed))
    return np.random.SeedSequence(ss.entropy, spawn_key=(figure,))


@dataclass
class Table:
    """A tidy table: one row per (system, N, run), columns :data:`COLUMNS`."""

    columns: dict[str, np.ndarray] = field(default_factory=dict)

    @classmethod
    def concat(cls, parts: Sequence[Table]) -> Table:
        """Stack tables with the same columns."""
        if not parts:
            return cls({c: np.array([]) for c in COLUMNS})
        return cls({c: np.concatenate([p.columns[c] for p in parts]) for c in COLUMNS})

    @classmethod
    def from_errors(
        cls,
        *,
        figure: str,
        panel: str,
        grid: np.ndarray,
        errors: np.ndarray,
        gamma: np.ndarray,
        bound: np.ndarray | None = None,
        sigma_w2: float,
        sigma_u2: float,
        psi_u: float,
    ) -> Table:
        """Rows of one panel from ``errors`` of shape (runs, K) and per-N curves of shape (K,)."""
        runs, K = errors.shape
        N = np.tile(grid, runs)
        run = np.repeat(np.arange(runs), K)
        rows = runs * K
        bound_col = np.full(K, np.nan) if bound is None else np.asarray(bound, dtype=float)
        return cls(
            {
                "figure": np.full(rows, figure, dtype=object),
                "panel": np.full(rows, panel, dtype=object),
                "sigma_w2": np.full(rows, sigma_w2),
                "sigma_u2": np.full(rows, sigma_u2),
                "r_sigma": np.full(rows, sigma_u2 / sigma_w2),
                "psi_u": np.full(rows, psi_u),
                "N": N.astype(np.int64),
                "run": run.astype(np.int64),
                "error": errors.reshape(-1),
                "gamma": np.tile(np.asarray(gamma, dtype=float), runs),
                "bound": np.tile(bound_col, runs),
            }
        )

    def __len__(self) -> int:
        return len(self.columns["N"]) if self.columns else 0

    def panels(self) -> list[str]:
        """Panel labels in order of first appearance."""
        labels = self.columns["panel"]
        _, idx = np.unique(labels.astype(str), return_index=True)
        return [str(labels[i]) for i in sorted(idx)]

    def panel(self, label: str) -> Table:
        """The rows of one panel."""
        mask = self.columns["panel"].astype(str) == label
        if not mask.any():
            raise ParameterError(f"no panel {label!r} in the table")
        return Table({c: v[mask] for c, v in self.columns.items()})

    def summary(self, label: str) -> dict[str, Any]:
        """Per-N statistics of one panel: grid, errors (runs, K), mean, gamma, bound, parameters."""
        t = self.panel(label)
        grid = np.unique(t.columns["N"])
        runs = np.unique(t.columns["run"])
        order = np.lexsort((t.columns["N"], t.columns["run"]))
        err = t.columns["error"][order].reshape(runs.size, grid.size)
        first = order[: grid.size]
        return {
            "panel": label,
            "N": grid,
            "errors": err,
            "mean": err.mean(axis=0),
            "gamma": t.columns["gamma"][first],
            "bound": t.columns["bound"][first],
            "sigma_w2": float(t.columns["sigma_w2"][0]),
            "sigma_u2": float(t.columns["sigma_u2"][0]),
            "r_sigma": float(t.columns["r_sigma"][0]),
            "psi_u": float(t.columns["psi_u"][0]),
        }

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write the table as CSV (floats with 17 significant digits, empty for NaN)."""
        path = Path(path)
        with path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(COLUMNS)
            cols = [self.columns[c] for c in COLUMNS]
            for row in zip(*cols):
                w.writerow(_fmt(v) for v in row)
        return path


def _fmt(v: Any) -> str:
    if isinstance(v, (float, np.floating)):
        return "" if np.isnan(v) else repr(float(v))
    return str(v)


def read_csv(path: str | os.PathLike[str]) -> Table:
    """Read a table written by :meth:`Table.to_csv`."""
    with Path(path).open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    cols: dict[str, np.ndarray] = {}
    for c in COLUMNS:
        vals = [r[c] for r in rows]
        if c in ("figure", "panel"):
            cols[c] = np.array(vals, dtype=object)
        elif c in ("N", "run"):
            cols[c] = np.array(vals, dtype=np.int64)
        else:
            cols[c] = np.array([float(v) if v else np.nan for v in vals])
    return Table(cols)


def _checked(check: Callable[[str], Any], what: str) -> Callable[[str], Any]:
    """An argparse ``type`` that runs ``check`` on the option's text and reports its package
    error as argparse's one-line usage error (not argparse's generic "invalid value")."""

    def convert(text: str) -> Any:
        try:
            return check(text)
        except ParameterError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    convert.__name__ = what
    return convert


def _seed(text: str) -> int:
    from encctl_gym._validation import check_int

    try:
        value = int(text)
    except ValueError:
        raise ParameterError(f"--seed must be a non-negative integer, got {text[:40]!r}") from None
    return check_int("--seed", value, minimum=0)


def _n_jobs(text: str) -> int:
    from encctl_gym.parallel import check_n_jobs

    try:
        value = int(text)
    except ValueError:
        raise ParameterError(f"--n-jobs must be -1 (all cores) or a count >= 1, got {text[:40]!r}") from None
    return check_n_jobs(value)


def _scheduler(text: str) -> str:
    from encctl_gym.parallel import check_scheduler

    return str(check_scheduler(text))


def add_common_arguments(parser: argparse.ArgumentParser) -> None:
    """The options every reproduction script shares (``--seed``, ``--n-jobs`` and ``--scheduler``
    are checked as they are parsed: a bad value is a one-line usage error, before any work)."""
    parser.add_argument("--out", default="results", help="output directory (default: results/)")
    parser.add_argument("--quick", action="store_true", help="small grid and few runs: a smoke test of a few seconds")
    parser.add_argument("--seed", type=_checked(_seed, "seed"), default=0, help="master seed, an integer >= 0 (default: 0)")
    parser.add_argument(
        "--n-jobs", type=_checked(_n_jobs, "n_jobs"), default=-1, help="worker processes (-1: all cores; 1: serial)"
    )
    parser.add_argument(
        "--scheduler",
        type=_checked(_scheduler, "scheduler"),
        default=None,
        help="Dask scheduler: 'local' (start a LocalCluster) or an address like tcp://host:8786 "
        "(default: joblib processes on this machine; needs encctl-gym[dask])",
    )
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")


def ensure_out_dir(out: str | os.PathLike[str]) -> Path:
    """Create the output directory."""
    path = Path(out)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ParameterError(f"cannot create the output directory {str(path)!r}: {exc}") from exc
    return path


def write_recorded_table(path: str | os.PathLike[str], title: str, command: str, table: str, notes: str = "") -> Path:
    """Print ``table`` and record it as a Markdown page: ``# title``, the command that printed it
    (and ``notes`` on its settings, after it), then the table; returns the path written."""
    print(table)
    out = Path(path)
    out.write_text(f"# {title}\n\nCommand: `{command}`{notes}\n\n{table}\n")
    print(f"  wrote {out}")
    return out


def plot_panel(ax: Any, s: dict[str, Any], title: str, *, bound: bool = False) -> None:
    """One log-log panel: gray dots per run, mean (solid), gamma (dashed), bound (dotted)."""
    N, err = s["N"], s["errors"]
    ax.loglog(
        np.broadcast_to(N, err.shape).ravel(),
        err.ravel(),
        ".",
        color="0.6",
        ms=2,
        alpha=0.5,
        rasterized=True,
        label="error (each run)",
    )
    ax.loglog(N, s["mean"], "-", color="tab:blue", lw=1.6, label="mean error")
    ax.loglog(N, s["gamma"], "--", color="tab:orange", lw=1.6, label=r"$\gamma(N)$ (eq:sic2)")
    if bound:
        ax.loglog(N, s["bound"], ":", color="k", lw=1.6, label=r"$\bar\gamma(N)$ (eq:bound)")
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="major", alpha=0.3)


def system_preset(name: str) -> Any:
    """The :class:`~encctl_gym.presets.SystemPreset` of a preset name, or of a plant file
    (``.yaml``/``.yml``, a path relative to the working directory, like the pages the experiments write)."""
    from encctl_gym.plant_file import load_plant_file
    from encctl_gym.presets import get_preset

    return load_plant_file(name).preset if name.endswith((".yaml", ".yml")) else get_preset(name)


def preset_spec(name: str) -> Any:
    """The :class:`~encctl_gym.sim.montecarlo.AttackSpec` of a preset of :mod:`encctl_gym.presets`."""
    from encctl_gym.presets import get_preset
    from encctl_gym.sim.montecarlo import AttackSpec

    p = get_preset(name)
    return AttackSpec(p.A, p.B, sigma_w2=p.sigma_w2, sigma_u2=p.sigma_u2, sigma_x2=p.sigma_x2)


def figure_table(
    figure: str,
    number: int,
    panels: Sequence[tuple[str, Any]],
    config: GridConfig,
    *,
    seed: int,
    n_jobs: int,
    scheduler: Any,
    progress: bool,
    bound: bool = False,
) -> Table:
    """The data of one of the paper's figures: for each ``(letter, spec)`` of ``panels``,
    ``config.runs`` Gaussian attacks identified on the grid of N (Definition def:error), with
    ``gamma(N)`` of eq:sic2 and, with ``bound``, eq:bound (:func:`panel_table`).

    The figure uses child ``number`` of ``SeedSequence(seed)`` (:func:`figure_seed`) and panel
    ``k`` its child ``k``, so a panel depends neither on the others nor on the workers
    (``n_jobs``, ``scheduler``: :func:`encctl_gym.parallel.run_tasks`).
    """
    from encctl_gym.sim.montecarlo import sweep_gaussian_attack

    grid = config.grid(4, 4)
    errors_all = sweep_gaussian_attack(
        [spec for _, spec in panels],
        sample_sizes=grid,
        runs=config.runs,
        seed=figure_seed(seed, number),
        n_jobs=n_jobs,
        scheduler=scheduler,
        progress=progress,
        desc=f"Figure {number}",
    )
    return Table.concat(
        [panel_table(figure, letter, spec, grid, errors, bound=bound) for (letter, spec), errors in zip(panels, errors_all)]
    )


def panel_table(figure: str, panel: str, spec: Any, grid: np.ndarray, errors: np.ndarray, *, bound: bool = False) -> Table:
    """The rows of one panel of Figure 1 or 2: the errors of its runs with ``gamma(N)`` of eq:sic2,
    ``psi_u`` (the scalar of ``Psi_u = psi_u I`` computed from ``(A, B)``) and, with ``bound``,
    the upper bound eq:bound ``(m+n) / ((N-1) m R_sigma)``."""
    from encctl_gym.security.complexity import input_upper_bound, sample_identifying_complexity_asymptotic
    from encctl_gym.security.gramians import controllability_gramian

    n, m = spec.B.shape
    r_sigma = spec.sigma_u2 / spec.sigma_w2
    gamma = sample_identifying_complexity_asymptotic(grid, spec.A, spec.B, r_sigma=r_sigma)
    psi_u = float(np.trace(controllability_gramian(spec.A, spec.B))) / n
    extra = {"bound": np.asarray(input_upper_bound(grid, m, n, r_sigma))} if bound else {}
    return Table.from_errors(
        figure=figure,
        panel=panel,
        grid=grid,
        errors=errors,
        gamma=np.asarray(gamma),
        sigma_w2=spec.sigma_w2,
        sigma_u2=spec.sigma_u2,
        psi_u=psi_u,
        **extra,
    )


def panel_figure(
    table: Table,
    panels: Sequence[str],
    shape: tuple[int, int],
    figsize: tuple[float, float],
    title: Callable[[dict[str, Any]], str],
    suptitle: str,
    path: str | Path,
    *,
    bound: bool = False,
    rect: tuple[float, float, float, float] = (0, 0.05, 1, 0.95),
) -> Path:
    """A grid of :func:`plot_panel` panels, one per label of ``panels`` (``title(summary)`` each),
    with a shared legend below and ``suptitle`` above, saved as a PNG at ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(*shape, figsize=figsize, sharex=True, sharey=True)
    for ax, letter in zip(axes.ravel(), panels):
        s = table.summary(letter)
        plot_panel(ax, s, title(s), bound=bound)
    for ax in axes[-1]:
        ax.set_xlabel("sample size $N$")
    for ax in axes[:, 0]:
        ax.set_ylabel(r"estimation error $\epsilon(N)$")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), frameon=False)
    fig.suptitle(suptitle, fontsize=10)
    fig.tight_layout(rect=rect)
    path = Path(path)
    save_figure(fig, path, dpi=130)
    plt.close(fig)
    return path


def run_figure(args: argparse.Namespace, compute: Callable[..., Table], plot: Callable[..., Path], stem: str, label: str) -> int:
    """Compute a figure's table, save ``<stem>.csv`` and ``<stem>.png`` under ``args.out``, print the paths."""
    out = ensure_out_dir(args.out)
    t0 = time.perf_counter()
    table = compute(
        grid_config(args.quick), seed=args.seed, n_jobs=args.n_jobs, scheduler=args.scheduler, progress=not args.no_progress
    )
    elapsed = time.perf_counter() - t0
    csv_path = table.to_csv(out / f"{stem}.csv")
    png_path = plot(table, out / f"{stem}.png")
    print(f"{label}: {len(table)} rows in {elapsed:.1f} s")
    print(f"  wrote {csv_path}")
    print(f"  wrote {png_path}")
    return 0


def entry_point(
    name: str, doc: str | None, add_arguments: Callable[[argparse.ArgumentParser], None], run: Callable[[argparse.Namespace], int]
) -> Callable[..., int]:
    """The ``main(argv=None) -> int`` of the experiment script ``experiments/<name>.py``
    (:func:`script_main` over its options and its run)."""

    def main(argv: Sequence[str] | None = None) -> int:
        return script_main(name, doc, add_arguments, run, argv)

    main.__doc__ = f"Entry point of ``python experiments/{name}.py``."
    return main


def figure_entry_points(
    stem: str, label: str, compute: Callable[..., Table], plot: Callable[..., Path], doc: str | None
) -> tuple[Callable[[argparse.ArgumentParser], None], Callable[[argparse.Namespace], int], Callable[..., int]]:
    """``add_arguments``, ``run`` and ``main`` of a figure script: the common options, then
    :func:`run_figure` (``<stem>.csv`` and ``<stem>.png`` under ``--out``)."""

    def run(args: argparse.Namespace) -> int:
        return run_figure(args, compute, plot, stem, label)

    run.__doc__ = f"Compute, save ``{stem}.csv`` and ``.png`` under ``args.out``; print the paths."
    return add_common_arguments, run, entry_point(stem, doc, add_common_arguments, run)


def script_main(
    name: str,
    doc: str | None,
    add_arguments: Callable[[argparse.ArgumentParser], None],
    run: Callable[[argparse.Namespace], int],
    argv: Sequence[str] | None = None,
) -> int:
    """``main`` of an experiment script: parse, run, and print a package error as one line (exit 2)."""
    from encctl_gym.cli import OneLineParser, one_line
    from encctl_gym.errors import EncctlError

    parser = OneLineParser(description=(doc or "").strip().splitlines()[0])
    add_arguments(parser)
    args = parser.parse_args(argv)
    try:
        return run(args)
    except EncctlError as exc:
        print(f"{name}: error: {one_line(str(exc))}", file=sys.stderr)
        return 2
