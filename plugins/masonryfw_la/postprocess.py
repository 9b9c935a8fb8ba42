"""From the programme's solution to the primary result variables: mechanism and contact forces.

The comparable fields (opening and slip at the interface ends, joint states,
crack indicator, macro-blocks) are derived from the mechanism by the core
(:mod:`masonryfw.results.semantics`), as for every solver.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .assembly import KinematicLP, Scales, Wall


@dataclass(frozen=True)
class ContactForces:
    """Normal (compression positive) and shear force of every interface end [N], shape (interface, end)."""

    normal: np.ndarray
    shear: np.ndarray


def mechanism(lp: KinematicLP, x: np.ndarray, scales: Scales) -> np.ndarray:
    """Block displacements (block, dof) in model units, normalised.

    Settlement cases: the moving supports move by a unit distance along their
    ``settlement_direction`` (``t = 1``). Otherwise the largest block translation is 1.
    """
    u = (lp.column_map @ x[: lp.n_block_columns]).reshape(-1, 3) * scales.dof
    if lp.settlement_column is not None:
        settlement = x[lp.settlement_column] * scales.length
        if settlement > 1e-9 * np.abs(u).max():
            return u / settlement
    largest = np.hypot(u[:, 0], u[:, 1]).max()
    return u / largest if largest > 0 else u


def contact_forces(lp: KinematicLP, y: np.ndarray, n_interface: int, scales: Scales) -> ContactForces:
    """End forces from the multipliers of the rows (see :mod:`.assembly` for the row order).

    Dry ends: ``N = y+ + y-``, ``T = mu (y- - y+)``. Cohesive ends: ``N = y3 - a_t``,
    ``T = y2 - y1``. Interfaces outside the programme carry nothing.
    """
    n_dry = lp.dry_ends.size
    n_coh = lp.cohesive_ends.size
    normal = np.zeros(2 * n_interface)
    shear = np.zeros(2 * n_interface)
    y_plus, y_minus = y[:n_dry], y[n_dry : 2 * n_dry]
    normal[lp.dry_ends] = y_plus + y_minus
    shear[lp.dry_ends] = lp.friction[lp.dry_ends] * (y_minus - y_plus)
    y1, y2, y3 = (y[2 * n_dry + k * n_coh : 2 * n_dry + (k + 1) * n_coh] for k in range(3))
    normal[lp.cohesive_ends] = y3 - lp.tension_share[lp.cohesive_ends]
    shear[lp.cohesive_ends] = y2 - y1
    return ContactForces(
        normal.reshape(-1, 2) * scales.force, shear.reshape(-1, 2) * scales.force
    )


def support_wrench(wall: Wall, forces: ContactForces) -> np.ndarray:
    """``(block, 3)``: the force (x, y) and moment about the centroid the contacts exert on every block
    (on side 1 of an interface the force is ``N n + T t`` at each end, on side 0 its opposite)."""
    fx = forces.normal * wall.normal[:, 0, None] + forces.shear * wall.tangent[:, 0, None]  # (interface, end)
    fy = forces.normal * wall.normal[:, 1, None] + forces.shear * wall.tangent[:, 1, None]
    n = wall.role.size
    wrench = np.zeros((n, 3))
    for side, sign in ((1, 1.0), (0, -1.0)):
        block = wall.sides[:, side]
        arm_x = wall.end_x - wall.centroid[block, 0, None]
        arm_y = wall.end_y - wall.centroid[block, 1, None]
        for d, values in enumerate((fx, fy, arm_x * fy - arm_y * fx)):
            wrench[:, d] += sign * np.bincount(block, weights=values.sum(axis=1), minlength=n)
    return wrench


def moving_support_reaction(wall: Wall, forces: ContactForces) -> float:
    """The settlement reaction at collapse [N] (``mf.settlement_reaction``: the work-conjugate of the
    settlement parameter, each support weighted by its motion; the upward reaction for one support
    translating down): ``(1 - alpha) R0`` by equilibrium of the settlement column."""
    return float((support_wrench(wall, forces) * wall.settlement_weights).sum())
