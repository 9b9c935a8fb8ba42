"""Export of a result to VTK (ParaView) through meshio.

``export_vtk(result, "wall.vtu")`` writes one unstructured-grid file per kind of
geometry and a multiblock index that opens them together:

| file | cells | data |
|---|---|---|
| ``wall.vtu`` | one polygon per block (triangle / quad / polygon) | cell: ``block_index``, ``block_role``, ``macro_block``, ``centroid_displacement`` (ux, uy, 0), ``rotation`` (rz); point: ``displacement`` (rigid motion at each vertex, for *Warp By Vector*) |
| ``wall_joints.vtu`` | one line per interface | cell: ``interface_index``, ``interface_kind``, ``interface_state``, ``crack_indicator``; point (the two ends): ``interface_opening``, ``interface_slip``, ``interface_normal_force``, ``interface_shear_force`` |
| ``wall_mesh.vtu`` | continuum mesh faces (``mesh_face_nodes``) | cell: ``face_index`` |
| ``wall_qp.vtu`` | one vertex per quadrature point | point: ``qp_failure`` (0 elastic, 1 tensile, 2 shear, 3 both) |
| ``wall_series_000.vtu``, ... | a result with snapshots (fdem in 3D keeps 20 by default): the blocks at each | as ``wall.vtu``, at the snapshot |
| ``wall_series.pvd`` | ParaView collection of the snapshots, each at its settlement [m] as the time: it plays the settlement | |
| ``wall.vtm`` | VTK multiblock index of the final state's files | |

A 3D result (``masonryfw_space = 3``) writes its blocks as the polygons of their faces (cell data per face:
``face_index``, ``block_index``, ``block_role``, ``macro_block``, ``centroid_displacement`` (ux, uy, uz),
``rotation`` (rx, ry, rz); point: ``displacement``, by the finite rotation of an incremental solver's result)
and its interfaces as their polygons (cell:
``interface_index``, ``interface_kind``, ``interface_state``, ``crack_indicator``, ``interface_normal_force``;
point: ``interface_opening``, ``interface_slip``, ``interface_point_force``).

Blocks are grouped into cell blocks by vertex count, so the cell order can
differ from the block order: ``block_index`` maps each cell back. Each block
has its own vertices (the CF ragged layout), so per-vertex data is exact.
Variables a result lacks are left out; files with nothing in them are not written.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .shapes import padded_block_nodes, vertex_motion

JOINT_POINT_VARIABLES = ("interface_opening", "interface_slip", "interface_normal_force", "interface_shear_force")
JOINT_CELL_VARIABLES = ("interface_kind", "interface_state", "crack_indicator")


def _meshio():
    try:
        import meshio
    except ImportError:
        raise mf.MasonryError("VTK export needs the meshio package: pip install meshio") from None
    return meshio


def _cell_type(count: int) -> str:
    return {2: "line", 3: "triangle", 4: "quad"}.get(count, "polygon")


def _points(x, y) -> np.ndarray:
    return np.column_stack([np.ravel(x), np.ravel(y), np.zeros(np.size(x))])


def _grouped_cells(connectivity: np.ndarray, count: np.ndarray):
    """Cell blocks by vertex count: ``[(type, connectivity)]`` and the row order they use."""
    groups, order = [], []
    for size in np.unique(count):
        rows = np.flatnonzero(count == size)
        groups.append((_cell_type(int(size)), connectivity[rows, :size]))
        order.append(rows)
    return groups, order


def _split(values: np.ndarray, order) -> list[np.ndarray]:
    return [np.asarray(values)[rows] for rows in order]


def _as_vtk(values: np.ndarray) -> np.ndarray:
    """VTK-friendly dtypes: int32 for integers and flags, float64 for the rest."""
    values = np.asarray(values)
    return values.astype(np.int32) if values.dtype.kind in "iub" else values.astype(np.float64)


def blocks_mesh(ds: xr.Dataset):
    """Blocks as polygons with their role, macro-block and motion (a 3D model's: :func:`blocks_mesh_3d`)."""
    if mfp.space(ds) == 3:
        return blocks_mesh_3d(ds)
    meshio = _meshio()
    geo = mfp.derive_geometry(ds)
    counts = geo.block_node_count.values.astype(np.int64)
    cells, order = _grouped_cells(padded_block_nodes(counts), counts)
    cell_data = {
        "block_index": _split(np.arange(counts.size, dtype=np.int32), order),
        "block_role": _split(_as_vtk(geo.block_role.values), order),
    }
    point_data = {}
    if "macro_block" in ds:
        cell_data["macro_block"] = _split(_as_vtk(ds.macro_block.values), order)
    if "block_displacement" in ds:
        u = mfp.block_motion(ds)
        cell_data["centroid_displacement"] = _split(np.column_stack([u[:, 0], u[:, 1], np.zeros(len(u))]), order)
        cell_data["rotation"] = _split(u[:, 2], order)
        ux, uy = vertex_motion(geo, u, str(ds.attrs.get("rotations", "small")))
        point_data["displacement"] = _points(ux, uy)
    return meshio.Mesh(_points(geo.node_x.values, geo.node_y.values), cells, point_data=point_data, cell_data=cell_data)


def blocks_mesh_3d(ds: xr.Dataset):
    """A 3D model's blocks as the polygons of their faces (a surface per block: ParaView draws it; cells carry their
    block's index, role, macro-block and motion), the rigid motion at every vertex as ``displacement``."""
    meshio = _meshio()
    geo = mfp.derive_geometry(ds)
    poly = mfp.polyhedra_of(geo)
    index = poly.face_vertex_index()
    counts = poly.face_node_count
    connectivity = np.full((counts.size, int(counts.max(initial=0))), -1, dtype=np.int64)
    rows = np.repeat(np.arange(counts.size), counts)
    connectivity[rows, np.arange(index.size) - np.repeat(mfp.block_offsets(counts)[:-1], counts)] = index
    cells, order = _grouped_cells(connectivity, counts)
    block = poly.face_block()
    cell_data = {"face_index": _split(np.arange(counts.size, dtype=np.int32), order),
                 "block_index": _split(block.astype(np.int32), order),
                 "block_role": _split(_as_vtk(geo.block_role.values[block]), order)}
    point_data = {}
    if "macro_block" in ds:
        cell_data["macro_block"] = _split(_as_vtk(ds.macro_block.values[block]), order)
    if "block_displacement" in ds:
        u = mfp.block_motion(ds)
        cell_data["centroid_displacement"] = _split(u[block, :3], order)
        cell_data["rotation"] = _split(u[block, 3:], order)
        owner = np.repeat(np.arange(geo.sizes["block"]), geo.block_node_count.values)
        centre = np.c_[geo.block_centroid_x.values, geo.block_centroid_y.values, geo.block_centroid_z.values]
        point_data["displacement"] = mfp.carried_motion(u, centre, poly.vertices, owner,
                                                        str(ds.attrs.get("rotations", "small")))
    return meshio.Mesh(poly.vertices, cells, point_data=point_data, cell_data=cell_data)


def joints_mesh_3d(ds: xr.Dataset):
    """A 3D model's interfaces as their polygons; per-vertex variables (opening, slip, the force on side 1) on
    their vertices, the interface's kind, state, crack indicator and normal force on the cell."""
    meshio = _meshio()
    count = ds.interface_node_count.values.astype(np.int64)
    points = mfp.interface_points(ds)
    connectivity = np.full((count.size, int(count.max(initial=0))), -1, dtype=np.int64)
    rows = np.repeat(np.arange(count.size), count)
    connectivity[rows, np.arange(rows.size) - np.repeat(mfp.block_offsets(count)[:-1], count)] = np.arange(rows.size)
    cells, order = _grouped_cells(connectivity, count)
    cell_data = {"interface_index": _split(np.arange(count.size, dtype=np.int32), order)}
    cell_data.update({name: _split(_as_vtk(ds[name].values), order)
                      for name in (*JOINT_CELL_VARIABLES, "interface_normal_force") if name in ds})
    point_data = {name: _as_vtk(ds[name].values) for name in ("interface_opening", "interface_slip") if name in ds}
    if "interface_point_force_x" in ds:
        point_data["interface_point_force"] = np.c_[ds.interface_point_force_x.values, ds.interface_point_force_y.values,
                                                    ds.interface_point_force_z.values]
    return meshio.Mesh(points, cells, point_data=point_data, cell_data=cell_data)


def joints_mesh(ds: xr.Dataset):
    """Interfaces as lines; per-end variables on their two end points (a 3D model's: :func:`joints_mesh_3d`)."""
    if mfp.space(ds) == 3:
        return joints_mesh_3d(ds)
    meshio = _meshio()
    n = ds.sizes["interface"]
    cell_data = {"interface_index": [np.arange(n, dtype=np.int32)]}
    cell_data.update({name: [_as_vtk(ds[name].values)] for name in JOINT_CELL_VARIABLES if name in ds})
    point_data = {name: _as_vtk(ds[name].values).ravel() for name in JOINT_POINT_VARIABLES if name in ds}
    return meshio.Mesh(
        _points(ds.interface_x.values, ds.interface_y.values),
        [("line", np.arange(2 * n).reshape(n, 2))],
        point_data=point_data,
        cell_data=cell_data,
    )


def continuum_mesh(ds: xr.Dataset):
    """The continuum mesh faces (padding indices, negative or masked, dropped)."""
    meshio = _meshio()
    faces = np.asarray(ds.mesh_face_nodes.to_masked_array().filled(-1), dtype=np.int64)
    count = (faces >= 0).sum(axis=1)
    cells, order = _grouped_cells(faces, count)
    return meshio.Mesh(
        _points(ds.mesh_node_x.values, ds.mesh_node_y.values), cells,
        cell_data={"face_index": _split(np.arange(faces.shape[0], dtype=np.int32), order)},
    )


def plastic_points(ds: xr.Dataset):
    """Quadrature points as a point cloud carrying their failure flag."""
    meshio = _meshio()
    n = ds.sizes["qp"]
    return meshio.Mesh(
        _points(ds.qp_x.values, ds.qp_y.values),
        [("vertex", np.arange(n).reshape(n, 1))],
        point_data={"qp_failure": _as_vtk(ds.qp_failure.values)},
    )


def _multiblock(pieces: list[tuple[str, Path]]) -> str:
    entries = "\n".join(
        f'    <DataSet index="{i}" name="{name}" file="{path.name}"/>' for i, (name, path) in enumerate(pieces)
    )
    return (
        '<?xml version="1.0"?>\n<VTKFile type="vtkMultiBlockDataSet" version="1.0">\n'
        f"  <vtkMultiBlockDataSet>\n{entries}\n  </vtkMultiBlockDataSet>\n</VTKFile>\n"
    )


#: The pieces of an export: name, file suffix, whether a result has it, how it is built.
PIECES = (
    ("blocks", "", lambda ds: True, blocks_mesh),
    ("joints", "_joints", lambda ds: ds.sizes.get("interface", 0) > 0, joints_mesh),
    ("mesh", "_mesh", lambda ds: "mesh_face_nodes" in ds, continuum_mesh),
    ("plastic_points", "_qp", lambda ds: "qp_failure" in ds, plastic_points),
)


def export_paths(ds: xr.Dataset, path: str | os.PathLike) -> list[Path]:
    """The files :func:`export_vtk` writes for ``ds`` at ``path`` (a ``.vtu`` name), the ``.vtm`` index of the
    final state last; before it, of a result with snapshots, their blocks and the ``.pvd`` collection of them."""
    path = Path(path)
    if path.suffix.lower() != ".vtu":
        raise mf.MasonryError(f"VTK export file {str(path)!r}: the name must end in .vtu")
    stem = path.with_suffix("")
    pieces = [Path(f"{stem}{suffix}.vtu") for _, suffix, present, _ in PIECES if present(ds)]
    return pieces + series_paths(ds, stem) + [path.with_suffix(".vtm")]


def series_paths(ds: xr.Dataset, stem: Path) -> list[Path]:
    """The time series' files: each snapshot's blocks (``<stem>_series_000.vtu``, ...) and their ``.pvd``
    collection last; none for a result without snapshots."""
    count = ds.sizes.get("snapshot", 0)
    return [Path(f"{stem}_series_{k:03d}.vtu") for k in range(count)] + ([Path(f"{stem}_series.pvd")] if count else [])


def snapshot_state(ds: xr.Dataset, k: int) -> xr.Dataset:
    """``ds`` moved to its snapshot ``k``: its blocks' displacements and rotations those of the snapshot (the final
    state's macro-blocks left out: they are the last record's)."""
    state = ds.drop_vars(["macro_block"] if "macro_block" in ds else [])
    return state.assign(block_displacement=ds.block_displacement.copy(data=ds.snapshot_block_displacement.values[k]),
                        block_rotation=ds.block_rotation.copy(data=ds.snapshot_block_rotation.values[k]))


def _collection(entries: list[tuple[float, Path]]) -> str:
    """A ParaView ``.pvd`` collection: each file at its time, here the settlement [m] of its snapshot."""
    rows = "\n".join(f'    <DataSet timestep="{time!r}" group="" part="0" file="{path.name}"/>' for time, path in entries)
    return ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
            f"  <Collection>\n{rows}\n  </Collection>\n</VTKFile>\n")


def export_vtk(ds: xr.Dataset, path: str | os.PathLike) -> list[Path]:
    """Write the VTK files of a result (see the module docstring); returns the paths written.

    Every target is checked (folder, not an input) before anything is written.
    """
    paths = export_paths(ds, path)
    for target in paths:
        mfp.check_output_path(target, [ds.encoding.get("source")])
    present = [(name, build) for name, _, has, build in PIECES if has(ds)]
    pieces = [(name, target) for (name, _), target in zip(present, paths)]
    writes = {target: _vtu_writer(build(ds)) for (_, build), target in zip(present, paths)}
    series = series_paths(ds, Path(path).with_suffix(""))
    build = blocks_mesh_3d if mfp.space(ds) == 3 else blocks_mesh
    for k, target in enumerate(series[:-1]):
        writes[target] = _vtu_writer(build(snapshot_state(ds, k)))
    if series:
        entries = list(zip(ds.snapshot_settlement.values.tolist(), series[:-1]))
        writes[series[-1]] = lambda temporary: temporary.write_text(_collection(entries))
    writes[paths[-1]] = lambda temporary: temporary.write_text(_multiblock(pieces))
    return mfp.write_atomically(writes, path)  # the set or nothing: ParaView opens the index, which names the rest


def _vtu_writer(mesh):
    return lambda temporary: mesh.write(temporary, file_format="vtu")
