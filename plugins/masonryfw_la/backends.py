"""Four solvers for ``min c.x  s.t.  G x >= 0,  a.x = 1`` (the kinematic programme).

Each returns the mechanism ``x``, the multipliers ``y >= 0`` of ``G x >= 0``
(the static contact forces) and the multiplier of ``a.x = 1`` (the static
alpha), so that ``G^T y + alpha_dual a = c`` at the optimum.

- ``highs``: HiGHS dual simplex through ``scipy.optimize.linprog``: an exact
  vertex; when mechanisms tie it returns one of them (not symmetric in general).
  Fast below ~100 blocks, slow beyond a few hundred (docs/benchmarks.md).
- ``ipm``: our primal-dual interior point on the normal equations ``G^T D G``
  with a CHOLMOD factor (:mod:`.ipm`; SciPy's SuperLU without ``cvxopt``), on
  the LP or on second-order cones (la in 3D, Coulomb's cone). Like
  Clarabel it converges to the interior of the optimal face (tied mechanisms
  come out as their mean). Problems without a finite optimum, and any failure
  to converge, are handed to Clarabel, whose infeasibility certificates give
  the messages; the status then says so.
- ``clarabel``: interior point on the LP as a conic problem; it converges to the
  centre of the optimal face, so tied mechanisms come out as their mean
  (symmetric on a symmetric wall).
- ``osqp``: ADMM on the LP plus ``eps/2 ||x - x_k||^2`` (``eps`` = :data:`OSQP_REGULARISATION`),
  proximal-point steps from ``x_0 = 0``: the first picks the minimum-norm
  mechanism, the next ones remove the regularisation's effect on alpha. Slow
  to converge on LPs; a cross-check, not a workhorse.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

import masonryfw as mf
import masonryfw.plugin_api as mfp

OSQP_REGULARISATION = 1e-3
OSQP_FIRST_STEP_TOLERANCE = 1e-5
OSQP_MAX_PROXIMAL_STEPS = 100
OSQP_MAX_ADMM_ITERATIONS = 100_000
UNBOUNDED_MESSAGE = (
    "the structure can carry any multiple of the live load (unbounded): no mechanism lets the "
    "live load do positive work (the kinematic programme is infeasible)"
)
DEAD_LOAD_MESSAGE = (
    "the dead load alone cannot be carried: the kinematic programme is unbounded (a mechanism "
    "exists in which the dead load does positive work whatever the multiplier)"
)


class LiveLoadUnbounded(mf.SolveError):
    """No mechanism lets the live load do positive work: any multiple of it is carried."""


class DeadLoadNotCarried(mf.SolveError):
    """A mechanism lets the dead load do positive work: no multiplier lets the wall stand."""


@dataclass(frozen=True)
class LPSolution:
    """What every backend returns (non-dimensional)."""

    x: np.ndarray
    y: np.ndarray
    alpha_primal: float
    alpha_dual: float
    status: str
    iterations: int


def solve_lp(backend: str, cost, constraints, live, tolerance: float) -> LPSolution:
    """Solve with ``backend``; infeasible / unbounded / failed solves raise :class:`SolveError`."""
    return {"ipm": solve_ipm, "highs": solve_highs, "clarabel": solve_clarabel, "osqp": solve_osqp}[backend](
        cost, constraints, live, tolerance
    )


def solve_ipm(cost, constraints, live, tolerance, second_order: int = 0, progress=None, normal=None) -> LPSolution:
    """:func:`.ipm.solve` (``second_order`` as :func:`solve_clarabel`'s; ``progress(iteration, error)``; ``normal``
    the :class:`.ipm.NormalMatrix` of ``constraints`` when the caller has it); when it cannot certify an optimum,
    Clarabel (the status names the reason)."""
    from . import ipm

    acceptable = ipm.CONE_ACCEPTABLE * tolerance if second_order else None
    try:
        sol = ipm.solve(cost, constraints, live, tolerance, cone_size=max(second_order, 1), progress=progress,
                        acceptable=acceptable, normal=normal)
    except ipm.IPMFailure as failure:
        fallback = solve_clarabel(cost, constraints, live, tolerance, second_order)
        return replace(fallback, status=f"{fallback.status} (ipm fell back to clarabel: {failure})")
    return LPSolution(
        x=sol.x,
        y=sol.y,
        alpha_primal=float(np.asarray(cost) @ sol.x),
        alpha_dual=sol.lam,
        status="optimal" if sol.error < tolerance else f"almost optimal (stalled at {sol.error:.1e})",
        iterations=sol.iterations,
    )


def solve_highs(cost, constraints, live, tolerance, method: str = "highs-ds") -> LPSolution:
    """HiGHS via ``linprog`` (``-G x <= 0``; its marginals are ``d objective / d rhs``)."""
    from scipy.optimize import linprog  # imported here: slow to import, only this backend needs it

    res = linprog(
        cost,
        A_ub=-constraints,
        b_ub=np.zeros(constraints.shape[0]),
        A_eq=sp.csr_matrix(live[None, :]),
        b_eq=np.ones(1),
        bounds=(None, None),
        method=method,
        options={
            "primal_feasibility_tolerance": max(tolerance, 1e-10),
            "dual_feasibility_tolerance": max(tolerance, 1e-10),
            "presolve": True,
        },
    )
    if res.status == 2:
        raise LiveLoadUnbounded(UNBOUNDED_MESSAGE)
    if res.status == 3:
        raise DeadLoadNotCarried(DEAD_LOAD_MESSAGE)
    if res.status != 0:
        raise mf.SolveError(f"HiGHS failed: {res.message}")
    return LPSolution(
        x=res.x,
        y=-res.ineqlin.marginals,
        alpha_primal=float(cost @ res.x),
        alpha_dual=float(res.eqlin.marginals[0]),
        status="optimal",
        iterations=int(res.nit),
    )


def solve_clarabel(cost, constraints, live, tolerance, second_order: int = 0) -> LPSolution:
    """Clarabel: ``A x + s = b``, ``s`` in (zero cone: ``a.x = 1``) x (non-negative cone: ``G x >= 0``); with
    ``second_order`` = k the rows of ``G x`` are second-order cones of k rows each instead (la in 3D's Coulomb
    cone, :mod:`.limit3d`), and ``y`` their multipliers, in the same cones."""
    import clarabel

    n_row, n_col = constraints.shape
    matrix = sp.vstack([sp.csr_matrix(live[None, :]), -constraints], format="csc")
    rhs = np.concatenate([[1.0], np.zeros(n_row)])
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    # "auto" picks faer (multithreaded supernodal) here; on these 2-D contact KKT systems QDLDL is
    # 5x faster per iteration at 10,000 units (0.5 s vs 2.5 s) with bit-identical alpha.
    settings.direct_solve_method = "qdldl"
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tolerance
    settings.tol_ktratio = min(settings.tol_ktratio, tolerance)
    solver = clarabel.DefaultSolver(
        sp.csc_matrix((n_col, n_col)),
        np.asarray(cost, dtype=float),
        matrix,
        rhs,
        [clarabel.ZeroConeT(1)] + ([clarabel.SecondOrderConeT(second_order)] * (n_row // second_order)
                                   if second_order else [clarabel.NonnegativeConeT(n_row)]),
        settings,
    )
    sol = mfp.interruptible(solver.solve)
    status = str(sol.status).split(".")[-1]
    if status in ("PrimalInfeasible", "AlmostPrimalInfeasible"):
        raise LiveLoadUnbounded(UNBOUNDED_MESSAGE)
    if status in ("DualInfeasible", "AlmostDualInfeasible"):
        raise DeadLoadNotCarried(DEAD_LOAD_MESSAGE)
    if status not in ("Solved", "AlmostSolved"):
        raise mf.SolveError(f"Clarabel failed: {status}")
    x = np.asarray(sol.x)
    z = np.asarray(sol.z)
    return LPSolution(
        x=x,
        y=z[1:],
        alpha_primal=float(cost @ x),
        alpha_dual=float(-z[0]),
        status="optimal" if status == "Solved" else "almost optimal",
        iterations=int(sol.iterations),
    )


def solve_osqp(cost, constraints, live, tolerance) -> LPSolution:
    """OSQP on proximal-point steps ``x_{k+1} = argmin c.x + eps/2 ||x - x_k||^2``, ``x_0 = 0``.

    The first step is the Tikhonov selection (minimum norm among near-optimal
    mechanisms). A fixed Tikhonov term either biases alpha (``eps`` above the
    exact-regularisation threshold: 4e-3 on Ferris & Tin-Loi's wall at
    ``eps = 1e-4``) or stalls ADMM (``eps <= 1e-6``; Test 12C stalls even at
    ``1e-4``); the proximal steps remove the bias with a well-conditioned
    ``eps``. They are inexact: each step is solved to ``max(tolerance,
    0.1 eps |x_k - x_{k-1}|)``. At convergence the regularisation force
    ``eps (x_{k+1} - x_k)`` left in the static equilibrium is below
    ``tolerance``, so the multipliers are LP contact forces. ``l <= A x <= u``
    with ``A = [a; G]``.
    """
    import osqp

    n_row, n_col = constraints.shape
    matrix = sp.vstack([sp.csr_matrix(live[None, :]), constraints], format="csc")
    lower = np.concatenate([[1.0], np.zeros(n_row)])
    upper = np.concatenate([[1.0], np.full(n_row, np.inf)])
    cost = np.asarray(cost, dtype=float)
    inner = max(tolerance, OSQP_FIRST_STEP_TOLERANCE)
    solver = osqp.OSQP()
    solver.setup(
        OSQP_REGULARISATION * sp.identity(n_col, format="csc"),
        cost,
        matrix,
        lower,
        upper,
        eps_abs=inner,
        eps_rel=inner,
        eps_prim_inf=tolerance,
        max_iter=OSQP_MAX_ADMM_ITERATIONS,
        polishing=False,
        warm_starting=True,
        verbose=False,
    )
    x = np.zeros(n_col)
    iterations = 0
    for _ in range(OSQP_MAX_PROXIMAL_STEPS):
        solver.update(q=cost - OSQP_REGULARISATION * x)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = solver.solve()
        iterations += res.info.iter
        status = res.info.status
        if status == "primal infeasible":
            raise LiveLoadUnbounded(UNBOUNDED_MESSAGE)
        if status not in ("solved", "solved inaccurate"):
            raise mf.SolveError(f"OSQP failed: {status} after {iterations} ADMM iterations")
        force = OSQP_REGULARISATION * np.abs(res.x - x).max()
        x = np.asarray(res.x)
        if force < tolerance and inner <= tolerance:
            break
        tighter = max(tolerance, min(inner, 0.1 * force))
        if tighter < inner:
            inner = tighter
            solver.update_settings(eps_abs=inner, eps_rel=inner)
    else:
        raise DeadLoadNotCarried(
            DEAD_LOAD_MESSAGE + f" (OSQP: the proximal steps did not settle in "
            f"{OSQP_MAX_PROXIMAL_STEPS} steps; last regularisation force {force:.3g})"
        )
    return LPSolution(
        x=x,
        y=-np.asarray(res.y)[1:],
        alpha_primal=float(cost @ x),
        alpha_dual=float(-res.y[0]),
        status="optimal" if status == "solved" else "almost optimal",
        iterations=int(iterations),
    )
