"""Graphs of blocks: the connected components of a node set through its pairs, in NumPy alone."""
from __future__ import annotations

import numpy as np


def connected_components(n_node: int, edges: np.ndarray) -> np.ndarray:
    """Connected-component label of every node through the ``(k, 2)`` node pairs ``edges``.

    Labels are 0..k-1 in order of the lowest node of each component. Min-label
    hooking with pointer jumping, vectorised over the edges: every node's parent
    only decreases, so each component ends on its lowest node. (``scipy.sparse.csgraph``
    would do it too, but importing it imports ``scipy.sparse.linalg``: 0.1 s of every
    ``masonryfw solve``.)
    """
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    parent = np.arange(n_node)
    while True:
        a, b = parent[edges[:, 0]], parent[edges[:, 1]]
        apart = a != b
        if not apart.any():
            break
        np.minimum.at(parent, np.maximum(a, b)[apart], np.minimum(a, b)[apart])
        while True:  # pointer jumping: every node straight onto its current root
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand
    return np.unique(parent, return_inverse=True)[1].reshape(n_node)
