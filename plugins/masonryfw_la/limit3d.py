"""Rigid-block limit analysis in 3D: the kinematic programme of polyhedra with a friction pyramid.

The 2D programme (:mod:`.assembly`) written for blocks with six velocities ``(ux, uy, uz, rx, ry, rz)`` at their
centroids and interfaces that are planar polygons. At every vertex ``p`` of an interface the relative velocity
(side 1 minus side 0) is ``v = u1 + w1 x (p - c1) - u0 - w0 x (p - c0)``; its normal part ``dn = n.v`` and
tangential part ``dt`` obey the associative no-tension Coulomb rule ``dn >= mu |dt|``, with ``|dt|`` taken over
a regular pyramid of ``sides`` directions ``e_j = cos(2 pi j / sides) t0 + sin(2 pi j / sides) t1``::

    (n - mu e_j) . v >= 0        j = 0 .. sides - 1

or, with ``sides = 0``, Coulomb's cone itself, ``(n.v, mu t0.v, mu t1.v)`` in the second-order cone (our interior
point, :mod:`.ipm`, or Clarabel).
Its dual (the static side) puts at each vertex the force ``sum_j y_j (n - mu e_j)`` on side 1, ``y >= 0``:
a normal force ``N = sum y`` and a friction force inside the regular polygon inscribed in Coulomb's circle of
radius ``mu N`` (exact in the pyramid's directions, ``cos(pi / sides)`` of it half-way between them; the first
direction is the interface's first tangent, horizontal on a vertical joint, x on a horizontal one, so that
sliding along or across a wall's bed and head joints is exact for any multiple of four sides).

Non-dimensional as in 2D: lengths by ``L``, rotations by ``L / r0`` (``r0`` the cube root of the median masonry
volume), forces by the total dead load ``W`` and moments by ``W r0``. Dry joints only: cohesion and tensile
strength are refused, not ignored.
"""
from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from . import backends
from .options import DEFAULT_BACKEND

#: The backends that solve Coulomb's cone (a second-order cone programme).
CONE_BACKENDS = ("ipm", "clarabel")

#: Coulomb's cone itself unless a caller asks for a pyramid: on the bundled house the 8-sided pyramid is 4.2 %
#: below the cone, and slower (docs/la.md, "In 3D").
DEFAULT_SIDES = 0


class Blocks3D(NamedTuple):
    """What the 3D programme reads: polyhedra, their contacts, loads and supports (SI units)."""

    centroid: np.ndarray  # (block, 3)
    volume: np.ndarray  # (block,)
    role: np.ndarray  # (block,) mfp.ROLE flags
    fixed: np.ndarray  # (block, 6) bool: the component of motion is held
    direction: np.ndarray  # (block, 6) a moving support's motion per unit settlement parameter t
    dead: np.ndarray  # (block, 6) force [N] and moment [N m] at the centroid
    live: np.ndarray  # (block, 6) scaled by the multiplier alpha
    contacts: mfp.Contacts
    friction: np.ndarray  # (interface,) mu
    scale: float  # L: the model's size [m]

    @property
    def n_block(self) -> int:
        return self.role.size


class LimitState3D(NamedTuple):
    """The collapse state: alpha, the mechanism and the forces at the interfaces' vertices (SI units)."""

    alpha: float
    motion: np.ndarray  # (block, 6) per unit settlement t, else per unit of the programme's normalisation
    point_force: np.ndarray  # (point, 3) the force on side 1 at each interface vertex [N]
    active: np.ndarray  # (interface,) bool: in the programme (not support on support, not held on held)
    solution: backends.LPSolution


class Scales3D(NamedTuple):
    length: float  # L [m]
    block: float  # r0 [m]
    force: float  # W [N]

    @property
    def dof(self) -> np.ndarray:
        """Physical dofs per programme unit: ``(L, L, L, L/r0, L/r0, L/r0)``."""
        return np.array([self.length] * 3 + [self.length / self.block] * 3)


def blocks_of(model) -> Blocks3D:
    """The arrays of a checked 3D model (derived geometry). Joints with cohesion or tensile strength are refused."""
    bonded = np.flatnonzero((model.interface_cohesion.values > 0) | (model.interface_tensile_strength.values > 0))
    if bonded.size:
        raise mf.SolveError(f"la in 3D: interface {bonded[0]} has cohesion or tensile strength "
                            f"({mfp.listed(bonded)} in all): only dry joints in 3D so far")
    centroid = np.c_[model.block_centroid_x.values, model.block_centroid_y.values, model.block_centroid_z.values]
    poly = mfp.polyhedra_of(model)
    scale = float(np.linalg.norm(poly.vertices.max(axis=0) - poly.vertices.min(axis=0))) if poly.vertices.size else 1.0
    return Blocks3D(centroid, model.block_volume.values, model.block_role.values, model.block_fixed.values != 0,
                    model.settlement_direction.values.astype(float),
                    np.c_[model.dead_load.values, model.dead_moment.values].astype(float),
                    np.c_[model.live_load.values, model.live_moment.values].astype(float),
                    mfp.contacts_of(model), model.interface_friction.values.astype(float), scale)


def scales_of(blocks: Blocks3D) -> Scales3D:
    masonry = mfp.masonry_blocks(blocks.role)
    volume = np.abs(blocks.volume[masonry])
    block = float(np.cbrt(np.median(volume))) if volume.size and np.median(volume) > 0 else blocks.scale
    for loads in (blocks.dead, blocks.live):
        force = float(np.linalg.norm(loads[:, :3], axis=1).sum())
        if force > 0:
            return Scales3D(blocks.scale, block, force)
    return Scales3D(blocks.scale, block, 1.0)


def column_map(blocks: Blocks3D, scales: Scales3D) -> tuple[sp.csr_matrix, int | None]:
    """The programme's columns to all block dofs: the free dofs, then one settlement parameter ``t`` moving every
    moving support by ``t * direction`` (as in 2D)."""
    moving = mfp.moving_blocks(blocks.role)
    free = np.flatnonzero((~blocks.fixed & ~moving[:, None] & ~mfp.support_blocks(blocks.role)[:, None]).ravel())
    rows, cols, vals = [free], [np.arange(free.size)], [np.ones(free.size)]
    settlement = None
    if moving.any():
        dofs = 6 * np.flatnonzero(moving)[:, None] + np.arange(6)
        rows.append(dofs.ravel())
        cols.append(np.full(dofs.size, free.size))
        vals.append((blocks.direction[moving] * scales.length / scales.dof).ravel())
        settlement = free.size
    matrix = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                           shape=(6 * blocks.n_block, free.size + (settlement is not None)))
    matrix.eliminate_zeros()
    return matrix, settlement


def cone_rows(blocks: Blocks3D, scales: Scales3D) -> tuple[sp.csr_matrix, np.ndarray]:
    """``(point * 3, 6 block)``: the rows ``n.v, mu t0.v, mu t1.v`` of every vertex, and those axes
    ``(point, 3, 3)``."""
    contacts = blocks.contacts
    owner = contacts.point_interface()
    axis = np.concatenate([contacts.normal[owner][:, None, :],
                           blocks.friction[owner][:, None, None] * contacts.tangent[owner]], axis=1)
    return relative_velocity_rows(blocks, scales, axis), axis


def pyramid_directions(sides: int) -> np.ndarray:
    """``(sides, 2)``: the pyramid's directions in the interface's tangent frame."""
    angle = 2.0 * np.pi * np.arange(sides) / sides
    return np.c_[np.cos(angle), np.sin(angle)]


def pyramid_rows(blocks: Blocks3D, scales: Scales3D, sides: int) -> tuple[sp.csr_matrix, np.ndarray]:
    """``(point * sides, 6 block)``: the rows ``(n - mu e_j) . v`` of every interface vertex, and their
    directions ``n - mu e_j`` ``(point, sides, 3)``."""
    contacts = blocks.contacts
    owner = contacts.point_interface()
    mu = blocks.friction[owner]
    e = pyramid_directions(sides)
    tangent = contacts.tangent[owner]  # (point, 2, 3)
    axis = contacts.normal[owner][:, None, :] - mu[:, None, None] * np.einsum("jk,pkd->pjd", e, tangent)
    return relative_velocity_rows(blocks, scales, axis), axis


def relative_velocity_rows(blocks: Blocks3D, scales: Scales3D, axis: np.ndarray) -> sp.csr_matrix:
    """``(point * k, 6 block)``: the relative velocity of every vertex (side 1 minus side 0) along each of its
    ``k`` axes ``(point, k, 3)``, in the programme's columns of all blocks."""
    contacts = blocks.contacts
    owner = contacts.point_interface()
    sides = axis.shape[1]
    side_block = contacts.sides[owner]  # (point, 2)
    arm = (contacts.points[:, None, :] - blocks.centroid[side_block]) / scales.block  # (point, side, 3)
    sign = np.array([-1.0, 1.0])
    translation = sign[None, :, None, None] * axis[:, None, :, :]  # (point, side, j, 3)
    rotation = sign[None, :, None, None] * np.cross(arm[:, :, None, :], axis[:, None, :, :])
    coef = np.concatenate([translation, rotation], axis=-1)  # (point, side, j, 6)
    n_point = owner.size
    rows = np.broadcast_to((np.arange(n_point)[:, None] * sides + np.arange(sides))[:, None, :, None],
                           coef.shape)
    cols = np.broadcast_to(6 * side_block[:, :, None, None] + np.arange(6), coef.shape)
    return sp.csr_matrix((coef.ravel(), (rows.ravel(), cols.ravel())), shape=(n_point * sides, 6 * blocks.n_block))


def programme_loads(blocks: Blocks3D, scales: Scales3D, cmap: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray]:
    """The cost (minus the dead load's work) and the live load's work per programme column; a live load that does
    no work on any free component of motion is refused."""
    unit = np.r_[np.ones(3), np.full(3, 1.0 / scales.block)] / scales.force  # loads per programme unit
    cost = -(cmap.T @ (blocks.dead * unit).ravel())
    live = cmap.T @ (blocks.live * unit).ravel()
    if not np.any(np.abs(live) > 1e-12 * max(1.0, np.abs(cost).max(initial=0.0))):
        raise mf.SolveError("no live load: the multiplier is undefined (the live load is zero on every component "
                            "of motion that is not held)")
    return cost, live


def active_interfaces(blocks: Blocks3D, cmap: sp.csr_matrix) -> np.ndarray:
    """Interfaces that constrain the motion: not ground on ground, and at least one side with a column."""
    support = mfp.support_blocks(blocks.role)
    moves = np.asarray(abs(cmap).sum(axis=1)).reshape(-1, 6).sum(axis=1) > 0
    sides = blocks.contacts.sides
    return ~support[sides].all(axis=1) & moves[sides].any(axis=1)


def limit_state_3d(blocks: Blocks3D, sides: int = DEFAULT_SIDES, solver: str = "ipm",
                   tolerance: float = 1e-9, progress=None) -> LimitState3D:
    """The collapse multiplier, mechanism and vertex forces of ``blocks`` (module docstring): a pyramid of
    ``sides`` sides, or Coulomb's cone with ``sides = 0`` (``solver`` ipm or clarabel). ``progress(iteration,
    error)``: the interior point's.

    Raises :class:`~.backends.LiveLoadUnbounded` when no mechanism lets the live load work and
    :class:`~.backends.DeadLoadNotCarried` when the dead load alone is not carried.
    """
    if 0 < sides < 3 or sides < 0:
        raise mf.SolveError(f"la in 3D: a friction pyramid needs at least 3 sides, not {sides} (0: the cone)")
    scales = scales_of(blocks)
    cmap, _ = column_map(blocks, scales)
    rows, axis = cone_rows(blocks, scales) if sides == 0 else pyramid_rows(blocks, scales, sides)
    per_point = axis.shape[1]
    active = active_interfaces(blocks, cmap)
    active_rows = np.repeat(active[blocks.contacts.point_interface()], per_point)
    constraints = (rows[active_rows] @ cmap).tocsr()
    constraints.eliminate_zeros()
    cost, live = programme_loads(blocks, scales, cmap)
    if solver == "ipm":
        sol = backends.solve_ipm(cost, constraints, live, tolerance, second_order=3 * (sides == 0), progress=progress)
    elif sides == 0:
        sol = backends.solve_clarabel(cost, constraints, live, tolerance, second_order=3)
    else:
        sol = backends.solve_lp(solver, cost, constraints, live, tolerance)
    motion = (cmap @ sol.x).reshape(-1, 6) * scales.dof
    y = np.zeros(active_rows.size)
    y[active_rows] = sol.y
    point_force = np.einsum("pj,pjd->pd", y.reshape(-1, per_point), axis) * scales.force
    return LimitState3D(float(sol.alpha_primal), motion, point_force, active, sol)


def iteration_progress(progress, friction: str, tolerance: float):
    """The interior point's ``(iteration, error)`` as progress from 0.2 to 0.95, by the error's decades from the
    first iterate's to the tolerance."""
    first: list[float] = []

    def report(iteration: int, error: float) -> None:
        first.append(error) if not first else None
        decades = np.log10(max(first[0], tolerance) / tolerance)
        done = np.log10(max(first[0], error) / max(error, tolerance)) / decades if decades > 0 else 1.0
        progress(0.2 + 0.75 * min(1.0, done), f"la: {friction}, interior point iteration {iteration}, "
                                              f"error {error:.1e}")

    return report


def support_wrenches(blocks: Blocks3D, state: LimitState3D) -> np.ndarray:
    """``(block, 6)``: the force and moment (about its centroid) the masonry exerts on every support block (0 for
    masonry blocks); the contact forces between two supports are not the wall's."""
    contacts = blocks.contacts
    owner = contacts.point_interface()
    support = mfp.support_blocks(blocks.role)
    wall = ~support[contacts.sides].all(axis=1)[owner]
    wrench = np.zeros((blocks.n_block, 6))
    for side, sign in ((1, 1.0), (0, -1.0)):  # point_force acts on side 1, its opposite on side 0
        block = contacts.sides[owner, side]
        force = sign * state.point_force * wall[:, None]
        np.add.at(wrench, block, np.c_[force, np.cross(contacts.points - blocks.centroid[block], force)])
    wrench[~support] = 0.0
    return wrench


def solve(model: xr.Dataset, options: Mapping[str, Any], progress=mfp.no_progress) -> xr.Dataset:
    """``la`` on a 3D model: the collapse multiplier, the mechanism and the forces at the interfaces' vertices."""
    clock = time.perf_counter()
    progress(0.0, "la: assembling the 3D programme")
    blocks = blocks_of(model)
    sides = int(options["pyramid_sides"])
    flow_rule = options["flow"]
    if flow_rule == "nonassociative" and sides != 0:
        raise mf.SolveError(f"la in 3D: non-associative friction is solved on Coulomb's cone (pyramid_sides = 0), "
                            f"not on a pyramid of {sides} sides")
    if sides == 0 and options["solver"] not in (None, *CONE_BACKENDS):
        raise mf.SolveError(f"la in 3D: Coulomb's cone is a second-order cone programme, which ipm and clarabel "
                            f"solve (solver = {options['solver']} solves LPs: a pyramid, pyramid_sides = 8 or more)")
    backend = options["solver"] or DEFAULT_BACKEND
    friction = "the cone" if sides == 0 else f"a pyramid of {sides} sides"
    progress(0.2, f"la: solving in 3D ({friction}, {backend})")
    flow, flow_attrs = None, {}
    if flow_rule == "nonassociative":
        from . import nonassociative3d

        flow, flow_attrs = nonassociative3d.reported(blocks, options, progress)
        state = flow.state
    else:
        state = limit_state_3d(blocks, sides, backend, options["tolerance"],
                               iteration_progress(progress, friction, options["tolerance"]))
    axis = ("block", "axis")
    data = {
        "collapse_multiplier": ((), state.alpha, mfp.variable_attrs("collapse_multiplier", "result3d")),
        "block_displacement": (axis, state.motion[:, :3], mfp.variable_attrs("block_displacement", "result3d")),
        "block_rotation": (axis, state.motion[:, 3:], mfp.variable_attrs("block_rotation", "result3d")),
        "interface_normal_force": ("interface", np.bincount(
            blocks.contacts.point_interface(), np.einsum("pd,pd->p", state.point_force,
                                                         blocks.contacts.normal[blocks.contacts.point_interface()]),
            minlength=blocks.contacts.n_interface), mfp.variable_attrs("interface_normal_force", "result3d")),
        "lp_status": ((), state.solution.status, {"long_name": "status of the programme", "units": "1"}),
        "lp_iterations": ((), np.int64(state.solution.iterations), {"long_name": "iterations of the backend",
                                                                    "units": "1"}),
    }
    for k, c in enumerate("xyz"):
        data[f"interface_point_force_{c}"] = ("interface_node", state.point_force[:, k],
                                              mfp.variable_attrs(f"interface_point_force_{c}", "result3d"))
    wrench = support_wrenches(blocks, state)
    data["support_reaction"] = (axis, -wrench[:, :3] + 0.0, mfp.variable_attrs("support_reaction", "result3d"))
    if mfp.moving_blocks(blocks.role).any():
        data["moving_support_reaction"] = ((), float(mf.settlement_reaction(model, wrench)),
                                           mfp.variable_attrs("moving_support_reaction", "result3d"))
    unconverged = "" if flow is None or flow.converged else " (NOT CONVERGED: the last iterate)"
    progress(1.0, f"la: alpha = {state.alpha:.6g}{unconverged}")
    method = f"cone, {backend}" if sides == 0 else f"pyramid of {sides} sides, {backend}"
    attrs = {"rotations": "small", "flow_rule": flow_rule, "method": method, "la_backend": backend,
             "la_pyramid_sides": sides, "la_time_s": time.perf_counter() - clock,
             "la_alpha_dual": float(state.solution.alpha_dual), **flow_attrs}
    return xr.Dataset(data, attrs=attrs)
