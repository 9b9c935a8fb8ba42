"""The core's result semantics (masonryfw.semantics) against independent references."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

import masonryfw as mf
from masonryfw import connected_components as components


def rectangle_nodes(x0, y0, b, h):
    return np.array([x0, x0 + b, x0 + b, x0]), np.array([y0, y0, y0 + h, y0 + h])


def scipy_labels(n, edges):
    graph = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    _, first = np.unique(labels, return_index=True)
    return np.argsort(np.argsort(first))[labels]  # relabelled in order of each component's lowest block


@pytest.mark.parametrize("seed", range(20))
def test_components_match_scipy_on_random_graphs(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 300))
    edges = rng.integers(0, n, size=(int(rng.integers(0, 2 * n)), 2))
    np.testing.assert_array_equal(components(n, edges), scipy_labels(n, edges))


def test_a_long_chain_in_scrambled_order_is_one_component():
    order = np.random.default_rng(1).permutation(5000)
    edges = np.c_[order[:-1], order[1:]]
    assert (components(5000, edges) == 0).all()


def test_labels_follow_the_lowest_block():
    np.testing.assert_array_equal(components(6, np.array([[5, 1], [4, 2], [2, 0]])), [0, 1, 0, 2, 0, 1])


def test_polar_moment_of_a_rectangle_and_a_triangle_far_from_the_origin():
    rx, ry = rectangle_nodes(1e4, -2e3, 0.3, 0.1)
    tx, ty = np.array([5e3, 5e3 + 3.0, 5e3]), np.array([7e3, 7e3, 7e3 + 4.0])
    moment = mf.polar_moment(np.concatenate([rx, tx]), np.concatenate([ry, ty]), [4, 3])
    assert moment[0] == pytest.approx(0.03 * (0.3**2 + 0.1**2) / 12, rel=1e-9)
    # triangle: J_c = A (a^2 + b^2 + c^2) / 36, sides 3, 4, 5, A = 6
    assert moment[1] == pytest.approx(6 * (9 + 16 + 25) / 36, rel=1e-9)


