"""From the final block positions and contact forces to the FORMAT.md result variables.

Joint motion comes from rigid kinematics: at each end point of a model
interface, the displacement of side 1 minus that of side 0 (finite rotations),
projected on the interface's normal (opening, >= 0 opens) and tangent (slip).
That is the same quantity the limit analysis reports, so the two compare directly.

States: ``intact`` when both ends move less than ``threshold``; ``open`` when
only the opening exceeds it; ``slide`` when only the slip does; ``open_slide``
when both do (dry Coulomb joints have no dilatancy here, unlike the LA's
associative flow). ``crack_indicator``: the joint's largest end motion over the
largest of all masonry joints, 0 below the threshold and on joints between two supports.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import xarray as xr
from scipy.sparse.csgraph import connected_components

import masonryfw as mf

from .kernels import face_frames
from .scene import DRIVEN_ROLES, Scene

STATE = mf.flags("interface_state")


def block_displacement(scene: Scene, pos: np.ndarray) -> np.ndarray:
    """(block, dof) displacement of the centroids [m, m, rad]."""
    u = pos - scene.pos0
    return u * np.array([scene.scales.length, scene.scales.length, 1.0])


def point_displacement(model: xr.Dataset, u: np.ndarray, blocks: np.ndarray, x: np.ndarray, y: np.ndarray):
    """Displacement of material points (x, y) of ``blocks`` under the rigid motions ``u`` (finite rotation)."""
    cx = model.block_centroid_x.values[blocks]
    cy = model.block_centroid_y.values[blocks]
    theta = u[blocks, 2]
    c, s = np.cos(theta), np.sin(theta)
    rx, ry = x - cx, y - cy
    return u[blocks, 0] + (c - 1) * rx - s * ry, u[blocks, 1] + s * rx + (c - 1) * ry


def relative_motion(model: xr.Dataset, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Opening and slip (interface, end) [m] of the final displacement ``u``."""
    sides = model.interface_blocks.values.astype(np.int64)
    x, y = model.interface_x.values, model.interface_y.values
    ux0, uy0 = point_displacement(model, u, sides[:, [0, 0]], x, y)
    ux1, uy1 = point_displacement(model, u, sides[:, [1, 1]], x, y)
    dx, dy = ux1 - ux0, uy1 - uy0
    nx, ny = model.interface_normal_x.values[:, None], model.interface_normal_y.values[:, None]
    tx, ty = model.interface_tangent_x.values[:, None], model.interface_tangent_y.values[:, None]
    return dx * nx + dy * ny, dx * tx + dy * ty


def masonry_joints(model: xr.Dataset) -> np.ndarray:
    role = model.block_role.values[model.interface_blocks.values.astype(np.int64)]
    return ~np.isin(role, DRIVEN_ROLES).all(axis=1)


def interface_states(opening: np.ndarray, slip: np.ndarray, threshold: float) -> np.ndarray:
    opens = opening.max(axis=1) > threshold
    slips = np.abs(slip).max(axis=1) > threshold
    state = np.full(opening.shape[0], STATE["intact"], dtype=np.int8)
    state[opens & ~slips] = STATE["open"]
    state[slips & ~opens] = STATE["slide"]
    state[opens & slips] = STATE["open_slide"]
    return state


def crack_indicator(motion: np.ndarray, masonry: np.ndarray, threshold: float) -> np.ndarray:
    largest = motion[masonry].max(initial=0.0)
    if largest <= 0:
        return np.zeros_like(motion)
    indicator = np.where(masonry & (motion > threshold), motion / largest, 0.0)
    return np.minimum(indicator, 1.0)


def macro_blocks(n_block: int, interface_blocks: np.ndarray, state: np.ndarray) -> np.ndarray:
    """Connected components through intact interfaces, labelled in order of their lowest block."""
    edges = interface_blocks[state == STATE["intact"]].astype(np.int64)
    graph = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n_block, n_block))
    _, labels = connected_components(graph, directed=False)
    _, first = np.unique(labels, return_index=True)
    return np.argsort(np.argsort(first))[labels]


def interface_forces(model: xr.Dataset, scene: Scene, faces: np.ndarray, props: np.ndarray,
                     normal: np.ndarray, shear: np.ndarray, pos: np.ndarray):
    """Contact forces of the face pairs mapped onto the model's interface ends [N].

    Each face pair that belongs to a model interface (``props[:, 3]``) gives its
    two end forces to the interface end nearest to each contact end (in the
    current configuration); normal = force on side 1 along the interface normal
    (compression positive), shear = along its tangent.
    """
    n_interface = model.sizes["interface"]
    normal_out = np.zeros((n_interface, 2))
    shear_out = np.zeros((n_interface, 2))
    rows = np.flatnonzero(props[:, 3] >= 0)
    if rows.size == 0:
        return normal_out, shear_out
    owner = props[rows, 3].astype(np.int64)
    g = face_frames(pos, scene.lx, scene.ly, scene.offs, faces[rows])
    nx, ny, ox, oy = g[:, 0:1], g[:, 1:2], g[:, 2:3], g[:, 3:4]
    s, h = g[:, 4:6], g[:, 8:10]  # (face, end)
    px, py = ox + s * ny + h * nx, oy - s * nx + h * ny  # t = (n_y, -n_x)
    sides = model.interface_blocks.values.astype(np.int64)[owner]
    sign = np.where(sides[:, 1] == faces[rows, 2], 1.0, -1.0)[:, None]
    fx = sign * (normal[rows] * nx + shear[rows] * ny) * scene.scales.force
    fy = sign * (normal[rows] * ny - shear[rows] * nx) * scene.scales.force
    # interface end points carried by side 0 into the current configuration
    u = block_displacement(scene, pos)
    ix, iy = model.interface_x.values[owner], model.interface_y.values[owner]
    dux, duy = point_displacement(model, u, sides[:, [0, 0]], ix, iy)
    ex, ey = (ix + dux) / scene.scales.length, (iy + duy) / scene.scales.length
    # nearest interface end of each contact end: (face, contact end, interface end)
    dist = np.hypot(ex[:, None, :] - px[:, :, None], ey[:, None, :] - py[:, :, None])
    nearest = dist.argmin(axis=2)
    n_i = np.stack((model.interface_normal_x.values[owner], model.interface_normal_y.values[owner]), axis=1)
    t_i = np.stack((model.interface_tangent_x.values[owner], model.interface_tangent_y.values[owner]), axis=1)
    target = owner[:, None] * 2 + nearest
    np.add.at(normal_out.reshape(-1), target.ravel(), (fx * n_i[:, :1] + fy * n_i[:, 1:]).ravel())
    np.add.at(shear_out.reshape(-1), target.ravel(), (fx * t_i[:, :1] + fy * t_i[:, 1:]).ravel())
    return normal_out, shear_out
