"""Vectorised polygon geometry on the CF ragged node layout.

Blocks are polygons stored block after block in ``node_x``/``node_y`` with
``block_node_count`` vertices each (counter-clockwise, first vertex not
repeated). Everything here works on all blocks at once.

Conventions (used by every solver):
- interface normal ``n`` points from side 0 into side 1 (the outward normal of
  the side-0 block's edge);
- interface tangent ``t = (n_y, -n_x)``: ``n`` rotated by -90 deg, so a bed
  joint (n = +y) has t = +x;
- end 0 / end 1 of an interface are its two stored end points.
"""
from __future__ import annotations

import numpy as np
import xarray as xr


def block_offsets(block_node_count: np.ndarray) -> np.ndarray:
    """Start index of every block's first node, with the total appended (length nblock + 1)."""
    counts = np.asarray(block_node_count, dtype=np.int64)
    return np.concatenate(([0], np.cumsum(counts)))


def node_block(block_node_count: np.ndarray) -> np.ndarray:
    """Block index of every node."""
    counts = np.asarray(block_node_count, dtype=np.int64)
    return np.repeat(np.arange(counts.size), counts)


def next_node(block_node_count: np.ndarray) -> np.ndarray:
    """Index of the following vertex of the same polygon, for every node (wraps around)."""
    counts = np.asarray(block_node_count, dtype=np.int64)
    start = block_offsets(counts)[:-1]
    idx = np.arange(counts.sum()) + 1
    has = counts > 0
    idx[(start + counts - 1)[has]] = start[has]
    return idx


def polygon_area_centroid(node_x, node_y, block_node_count):
    """Signed area (positive counter-clockwise) and centroid of every block.

    Coordinates are shifted by each block's vertex mean before the shoelace sum,
    so walls far from the origin keep full precision. Where the area vanishes
    (degenerate polygons, blocks with fewer than 3 vertices) the centroid is the
    vertex mean, so a validator can still say where the block is.
    """
    x = np.asarray(node_x, dtype=float)
    y = np.asarray(node_y, dtype=float)
    counts = np.asarray(block_node_count, dtype=np.int64)
    n = counts.size
    owner = node_block(counts)
    nxt = next_node(counts)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_x = np.bincount(owner, x, minlength=n) / counts
        mean_y = np.bincount(owner, y, minlength=n) / counts
        xs, ys = x - mean_x[owner], y - mean_y[owner]
        cross = xs * ys[nxt] - xs[nxt] * ys
        area = 0.5 * np.bincount(owner, cross, minlength=n)
        cx = np.bincount(owner, (xs + xs[nxt]) * cross, minlength=n) / (6 * area) + mean_x
        cy = np.bincount(owner, (ys + ys[nxt]) * cross, minlength=n) / (6 * area) + mean_y
    flat = ~np.isfinite(cx) | ~np.isfinite(cy) | (area == 0)
    return area, np.where(flat, mean_x, cx), np.where(flat, mean_y, cy)


def block_bounds(node_x, node_y, block_node_count):
    """Per-block bounding boxes ``(xmin, xmax, ymin, ymax)`` (NaN for a block without vertices)."""
    x = np.asarray(node_x, dtype=float)
    y = np.asarray(node_y, dtype=float)
    counts = np.asarray(block_node_count, dtype=np.int64)
    start = block_offsets(counts)[:-1]
    has = counts > 0
    out = []
    for values, reduce in ((x, np.minimum), (x, np.maximum), (y, np.minimum), (y, np.maximum)):
        bound = np.full(counts.size, np.nan)
        if values.size:
            bound[has] = reduce.reduceat(values, start[has])
        out.append(bound)
    return tuple(out)


def model_scale(node_x, node_y) -> float:
    """Characteristic length of a model: the diagonal of its bounding box."""
    x = np.asarray(node_x, dtype=float)
    y = np.asarray(node_y, dtype=float)
    if x.size == 0:
        return 1.0
    diag = float(np.hypot(np.ptp(x), np.ptp(y)))
    return diag if diag > 0 else 1.0


def interface_frame(interface_x, interface_y, side0_cx, side0_cy):
    """Length, unit normal (from side 0 into side 1) and unit tangent of every interface.

    The normal is perpendicular to the segment and oriented away from the side-0
    block's centroid (for convex blocks, the outward normal of its edge).
    """
    ix = np.asarray(interface_x, dtype=float).reshape(-1, 2)
    iy = np.asarray(interface_y, dtype=float).reshape(-1, 2)
    dx = ix[:, 1] - ix[:, 0]
    dy = iy[:, 1] - iy[:, 0]
    length = np.hypot(dx, dy)
    with np.errstate(divide="ignore", invalid="ignore"):
        nx, ny = dy / length, -dx / length
    mx, my = ix.mean(axis=1), iy.mean(axis=1)
    flip = nx * (mx - side0_cx) + ny * (my - side0_cy) < 0
    nx = np.where(flip, -nx, nx)
    ny = np.where(flip, -ny, ny)
    return length, nx, ny, ny, -nx


#: Variables added by :func:`derive_geometry`: recomputed on every load, never
#: trusted from a file, and left out of the content hash.
DERIVED_GEOMETRY_VARIABLES = (
    "block_area",
    "block_centroid_x",
    "block_centroid_y",
    "interface_length",
    "interface_normal_x",
    "interface_normal_y",
    "interface_tangent_x",
    "interface_tangent_y",
)


def derive_geometry(ds: xr.Dataset) -> xr.Dataset:
    """Return ``ds`` with block areas, centroids, interface lengths, normals and tangents.

    Always recomputed from the vertices: values stored in a file are never trusted.
    """
    area, cx, cy = polygon_area_centroid(ds.node_x.values, ds.node_y.values, ds.block_node_count.values)
    out = ds.assign(
        block_area=("block", area, {"units": "m2", "long_name": "block area (derived)"}),
        block_centroid_x=("block", cx, {"units": "m", "long_name": "block centroid x (derived)"}),
        block_centroid_y=("block", cy, {"units": "m", "long_name": "block centroid y (derived)"}),
    )
    if "interface_blocks" in ds and ds.sizes.get("interface", 0) > 0:
        side0 = ds.interface_blocks.values[:, 0].astype(np.int64)
        ok = (side0 >= 0) & (side0 < cx.size)
        s0 = np.where(ok, side0, 0)
        length, nx, ny, tx, ty = interface_frame(
            ds.interface_x.values, ds.interface_y.values, cx[s0], cy[s0]
        )
        nx, ny, tx, ty = (np.where(ok, a, np.nan) for a in (nx, ny, tx, ty))
    else:
        length = nx = ny = tx = ty = np.zeros(ds.sizes.get("interface", 0))
    dims = ("interface",)
    return out.assign(
        interface_length=(dims, length, {"units": "m", "long_name": "interface length (derived)"}),
        interface_normal_x=(dims, nx, {"units": "1", "long_name": "interface unit normal x, side 0 to side 1 (derived)"}),
        interface_normal_y=(dims, ny, {"units": "1", "long_name": "interface unit normal y, side 0 to side 1 (derived)"}),
        interface_tangent_x=(dims, tx, {"units": "1", "long_name": "interface unit tangent x = n_y (derived)"}),
        interface_tangent_y=(dims, ty, {"units": "1", "long_name": "interface unit tangent y = -n_x (derived)"}),
    )
