"""The index calculus's precomputation in a file: saved once, loaded by a later run, checked.

The precomputation of :mod:`.index_calculus` depends only on the group (p, q, g) and the
factor-base bound B, so it can be computed once (``encctl-gym crack --save-precomputation
PATH``) and used by every later run on that group (``--load-precomputation PATH``, the
breaker option ``precomputation=PATH``, the environment's ``breaker_precomputation``). A file
holds either

* the solved factor base (``complete``): ``lambda(l)`` for the primes the relations determine, or
* the relations collected so far and the position of the residue walk
  (:class:`~.relations.RelationWalk`), written when the collection was interrupted: loading it
  resumes the collection where it stopped.

Format: an NPZ archive (``numpy.savez_compressed``, read with ``allow_pickle=False``: no pickles)
with a JSON ``header`` (format name, version, the group, B, the time spent so far) and integer
arrays: the logarithms and right-hand sides as little-endian bytes of the width of q
(``logs``, ``known``, ``rhs``), the relations as a sparse row list (``indptr``, ``cols``,
``coefs``). The file is written to a temporary name and renamed, so an interrupted write
leaves the previous file whole.

Reading is bounded (:data:`MAX_FILE_BYTES` of arrays, uncompressed and as the ``.npy`` headers
declare them, checked before they are allocated; :func:`encctl_gym._npz.read_npz`), a corrupt
archive is a :class:`~encctl_gym.errors.ConfigError`, and the content is checked: every field's type and range, every logarithm against
``g^lambda(l) = l^n (mod p)`` and every relation against ``(prod l^e)^n = g^rhs (mod p)``, so a
corrupt or edited file raises :class:`~encctl_gym.errors.ConfigError` naming the file and the
entry, never a wrong key later. :meth:`SavedPrecomputation.check_group` refuses a file of
another group or bound, naming what differs.
"""

from __future__ import annotations

import dataclasses
import json
import os
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gmpy2
import numpy as np

from .._npz import read_npz
from .._validation import check_int, check_nonnegative, check_regular_file, format_value
from ..crypto.arith import format_int
from ..crypto.group import GroupParams
from ..errors import ConfigError, EncctlError, ParameterError, ResourceLimitError
from .base import Cost
from .relations import Relation, RelationWalk
from .smoothness import check_bound, primes_up_to

__all__ = [
    "SavedPrecomputation",
    "PrecomputationInterrupted",
    "load_precomputation",
    "FORMAT",
    "VERSION",
    "MAX_FILE_BYTES",
    "max_relations",
]

#: The ``format`` of the header.
FORMAT = "encctl-gym index-calculus precomputation"
#: The version of the layout written; a file of another version is refused.
VERSION = 1
#: Largest total of a file's arrays, uncompressed (bytes): 1 GiB. A 128-bit group's solved factor
#: base is about 0.2 MB, its relations about 3 MB.
MAX_FILE_BYTES = 1 << 30
_MEMBERS = {"header", "logs", "known", "indptr", "cols", "coefs", "rhs"}
_HEADER_FIELDS = {"format", "version", "group", "bound", "complete", "walk", "cost", "phase_seconds", "phase_cpu_seconds"}


def _to_bytes(values: list[int], width: int) -> np.ndarray:
    raw = b"".join(int(v).to_bytes(width, "little") for v in values)
    return np.frombuffer(raw, dtype=np.uint8).reshape(len(values), width)


def _from_bytes(array: np.ndarray) -> list[int]:
    return [int.from_bytes(row.tobytes(), "little") for row in array]


@dataclasses.dataclass
class SavedPrecomputation:
    """The content of a precomputation file (see the module docstring).

    Attributes
    ----------
    group : GroupParams
        The group it belongs to.
    bound : int
        The factor-base bound B.
    logs : list of int or None, or None
        ``lambda(l)`` per prime ``l <= B`` (``None`` entries: not determined) when complete,
        else ``None``.
    relations : list of Relation
        The relations collected so far (empty in a complete file).
    walk : RelationWalk or None
        The next residue of the collection (``None`` in a complete file).
    cost : Cost
        The work spent on it so far (wall and CPU seconds, operation counts).
    phase_seconds, phase_cpu_seconds : dict
        Wall and CPU seconds per phase so far.
    path : str or None
        The file it was loaded from.
    read_seconds : float
        Wall seconds :func:`load_precomputation` took to read and check it (0 if not loaded).
    """

    group: GroupParams
    bound: int
    logs: list[int | None] | None
    relations: list[Relation]
    walk: RelationWalk | None
    cost: Cost
    phase_seconds: dict[str, float] = dataclasses.field(default_factory=dict)
    phase_cpu_seconds: dict[str, float] = dataclasses.field(default_factory=dict)
    path: str | None = None
    read_seconds: float = 0.0

    @property
    def complete(self) -> bool:
        """True if it holds the solved factor base (else relations to resume from)."""
        return self.logs is not None

    def check_group(self, group: GroupParams, bound: int | None = None) -> None:
        """Refuse to use it for another group, or with another factor-base bound.

        Raises
        ------
        ConfigError
            Naming the file and the first of p, q, g and B that differs, with both values.
        """
        where = f"the precomputation file {format_value(self.path or '(unsaved)')}"
        for name in ("p", "q", "g"):
            mine, theirs = getattr(self.group, name), getattr(group, name)
            if mine != theirs:
                raise ConfigError(
                    f"{where} is for another group: its {name} = {format_int(mine)} ({mine.bit_length()} bits), "
                    f"this group's {name} = {format_int(theirs)} ({theirs.bit_length()} bits)"
                )
        if bound is not None and bound != self.bound:
            raise ConfigError(f"{where} was made with factor-base bound {self.bound}, this breaker's bound is {bound}")

    def save(self, path: str | os.PathLike[str]) -> str:
        """Write it to ``path`` (an NPZ archive, whatever the suffix; replaced whole). Returns the path.

        Raises
        ------
        ConfigError
            If the file cannot be written.
        """
        target = Path(os.fspath(path))
        width = max(1, (self.group.q.bit_length() + 7) // 8)
        logs = self.logs or []
        rows = [r.row for r in self.relations]
        indptr = np.zeros(len(rows) + 1, dtype=np.int64)
        indptr[1:] = np.cumsum([len(r) for r in rows])
        header = {
            "format": FORMAT,
            "version": VERSION,
            "group": self.group.to_dict(),
            "bound": self.bound,
            "complete": self.complete,
            "walk": None if self.walk is None else [hex(self.walk.e), hex(self.walk.c)],
            "cost": self.cost.to_dict(),
            "phase_seconds": self.phase_seconds,
            "phase_cpu_seconds": self.phase_cpu_seconds,
        }
        arrays = {
            "header": np.array(json.dumps(header)),
            "logs": _to_bytes([v or 0 for v in logs], width),
            "known": np.array([v is not None for v in logs], dtype=bool),
            "indptr": indptr,
            "cols": np.array([j for r in rows for j in r], dtype=np.int64),
            "coefs": np.array([e for r in rows for e in r.values()], dtype=np.int64),
            "rhs": _to_bytes([r.rhs for r in self.relations], width),
        }
        try:
            fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", dir=target.parent if str(target.parent) else ".")
            try:
                with os.fdopen(fd, "wb") as f:
                    np.savez_compressed(f, **arrays)  # type: ignore[arg-type]
                mask = os.umask(0)
                os.umask(mask)
                os.chmod(tmp, 0o666 & ~mask)  # mkstemp's 0600 -> what open() would have given
                os.replace(tmp, target)
            except BaseException:
                Path(tmp).unlink(missing_ok=True)
                raise
        except OSError as exc:
            raise ConfigError(
                f"cannot write the precomputation file {format_value(str(target))}: {exc.strerror or exc}"
            ) from None
        self.path = str(target)
        return str(target)


class PrecomputationInterrupted(KeyboardInterrupt):
    """The index calculus's precomputation stopped by ``KeyboardInterrupt`` (Ctrl-C, or raised by
    a progress callback).

    A ``KeyboardInterrupt``, so a caller that does not look for it stops as on any Ctrl-C; one
    that does can :meth:`SavedPrecomputation.save` what was collected and resume later.

    Attributes
    ----------
    phase : str
        The phase it stopped in (``"relations"``, ``"linear algebra"``).
    state : SavedPrecomputation
        The relations collected so far and the walk's position (not complete).
    """

    def __init__(self, phase: str, state: SavedPrecomputation) -> None:
        super().__init__(f"index-calculus precomputation interrupted in its {phase} ({len(state.relations)} relations)")
        self.phase = phase
        self.state = state


def _fail(path: str, what: str) -> ConfigError:
    return ConfigError(f"the precomputation file {format_value(path)} {what}")


def _read_arrays(path: str) -> dict[str, np.ndarray]:
    return read_npz(
        path,
        where=f"the precomputation file {format_value(path)}",
        max_bytes=MAX_FILE_BYTES,
        max_members=len(_MEMBERS),
        limit_name="MAX_FILE_BYTES",
        members=_MEMBERS,
    )


def _header(path: str, arrays: dict[str, np.ndarray]) -> dict[str, Any]:
    raw = arrays["header"]
    if raw.dtype.kind != "U" or raw.shape != ():
        raise _fail(path, "has a header that is not one string")
    try:
        header = json.loads(str(raw[()]))
    except (ValueError, RecursionError) as exc:
        raise _fail(path, f"has a header that is not JSON ({format_value(str(exc))})") from None
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise _fail(path, f"is not a precomputation file: its header's format is not {FORMAT!r}")
    if header.get("version") != VERSION:
        raise _fail(path, f"has layout version {format_value(header.get('version'))}; this version reads {VERSION}")
    missing = _HEADER_FIELDS - set(header)
    if missing:
        raise _fail(path, f"has a header without {', '.join(sorted(missing))}")
    return header


def _array(path: str, arrays: dict[str, np.ndarray], name: str, kind: str, ndim: int) -> np.ndarray:
    a = arrays[name]
    if a.dtype.kind != kind or a.ndim != ndim:
        raise _fail(path, f"has an array {name!r} of dtype {a.dtype} and {a.ndim} dimensions")
    return a


#: Largest operation count a header may hold (2^63: far above any count a run reaches).
MAX_OPERATIONS = 1 << 63


def _cost(header: dict[str, Any]) -> tuple[Cost, list[dict[str, float]]]:
    """The header's cost and per-phase seconds: seconds finite and >= 0 (a NaN, a negative or a
    10^400 would become the deciphering time of a measured clock), counts integers in
    ``[0, MAX_OPERATIONS]``; a bad one raises :class:`~encctl_gym.errors.ParameterError` naming it."""
    raw = header["cost"]
    if not isinstance(raw, dict) or not all(isinstance(header[f], dict) for f in ("phase_seconds", "phase_cpu_seconds")):
        raise ParameterError("cost, phase_seconds and phase_cpu_seconds must be mappings")
    if not isinstance(raw["operations"], dict):
        raise ParameterError(f"cost.operations must be a mapping, got {format_value(raw['operations'])}")
    cost = Cost(
        check_nonnegative("cost.seconds", raw["seconds"]),
        {str(k): check_int(f"cost.operations.{k}", v, minimum=0, maximum=MAX_OPERATIONS) for k, v in raw["operations"].items()},
        check_nonnegative("cost.cpu_seconds", raw["cpu_seconds"]),
    )
    phases = [
        {str(k): check_nonnegative(f"{f}.{k}", v) for k, v in header[f].items()} for f in ("phase_seconds", "phase_cpu_seconds")
    ]
    return cost, phases


def max_relations(primes: int) -> int:
    """The most relations a file for a factor base of ``primes`` primes may hold: twice the primes
    plus 1000. The collection stops at ``k (1 + EXTRA_FRACTION) + EXTRA_CONSTANT`` relations and adds
    at most ``MAX_ROUNDS`` rounds of ``max(EXTRA_CONSTANT, EXTRA_FRACTION k)`` (about ``1.35 k + 140``);
    more cannot come from :meth:`SavedPrecomputation.save`, and each costs a check and a dict."""
    return 2 * primes + 1000


def _relations(name: str, arrays: dict[str, np.ndarray], group: GroupParams, primes: Sequence[int], width: int) -> list[Relation]:
    """The relations of an interrupted collection, each checked against ``(prod l^e)^n = g^rhs (mod p)``.

    At most :func:`max_relations` of them, each of at most ``2 (bits(p) + 16)`` primes: a row is
    ``lambda(|a|) - lambda(|b|)`` for a sieve pair with ``|a|, |b| < 2^(bits(p)/2 + 14)``
    (:func:`~.relations.sieve_region`), and ``|a|`` has fewer distinct prime factors than bits."""
    q, p, g, n = group.q, group.p, group.g, group.cofactor
    rhs = _array(name, arrays, "rhs", "u", 2)
    count, limit = rhs.shape[0], max_relations(len(primes))
    if count > limit:
        raise ResourceLimitError(
            f"the precomputation file {format_value(name)} holds {count} relations; a factor base of {len(primes)} "
            f"primes needs fewer than {limit} (max_relations)"
        )
    relations: list[Relation] = []
    indptr = _array(name, arrays, "indptr", "i", 1)
    cols, coefs = _array(name, arrays, "cols", "i", 1), _array(name, arrays, "coefs", "i", 1)
    if (
        indptr.shape != (count + 1,)
        or rhs.shape[1:] != (width,)
        or indptr[0] != 0
        or np.any(np.diff(indptr) < 0)
        or indptr[-1] != cols.size
        or cols.size != coefs.size
        or (cols.size and (cols.min() < 0 or cols.max() >= len(primes)))
    ):
        raise _fail(name, "has relation arrays that do not fit together")
    longest, most = (int(np.diff(indptr).max()) if count else 0), 2 * (p.bit_length() + 16)
    if longest > most:
        raise _fail(name, f"has a relation of {longest} primes; a pair a, b of the sieve has at most {most}")
    for i, r in enumerate(_from_bytes(rhs)):
        a, b = indptr[i], indptr[i + 1]
        row = dict(zip(cols[a:b].tolist(), coefs[a:b].tolist()))
        num = den = gmpy2.mpz(1)
        for j, e in row.items():
            if e > 0:
                num = num * gmpy2.powmod(primes[j], e, p) % p
            else:
                den = den * gmpy2.powmod(primes[j], -e, p) % p
        if r >= q or gmpy2.powmod(num, n, p) != gmpy2.powmod(g, r, p) * gmpy2.powmod(den, n, p) % p:
            raise _fail(name, f"has a wrong relation (number {i})")
        relations.append(Relation((row, r)))
    return relations


def load_precomputation(path: str | os.PathLike[str]) -> SavedPrecomputation:
    """Read and check a file written by :meth:`SavedPrecomputation.save`.

    Raises
    ------
    ConfigError
        If the file does not exist, is not a regular file, is not a precomputation file of this
        version, or a field, a logarithm or a relation is wrong (the message names the file and
        the entry); :class:`~encctl_gym.errors.ResourceLimitError` if its arrays exceed
        :data:`MAX_FILE_BYTES`.
    """
    start = time.perf_counter()
    name = check_regular_file("precomputation file", path)
    arrays = _read_arrays(name)
    header = _header(name, arrays)
    try:
        group = GroupParams.from_dict(header["group"]).verify()
        bound = check_bound(header["bound"])
        cost, phases = _cost(header)
        walk = None if header["walk"] is None else RelationWalk(*(int(v, 16) for v in header["walk"]))
    except (EncctlError, KeyError, TypeError, ValueError, AttributeError, OverflowError) as exc:
        raise _fail(name, f"has a bad header entry: {format_value(str(exc))}") from None
    q, p, g, n = group.q, group.p, group.g, group.cofactor
    width = max(1, (q.bit_length() + 7) // 8)
    primes = primes_up_to(bound)
    logs: list[int | None] | None = None
    relations: list[Relation] = []
    if header["complete"] is True:
        raw, known = _array(name, arrays, "logs", "u", 2), _array(name, arrays, "known", "b", 1)
        if raw.shape != (len(primes), width) or known.shape != (len(primes),):
            raise _fail(name, f"has {raw.shape[0]} logarithms; bound {bound} has {len(primes)} primes")
        logs = [v if k else None for v, k in zip(_from_bytes(raw), known.tolist())]
        for ell, v in zip(primes, logs):
            if v is not None and (v >= q or gmpy2.powmod(g, v, p) != gmpy2.powmod(ell, n, p)):
                raise _fail(name, f"has a wrong logarithm for the prime {ell}: g^lambda != {ell}^{n} (mod p)")
    elif header["complete"] is False and walk is not None:
        if not (0 < walk.e < q and 0 < walk.c < q):
            raise _fail(name, "has a residue walk outside [1, q)")
        relations = _relations(name, arrays, group, primes, width)
    else:
        raise _fail(name, "has a header that is neither complete nor a relation collection with its walk")
    return SavedPrecomputation(group, bound, logs, relations, walk, cost, phases[0], phases[1], name, time.perf_counter() - start)
