"""topology.components against SciPy's connected components (an independent implementation)."""
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from masonryfw_la.topology import components


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
