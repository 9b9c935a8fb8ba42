"""Vectorised polygon geometry on the CF ragged node layout.

Blocks are polygons stored block after block in ``node_x``/``node_y`` with
``block_node_count`` vertices each (counter-clockwise, first vertex not
repeated). Everything here works on all blocks at once.

Conventions (used by every solver):
- interface normal ``n`` points from side 0 into side 1 (the outward normal of
  the side-0 block's edge that carries the interface);
- interface tangent ``t = (n_y, -n_x)``: ``n`` rotated by -90 deg, so a bed
  joint (n = +y) has t = +x;
- end 0 / end 1 of an interface are its two stored end points.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # annotations only
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


def vertex_turns(node_x, node_y, block_node_count):
    """Per vertex: length of the outgoing edge, signed distance from the chord of its two neighbours
    (> 0 for a left turn) and whether the path goes on forward (no reversal)."""
    x = np.asarray(node_x, dtype=float)
    y = np.asarray(node_y, dtype=float)
    nxt = next_node(block_node_count)
    prev = np.empty_like(nxt)
    prev[nxt] = np.arange(nxt.size)
    ax, ay = x - x[prev], y - y[prev]
    bx, by = x[nxt] - x, y[nxt] - y
    chord = np.hypot(x[nxt] - x[prev], y[nxt] - y[prev])
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = (ax * by - ay * bx) / chord
    return np.hypot(bx, by), offset, ax * bx + ay * by > 0


def convex_blocks(node_x, node_y, block_node_count, tol: float = 0.0) -> np.ndarray:
    """Whether every polygon is convex: no vertex turns against the polygon's orientation by more than ``tol``.

    ``tol`` is a length: the distance of a vertex from the chord of its two neighbours.
    """
    x = np.asarray(node_x, dtype=float)
    y = np.asarray(node_y, dtype=float)
    counts = np.asarray(block_node_count, dtype=np.int64)
    offset = vertex_turns(x, y, counts)[1]
    owner = node_block(counts)
    sign = np.sign(polygon_area_centroid(x, y, counts)[0])[owner]
    reflex = np.nan_to_num(sign * offset, nan=0.0) < -tol
    return np.bincount(owner, reflex, minlength=counts.size) == 0


def triangulated(node_x, node_y, block_node_count, blocks) -> tuple[np.ndarray, np.ndarray]:
    """Triangles ``(n, 3)`` of node indices, counter-clockwise, and their block: the constrained
    Delaunay triangulation (GEOS, through shapely) of every polygon in ``blocks``, on its own vertices."""
    import shapely  # here, not at the top: most models are convex and the CLI starts faster without it

    x = np.asarray(node_x, dtype=float)
    y = np.asarray(node_y, dtype=float)
    counts = np.asarray(block_node_count, dtype=np.int64)
    blocks = np.asarray(blocks, dtype=np.int64)
    if blocks.size == 0:
        return np.zeros((0, 3), np.int64), np.zeros(0, np.int64)
    owner = node_block(counts)
    chosen = np.isin(owner, blocks)
    nodes = np.flatnonzero(chosen)
    position = {(int(owner[k]), x[k], y[k]): int(k) for k in nodes}
    present, rank = np.unique(owner[chosen], return_inverse=True)
    rings = shapely.linearrings(np.c_[x[chosen], y[chosen]], indices=rank)
    parts, which = shapely.get_parts(shapely.constrained_delaunay_triangles(shapely.polygons(rings)),
                                     return_index=True)
    block_of = present[which]
    corners = shapely.get_coordinates(shapely.get_exterior_ring(parts)).reshape(-1, 4, 2)[:, :3]
    triangles = np.array([[position[(int(b), cx, cy)] for cx, cy in corner] for b, corner in zip(block_of, corners)],
                         dtype=np.int64).reshape(-1, 3)
    tx, ty = x[triangles], y[triangles]
    clockwise = (tx[:, 1] - tx[:, 0]) * (ty[:, 2] - ty[:, 0]) - (tx[:, 2] - tx[:, 0]) * (ty[:, 1] - ty[:, 0]) < 0
    triangles[clockwise] = triangles[clockwise][:, ::-1]
    return triangles, block_of


def convex_pieces(node_x, node_y, block_node_count, tol: float = 0.0):
    """Convex counter-clockwise polygons that tile every block: ``(x, y, counts, owner)`` in the ragged layout.

    A convex block is its own piece; a non-convex one is split into the triangles
    of :func:`triangulated`, which use its vertices only. ``tol`` as in :func:`convex_blocks`.
    """
    x = np.asarray(node_x, dtype=float)
    y = np.asarray(node_y, dtype=float)
    counts = np.asarray(block_node_count, dtype=np.int64)
    convex = convex_blocks(x, y, counts, tol)
    if convex.all():
        return x, y, counts, np.arange(counts.size)
    triangles, which = triangulated(x, y, counts, np.flatnonzero(~convex))
    keep = convex[node_block(counts)]
    owner = np.concatenate((np.flatnonzero(convex), which))
    out_counts = np.concatenate((counts[convex], np.full(which.size, 3)))
    order = np.argsort(owner, kind="stable")
    px = np.concatenate((x[keep], x[triangles].ravel()))
    py = np.concatenate((y[keep], y[triangles].ravel()))
    sorted_counts = out_counts[order]
    first = np.repeat(block_offsets(out_counts)[:-1][order], sorted_counts)
    nodes = first + np.arange(sorted_counts.sum()) - np.repeat(block_offsets(sorted_counts)[:-1], sorted_counts)
    return px[nodes], py[nodes], sorted_counts, owner[order]


def model_scale(node_x, node_y) -> float:
    """Characteristic length of a model: the diagonal of its bounding box."""
    x = np.asarray(node_x, dtype=float)
    y = np.asarray(node_y, dtype=float)
    if x.size == 0:
        return 1.0
    diag = float(np.hypot(np.ptp(x), np.ptp(y)))
    return diag if diag > 0 else 1.0


def point_segment_distance(px, py, ax, ay, bx, by):
    """Distance from points p to segments ab (a degenerate segment is its point)."""
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(((px - ax) * dx + (py - ay) * dy) / length2, 0.0, 1.0)
    t = np.where(length2 > 0, t, 0.0)
    return np.hypot(ax + t * dx - px, ay + t * dy - py)


def carrying_edges(interface_x, interface_y, blocks, node_x, node_y, block_node_count) -> np.ndarray:
    """Node index of the edge of ``blocks[i]`` that interface ``i`` lies on (the nearest to both its ends).

    The edge runs from that node to the next vertex of its polygon.
    """
    ix = np.asarray(interface_x, dtype=float).reshape(-1, 2)
    iy = np.asarray(interface_y, dtype=float).reshape(-1, 2)
    x, y = np.asarray(node_x, dtype=float), np.asarray(node_y, dtype=float)
    counts = np.asarray(block_node_count, dtype=np.int64)
    blocks = np.asarray(blocks, dtype=np.int64)
    nxt = next_node(counts)
    per = counts[blocks]
    row = np.repeat(np.arange(blocks.size), per)
    edge = np.repeat(block_offsets(counts)[:-1][blocks], per) + np.arange(per.sum()) - np.repeat(
        np.cumsum(per) - per, per)
    ax, ay, bx, by = x[edge], y[edge], x[nxt[edge]], y[nxt[edge]]
    far = np.maximum(point_segment_distance(ix[row, 0], iy[row, 0], ax, ay, bx, by),
                     point_segment_distance(ix[row, 1], iy[row, 1], ax, ay, bx, by))
    order = np.lexsort((far, row))
    first = np.searchsorted(row[order], np.arange(blocks.size))
    return edge[order[np.minimum(first, max(edge.size - 1, 0))]] if edge.size else np.zeros(0, np.int64)


def interface_frame(interface_x, interface_y, side0, node_x, node_y, block_node_count):
    """Length, unit normal (from side 0 into side 1) and unit tangent of every interface.

    The normal is the outward normal of the side-0 block's edge that carries the
    interface (by the polygon's orientation), so it is right for non-convex blocks
    too, whose centroid may lie on either side of an interface's line.
    """
    ix = np.asarray(interface_x, dtype=float).reshape(-1, 2)
    iy = np.asarray(interface_y, dtype=float).reshape(-1, 2)
    dx = ix[:, 1] - ix[:, 0]
    dy = iy[:, 1] - iy[:, 0]
    length = np.hypot(dx, dy)
    with np.errstate(divide="ignore", invalid="ignore"):
        nx, ny = dy / length, -dx / length
    x, y = np.asarray(node_x, dtype=float), np.asarray(node_y, dtype=float)
    counts = np.asarray(block_node_count, dtype=np.int64)
    edge = carrying_edges(ix, iy, side0, x, y, counts)
    nxt = next_node(counts)
    ex, ey = x[nxt[edge]] - x[edge], y[nxt[edge]] - y[edge]
    area = polygon_area_centroid(x, y, counts)[0]
    outward = np.sign(area[np.asarray(side0, dtype=np.int64)])  # (ey, -ex) is outward on a counter-clockwise polygon
    flip = outward * (nx * ey - ny * ex) < 0
    nx = np.where(flip, -nx, nx)
    ny = np.where(flip, -ny, ny)
    return length, nx, ny, ny, -nx


#: Variables added by :func:`derive_planar_geometry`: recomputed on every load, never
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


def derive_planar_geometry(ds: xr.Dataset) -> xr.Dataset:
    """Return the 2D model ``ds`` with block areas, centroids, interface lengths, normals and tangents
    (:func:`masonryfw.format.derived.derive_geometry` for a model of either dimension)."""
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
            ds.interface_x.values, ds.interface_y.values, s0, ds.node_x.values, ds.node_y.values,
            ds.block_node_count.values,
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
