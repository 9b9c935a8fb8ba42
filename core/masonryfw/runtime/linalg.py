"""Sparse symmetric positive definite factorisations on a fixed pattern, shared by the solvers.

Interior points (``la``) and Newton iterations (``jmm``) factorise many matrices with
one sparsity pattern and changing values. CHOLMOD's supernodal Cholesky (through
cvxopt) is 5-8x faster than SciPy's SuperLU on the 2-D matrices masonry models give
(docs/benchmarks.md), and its ordering is computed once per pattern. SuperLU is the
fallback when cvxopt is not installed: cvxopt is GPL-3, so a GPL-free install drops it
and keeps working, slower, with the same results.

The ordering of a large pattern (``ND_MIN_SIZE`` columns and more) is METIS's nested
dissection (pymetis, MIT and Apache-2.0) rather than CHOLMOD's AMD: cvxopt's CHOLMOD is
built without METIS, and on the 2-D meshes and contact graphs of big walls nested
dissection halves the fill's work (jmm, 307,680 DOFs: a factor in 0.33 s against 0.65 s;
docs/architecture.md). Without pymetis, AMD.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def has_cholmod() -> bool:
    """Whether CHOLMOD (through cvxopt) is installed: :func:`cholesky_factor` then uses it, else SuperLU."""
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


ND_MIN_SIZE = 20_000  # columns from which nested dissection pays for its own time (see fill_reducing_order)


def fill_reducing_order(lower: sp.csc_matrix) -> np.ndarray | None:
    """METIS's nested dissection of the graph of ``lower`` (a permutation), or None: pattern smaller than
    ``ND_MIN_SIZE`` or no pymetis (then CHOLMOD's AMD). Measured on the 307,680-DOF jmm pattern of the
    2,432-block scale wall: 2.1 s once, then every factor in 0.33 s against 0.65 s (AMD); on la's
    30,196-column LP of 10,067 blocks the factor and the solve 16 and 30 % faster."""
    if lower.shape[0] < ND_MIN_SIZE:
        return None
    try:
        import pymetis
    except ImportError:
        return None
    graph = (lower + lower.T).tocsr()
    graph.setdiag(0)
    graph.eliminate_zeros()
    order, _ = pymetis.nested_dissection(pymetis.CSRAdjacency(graph.indptr, graph.indices))  # (perm, iperm)
    return np.asarray(order, dtype=np.int64)


class CholmodFactor:
    """Supernodal Cholesky of the lower triangle; one symbolic analysis per pattern (nested dissection for a
    large pattern, :func:`fill_reducing_order`, else AMD)."""

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
        order = fill_reducing_order(lower)
        self._order = None if order is None else cvxopt.matrix(order.astype(int))
        self._symbolic = None

    def factorise(self, values: np.ndarray) -> bool:
        self._matrix.V = self._cvxopt.matrix(np.asarray(values, dtype=float))
        if self._symbolic is None:
            ordered = {} if self._order is None else {"p": self._order}
            self._symbolic = self._cholmod.symbolic(self._matrix, uplo="L", **ordered)
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
