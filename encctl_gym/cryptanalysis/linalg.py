"""Linear algebra modulo a prime q for the index calculus, on python-flint's matrices.

The relations of :mod:`.index_calculus` form a sparse system ``R x = r (mod q)`` with small
integer coefficients and one unknown per factor-base prime. :func:`solve_mod_prime` reduces the
augmented matrix ``[R | r]`` to reduced row echelon form with FLINT (``nmod_mat`` when q fits in
a machine word, ``fmpz_mod_mat`` otherwise) and reads off every unknown the system determines;
unknowns it leaves free are reported as ``None``, never guessed.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from .._validation import check_int, format_value
from ..errors import BreakerError, OptionalDependencyError, ParameterError

__all__ = ["solve_mod_prime", "flint_backend"]

_WORD = 1 << 63


def _flint():  # python-flint is a core dependency; the error is for broken installs
    try:
        import flint
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise OptionalDependencyError("the index calculus needs python-flint; install it with: pip install python-flint") from exc
    return flint


def flint_backend(q: int) -> str:
    """``"nmod_mat"`` for ``q < 2^63``, else ``"fmpz_mod_mat"``."""
    return "nmod_mat" if q < _WORD else "fmpz_mod_mat"


def solve_mod_prime(rows: Sequence[Mapping[int, int]], rhs: Sequence[int], ncols: int, q: int) -> tuple[list[int | None], int]:
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

    Returns
    -------
    (list of int or None, int)
        ``x_j`` in ``[0, q)`` for every determined unknown (``None`` for a free or absent one),
        and the rank of the system.

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
