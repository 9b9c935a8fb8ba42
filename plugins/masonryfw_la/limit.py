"""One limit state of a wall given as arrays: what ``la`` solves once and ``la-incremental`` at every increment.

The public face of the method for other plugins (``from masonryfw_la import Wall, limit_state``): a
:class:`~.assembly.Wall` may describe any configuration of rigid blocks, the model's or one moved by
finite motions with its contacts found again (a point contact is an interface whose two ends coincide).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import masonryfw as mf

from . import assembly, backends, postprocess


@dataclass(frozen=True)
class LimitState:
    """The associative collapse state of one configuration, in model units (docs/la.md)."""

    alpha: float
    motion: np.ndarray  # (block, 3) mechanism: per unit settlement t, else largest translation 1
    normal: np.ndarray  # (interface, end) [N], compression positive
    shear: np.ndarray  # (interface, end) [N]
    reaction: float | None  # the settlement reaction at collapse [N], None without moving supports
    lp: assembly.KinematicLP
    solution: backends.LPSolution


def check_live_load(lp: assembly.KinematicLP) -> None:
    """A live load that no admissible motion can do work on leaves alpha undefined."""
    if not np.any(np.abs(lp.live) > 1e-12 * max(1.0, np.abs(lp.cost).max(initial=0.0))):
        raise mf.SolveError(
            "no live load: the multiplier is undefined (live_load is zero on every component "
            "of motion that is not held)"
        )


def wall_scales(model, wall: assembly.Wall) -> assembly.Scales:
    """The programme's scales of ``model`` (kept through every moved configuration of a wall)."""
    return assembly.model_scales(model, wall)


def limit_state(wall: assembly.Wall, scales: assembly.Scales, solver: str = "ipm",
                tolerance: float = 1e-9, normal_force: np.ndarray | None = None) -> LimitState:
    """Alpha, mechanism and contact forces of ``wall``: associative joints, or with ``normal_force`` [N]
    ``(interface, end)`` joints that slide without opening against the shear capacity of those forces
    (one LP of the non-associative sequence, docs/la.md).

    Raises :class:`~.backends.LiveLoadUnbounded` when no mechanism lets the live load work and
    :class:`~.backends.DeadLoadNotCarried` when the dead load alone is not carried.
    """
    given = None if normal_force is None else np.ravel(normal_force) / scales.force
    lp = assembly.assemble(wall, scales, assembly.interface_kinematics(wall, scales), normal_force=given)
    check_live_load(lp)
    if lp.constraints.shape[0] == 0 and np.any(lp.cost != 0):  # no contact holds a block its weight moves
        raise backends.DeadLoadNotCarried(backends.DEAD_LOAD_MESSAGE)
    sol = backends.solve_lp(solver, lp.cost, lp.constraints, lp.live, tolerance)
    return state_of(wall, lp, sol, scales)


def state_of(wall: assembly.Wall, lp: assembly.KinematicLP, sol: backends.LPSolution,
             scales: assembly.Scales) -> LimitState:
    """The limit state a solved programme describes."""
    forces = postprocess.contact_forces(lp, sol.y, wall.n_interface, scales)
    reaction = postprocess.moving_support_reaction(wall, forces) if lp.settlement_column is not None else None
    return LimitState(float(sol.alpha_primal), postprocess.mechanism(lp, sol.x, scales), forces.normal,
                      forces.shear, reaction, lp, sol)


#: A falling motion does at least this share of the most work the dead load could do in the bounds (less is
#: round-off of a motion that carries it).
FALLING_WORK_TOLERANCE = 1e-9


def falling_motion(wall: assembly.Wall, scales: assembly.Scales) -> np.ndarray:
    """``(block, 3)``: how a configuration that cannot carry its dead load falls, with the supports held.

    The admissible motion (associative joints, no live load working, every component of the block
    columns within one unit) in which the dead load does the most work, by HiGHS; zero when the dead
    load is carried. Its scale is arbitrary: the direction is what a caller follows.
    """
    from scipy.optimize import linprog  # slow to import: only a configuration that falls needs it

    if wall.n_interface == 0:  # nothing touches anything: every free block falls along its dead load
        free = ~(wall.support | wall.fixed.all(axis=1))
        return np.where(free[:, None], np.c_[wall.dead[:, :2], np.zeros(wall.n_block)], 0.0)
    lp = assembly.assemble(wall, scales, assembly.interface_kinematics(wall, scales))
    n = lp.cost.size
    bounds = np.full((n, 2), [-1.0, 1.0])
    if lp.settlement_column is not None:
        bounds[lp.settlement_column] = 0.0
    res = linprog(lp.cost, A_ub=-lp.constraints, b_ub=np.zeros(lp.constraints.shape[0]),
                  A_eq=np.atleast_2d(lp.live), b_eq=np.zeros(1), bounds=bounds, method="highs")
    if res.status != 0 or not res.fun < -FALLING_WORK_TOLERANCE * np.abs(lp.cost).sum():
        return np.zeros((wall.n_block, 3))
    return (lp.column_map @ res.x[: lp.n_block_columns]).reshape(-1, 3) * scales.dof
