"""Result variables both jmm methods write: the mesh and the quadrature-point fields (docs/format.md)."""
from __future__ import annotations

import numpy as np
import xarray as xr

import masonryfw.plugin_api as mfp


def variable(dims, values, units: str, long_name: str, **attrs) -> xr.Variable:
    return xr.Variable(dims, values, {"units": units, "long_name": long_name, **attrs})


def mesh_variables(points: np.ndarray, triangles: np.ndarray) -> dict[str, xr.Variable]:
    """The triangles ``(3, faces)`` on ``points`` ``(2, nodes)`` [m]: node coordinates and the face-node table."""
    return {
        "mesh_node_x": variable("mesh_node", points[0], "m", "continuum mesh node x"),
        "mesh_node_y": variable("mesh_node", points[1], "m", "continuum mesh node y"),
        "mesh_face_nodes": variable(("mesh_face", "mesh_face_node"), triangles.T.astype(np.int32), "1",
                                    mfp.variable_attrs("mesh_face_nodes")["long_name"]),
    }


def point_variables(xy: np.ndarray, failure: np.ndarray, stress: np.ndarray, where: str, when: str,
                    ) -> dict[str, xr.Variable]:
    """``qp_x/y`` (``where`` the points are), ``qp_failure`` and ``qp_stress_*`` [Pa] (``when`` they hold)."""
    flags = mfp.flags("qp_failure")
    return {
        "qp_x": variable("qp", xy[0], "m", f"{where} x"),
        "qp_y": variable("qp", xy[1], "m", f"{where} y"),
        "qp_failure": variable("qp", failure, "1", f"failure mode {when}",
                               flag_values=np.array(sorted(flags.values()), dtype=np.int8),
                               flag_meanings=" ".join(sorted(flags, key=flags.get))),
        "qp_stress_xx": variable("qp", stress[:, 0], "Pa", f"stress sigma_xx {when} (tension positive)"),
        "qp_stress_yy": variable("qp", stress[:, 1], "Pa", f"stress sigma_yy {when} (tension positive)"),
        "qp_stress_xy": variable("qp", stress[:, 2], "Pa", f"shear stress sigma_xy {when}"),
    }


def block_mechanism(model: xr.Dataset, block, x, y, ux, uy, weight, settlement: float) -> np.ndarray | None:
    """A continuum's field ``(ux, uy)`` at weighted points ``(x, y)`` of blocks ``block`` [m] as block motions
    (block, 3): projected onto each block's rigid motions (:func:`masonryfw.plugin_api.rigid_fit`), the supports moving
    by ``settlement`` along their ``settlement_direction`` (fixed ones stay). None when a block gets no
    motion (no point in it)."""
    fitted = mfp.rigid_fit(block, x, y, ux, uy, weight, model.block_centroid_x.values, model.block_centroid_y.values)
    supports = mfp.support_blocks(model.block_role.values)
    fitted[supports] = model.settlement_direction.values[supports] * settlement
    return None if np.isnan(fitted).any() else fitted


def with_mechanism(result: xr.Dataset, motion: np.ndarray | None, flow_rule: str) -> xr.Dataset:
    """``result`` with ``motion`` (a mechanism: linearised kinematics) as its block motions, if there is one;
    ``flow_rule`` says how its joints dilate (docs/format.md)."""
    if motion is None:
        return result
    return result.assign(mfp.motion_variables(motion)).assign_attrs(rotations="small", flow_rule=flow_rule)
