"""The ``la`` solve function: assembly -> linear programme -> primary result variables.

The core derives the comparable fields (relative motion, joint states, crack
indicator, macro-blocks) from the mechanism: ``rotations = "small"`` (a
velocity field) and ``flow_rule`` ``associative`` (dilatant joints) or
``nonassociative`` (option ``flow``: :mod:`.nonassociative`).
"""
from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

import masonryfw.plugin_api as mfp

from . import assembly, backends, limit, nonassociative, topology
from .options import DEFAULT_BACKEND


def solve(model: xr.Dataset, options: Mapping[str, Any], progress=mfp.no_progress) -> xr.Dataset:
    """Collapse multiplier, mechanism and contact forces of ``model`` (checked, options resolved by the core)."""
    if mfp.space(model) == 3:
        from . import limit3d

        return limit3d.solve(model, options, progress)
    backend = options["solver"] or DEFAULT_BACKEND
    clock = time.perf_counter()
    progress(0.0, "la: assembling the kinematic programme")
    wall = assembly.Wall.from_model(model)
    topology.check_supported(wall)
    scales = assembly.model_scales(model, wall)
    kin = assembly.interface_kinematics(wall, scales)
    lp = assembly.assemble(wall, scales, kin)
    limit.check_live_load(lp)
    t_assembly = time.perf_counter() - clock

    rows, cols = lp.constraints.shape
    progress(0.2, f"la: solving the LP with {backend} ({rows} rows, {cols} columns)")
    clock = time.perf_counter()
    flow = None
    if options["flow"] == "nonassociative":
        shown = nonassociative.halves(progress, options["flow_starts"])
        flow = nonassociative.solve(wall, scales, kin, options, shown[0])
        lp, sol = flow.lp, flow.solution
    else:
        sol = backends.solve_lp(backend, lp.cost, lp.constraints, lp.live, options["tolerance"])
    t_lp = time.perf_counter() - clock

    progress(0.9, "la: post-processing")
    clock = time.perf_counter()
    result = result_dataset(limit.state_of(wall, lp, sol, scales), "associative" if flow is None else "nonassociative")
    if flow is not None:
        result.attrs.update(
            la_flow_iterations=len(flow.alphas),
            la_flow_converged=int(flow.converged),
            la_flow_last_change=flow.change,
            la_alpha_associative=flow.alpha_associative,
            la_flow_selection="the first fixed point of the sequence of LPs started from the associative solution's "
                              "normal forces; each LP's contact forces with the least squared normal forces, "
                              + (f"by the LP regularised with weight {flow.selection_weight:g} (ipm), then the "
                                 f"exact finish by LP + QP{'' if flow.finish == 'exact' else ': ' + flow.finish}"
                                 if backend == "ipm" else f"by a QP after the {backend} LP")
                              + " (docs/la.md)",
        )
        if not flow.converged:
            result.attrs["stop_reason"] = flow.stop_reason
        if options["flow_starts"] == 2:
            progress(0.55, "la: the non-associative sequence again, from zero normal forces")
            again = nonassociative.solve(wall, scales, kin, options, shown[1], from_zero=True)
            result.attrs.update(nonassociative.second_start(float(sol.alpha_primal), flow.converged,
                                                            float(again.solution.alpha_primal), again.converged,
                                                            options["flow_tolerance"]))
    result.attrs.update(
        method=backend,
        la_backend=backend,
        la_time_assembly_s=t_assembly,
        la_time_lp_s=t_lp,
        la_time_postprocess_s=time.perf_counter() - clock,
        la_lp_rows=int(rows),
        la_lp_columns=int(cols),
        la_interfaces_outside_lp=int((~lp.active_interfaces).sum()),
    )
    unconverged = "" if flow is None or flow.converged else " (NOT CONVERGED: the last iterate)"
    progress(1.0, f"la: alpha = {sol.alpha_primal:.6g}{unconverged}")
    return result


def result_dataset(state: limit.LimitState, flow_rule: str = "associative") -> xr.Dataset:
    """The primary result variables of one solved programme (docs/format.md)."""
    ie = ("interface", "end")
    sol = state.solution
    data = {
        "collapse_multiplier": ((), sol.alpha_primal, mfp.variable_attrs("collapse_multiplier")),
        **mfp.motion_variables(state.motion),
        "interface_normal_force": (ie, state.normal, mfp.variable_attrs("interface_normal_force")),
        "interface_shear_force": (ie, state.shear, mfp.variable_attrs("interface_shear_force")),
        "lp_status": ((), sol.status, {"long_name": "status of the linear programme", "units": "1"}),
        "lp_iterations": ((), np.int64(sol.iterations), {"long_name": "iterations of the LP backend", "units": "1"}),
    }
    if state.reaction is not None:
        data["moving_support_reaction"] = ((), state.reaction, mfp.variable_attrs("moving_support_reaction"))
    return xr.Dataset(data, attrs={"la_alpha_dual": float(sol.alpha_dual), "rotations": "small",
                                   "flow_rule": flow_rule})
