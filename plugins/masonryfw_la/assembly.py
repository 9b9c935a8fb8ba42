"""Assembly of the kinematic (upper bound) linear programme of a rigid-block wall.

Paper eqs. (1)-(11), written directly on sparse matrices. Unknowns are the block
velocities ``u = (ux, uy, rz)``; at each of the two end points of every
interface the relative velocity (side 1 minus side 0) has a normal part ``dn``
and a tangential part ``dt``. The associative (dilatant) no-tension Coulomb
flow rule ``dn = mu (l1 + l2) + l3, dt = l1 - l2, l >= 0`` is written without
the multipliers as two inequalities per end::

    dn - mu dt >= 0,   dn + mu dt >= 0          (dry end, dissipates nothing)

An end with cohesion ``c`` or tensile strength ``ft`` dissipates
``D = a_t dn + (a_c - mu a_t) |dt|`` with ``a_c = c A``, ``a_t = min(ft, c/mu) A``
(``A`` = half the contact area: the end's share). It gets one extra column
``s >= |dt|`` and three rows::

    s - dt >= 0,   s + dt >= 0,   dn - mu s >= 0,   cost + a_t dn + (a_c - mu a_t) s

The programme is ``min cost.x  s.t.  G x >= 0,  live.x = 1``; its optimum is the
collapse multiplier alpha, and its dual is the static (lower bound) problem:
contact forces in equilibrium with ``f0 + alpha fL``.

Everything is non-dimensional: lengths by the model scale ``L`` (bounding-box
diagonal), forces by the total dead load ``W``; the rotation column is
``rz r0 / L`` with ``r0`` a typical block size (the square root of the median
unit area), so that all columns are velocities of the same order and moments
are divided by ``W r0``. The same wall in mm and in m gives the same numbers.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import xarray as xr

import masonryfw.plugin_api as mfp

ROLE = mfp.ROLE


@dataclass(frozen=True)
class Wall:
    """The arrays of a model the programme needs, read from the dataset once."""

    role: np.ndarray  # (block,)
    fixed: np.ndarray  # (block, dof) bool
    direction: np.ndarray  # (block, dof) settlement direction
    settlement_weights: np.ndarray  # (block, dof) mfp.settlement_weights: the settlement reaction's
    dead: np.ndarray  # (block, dof)
    live: np.ndarray
    thickness: np.ndarray
    area: np.ndarray
    centroid: np.ndarray  # (block, 2)
    node_x: np.ndarray
    node_y: np.ndarray
    sides: np.ndarray  # (interface, side) int64
    end_x: np.ndarray  # (interface, end)
    end_y: np.ndarray
    normal: np.ndarray  # (interface, 2)
    tangent: np.ndarray
    length: np.ndarray
    friction: np.ndarray
    cohesion: np.ndarray
    tensile_strength: np.ndarray

    @classmethod
    def from_model(cls, model: xr.Dataset) -> Wall:
        # Variables, not DataArrays: building a DataArray for each of the 26 took 1.5 ms at 100 units
        v = {name: np.asarray(var.values) for name, var in model.variables.items()}
        return cls(
            role=v["block_role"],
            fixed=v["block_fixed"] != 0,
            direction=v["settlement_direction"].astype(float),
            settlement_weights=mfp.settlement_weights(model),
            dead=mfp.block_loads(model, "dead"),
            live=mfp.block_loads(model, "live"),
            thickness=v["block_thickness"].astype(float),
            area=v["block_area"],
            centroid=np.c_[v["block_centroid_x"], v["block_centroid_y"]],
            node_x=v["node_x"],
            node_y=v["node_y"],
            sides=v["interface_blocks"].astype(np.int64).reshape(-1, 2),
            end_x=v["interface_x"].reshape(-1, 2),
            end_y=v["interface_y"].reshape(-1, 2),
            normal=np.c_[v["interface_normal_x"], v["interface_normal_y"]],
            tangent=np.c_[v["interface_tangent_x"], v["interface_tangent_y"]],
            length=v["interface_length"],
            friction=v["interface_friction"].astype(float),
            cohesion=v["interface_cohesion"].astype(float),
            tensile_strength=v["interface_tensile_strength"].astype(float),
        )

    @property
    def n_block(self) -> int:
        return self.role.size

    @property
    def n_interface(self) -> int:
        return self.sides.shape[0]

    @property
    def support(self) -> np.ndarray:
        """Blocks that are supports (ground)."""
        return mfp.support_blocks(self.role)

    @property
    def moving(self) -> np.ndarray:
        return mfp.moving_blocks(self.role)

    @property
    def between_supports(self) -> np.ndarray:
        """Interfaces whose two sides are supports: ground against ground, not a joint."""
        return self.support[self.sides].all(axis=1)


@dataclass(frozen=True)
class Scales:
    """Reference length ``L``, block size ``r0`` [model units] and force ``W`` [N] of the programme."""

    length: float
    block: float
    force: float

    @property
    def dof(self) -> np.ndarray:
        """Physical block dofs ``(ux, uy, rz)`` per programme unit: ``(L, L, L / r0)``."""
        return np.array([self.length, self.length, self.length / self.block])


@dataclass(frozen=True)
class Kinematics:
    """Relative velocity of every interface end as a linear map of the block velocities.

    Rows are interface ends ``2 * interface + end``; columns are the block dofs
    ``3 * block + dof`` (non-dimensional). ``opening = normal @ u``, ``slip = tangent @ u``.
    """

    normal: sp.csr_matrix
    tangent: sp.csr_matrix


@dataclass(frozen=True)
class KinematicLP:
    """``min cost.x  s.t.  constraints @ x >= 0,  live.x = 1`` and its bookkeeping.

    Columns: the free block dofs, then (if there are moving supports) the one
    shared settlement parameter, then one ``s`` per cohesive end. Rows: the dry
    ends' ``dn - mu dt`` rows, their ``dn + mu dt`` rows, then the cohesive
    ends' ``s - dt``, ``s + dt``, ``dn - mu s`` rows.
    """

    cost: np.ndarray
    live: np.ndarray
    constraints: sp.csr_matrix
    column_map: sp.csr_matrix  # (3 nblock, block columns): full u = column_map @ x[:n]
    settlement_column: int | None
    dry_ends: np.ndarray  # end indices (2 * interface + end) of the dry rows
    cohesive_ends: np.ndarray
    friction: np.ndarray  # mu of every end (all interfaces)
    tension_share: np.ndarray  # a_t of every end (non-dimensional force)
    active_interfaces: np.ndarray  # bool per interface: has rows in the programme

    @property
    def n_block_columns(self) -> int:
        return self.column_map.shape[1]


def model_scales(model: xr.Dataset, wall: Wall) -> Scales:
    """The model's scales (:func:`masonryfw.plugin_api.model_scales`), the force being the total dead load
    (the live load's when there is no dead load): the dual forces are then of order one."""
    scales = mfp.model_scales(model)
    for loads in (wall.dead, wall.live):
        force = float(np.hypot(loads[:, 0], loads[:, 1]).sum())
        if force > 0:
            return Scales(scales.length, scales.block, force)
    return Scales(scales.length, scales.block, 1.0)


def nondimensional_loads(loads: np.ndarray, scales: Scales) -> np.ndarray:
    """Block loads ``(fx, fy, m)`` flattened block-major, divided by ``(W, W, W r0)``."""
    return (loads * scales.dof / (scales.length * scales.force)).ravel()


def interface_kinematics(wall: Wall, scales: Scales) -> Kinematics:
    """Sparse maps from block velocities to the normal and tangential relative velocity at every end."""
    n_interface, sides = wall.n_interface, wall.sides
    centre = wall.centroid[sides]  # (i, side, 2)
    rx = (wall.end_x[:, :, None] - centre[:, None, :, 0]) / scales.block  # (i, end, side)
    ry = (wall.end_y[:, :, None] - centre[:, None, :, 1]) / scales.block
    sign = np.array([-1.0, 1.0])  # side 1 minus side 0
    rows = np.broadcast_to(np.arange(2 * n_interface).reshape(n_interface, 2, 1, 1), (n_interface, 2, 2, 3))
    cols = np.broadcast_to(3 * sides[:, None, :, None] + np.arange(3), (n_interface, 2, 2, 3))
    shape = (2 * n_interface, 3 * wall.n_block)

    def relative(axis: np.ndarray) -> sp.csr_matrix:
        ax, ay = axis[:, 0, None, None], axis[:, 1, None, None]
        coef = np.stack(
            np.broadcast_arrays(sign * ax, sign * ay, sign * (rx * ay - ry * ax)), axis=-1
        )  # (i, end, side, dof)
        return sp.csr_matrix((coef.ravel(), (rows.ravel(), cols.ravel())), shape=shape)

    return Kinematics(relative(wall.normal), relative(wall.tangent))


def column_map(wall: Wall, scales: Scales) -> tuple[sp.csr_matrix, int | None]:
    """Map from the programme's block columns to all block dofs, and the settlement column.

    Held components (``block_fixed``) get no column. Every moving support moves
    as ``u = t * settlement_direction`` with one scalar ``t`` shared by all of
    them: one column, the last. ``t`` is non-dimensional (``t_physical / L``).
    """
    moving = wall.moving
    free_dofs = np.flatnonzero((~wall.fixed & ~moving[:, None]).ravel())
    n_free = free_dofs.size
    rows, cols, vals = [free_dofs], [np.arange(n_free)], [np.ones(n_free)]
    settlement_column = None
    if moving.any():
        direction = wall.direction[moving] * scales.length / scales.dof
        moving_dofs = 3 * np.flatnonzero(moving)[:, None] + np.arange(3)
        rows.append(moving_dofs.ravel())
        cols.append(np.full(moving_dofs.size, n_free))
        vals.append(direction.ravel())
        settlement_column = n_free
    n_col = n_free + (settlement_column is not None)
    matrix = sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(3 * wall.n_block, n_col)
    )
    matrix.eliminate_zeros()
    return matrix, settlement_column


def end_strengths(wall: Wall, scales: Scales) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per end: friction mu, cohesive share ``a_c`` and tensile share ``a_t`` (non-dimensional forces).

    The tensile strength is capped at ``c / mu``: with Coulomb's cone and a
    tension cut-off (the paper's eq. 12) no point of the joint can carry more.
    """
    half_area = 0.5 * wall.length * wall.thickness[wall.sides].min(axis=1)
    mu = wall.friction
    with np.errstate(divide="ignore"):
        cap = np.where(mu > 0, wall.cohesion / np.where(mu > 0, mu, 1.0), np.inf)
    a_c = wall.cohesion * half_area / scales.force
    a_t = np.minimum(wall.tensile_strength, cap) * half_area / scales.force
    return np.repeat(mu, 2), np.repeat(a_c, 2), np.repeat(a_t, 2)


def active_interfaces(wall: Wall, normal: sp.csr_matrix, tangent: sp.csr_matrix) -> np.ndarray:
    """Interfaces that constrain the motion: not between two supports, not between two held blocks.

    Two supports are both ground (a settling support sliding past a fixed one is
    the loading, not a joint); between two held blocks the relative motion is zero.
    ``normal``/``tangent`` are the kinematic maps already restricted to the columns.
    """
    moves = (np.diff(normal.indptr) + np.diff(tangent.indptr)).reshape(-1, 2).sum(axis=1) > 0
    return moves & ~wall.between_supports


def with_columns(matrix: sp.csr_matrix, n_col: int) -> sp.csr_matrix:
    """The same CSR matrix seen with ``n_col`` columns (extra columns empty)."""
    return sp.csr_matrix((matrix.data, matrix.indices, matrix.indptr), shape=(matrix.shape[0], n_col))


def assemble(wall: Wall, scales: Scales, kin: Kinematics, normal_force: np.ndarray | None = None) -> KinematicLP:
    """The kinematic programme of ``wall`` (see the module docstring).

    ``normal_force`` (one per end ``2 * interface + end``, non-dimensional) makes the joints
    non-associative (:mod:`.nonassociative`): every active end slides without opening
    (rows ``s - dt``, ``s + dt``, ``dn``) against a fixed shear capacity ``a_c + mu N``,
    and opens against its tensile strength as before.
    """
    cmap, settlement_column = column_map(wall, scales)
    normal = kin.normal @ cmap
    tangent = kin.tangent @ cmap
    normal.eliminate_zeros()
    tangent.eliminate_zeros()
    active = active_interfaces(wall, normal, tangent)
    mu, a_c, a_t = end_strengths(wall, scales)
    active_end = np.repeat(active, 2)
    cohesive_end = (a_c > 0) | (a_t > 0) | (normal_force is not None)
    dry = np.flatnonzero(active_end & ~cohesive_end)
    coh = np.flatnonzero(active_end & cohesive_end)

    n_col = cmap.shape[1]
    n_total = n_col + coh.size
    cost = np.zeros(n_total)
    live = np.zeros(n_total)
    cost[:n_col] = -(cmap.T @ nondimensional_loads(wall.dead, scales))
    live[:n_col] = cmap.T @ nondimensional_loads(wall.live, scales)

    normal_dry = normal[dry]
    mu_tangent_dry = tangent[dry].multiply(mu[dry][:, None]).tocsr()
    rows = [normal_dry - mu_tangent_dry, normal_dry + mu_tangent_dry]
    if coh.size:
        eye = sp.identity(coh.size, format="csr")
        dilatancy = mu[coh] if normal_force is None else np.zeros(coh.size)
        rows += [
            sp.hstack([-tangent[coh], eye]),
            sp.hstack([tangent[coh], eye]),
            sp.hstack([normal[coh], -sp.diags(dilatancy)]),
        ]
        cost[:n_col] += normal[coh].T @ a_t[coh]
        if normal_force is None:
            cost[n_col:] += a_c[coh] - mu[coh] * a_t[coh]
        else:  # the shear capacity of the normal force given (never below zero: N >= -a_t, a_t <= a_c / mu)
            cost[n_col:] += np.maximum(a_c[coh] + mu[coh] * normal_force[coh], 0.0)
    constraints = sp.vstack([with_columns(r.tocsr(), n_total) for r in rows], format="csr")
    return KinematicLP(
        cost=cost,
        live=live,
        constraints=constraints,
        column_map=cmap,
        settlement_column=settlement_column,
        dry_ends=dry,
        cohesive_ends=coh,
        friction=mu,
        tension_share=a_t,
        active_interfaces=active,
    )
