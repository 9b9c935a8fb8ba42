"""Newton-Raphson with the consistent tangent, a tangent predictor and a backtracking line search.

A load step goes from a converged :class:`State` to the next under a gravity factor and a
support settlement (non-dimensional). The stress update is path-independent within a
step (trial = converged stress + D (strain - converged strain), then the exact return),
so the iterations only search for the displacement that balances it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import reverse_cuthill_mckee

import masonryfw.plugin_api as mfp

from .problem import Problem


@dataclass
class State:
    """A converged (or trial) state: displacements and the quadrature-point fields."""

    u: np.ndarray
    strain: np.ndarray
    stress: np.ndarray
    tangent: np.ndarray
    active: np.ndarray
    residual: np.ndarray = field(default=None, repr=False)

    @classmethod
    def initial(cls, problem: Problem) -> State:
        n, nf = problem.disc.n_points, len(problem.return_map.b)
        return cls(
            u=np.zeros(problem.disc.ndof), strain=np.zeros((n, 3)), stress=np.zeros((n, 3)),
            tangent=problem.D_points.copy(), active=np.zeros((n, nf), dtype=bool),
        )


@dataclass
class StepReport:
    converged: bool
    iterations: int
    residuals: list  # relative residual norm after each iteration (the first is the predictor's start)


def free_lower_pattern(K: sp.csr_matrix, free: np.ndarray):
    """A Cholesky factor for the lower triangle of ``K[free][:, free]``, and where its values sit in ``K.data``.

    ``K`` comes in the discretisation's fixed CSR pattern, so the map is computed once and
    every later factorisation reads ``K.data[take]``.
    """
    index = np.full(K.shape[0], -1)
    index[free] = np.arange(free.size)
    row = index[np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))]
    col = index[K.indices]
    keep = np.flatnonzero((row >= 0) & (col >= 0) & (row >= col))
    take = keep[np.lexsort((row[keep], col[keep]))]  # column-major, rows sorted: CSC order
    indptr = np.concatenate([[0], np.cumsum(np.bincount(col[take], minlength=free.size))])
    lower = sp.csc_matrix((np.ones(take.size), row[take], indptr), shape=(free.size, free.size))
    return mfp.cholesky_factor(lower), take


class NewtonSolver:
    """Solves one load step; ``tolerance`` is on ||free residual|| / ||full gravity load||."""

    def __init__(self, problem: Problem, tolerance: float = 1e-8, max_iterations: int = 30,
                 line_search: int = 4, regularisation: tuple[float, float] = (1e-2, 1e-8)):
        self.problem = problem
        self.regularisation = regularisation
        self.tolerance = tolerance
        self.max_iterations = max_iterations
        self.line_search = line_search
        self.free = problem.free
        self.prescribed = np.concatenate([problem.fixed, problem.moving])
        self.reference = float(np.linalg.norm(problem.gravity)) or 1.0
        self._order = None
        self._cholesky = None
        self.symmetric = np.array_equal(problem.return_map.A, problem.return_map.G)

    def prescribed_values(self, settlement: float) -> np.ndarray:
        return np.concatenate([np.zeros(self.problem.fixed.size), settlement * self.problem.moving_direction])

    def external(self, gravity_factor: float, load_factor: float) -> np.ndarray:
        """The applied loads: ``gravity_factor`` times gravity plus ``load_factor`` times the live load."""
        p = self.problem
        return gravity_factor * p.gravity + load_factor * p.live if load_factor else gravity_factor * p.gravity

    def evaluate(self, u: np.ndarray, start: State, gravity_factor: float, load_factor: float = 0.0) -> State:
        """Strains, returned stresses, tangents and the residual ``f_int - f_ext`` at ``u``.

        Where the beds are not horizontal the return works in every point's bed frame
        (``Problem.to_bed``): the JMM's faces read the stress normal to the bed and head planes.
        D is isotropic, so the elastic predictor and the energy norm are the same in any frame.
        """
        p = self.problem
        strain = p.disc.strain(u)
        trial = start.stress + np.einsum("nij,nj->ni", p.D_points, strain - start.strain)
        stress, tangent = trial, p.D_points.copy()
        active = np.zeros_like(start.active)
        m = p.masonry_points
        if p.to_bed is None:
            stress[m], tangent[m], active[m], _ = p.return_map(trial[m], bounds=p.face_bounds)
        else:
            local, local_tangent, active[m], _ = p.return_map(np.einsum("nij,nj->ni", p.to_bed, trial[m]),
                                                              bounds=p.face_bounds)
            stress[m] = np.einsum("nij,nj->ni", p.from_bed, local)
            tangent[m] = p.from_bed @ local_tangent @ p.from_bed.transpose(0, 2, 1)
        residual = p.disc.internal_force(stress) - self.external(gravity_factor, load_factor)
        return State(u, strain, stress, tangent, active, residual)

    def reaction(self, state: State) -> float:
        """The settlement reaction (non-dimensional, ``mf.settlement_reaction``): minus the work of the moving
        supports' nodal forces on the wall per unit settlement."""
        return self.problem.settlement_reaction(state.residual)

    def _norm(self, state: State) -> float:
        return float(np.linalg.norm(state.residual[self.free])) / self.reference

    def _solve(self, K: sp.csr_matrix, rhs: np.ndarray) -> np.ndarray:
        """Solve the free-free block of ``K`` (assembled in the fixed pattern) for ``rhs``.

        Associated flow (the default) gives a symmetric positive definite tangent: a
        Cholesky factor on the fixed pattern of the free-free lower triangle
        (``mfp.cholesky_factor``: CHOLMOD, its ordering computed once). Non-associated flow
        gives a non-symmetric tangent, and a tangent that turns out not to be positive
        definite falls back too: SuperLU pre-ordered once by reverse Cuthill-McKee, then
        minimum degree on A^T + A (Test 12C, 16k DOFs: 0.15 s against 0.42 s for plain
        spsolve), SymmetricMode preferring diagonal pivots and partial pivoting doing the rest.
        """
        if self.symmetric:
            if self._cholesky is None:
                self._cholesky = free_lower_pattern(K, self.free)
            factor, take = self._cholesky
            if factor.factorise(K.data[take]):
                return factor.solve(rhs)
        block = K[self.free][:, self.free]
        if self._order is None:
            self._order = reverse_cuthill_mckee(block.tocsr(), symmetric_mode=True)
        o = self._order
        lu = spla.splu(block[o][:, o].tocsc(), permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})
        x = np.empty_like(rhs)
        x[o] = lu.solve(rhs[o])
        return x

    def step(self, start: State, gravity_factor: float, settlement: float,
             max_iterations: int | None = None, guess: np.ndarray | None = None,
             load_factor: float = 0.0, iterated=None) -> tuple[State, StepReport]:
        """One load step from the converged ``start``; the first solve is the tangent predictor.

        ``guess`` (displacements, e.g. the last step's increment extrapolated) replaces the
        predictor when its residual is lower. The tangent predictor sees the kappa-stiffened
        tangent at open or sliding points, so it underestimates the motion of a mechanism that
        is already forming; the extrapolated increment does not (measured on Facade 1: half
        the Newton iterations to the same settlement, docs/jmm.md). ``iterated(iterations, residual)``, if
        given, hears of every iteration (a long step's sign of life).
        """
        limit = max_iterations or self.max_iterations
        p, free, fixed_all = self.problem, self.free, self.prescribed
        K = p.disc.stiffness(self._regularised(start, False)).tocsr()
        u = start.u.copy()
        jump = self.prescribed_values(settlement) - start.u[fixed_all]
        u[fixed_all] += jump
        base = p.disc.internal_force(start.stress) - self.external(gravity_factor, load_factor)
        rhs = -(base[free] + K[free][:, fixed_all] @ jump)
        u[free] += self._solve(K, rhs)
        state = self.evaluate(u, start, gravity_factor, load_factor)
        residuals = [self._norm(state)]
        if guess is not None and residuals[0] > self.tolerance:
            guessed = guess.copy()
            guessed[fixed_all] = u[fixed_all]
            other = self.evaluate(guessed, start, gravity_factor, load_factor)
            if self._norm(other) < residuals[0]:
                state, residuals = other, [self._norm(other)]
        iterations = 1
        previous = start.active
        while residuals[-1] > self.tolerance and iterations < limit:
            if not np.isfinite(residuals[-1]):
                break
            settled = not (state.active != previous).any()
            previous = state.active
            K = p.disc.stiffness(self._regularised(state, settled)).tocsr()
            du = self._solve(K, -state.residual[free])
            iterations += 1
            state = self._line_search(state, du, start, gravity_factor, residuals[-1], load_factor)
            residuals.append(self._norm(state))
            if iterated is not None:
                iterated(iterations, residuals[-1])
        converged = bool(residuals[-1] <= self.tolerance)
        return state, StepReport(converged, iterations, residuals)

    def _regularised(self, state: State, settled: bool) -> np.ndarray:
        """Tangents with ``kappa D`` added where two or three faces are active (rank 1 or 0).

        The exact tangent makes the global matrix singular wherever a band of points sits
        on an edge of the domain (an opening joint along a free surface, a sliding band), so
        a fraction kappa of D is added there: the larger kappa while the active set still
        changes (robust, linear convergence), the smaller once it has settled (the exact
        Newton step of that active set: quadratic convergence). Only the search direction
        changes: the residual, hence the converged state, does not depend on kappa.
        """
        kappa = self.regularisation[1] if settled else self.regularisation[0]
        p = self.problem
        rank_deficient = state.active.sum(axis=1) >= 2
        tangent = state.tangent.copy()
        tangent[rank_deficient] += kappa * p.D_points[rank_deficient]
        return tangent

    def _line_search(self, state: State, du: np.ndarray, start: State, gravity_factor: float,
                     norm0: float, load_factor: float = 0.0) -> State:
        """Full step if it lowers the residual, else the best of the halved steps tried."""
        best, best_norm, alpha = None, np.inf, 1.0
        for _ in range(self.line_search + 1):
            u = state.u.copy()
            u[self.free] += alpha * du
            trial = self.evaluate(u, start, gravity_factor, load_factor)
            norm = self._norm(trial)
            if norm < best_norm:
                best, best_norm = trial, norm
            if norm < norm0:
                break
            alpha *= 0.5
        return best
