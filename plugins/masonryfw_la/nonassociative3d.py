"""Non-associative friction in 3D: joints that slide without opening, by a sequence of cone programmes.

The 2D sequence (:mod:`.nonassociative`, after Gilbert, Casapulla & Ahmed 2006) on Coulomb's cone. At every
vertex of an interface the cone ``|T| <= mu N`` is replaced by a disc of fixed radius ``R = mu N_k``, ``N_k`` the
vertex's normal force in the previous programme, with the flow rule of a joint that slides without dilatancy:
``dn >= 0`` and a slip ``s >= |dt|`` that dissipates ``R s``. Each programme is a second-order cone programme
with one more column per vertex, its slip ``s``, and two cones of three rows per vertex:

    (n.v, 0, 0)          the orthant dn >= 0, written as a cone so that one interior point serves (its zero rows
                         carry nothing: their multipliers go to zero with the centring)
    (s, t0.v, t1.v)      the slip bounds the tangential motion

The static side puts at the vertex a normal force ``N >= 0`` and a friction force ``T`` with ``|T| <= R`` (the
slip column's equation makes the cone's first multiplier ``R``). Each programme's contact forces are the least
squared normal forces, for the 2D reason: the interior point's centre of a tied set of forces is a made-up clamping
force that raises the next capacities. As in 2D (:func:`.nonassociative.selected_solution`), the ipm solves each
programme regularised by ``w N^2 / 2`` on the normal cones' first rows (:class:`.cones.LorentzScaling`: the normal
weights ``(W^2 + w e0 e0^T)^-1``), and a sequence that settles finishes with the exact selection (the programme, then
the QP :func:`.nonassociative.least_squared_forces`); the other backends take the QP after every programme. Measured
on the house: the regularised programme in 1.5 s against 2.3 s for the programme and 9-16 s for the QP (Clarabel),
alpha to 4e-10 and the normal forces to 1e-6 of the dead load of the QP's on the same regularised problem. The
sequence (relaxation, the extrapolation of one slow mode, the test of steadiness) is the 2D one
(:class:`.nonassociative.FixedPoint`), on the vertices' normal forces; it starts from the associative cone's forces,
or from none when the associative programme has no mechanism (the dilatancy is blocked).
"""
from __future__ import annotations

import logging
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

import masonryfw as mf

from . import backends, limit3d, nonassociative
from .options import DEFAULT_BACKEND

LOG = logging.getLogger("masonryfw.la")
#: A regularised sequence whose normal forces move less than this (over the dead load) but whose alpha does not
#: settle goes on to the exact finish: the regularised selection's forces are good to about 1e-6 (Test 12C's twin:
#: 3e-7 to 5e-6 a programme, alpha over 7e-6), a sequence that truly wanders moves them by 1e-3 and more.
SETTLED = nonassociative.FINISH * nonassociative.FORCE_TOLERANCE


class FlowProgramme3D(NamedTuple):
    """What stays the same along the sequence (non-dimensional, the programme's columns: the blocks', then one
    slip per vertex)."""

    constraints: sp.csr_matrix  # (6 vertex, columns): the normal cones, then the slip cones
    dead: np.ndarray  # the cost of the block columns (the dead load's work)
    live: np.ndarray  # (columns,)
    friction: np.ndarray  # (vertex,) mu
    vertices: np.ndarray  # (vertex,) the programme's vertices among the contacts' points
    block_columns: int

    def cost(self, normal: np.ndarray) -> np.ndarray:
        """The slips dissipate ``mu N`` each for the normal forces ``normal`` (over the dead load)."""
        return np.r_[self.dead, self.friction * np.maximum(normal, 0.0)]

    def normal_forces(self, y: np.ndarray) -> np.ndarray:
        """Each vertex's normal force: the first multiplier of its normal cone."""
        return y[:3 * self.vertices.size:3]

    def squared_rows(self) -> np.ndarray:
        """1 on the rows whose multipliers are the normal forces."""
        rows = np.zeros(self.constraints.shape[0])
        rows[:3 * self.vertices.size:3] = 1.0
        return rows

    def at(self, normal: np.ndarray) -> nonassociative.Programme:
        """The programme for the normal forces ``normal``, as the selection sees it."""
        return nonassociative.Programme(self.cost(normal), self.constraints, self.live, self.squared_rows(), 3)

    def point_forces(self, y: np.ndarray, axes: np.ndarray, n_point: int, force: float) -> np.ndarray:
        """``(point, 3)`` the force on side 1 at every interface vertex [N] (zero off the programme)."""
        n_vertex = self.vertices.size
        slip = y[3 * n_vertex:].reshape(-1, 3)
        local = np.c_[self.normal_forces(y), slip[:, 1:]]  # N, T0, T1
        forces = np.zeros((n_point, 3))
        forces[self.vertices] = np.einsum("pj,pjd->pd", local, axes[self.vertices]) * force
        return forces


class Flow3D(NamedTuple):
    """The reported programme's state and how the sequence went."""

    state: limit3d.LimitState3D
    alpha_associative: float  # nan when the associative programme has no mechanism
    alphas: tuple[float, ...]
    converged: bool
    change: float  # the last step's largest vertex normal force change (over the dead load)
    selection_weight: float  # of the ipm's regularised programmes (the other backends' selection is a QP)
    stop_reason: str = ""
    finish: str = "exact"  # how the ipm's sequence ended: the exact selection, or why not


def vertex_axes(blocks: limit3d.Blocks3D) -> np.ndarray:
    """``(point, 3, 3)``: each interface vertex's normal and its interface's two tangents."""
    contacts = blocks.contacts
    owner = contacts.point_interface()
    return np.concatenate([contacts.normal[owner][:, None, :], contacts.tangent[owner]], axis=1)


def flow_programme(blocks: limit3d.Blocks3D, scales: limit3d.Scales3D) -> tuple[FlowProgramme3D, sp.csr_matrix]:
    """The programme of the module docstring, and the map of its block columns to all block dofs."""
    cmap, _ = limit3d.column_map(blocks, scales)
    owner = blocks.contacts.point_interface()
    vertices = np.flatnonzero(limit3d.active_interfaces(blocks, cmap)[owner])
    rows = limit3d.relative_velocity_rows(blocks, scales, vertex_axes(blocks))
    velocity = (rows[(3 * vertices[:, None] + np.arange(3)).ravel()] @ cmap).tocoo()  # rows 3 vertex + axis
    n_vertex, n_column = vertices.size, cmap.shape[1]
    cone_row = np.where(velocity.row % 3 == 0, velocity.row, 3 * n_vertex + velocity.row)
    slip = np.arange(n_vertex)
    constraints = sp.csr_matrix(
        (np.r_[velocity.data, np.ones(n_vertex)],
         (np.r_[cone_row, 3 * (n_vertex + slip)], np.r_[velocity.col, n_column + slip])),
        shape=(6 * n_vertex, n_column + n_vertex))
    constraints.eliminate_zeros()
    dead, live = limit3d.programme_loads(blocks, scales, cmap)
    programme = FlowProgramme3D(constraints, dead, np.r_[live, np.zeros(n_vertex)], blocks.friction[owner][vertices],
                                vertices, n_column)
    return programme, cmap


def associative_start(blocks: limit3d.Blocks3D, programme: FlowProgramme3D, backend: str,
                      tolerance: float) -> tuple[np.ndarray, float]:
    """The vertices' normal forces (over the dead load) and alpha of the associative cone, or none and nan when it
    has no mechanism."""
    try:
        state = limit3d.limit_state_3d(blocks, 0, backend, tolerance)
    except backends.LiveLoadUnbounded:
        return np.zeros(programme.vertices.size), np.nan
    normal = np.einsum("pd,pd->p", state.point_force, vertex_axes(blocks)[:, 0])
    return normal[programme.vertices] / limit3d.scales_of(blocks).force, state.alpha


def solve(blocks: limit3d.Blocks3D, options, progress, from_zero: bool = False) -> Flow3D:
    """The sequence of cone programmes of the module docstring (options as the 2D sequence's; ``from_zero``: started
    from zero normal forces, the second start of option ``flow_starts``)."""
    backend, cone_tolerance = options["solver"] or DEFAULT_BACKEND, options["tolerance"]
    scales = limit3d.scales_of(blocks)
    programme, cmap = flow_programme(blocks, scales)
    axes = vertex_axes(blocks)
    normal, alpha_associative = ((np.zeros(programme.vertices.size), np.nan) if from_zero
                                 else associative_start(blocks, programme, backend, cone_tolerance))
    sequence = nonassociative.FixedPoint(options["flow_tolerance"], options["flow_relaxation"])
    selection = nonassociative.Selection(backend, cone_tolerance, nonassociative.selection_weight(blocks.n_block))
    cap = options["flow_iterations"]
    last: tuple[nonassociative.Programme, backends.LPSolution] | None = None
    regularised_end = None  # the regularised sequence's fixed point, kept in case the finish fails

    def finished(at: nonassociative.Programme, solution: backends.LPSolution, converged: bool, reason: str = "",
                 finish: str = "exact") -> Flow3D:
        solution = nonassociative.admissible(selection, at, solution)
        motion = (cmap @ solution.x[:programme.block_columns]).reshape(-1, 6) * scales.dof
        forces = programme.point_forces(solution.y, axes, axes.shape[0], scales.force)
        state = limit3d.LimitState3D(float(solution.alpha_primal), motion, forces,
                                     limit3d.active_interfaces(blocks, cmap), solution)
        return Flow3D(state, alpha_associative, tuple(sequence.alphas), converged, sequence.change, selection.weight,
                      reason, finish)

    for k in range(cap):
        at = programme.at(normal)
        try:
            solution = nonassociative.selected_solution(selection, at)
        except mf.SolveError as error:
            if last is None:
                raise
            if regularised_end is not None:  # the finish failed: the regularised fixed point stands
                finish = (f"failed at programme {k + 1} ({error}): the regularised selection's fixed point is "
                          "reported")
                LOG.warning("la: the exact finish %s", finish)
                return finished(*regularised_end, True, finish=finish)
            reason = f"programme {k + 1} of the non-associative sequence failed ({error}): the last iterate is reported"
            LOG.warning("la: %s", reason)
            return finished(*last, False, reason, finish="not reached: a programme failed")
        last = (at, solution)
        residual = programme.normal_forces(solution.y) - normal
        # the finish is judged at the flow tolerance itself (2D: at FINISH of it): a cone programme's alpha may stall
        # at CONE_ACCEPTABLE times its tolerance, 1e-7, above FINISH x 1e-6
        steady = sequence.steady(solution.alpha_primal, residual)
        progress(0.2 + 0.7 * (k + 1) / cap, f"la: non-associative cone programme {k + 1}: alpha = "
                                              f"{solution.alpha_primal:.6g}, normal forces moved {sequence.change:.2e} W")
        wandering = not steady and sequence.wandering()
        if selection.regularised and (steady or (wandering and sequence.change <= SETTLED)):
            # finish with the exact selection (module docstring of .nonassociative); forces settled but alpha
            # still moving is the regularised selection's round-off: the exact one settles it
            selection.finishing = True
            sequence.start_finish()
            regularised_end = last if steady else None
        elif steady:
            return finished(*last, True)
        elif wandering:
            tail = sequence.alphas[-nonassociative.WANDER_WINDOW:]
            reason = (f"the non-associative sequence wanders: alpha between {min(tail):.6g} and {max(tail):.6g} over "
                      f"its last {len(tail)} programmes, the normal forces still moving {sequence.change:.2e} W (no "
                      f"fixed point to the tolerance: docs/la.md); the last iterate is reported")
            LOG.warning("la: %s", reason)
            return finished(*last, False, reason, finish="not reached (the sequence did not settle)")
        normal = sequence.next_normal(normal, residual)
    reason = f"the non-associative iteration did not converge in {cap} programmes: the last iterate is reported"
    LOG.warning("la: %s (alpha %s, normal forces still moving %.2e W)", reason, sequence.alphas[-3:], sequence.change)
    return finished(*last, False, reason, finish="not reached (the sequence did not settle)")


def reported(blocks: limit3d.Blocks3D, options, progress) -> tuple[Flow3D, dict]:
    """The sequence (:func:`solve`) and the result's attributes that say how it went, with the second start of
    option ``flow_starts = 2``."""
    backend = options["solver"] or DEFAULT_BACKEND
    shown = nonassociative.halves(progress, options["flow_starts"])
    flow = solve(blocks, options, shown[0])
    attrs = {"la_flow_iterations": len(flow.alphas), "la_flow_converged": int(flow.converged),
             "la_flow_last_change": flow.change, "la_alpha_associative": flow.alpha_associative,
             "la_flow_selection": "the first fixed point of the sequence of cone programmes started from the "
                                  "associative cone's normal forces; each programme's contact forces with the least "
                                  "squared normal forces, "
                                  + (f"by the programme regularised with weight {flow.selection_weight:g} (ipm), then "
                                     f"the exact finish by programme + QP"
                                     f"{'' if flow.finish == 'exact' else ': ' + flow.finish}"
                                     if backend == "ipm" else f"by a QP after the {backend} solve") + " (docs/la.md)"}
    if not flow.converged:
        attrs["stop_reason"] = flow.stop_reason
    if options["flow_starts"] == 2:
        progress(0.55, "la: the non-associative sequence again, from zero normal forces")
        again = solve(blocks, options, shown[1], from_zero=True)
        attrs.update(nonassociative.second_start(flow.state.alpha, flow.converged, again.state.alpha, again.converged,
                                                 options["flow_tolerance"]))
    return flow, attrs
