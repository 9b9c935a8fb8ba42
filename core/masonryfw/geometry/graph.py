"""Graphs of blocks, in NumPy alone: the connected components of a node set through its pairs, and the row of a
list of block pairs (a model's interfaces) that joins two given blocks."""
from __future__ import annotations

from typing import NamedTuple

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


class PairIndex(NamedTuple):
    """A list of block pairs ready to be searched by its two blocks in either order (:func:`pair_index`)."""

    keys: np.ndarray  # sorted min * n_block + max of every pair
    rows: np.ndarray  # the pair's row in the list, for each sorted key
    n_block: int


def pair_key(sides: np.ndarray, n_block: int) -> np.ndarray:
    """``(k,)`` one integer per ``(k, 2)`` block pair, the same for either order of its two blocks."""
    sides = np.asarray(sides, dtype=np.int64).reshape(-1, 2)
    return sides.min(axis=1) * n_block + sides.max(axis=1)


def pair_index(pairs: np.ndarray, n_block: int) -> PairIndex:
    """The index of the ``(k, 2)`` block ``pairs`` (``interface_blocks``), made once for many searches."""
    keys = pair_key(pairs, n_block)
    order = np.argsort(keys, kind="stable")
    return PairIndex(keys[order], order, n_block)


def find_pairs(index: PairIndex, sides: np.ndarray) -> np.ndarray:
    """``(k,)`` the row of the indexed pairs joining each of the ``(k, 2)`` block pairs ``sides`` (the first
    of several), -1 where none does."""
    wanted = pair_key(sides, index.n_block)
    if index.keys.size == 0:
        return np.full(wanted.size, -1)
    at = np.clip(np.searchsorted(index.keys, wanted), 0, index.keys.size - 1)
    return np.where(index.keys[at] == wanted, index.rows[at], -1)
