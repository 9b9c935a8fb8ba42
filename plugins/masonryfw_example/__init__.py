"""Example plugin ``statics``: load resultants and support reactions. A template to copy.

A plugin is a module with ``@hookimpl`` functions returning records, registered
in its distribution's ``pyproject.toml``::

    [project.entry-points.masonryfw]
    example = "masonryfw_example"

The solve function gets a checked model with derived geometry and resolved
options, and returns a dataset holding only the variables it computed.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

import masonryfw as mf


def load_resultant(load: np.ndarray, cx: np.ndarray, cy: np.ndarray) -> np.ndarray:
    """Resultant ``(Fx, Fy, Mz about the origin)`` of loads ``(nblock, 3)`` applied at the centroids."""
    fx, fy, mz = load.T
    return np.array([fx.sum(), fy.sum(), (mz + cx * fy - cy * fx).sum()])


def solve_statics(model: xr.Dataset, options, progress) -> xr.Dataset:
    """Load resultants, and the dead reaction of every support under the settlement convention.

    The masonry weight W (minus the dead vertical load on units and lintels) is
    shared by the supports in proportion to their contact length with the wall:
    ``R_s = W * L_s / L_total`` (FORMAT.md, settlement loading).
    """
    roles = mf.flags("block_role")
    is_support = np.isin(model.block_role.values, [roles["fixed_support"], roles["moving_support"]])
    dead, live = model.dead_load.values, model.live_load.values
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
    return xr.Dataset(
        {
            "support_dead_reaction": ("block", weight * contact / contact.sum(), {
                "units": "N", "long_name": "upward dead reaction of each support, W * L_s / L_total (0 off supports)"}),
            "masonry_weight": ((), weight, {"units": "N", "long_name": "weight W of the units and lintels"}),
            "total_dead_load": ("dof", load_resultant(dead, cx, cy), {
                "units": "N, N, N m", "long_name": "resultant of the dead loads, moment about the origin"}),
            "total_live_load": ("dof", load_resultant(live, cx, cy), {
                "units": "N, N, N m", "long_name": "resultant of the live loads, moment about the origin"}),
        }
    )


@mf.hookimpl
def masonryfw_solvers():
    """The records this plugin contributes (called once per lookup)."""
    summary = "load resultants and support dead reactions (no failure analysis)"
    return [mf.Solver("statics", summary, solve_statics, "1.0")]
