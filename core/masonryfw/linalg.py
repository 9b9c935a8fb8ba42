"""Sparse symmetric positive definite factorisations on a fixed pattern, shared by the solvers.

Interior points (``la``) and Newton iterations (``jmm``) factorise many matrices with
one sparsity pattern and changing values. CHOLMOD's supernodal Cholesky (through
cvxopt) is 5-8x faster than SciPy's SuperLU on the 2-D matrices masonry models give
(docs/benchmarks.md), and its ordering is computed once per pattern. SuperLU is the
fallback when cvxopt is not installed: cvxopt is GPL-3, so a GPL-free install drops it
and keeps working, slower, with the same results.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def has_cholmod() -> bool:
    try:
        import cvxopt.cholmod  # noqa: F401
    except ImportError:
        return False
    return True


def cholesky_factor(lower: sp.csc_matrix, use_cholmod: bool | None = None) -> CholmodFactor | SuperLUFactor:
    """A factor object for matrices with the lower-triangular pattern ``lower`` (CSC, sorted indices).

    ``factor.factorise(values)`` takes the values in the order of ``lower.data`` and
    returns False when the matrix is not positive definite (nothing raised: callers
    regularise or fall back); ``factor.solve(rhs)`` then solves for one vector or a
    2-D array of columns. ``factor.name`` says which backend is in use.
    """
    if use_cholmod is None:
        use_cholmod = has_cholmod()
    lower = sp.csc_matrix(lower)
    lower.sum_duplicates()  # sorted and unique: the order of the values given to factorise
    return CholmodFactor(lower) if use_cholmod else SuperLUFactor(lower)


class CholmodFactor:
    """Supernodal Cholesky of the lower triangle; one symbolic analysis (AMD) per pattern."""

    name = "cholmod"

    def __init__(self, lower: sp.csc_matrix):
        import cvxopt
        from cvxopt import cholmod

        self._cvxopt, self._cholmod = cvxopt, cholmod
        n = lower.shape[0]
        columns = np.repeat(np.arange(n), np.diff(lower.indptr))
        # column-sorted triplets keep cvxopt's storage in the order of lower.data; ones, not the
        # data, so that an explicit zero stays in the pattern; cvxopt matrices convert 3x faster than lists
        self._matrix = cvxopt.spmatrix(
            cvxopt.matrix(np.ones(lower.nnz)), cvxopt.matrix(lower.indices.astype(int)),
            cvxopt.matrix(columns), (n, n),
        )
        self._symbolic = None

    def factorise(self, values: np.ndarray) -> bool:
        self._matrix.V = self._cvxopt.matrix(np.asarray(values, dtype=float))
        if self._symbolic is None:
            self._symbolic = self._cholmod.symbolic(self._matrix, uplo="L")
        try:
            self._cholmod.numeric(self._matrix, self._symbolic)
        except ArithmeticError:
            self._symbolic = None  # a failed numeric factor is not reused
            return False
        return True

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        rhs = np.asarray(rhs, dtype=float)
        b = self._cvxopt.matrix(rhs.reshape(rhs.shape[0], -1))
        self._cholmod.solve(self._symbolic, b)
        return np.asarray(b).reshape(rhs.shape)


class SuperLUFactor:
    """SuperLU on the full symmetric matrix (symmetric mode, minimum degree on ``M + M^T``)."""

    name = "superlu"

    def __init__(self, lower: sp.csc_matrix):
        self._lower = lower
        self._lu = None

    def factorise(self, values: np.ndarray) -> bool:
        import scipy.sparse.linalg as spla

        lower = sp.csc_matrix((values, self._lower.indices, self._lower.indptr), shape=self._lower.shape)
        full = (lower + sp.tril(lower, k=-1).T).tocsc()
        try:
            self._lu = spla.splu(full, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                 options={"SymmetricMode": True})
        except RuntimeError:  # exactly singular
            return False
        return bool(np.all(self._lu.U.diagonal() > 0))

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        return self._lu.solve(np.asarray(rhs, dtype=float))
