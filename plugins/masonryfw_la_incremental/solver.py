"""The ``la-incremental`` solve function: options -> reference configuration -> increments -> history.

The core derives the comparable fields from the last configuration's block motions
(``rotations = "finite"``; ``flow_rule`` the option ``flow``'s).
"""
from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import xarray as xr

import masonryfw.plugin_api as mfp

from . import history, stepping
from .configuration import reference

#: Without a target, a run follows the wall to this share of its height.
DEFAULT_TARGET_SHARE = 0.1


def default_target(model: xr.Dataset) -> float:
    if "settlement_target" in model:
        return float(model.settlement_target)
    masonry = mfp.masonry_blocks(model.block_role.values)
    _, _, ymin, ymax = mfp.block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    return DEFAULT_TARGET_SHARE * float(ymax[masonry].max() - ymin[masonry].min())


def solve(model: xr.Dataset, options: Mapping[str, Any], progress=mfp.no_progress) -> xr.Dataset:
    """Follow ``model`` from its configuration to collapse or to the target (module docstring)."""
    clock = time.perf_counter()
    ref = reference(model, options["gap"])
    target = options["settlement"] or default_target(model)
    controls = stepping.Controls(
        target=target,
        step=options["step"] * ref.unit_height,
        max_increments=options["increments"],
        solver=options["solver"],
        record_spacing=target / options["records"] if options["records"] else 0.0,
        tolerance=options["tolerance"],
        flow=options["flow"],
    )
    records = history.History(model, ref)
    outcome = stepping.run(ref, controls, records, progress)
    result = history.result_dataset(records, outcome, stepping.settlement_driven(ref), options["flow"])
    result.attrs.update(
        la_incremental_increments=len(records.rows) - 1,
        la_incremental_target=controls.target,
        la_incremental_step_m=controls.step,
        la_incremental_gap_m=ref.gap,
        la_incremental_time_per_increment_s=(time.perf_counter() - clock) / max(len(records.rows), 1),
    )
    if not outcome.interrupted:
        progress(1.0, f"la-incremental: {outcome.reason}")
    return result
