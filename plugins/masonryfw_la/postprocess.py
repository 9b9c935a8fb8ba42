"""From the programme's solution to the FORMAT.md result variables.

Interface states (with associative flow a slip always comes with a dilatant
opening ``>= mu |slip|``, so "slide" cannot mean "slip without opening"):

- ``intact``: no end moves (``|(opening, slip)|``) more than ``threshold`` times the
  largest joint motion;
- ``open``: the joint moves but its slip is below the threshold (hinging or separation);
- ``slide``: the slip is above the threshold and the opening is no more than the
  dilatancy of that slip (``opening <= mu |slip| + threshold`` at both ends);
- ``open_slide``: the slip is above the threshold and one end opens more than the
  dilatancy alone would (sliding combined with rocking or separation).

``crack_indicator`` = largest end motion ``|(opening, slip)|`` of the joint over
the largest of all masonry joints, set to 0 below the threshold. Joints between
two supports (ground next to ground) are not masonry joints: indicator 0.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import masonryfw as mf

from .assembly import Kinematics, KinematicLP, Scales, Wall
from .topology import components

STATE = mf.flags("interface_state")


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


def relative_motion(kin: Kinematics, u: np.ndarray, scales: Scales) -> tuple[np.ndarray, np.ndarray]:
    """Opening and slip (interface, end) of the mechanism ``u`` (model units)."""
    u_nd = (u / scales.dof).ravel()
    opening = (kin.normal @ u_nd).reshape(-1, 2) * scales.length
    slip = (kin.tangent @ u_nd).reshape(-1, 2) * scales.length
    return opening, slip


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


def joint_motion(opening: np.ndarray, slip: np.ndarray) -> np.ndarray:
    """Largest end motion ``|(opening, slip)|`` of every interface."""
    return np.hypot(opening, slip).max(axis=1)


def masonry_joints(wall: Wall) -> np.ndarray:
    """Interfaces with at least one side that is not a support."""
    return ~wall.between_supports


def interface_states(
    opening: np.ndarray, slip: np.ndarray, friction: np.ndarray, threshold: float
) -> np.ndarray:
    """int8 state of every interface (see the module docstring); ``threshold`` in model units."""
    moves = joint_motion(opening, slip) > threshold
    slips = np.abs(slip).max(axis=1) > threshold
    extra_opening = (opening - friction[:, None] * np.abs(slip)).max(axis=1) > threshold
    state = np.full(opening.shape[0], STATE["intact"], dtype=np.int8)
    state[moves & ~slips] = STATE["open"]
    state[moves & slips & ~extra_opening] = STATE["slide"]
    state[moves & slips & extra_opening] = STATE["open_slide"]
    return state


def crack_indicator(motion: np.ndarray, masonry: np.ndarray, relative_threshold: float) -> np.ndarray:
    """Joint motion over the largest masonry-joint motion, 0 below the threshold and on non-masonry joints."""
    largest = motion[masonry].max(initial=0.0)
    if largest <= 0:
        return np.zeros_like(motion)
    indicator = np.where(masonry, motion / largest, 0.0)
    return np.where(indicator > relative_threshold, np.minimum(indicator, 1.0), 0.0)


def macro_blocks(n_block: int, interface_blocks: np.ndarray, state: np.ndarray) -> np.ndarray:
    """Label of the rigid macro-block of every block: connected through intact interfaces."""
    intact = interface_blocks[state == STATE["intact"]]
    return components(n_block, intact)


def moving_support_reaction(wall: Wall, forces: ContactForces) -> float:
    """Upward vertical force the ground must give the moving supports at collapse [N].

    Minus the vertical component of the contact forces the wall exerts on them
    (on side 1 the force is ``N n + T t``, on side 0 its opposite).
    """
    moving = wall.moving[wall.sides].astype(float)  # (interface, side)
    on_side1_y = forces.normal.sum(axis=1) * wall.normal[:, 1] + forces.shear.sum(axis=1) * wall.tangent[:, 1]
    return float(-(on_side1_y * (moving[:, 1] - moving[:, 0])).sum())
