"""Linear algebra modulo a prime q for the index calculus, on python-flint's matrices.

The relations of :mod:`.index_calculus` form a sparse system ``R x = r (mod q)`` with small
integer coefficients and one unknown per factor-base prime. :func:`solve_mod_prime` reduces the
augmented matrix ``[R | r]`` to reduced row echelon form with FLINT (``nmod_mat`` when q fits in
a machine word, ``fmpz_mod_mat`` otherwise) and reads off every unknown the system determines;
unknowns it leaves free are reported as ``None``, never guessed.
"""

from __future__ import annotations

import heapq
from collections.abc import Callable, Mapping, Sequence

from .._validation import check_int, format_value
from ..errors import BreakerError, OptionalDependencyError, ParameterError
from ..resources import format_bytes

__all__ = ["solve_mod_prime", "flint_backend", "structured_elimination", "DENSE_BYTES_PER_ENTRY"]

Report = Callable[[str, float, "float | None"], None]

_WORD = 1 << 63
#: Peak bytes per entry of the dense system ``[R | r]`` in :func:`solve_mod_prime` (the FLINT
#: matrix, its echelon form and the entries read back), measured for a 2120 x 2001 system with a
#: 61-bit q: 91 bytes.
DENSE_BYTES_PER_ENTRY = 91
#: Structured elimination pivots on columns of at most this weight (rows containing them) ...
MAX_PIVOT_WEIGHT = 24
#: ... while an elimination step costs at most this many entry updates (weight times the
#: pivot row's length); beyond, the rest is left to the dense elimination.
MAX_STEP_WORK = 4096


def _flint():  # python-flint is a core dependency; the error is for broken installs
    try:
        import flint
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise OptionalDependencyError("the index calculus needs python-flint; install it with: pip install python-flint") from exc
    return flint


def flint_backend(q: int) -> str:
    """``"nmod_mat"`` for ``q < 2^63``, else ``"fmpz_mod_mat"``."""
    return "nmod_mat" if q < _WORD else "fmpz_mod_mat"


def structured_elimination(
    rows: Sequence[Mapping[int, int]], rhs: Sequence[int], q: int, report: Report | None = None
) -> tuple[list[dict[int, int]], list[int], list[tuple[int, dict[int, int], int]]]:
    """Shrink a sparse system modulo a prime q before the dense elimination.

    Repeatedly takes the column of smallest weight (number of rows containing it, at most
    :data:`MAX_PIVOT_WEIGHT`), picks its shortest row as the pivot, subtracts multiples of the
    pivot from the other rows containing the column (so they no longer do) and sets the pivot
    aside. Each step removes one row and one column, so the excess of rows over columns is kept,
    and the remaining system (the *core*) has the same solutions in the remaining unknowns; an
    eliminated unknown follows from its pivot row once the later ones are known
    (back-substitution, in :func:`solve_mod_prime`). A column of weight 1 is a singleton: its row
    is only needed for its own unknown. Stops when every column is heavier, or a step would
    update more than :data:`MAX_STEP_WORK` entries. ``report(phase, done, total)``, if given, is
    told the pivots so far (phase ``"linear algebra: structured elimination"``, of the columns).

    Returns
    -------
    (list of dict, list of int, list of (int, dict, int))
        The core rows and right-hand sides (reduced modulo q), and the pivots
        ``(column, row, rhs)`` in the order of elimination.
    """
    work = [{j: c % q for j, c in row.items() if c % q} for row in rows]
    right = [r % q for r in rhs]
    holders: dict[int, set[int]] = {}
    for i, row in enumerate(work):
        for j in row:
            holders.setdefault(j, set()).add(i)
    heap = [(len(h), j) for j, h in holders.items()]
    heapq.heapify(heap)
    pivots: list[tuple[int, dict[int, int], int]] = []
    alive = set(range(len(work)))
    phase, columns = "linear algebra: structured elimination", len(holders)
    while heap:
        if report is not None and not len(pivots) % 256:
            report(phase, len(pivots), columns)
        weight, col = heapq.heappop(heap)
        held = holders.get(col)
        if held is None or len(held) != weight:
            continue  # a stale entry (the column was eliminated or its weight changed)
        if weight > MAX_PIVOT_WEIGHT:
            break
        if weight == 0:  # every row holding it was eliminated: the column has left the system
            del holders[col]
            continue
        piv = min(held, key=lambda i: len(work[i]))
        prow = work[piv]
        if (weight - 1) * len(prow) > MAX_STEP_WORK:
            break
        pivots.append((col, prow, right[piv]))
        alive.discard(piv)
        for j in prow:
            holders[j].discard(piv)
        inv = pow(prow[col], -1, q)
        for other in list(held):
            orow = work[other]
            factor = orow[col] * inv % q
            for j, c in prow.items():
                v = (orow.get(j, 0) - factor * c) % q
                if v:
                    if j not in orow:
                        holders[j].add(other)
                    orow[j] = v
                elif j in orow:
                    del orow[j]
                    holders[j].discard(other)
            right[other] = (right[other] - factor * right[piv]) % q
        del holders[col]
        for j in prow:
            if j != col and j in holders:
                heapq.heappush(heap, (len(holders[j]), j))
    if report is not None:
        report(phase, len(pivots), columns)
    core = sorted(alive)
    return [work[i] for i in core], [right[i] for i in core], pivots


def solve_mod_prime(
    rows: Sequence[Mapping[int, int]], rhs: Sequence[int], ncols: int, q: int, report: Report | None = None
) -> tuple[list[int | None], int]:
    """Solve ``sum_j rows[i][j] x_j = rhs[i] (mod q)`` for every unknown the system determines.

    Parameters
    ----------
    rows : sequence of mappings
        Sparse rows ``{column: coefficient}`` (integers, any sign).
    rhs : sequence of int
        Right-hand sides.
    ncols : int
        Number of unknowns.
    q : int
        A prime modulus.
    report : callable, optional
        ``report(phase, done, total)`` (:meth:`~.base.Deadline.report`): the pivots of the
        structured elimination, then the dense elimination as one unit (FLINT reports nothing
        from inside; its phase names the core's size and its expected memory).

    Returns
    -------
    (list of int or None, int)
        ``x_j`` in ``[0, q)`` for every determined unknown (``None`` for a free or absent one),
        and the rank of the system. The system is first shrunk by
        :func:`structured_elimination`; an unknown it eliminated is reported when the unknowns of
        its pivot row are (a determined unknown whose pivot row holds a free one is reported as
        ``None``: never a guess).

    Raises
    ------
    ParameterError
        If ``q < 2``, ``ncols < 0``, a column lies outside ``[0, ncols)`` or the lengths differ.
    BreakerError
        If the system is inconsistent (a relation is wrong: never expected).
    """
    if len(rows) != len(rhs):
        raise ParameterError(f"rows and rhs differ in length: {len(rows)} != {len(rhs)}")
    ncols = check_int("ncols", ncols, minimum=0)
    q = check_int("q", q, minimum=2)
    flint = _flint()
    used = sorted({j for row in rows for j, c in row.items() if c % q})
    if used and not (0 <= used[0] and used[-1] < ncols):
        bad = used[0] if used[0] < 0 else used[-1]
        raise ParameterError(f"a row has a coefficient in column {format_value(bad)}, outside [0, ncols = {ncols})")
    if not used:
        return [None] * ncols, 0
    rows, rhs, pivots = structured_elimination(rows, rhs, q, report)
    if report is not None:
        width = len({j for row in rows for j in row}) + 1
        dense = f"linear algebra: dense {len(rows)} x {width} ({format_bytes(len(rows) * width * DENSE_BYTES_PER_ENTRY)})"
        report(dense, 0, 1)
    solution, rank = _solve_dense(flint, rows, rhs, ncols, q)
    if report is not None:
        report(dense, 1, 1)
    for col, prow, r in reversed(pivots):  # back-substitution, latest pivot first
        known = [(c, solution[j]) for j, c in prow.items() if j != col]
        if all(v is not None for _, v in known):
            total = sum(c * v for c, v in known if v is not None)
            solution[col] = (r - total) * pow(prow[col], -1, q) % q
    return solution, rank + len(pivots)


def _solve_dense(
    flint, rows: Sequence[Mapping[int, int]], rhs: Sequence[int], ncols: int, q: int
) -> tuple[list[int | None], int]:
    # The dense elimination of a (reduced) system with FLINT: every unknown it determines.
    used = sorted({j for row in rows for j, c in row.items() if c % q})
    if not used:
        if any(r % q for r in rhs):
            raise BreakerError("the relations are inconsistent modulo q (a wrong relation)")
        return [None] * ncols, 0
    pos = {j: i for i, j in enumerate(used)}
    width = len(used) + 1
    # Built entry by entry into a zero matrix: the rows are sparse (a dozen entries of a few
    # thousand), and a full list of Python integers costs more than the elimination.
    if q < _WORD:
        mat = flint.nmod_mat(len(rows), width, q)
    else:
        mat = flint.fmpz_mod_mat(len(rows), width, flint.fmpz_mod_ctx(q))
    for i, (row, r) in enumerate(zip(rows, rhs)):
        for j, c in row.items():
            if c % q:
                mat[i, pos[j]] = c % q
        mat[i, width - 1] = r % q
    reduced, rank = mat.rref()
    solution: list[int | None] = [None] * ncols
    # Only the entries needed are read back (reading the whole reduced matrix costs half as
    # much as the elimination): the leading column of each nonzero row, found by one scan since
    # they increase, then each pivot row's entries in the free columns and its right-hand side.
    leads: list[int] = []
    lead = 0
    for i in range(rank):
        while int(reduced[i, lead]) == 0:
            lead += 1
        leads.append(lead)
        lead += 1
    if leads and leads[-1] == width - 1:
        raise BreakerError("the relations are inconsistent modulo q (a wrong relation)")
    pivot_cols = set(leads)
    free = [k for k in range(width - 1) if k not in pivot_cols]
    for i, lead in enumerate(leads):
        if all(int(reduced[i, k]) == 0 for k in free):  # this unknown does not depend on a free one
            solution[used[lead]] = int(reduced[i, width - 1])
    return solution, rank
    values = [int(v) for v in reduced.entries()]
    pivots = []
    for i in range(rank):
        reduced_row = values[i * width : (i + 1) * width]
        lead = next(k for k, v in enumerate(reduced_row) if v)
        if lead == width - 1:
            raise BreakerError("the relations are inconsistent modulo q (a wrong relation)")
        pivots.append((lead, reduced_row))
    pivot_cols = {lead for lead, _ in pivots}
    free = [k for k in range(width - 1) if k not in pivot_cols]
    for lead, reduced_row in pivots:
        if all(reduced_row[k] == 0 for k in free):  # this unknown does not depend on a free one
            solution[used[lead]] = reduced_row[width - 1]
    return solution, rank
