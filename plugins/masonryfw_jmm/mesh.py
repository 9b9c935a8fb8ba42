"""Triangle meshes of the wall's masonry blocks, and the segments where the masonry rests on supports.

Two meshers, one result (:class:`WallMesh`: every triangle belongs to one block):

- **structured**, when every unit and lintel is an axis-aligned rectangle (the builder's
  walls): the grid lines are every block and support edge coordinate, each interval
  split into equal parts no longer than the mesh size; a grid cell belongs to the block
  its centre lies in (openings are left out) and is cut into two triangles along
  alternating diagonals (no preferred direction). Cells follow the courses exactly.
- **gmsh** otherwise (drawn walls: stones of any shape, arches): every block a plane
  surface of gmsh's own geometry kernel, its outline given a vertex wherever a neighbour's
  edge or a support ends along it (:func:`conforming_outlines`), so that blocks meeting along
  part of an edge (T-junctions) share one line there and its nodes; meshed by gmsh's
  Delaunay mesher with elements no larger than the mesh size. (OpenCASCADE's fragment of
  the blocks did the same from the geometry alone: 64 s of the gable house's 4,364 blocks,
  against about 1 s for the outlines from the interfaces the model already has.)

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


def conforming_outlines(model: xr.Dataset, blocks: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """``(points (2, n), outlines)``: every block of ``blocks`` as a loop of point indices with a vertex wherever
    a neighbour's edge starts or ends along its own (the ends of its interfaces: T-junctions, the supports' ends),
    points shared between blocks (merged within 1e-9 of the model's size).

    Meshed edge by edge, two blocks then share their nodes on every common stretch; a base edge across two
    supports is split where one ends (held by neither whole, the no-tension masonry over the gap could not
    take the weight)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    x, y = model.node_x.values, model.node_y.values
    start = mfp.block_offsets(model.block_node_count.values)
    tol = 1e-9 * mfp.model_scale(x, y)
    sides = model.interface_blocks.values.astype(np.int64)
    ends = np.stack([model.interface_x.values, model.interface_y.values], axis=-1)  # (interface, end, xy)
    touching = np.concatenate([sides[:, 0], sides[:, 0], sides[:, 1], sides[:, 1]])
    at = np.concatenate([ends[:, 0], ends[:, 1], ends[:, 0], ends[:, 1]])
    order = np.argsort(touching, kind="stable")
    touching, at = touching[order], at[order]
    loops_xy = []
    for b in blocks:  # a few vertices and a few interface ends each
        corners = np.stack([x[start[b]:start[b + 1]], y[start[b]:start[b + 1]]], axis=1)
        candidates = at[np.searchsorted(touching, b):np.searchsorted(touching, b, side="right")]
        loop = []
        for a, c in zip(corners, np.roll(corners, -1, axis=0)):
            edge = c - a
            length2 = edge @ edge
            t = (candidates - a) @ edge / length2
            off = np.abs((candidates[:, 0] - a[0]) * edge[1] - (candidates[:, 1] - a[1]) * edge[0]) / np.sqrt(length2)
            inner = (off <= tol) & (t * np.sqrt(length2) > tol) & ((1 - t) * np.sqrt(length2) > tol)
            loop.append(a[None])
            loop.append(a + np.unique(t[inner])[:, None] * edge)
        loops_xy.append(np.concatenate(loop))
    sizes = np.array([len(loop) for loop in loops_xy])
    raw = np.concatenate(loops_xy)
    pairs = cKDTree(raw).query_pairs(tol, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(raw), len(raw)))
    _, label = connected_components(graph, directed=False)
    first = np.unique(label, return_index=True)[1]
    points = raw[first].T
    outlines = []
    for ids in np.split(label, np.cumsum(sizes)[:-1]):
        keep = ids != np.roll(ids, 1)  # a vertex merged with the one before it
        outlines.append(ids[keep])
    return points, outlines


def gmsh_mesh(model: xr.Dataset, size: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(points, triangles, block)`` of the masonry blocks meshed by gmsh (module docstring)."""
    try:
        import gmsh
    except (ImportError, OSError) as exc:  # the wheel needs the system's libGLU and X libraries
        raise mf.SolveError(f"jmm: this wall is not made of axis-aligned rectangles and needs gmsh to be meshed, "
                            f"which does not load here ({exc})") from None
    blocks = masonry(model)
    corners, outlines = conforming_outlines(model, blocks)
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("wall")
        geo = gmsh.model.geo
        point_tags = [geo.addPoint(px, py, 0.0) for px, py in corners.T]
        lines: dict[tuple[int, int], int] = {}
        surfaces = []
        for outline in outlines:  # gmsh's API takes one entity at a time
            loop = []
            for p, q in zip(outline, np.roll(outline, -1)):
                key = (min(p, q), max(p, q))
                if key not in lines:  # a stretch two blocks share is one line, meshed once
                    lines[key] = geo.addLine(point_tags[key[0]], point_tags[key[1]])
                loop.append(lines[key] if p < q else -lines[key])
            surfaces.append(geo.addPlaneSurface([geo.addCurveLoop(loop)]))
        geo.synchronize()
        for name, value in (("Mesh.MeshSizeMax", size), ("Mesh.MeshSizeMin", 0.0), ("Mesh.MeshSizeFromPoints", 0),
                            ("Mesh.MeshSizeExtendFromBoundary", 0), ("Mesh.MeshSizeFromCurvature", 0),
                            ("Mesh.Algorithm", 6)):
            gmsh.option.setNumber(name, value)
        gmsh.model.mesh.generate(2)
        tags, coordinates, _ = gmsh.model.mesh.getNodes()
        position = np.zeros(int(tags.max()) + 1, dtype=np.int64)
        position[tags.astype(np.int64)] = np.arange(tags.size)
        triangles, owner = [], []
        for b, surface in zip(blocks, surfaces):
            types, _, nodes = gmsh.model.mesh.getElements(2, surface)
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
