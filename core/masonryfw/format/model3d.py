"""Models in 3D (``masonryfw_space = 3``, docs/format.md): the dataset of polyhedra, read back and derived.

A 3D model holds the polyhedra (:mod:`.polyhedra`) and the contacts found between them, with the roles,
materials, loads and supports of 2D in their six-component form. :func:`twin` stands a planar model up one
block thick (its y becomes z), the reference every 3D solver is checked against: the same wall, the same
answer.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ..geometry import polyhedra
from ..geometry.graph import find_pairs, pair_index
from ..geometry.polygons import model_scale
from ..runtime.errors import ModelError
from .dofs import block_loads
from .roles import support_blocks
from .schema import format_header, load_schema, variable_attrs

#: Contacts are found to this share of the model's size (its bounding-box diagonal).
CONTACT_TOLERANCE = 1e-6
#: The variables :func:`derive_geometry_3d` adds.
DERIVED_3D_VARIABLES = ("block_volume", "block_centroid_x", "block_centroid_y", "block_centroid_z", "interface_area",
                        "interface_normal_x", "interface_normal_y", "interface_normal_z")
#: 2D's (x, y, rz) in 3D's (ux, uy, uz, rx, ry, rz): x stays, y becomes z, a turn about 2D's z is one about -y.
PLANAR_DOFS = np.array([0, 2, 4])
PLANAR_SIGN = np.array([1.0, 1.0, -1.0])


def space(ds: xr.Dataset) -> int:
    """2 or 3: the model's dimension (the ``masonryfw_space`` attribute; a file without it is 2D)."""
    return int(np.asarray(ds.attrs.get("masonryfw_space", 2)).item())


def require_space(datasets, spaces: tuple[int, ...], who: str) -> None:
    """A :class:`ModelError` when a dataset is of a dimension ``who`` (a plotter, a comparator, a command) does
    not handle; ``spaces``: the dimensions it declares."""
    for ds in datasets:
        if space(ds) not in spaces:
            handles = " and ".join(f"{d}D" for d in spaces)
            raise ModelError(f"{who} handles {handles} models and results; {ds.attrs.get('title', 'this dataset')!r} "
                             f"is {space(ds)}D (masonryfw_space = {space(ds)}). Its key numbers: masonryfw solve; "
                             "its description: masonryfw info")


def polyhedra_of(ds: xr.Dataset) -> polyhedra.Polyhedra:
    """The blocks of a 3D model as :class:`~masonryfw.geometry.polyhedra.Polyhedra`."""
    return polyhedra.Polyhedra(np.c_[ds.node_x.values, ds.node_y.values, ds.node_z.values].astype(float),
                               ds.block_node_count.values.astype(np.int64), ds.block_face_count.values.astype(np.int64),
                               ds.face_node_count.values.astype(np.int64), ds.face_nodes.values.astype(np.int64))


def interface_points(ds: xr.Dataset) -> np.ndarray:
    """``(interface_node, 3)``: the vertices of a 3D model's interface polygons, interface after interface."""
    return np.c_[ds.interface_node_x.values, ds.interface_node_y.values, ds.interface_node_z.values].astype(float)


def contacts_of(ds: xr.Dataset) -> polyhedra.Contacts:
    """The interfaces a 3D model stores, with their normals and tangents derived from their polygons."""
    count = ds.interface_node_count.values.astype(np.int64)
    points = interface_points(ds)
    normal, area = polyhedra.polygon_normals(points, count)
    return polyhedra.Contacts(ds.interface_blocks.values.astype(np.int64).reshape(-1, 2), normal,
                              polyhedra.plane_frame(normal), count, points, area)


def derive_geometry_3d(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` with its blocks' volumes and centroids and its interfaces' areas and normals (derived)."""
    volume, centroid = polyhedra.volumes_centroids(polyhedra_of(ds))
    normal, area = polyhedra.polygon_normals(interface_points(ds), ds.interface_node_count.values.astype(np.int64))
    out = ds.assign(block_volume=("block", volume, {"units": "m3", "long_name": "block volume (derived)"}))
    for k, c in enumerate("xyz"):
        out[f"block_centroid_{c}"] = ("block", centroid[:, k], {"units": "m", "long_name": f"block centroid {c} (derived)"})
    out["interface_area"] = ("interface", area, {"units": "m2", "long_name": "interface area (derived)"})
    for k, c in enumerate("xyz"):
        out[f"interface_normal_{c}"] = ("interface", normal[:, k],
                                        {"units": "1", "long_name": f"interface unit normal {c}, side 0 to side 1 (derived)"})
    return out


def model_from_polyhedra(poly: polyhedra.Polyhedra, contacts: polyhedra.Contacts, arrays: dict, attrs: dict) -> xr.Dataset:
    """The 3D model dataset of ``poly`` and ``contacts``; ``arrays``: every other variable of the format (name:
    values, on their schema's dims), ``attrs``: the global attributes beyond the format's own."""
    variables = {
        "node_x": poly.vertices[:, 0], "node_y": poly.vertices[:, 1], "node_z": poly.vertices[:, 2],
        "block_node_count": poly.block_node_count, "block_face_count": poly.block_face_count,
        "face_node_count": poly.face_node_count, "face_nodes": poly.face_nodes,
        "interface_blocks": contacts.sides, "interface_node_count": contacts.point_count,
        "interface_node_x": contacts.points[:, 0], "interface_node_y": contacts.points[:, 1],
        "interface_node_z": contacts.points[:, 2], **arrays,
    }
    schema = load_schema("model3d")["variables"]
    ds = xr.Dataset({name: (schema[name]["dims"], np.asarray(values), variable_attrs(name, "model3d"))
                     for name, values in variables.items()})
    ds = ds.assign_coords(dof=("dof", schema["dof"]["values"], variable_attrs("dof", "model3d")))
    ds.attrs = {**format_header("model"), "masonryfw_space": 3, **attrs}
    return ds


def lifted(planar: np.ndarray) -> np.ndarray:
    """``(block, 3)`` values over 2D's (x, y, rz) as ``(block, 6)`` over 3D's dofs (:data:`PLANAR_DOFS`)."""
    out = np.zeros((planar.shape[0], 6), dtype=planar.dtype)
    out[:, PLANAR_DOFS] = planar * PLANAR_SIGN.astype(planar.dtype) + 0.0 if planar.dtype.kind == "f" else planar
    return out


def twin(model: xr.Dataset) -> xr.Dataset:
    """The 3D twin of a planar model (derived geometry): every polygon stood in the x-z plane its thickness deep
    about y = 0 (:func:`masonryfw.plugin_api.prisms`); roles, materials and loads as in the plane; a support
    held (or moved) out of the plane too. Interfaces found again from the faces; each takes the friction,
    cohesion and tensile strength of the planar interface between the same two blocks."""
    poly = polyhedra.prisms(model.node_x.values, model.node_y.values, model.block_node_count.values,
                            model.block_thickness.values)
    scale = model_scale(model.node_x.values, model.node_y.values)
    contacts = polyhedra.find_contacts(poly, CONTACT_TOLERANCE * scale)
    joint = planar_joint(model, contacts.sides)
    support = support_blocks(model.block_role.values)
    contacts = _without(contacts, (joint < 0) & support[contacts.sides].all(axis=1))  # ground on ground
    joint = planar_joint(model, contacts.sides)
    fixed = lifted(model.block_fixed.values.astype(np.int8))
    out_of_plane = np.setdiff1d(np.arange(6), PLANAR_DOFS)
    fixed[np.ix_(np.flatnonzero(support), out_of_plane)] = 1  # out of the plane a support is held
    moving = model.settlement_direction.values.astype(float)
    loads = {kind: block_loads(model, kind) for kind in ("dead", "live")}
    arrays = {
        "block_role": model.block_role.values, "block_unit_weight": model.block_unit_weight.values,
        "interface_kind": _joint_values(model.interface_kind.values, joint, 3),
        "interface_friction": _joint_values(model.interface_friction.values, joint, float(np.median(model.interface_friction.values))),
        "interface_cohesion": _joint_values(model.interface_cohesion.values, joint, 0.0),
        "interface_tensile_strength": _joint_values(model.interface_tensile_strength.values, joint, 0.0),
        "block_fixed": fixed, "settlement_direction": lifted(moving),
    }
    for kind, values in loads.items():
        arrays[f"{kind}_load"] = np.c_[values[:, 0], np.zeros(len(values)), values[:, 1]]
        arrays[f"{kind}_moment"] = np.c_[np.zeros(len(values)), 0.0 - values[:, 2], np.zeros(len(values))]
    for name in ("block_young_modulus", "block_poisson_ratio", "settlement_target"):
        if name in model:
            arrays[name] = model[name].values
    attrs = {"title": f"{model.attrs.get('title', 'model')} (3D twin)"}
    if "source_spec" in model.attrs:
        attrs["source_spec"] = model.attrs["source_spec"]
    return model_from_polyhedra(poly, contacts, arrays, attrs)


def planar_joint(model: xr.Dataset, sides: np.ndarray) -> np.ndarray:
    """The planar model's interface between each contact's two blocks (the first of several), -1 where none."""
    return find_pairs(pair_index(model.interface_blocks.values, model.sizes["block"]), sides)


def _joint_values(values: np.ndarray, joint: np.ndarray, default) -> np.ndarray:
    return np.where(joint >= 0, values[np.maximum(joint, 0)], default).astype(values.dtype)


def _without(contacts: polyhedra.Contacts, drop: np.ndarray) -> polyhedra.Contacts:
    keep = ~drop
    point_keep = np.repeat(keep, contacts.point_count)
    return polyhedra.Contacts(contacts.sides[keep], contacts.normal[keep], contacts.tangent[keep],
                              contacts.point_count[keep], contacts.points[point_keep], contacts.area[keep])
