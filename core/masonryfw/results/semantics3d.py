"""What a 3D result means: the 2D definitions (:mod:`masonryfw.results.semantics`) at the vertices of planar interfaces.

The relative motion of side 1 against side 0 at every interface vertex: its opening along the interface's
normal and its slip, the length of its tangential part (a direction in the interface's plane has no sign to
keep). An interface's joint motion is the largest ``|(max(opening, 0), slip)|`` of its vertices; states, the
crack indicator and the macro-blocks follow from them exactly as in 2D (the same functions, on the vertices
laid out interface by interface, padded with zeros, which change no maximum the definitions take).
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ..format.model3d import interface_points
from ..format.roles import masonry_joints
from ..format.schema import variable_attrs
from ..runtime.errors import SolveError
from .semantics import (
    CRACK_THRESHOLD,
    crack_indicator,
    dilatancy,
    indicator_attrs,
    intact_threshold,
    interface_states,
    joint_motion,
    macro_blocks,
)


def vertex_motion(model: xr.Dataset, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Opening and slip ``(interface_node,)`` of block motions ``u`` ``(block, 6)`` (side 1 minus side 0), by the
    linearised rigid motion ``u_c + r x (p - c)`` (a mechanism)."""
    count = model.interface_node_count.values.astype(np.int64)
    points = interface_points(model)
    normal = np.c_[model.interface_normal_x.values, model.interface_normal_y.values, model.interface_normal_z.values]
    owner = np.repeat(np.arange(count.size), count)
    sides = model.interface_blocks.values.astype(np.int64)[owner]
    centroid = np.c_[model.block_centroid_x.values, model.block_centroid_y.values, model.block_centroid_z.values]
    u = np.asarray(u, dtype=float)
    moved = [u[sides[:, k], :3] + np.cross(u[sides[:, k], 3:], points - centroid[sides[:, k]]) for k in (0, 1)]
    relative = moved[1] - moved[0]
    n = normal[owner]
    opening = np.einsum("pd,pd->p", relative, n)
    slip = np.linalg.norm(relative - opening[:, None] * n, axis=1)
    return opening, slip


def padded(values: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Ragged per-vertex values ``(interface_node,)`` as ``(interface, most vertices)``, zeros after each."""
    out = np.zeros((count.size, int(count.max(initial=0))))
    rows = np.repeat(np.arange(count.size), count)
    cols = np.arange(values.size) - np.repeat(np.cumsum(count) - count, count)
    out[rows, cols] = values
    return out


def derived_variables_3d(model: xr.Dataset, u: np.ndarray, rotations: str, flow_rule: str,
                         share: float = CRACK_THRESHOLD) -> dict[str, tuple]:
    """The comparable result variables of block motions ``u`` (block, 6) on a 3D ``model`` (derived geometry): a
    mechanism's (``rotations = "small"``; finite rotations in 3D are refused until a solver returns them)."""
    if rotations != "small":
        raise SolveError(f"rotations = {rotations!r} in 3D: the comparable fields of finite 3D motions are not "
                         "derived yet (a mechanism's, rotations = 'small', are)")
    opening, slip = vertex_motion(model, u)
    count = model.interface_node_count.values.astype(np.int64)
    opening_2d, slip_2d = padded(opening, count), padded(slip, count)
    motion = joint_motion(opening_2d, slip_2d)
    masonry = masonry_joints(model.block_role.values, model.interface_blocks.values)
    state = interface_states(opening_2d, slip_2d, dilatancy(model, flow_rule),
                             intact_threshold(motion, masonry, share))
    labels = macro_blocks(model.sizes["block"], model.interface_blocks.values, state)
    return {
        "interface_opening": (("interface_node",), opening, variable_attrs("interface_opening", "result3d")),
        "interface_slip": (("interface_node",), slip, variable_attrs("interface_slip", "result3d")),
        "interface_state": (("interface",), state, variable_attrs("interface_state", "result3d")),
        "crack_indicator": (("interface",), crack_indicator(motion, masonry, share), indicator_attrs(share)),
        "macro_block": (("block",), labels.astype(np.int32), variable_attrs("macro_block", "result3d")),
    }
