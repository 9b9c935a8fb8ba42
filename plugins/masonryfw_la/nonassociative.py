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
12C). The tail is linear: the residuals ``N_new - N_k`` shrink by a steady factor
``rho`` (0.7-0.92 on the bundled walls) along one direction; when two residuals are
aligned (cosine > :data:`ALIGNED`) the next step goes to that mode's limit,
``N_k + r (N_new - N_k) / (1 - rho)``.

Converged when the estimated distance to the limit, the last step over ``1 - rho``,
is at most ``tolerance * max(1, |alpha|)`` for alpha's last two steps (one alone can
be a turning point) and at most :data:`FORCE_TOLERANCE` times the total dead load
for every end's normal force. Measured against sequences run 250-400 LPs: alpha
within 1e-6 of the limit on the bundled walls, 2.3e-6 on Facade 3 (a test on the last step alone left
errors up to 3e-5, Test 12C). The fixed point is the solution reported: the forces of the
last LP, whose capacities are (to the tolerance) those of its own normal forces.
When the cap on the iterations is reached first, the last iterate is reported with
``la_flow_converged = 0`` and a warning: never a silent number.

Non-associative solutions need not be unique (Panel 4: fixed points at alpha
0.548725, 0.548685 and 0.548820, each reached by a long sequence after a kick).
Each LP's contact forces are chosen as those with the least squared normal forces:
a block squeezed between two supports gets no clamping force the loads do not need,
which would otherwise raise its capacity (the interior point backends return the
centre of the optimal face, a made-up prestress). With the ipm backend each LP is
one solve of the LP regularised by ``w |N|^2 / 2`` (:func:`selected_solution`; exact
below a threshold weight); the other backends solve their LP and then the selection
QP (:func:`least_squared_forces`, Clarabel). The regularised selection is exact in alpha but
not quite in the forces: its fixed point lay 3e-6 (Test 12C) to 1.5e-5 (Panel 4) from the
exact selection's, and on a small symmetric wall its forces moved with the round-off, so
that the order of the blocks changed alpha by up to 4.4e-6 (12 orders; 1e-5 once in CI).
So the sequence ends with a *finish*: once steady, the LPs go on with the exact selection
(the QP) to :data:`FINISH` of both tolerances. Where the QP fails (Clarabel's iteration cap on
the 1,000-unit wall at LP 41), the regularised fixed point is reported, converged, with
``la_flow_selection`` saying so. Measured: the conformance wall's alpha
over 12 block orders within 2e-8 (was 4.4e-6), 35-44 LPs (was 19-26); Facade 3 36 LPs
and 5.3-6.3 s (was 17 and 1.6-2.4 s). The one reported is the first fixed point
this sequence reaches from the associative forces; it does not depend on the order
of the blocks, the thread count or the length unit (tested).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp

from . import assembly, backends, postprocess
from .options import DEFAULT_BACKEND

LOG = logging.getLogger("masonryfw.la")
#: The relaxation is halved, down to this, whenever alpha's change changes sign.
MIN_RELAXATION = 0.05
#: Two residuals this aligned (cosine) show one slow mode, which the next step extrapolates to its limit
#: when they contract by a factor between these two.
ALIGNED = 0.99
EXTRAPOLATE_ABOVE = 0.3
MAX_CONTRACTION = 0.98
#: A sequence whose last this many LPs did not halve its smallest change roams without converging (3D).
WANDER_WINDOW = 15
#: The finish (the exact selection) stops at this share of the tolerances (alpha's and the forces').
FINISH = 0.01
#: Converged only if no end's normal force is estimated farther than this from its limit (over the dead load).
FORCE_TOLERANCE = 1e-3
#: Clarabel's tolerances for the selection QP (forces over the dead load).
SELECTION_TOLERANCE = 1e-7
#: Weight of the squared normal forces in the ipm's regularised LP (forces over the dead load), divided
#: by the number of blocks over SELECTION_BLOCKS: the exactness threshold falls as the wall grows (measured:
#: 1e-2 exact on the bundled walls, short by 6e-5 at 1,000 units, where 1e-3 is exact, and not converging at
#: 10,000 units, where 1e-3 is short by 7e-6).
SELECTION_WEIGHT = 1e-2
SELECTION_BLOCKS = 100
RETRY_WEIGHT = 0.1
#: The regularised LP is solved this tightly (its selection is then within 2e-5 W of the QP's, measured), or
#: to the LP's tolerance where it stalls above this (Test 8C: some of its LPs stall at 9e-10).
SELECTION_IPM_TOLERANCE = 1e-10
#: The status of a regularised solve, whose mechanism and alpha are replaced by the plain LP's when reported.
REGULARISED = "optimal (regularised)"


def contraction(residual: np.ndarray, previous: np.ndarray) -> float:
    """How much the fixed-point residual shrank in the last step (its norm over the previous one's)."""
    return float(np.linalg.norm(residual) / max(np.linalg.norm(previous), 1e-300))


def aligned(residual: np.ndarray, previous: np.ndarray) -> bool:
    """The two residuals point the same way (cosine above :data:`ALIGNED`): one slow mode dominates."""
    norms = np.linalg.norm(residual) * np.linalg.norm(previous)
    return bool(norms > 0 and residual @ previous > ALIGNED * norms)


def oscillates(last: list[float], tolerance: float) -> bool:
    """Alpha went up then down (or down then up), both steps larger than the tolerance."""
    steps = np.diff(last)
    return bool(steps[0] * steps[1] < 0 and np.abs(steps).min() > tolerance * max(1.0, abs(last[-1])))


@dataclass
class FixedPoint:
    """The sequence's steps on the normal forces (module docstring), in 2D and 3D: relaxation, the extrapolation
    of one slow mode, and the test of steadiness."""

    tolerance: float  # alpha's, relative
    relaxation: float
    alphas: list[float] = field(default_factory=list)  # of every LP so far
    change: float = np.inf  # the last residual's largest normal force (over the dead load)
    rho: float = 0.0  # the residuals' contraction
    previous: np.ndarray | None = None  # the last plain (not extrapolated) residual
    finish_from: int = 0  # the first LP of a finish, whose steadiness is judged on its own
    changes: list[float] = field(default_factory=list)  # of every LP so far

    def steady(self, alpha: float, residual: np.ndarray, finish: float = 1.0) -> bool:
        """Record one LP (its alpha, the change it asks of the normal forces): steady when the estimated distance
        to the limit, the last step over ``1 - rho``, is within ``finish`` times both tolerances."""
        self.change = float(np.abs(residual).max(initial=0.0))
        self.changes.append(self.change)
        if self.previous is not None:
            self.rho = contraction(residual, self.previous)
        slow = 1.0 / (1.0 - min(self.rho, MAX_CONTRACTION))  # distance to the limit over the last step
        # alpha's last two steps: one alone can be a turning point while the forces still move
        steps = np.abs(np.diff([*self.alphas[max(len(self.alphas) - 2, self.finish_from):], alpha]))
        self.alphas.append(alpha)
        return bool(steps.size == 2 and steps.max() * slow <= finish * self.tolerance * max(1.0, abs(alpha))
                    and self.change * slow <= finish * FORCE_TOLERANCE)

    def wandering(self) -> bool:
        """The last :data:`WANDER_WINDOW` LPs did not halve the smallest change of the ones before them (in this
        phase: the finish is judged on its own): the sequence roams a set of near fixed points (3D; module docstring
        of :mod:`.nonassociative3d`)."""
        phase = self.changes[self.finish_from:]
        before, recent = phase[:-WANDER_WINDOW], phase[-WANDER_WINDOW:]
        return len(before) >= WANDER_WINDOW and min(recent) > 0.5 * min(before)

    def start_finish(self) -> None:
        self.finish_from = len(self.alphas)

    def next_normal(self, normal: np.ndarray, residual: np.ndarray) -> np.ndarray:
        """The next LP's normal forces: relaxed, or extrapolated to the limit of one slow mode."""
        factor = self.relaxation
        if (self.previous is not None and aligned(residual, self.previous)
                and EXTRAPOLATE_ABOVE < self.rho < MAX_CONTRACTION):
            factor = self.relaxation / (1.0 - self.rho)  # to the limit of the slow mode
            self.previous = None  # the next residual says nothing about the contraction
        else:
            if len(self.alphas) >= 3 and oscillates(self.alphas[-3:], self.tolerance):
                self.relaxation = max(0.5 * self.relaxation, MIN_RELAXATION)  # take smaller steps
                factor = self.relaxation
            self.previous = residual
        return normal + factor * residual


@dataclass(frozen=True)
class FlowIteration:
    """The reported LP and how the sequence went."""

    lp: assembly.KinematicLP
    solution: backends.LPSolution
    alpha_associative: float  # nan when the associative programme has no mechanism
    alphas: tuple[float, ...]  # alpha of every LP of the sequence
    converged: bool
    change: float  # the last step's largest normal-force change (over the dead load)
    selection_weight: float  # of the ipm's regularised LPs (the other backends' selection is a QP)
    stop_reason: str = ""  # why an unconverged sequence stopped
    finish: str = "exact"  # how the ipm's sequence ended: the exact selection, or why not (module docstring)


def end_normal_forces(lp: assembly.KinematicLP, y: np.ndarray, n_interface: int,
                      scales: assembly.Scales) -> np.ndarray:
    """Normal force of every end ``2 * interface + end`` of the multipliers ``y`` (non-dimensional)."""
    forces = postprocess.contact_forces(lp, y, n_interface, scales)
    return forces.normal.ravel() / scales.force


def halves(progress, starts: int) -> tuple:
    """The progress of each of ``starts`` sequences (each reports shares 0.2 to 0.9): one after the other, so that
    the bar does not run backwards when the second start begins."""
    if starts == 1:
        return (progress,)
    return tuple((lambda share, message="", low=low: progress(low + 0.35 * (share - 0.2) / 0.7, message))
                 for low in (0.2, 0.55))


def second_start(alpha: float, converged: bool, alpha_from_zero: float, converged_from_zero: bool,
                 tolerance: float) -> dict:
    """The attributes of option ``flow_starts = 2``: the second sequence's alpha (from zero normal forces) and whether
    the two starts end at one alpha (both converged, within ten times the flow tolerance); a warning when not."""
    agree = bool(converged and converged_from_zero
                 and abs(alpha_from_zero - alpha) <= 10 * tolerance * max(1.0, abs(alpha)))
    if not agree:
        LOG.warning("la: from zero normal forces the non-associative sequence ends at alpha %.7g%s, the first start at "
                    "%.7g%s: the two starts do not agree (a fixed point need not be unique: docs/la.md)",
                    alpha_from_zero, "" if converged_from_zero else " (not converged)", alpha,
                    "" if converged else " (not converged)")
    return {"la_flow_alpha_from_zero": float(alpha_from_zero), "la_flow_starts_agree": int(agree)}


class Programme(NamedTuple):
    """One programme of a sequence as its selection sees it, in 2D (an LP) or 3D (cones of ``cone_size`` rows):
    ``min cost.x``, ``G x`` in the cones, ``live.x = 1``, and ``squared``: 1 on the rows whose multipliers are the
    normal forces.

    The static problem of a programme has many solutions where blocks can be squeezed between
    supports (a unit under a cap that only touches it); the interior point backends return
    the centre of that set, whose made-up clamping force would raise the next capacities,
    and a vertex (least total compression by the simplex) jumps from one LP to the next: the
    selection takes the least squared normal forces (:func:`selected_solution`)."""

    cost: np.ndarray
    constraints: object  # sp.csr_matrix
    live: np.ndarray
    squared: np.ndarray
    cone_size: int = 1


def programme_of(lp: assembly.KinematicLP) -> Programme:
    """A 2D LP of the sequence as a :class:`Programme`."""
    return Programme(lp.cost, lp.constraints, lp.live, selection_rows(lp))


def least_squared_forces(cost, constraints, live, squared: np.ndarray, alpha: float, tolerance: float,
                         cone_size: int = 1) -> np.ndarray:
    """The multipliers ``y`` in equilibrium with ``dead + alpha live`` with the least ``sum(squared * y^2) / 2``
    (a QP, Clarabel): unique normal forces, and no self-stress that the loads do not need.

    Variables ``(y, a)``: ``G^T y + a live = cost``, ``y`` in the programme's cones (the orthant, or second-order
    cones of ``cone_size`` rows), ``a >= alpha - slack``; ``squared`` is 1 on the rows whose multipliers are
    normal forces.
    """
    import clarabel
    import scipy.sparse as sp

    n_row, n_col = constraints.shape
    weight = np.append(squared, 0.0)  # nothing on the live multiplier
    slack = 10 * tolerance * max(1.0, abs(alpha))
    matrix = sp.vstack([
        sp.hstack([constraints.T, sp.csr_matrix(np.asarray(live)[:, None])]),  # = cost (zero cone)
        -sp.identity(n_row + 1, format="csr"),  # y in the cones, a >= alpha - slack
    ], format="csc")
    rhs = np.concatenate([cost, np.zeros(n_row), [-(alpha - slack)]])
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.direct_solve_method = "qdldl"
    # the forces only move the next capacities; the iteration's force test is 1e-3 of the dead load
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = SELECTION_TOLERANCE
    cones = ([clarabel.NonnegativeConeT(n_row + 1)] if cone_size == 1
             else [clarabel.SecondOrderConeT(cone_size)] * (n_row // cone_size) + [clarabel.NonnegativeConeT(1)])
    solver = clarabel.DefaultSolver(sp.diags(weight, format="csc"), np.zeros(n_row + 1), matrix, rhs,
                                    [clarabel.ZeroConeT(n_col), *cones], settings)
    solution = mfp.interruptible(solver.solve)
    status = str(solution.status).split(".")[-1]
    if status not in ("Solved", "AlmostSolved"):
        raise mf.SolveError(f"la: the least-compression contact forces at alpha = {alpha:.6g} were not found "
                            f"(Clarabel: {status})")
    y = np.asarray(solution.x)[:n_row]
    return np.maximum(y, 0.0) if cone_size == 1 else y


def selection_rows(lp: assembly.KinematicLP) -> np.ndarray:
    """1 on the rows whose multipliers are the normal forces (the ``dn >= 0`` rows), 0 elsewhere."""
    n_row = lp.constraints.shape[0]
    rows = np.zeros(n_row)
    rows[n_row - lp.cohesive_ends.size:] = 1.0
    return rows


@dataclass
class Selection:
    """How each programme of the sequence gets its contact forces (see :func:`selected_solution`)."""

    backend: str
    tolerance: float
    weight: float = SELECTION_WEIGHT  # of the ipm's regularised programme
    normal_matrix: object = None  # the ipm's G^T D G pattern: G is the same in every programme of the sequence
    finishing: bool = False  # the last programmes: the exact selection (the QP) whatever the backend

    @property
    def regularised(self) -> bool:
        return self.backend == "ipm" and not self.finishing


def selection_weight(blocks: int) -> float:
    """The regularised programme's weight for a model of ``blocks`` blocks (:data:`SELECTION_WEIGHT`)."""
    return SELECTION_WEIGHT * min(1.0, SELECTION_BLOCKS / blocks)


def selected_solution(selection: Selection, programme: Programme) -> backends.LPSolution:
    """Alpha and the selected contact forces of one programme of the sequence.

    ipm: one solve of the programme regularised by ``weight |y_n|^2 / 2`` (exact regularisation: below
    a threshold weight its optimum is the programme's optimum with the least squared normal forces,
    Mangasarian & Meyer 1979, Friedlander & Tseng 2007; :func:`solve` finishes with the exact
    selection whatever it gave). ``alpha_primal`` is then the static multiplier, a lower bound of the programme's.
    A programme the regularised interior point fails on is tried once more with the weight times
    :data:`RETRY_WEIGHT` (the 10,000-unit wall's 32nd LP diverged at 1e-4), then, like the other
    backends' programmes, solved plainly and followed by the selection QP (:func:`least_squared_forces`; one LP
    of Test 8C's sequence stalls at a gap of 2e-8 whatever the weight).
    """
    from . import ipm

    cones = programme.cone_size > 1
    if selection.regularised:
        if selection.normal_matrix is None:
            selection.normal_matrix = ipm.NormalMatrix(programme.constraints, programme.cone_size)
        acceptable = selection.tolerance * (ipm.CONE_ACCEPTABLE if cones else 1.0)
        for weight in (selection.weight, RETRY_WEIGHT * selection.weight):
            try:
                result = ipm.solve(programme.cost, programme.constraints, programme.live,
                                   min(selection.tolerance, SELECTION_IPM_TOLERANCE), weight=weight * programme.squared,
                                   normal=selection.normal_matrix, acceptable=acceptable, cone_size=programme.cone_size)
            except ipm.IPMFailure as failure:
                LOG.info("la: the regularised programme with weight %g failed (%s)", weight, failure)
            else:
                return backends.LPSolution(x=result.x, y=result.y, alpha_primal=result.lam, alpha_dual=result.lam,
                                           status=REGULARISED, iterations=result.iterations)
    solution = plain_solution(selection, programme)
    return replace(solution, y=least_squared_forces(programme.cost, programme.constraints, programme.live,
                                                    programme.squared, solution.alpha_primal, selection.tolerance,
                                                    programme.cone_size))


def plain_solution(selection: Selection, programme: Programme) -> backends.LPSolution:
    """The programme solved as it is (its mechanism and alpha; its forces the backend's)."""
    cost, constraints, live, tolerance = programme.cost, programme.constraints, programme.live, selection.tolerance
    if programme.cone_size == 1:
        return backends.solve_lp(selection.backend, cost, constraints, live, tolerance)
    if selection.backend == "ipm":
        return backends.solve_ipm(cost, constraints, live, tolerance, programme.cone_size,
                                  normal=selection.normal_matrix)
    return backends.solve_clarabel(cost, constraints, live, tolerance, programme.cone_size)


def admissible(selection: Selection, programme: Programme, solution: backends.LPSolution) -> backends.LPSolution:
    """The solution to report: a regularised one gets the plain programme's mechanism and alpha (its own
    mechanism may open by ``weight y_n``) and keeps its selected forces."""
    if solution.status != REGULARISED:
        return solution
    return replace(plain_solution(selection, programme), y=solution.y)


def solve(wall: assembly.Wall, scales: assembly.Scales, kin: assembly.Kinematics, options,
          progress=mfp.no_progress, from_zero: bool = False) -> FlowIteration:
    """The sequence of LPs of the module docstring (``from_zero``: started from zero normal forces, the second start
    of option ``flow_starts``)."""
    backend, lp_tolerance = options["solver"] or DEFAULT_BACKEND, options["tolerance"]
    tolerance, cap, relaxation = options["flow_tolerance"], options["flow_iterations"], options["flow_relaxation"]
    normal, alpha_associative = np.zeros(2 * wall.n_interface), np.nan
    lp = assembly.assemble(wall, scales, kin)
    if not from_zero:
        try:
            first = backends.solve_lp(backend, lp.cost, lp.constraints, lp.live, lp_tolerance)
            normal = end_normal_forces(lp, first.y, wall.n_interface, scales)
            alpha_associative = first.alpha_primal
        except backends.LiveLoadUnbounded:
            pass  # the dilatancy is blocked: start from no friction at all
    selection = Selection(backend, lp_tolerance, selection_weight(wall.n_block))
    sequence = FixedPoint(tolerance, relaxation)
    alphas = sequence.alphas
    regularised_end = None  # the regularised sequence's fixed point, kept in case the finish fails
    solution: backends.LPSolution | None = None
    for k in range(cap):
        try:
            lp_k = assembly.assemble(wall, scales, kin, normal_force=normal)
            solution_k = selected_solution(selection, programme_of(lp_k))
        except mf.SolveError as error:
            if solution is None:
                raise
            if regularised_end is not None:  # the finish failed: the regularised fixed point stands
                finish = f"failed at LP {k + 1} ({error}): the regularised selection's fixed point is reported"
                LOG.warning("la: the exact finish %s", finish)
                lp_r, solution_r, alphas_r, change_r = regularised_end
                return FlowIteration(lp_r, admissible(selection, programme_of(lp_r), solution_r), alpha_associative, alphas_r,
                                     True, change_r, selection.weight, finish=finish)
            reason = f"LP {k + 1} of the non-associative sequence failed ({error}): the last iterate is reported"
            LOG.warning("la: %s", reason)
            return FlowIteration(lp, admissible(selection, programme_of(lp), solution), alpha_associative, tuple(alphas), False,
                                 sequence.change, selection.weight, reason)
        lp, solution = lp_k, solution_k
        residual = end_normal_forces(lp, solution.y, wall.n_interface, scales) - normal
        alpha = solution.alpha_primal
        steady = sequence.steady(alpha, residual, FINISH if selection.finishing else 1.0)
        progress(0.2 + 0.7 * (k + 1) / cap, f"la: non-associative LP {k + 1}: alpha = {alpha:.6g}, "
                                              f"normal forces moved {sequence.change:.2e} W")
        if steady and selection.regularised:  # finish with the exact selection: see the module docstring
            selection.finishing = True
            sequence.start_finish()
            regularised_end = (lp, solution, tuple(alphas), sequence.change)
        elif steady:
            return FlowIteration(lp, solution, alpha_associative, tuple(alphas), True, sequence.change,
                                 selection.weight)
        normal = sequence.next_normal(normal, residual)
    LOG.warning("la: the non-associative iteration did not converge in %d LPs (alpha %s, normal forces still "
                "moving %.2e W); the last iterate is reported", cap, alphas[-3:], sequence.change)
    return FlowIteration(lp, admissible(selection, programme_of(lp), solution), alpha_associative, tuple(alphas), False,
                         sequence.change, selection.weight, f"the non-associative iteration did not converge in "
                                                            f"{cap} LPs: the last iterate is reported")
