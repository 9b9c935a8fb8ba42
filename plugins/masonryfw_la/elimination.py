"""The normal matrix with its paired columns eliminated: the slip bounds of the non-associative programme.

A column with exactly two non-zeros, both 1, in rows that no other such column touches (the slip bound ``s`` of a
non-associative joint end: rows ``s - dt >= 0`` and ``s + dt >= 0``) meets the other columns only through those
two rows, and its own entry of ``M = G^T D G`` is ``d1 + d2``. Eliminating it leaves the Schur complement over the
other columns, ``S = G'^T D' G'``: the two rows become one, their difference ``g1 - g2`` over the kept columns,
weighted ``d1 d2 / (d1 + d2)`` (formed so, without the cancellation of ``Mxx - Mxs Mss^-1 Msx``: near the optimum
``d`` spans twenty orders of magnitude). The non-associative programme's factor is then the size of the
associative one's (7,291 columns against 21,595 on the 2,432-block running-bond wall).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp


class Elimination(NamedTuple):
    """Which columns of ``G`` are eliminated and the rows that carry them."""

    columns: np.ndarray  # the eliminated columns
    kept: np.ndarray  # the others, in order
    first: np.ndarray  # (eliminated,) the row of each one's first 1
    second: np.ndarray  # and of its second
    other: np.ndarray  # the rows that touch no eliminated column
    first_rows: sp.csr_matrix  # G[first] over the kept columns
    second_rows: sp.csr_matrix  # G[second] over the kept columns


def paired_columns(constraints: sp.csr_matrix) -> Elimination | None:
    """The columns of ``constraints`` that can be eliminated (module docstring), or None when there are none."""
    by_column = constraints.tocsc()
    by_column.sort_indices()
    counts = np.diff(by_column.indptr)
    candidates = np.flatnonzero(counts == 2)
    start = by_column.indptr[candidates]
    ones = (by_column.data[start] == 1.0) & (by_column.data[start + 1] == 1.0)
    candidates, start = candidates[ones], start[ones]
    first, second = by_column.indices[start], by_column.indices[start + 1]
    touched = np.bincount(np.concatenate([first, second]), minlength=constraints.shape[0])
    alone = (touched[first] == 1) & (touched[second] == 1)
    if not alone.any():
        return None
    columns, first, second = candidates[alone], first[alone], second[alone]
    kept = np.setdiff1d(np.arange(constraints.shape[1]), columns)
    other = np.setdiff1d(np.arange(constraints.shape[0]), np.concatenate([first, second]))
    over_kept = constraints[:, kept].tocsr()
    return Elimination(columns, kept, first, second, other, over_kept[first], over_kept[second])


def reduced_rows(constraints: sp.csr_matrix, elimination: Elimination) -> sp.csr_matrix:
    """``G'``: the rows without eliminated columns, then one row ``g1 - g2`` per eliminated column (kept columns)."""
    other = constraints[elimination.other][:, elimination.kept]
    return sp.vstack([other, elimination.first_rows - elimination.second_rows], format="csr")


def reduced_weights(d: np.ndarray, elimination: Elimination) -> np.ndarray:
    """``D'`` of :func:`reduced_rows`: the other rows' weights, then ``d1 d2 / (d1 + d2)`` per eliminated column."""
    d1, d2 = d[elimination.first], d[elimination.second]
    return np.concatenate([d[elimination.other], d1 * d2 / (d1 + d2)])


def solve(factor, d: np.ndarray, elimination: Elimination, rhs: np.ndarray) -> np.ndarray:
    """``M(d)^-1 rhs`` with ``factor`` the factor of the Schur complement ``S(d)`` over the kept columns."""
    d1, d2 = d[elimination.first], d[elimination.second]
    own = d1 + d2  # the eliminated columns' diagonal of M
    r_kept, r_own = rhs[elimination.kept], rhs[elimination.columns]
    scaled = r_own / own
    kept = factor.solve(r_kept - (elimination.first_rows.T @ (d1 * scaled) + elimination.second_rows.T @ (d2 * scaled)))
    solution = np.empty_like(rhs)
    solution[elimination.kept] = kept
    solution[elimination.columns] = (r_own - d1 * (elimination.first_rows @ kept)
                                     - d2 * (elimination.second_rows @ kept)) / own
    return solution
