"""The ``statics`` solver: load resultants and support dead reactions (imported when it runs)."""
from __future__ import annotations

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp


def load_resultant(load: np.ndarray, cx: np.ndarray, cy: np.ndarray) -> tuple[np.ndarray, float]:
    """Resultant force ``(Fx, Fy)`` and moment about the origin of loads ``(nblock, 3)`` at the centroids."""
    fx, fy, mz = load.T
    return np.array([fx.sum(), fy.sum()]), float((mz + cx * fy - cy * fx).sum())


def solve_statics(model: xr.Dataset, options, progress) -> xr.Dataset:
    """Load resultants, and the dead reaction of every support under the settlement convention.

    The masonry weight W (minus the dead vertical load on units and lintels) is
    shared by the supports in proportion to their contact length with the wall:
    ``R_s = W * L_s / L_total`` (docs/format.md, settlement loading).
    """
    is_support = mfp.support_blocks(model.block_role.values)
    dead, live = mfp.block_loads(model, "dead"), mfp.block_loads(model, "live")
    cx, cy = model.block_centroid_x.values, model.block_centroid_y.values
    progress(0.0, "load resultants")
    weight = -dead[~is_support, 1].sum()
    pairs = model.interface_blocks.values
    wall_on_support = is_support[pairs[:, 0]] != is_support[pairs[:, 1]]
    support_side = np.where(is_support[pairs[:, 0]], pairs[:, 0], pairs[:, 1])[wall_on_support]
    contact = np.bincount(
        support_side, weights=model.interface_length.values[wall_on_support], minlength=is_support.size
    )
    if contact.sum() <= 0:
        raise mf.SolveError("statics: no wall block rests on a support block")
    progress(1.0, "done")
    variables = {
        "support_dead_reaction": ("block", weight * contact / contact.sum(), {
            "units": "N", "long_name": "upward dead reaction of each support, W * L_s / L_total (0 off supports)"}),
        "masonry_weight": ((), weight, {"units": "N", "long_name": "weight W of the units and lintels"}),
    }
    for which, load in (("dead", dead), ("live", live)):
        force, moment = load_resultant(load, cx, cy)
        variables[f"total_{which}_force"] = ("axis", force, {
            "units": "N", "long_name": f"resultant force (x, y) of the {which} loads"})
        variables[f"total_{which}_moment"] = ((), moment, {
            "units": "N m", "long_name": f"resultant moment of the {which} loads about the origin"})
    return xr.Dataset(variables)
