"""Non-associative friction: joints that slide without opening, by a sequence of LPs.

After Gilbert, Casapulla & Ahmed (2006, Comput. Struct. 84:873-887): the Coulomb
cone of every joint end is replaced by a *fixed* shear capacity ``a_c + mu N_k``
from the normal force ``N_k`` of the previous solution, with a flow rule that lets
the end slide without dilatancy (``dn >= 0``, ``s >= |dt|``; tension and opening as
in the associative programme). Each LP is an associative problem with a
zero-friction, cohesive-like surface, solved by the chosen backend; its dual gives
the new normal forces. The sequence starts from the associative solution's
normal forces (the associative alpha is an upper bound of the non-associative
one) or, when the associative programme has no mechanism (the dilatancy is
blocked), from zero normal forces.

Update: ``N_{k+1} = N_k + r (N_new - N_k)`` with the relaxation ``r`` (option
``flow_relaxation``, halved down to :data:`MIN_RELAXATION` whenever alpha's change
changes sign by more than the tolerance: the plain fixed point oscillates on Test
12C). Converged when, between two LPs, alpha changes by at most ``tolerance *
max(1, |alpha|)`` and no end's normal force by more than :data:`FORCE_TOLERANCE`
times the total dead load (the interior point backends' forces drift slowly along
degenerate directions that do not move alpha).
The fixed point is the solution reported: the mechanism and the forces of the last
LP, whose capacities are (to the tolerance) those of its own normal forces. When
the cap on the iterations is reached first, the last iterate is reported with
``la_flow_converged = 0`` and a warning: never a silent number.

Non-associative solutions need not be unique. Each LP's contact forces are chosen
as those with the least squared normal forces (:func:`least_compression`): a block
squeezed between two supports gets no clamping force the loads do not need, which
would otherwise raise its capacity (the interior point backends return the centre
of the optimal face, a made-up prestress). The one reported is the fixed point this
sequence reaches from the associative forces; it does not depend on the order of
the blocks or on the length unit (tested).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, replace

import numpy as np

import masonryfw as mf

from . import assembly, backends, postprocess

LOG = logging.getLogger("masonryfw.la")
#: The relaxation is halved, down to this, whenever alpha's change changes sign.
MIN_RELAXATION = 0.05
#: Converged only if no end's normal force moved more than this (over the total dead load) in the last LP.
FORCE_TOLERANCE = 1e-3
#: Clarabel's tolerances for the selection QP (forces over the dead load).
SELECTION_TOLERANCE = 1e-7


def oscillates(last: list[float], tolerance: float) -> bool:
    """Alpha went up then down (or down then up), both steps larger than the tolerance."""
    steps = np.diff(last)
    return bool(steps[0] * steps[1] < 0 and np.abs(steps).min() > tolerance * max(1.0, abs(last[-1])))


@dataclass(frozen=True)
class FlowIteration:
    """The reported LP and how the sequence went."""

    lp: assembly.KinematicLP
    solution: backends.LPSolution
    alpha_associative: float  # nan when the associative programme has no mechanism
    alphas: tuple[float, ...]  # alpha of every LP of the sequence
    converged: bool
    change: float  # the last step's largest normal-force change (over the dead load)


def end_normal_forces(lp: assembly.KinematicLP, y: np.ndarray, n_interface: int,
                      scales: assembly.Scales) -> np.ndarray:
    """Normal force of every end ``2 * interface + end`` of the multipliers ``y`` (non-dimensional)."""
    forces = postprocess.contact_forces(lp, y, n_interface, scales)
    return forces.normal.ravel() / scales.force


def least_compression(lp: assembly.KinematicLP, alpha: float, tolerance: float) -> np.ndarray:
    """Among the contact forces in equilibrium with ``dead + alpha live`` within the LP's capacities,
    those with the least sum of squared normal forces (a QP, Clarabel): unique normal forces, and no
    self-stress that the loads do not need.

    The static problem of an LP has many solutions where blocks can be squeezed between
    supports (a unit under a cap that only touches it); the interior point backends return
    the centre of that set, whose made-up clamping force would raise the next capacities,
    and a vertex (least total compression by the simplex) jumps from one LP to the next.
    Variables ``(y, a)``: ``G^T y + a live = cost``, ``y >= 0``, ``a >= alpha - slack``;
    minimise ``|y_n|^2 / 2`` over the multipliers ``y_n`` of the ``dn >= 0`` rows (normal force
    plus the constant tension share).
    """
    import clarabel
    import scipy.sparse as sp

    n_row, n_col = lp.constraints.shape
    n_coh = lp.cohesive_ends.size
    weight = np.zeros(n_row + 1)
    weight[n_row - n_coh:n_row] = 1.0  # the third block of the cohesive rows: dn >= 0
    slack = 10 * tolerance * max(1.0, abs(alpha))
    matrix = sp.vstack([
        sp.hstack([lp.constraints.T, sp.csr_matrix(lp.live[:, None])]),  # = cost (zero cone)
        -sp.identity(n_row + 1, format="csr"),  # y >= 0, a >= alpha - slack (non-negative cone)
    ], format="csc")
    rhs = np.concatenate([lp.cost, np.zeros(n_row), [-(alpha - slack)]])
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.direct_solve_method = "qdldl"
    # the forces only move the next capacities; the iteration's force test is 1e-3 of the dead load
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = SELECTION_TOLERANCE
    solver = clarabel.DefaultSolver(sp.diags(weight, format="csc"), np.zeros(n_row + 1), matrix, rhs,
                                    [clarabel.ZeroConeT(n_col), clarabel.NonnegativeConeT(n_row + 1)], settings)
    solution = solver.solve()
    status = str(solution.status).split(".")[-1]
    if status not in ("Solved", "AlmostSolved"):
        raise mf.SolveError(f"la: the least-compression contact forces at alpha = {alpha:.6g} were not found "
                            f"(Clarabel: {status})")
    return np.maximum(np.asarray(solution.x)[:n_row], 0.0)


def solve(wall: assembly.Wall, scales: assembly.Scales, kin: assembly.Kinematics, options,
          progress=mf.no_progress) -> FlowIteration:
    """The sequence of LPs of the module docstring."""
    backend, lp_tolerance = options["solver"], options["tolerance"]
    tolerance, cap, relaxation = options["flow_tolerance"], options["flow_iterations"], options["flow_relaxation"]
    try:
        lp = assembly.assemble(wall, scales, kin)
        first = backends.solve_lp(backend, lp.cost, lp.constraints, lp.live, lp_tolerance)
        normal = end_normal_forces(lp, first.y, wall.n_interface, scales)
        alpha_associative = first.alpha_primal
    except mf.SolveError as error:
        if backends.UNBOUNDED_MESSAGE not in str(error):
            raise
        normal = np.zeros(2 * wall.n_interface)  # the dilatancy is blocked: start from no friction at all
        alpha_associative = np.nan
    alphas: list[float] = []
    change = np.inf
    for k in range(cap):
        lp = assembly.assemble(wall, scales, kin, normal_force=normal)
        solution = backends.solve_lp(backend, lp.cost, lp.constraints, lp.live, lp_tolerance)
        solution = replace(solution, y=least_compression(lp, solution.alpha_primal, lp_tolerance))
        new = end_normal_forces(lp, solution.y, wall.n_interface, scales)
        change = float(np.abs(new - normal).max(initial=0.0))
        alpha = solution.alpha_primal
        steady = bool(alphas) and abs(alpha - alphas[-1]) <= tolerance * max(1.0, abs(alpha))
        alphas.append(alpha)
        progress(0.2 + 0.7 * (k + 1) / cap, f"la: non-associative LP {k + 1}: alpha = {alpha:.6g}, "
                                              f"normal forces moved {change:.2e} W")
        if steady and change <= FORCE_TOLERANCE:
            return FlowIteration(lp, solution, alpha_associative, tuple(alphas), True, change)
        if len(alphas) >= 3 and oscillates(alphas[-3:], tolerance):
            relaxation = max(0.5 * relaxation, MIN_RELAXATION)  # take smaller steps
        normal = normal + relaxation * (new - normal)
    LOG.warning("la: the non-associative iteration did not converge in %d LPs (alpha %s, normal forces still "
                "moving %.2e W); the last iterate is reported", cap, alphas[-3:], change)
    return FlowIteration(lp, solution, alpha_associative, tuple(alphas), False, change)
