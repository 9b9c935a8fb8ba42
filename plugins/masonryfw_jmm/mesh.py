"""A structured triangle mesh of the wall that follows the courses, the openings and the supports.

The wall's masonry blocks (units and lintels) must be axis-aligned rectangles (every
bundled wall is). The grid lines are every block and support edge coordinate, each
interval split into equal parts no longer than the mesh size; a grid cell belongs to the
mesh when its centre lies in a masonry block (openings are left out), and it takes that
block's material (a lintel cell is elastic). Each cell is cut into two triangles along
alternating diagonals (no preferred direction).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

import masonryfw as mf

ROLE = mf.flags("block_role")


@dataclass(frozen=True)
class WallMesh:
    """Triangles of the wall, the block each came from, and the support segments (model units, m)."""

    points: np.ndarray  # (2, nodes)
    triangles: np.ndarray  # (3, triangles)
    block: np.ndarray  # (triangles,) model block index
    supports: tuple  # ((x0, x1, y, block index, role), ...) top edges of the support blocks


def block_rectangles(model: xr.Dataset) -> np.ndarray:
    """``(block, 4)`` = x0, y0, x1, y1 of every block; a non-rectangular masonry block raises ModelError."""
    counts = model.block_node_count.values.astype(int)
    offsets = np.concatenate([[0], np.cumsum(counts)])
    owner = np.repeat(np.arange(counts.size), counts)
    x, y = model.node_x.values, model.node_y.values
    box = np.stack([
        np.minimum.reduceat(x, offsets[:-1]), np.minimum.reduceat(y, offsets[:-1]),
        np.maximum.reduceat(x, offsets[:-1]), np.maximum.reduceat(y, offsets[:-1]),
    ], axis=1)
    tol = 1e-9 * mf.model_scale(model.node_x.values, model.node_y.values)
    on_x = np.isclose(x, box[owner, 0], atol=tol) | np.isclose(x, box[owner, 2], atol=tol)
    on_y = np.isclose(y, box[owner, 1], atol=tol) | np.isclose(y, box[owner, 3], atol=tol)
    corner_ok = np.logical_and.reduceat(on_x & on_y, offsets[:-1])
    area = (box[:, 2] - box[:, 0]) * (box[:, 3] - box[:, 1])
    bad = np.nonzero(~corner_ok | ~np.isclose(area, model.block_area.values, rtol=1e-9))[0]
    masonry = np.isin(model.block_role.values, [ROLE["unit"], ROLE["lintel"]])
    bad = bad[masonry[bad]]
    if bad.size:
        raise mf.ModelError(
            f"jmm meshes walls of axis-aligned rectangular blocks; block {int(bad[0])} "
            f"(and {bad.size - 1} more) is not one"
        )
    return box


def _grid_lines(edges: np.ndarray, size: float, tol: float) -> np.ndarray:
    """Sorted unique ``edges`` with every gap split into equal parts no longer than ``size``."""
    edges = np.unique(np.round(edges / tol) * tol)
    parts = np.maximum(np.ceil(np.diff(edges) / size * (1 - 1e-6)).astype(int), 1)  # 1e-6: sizes read from data
    starts = np.repeat(edges[:-1], parts)
    steps = np.repeat(np.diff(edges) / parts, parts)
    index = np.arange(parts.sum()) - np.repeat(np.cumsum(parts) - parts, parts)
    return np.append(starts + index * steps, edges[-1])


def wall_mesh(model: xr.Dataset, size: float) -> WallMesh:
    """Mesh the masonry blocks of ``model`` with cells no larger than ``size`` (m)."""
    if not size > 0:
        raise mf.ModelError(f"jmm mesh size must be > 0, got {size}")
    box = block_rectangles(model)
    role = model.block_role.values
    masonry = np.nonzero(np.isin(role, [ROLE["unit"], ROLE["lintel"]]))[0]
    if masonry.size == 0:
        raise mf.ModelError("jmm: the model has no unit or lintel blocks to mesh")
    tol = 1e-9 * mf.model_scale(model.node_x.values, model.node_y.values)
    xs = _grid_lines(box[:, [0, 2]].ravel(), size, tol)
    ys = _grid_lines(box[masonry][:, [1, 3]].ravel(), size, tol)
    cx, cy = 0.5 * (xs[1:] + xs[:-1]), 0.5 * (ys[1:] + ys[:-1])
    owner = np.full((cy.size, cx.size), -1)
    b = masonry
    i0, i1 = np.searchsorted(cx, box[b, 0]), np.searchsorted(cx, box[b, 2])
    j0, j1 = np.searchsorted(cy, box[b, 1]), np.searchsorted(cy, box[b, 3])
    # blocks cover disjoint rectangles of cells: paint each block's index range (vectorised by cell)
    rows, cols = np.meshgrid(np.arange(cy.size), np.arange(cx.size), indexing="ij")
    ci, cj = rows.ravel(), cols.ravel()
    for k in range(b.size):  # one slice assignment per block (mesh set-up, not a hot path)
        owner[j0[k]:j1[k], i0[k]:i1[k]] = b[k]
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
    triangles = triangles.reshape(3, -1)
    gx, gy = np.meshgrid(xs, ys)
    points = np.stack([gx.ravel()[used], gy.ravel()[used]])
    support_blocks = np.nonzero(np.isin(role, [ROLE["fixed_support"], ROLE["moving_support"]]))[0]
    supports = tuple(
        (float(box[k, 0]), float(box[k, 2]), float(box[k, 3]), int(k), int(role[k])) for k in support_blocks
    )
    return WallMesh(points, triangles, np.concatenate([cell_block, cell_block]), supports)
