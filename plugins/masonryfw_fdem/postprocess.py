"""From the final block positions and contact forces to the primary result variables.

The comparable fields (opening and slip at the model's interface ends with
finite rotations, joint states, crack indicator, macro-blocks) are derived by the
core (:mod:`masonryfw.results.semantics`), as for every solver: the same quantities the
limit analysis reports, so the two compare directly.
"""
from __future__ import annotations

import numpy as np

import masonryfw.plugin_api as mfp

from .kernels import face_frames
from .scene import Scene


def block_displacement(scene: Scene, pos: np.ndarray) -> np.ndarray:
    """(block, 3) displacement of the centroids [m, m] and rotation [rad]."""
    u = pos - scene.pos0
    return u * np.array([scene.scales.length, scene.scales.length, 1.0])


def block_displacement3(scene, snapshot: np.ndarray) -> np.ndarray:
    """``(block, 6)`` [m, rad]: centroid displacements and rotation vectors (axis times angle) of a 3D state's
    snapshot (centroids, then unit quaternions)."""
    pos, quat = snapshot[:, :3], snapshot[:, 3:]
    quat = quat * np.where(quat[:, :1] < 0.0, -1.0, 1.0)  # the shorter way round
    sine = np.linalg.norm(quat[:, 1:], axis=1)
    angle = 2.0 * np.arctan2(sine, quat[:, 0])
    axis = quat[:, 1:] / np.where(sine > 0, sine, 1.0)[:, None]
    return np.c_[(pos - scene.pos0) * scene.scales.length, axis * angle[:, None]]


def interface_normal_forces3(scene, faces: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """``(interface,)`` [N]: each model interface's normal force (compression positive), the sum of the normal
    forces at the points of the face pairs between its two blocks (``normal``: pair, point; a pair between
    blocks that share no interface, a contact the settlement made, is left out; blocks joined by several
    interfaces give it to the first)."""
    out = np.zeros(scene.model.sizes["interface"])
    if faces.size:
        joint = mfp.find_pairs(scene.joints, scene.bodies.face_block[faces])
        kept = joint >= 0
        np.add.at(out, joint[kept], normal[kept].sum(axis=1) * scene.scales.force)
    return out


def interface_forces(scene: Scene, faces: np.ndarray, props: np.ndarray, normal: np.ndarray, shear: np.ndarray,
                     pos: np.ndarray):
    """Contact forces of the face pairs mapped onto the model's interface ends [N].

    Each face pair that belongs to a model interface (``props[:, 3]``) gives its
    two end forces to the interface end nearest to each contact end (in the
    current configuration); normal = force on side 1 along the interface normal
    (compression positive), shear = along its tangent.
    """
    model = scene.model
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
    dux, duy = mfp.point_motion(u, model.block_centroid_x.values, model.block_centroid_y.values, ix, iy,
                               sides[:, [0, 0]], "finite")
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
