"""The cones' share of the interior point's normal matrix, summed in one compiled pass (numba).

For every cone ``c`` the rows ``R_c G_c`` (``R_c`` its scaling's ``diag(sigma) U^T``, :mod:`.cones`) and the
products of their columns two by two, summed over the cones of one group (the vertices of one interface share
their columns) and added to the pattern's entries. NumPy took 0.43 s of the 1.45 s of an iteration at 20,884
blocks doing the same in passes over temporaries of (pairs x cones) (docs/benchmarks.md, "la in 3D at scale").
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def normal_values(values, rows, group_start, slot, first, second, size):
    """The pattern's values (``size``) of ``sum over cones of (R_c G_c)^T (R_c G_c)``.

    ``values`` (cone, k, width): each cone's rows of ``G`` in its padded columns; ``rows`` (cone, r, k): ``R_c``;
    ``group_start`` (group,): each group's first cone; ``slot`` (group, pair): where each pair ``(first[p],
    second[p])`` of a group's columns lands in the pattern's data (``size`` for a padded column: dropped).
    """
    n_cone, k, width = values.shape
    n_row = rows.shape[1]
    n_pair = first.size
    n_group = group_start.size
    out = np.zeros(size + 1)
    scaled = np.empty((n_row, width))
    summed = np.empty(n_pair)
    for g in range(n_group):
        end = group_start[g + 1] if g + 1 < n_group else n_cone
        summed[:] = 0.0
        for c in range(group_start[g], end):
            for r in range(n_row):
                for j in range(width):
                    total = 0.0
                    for a in range(k):
                        total += rows[c, r, a] * values[c, a, j]
                    scaled[r, j] = total
            for p in range(n_pair):
                i, j = first[p], second[p]
                total = 0.0
                for r in range(n_row):
                    total += scaled[r, i] * scaled[r, j]
                summed[p] += total
        for p in range(n_pair):
            out[slot[g, p]] += summed[p]
    return out[:size]
