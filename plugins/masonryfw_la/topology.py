"""Graph questions on the contact graph (blocks = nodes, interfaces = edges)."""
from __future__ import annotations

import numpy as np

import masonryfw as mf


MAX_NAMED = 20


def components(n_block: int, edges: np.ndarray) -> np.ndarray:
    """Connected-component label of every block through the given ``(k, 2)`` block pairs.

    Labels are 0..k-1 in order of the lowest block index of each component. Min-label
    hooking with pointer jumping, vectorised over the edges: every block's parent only
    decreases, so each component ends on its lowest block. (``scipy.sparse.csgraph``
    would do it too, but importing it imports ``scipy.sparse.linalg``: 0.1 s of every
    ``masonryfw solve``.)
    """
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    parent = np.arange(n_block)
    while True:
        a, b = parent[edges[:, 0]], parent[edges[:, 1]]
        apart = a != b
        if not apart.any():
            break
        np.minimum.at(parent, np.maximum(a, b)[apart], np.minimum(a, b)[apart])
        while True:  # pointer jumping: every block straight onto its current root
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand
    return np.unique(parent, return_inverse=True)[1].reshape(n_block)


def name_blocks(blocks: np.ndarray) -> str:
    """``"12, 13"`` (the first few, then how many more)."""
    shown = ", ".join(str(b) for b in blocks[:MAX_NAMED])
    more = blocks.size - MAX_NAMED
    return shown + (f" and {more} more" if more > 0 else "")


def check_supported(wall) -> None:
    """Raise when a connected group of blocks touches no support and holds no component.

    Such a group moves as a rigid body with no joint resisting: the problem has
    no finite multiplier, and naming the blocks is more useful than "unbounded".
    """
    labels = components(wall.n_block, wall.sides)
    anchored = wall.support | wall.fixed.any(axis=1)
    supported = np.zeros(labels.max() + 1, dtype=bool)
    np.logical_or.at(supported, labels, anchored)
    loose = np.flatnonzero(~supported[labels])
    if loose.size:
        what = f"block {loose[0]} is" if loose.size == 1 else f"blocks {name_blocks(loose)} are"
        raise mf.SolveError(
            f"{what} not supported: no chain of contacts links them to a support or a held "
            "block, so they can move as a rigid body with no joint resisting"
        )
