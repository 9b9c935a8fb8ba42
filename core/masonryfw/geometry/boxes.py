"""The broad phase of every search for blocks or faces that touch or overlap: pairs of axis-aligned boxes that
meet, in 2D or 3D, found on a uniform grid so that the work grows with the number of boxes, not its square.

Each box (grown by ``pad``; a negative pad shrinks it) is entered in every cell of a grid it covers, the cell as
large as the median box; pairs are formed only inside a cell, then kept where the boxes meet on every axis. An
optional ``group`` (a face's plane, say) keeps pairs within a group: it is one more coordinate of the cells.
"""
from __future__ import annotations

import numpy as np


def ragged_expand(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(row, position)``: every row repeated ``counts[row]`` times, with its position 0..count-1."""
    counts = np.asarray(counts, dtype=np.int64)
    row = np.repeat(np.arange(counts.size), counts)
    position = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    return row, position


#: A box covering more grid cells than this is paired with every box directly (one huge support block would
#: otherwise be entered in millions of cells).
MOST_CELLS = 4096


def box_pairs(low: np.ndarray, high: np.ndarray, pad: float = 0.0, group: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
    """``(a, b)``, ``a < b``: the boxes ``[low, high]`` (``(n, d)``) that meet once each is grown by ``pad`` on
    every side (touching counts), of one ``group`` when groups are given."""
    low, high = np.asarray(low, dtype=float) - pad, np.asarray(high, dtype=float) + pad
    n = low.shape[0]
    if n < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    high = np.maximum(high, low)
    group = np.zeros(n, dtype=np.int64) if group is None else np.asarray(group, dtype=np.int64)
    cell = float(np.median((high - low).max(axis=1)))
    cell = cell if cell > 0 and np.isfinite(cell) else 1.0
    origin = low.min(axis=0)
    first = np.floor((low - origin) / cell).astype(np.int64)
    span = np.floor((high - origin) / cell).astype(np.int64) - first + 1
    cells = np.prod(span.astype(float), axis=1)
    large = cells > MOST_CELLS
    small = np.flatnonzero(~large)
    row, position = ragged_expand(cells[small].astype(np.int64))
    row = small[row]
    keys = [group[row]]
    stride = np.ones(row.size, dtype=np.int64)
    for axis in range(low.shape[1]):  # each entry's cell, one axis at a time
        size = span[row, axis]
        keys.append(first[row, axis] + (position // stride) % size)
        stride = stride * size
    order = np.lexsort([row, *keys[::-1]])
    member = row[order]
    cell_of = np.stack([k[order] for k in keys], axis=1)
    starts = np.flatnonzero(np.concatenate(([True], (np.diff(cell_of, axis=0) != 0).any(axis=1))))
    ends = np.append(starts[1:], member.size)
    partners = np.repeat(ends, ends - starts) - np.arange(member.size) - 1
    left, offset = ragged_expand(partners)
    a, b = member[left], member[left + 1 + offset]
    big = np.flatnonzero(large)
    if big.size:  # each large box against every box
        a = np.concatenate([a, np.repeat(big, n)])
        b = np.concatenate([b, np.tile(np.arange(n), big.size)])
    a, b = np.minimum(a, b), np.maximum(a, b)
    key = np.sort(a[a != b] * n + b[a != b])
    key = key[np.concatenate(([True], np.diff(key) != 0))] if key.size else key
    a, b = key // n, key % n
    meet = ((low[a] <= high[b]) & (low[b] <= high[a])).all(axis=1) & (group[a] == group[b])
    return a[meet], b[meet]
