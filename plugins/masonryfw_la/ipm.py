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

With ``cone_size = 3`` the rows of ``G`` come in second-order cones of three
rows (la in 3D: Coulomb's cone at each interface vertex, ``(n.v, mu t0.v,
mu t1.v)``) and ``y`` lies in the same cones. The method is the same on
Nesterov and Todd's scaling (:mod:`.cones`): ``D = W^-2`` becomes a symmetric
3 x 3 block per cone, so ``M`` keeps the sparsity of ``G^T G`` over each cone's
rows (one vertex's: the same two blocks). It is summed from the rows
``diag(sigma) U^T G`` of each cone (``W^-1 = U diag(sigma) U^T``), never from
``W^-2`` formed first (:class:`ConeEntries`); one step length serves primal and
dual; the predictor-corrector's second-order term is the cones' Jordan product
and Gondzio's correctors act on the spectral values of each cone's product.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

import masonryfw.plugin_api as mfp

from . import cones as cone_kinds
from . import elimination

MAX_ITERATIONS = 100
STEP_TO_BOUNDARY = 0.995  # fraction of the step to the boundary of s >= 0, y >= 0
MAX_CORRECTORS = 3  # Gondzio centrality correctors per iteration (the 10,000-unit wall: 79 iterations with 2, 65 with 3)
#: Second-order cones: their factor costs ten times a solve, and the house of 4,390 blocks takes 50, 36, 33 and
#: 31 iterations with 0, 2, 3 and 4 correctors.
CONE_CORRECTORS = 4
#: Second-order cones: an iterate within this many times the tolerance that has stopped improving is returned.
#: Their normal equations lose digits near the optimum faster than an LP's: the 20,884-block brick house stalls
#: at 4.4e-9 against the tolerance 1e-9, then diverges.
CONE_ACCEPTABLE = 100.0
REGULARISATION = 1e-13  # diagonal shift of M, relative to each diagonal entry
MAX_REGULARISATION = 1e-5
REFINEMENT_STEPS = 4
#: Refinement stops once the dual equation holds to this share of the tolerance: the dual residual sits at 1e-16
#: while the gap decides convergence (the 10,000-unit wall), and below it refining cannot change when the iterate
#: converges (65 solves fewer there, the same iterations).
DUAL_FLOOR = 1e-3
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
    error: float  # the largest of the relative residuals and gap (below the tolerance, or the acceptable one)


class NormalMatrix:
    """``M(D) = G^T D G`` on a fixed lower-triangular pattern and its factor.

    ``D`` is diagonal (an LP: one weight per row of ``G``) or, for second-order cones of
    ``cone_size`` rows, a symmetric block per cone, ``W^-2``. The pattern (with the whole
    diagonal) is built once; each iteration only computes its values: for an LP
    ``M_lower.data = pairs @ d`` where ``pairs`` maps every row to the products of its
    non-zeros that land on each entry of ``M``; for cones from the rows ``diag(sigma) U^T G``
    of each (:class:`.cones.LorentzScaling`).
    """

    def __init__(self, constraints: sp.csr_matrix, cone_size: int = 1):
        self.G = constraints.tocsr()
        self.Gt = self.G.T.tocsr()
        self.n = self.G.shape[1]
        self.elimination = elimination.paired_columns(self.G) if cone_size == 1 else None
        factored = self.G if self.elimination is None else elimination.reduced_rows(self.G, self.elimination)
        self.cones: ConeEntries | None = None
        if cone_size == 1:
            self.pattern, pairs = lower_pattern(factored)
            self.pairs = pairs.T  # values = pairs @ d (of the factored rows)
        else:
            self.pattern, self.cones = cone_pattern(factored, cone_size)
        self.diagonal = diagonal_slots(self.pattern)
        self.scaling: cone_kinds.OrthantScaling | cone_kinds.LorentzScaling | None = None
        self.factor = mfp.cholesky_factor(self.pattern)

    def factorise(self, scaling) -> None:
        """Factor ``M(D)`` for ``D = W^-2`` of ``scaling`` (an LP: its Schur complement over the columns not
        eliminated, :mod:`.elimination`) with each diagonal entry raised by ``REGULARISATION`` of itself (more
        if needed)."""
        self.scaling = scaling
        if self.cones is not None:
            values = self.cones.normal_values(scaling.normal_rows, self.pattern.nnz)
        else:
            weights = scaling.normal_weights
            values = self.pairs @ (weights if self.elimination is None
                                   else elimination.reduced_weights(weights, self.elimination))
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
        return self.Gt @ self.scaling.times_normal_weights(self.G @ v)

    def through_factor(self, rhs: np.ndarray) -> np.ndarray:
        """``M^-1 rhs`` by the factor of the last :meth:`factorise` (its shift included)."""
        if self.elimination is None:
            return self.factor.solve(rhs)
        return elimination.solve(self.factor, self.scaling.normal_weights, self.elimination, rhs)

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


class ConeEntries(NamedTuple):
    """Where the cones' products land in the normal matrix. The cones of one interface (its vertices) share their
    columns: consecutive cones with the same columns are a group, whose products are summed before they are
    placed. Every group has the same pairs of positions ``(i, j)``, ``i >= j`` among the padded columns (the
    columns are sorted: ``M[cols[i], cols[j]]`` is in the lower triangle); a pair with a padded column goes to a
    slot past the pattern's, dropped."""

    values: np.ndarray  # (cone, k, width) each row's values in its cone's columns (0 where it has none)
    group_start: np.ndarray  # (group,) each group's first cone
    slot: np.ndarray  # (group, pair) the place of each pair of positions in the pattern's data

    def normal_values(self, rows: np.ndarray, size: int) -> np.ndarray:
        """The pattern's values of ``sum over cones of (R_c G_c)^T (R_c G_c)`` for ``rows`` R (cone, r, k)."""
        from . import normal_products

        first, second = np.tril_indices(self.values.shape[2])
        return normal_products.normal_values(self.values, np.ascontiguousarray(rows), self.group_start, self.slot,
                                             first, second, size)


def cone_pattern(constraints: sp.csr_matrix, cone_size: int = 1) -> tuple[sp.csc_matrix, ConeEntries]:
    """Lower triangle of ``G^T D G`` plus the diagonal (CSC, sorted), for ``D`` block diagonal with a block per
    cone of ``cone_size`` rows, and where each cone's products land in it.

    A cone's rows have a handful of non-zeros (six for a dry joint end in 2D, twelve
    for a vertex in 3D): each cone's columns are padded to the widest cone's.
    """
    G = constraints.tocsr()
    k = cone_size
    n_row, n = G.shape
    n_cone = n_row // k
    row_of = np.repeat(np.arange(n_row), np.diff(G.indptr))
    cone_of = row_of // k
    by_cone = sp.csr_matrix((np.ones(G.nnz), (cone_of, G.indices)), shape=(n_cone, n))  # each cone's columns
    by_cone.sum_duplicates()
    counts = np.diff(by_cone.indptr)
    width = int(counts.max(initial=0))
    position = np.arange(by_cone.nnz) - np.repeat(by_cone.indptr[:-1], counts)
    cols = np.full((n_cone, width), -1, dtype=np.int64)
    cols[np.repeat(np.arange(n_cone), counts), position] = by_cone.indices
    key = np.repeat(np.arange(n_cone), counts) * (n + 1) + by_cone.indices  # sorted: cone, then column
    at = np.searchsorted(key, cone_of * (n + 1) + G.indices) - by_cone.indptr[cone_of]
    values = np.zeros((n_cone, k, width))
    values[cone_of, row_of % k, at] = G.data
    structure = abs(by_cone).T.tocsr() @ abs(by_cone) + sp.identity(n, format="csr")  # positive: no cancellation
    pattern = sp.tril(structure, format="csc")
    pattern.sort_indices()
    slot_of = sp.csc_matrix((np.arange(1, pattern.nnz + 1), pattern.indices, pattern.indptr), shape=(n, n))
    group_start = np.flatnonzero(np.r_[True, (cols[1:] != cols[:-1]).any(axis=1)])  # cones sharing their columns
    lead = cols[group_start]
    first, second = np.tril_indices(width)
    valid = (lead[:, first] >= 0) & (lead[:, second] >= 0)
    slot = np.full(valid.shape, pattern.nnz, dtype=np.int64)
    slot[valid] = np.asarray(slot_of[lead[:, first][valid], lead[:, second][valid]]).ravel() - 1
    return pattern, ConeEntries(values, group_start, slot)


def lower_pattern(constraints: sp.csr_matrix) -> tuple[sp.csc_matrix, sp.csr_matrix]:
    """An LP's :func:`cone_pattern` and the map from the row weights to its values: ``values = pairs.T @ d``
    (one row per row of ``G``)."""
    pattern, entries = cone_pattern(constraints)
    row = entries.values[:, 0, :]
    n_row = row.shape[0]
    first, second = np.tril_indices(row.shape[1])
    slot = entries.slot[np.repeat(np.arange(entries.group_start.size), np.diff(np.r_[entries.group_start, n_row]))]
    kept = slot < pattern.nnz  # (row, pair): each row has its group's pairs, with its own products
    products = (row[:, first] * row[:, second])[kept]
    indptr = np.concatenate([[0], np.cumsum(kept.sum(axis=1))])
    return pattern, sp.csr_matrix((products, slot[kept], indptr), shape=(n_row, pattern.nnz))


def diagonal_slots(pattern: sp.csc_matrix) -> np.ndarray:
    """Positions of the diagonal entries in the CSC data of ``pattern`` (lower triangle: first of each column)."""
    return pattern.indptr[:-1].copy()


def dot(u: np.ndarray, v: np.ndarray) -> float:
    """``u . v`` without BLAS: numpy hands long dot products to a threaded BLAS, whose thread
    start-up costs milliseconds on a loaded machine (measured: 7 ms for 12,000 entries)."""
    return float(np.multiply(u, v).sum())


@dataclass(frozen=True)
class Direction:
    """A Newton direction (``ds = G dx + rp`` keeps the primal residual at rounding level)."""

    dx: np.ndarray
    dy: np.ndarray
    dlam: float
    ds: np.ndarray

    def steps(self, cones, s: np.ndarray, y: np.ndarray, together: bool = False) -> tuple[float, float]:
        """Largest primal and dual steps that keep ``s`` and ``y`` in the cones (``together``: one for both)."""
        primal, dual = cones.max_step(s, self.ds), cones.max_step(y, self.dy)
        return (min(primal, dual),) * 2 if together else (primal, dual)


class NewtonSystem:
    """The Newton equations at one iterate, reduced to ``M(W^-2)`` bordered by ``a``.

    Unreduced (``s`` eliminated with ``ds = G dx + w dy + rp``; ``w = 0`` but for a regularised LP)::

        G dx + (W^2 + w) dy = W (lambda \\ rc) - rp
        G^T dy + a dlam     = rd
        a.dx                = -ra

    where ``lambda o (W^-1 ds + W dy) = rc`` is the complementarity target (:mod:`.cones`; for an LP
    ``W^2 = s / y`` and ``W (lambda \\ rc) = rc / y``).
    """

    def __init__(self, normal: NormalMatrix, scaling, a, rp, ra, rd):
        self.normal, self.scaling, self.a = normal, scaling, a
        self.rp, self.ra, self.rd = rp, ra, rd
        normal.factorise(scaling)
        self.q = normal.through_factor(a)
        self.aq = dot(a, self.q)

    def _through_factor(self, f1, f2, f3) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
        """``(dx, dy, dlam, G dx)`` from one solve with the factor."""
        G, Gt, weights = self.normal.G, self.normal.Gt, self.scaling.times_normal_weights
        p = self.normal.through_factor(Gt @ weights(f1) - f2)
        dlam = (f3 - dot(self.a, p)) / self.aq
        dx = p + self.q * dlam
        g_dx = G @ dx
        return dx, weights(f1 - g_dx), dlam, g_dx

    def direction(self, rc: np.ndarray) -> Direction:
        dx, dy, dlam, g_dx = self._through_factor(self.scaling.target_rhs(rc) - self.rp, self.rd, -self.ra)
        return Direction(dx, dy, dlam, g_dx + self.scaling.primal_shift(dy) + self.rp)

    def refine(self, step: Direction, rc: np.ndarray, dual_target: float) -> Direction:
        """Iterative refinement on the unreduced equations until the dual equation holds to ``dual_target``.

        The factor is of ``M`` whose entries span the range of ``y / s``; the
        unreduced residuals have no such products, so refinement restores the
        accuracy that the dual residual (and the duality gap) needs.
        """
        Gt, a = self.normal.Gt, self.a
        f1 = self.scaling.target_rhs(rc) - self.rp
        dx, dy, dlam = step.dx, step.dy, step.dlam
        g_dx = step.ds - self.rp - self.scaling.primal_shift(dy)
        previous = np.inf
        for _ in range(REFINEMENT_STEPS):
            r2 = self.rd - Gt @ dy - a * dlam
            size = np.abs(r2).max()
            if size <= dual_target or size > 0.5 * previous:
                break
            previous = size
            r1 = f1 - g_dx - self.scaling.times_normal_weights_inverse(dy)
            ex, ey, el, g_ex = self._through_factor(r1, r2, -self.ra - dot(a, dx))
            dx, dy, dlam, g_dx = dx + ex, dy + ey, dlam + el, g_dx + g_ex
        return Direction(dx, dy, dlam, g_dx + self.scaling.primal_shift(dy) + self.rp)


def cones_of(rows: int, cone_size: int):
    """The orthant of ``rows`` rows (``cone_size`` 1), or ``rows / 3`` second-order cones (``cone_size`` 3)."""
    if cone_size == 1:
        return cone_kinds.Orthant(rows)
    if cone_size != 3 or rows % 3:
        raise ValueError(f"second-order cones of 3 rows only ({rows} rows in cones of {cone_size})")
    return cone_kinds.SecondOrderCones(rows // 3)


def solve(cost, constraints, live, tolerance: float, weight: np.ndarray | None = None,
          normal: NormalMatrix | None = None, acceptable: float | None = None, cone_size: int = 1,
          progress=None) -> IPMResult:
    """Solve ``min c.x, G x in K, a.x = 1`` to ``tolerance`` (relative residuals and gap) or raise IPMFailure.

    ``K`` is the orthant (an LP: ``G x >= 0``) or, with ``cone_size = 3``, second-order cones of three rows.
    With ``weight`` (``w >= 0``, one per row; on cones zero but on each cone's first row) the static side becomes
    ``max lam - sum(w y^2) / 2``: the programme regularised by a quadratic in the multipliers, whose primal
    constraint is ``G x + w y`` in ``K``. The Newton steps keep their form, with ``D = y / (s + w y)`` (cones:
    ``(W^2 + w e0 e0^T)^-1``, :class:`.cones.LorentzScaling`).
    ``normal``: the :class:`NormalMatrix` of ``constraints`` when the caller has it (a sequence of
    LPs with the same ``G``). ``acceptable``: a looser tolerance at which an iterate that has
    stopped improving (:data:`STALL` iterations without halving its error) is returned.
    ``progress(iteration, error)``: called after every iteration.
    """
    c = np.asarray(cost, dtype=float)
    a = np.asarray(live, dtype=float)
    normal = NormalMatrix(constraints, cone_size) if normal is None else normal
    G, Gt = normal.G, normal.Gt
    m = G.shape[0]
    if m == 0:
        raise IPMFailure("no constraints")
    cones = cones_of(m, cone_size)
    if weight is not None and cone_size != 1 and np.any(np.asarray(weight).reshape(-1, cone_size)[:, 1:]):
        raise ValueError("on cones a regularised programme's weight is on each cone's first row only")
    w = np.zeros(m) if weight is None else np.asarray(weight, dtype=float)
    orthant = cone_size == 1

    x, s, y, lam = starting_point(normal, cones, c, a)
    scale_c = 1.0 + np.abs(c).max()
    step_p = step_d = 0.0
    errors: list[float] = []
    best = IPMResult(x=x, y=y, lam=float(lam), iterations=0, error=np.inf)
    for iteration in range(MAX_ITERATIONS + 1):
        rp = G @ x + w * y - s
        ra = dot(a, x) - 1.0
        rd = c - Gt @ y - lam * a
        mu = dot(s, y) / cones.degree
        primal_obj = dot(c, x) + dot(w * y, y)  # the gap of the regularised pair is c.x + y.w.y - lam
        primal_err = max(np.abs(rp).max() / (1.0 + np.abs(s).max()), abs(ra))
        dual_err = np.abs(rd).max() / scale_c
        gap_err = max(abs(primal_obj - lam), dot(s, y)) / (1.0 + abs(primal_obj))
        error = max(primal_err, dual_err, gap_err)
        if progress is not None:
            progress(iteration, error)
        if error < best.error:
            best = IPMResult(x=x, y=y, lam=float(lam), iterations=iteration, error=error)
        if error < tolerance:
            return best
        errors.append(error)
        usable = acceptable is not None and best.error < acceptable
        if usable and len(errors) > STALL and error > 0.5 * errors[-STALL - 1]:
            return best  # stalled at an acceptable error
        if iteration == MAX_ITERATIONS:
            break
        if not (np.abs(x).max() < DIVERGENCE and np.abs(y).max() < DIVERGENCE and np.isfinite(error)):
            if usable:  # rounding has taken an iterate past the cones' boundary after an acceptable one
                return best
            raise IPMFailure(f"the iterates diverge after {iteration} iterations (no finite optimum)")

        scaling = cones.scaling(s, y, w)
        newton = NewtonSystem(normal, scaling, a, rp, ra, rd)
        # Mehrotra: the affine-scaling predictor sets the centring and the second-order term
        squared = scaling.lam_squared()
        affine = newton.direction(-squared)
        step_p, step_d = affine.steps(cones, s, y, together=not orthant)
        mu_affine = dot(s + step_p * affine.ds, y + step_d * affine.dy) / cones.degree
        target = (mu_affine / mu) ** 3 * mu
        rc = target * cones.identity(s) - squared - scaling.scaled_product(affine.ds, affine.dy)
        step = newton.direction(rc)
        step_p, step_d = step.steps(cones, s, y, together=not orthant)
        # Gondzio: push the products s_i y_i (a cone's: the spectral values of its scaled product) that a longer
        # step would put outside [0.1, 10] x target back inside, while that lengthens the step
        for _ in range(MAX_CORRECTORS if orthant else CONE_CORRECTORS):
            trial_p, trial_d = min(1.0, 1.5 * step_p + 0.1), min(1.0, 1.5 * step_d + 0.1)
            product = cones.trial_product(scaling, s, step.ds, y, step.dy, trial_p, trial_d)
            correction = cones.centring(product, target)
            corrected = newton.direction(rc + correction)
            new_p, new_d = corrected.steps(cones, s, y, together=not orthant)
            if new_p + new_d < 1.01 * (step_p + step_d):
                break
            step, step_p, step_d, rc = corrected, new_p, new_d, rc + correction
        dual_target = 0.1 * max(np.abs(rd).max(), DUAL_FLOOR * tolerance * scale_c)
        step = newton.refine(step, rc, dual_target)
        # y is in a regularised LP's primal residual too, and the cones' scaling is of both: one step for all
        step_p, step_d = step.steps(cones, s, y, together=weight is not None or not orthant)
        step_p = STEP_TO_BOUNDARY * step_p
        step_d = STEP_TO_BOUNDARY * step_d
        x = x + step_p * step.dx
        s = s + step_p * step.ds
        y = y + step_d * step.dy
        lam = lam + step_d * step.dlam
    if acceptable is not None and best.error < acceptable:
        return best
    raise IPMFailure(
        f"not converged in {MAX_ITERATIONS} iterations (primal {primal_err:.1e}, dual {dual_err:.1e}, "
        f"gap {gap_err:.1e})"
    )


def starting_point(normal: NormalMatrix, cones, c: np.ndarray, a: np.ndarray):
    """Mehrotra's: least-squares ``x`` with ``a.x = 1``, least-norm ``(y, lam)``, shifted inside the cones."""
    G = normal.G
    m = G.shape[0]
    unit = cones.identity(np.zeros(m))
    normal.factorise(cones.scaling(unit, unit, np.zeros(m)))  # W = I: M = G^T G
    q = normal.solve(a)
    x = q / dot(a, q)
    w = normal.solve(c)
    lam = dot(a, w) / dot(a, q)
    y = G @ (w - lam * q)
    s = G @ x
    e = unit
    s = s + max(-1.5 * cones.smallest_eigenvalue(s), 0.0) * e
    y = y + max(-1.5 * cones.smallest_eigenvalue(y), 0.0) * e
    sy = dot(s, y)
    if sy <= 0:  # s = y = 0 (both already centred at zero)
        s, y = s + e, y + e
        sy = dot(s, y)
    s = s + 0.5 * sy / cones.identity_weight(y) * e
    y = y + 0.5 * sy / cones.identity_weight(s) * e
    return x, s, y, lam
