"""Primal-dual interior point for ``min c.x  s.t.  G x >= 0,  a.x = 1`` on the normal equations.

Unknowns: the mechanism ``x`` (free), the slacks ``s = G x >= 0``, the contact
multipliers ``y >= 0`` and the static multiplier ``lam`` of ``a.x = 1``
(``G^T y + lam a = c`` at the optimum). Each Newton step eliminates ``s`` and
``y``, leaving the normal equations ``M dx = G^T D G dx = b + a dlam`` with
``D = y / s``, bordered by ``a.dx = -(a.x - 1)``: two solves with one
Cholesky factor of ``M``, ``p = M^-1 b`` and ``q = M^-1 a``, then ``dlam``
from the border. The contact LPs are small-bandwidth 2-D graphs: ``M`` has a
few tens of non-zeros per column and factorises in 60-80 ms (CPU) at
10,000 units with CHOLMOD (supernodal, through ``cvxopt``), against 0.45 s for
Clarabel's QDLDL on the 5x larger KKT system of the conic form. Without
``cvxopt`` (GPL) the factor is SciPy's SuperLU on ``M``: slower, same method.

The method is Mehrotra's predictor-corrector with his starting point
(least-squares ``x`` and least-norm ``(y, lam)`` shifted into the interior),
separate primal and dual step lengths, and Gondzio's centrality correctors.
Like every path-following method it converges to the relative interior of
the optimal face (its analytic centre as ``mu -> 0``): tied mechanisms come
out as their mean, symmetric on a symmetric wall.

Near the optimum ``D`` spans 20 orders of magnitude: the factor is of ``M``
with each diagonal entry raised by 1e-13 of itself (more only if the
Cholesky meets a non-positive pivot), and the accepted direction is refined
on the unreduced Newton equations, whose residuals carry no ``D`` products:
that keeps the dual residual, hence the duality gap, at rounding level.
Problems without a finite optimum make the iterates diverge within a few
iterations: :class:`IPMFailure`, and the caller hands them to Clarabel.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

import masonryfw.plugin_api as mfp

from . import elimination

MAX_ITERATIONS = 100
STEP_TO_BOUNDARY = 0.995  # fraction of the step to the boundary of s >= 0, y >= 0
MAX_CORRECTORS = 2  # Gondzio centrality correctors per iteration
REGULARISATION = 1e-13  # diagonal shift of M, relative to each diagonal entry
MAX_REGULARISATION = 1e-5
REFINEMENT_STEPS = 4
STALL = 5  # iterations without halving the error: stalled (see ``acceptable``)
DIVERGENCE = 1e12  # |x| or |y| beyond this (non-dimensional): no finite optimum


class IPMFailure(RuntimeError):
    """The interior point could not certify an optimum (the caller falls back to Clarabel)."""


@dataclass(frozen=True)
class IPMResult:
    x: np.ndarray
    y: np.ndarray
    lam: float
    iterations: int


class NormalMatrix:
    """``M(d) = G^T diag(d) G`` on a fixed lower-triangular pattern and its factor.

    The pattern (with the whole diagonal) is built once; each iteration only
    computes its values, ``M_lower.data = pairs @ d`` where ``pairs`` maps
    every row of ``G`` to the products of its non-zeros that land on each
    entry of ``M``.
    """

    def __init__(self, constraints: sp.csr_matrix):
        self.G = constraints.tocsr()
        self.Gt = self.G.T.tocsr()
        self.n = self.G.shape[1]
        self.elimination = elimination.paired_columns(self.G)
        factored = self.G if self.elimination is None else elimination.reduced_rows(self.G, self.elimination)
        self.pattern, pairs = lower_pattern(factored)
        self.pairs = pairs.T  # values = pairs @ d (of the factored rows)
        self.diagonal = diagonal_slots(self.pattern)
        self.d = None
        self.factor = mfp.cholesky_factor(self.pattern)

    def factorise(self, d: np.ndarray) -> None:
        """Factor ``M(d)`` (its Schur complement over the columns not eliminated, :mod:`.elimination`) with each
        diagonal entry raised by ``REGULARISATION`` of itself (more if needed)."""
        self.d = d
        values = self.pairs @ (d if self.elimination is None else elimination.reduced_weights(d, self.elimination))
        diagonal = values[self.diagonal]
        floor = 1e-300 + 1e-30 * diagonal.max(initial=0.0)
        shift = REGULARISATION
        while shift <= MAX_REGULARISATION:
            shifted = values.copy()
            shifted[self.diagonal] += shift * diagonal + floor
            if self.factor.factorise(shifted):
                return
            shift *= 100.0
        raise IPMFailure("the normal equations are singular (a mechanism the contacts do not see)")

    def product(self, v: np.ndarray) -> np.ndarray:
        return self.Gt @ (self.d * (self.G @ v))

    def through_factor(self, rhs: np.ndarray) -> np.ndarray:
        """``M^-1 rhs`` by the factor of the last :meth:`factorise` (its shift included)."""
        if self.elimination is None:
            return self.factor.solve(rhs)
        return elimination.solve(self.factor, self.d, self.elimination, rhs)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """``M^-1 rhs`` with iterative refinement against the unshifted ``M`` (for the starting point)."""
        sol = self.through_factor(rhs)
        size = np.abs(rhs).max(initial=0.0)
        for _ in range(REFINEMENT_STEPS):
            residual = rhs - self.product(sol)
            if np.abs(residual).max(initial=0.0) <= 1e-15 * size:
                break
            sol += self.through_factor(residual)
        return sol


def lower_pattern(constraints: sp.csr_matrix) -> tuple[sp.csc_matrix, sp.csr_matrix]:
    """Lower triangle of ``G^T G`` plus the diagonal (CSC, sorted), and the map from row weights to its values.

    The map is returned with one row per row of ``G``: ``values = pairs.T @ d``.
    Rows of ``G`` have a handful of non-zeros (six for a dry joint end): they are
    padded to the longest row and all pairs of positions are formed at once.
    """
    G = constraints
    n_row, n = G.shape
    counts = np.diff(G.indptr)
    width = int(counts.max(initial=0))
    position = np.arange(G.nnz) - np.repeat(G.indptr[:-1], counts)
    row_of = np.repeat(np.arange(n_row), counts)
    cols = np.full((n_row, width), -1, dtype=np.int64)
    vals = np.zeros((n_row, width))
    cols[row_of, position] = G.indices
    vals[row_of, position] = G.data
    structure = abs(G).T.tocsr() @ abs(G) + sp.identity(n, format="csr")  # positive: no cancellation
    pattern = sp.tril(structure, format="csc")
    pattern.sort_indices()
    slot_of = sp.csc_matrix((np.arange(1, pattern.nnz + 1), pattern.indices, pattern.indptr), shape=(n, n))
    take = (cols[:, None, :] >= 0) & (cols[:, :, None] >= cols[:, None, :])  # (row, k, j): M[col k, col j]
    indptr = np.concatenate([[0], np.cumsum(take.sum(axis=(1, 2)))])
    flat = np.flatnonzero(take)
    row, k, j = flat // (width * width), (flat // width) % width, flat % width
    slot = np.asarray(slot_of[cols[row, k], cols[row, j]]).ravel() - 1
    products = vals[row, k] * vals[row, j]
    pairs = sp.csr_matrix((products, slot, indptr), shape=(n_row, pattern.nnz))
    return pattern, pairs


def diagonal_slots(pattern: sp.csc_matrix) -> np.ndarray:
    """Positions of the diagonal entries in the CSC data of ``pattern`` (lower triangle: first of each column)."""
    return pattern.indptr[:-1].copy()


def dot(u: np.ndarray, v: np.ndarray) -> float:
    """``u . v`` without BLAS: numpy hands long dot products to a threaded BLAS, whose thread
    start-up costs milliseconds on a loaded machine (measured: 7 ms for 12,000 entries)."""
    return float(np.multiply(u, v).sum())


def max_step(v: np.ndarray, dv: np.ndarray) -> float:
    """Largest ``t <= 1`` with ``v + t dv >= 0`` (``v > 0``)."""
    fastest = (dv / v).min(initial=0.0)
    return 1.0 if fastest >= -1.0 else -1.0 / fastest


@dataclass(frozen=True)
class Direction:
    """A Newton direction (``ds = G dx + rp`` keeps the primal residual at rounding level)."""

    dx: np.ndarray
    dy: np.ndarray
    dlam: float
    ds: np.ndarray

    def steps(self, s: np.ndarray, y: np.ndarray) -> tuple[float, float]:
        """Largest primal and dual steps that keep ``s`` and ``y`` non-negative."""
        return max_step(s, self.ds), max_step(y, self.dy)


class NewtonSystem:
    """The Newton equations at one iterate, reduced to ``M(y / (s + w y))`` bordered by ``a``.

    Unreduced (``s`` eliminated with ``ds = G dx + w dy + rp``; ``w = 0`` but for a regularised solve)::

        G dx + (s / y + w) dy = rc / y - rp
        G^T dy + a dlam   = rd
        a.dx              = -ra

    where ``s dy + y ds = rc`` is the complementarity target.
    """

    def __init__(self, normal: NormalMatrix, s, y, a, rp, ra, rd, weight):
        self.normal, self.s, self.y, self.a, self.w = normal, s, y, a, weight
        self.rp, self.ra, self.rd = rp, ra, rd
        self.d = y / (s + weight * y)
        normal.factorise(self.d)
        self.q = normal.through_factor(a)
        self.aq = dot(a, self.q)

    def _through_factor(self, f1, f2, f3) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
        """``(dx, dy, dlam, G dx)`` from one solve with the factor."""
        G, Gt, d = self.normal.G, self.normal.Gt, self.d
        p = self.normal.through_factor(Gt @ (d * f1) - f2)
        dlam = (f3 - dot(self.a, p)) / self.aq
        dx = p + self.q * dlam
        g_dx = G @ dx
        return dx, d * (f1 - g_dx), dlam, g_dx

    def direction(self, rc: np.ndarray) -> Direction:
        dx, dy, dlam, g_dx = self._through_factor(rc / self.y - self.rp, self.rd, -self.ra)
        return Direction(dx, dy, dlam, g_dx + self.w * dy + self.rp)

    def refine(self, step: Direction, rc: np.ndarray, dual_target: float) -> Direction:
        """Iterative refinement on the unreduced equations until the dual equation holds to ``dual_target``.

        The factor is of ``M`` whose entries span the range of ``y / s``; the
        unreduced residuals have no such products, so refinement restores the
        accuracy that the dual residual (and the duality gap) needs.
        """
        Gt, a = self.normal.Gt, self.a
        f1 = rc / self.y - self.rp
        dx, dy, dlam, g_dx = step.dx, step.dy, step.dlam, step.ds - self.rp - self.w * step.dy
        previous = np.inf
        for _ in range(REFINEMENT_STEPS):
            r2 = self.rd - Gt @ dy - a * dlam
            size = np.abs(r2).max()
            if size <= dual_target or size > 0.5 * previous:
                break
            previous = size
            r1 = f1 - g_dx - dy * (self.s / self.y + self.w)
            ex, ey, el, g_ex = self._through_factor(r1, r2, -self.ra - dot(a, dx))
            dx, dy, dlam, g_dx = dx + ex, dy + ey, dlam + el, g_dx + g_ex
        return Direction(dx, dy, dlam, g_dx + self.w * dy + self.rp)


def solve(cost, constraints, live, tolerance: float, weight: np.ndarray | None = None,
          normal: NormalMatrix | None = None, acceptable: float | None = None) -> IPMResult:
    """Solve ``min c.x, G x >= 0, a.x = 1`` to ``tolerance`` (relative residuals and gap) or raise IPMFailure.

    With ``weight`` (``w >= 0``, one per row) the static side becomes ``max lam - sum(w y^2) / 2``:
    the programme regularised by a quadratic in the multipliers, whose primal constraint is
    ``G x + w y >= 0``. The Newton steps keep their form, with ``D = y / (s + w y)``.
    ``normal``: the :class:`NormalMatrix` of ``constraints`` when the caller has it (a sequence of
    LPs with the same ``G``). ``acceptable``: a looser tolerance at which an iterate that has
    stopped improving (:data:`STALL` iterations without halving its error) is returned.
    """
    c = np.asarray(cost, dtype=float)
    a = np.asarray(live, dtype=float)
    normal = NormalMatrix(constraints) if normal is None else normal
    G, Gt = normal.G, normal.Gt
    m = G.shape[0]
    if m == 0:
        raise IPMFailure("no constraints")
    w = np.zeros(m) if weight is None else np.asarray(weight, dtype=float)

    x, s, y, lam = starting_point(normal, c, a)
    scale_c = 1.0 + np.abs(c).max()
    step_p = step_d = 0.0
    errors: list[float] = []
    for iteration in range(MAX_ITERATIONS + 1):
        rp = G @ x + w * y - s
        ra = dot(a, x) - 1.0
        rd = c - Gt @ y - lam * a
        mu = dot(s, y) / m
        primal_obj = dot(c, x) + dot(w * y, y)  # the gap of the regularised pair is c.x + y.w.y - lam
        primal_err = max(np.abs(rp).max() / (1.0 + np.abs(s).max()), abs(ra))
        dual_err = np.abs(rd).max() / scale_c
        gap_err = max(abs(primal_obj - lam), m * mu) / (1.0 + abs(primal_obj))
        error = max(primal_err, dual_err, gap_err)
        if error < tolerance:
            return IPMResult(x=x, y=y, lam=float(lam), iterations=iteration)
        errors.append(error)
        if acceptable is not None and error < acceptable and len(errors) > STALL and error > 0.5 * errors[-STALL - 1]:
            return IPMResult(x=x, y=y, lam=float(lam), iterations=iteration)
        if iteration == MAX_ITERATIONS:
            break
        if not (np.abs(x).max() < DIVERGENCE and np.abs(y).max() < DIVERGENCE and np.isfinite(mu)):
            raise IPMFailure(f"the iterates diverge after {iteration} iterations (no finite optimum)")

        newton = NewtonSystem(normal, s, y, a, rp, ra, rd, w)
        # Mehrotra: the affine-scaling predictor sets the centring and the second-order term
        affine = newton.direction(-s * y)
        step_p, step_d = affine.steps(s, y)
        mu_affine = dot(s + step_p * affine.ds, y + step_d * affine.dy) / m
        target = (mu_affine / mu) ** 3 * mu
        rc = target - s * y - affine.ds * affine.dy
        step = newton.direction(rc)
        step_p, step_d = step.steps(s, y)
        # Gondzio: push the products s_i y_i that a longer step would put outside
        # [0.1, 10] x target back inside, while that lengthens the step
        for _ in range(MAX_CORRECTORS):
            trial_p, trial_d = min(1.0, 1.5 * step_p + 0.1), min(1.0, 1.5 * step_d + 0.1)
            product = (s + trial_p * step.ds) * (y + trial_d * step.dy)
            correction = np.clip(0.1 * target - product, 0.0, None) + np.clip(10.0 * target - product, -10.0 * target, 0.0)
            corrected = newton.direction(rc + correction)
            new_p, new_d = corrected.steps(s, y)
            if new_p + new_d < 1.01 * (step_p + step_d):
                break
            step, step_p, step_d, rc = corrected, new_p, new_d, rc + correction
        dual_target = 0.1 * max(np.abs(rd).max(), tolerance * scale_c * 1e-6)
        step = newton.refine(step, rc, dual_target)
        step_p, step_d = step.steps(s, y)
        if weight is not None:  # y is in the primal residual too: one step for all
            step_p = step_d = min(step_p, step_d)
        step_p = STEP_TO_BOUNDARY * step_p
        step_d = STEP_TO_BOUNDARY * step_d
        x = x + step_p * step.dx
        s = s + step_p * step.ds
        y = y + step_d * step.dy
        lam = lam + step_d * step.dlam
    raise IPMFailure(
        f"not converged in {MAX_ITERATIONS} iterations (primal {primal_err:.1e}, dual {dual_err:.1e}, "
        f"gap {gap_err:.1e})"
    )


def starting_point(normal: NormalMatrix, c: np.ndarray, a: np.ndarray):
    """Mehrotra's: least-squares ``x`` with ``a.x = 1``, least-norm ``(y, lam)``, shifted inside."""
    G = normal.G
    normal.factorise(np.ones(G.shape[0]))
    q = normal.solve(a)
    x = q / dot(a, q)
    w = normal.solve(c)
    lam = dot(a, w) / dot(a, q)
    y = G @ (w - lam * q)
    s = G @ x
    s = s + max(-1.5 * s.min(), 0.0)
    y = y + max(-1.5 * y.min(), 0.0)
    sy = dot(s, y)
    if sy <= 0:  # s = y = 0 (both already centred at zero)
        s, y = s + 1.0, y + 1.0
        sy = dot(s, y)
    s = s + 0.5 * sy / y.sum()
    y = y + 0.5 * sy / s.sum()
    return x, s, y, lam
