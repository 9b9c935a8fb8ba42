"""mfp.cholesky_factor: CHOLMOD and its SuperLU fallback against a dense solve."""
import sys

import numpy as np
import pytest
import scipy.sparse as sp

import masonryfw.plugin_api as mfp

BACKENDS = [pytest.param(True, id="cholmod"), pytest.param(False, id="superlu")]


def laplacian_2d(n: int) -> sp.csc_matrix:
    """The 5-point Laplacian on an n x n grid plus the identity: SPD, 2-D sparsity like a wall's."""
    one = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    return (sp.kron(sp.identity(n), one) + sp.kron(one, sp.identity(n)) + sp.identity(n * n)).tocsc()


def factor_of(matrix, use_cholmod):
    lower = sp.tril(matrix, format="csc")
    lower.sort_indices()
    factor = mfp.cholesky_factor(lower, use_cholmod=use_cholmod)
    return factor, lower


@pytest.mark.parametrize("use_cholmod", BACKENDS)
def test_solves_match_a_dense_solve_for_new_values_on_the_same_pattern(use_cholmod):
    matrix = laplacian_2d(12)
    factor, lower = factor_of(matrix, use_cholmod)
    assert factor.name == ("cholmod" if use_cholmod else "superlu")
    rng = np.random.default_rng(1)
    rhs = rng.standard_normal(matrix.shape[0])
    block = rng.standard_normal((matrix.shape[0], 3))
    for scale in (1.0, 1e-6, 1e6):  # refactorised with other values: the symbolic analysis is reused
        shifted = lower.copy()
        shifted.setdiag(shifted.diagonal() * (1 + scale))
        assert factor.factorise(shifted.data)
        dense = shifted.toarray() + np.tril(shifted.toarray(), -1).T
        np.testing.assert_allclose(factor.solve(rhs), np.linalg.solve(dense, rhs), rtol=1e-10)
        np.testing.assert_allclose(factor.solve(block), np.linalg.solve(dense, block), rtol=1e-10)


@pytest.mark.parametrize("use_cholmod", BACKENDS)
def test_an_indefinite_matrix_is_reported_and_the_factor_recovers(use_cholmod):
    factor, lower = factor_of(laplacian_2d(5), use_cholmod)
    indefinite = lower.copy()
    indefinite.setdiag(indefinite.diagonal() - 3.0)  # same pattern; eigenvalues 5 - 3 - 4 cos.. < 0 for some
    assert np.linalg.eigvalsh(indefinite.toarray() + np.tril(indefinite.toarray(), -1).T).min() < 0
    assert not factor.factorise(indefinite.data)
    assert factor.factorise(lower.data)
    np.testing.assert_allclose(factor.solve(np.ones(25)), np.linalg.solve(laplacian_2d(5).toarray(), np.ones(25)))


def test_an_explicit_zero_stays_in_the_pattern():
    lower = sp.csc_matrix((np.array([2.0, 0.0, 3.0]), np.array([0, 1, 1]), np.array([0, 2, 3])), shape=(2, 2))
    factor = mfp.cholesky_factor(lower, use_cholmod=True)
    assert factor.factorise(np.array([2.0, 1.0, 3.0]))  # the zero slot now holds the off-diagonal 1
    np.testing.assert_allclose(factor.solve(np.array([1.0, 0.0])), np.linalg.solve([[2, 1], [1, 3]], [1, 0]))


def test_without_cvxopt_the_fallback_is_used(monkeypatch):
    monkeypatch.setitem(sys.modules, "cvxopt", None)  # `import cvxopt` now raises ImportError
    monkeypatch.setitem(sys.modules, "cvxopt.cholmod", None)
    assert not mfp.has_cholmod()
    factor, lower = factor_of(laplacian_2d(4), None)
    assert factor.name == "superlu"
    assert factor.factorise(lower.data)
    np.testing.assert_allclose(factor.solve(np.ones(16)), np.linalg.solve(laplacian_2d(4).toarray(), np.ones(16)))
