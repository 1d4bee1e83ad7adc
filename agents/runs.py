"""Training run directories: where a run goes, what its ``run.json`` holds, and finding runs.

A run directory is written by :func:`agents.train.train` and read by
:func:`agents.sb3.load_attacker`, ``encctl-gym evaluate`` and ``encctl-gym compare``; this
module is the one place that knows its layout:

=======================  ==================================================================
file                     content
=======================  ==================================================================
``run.json``             :class:`RunInfo`: algorithm, observation mode, environment
                         configuration, system label, seed, the resolved training
                         configuration, timing, and (after it ran) the final evaluation
``model.zip``            the model at the end of training
``best_model.zip``       the best model of the evaluation callback
``vecnormalize.npz``     observation statistics (when observations are normalised; arrays)
``learning_curve.npz``   the evaluation callback's record (:mod:`agents.curves`)
``learning_curve.png``   its plot
``evaluations.npz``      stable-baselines3's own evaluation log (returns, lengths)
``tb/``                  TensorBoard logs
=======================  ==================================================================

stable-baselines3's own loader unpickles the ``data`` entry of ``model.zip``;
:func:`~agents.sb3.load_attacker` does not use it: it rebuilds the model from ``run.json``'s
config and loads the archive's weights only (``torch.load(..., weights_only=True)``). Older runs
hold ``vecnormalize.pkl`` instead of ``vecnormalize.npz``; it, and stable-baselines3's loader for
a model the config cannot rebuild, are used only on request (``load_attacker(...,
allow_pickle=True)``, ``encctl-gym evaluate --allow-pickle``).
"""

from __future__ import annotations

import json
import os
import shutil
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from encctl_gym._validation import check_path_name, format_value, read_bounded
from encctl_gym.errors import ConfigError

__all__ = [
    "RUN_FILE",
    "MAX_RUN_FILE_BYTES",
    "RunInfo",
    "read_run",
    "check_model_file",
    "find_runs",
    "new_run_dir",
    "check_output_dir",
]

#: The metadata file that makes a directory a training run.
RUN_FILE = "run.json"
#: Largest ``run.json`` read (bytes); one written by ``train`` takes a few kilobytes.
MAX_RUN_FILE_BYTES = 16 * 2**20

#: Model files by the name ``which`` selects them with.
MODEL_FILES = {"final": "model.zip", "best": "best_model.zip"}


@dataclass(frozen=True)
class RunInfo:
    """The metadata of one training run (the content of its ``run.json``).

    Attributes
    ----------
    path : Path
        The run directory.
    algo : str
        Algorithm name (a key of :data:`agents.sb3.ALGORITHMS`).
    observation : str
        Observation mode the policy was trained with (``full``, ``no_budget``, ``blind``).
    env : dict
        The training environment's configuration (attack length set through the budget).
    system : str
        The system's label: a preset name, or the stem of the plant file given to ``--system``.
    seed : int
        Training seed.
    quick : bool
        A smoke-test run (``--quick``).
    meta : dict
        Everything in ``run.json``.
    """

    path: Path
    algo: str
    observation: str
    env: dict[str, Any]
    system: str
    seed: int
    quick: bool
    meta: dict[str, Any] = field(repr=False)

    @property
    def features(self) -> list[str]:
        """The features (:mod:`agents.features`) the policy was trained with (``[]`` for runs
        without the ``features`` entry)."""
        from .features import check_features

        return check_features(self.meta.get("config", {}).get("features") or [], f"{self.path / RUN_FILE}: config.features")

    @property
    def custom_plant(self) -> bool:
        """True if the plant matrices were given explicitly (``--system FILE``), not by a preset."""
        return self.env.get("A") is not None or self.env.get("B") is not None

    def model_path(self, which: str = "final") -> Path:
        """The model file of ``which`` (``"final"`` or ``"best"``); :class:`ConfigError` if absent."""
        if which not in MODEL_FILES:
            raise ConfigError(f"which must be one of {', '.join(MODEL_FILES)}, got {which!r}")
        p = self.path / MODEL_FILES[which]
        if not p.is_file():
            raise ConfigError(f"no {MODEL_FILES[which]} in {self.path}")
        check_model_file(p)
        return p


def check_model_file(path: str | Path) -> None:
    """Check, without unpickling anything, that ``path`` is a model archive as stable-baselines3
    saves it (a readable zip file holding the ``data`` member).

    Raises
    ------
    ConfigError
        For a file that is not a zip archive, a damaged one, or one without ``data``.
    """
    p = Path(path)
    try:
        with zipfile.ZipFile(p) as archive:
            names = archive.namelist()
    except (zipfile.BadZipFile, OSError, ValueError, EOFError) as exc:
        raise ConfigError(f"cannot load {p}: not a readable model archive (a zip file): {format_value(str(exc))}") from None
    if "data" not in names:
        raise ConfigError(
            f"cannot load {p}: not a stable-baselines3 model archive (no 'data' member among {format_value(names)})"
        )


def read_run(run_dir: str | Path) -> RunInfo:
    """Read and check a run directory's ``run.json``.

    Parameters
    ----------
    run_dir : path
        A directory written by ``encctl-gym train``.

    Returns
    -------
    RunInfo

    Raises
    ------
    ConfigError
        If the directory does not exist (naming its ``-quick`` sibling when there is one, the
        directory ``train --quick`` writes), its ``run.json`` is missing, larger than :data:`MAX_RUN_FILE_BYTES`,
        is not valid JSON (including integers of over 4300 digits and nesting deeper than
        Python's recursion limit), or lacks a field (``algo``, ``observation``, ``env``) or has
        one of the wrong type.
    """
    path = Path(run_dir)
    meta_path = path / RUN_FILE
    if not path.exists():
        quick = path.with_name(path.name + "-quick") if path.name else None
        hint = (
            f"; a smoke-test run (--quick) of that name is {str(quick)!r}"
            if quick is not None and (quick / RUN_FILE).is_file()
            else ""
        )
        raise ConfigError(f"the run directory {str(path)!r} does not exist{hint}")
    if not meta_path.is_file():
        raise ConfigError(f"{str(path)!r} is not a training run (no {RUN_FILE})")
    raw = read_bounded("the run file", meta_path, MAX_RUN_FILE_BYTES, "MAX_RUN_FILE_BYTES", error=ConfigError)
    try:
        meta = json.loads(raw.decode("utf-8"))
    except (OSError, ValueError, RecursionError) as exc:  # ValueError: bad JSON, bad UTF-8, an integer of over 4300 digits
        what = (
            "nests too deeply"
            if isinstance(exc, RecursionError)
            else format_value(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
        )
        raise ConfigError(f"cannot read {meta_path}: {what}") from None
    if not isinstance(meta, dict):
        raise ConfigError(f"{meta_path} must hold a JSON object, got {type(meta).__name__}")
    for key, typ in (("algo", str), ("observation", str), ("env", dict)):
        if not isinstance(meta.get(key), typ):
            raise ConfigError(f"{meta_path}: field {key!r} must be a {typ.__name__}, got {meta.get(key)!r}")
    config = meta.get("config", {})
    if not isinstance(config, dict):
        raise ConfigError(f"{meta_path}: field 'config' must be an object, got {config!r}")
    env = meta["env"]
    system = meta.get("system") or config.get("system") or env.get("preset") or "custom"
    seed = meta.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int):
        raise ConfigError(f"{meta_path}: field 'seed' must be an integer, got {seed!r}")
    return RunInfo(
        path=path,
        algo=meta["algo"],
        observation=meta["observation"],
        env=env,
        system=str(system),
        seed=seed,
        quick=bool(config.get("quick", False)),
        meta=meta,
    )


def find_runs(
    roots: Sequence[str | Path], *, include_quick: bool = False, left_out: list[tuple[Path, str]] | None = None
) -> list[RunInfo]:
    """The training runs (a ``run.json`` and a ``model.zip``) under ``roots``.

    A root that is itself a run is taken as given; under any other root every direct
    subdirectory that is a run counts, quick (smoke-test) runs only with ``include_quick``.
    The directories with a ``run.json`` that are not taken (a quick run, a run without
    ``model.zip``) are appended to ``left_out`` with the reason, when it is given.

    Raises
    ------
    ConfigError
        If a root does not exist, or a run's ``run.json`` is broken (:func:`read_run`).
    """
    out: list[RunInfo] = []
    for root in roots:
        root = Path(root)
        if (root / RUN_FILE).exists():
            out.append(read_run(root))
            continue
        if not root.is_dir():
            raise ConfigError(f"runs directory {str(root)!r} does not exist")
        for meta in sorted(root.glob(f"*/{RUN_FILE}")):
            if not (meta.parent / MODEL_FILES["final"]).exists():
                if left_out is not None:
                    left_out.append((meta.parent, f"no {MODEL_FILES['final']} (training unfinished or failed)"))
                continue
            info = read_run(meta.parent)
            if include_quick or not info.quick:
                out.append(info)
            elif left_out is not None:
                left_out.append((meta.parent, "a smoke-test run (--quick); give its directory to --runs to include it"))
    return out


def new_run_dir(parent: str | Path, name: str, *, overwrite: bool = False) -> Path:
    """Create the directory of a new run and return it; an earlier run is never silently replaced.

    Parameters
    ----------
    parent : path
        Where runs are kept.
    name : str
        The wanted directory name.
    overwrite : bool
        Replace an earlier run of that name (its files are deleted first, so nothing of it, such
        as an old ``best_model.zip``, survives into the new run).

    Returns
    -------
    Path
        ``parent / name`` if it is free (or ``overwrite``), else the first free
        ``parent / f"{name}-{i}"``, ``i = 2, 3, ...``.

    Raises
    ------
    ConfigError
        If ``name`` is not a plain directory name, ``parent`` exists but is not a directory or
        cannot be created, or ``overwrite`` is asked for a directory that holds files but no run
        (it is not deleted).
    """
    if not name or Path(name).name != name or name in (".", ".."):
        raise ConfigError(f"run name must be a plain directory name, got {name!r}")
    check_path_name("run name (--name)", name)
    parent = Path(parent)
    check_output_dir(parent, "the runs directory (--out)")
    target = parent / name
    check_path_name("run directory", target)
    if overwrite and target.is_symlink():  # rmtree refuses a link; deleting what it points to is not asked
        raise ConfigError(
            f"--overwrite refuses to delete {str(target)!r}: it is a symbolic link (to {os.readlink(target)!r}); "
            "remove the link or choose another --name"
        )
    if target.exists() and overwrite:
        if not target.is_dir():
            raise ConfigError(f"{str(target)!r} exists and is not a directory")
        if any(target.iterdir()):
            if not (target / RUN_FILE).exists():
                raise ConfigError(f"--overwrite refuses to delete {str(target)!r}: it holds files but no {RUN_FILE}")
            shutil.rmtree(target)
    elif target.exists() and (not target.is_dir() or any(target.iterdir())):
        i = 2
        while (parent / f"{name}-{i}").exists():
            i += 1
        target = parent / f"{name}-{i}"
    try:
        target.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"cannot create the run directory {str(target)!r}: {exc.strerror or exc}") from None
    return target


def check_output_dir(path: str | Path, what: str = "the output directory") -> Path:
    """Create the directory ``path`` (with its parents) if needed, before any work is done.

    Raises
    ------
    ConfigError
        If ``path`` or one of its parents is a file, or the directory cannot be created.
    """
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise ConfigError(f"{what} {str(p)!r} exists and is not a directory")
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"cannot create {what} {str(p)!r}: {exc.strerror or exc}") from None
    return p
