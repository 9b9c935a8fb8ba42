"""Block vectors ``(ux, uy, rz)``: the format's forces and moments, displacements and rotations.

The format stores a block's in-plane vector and its rotational part in two
variables, each with one unit (CF): ``dead_load`` (block, axis) [N] and
``dead_moment`` (block) [N m]; ``block_displacement`` (block, axis) [m] and
``block_rotation`` (block) [rad]. Solvers work with the three components of a
block together; these functions convert between the two forms.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .schema import load_schema, variable_attrs

if TYPE_CHECKING:  # annotations only
    import xarray as xr

#: Variable pairs holding one block vector: (in-plane part (block, axis), rotational part (block,)).
LOAD_VARIABLES = {"dead": ("dead_load", "dead_moment"), "live": ("live_load", "live_moment")}
MOTION_VARIABLES = ("block_displacement", "block_rotation")


def _stacked(ds: xr.Dataset, planar: str, rotational: str) -> np.ndarray:
    n = ds.sizes["block"]
    return np.concatenate([np.asarray(ds[planar].values, dtype=float).reshape(n, -1),
                           np.asarray(ds[rotational].values, dtype=float).reshape(n, -1)], axis=1)


def block_loads(ds: xr.Dataset, which: str) -> np.ndarray:
    """``(block, 3)`` = force x, force y [N], moment [N m] of the ``dead`` or ``live`` load; ``(block, 6)`` = force
    (x, y, z) and moment (x, y, z) of a 3D model's."""
    return _stacked(ds, *LOAD_VARIABLES[which])


def block_motion(ds: xr.Dataset) -> np.ndarray:
    """``(block, 3)`` = displacement x, y [m] of the centroid and rotation [rad] of a result; ``(block, 6)`` of a
    3D one."""
    return _stacked(ds, *MOTION_VARIABLES)


def load_variables(which: str, vector: np.ndarray) -> dict[str, tuple]:
    """The format variables of a ``dead``/``live`` load given as ``(block, 3)``."""
    planar, rotational = LOAD_VARIABLES[which]
    vector = np.asarray(vector, dtype=float)
    return {planar: (("block", "axis"), vector[:, :2], variable_attrs(planar)),
            rotational: (("block",), vector[:, 2], variable_attrs(rotational))}


def motion_variables(vector: np.ndarray) -> dict[str, tuple]:
    """``block_displacement`` and ``block_rotation`` of a motion given as ``(block, 3)``."""
    planar, rotational = MOTION_VARIABLES
    vector = np.asarray(vector, dtype=float)
    return {planar: (("block", "axis"), vector[:, :2], variable_attrs(planar)),
            rotational: (("block",), vector[:, 2], variable_attrs(rotational))}


#: The rotational part of a split block vector: its name from the in-plane part's.
_ROTATIONAL_NAMES = (("_displacement", "_rotation"), ("_load", "_moment"))


def _rotational_name(name: str) -> str:
    for suffix, replacement in _ROTATIONAL_NAMES:
        if name.endswith(suffix):
            return name[: -len(suffix)] + replacement
    return name + "_rz"


def _single_units(units: str) -> tuple[str, str]:
    """``"N, N, N m"`` -> ``("N", "N m")``; ``"m m rad"`` -> ``("m", "rad")`` (version-1 per-dof units)."""
    parts = [p.strip() for p in units.replace(",", " ,").split(",")] if "," in units else units.split()
    parts = [p for p in parts if p]
    return (parts[0], parts[-1]) if len(parts) == 3 else (units, units)


def upgrade(ds: xr.Dataset) -> xr.Dataset:
    """A dataset of format version 1 in the current version (2); any other dataset unchanged.

    Version 1 stored block vectors with one ``dof`` dimension and per-component
    units (``dead_load`` (block, dof) in "N, N, N m"), which CF cannot express.
    Every such variable is split into its in-plane part (``..., axis``) and its
    rotational part (``dead_load`` -> ``dead_moment``, ``block_displacement`` ->
    ``block_rotation``, other names + ``_rz``). Nothing else changed.
    """
    version = ds.attrs.get("masonryfw_format_version")
    try:
        is_one = int(np.asarray(version).item()) == 1
    except (TypeError, ValueError):
        return ds
    if not is_one:
        return ds
    split = [str(name) for name, var in ds.data_vars.items()
             if var.dims[-1:] == ("dof",) and name not in ("block_fixed", "settlement_direction")]
    replaced = {}
    for name in split:
        var = ds[name]
        planar_units, rotational_units = _single_units(str(var.attrs.get("units", "")))
        planar = var.isel(dof=slice(0, 2)).rename(dof="axis").drop_vars("dof", errors="ignore")
        rotational = var.isel(dof=2).drop_vars("dof", errors="ignore")
        planar.attrs = {**var.attrs, "units": planar_units}
        rotational.attrs = {**var.attrs, "units": rotational_units}
        for source in (planar, rotational):
            source.encoding = {}
        for new_name, part in ((name, planar), (_rotational_name(name), rotational)):
            if new_name in load_schema("result")["variables"]:
                part.attrs = variable_attrs(new_name)
            replaced[new_name] = part.variable
    out = ds.drop_vars(split).assign(replaced)
    out.attrs = {**ds.attrs, "masonryfw_format_version": 2}
    out.encoding = dict(ds.encoding)
    return out
