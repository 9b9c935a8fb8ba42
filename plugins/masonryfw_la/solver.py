"""The ``la`` solve function: assembly -> linear programme -> result variables."""
from __future__ import annotations

import time
from typing import Any, Mapping

import numpy as np
import xarray as xr

import masonryfw as mf

from . import assembly, backends, postprocess, topology

DEFAULT_BACKEND = "ipm"
DEFAULT_TOLERANCE = 1e-9
DEFAULT_CRACK_THRESHOLD = 1e-4

OPTIONS = (
    mf.Option(
        "solver",
        str,
        DEFAULT_BACKEND,
        "LP backend: ipm (our interior point on the normal equations with CHOLMOD; fastest from "
        "~300 blocks, 2.2x Clarabel at 1,000 units, 3.5x at 10,000; tied mechanisms come out as their mean; "
        "infeasible problems go to clarabel), clarabel (conic interior point, fastest below ~300 "
        "blocks), highs (dual simplex, exact vertex; slow beyond a few hundred blocks), osqp "
        "(ADMM with proximal regularisation; slow, a cross-check)",
        backends.BACKENDS,
    ),
    mf.Option("tolerance", float, DEFAULT_TOLERANCE, "feasibility / optimality tolerance of the backend"),
    mf.Option(
        "crack_threshold",
        float,
        DEFAULT_CRACK_THRESHOLD,
        "a joint moving less than this fraction of the largest joint motion counts as intact",
    ),
)


def check_inputs(wall: assembly.Wall) -> None:
    """Problems the programme cannot express, each naming the block / interface."""
    moving = np.flatnonzero(wall.moving)
    direction = wall.direction[moving]
    still = moving[~np.any(direction != 0, axis=1)]
    if still.size:
        raise mf.ModelError(
            f"moving support block(s) {topology.name_blocks(still)}: settlement_direction is zero"
        )
    clash = moving[np.any(wall.fixed[moving] & (direction != 0), axis=1)]
    if clash.size:
        raise mf.ModelError(
            f"moving support block(s) {topology.name_blocks(clash)}: settlement_direction moves a "
            "component that block_fixed holds"
        )
    bad = np.flatnonzero(~np.isfinite(wall.normal).all(axis=1) | ~(wall.length > 0))
    if bad.size:
        raise mf.ModelError(
            f"interface(s) {topology.name_blocks(bad)}: zero length or invalid blocks (no normal)"
        )
    topology.check_supported(wall)


def check_live_load(lp: assembly.KinematicLP) -> None:
    """A live load that no admissible motion can do work on leaves alpha undefined."""
    if not np.any(np.abs(lp.live) > 1e-12 * max(1.0, np.abs(lp.cost).max(initial=0.0))):
        raise mf.SolveError(
            "no live load: the multiplier is undefined (live_load is zero on every component "
            "of motion that is not held)"
        )


def check_options(options: Mapping[str, Any]) -> None:
    """Raise PluginError naming an option out of range (the types and choices are checked by the core)."""
    if not 0 < options["tolerance"] < 1:
        raise mf.PluginError(f"solver 'la': option 'tolerance' must be in (0, 1), got {options['tolerance']}")
    if not 0 <= options["crack_threshold"] < 1:
        raise mf.PluginError(
            f"solver 'la': option 'crack_threshold' must be in [0, 1), got {options['crack_threshold']}"
        )


def solve(model: xr.Dataset, options: Mapping[str, Any], progress=mf.no_progress) -> xr.Dataset:
    """Collapse multiplier, mechanism, contact forces and crack pattern of ``model``."""
    options = {o.name: o.default for o in OPTIONS} | dict(options)
    check_options(options)
    clock = time.perf_counter()
    progress(0.0, "la: assembling the kinematic programme")
    wall = assembly.Wall.from_model(model)
    check_inputs(wall)
    scales = assembly.model_scales(wall)
    kin = assembly.interface_kinematics(wall, scales)
    lp = assembly.assemble(wall, scales, kin)
    check_live_load(lp)
    t_assembly = time.perf_counter() - clock

    rows, cols = lp.constraints.shape
    progress(0.2, f"la: solving the LP with {options['solver']} ({rows} rows, {cols} columns)")
    clock = time.perf_counter()
    sol = backends.solve_lp(options["solver"], lp.cost, lp.constraints, lp.live, options["tolerance"])
    t_lp = time.perf_counter() - clock

    progress(0.9, "la: post-processing")
    clock = time.perf_counter()
    result = result_dataset(wall, lp, kin, sol, scales, options)
    t_post = time.perf_counter() - clock
    result.attrs.update(
        la_backend=options["solver"],
        la_time_assembly_s=t_assembly,
        la_time_lp_s=t_lp,
        la_time_postprocess_s=t_post,
        la_lp_rows=int(rows),
        la_lp_columns=int(cols),
        la_interfaces_outside_lp=int((~lp.active_interfaces).sum()),
    )
    progress(1.0, f"la: alpha = {sol.alpha_primal:.6g}")
    return result


def result_dataset(
    wall: assembly.Wall,
    lp: assembly.KinematicLP,
    kin: assembly.Kinematics,
    sol: backends.LPSolution,
    scales: assembly.Scales,
    options: Mapping[str, Any],
) -> xr.Dataset:
    """The FORMAT.md result variables of one solved programme."""
    u = postprocess.mechanism(lp, sol.x, scales)
    opening, slip = postprocess.relative_motion(kin, u, scales)
    forces = postprocess.contact_forces(lp, sol.y, wall.n_interface, scales)
    motion = postprocess.joint_motion(opening, slip)
    masonry = postprocess.masonry_joints(wall)
    threshold = options["crack_threshold"] * motion[masonry].max(initial=0.0)
    state = postprocess.interface_states(opening, slip, wall.friction, threshold)
    crack = postprocess.crack_indicator(motion, masonry, options["crack_threshold"])
    macro = postprocess.macro_blocks(wall.n_block, wall.sides, state)

    ie = ("interface", "end")
    data = {
        "collapse_multiplier": ((), sol.alpha_primal, mf.variable_attrs("collapse_multiplier")),
        "block_displacement": (("block", "dof"), u, mf.variable_attrs("block_displacement")),
        "interface_opening": (ie, opening, mf.variable_attrs("interface_opening")),
        "interface_slip": (ie, slip, mf.variable_attrs("interface_slip")),
        "interface_normal_force": (ie, forces.normal, mf.variable_attrs("interface_normal_force")),
        "interface_shear_force": (ie, forces.shear, mf.variable_attrs("interface_shear_force")),
        "interface_state": ("interface", state, mf.variable_attrs("interface_state")),
        "crack_indicator": ("interface", crack, mf.variable_attrs("crack_indicator")),
        "macro_block": ("block", macro.astype(np.int32), mf.variable_attrs("macro_block")),
        "lp_status": ((), sol.status, {"long_name": "status of the linear programme", "units": "1"}),
        "lp_iterations": (
            (),
            np.int64(sol.iterations),
            {"long_name": "iterations of the LP backend", "units": "1"},
        ),
    }
    if lp.settlement_column is not None:
        data["moving_support_reaction"] = (
            (),
            postprocess.moving_support_reaction(wall, forces),
            {
                "long_name": "upward vertical reaction on the moving supports at collapse (dual forces)",
                "units": "N",
            },
        )
    result = xr.Dataset(data)
    result.attrs.update(
        la_alpha_dual=float(sol.alpha_dual),
        la_crack_threshold=float(options["crack_threshold"]),
        la_motion_threshold=float(threshold),
        la_macro_blocks=int(macro.max(initial=-1) + 1),
        la_masonry_macro_blocks=int(np.unique(macro[~wall.support]).size),
    )
    return result
