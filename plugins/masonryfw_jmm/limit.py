"""``jmm-limit``: the collapse state of the JMM continuum as one linear programme on the mesh.

The JMM strength domain is the polyhedron ``A s <= b`` (material.py), so the lower-bound
(static) theorem of limit analysis on a finite-element stress field is a linear programme.
The formulation is Sloan's (1988) static one, as used by Lyamin and Sloan:

- **stress field**: linear in every triangle of the wall mesh (the triangles of
  :func:`.problem.wall_domain`, the same mesh as the incremental solver's), three nodal stress triplets ``[sxx, syy, sxy]`` per triangle,
  discontinuous between triangles; variable ``9 e + 3 k + c`` is component ``c`` at corner
  ``k`` of triangle ``e``;
- **equilibrium** with gravity in every triangle (``div s + b = 0`` is constant there: two rows);
- **traction continuity** ``t_e s_e n = t_f s_f n`` across every interior edge at both end
  points (``t``: thickness), which makes the piecewise-linear tractions continuous along it;
- **free boundary** (top, sides, openings, base not on a support): ``s n = 0`` at both ends;
- **supports**: on a fixed support's edges the traction is free (unknown); on the moving
  support's edges it is free too and its vertical resultant is the reaction ``R``;
- **strength**: ``A s <= b`` at every corner of every masonry triangle (the domain is convex
  and the field linear, so it then holds everywhere in the triangle: the field is statically
  admissible everywhere, not only at sample points). Lintel triangles are left
  unconstrained: they are elastic in the incremental solver, i.e. never yield.

Objective: **minimise R**. A settling support unloads until the wall carries the least
reaction it can by arching over it; the incremental analysis approaches that value as its
plateau. Every feasible field is statically admissible for the discretised continuum, so
the optimum ``R_min`` is an upper bound on the continuum's exact smallest reaction (a lower
bound on the collapse multiplier ``alpha = 1 - R_min / R_0``) that decreases as the mesh
is refined. ``R_0`` is the paper's settlement dead load (docs/architecture.md): the masonry
weight times the moving support's share of the wall-on-support contact length, as the
``la`` solver's alpha, so the two alphas compare directly.

Why this and not the kinematic (upper-bound) form: the static form needs no flow rule and
no velocity-discontinuity elements, its equilibrium rows mirror the FE residual, and the
duals of the strength rows are the plastic multipliers, which give the mechanism (the
plastic zone) at no extra cost. The strength is the one the incremental solver uses, with
its apex regularisation (``apex_shift``; 0 gives the exact paper domain).

The LP is solved by Clarabel (interior point, QDLDL: several times faster than "auto" on
these problems). Its duals are maximally complementary, so a face whose multiplier is
positive in some optimal mechanism has a positive multiplier here: the plastic zone is the
union of the collapse mechanisms, not one arbitrary vertex of the dual polyhedron.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import xarray as xr
from skfem import MeshTri

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .fabric import stress_rotation
from .material import failure_mode
from .output import block_mechanism, mesh_variables, point_variables, variable, with_mechanism
from .problem import Domain, live_body_force, support_facets, wall_domain

ROLE = mfp.ROLE
#: a strength row is plastic when its multiplier per unit volume exceeds this fraction of the largest
PLASTIC_DUAL_FRACTION = 1e-4
#: local corner pairs of the three edges of a triangle
LOCAL_EDGES = np.array([[0, 1], [1, 2], [2, 0]])


@dataclass(frozen=True)
class Edges:
    """Every edge of a triangle mesh, once per adjacent triangle (``occurrence``)."""

    element: np.ndarray  # (occ,) triangle of the occurrence
    local: np.ndarray  # (occ, 2) local corners of the edge's two end points, sorted by global node index
    normal: np.ndarray  # (occ, 2) unit normal pointing out of the triangle
    length: np.ndarray  # (occ,)
    interior: np.ndarray  # (pairs, 2) occurrence indices of the two sides of each interior edge
    boundary: np.ndarray  # (b,) occurrence indices of the boundary edges


def mesh_edges(points: np.ndarray, triangles: np.ndarray) -> Edges:
    """The edge table of ``triangles`` (3, e) on ``points`` (2, n)."""
    n_el = triangles.shape[1]
    element = np.repeat(np.arange(n_el), 3)
    local = np.tile(LOCAL_EDGES, (n_el, 1))
    nodes = triangles[local, element[:, None]]  # (occ, 2) global nodes
    swap = nodes[:, 0] > nodes[:, 1]
    local = np.where(swap[:, None], local[:, ::-1], local)
    nodes = np.sort(nodes, axis=1)
    p, q = points[:, nodes[:, 0]].T, points[:, nodes[:, 1]].T
    length = np.hypot(*(q - p).T)
    normal = np.stack([q[:, 1] - p[:, 1], p[:, 0] - q[:, 0]], axis=1) / length[:, None]
    opposite = np.tile(3 - LOCAL_EDGES.sum(axis=1), n_el)  # local corner not on the edge
    third = points[:, triangles[opposite, element]].T
    normal *= np.where(((third - p) * normal).sum(axis=1) > 0, -1.0, 1.0)[:, None]
    key = nodes[:, 0].astype(np.int64) * points.shape[1] + nodes[:, 1]
    order = np.argsort(key, kind="stable")
    _, first, counts = np.unique(key[order], return_index=True, return_counts=True)
    interior = np.stack([order[first[counts == 2]], order[first[counts == 2] + 1]], axis=1)
    return Edges(element, local, normal, length, interior, np.sort(order[first[counts == 1]]))


def traction_operator(n_var: int, element, local, normal, weight) -> sp.csr_matrix:
    """``(2 m, n_var)``: ``weight * s n`` (x then y component) at corner ``local`` of ``element``, m points."""
    m = element.size
    base = 9 * element + 3 * local
    rows = np.repeat(np.arange(2 * m).reshape(m, 2), 2, axis=1).ravel()  # x, x, y, y per point
    cols = np.stack([base, base + 2, base + 2, base + 1], axis=1).ravel()  # sxx, sxy | sxy, syy
    data = (np.stack([normal[:, 0], normal[:, 1], normal[:, 0], normal[:, 1]], axis=1) * weight[:, None]).ravel()
    return sp.csr_matrix((data, (rows, cols)), shape=(2 * m, n_var))


class StaticField:
    """Operators of the piecewise-linear discontinuous stress field on a triangle mesh (non-dimensional)."""

    def __init__(self, points: np.ndarray, triangles: np.ndarray, thickness: np.ndarray):
        self.points, self.triangles, self.thickness = points, triangles, np.asarray(thickness, dtype=float)
        self.n_el = triangles.shape[1]
        self.n_var = 9 * self.n_el
        x, y = points[0, triangles], points[1, triangles]  # (3, e)
        x1, x2 = np.roll(x, -1, axis=0), np.roll(x, -2, axis=0)
        y1, y2 = np.roll(y, -1, axis=0), np.roll(y, -2, axis=0)
        twice_area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0])
        self.area = 0.5 * np.abs(twice_area)  # the gradients below hold for either orientation
        degenerate = self.area <= 1e-12 * np.ptp(points, axis=1).prod()
        if degenerate.any():
            raise mf.ModelError(f"jmm limit: mesh triangle {int(np.argmax(degenerate))} has no area")
        self.grad = np.stack([(y1 - y2) / twice_area, (x2 - x1) / twice_area])  # (2, 3 corners, e)
        self.edges = mesh_edges(points, triangles)

    def equilibrium(self, body: np.ndarray) -> tuple[sp.csr_matrix, np.ndarray]:
        """Rows ``V (div s + b) = 0`` per triangle (V = area x thickness) for a ``(e, 2)`` body force."""
        volume = self.area * self.thickness
        e = np.arange(self.n_el)
        cols = 9 * e[:, None] + 3 * np.arange(3)[None, :]  # (e, 3): sxx of each corner
        gx, gy = self.grad[0].T * volume[:, None], self.grad[1].T * volume[:, None]  # (e, 3)
        rows_x = np.repeat(2 * e, 6)
        rows_y = rows_x + 1
        cols_x = np.concatenate([cols, cols + 2], axis=1).ravel()  # d sxx/dx + d sxy/dy
        cols_y = np.concatenate([cols + 2, cols + 1], axis=1).ravel()  # d sxy/dx + d syy/dy
        data = np.concatenate([gx, gy], axis=1).ravel()
        matrix = sp.csr_matrix((np.concatenate([data, data]), (np.concatenate([rows_x, rows_y]),
                                np.concatenate([cols_x, cols_y]))), shape=(2 * self.n_el, self.n_var))
        return matrix, -(body * volume[:, None]).ravel()

    def _edge_traction(self, occurrences: np.ndarray, normal: np.ndarray | None = None) -> sp.csr_matrix:
        """Thickness x traction ``s n`` at both end points of each edge occurrence (4 rows per edge)."""
        E = self.edges
        element = np.repeat(E.element[occurrences], 2)
        n = np.repeat(E.normal[occurrences] if normal is None else normal, 2, axis=0)
        return traction_operator(self.n_var, element, E.local[occurrences].ravel(), n, self.thickness[element])

    def continuity(self) -> sp.csr_matrix:
        """Rows ``t_e s_e n - t_f s_f n = 0`` at both ends of every interior edge (``n`` of side e)."""
        side_e, side_f = self.edges.interior.T
        n = self.edges.normal[side_e]
        return self._edge_traction(side_e, n) - self._edge_traction(side_f, n)

    def boundary_traction(self, occurrences: np.ndarray) -> sp.csr_matrix:
        """Thickness x traction on the body (``s n_out``) at both ends of boundary edges (4 rows per edge)."""
        return self._edge_traction(occurrences)

    def boundary_resultant(self, occurrences: np.ndarray) -> sp.csr_matrix:
        """``(2, n_var)``: the force the outside exerts on the body through these boundary edges (x, y)."""
        traction = self.boundary_traction(occurrences)  # rows (edge, end, component)
        half_length = np.repeat(0.5 * self.edges.length[occurrences], 4)
        component = np.tile([0, 1], 2 * occurrences.size)
        summing = sp.csr_matrix((half_length, (component, np.arange(half_length.size))),
                                shape=(2, half_length.size))
        return summing @ traction

    def strength(self, A: np.ndarray, b: np.ndarray, corner: np.ndarray, face: np.ndarray,
                 to_bed: np.ndarray | None = None):
        """Rows ``A[face] T s <= b[face]`` at stress nodes ``corner`` (= 3 element + local corner); one row each.

        ``to_bed``: ``(e, 3, 3)`` rotation of each triangle's stresses into its bed frame (None: horizontal beds).
        """
        coefficients = A[face] if to_bed is None else np.einsum("rk,rkj->rj", A[face], to_bed[corner // 3])
        rows = np.repeat(np.arange(corner.size), 3)
        cols = (3 * corner[:, None] + np.arange(3)).ravel()
        return sp.csr_matrix((coefficients.ravel(), (rows, cols)), shape=(corner.size, self.n_var)), b[face]

    def implied_by_free_edges(self, A: np.ndarray, free: np.ndarray, to_bed: np.ndarray | None = None) -> np.ndarray:
        """Boolean ``(3 e, faces)``: strength rows that the traction-free conditions already decide.

        On a free edge with normal n the stress at its end points is uniaxial along the edge,
        ``s = k (ny^2, nx^2, -nx ny)``; a face with ``A s_t = 0`` then reads ``0 <= b``. At c = 0
        that row is tight but says nothing, and its multiplier is arbitrary (any value is
        cancelled by the boundary rows' multipliers), so it would mark the whole free surface
        plastic. A stress node on two free edges of different direction has ``s = 0``: all its
        rows are decided.
        """
        E = self.edges
        corner = (3 * np.repeat(E.element[free], 2) + E.local[free].ravel())
        nx, ny = np.repeat(E.normal[free], 2, axis=0).T
        implied = np.zeros((3 * self.n_el, A.shape[0]), dtype=bool)
        uniaxial = np.stack([ny**2, nx**2, -nx * ny], axis=1)  # (entries, 3)
        if to_bed is not None:
            uniaxial = np.einsum("nij,nj->ni", to_bed[corner // 3], uniaxial)
        tangential = uniaxial @ A.T  # (entries, faces)
        np.logical_or.at(implied, corner, np.abs(tangential) <= 1e-12 * np.abs(A).max())
        direction = np.round(np.abs(np.stack([nx, ny], axis=1)), 9)
        distinct = np.unique(np.column_stack([corner, direction]), axis=0)[:, 0].astype(int)
        implied[np.bincount(distinct, minlength=3 * self.n_el) > 1] = True
        return implied


@dataclass
class LPSolution:
    x: np.ndarray
    strength_duals: np.ndarray
    equality_duals: np.ndarray
    objective: float
    status: str
    iterations: int
    seconds: float


def solve_lp(cost: np.ndarray, equalities: sp.spmatrix, rhs: np.ndarray, inequalities: sp.spmatrix,
             bounds: np.ndarray, tolerance: float = 1e-8) -> LPSolution:
    """``min cost.x`` s.t. ``equalities x = rhs``, ``inequalities x <= bounds``, by Clarabel (QDLDL)."""
    import clarabel

    n_eq, n_in = equalities.shape[0], inequalities.shape[0]
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.direct_solve_method = "qdldl"
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tolerance
    start = time.perf_counter()
    solver = clarabel.DefaultSolver(
        sp.csc_matrix((cost.size, cost.size)), np.asarray(cost, dtype=float),
        sp.vstack([equalities, inequalities], format="csc"), np.concatenate([rhs, bounds]),
        [clarabel.ZeroConeT(n_eq), clarabel.NonnegativeConeT(n_in)], settings,
    )
    sol = mfp.interruptible(solver.solve)
    seconds = time.perf_counter() - start
    status = str(sol.status).split(".")[-1]
    if status in ("PrimalInfeasible", "AlmostPrimalInfeasible"):
        raise mf.SolveError(
            f"jmm limit: Clarabel finds no statically admissible stress field ({status}) on this mesh. With "
            "c = 0 a lintel or strip one cell deep cannot pass its shear to the masonry (measured on Facade 3 at "
            "mesh_size 0.05 m; 0.025 m works): try a smaller mesh_size"
        )
    if status not in ("Solved", "AlmostSolved"):
        raise mf.SolveError(f"jmm limit: Clarabel stopped with status {status} after {sol.iterations} iterations")
    x = np.asarray(sol.x)
    z = np.asarray(sol.z)
    return LPSolution(x, z[n_eq:], z[:n_eq], float(cost @ x), status, int(sol.iterations), seconds)


def plastic_rows(duals: np.ndarray, volume: np.ndarray) -> np.ndarray:
    """Strength rows whose multiplier per unit volume (of their stress node) is significant."""
    rate = duals / volume
    return rate > PLASTIC_DUAL_FRACTION * rate.max(initial=0.0)


def support_edges(domain: Domain, field: StaticField, model: xr.Dataset) -> tuple[np.ndarray, np.ndarray]:
    """Boundary edge occurrences on fixed and on moving supports: those lying on the model's support
    interfaces (the same test as the incremental solver's prescribed DOFs)."""
    E, H = field.edges, domain.length
    occ = E.boundary
    ends = field.triangles[E.local[occ], E.element[occ][:, None]].T  # (2, b) global nodes
    on = support_facets(field.points, ends, domain.mesh.supports / H, 1e-6 * domain.mesh_size / H)
    block = np.where(on >= 0, domain.mesh.support_block[np.maximum(on, 0)], -1)
    role = np.where(block >= 0, model.block_role.values[np.maximum(block, 0)], -1)
    fixed, moving = mfp.fixed_blocks(role), mfp.moving_blocks(role)
    return occ[fixed], occ[moving]


def check_vertical_settlement(model: xr.Dataset) -> None:
    """The LP's objective is the vertical reaction: every moving support must translate straight down, all
    at one rate (a trough's segments at their own rates need the incremental solver)."""
    moving = np.nonzero(mfp.moving_blocks(model.block_role.values))[0]
    direction = model.settlement_direction.values[moving]
    bad = moving[~(np.isclose(direction[:, 0], 0) & np.isclose(direction[:, 2], 0) & (direction[:, 1] < 0))]
    if bad.size:
        raise mf.ModelError(
            f"jmm-limit: moving support block {int(bad[0])} has settlement_direction "
            f"{model.settlement_direction.values[bad[0]].tolist()}; the limit LP needs a downward vertical "
            "translation (0, -1, 0) (use the solver jmm for rotations and horizontal ground motion)"
        )
    rates = -direction[:, 1]
    if moving.size and not np.allclose(rates, rates[0], rtol=1e-9):
        other = moving[int(np.argmax(~np.isclose(rates, rates[0], rtol=1e-9)))]
        raise mf.ModelError(
            f"jmm-limit: moving support blocks {int(moving[0])} and {int(other)} settle at different rates "
            f"({rates[0]:.6g} and {-model.settlement_direction.values[other, 1]:.6g}); the limit LP minimises one "
            "vertical reaction, so every moving support must settle at one rate (use the solver jmm for a profile)"
        )


@dataclass
class LimitLP:
    """An assembled limit LP and what is needed to read its solution.

    Settlement (``dead_reaction`` set): ``min R``, the moving support's vertical reaction.
    Load factor (``dead_reaction`` None): ``max lambda`` of the live load, the last variable.
    """

    field: StaticField
    cost: np.ndarray
    equalities: sp.csr_matrix
    rhs: np.ndarray
    inequalities: sp.csr_matrix
    bounds: np.ndarray
    strength_corner: np.ndarray  # stress node (3 element + local corner) of every strength row
    strength_face: np.ndarray  # face (row of A) of every strength row
    dead_reaction: float | None  # W L_moving / L_contact: the settlement dead load of the moving support
    n_faces: int


def strength_rows(field: StaticField, A: np.ndarray, b: np.ndarray, strong: np.ndarray, free: np.ndarray,
                  to_bed: np.ndarray | None, head: np.ndarray | None = None, headless: np.ndarray | None = None):
    """``(inequalities, bounds, corner, face)``: ``A T s <= b`` at the corners of the ``strong`` triangles,
    less the rows the free edges already decide and the ``head`` faces of ``headless`` triangles."""
    corner = np.repeat((3 * np.asarray(strong)[:, None] + np.arange(3)).ravel(), A.shape[0])
    face = np.tile(np.arange(A.shape[0]), corner.size // A.shape[0])
    keep = ~field.implied_by_free_edges(A, free, to_bed)[corner, face]
    if headless is not None:
        keep &= ~(headless[corner // 3] & head[face])
    corner, face = corner[keep], face[keep]
    inequalities, bounds = field.strength(A, b, corner, face, to_bed)
    return inequalities, bounds, corner, face


def settlement_lp(field: StaticField, unit_weight: np.ndarray, strong: np.ndarray, A: np.ndarray, b: np.ndarray,
                  fixed: np.ndarray, moving: np.ndarray, to_bed: np.ndarray | None = None,
                  head: np.ndarray | None = None, headless: np.ndarray | None = None) -> LimitLP:
    """``min R`` for a body under its weight (``unit_weight`` per triangle, acting in -y) on supports.

    ``fixed`` and ``moving`` are boundary edge occurrences on the supports (traction free to
    take any value); every other boundary edge is traction free; ``A T s <= b`` holds at the
    corners of the ``strong`` triangles (``T``: ``to_bed``, the bed frame of every triangle).
    """
    body = np.stack([np.zeros(field.n_el), -unit_weight], axis=1)
    equilibrium, load = field.equilibrium(body)
    free = np.setdiff1d(field.edges.boundary, np.concatenate([fixed, moving]))
    equalities = sp.vstack([equilibrium, field.continuity(), field.boundary_traction(free)], format="csr")
    rhs = np.concatenate([load, np.zeros(equalities.shape[0] - load.size)])
    inequalities, bounds, corner, face = strength_rows(field, A, b, strong, free, to_bed, head, headless)
    weight = float((unit_weight * field.area * field.thickness).sum())
    lengths = field.edges.length
    share = lengths[moving].sum() / (lengths[fixed].sum() + lengths[moving].sum())
    cost = field.boundary_resultant(moving).toarray()[1]
    return LimitLP(field, cost, equalities, rhs, inequalities, bounds, corner, face, float(weight * share),
                   A.shape[0])


def load_factor_lp(field: StaticField, dead_body: np.ndarray, live_body: np.ndarray, strong: np.ndarray,
                   A: np.ndarray, b: np.ndarray, supports: np.ndarray, to_bed: np.ndarray | None = None,
                   head: np.ndarray | None = None, headless: np.ndarray | None = None) -> LimitLP:
    """``max lambda``: the body in equilibrium under ``dead_body + lambda live_body`` (``(e, 2)`` per unit
    volume) on held ``supports``, every other boundary edge traction free, ``A T s <= b`` in the ``strong``
    triangles. The variables are the stresses and then lambda."""
    equilibrium, dead = field.equilibrium(dead_body)
    _, live = field.equilibrium(live_body)
    free = np.setdiff1d(field.edges.boundary, supports)
    column = lambda values: sp.csr_matrix(np.asarray(values, dtype=float).reshape(-1, 1))  # noqa: E731
    others = sp.vstack([field.continuity(), field.boundary_traction(free)], format="csr")
    equalities = sp.vstack([sp.hstack([equilibrium, column(-live)]),
                            sp.hstack([others, sp.csr_matrix((others.shape[0], 1))])], format="csr")
    rhs = np.concatenate([dead, np.zeros(others.shape[0])])
    inequalities, bounds, corner, face = strength_rows(field, A, b, strong, free, to_bed, head, headless)
    inequalities = sp.hstack([inequalities, sp.csr_matrix((inequalities.shape[0], 1))], format="csr")
    cost = np.zeros(field.n_var + 1)
    cost[-1] = -1.0
    return LimitLP(field, cost, equalities, rhs, inequalities, bounds, corner, face, None, A.shape[0])


def wall_lp(domain: Domain, model: xr.Dataset, A: np.ndarray, b: np.ndarray, names: tuple[str, ...]) -> LimitLP:
    """The limit LP of the wall meshed by :func:`.problem.wall_domain` (non-dimensional, module docstring):
    the settlement LP with a moving support, else the load-factor LP of the live load."""
    H = domain.length
    mesh = MeshTri(domain.mesh.points / H, domain.mesh.triangles)
    blocks = domain.mesh.block
    field = StaticField(mesh.p, mesh.t, model.block_thickness.values[blocks] / H)
    unit_weight = model.block_unit_weight.values[blocks] / domain.unit_weight
    fixed, moving = support_edges(domain, field, model)
    strong = np.nonzero(mfp.jointed_blocks(model.block_role.values[blocks]))[0]
    angle = domain.angles[blocks]
    to_bed = stress_rotation(angle) if np.any(angle) else None
    head = np.array([name.startswith("head") for name in names])
    headless = domain.headless[blocks]
    if moving.size:
        return settlement_lp(field, unit_weight, strong, A, b, fixed, moving, to_bed, head, headless)
    if not np.any(mfp.block_loads(model, "live")[blocks]):
        raise mf.ModelError("jmm-limit: no moving support to settle and no live load to raise: nothing to analyse")
    dead = np.stack([np.zeros(field.n_el), -unit_weight], axis=1)
    return load_factor_lp(field, dead, live_body_force(model, blocks, domain.unit_weight), strong, A, b, fixed,
                          to_bed, head, headless)


def collapse_points(field: StaticField, stress: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points midway between each corner and its triangle's centroid, and the stress there.

    They are the P2 solver's quadrature points (barycentric (2/3, 1/6, 1/6)), so ``qp_*`` of
    both methods sit at the same places; point ``k`` takes the flags of corner ``k``.
    """
    corners = field.points[:, field.triangles]  # (2, 3, e)
    xy = 0.5 * (corners + corners.mean(axis=1, keepdims=True))
    s = stress.reshape(field.n_el, 3, 3)  # (e, corner, component)
    at_points = 0.5 * s + 0.5 * s.mean(axis=1, keepdims=True)
    return xy.transpose(0, 2, 1).reshape(2, -1), at_points.reshape(-1, 3)


def limit_mechanism(domain: Domain, lp: LimitLP, sol: LPSolution, model: xr.Dataset) -> np.ndarray | None:
    """The collapse mechanism as block motions (block, 3): per metre of settlement (as la's), or per unit
    rate of the live load's multiplier.

    The static LP's kinematic side: the duals of the equilibrium rows ``V (div s + b) = 0`` are the
    triangles' velocities, scaled so that the moving support settles at unit rate (the cost is its
    reaction; checked: the fastest point moves at 1.000). They are projected onto each block's rigid
    motions at the triangles' centroids, weighted by volume (:func:`masonryfw.plugin_api.rigid_fit`); the
    supports move along their ``settlement_direction`` (0 when fixed). None where a block gets no
    motion (no triangle)."""
    field, H = lp.field, domain.length
    velocity = sol.equality_duals[:2 * field.n_el].reshape(field.n_el, 2)
    cx, cy = (field.points[c, field.triangles].mean(axis=0) * H for c in (0, 1))
    return block_mechanism(model, domain.mesh.block, cx, cy, velocity[:, 0], velocity[:, 1],
                           field.area * field.thickness, 1.0 if lp.dead_reaction is not None else 0.0)


def limit_dataset(domain: Domain, lp: LimitLP, sol: LPSolution, names: tuple[str, ...],
                  assembly: float) -> xr.Dataset:
    """The result variables (physical units) of the limit LP (docs/format.md)."""
    field, H, S = lp.field, domain.length, domain.stress
    element = lp.strength_corner // 3
    plastic = plastic_rows(sol.strength_duals, field.area[element] * field.thickness[element] / 3.0)
    active = np.zeros((3 * field.n_el, lp.n_faces), dtype=bool)
    active[lp.strength_corner[plastic], lp.strength_face[plastic]] = True
    failure = failure_mode(active, names)
    (qx, qy), stress = collapse_points(field, sol.x[:field.n_var])
    qx, qy, stress = qx * H, qy * H, stress * S
    variables = {
        **mesh_variables(field.points * H, field.triangles),
        **point_variables((qx, qy), failure, stress, "point (midway between a triangle corner and its centroid)",
                          "in the collapse state (failure: LP duals of the strength rows)"),
    }
    attrs = {"jmm_beta": domain.beta}
    if lp.dead_reaction is None:
        variables["collapse_multiplier"] = variable((), float(sol.x[-1]), "1",
                                                    "largest multiplier of the live load (static LP), lower bound "
                                                    "on the mesh")
    else:
        reaction = sol.objective * domain.force
        dead = lp.dead_reaction * domain.force
        variables["collapse_multiplier"] = variable((), 1.0 - reaction / dead, "1",
                                                    "alpha = 1 - R_min / (W L_moving / L_contact), lower bound on "
                                                    "the mesh")
        variables["moving_support_reaction"] = variable((), reaction, "N", "smallest upward vertical reaction of "
                                                        "the moving support (static LP)")
        attrs["jmm_dead_reaction_n"] = dead
    attrs = {
        **attrs,
        "jmm_lp_variables": int(lp.cost.size),
        "jmm_lp_equalities": int(lp.equalities.shape[0]),
        "jmm_lp_inequalities": int(lp.inequalities.shape[0]),
        "jmm_lp_nonzeros": int(lp.equalities.nnz + lp.inequalities.nnz),
        "jmm_lp_status": sol.status,
        "jmm_lp_iterations": sol.iterations,
        "jmm_lp_assembly_time_s": assembly,
        "jmm_lp_solve_time_s": sol.seconds,
    }
    return xr.Dataset(variables, attrs=attrs)


def solve(model: xr.Dataset, options, progress) -> xr.Dataset:
    """Smallest moving-support reaction the JMM continuum can carry (or, without a moving support, the largest
    multiplier of its live load): the ``jmm-limit`` solver entry point."""
    check_vertical_settlement(model)
    start = time.perf_counter()
    progress(0.0, "meshing and assembling the limit LP")
    domain = wall_domain(model, options["mesh_size"], options["beta"])
    A, b, _, names = domain.scaled_strength(options["apex_shift"]).faces()
    lp = wall_lp(domain, model, A, b, names)
    assembly = time.perf_counter() - start
    progress(0.2, f"solving the limit LP: {lp.field.n_var} variables, {lp.equalities.shape[0]} equalities, "
             f"{lp.inequalities.shape[0]} inequalities")
    sol = solve_lp(lp.cost, lp.equalities, lp.rhs, lp.inequalities, lp.bounds)
    result = limit_dataset(domain, lp, sol, names, assembly)
    progress(1.0, f"limit LP {sol.status}: alpha = {float(result.collapse_multiplier):.4f}")
    return with_mechanism(result, limit_mechanism(domain, lp, sol, model), "associative")  # an associated LP
