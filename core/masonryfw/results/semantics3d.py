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


def rotation_matrices(rotation: np.ndarray) -> np.ndarray:
    """``(k, 3, 3)``: the rotations of the rotation vectors ``(k, 3)`` (axis times angle; Rodrigues' formula)."""
    rotation = np.asarray(rotation, dtype=float).reshape(-1, 3)
    angle = np.linalg.norm(rotation, axis=1)
    axis = rotation / np.where(angle > 0, angle, 1.0)[:, None]
    cross = np.zeros((rotation.shape[0], 3, 3))
    cross[:, 0, 1], cross[:, 0, 2], cross[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
    cross -= cross.transpose(0, 2, 1)
    sin, cos = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + sin * cross + (1.0 - cos) * cross @ cross


def vertex_motion(model: xr.Dataset, u: np.ndarray, rotations: str = "small") -> tuple[np.ndarray, np.ndarray]:
    """Opening and slip ``(interface_node,)`` of block motions ``u`` ``(block, 6)`` (side 1 minus side 0): by the
    linearised rigid motion ``u_c + r x (p - c)`` of a mechanism (``rotations = "small"``), or by the finite one
    ``u_c + (R(r) - I)(p - c)`` of a displacement whose rotation vector is ``r`` (``"finite"``); measured along
    the interface's normal and in its plane as the model has them."""
    count = model.interface_node_count.values.astype(np.int64)
    points = interface_points(model)
    normal = np.c_[model.interface_normal_x.values, model.interface_normal_y.values, model.interface_normal_z.values]
    owner = np.repeat(np.arange(count.size), count)
    sides = model.interface_blocks.values.astype(np.int64)[owner]
    centroid = np.c_[model.block_centroid_x.values, model.block_centroid_y.values, model.block_centroid_z.values]
    relative = carried_motion(u, centroid, points, sides[:, 1], rotations) - \
        carried_motion(u, centroid, points, sides[:, 0], rotations)
    n = normal[owner]
    opening = np.einsum("pd,pd->p", relative, n)
    slip = np.linalg.norm(relative - opening[:, None] * n, axis=1)
    return opening, slip


def carried_motion(u: np.ndarray, centroid: np.ndarray, points: np.ndarray, owner: np.ndarray,
                   rotations: str = "small") -> np.ndarray:
    """``(point, 3)``: the motion of ``points`` carried rigidly by their blocks ``owner`` under block motions ``u``
    ``(block, 6)`` about the blocks' ``centroid`` ``(block, 3)``: ``u_c + r x (p - c)`` of a mechanism
    (``rotations = "small"``), ``u_c + (R(r) - I)(p - c)`` of a displacement whose rotation vector is r
    (``"finite"``)."""
    u = np.asarray(u, dtype=float)
    arm = points - centroid[owner]
    if rotations == "finite":
        return u[owner, :3] + np.einsum("pij,pj->pi", rotation_matrices(u[:, 3:])[owner], arm) - arm
    return u[owner, :3] + np.cross(u[owner, 3:], arm)


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
    mechanism's (``rotations = "small"``) or a displacement's (``"finite"``, the rotation a rotation vector)."""
    if rotations not in ("small", "finite"):
        raise SolveError(f"rotations = {rotations!r}: must be 'small' or 'finite'")
    opening, slip = vertex_motion(model, u, rotations)
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
