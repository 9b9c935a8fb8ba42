"""Where polygons come too close: two edges of one polygon meeting (:func:`self_intersections`), and blocks
that interpenetrate (:func:`overlapping_blocks`: a uniform grid of bounding boxes as the broad phase, the
separating-axis depth of convex pieces as the narrow one). Plain geometry on the ragged polygon layout of the
format; :mod:`masonryfw.format.checks` words what it finds as problems."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .boxes import box_pairs, ragged_expand
from .polygons import block_bounds, block_offsets, convex_pieces, next_node, point_segment_distance


def segment_distance(p0x, p0y, p1x, p1y, q0x, q0y, q1x, q1y):
    """Shortest distance between segments p and q (0 when they cross), and a point near the contact."""
    def side(ax, ay, bx, by, cx, cy):
        return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)

    d1 = side(q0x, q0y, q1x, q1y, p0x, p0y)
    d2 = side(q0x, q0y, q1x, q1y, p1x, p1y)
    d3 = side(p0x, p0y, p1x, p1y, q0x, q0y)
    d4 = side(p0x, p0y, p1x, p1y, q1x, q1y)
    crosses = (d1 * d2 < 0) & (d3 * d4 < 0)
    candidates = [  # (distance of an end point from the other segment, that end point)
        (point_segment_distance(p0x, p0y, q0x, q0y, q1x, q1y), p0x, p0y),
        (point_segment_distance(p1x, p1y, q0x, q0y, q1x, q1y), p1x, p1y),
        (point_segment_distance(q0x, q0y, p0x, p0y, p1x, p1y), q0x, q0y),
        (point_segment_distance(q1x, q1y, p0x, p0y, p1x, p1y), q1x, q1y),
    ]
    dist = np.stack([c[0] for c in candidates])
    which = np.argmin(dist, axis=0)
    near_x = np.choose(which, [c[1] for c in candidates])
    near_y = np.choose(which, [c[2] for c in candidates])
    with np.errstate(invalid="ignore", divide="ignore"):
        t = d1 / (d1 - d2)
        cross_x = p0x + t * (p1x - p0x)
        cross_y = p0y + t * (p1y - p0y)
    distance = np.where(crosses, 0.0, dist.min(axis=0))
    return distance, np.where(crosses, cross_x, near_x), np.where(crosses, cross_y, near_y)


def self_intersections(x, y, counts, candidates, tol):
    """Blocks (among ``candidates``, a mask) two of whose non-adjacent edges come within ``tol``, and where (a point
    of each), in block order.

    Blocks are grouped by vertex count; within a group all non-adjacent edge
    pairs of all blocks are tested at once (k(k-3)/2 pairs for k vertices).
    """
    start = block_offsets(counts)[:-1]
    blocks_out, points_out = [], []
    for k in np.unique(counts[candidates]):
        if k < 4:
            continue  # a triangle has no non-adjacent edges
        blocks = np.flatnonzero(candidates & (counts == k))
        idx = start[blocks][:, None] + np.arange(k)[None, :]
        i, j = np.triu_indices(k, 2)
        keep = ~((i == 0) & (j == k - 1))
        i, j = i[keep], j[keep]
        vx, vy = x[idx], y[idx]
        wx, wy = np.roll(vx, -1, axis=1), np.roll(vy, -1, axis=1)
        dist, px, py = segment_distance(
            vx[:, i], vy[:, i], wx[:, i], wy[:, i], vx[:, j], vy[:, j], wx[:, j], wy[:, j]
        )
        hit = dist <= tol
        rows = np.flatnonzero(hit.any(axis=1))
        first = np.argmax(hit[rows], axis=1)
        blocks_out += blocks[rows].tolist()
        points_out += [(float(px[r, c]), float(py[r, c])) for r, c in zip(rows, first)]
    order = np.argsort(blocks_out, kind="stable")
    return np.asarray(blocks_out, dtype=np.int64)[order], [points_out[o] for o in order]


def candidate_pairs(xmin, xmax, ymin, ymax, tol):
    """Pairs (a < b) of blocks whose bounding boxes, shrunk by tol, overlap (strictly: boxes that only touch
    once shrunk do not), found by the one broad phase (:func:`masonryfw.geometry.boxes.box_pairs`)."""
    low, high = np.c_[xmin, ymin] + tol, np.c_[xmax, ymax] - tol
    a, b = box_pairs(low, high)
    overlap = ((low[a] < high[b]) & (low[b] < high[a])).all(axis=1)
    return a[overlap], b[overlap]


@dataclass(frozen=True)
class ConvexPolygons:
    """Convex polygons in the ragged layout, for the separating-axis test."""

    x: np.ndarray
    y: np.ndarray
    counts: np.ndarray
    owner: np.ndarray  # block of every polygon

    @property
    def start(self) -> np.ndarray:
        return block_offsets(self.counts)[:-1]

    @property
    def next(self) -> np.ndarray:
        return next_node(self.counts)


def penetration(pieces: ConvexPolygons, a, b):
    """Separating-axis depth of convex counter-clockwise polygon b into a, over a's edge normals.

    For each edge of ``a`` (outward unit normal n, support value h = n . edge
    start) the depth is ``h - min_j n . q_j`` over the vertices q of ``b``; the
    polygons overlap by at most the smallest of these (<= 0: separated or touching).
    """
    x, y, nxt, start, counts = pieces.x, pieces.y, pieces.next, pieces.start, pieces.counts
    pair, k = ragged_expand(counts[a])
    edge = start[a][pair] + k
    ex, ey = x[nxt[edge]] - x[edge], y[nxt[edge]] - y[edge]
    length = np.hypot(ex, ey)
    nx, ny = ey / length, -ex / length
    h = nx * x[edge] + ny * y[edge]
    row, j = ragged_expand(counts[b][pair])
    vertex = start[b][pair][row] + j
    projection = nx[row] * x[vertex] + ny[row] * y[vertex]
    row_start = np.concatenate(([0], np.cumsum(counts[b][pair])[:-1]))
    depth_per_edge = h - np.minimum.reduceat(projection, row_start)
    pair_start = np.concatenate(([0], np.cumsum(counts[a])[:-1]))
    return np.minimum.reduceat(depth_per_edge, pair_start)



def overlapping_blocks(x, y, counts, blocks, tol):
    """``(p, q, depth)``: every pair of ``blocks`` (p < q) that interpenetrate by more than ``tol``, with the
    depth, ordered by p then q; bounding boxes on a grid (:func:`candidate_pairs`), then separating axes
    (:func:`penetration`). Non-convex blocks are tested through their convex pieces
    (:func:`masonryfw.geometry.polygons.convex_pieces`); two blocks overlap by the deepest overlap of any two of their
    pieces."""
    none = np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    if blocks.size < 2:
        return none
    start = block_offsets(counts)[:-1]
    nodes = np.repeat(start[blocks], counts[blocks]) + ragged_expand(counts[blocks])[1]
    px, py, pc, owner = convex_pieces(x[nodes], y[nodes], counts[blocks], tol)
    pieces = ConvexPolygons(px, py, pc, blocks[owner])
    a, b = candidate_pairs(*block_bounds(px, py, pc), tol)
    other = pieces.owner[a] != pieces.owner[b]
    a, b = a[other], b[other]
    if a.size == 0:
        return none
    depth = np.minimum(penetration(pieces, a, b), penetration(pieces, b, a))
    overlapping = depth > tol
    p_block = np.minimum(pieces.owner[a], pieces.owner[b])[overlapping]
    q_block = np.maximum(pieces.owner[a], pieces.owner[b])[overlapping]
    depth = depth[overlapping]
    order = np.lexsort((-depth, q_block, p_block))
    first = np.concatenate(([True], (np.diff(p_block[order]) != 0) | (np.diff(q_block[order]) != 0)))[:order.size]
    return p_block[order][first], q_block[order][first], depth[order][first]
