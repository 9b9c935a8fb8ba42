"""Triangle meshes of the wall's masonry blocks, and the segments where the masonry rests on supports.

Two meshers, one result (:class:`WallMesh`: every triangle belongs to one block):

- **structured**, when every unit and lintel is an axis-aligned rectangle (the builder's
  walls): the grid lines are every block and support edge coordinate, each interval
  split into equal parts no longer than the mesh size; a grid cell belongs to the block
  its centre lies in (openings are left out) and is cut into two triangles along
  alternating diagonals (no preferred direction). Cells follow the courses exactly.
- **gmsh** otherwise (drawn walls: stones of any shape, arches): every block a plane
  surface of OpenCASCADE, fragmented together so that blocks meeting along part of an
  edge (T-junctions) share their nodes, and with the supports' ends (a base edge across
  two supports would be held by neither), meshed by gmsh's Delaunay mesher with elements
  no larger than the mesh size.

Supports are the model's support interfaces (masonry on a support block): the boundary
edges of the mesh on those segments are held or moved.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

KIND = mfp.flags("interface_kind")


@dataclass(frozen=True)
class WallMesh:
    """Triangles of the wall, the block each came from, and the support segments (model units, m)."""

    points: np.ndarray  # (2, nodes)
    triangles: np.ndarray  # (3, triangles), counter-clockwise
    block: np.ndarray  # (triangles,) model block index
    supports: np.ndarray  # (segments, end, xy) where the masonry rests on a support block
    support_block: np.ndarray  # (segments,) the support block of each segment
    mesher: str  # structured or gmsh


def masonry(model: xr.Dataset) -> np.ndarray:
    """Indices of the units and lintels (the blocks the mesh covers)."""
    found = np.flatnonzero(mfp.masonry_blocks(model.block_role.values))
    if found.size == 0:
        raise mf.ModelError("jmm: the model has no unit or lintel blocks to mesh")
    return found


def block_boxes(model: xr.Dataset) -> np.ndarray:
    """``(block, 4)`` = x0, y0, x1, y1 of every block's bounding box."""
    xmin, xmax, ymin, ymax = mfp.block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    return np.stack([xmin, ymin, xmax, ymax], axis=1)


def axis_aligned(model: xr.Dataset) -> bool:
    """Whether every unit and lintel is an axis-aligned rectangle (its area fills its bounding box)."""
    box = block_boxes(model)
    area = (box[:, 2] - box[:, 0]) * (box[:, 3] - box[:, 1])
    blocks = masonry(model)
    return bool(np.allclose(area[blocks], model.block_area.values[blocks], rtol=1e-9))


def support_segments(model: xr.Dataset) -> tuple[np.ndarray, np.ndarray]:
    """``(segments (k, end, xy), support block (k,))``: every interface between masonry and a support."""
    sides = model.interface_blocks.values.astype(np.int64)
    support = mfp.support_blocks(model.block_role.values)
    on = support[sides].any(axis=1) & ~support[sides].all(axis=1)
    segments = np.stack([model.interface_x.values[on], model.interface_y.values[on]], axis=2)
    return segments, np.where(support[sides[on, 0]], sides[on, 0], sides[on, 1])


def grid_lines(edges: np.ndarray, size: float, tol: float) -> np.ndarray:
    """Sorted unique ``edges`` with every gap split into equal parts no longer than ``size``."""
    edges = np.unique(np.round(edges / tol) * tol)
    parts = np.maximum(np.ceil(np.diff(edges) / size * (1 - 1e-6)).astype(int), 1)  # 1e-6: sizes read from data
    starts = np.repeat(edges[:-1], parts)
    steps = np.repeat(np.diff(edges) / parts, parts)
    index = np.arange(parts.sum()) - np.repeat(np.cumsum(parts) - parts, parts)
    return np.append(starts + index * steps, edges[-1])


def structured_mesh(model: xr.Dataset, size: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(points, triangles, block)`` of the grid mesh of an axis-aligned wall (module docstring)."""
    box = block_boxes(model)
    b = masonry(model)
    tol = 1e-9 * mfp.model_scale(model.node_x.values, model.node_y.values)
    xs = grid_lines(box[:, [0, 2]].ravel(), size, tol)
    ys = grid_lines(box[b][:, [1, 3]].ravel(), size, tol)
    cx, cy = 0.5 * (xs[1:] + xs[:-1]), 0.5 * (ys[1:] + ys[:-1])
    owner = np.full((cy.size, cx.size), -1)
    i0, i1 = np.searchsorted(cx, box[b, 0]), np.searchsorted(cx, box[b, 2])
    j0, j1 = np.searchsorted(cy, box[b, 1]), np.searchsorted(cy, box[b, 3])
    for k in range(b.size):  # blocks cover disjoint rectangles of cells: one slice assignment each
        owner[j0[k]:j1[k], i0[k]:i1[k]] = b[k]
    rows, cols = np.meshgrid(np.arange(cy.size), np.arange(cx.size), indexing="ij")
    ci, cj = rows.ravel(), cols.ravel()
    inside = owner[ci, cj] >= 0
    ci, cj = ci[inside], cj[inside]
    nx = xs.size
    node = lambda j, i: j * nx + i  # noqa: E731
    a, bb, c, d = node(ci, cj), node(ci, cj + 1), node(ci + 1, cj + 1), node(ci + 1, cj)
    flip = (ci + cj) % 2 == 1
    t1 = np.where(flip, [a, bb, d], [a, bb, c])
    t2 = np.where(flip, [bb, c, d], [a, c, d])
    triangles = np.concatenate([t1, t2], axis=1)
    cell_block = owner[ci, cj]
    used, triangles = np.unique(triangles, return_inverse=True)
    gx, gy = np.meshgrid(xs, ys)
    points = np.stack([gx.ravel()[used], gy.ravel()[used]])
    return points, triangles.reshape(3, -1), np.concatenate([cell_block, cell_block])


def gmsh_mesh(model: xr.Dataset, size: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(points, triangles, block)`` of the masonry blocks meshed by gmsh (module docstring)."""
    try:
        import gmsh
    except (ImportError, OSError) as exc:  # the wheel needs the system's libGLU and X libraries
        raise mf.SolveError(f"jmm: this wall is not made of axis-aligned rectangles and needs gmsh to be meshed, "
                            f"which does not load here ({exc})") from None
    blocks = masonry(model)
    x, y = model.node_x.values, model.node_y.values
    start = mfp.block_offsets(model.block_node_count.values)
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("wall")
        occ = gmsh.model.occ
        surfaces = []
        for b in blocks:  # gmsh's API takes one entity at a time
            corners = [occ.addPoint(x[k], y[k], 0.0) for k in range(start[b], start[b + 1])]
            lines = [occ.addLine(p, q) for p, q in zip(corners, corners[1:] + corners[:1])]
            surfaces.append(occ.addPlaneSurface([occ.addCurveLoop(lines)]))
        ends = np.unique(support_segments(model)[0].reshape(-1, 2), axis=0)
        corners = [(0, occ.addPoint(px, py, 0.0)) for px, py in ends]
        # the supports' ends split the blocks' edges: every mesh edge on the base lies on one support (an edge
        # across two is held by neither, and the no-tension masonry over that gap cannot take the weight)
        _, pieces = occ.fragment([(2, s) for s in surfaces], corners)
        occ.synchronize()
        for name, value in (("Mesh.MeshSizeMax", size), ("Mesh.MeshSizeMin", 0.0), ("Mesh.MeshSizeFromPoints", 0),
                            ("Mesh.MeshSizeExtendFromBoundary", 0), ("Mesh.MeshSizeFromCurvature", 0),
                            ("Mesh.Algorithm", 6)):
            gmsh.option.setNumber(name, value)
        gmsh.model.mesh.generate(2)
        tags, coordinates, _ = gmsh.model.mesh.getNodes()
        position = np.zeros(int(tags.max()) + 1, dtype=np.int64)
        position[tags.astype(np.int64)] = np.arange(tags.size)
        triangles, owner = [], []
        for b, piece in zip(blocks, pieces):
            for dim, tag in piece:
                types, _, nodes = gmsh.model.mesh.getElements(dim, tag)
                for kind, connectivity in zip(types, nodes):
                    if kind == 2:  # 3-node triangles
                        triangles.append(position[connectivity.astype(np.int64)].reshape(-1, 3))
                        owner.append(np.full(triangles[-1].shape[0], b))
    finally:
        gmsh.finalize()
    points = coordinates.reshape(-1, 3)[:, :2].T.copy()
    triangles = np.concatenate(triangles)
    px, py = points[0, triangles], points[1, triangles]
    clockwise = (px[:, 1] - px[:, 0]) * (py[:, 2] - py[:, 0]) - (px[:, 2] - px[:, 0]) * (py[:, 1] - py[:, 0]) < 0
    triangles[clockwise] = triangles[clockwise][:, ::-1]
    used, triangles = np.unique(triangles, return_inverse=True)
    # C order: scikit-fem copies (and says so) anything else
    return np.ascontiguousarray(points[:, used]), np.ascontiguousarray(triangles.reshape(-1, 3).T), np.concatenate(owner)


def wall_mesh(model: xr.Dataset, size: float) -> WallMesh:
    """Mesh the masonry blocks of ``model`` with elements no larger than ``size`` (m)."""
    if not size > 0:
        raise mf.ModelError(f"jmm mesh size must be > 0, got {size}")
    mesher = "structured" if axis_aligned(model) else "gmsh"
    points, triangles, block = (structured_mesh if mesher == "structured" else gmsh_mesh)(model, size)
    segments, support_block = support_segments(model)
    return WallMesh(points, triangles, block, segments, support_block, mesher)
