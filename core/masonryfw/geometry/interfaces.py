"""Contact detection between convex polygons, by sorting (no all-pairs loop).

An interface is the common part of two collinear edges of different blocks whose
outward normals are opposite (antiparallel), longer than the tolerance. One edge
may touch several edges of other blocks (a unit over two half-offset units gives
two interfaces); edges that only meet at a corner give none.

Algorithm (everything vectorised over all edges):

1. every polygon edge gets its outward unit normal ``n``; each edge is written
   on its *line* with a canonical normal ``m = +-n`` whose angle lies in
   (-90 deg, +90 deg], and a sign (+1 when ``m == n``);
2. edges are sorted by that angle and chained into direction groups (a new group
   starts where consecutive angles differ by more than ``tol / model_scale``);
   the cyclic cut of the angles is placed in their widest gap, so that edges
   near +-90 deg (bed joints) never fall on both sides of the cut;
3. within a direction group, edges are sorted by the offset of their line
   ``m_group . midpoint`` and chained into line groups (gap ``2 tol``);
4. on each line, a sweep over the edges sorted along the tangent pairs every
   +1 edge with every overlapping -1 edge (done for all lines at once with
   lexicographic counting, see :func:`_count_before`);
5. every candidate is verified exactly: different blocks, overlap length at
   least ``tol``, and the two edges' lines less than ``tol`` apart at both ends
   of the overlap.

Orientation (deterministic, documented in the docstring of
:func:`detect_interfaces`): side 0 is the block whose outward normal has angle
in (-90 deg, +90 deg]; end 0 comes first along the tangent ``t = (n_y, -n_x)``.
"""
from __future__ import annotations

import numpy as np

from ..runtime.errors import ModelError
from .polygons import model_scale, next_node, node_block


def detect_interfaces(node_x, node_y, block_node_count, *, tol=None) -> dict:
    """Find every contact segment between the polygons of a block assembly.

    Parameters
    ----------
    node_x, node_y, block_node_count
        CF ragged polygon layout (vertices block after block, counter-clockwise;
        a clockwise polygon is handled too, by the sign of its area).
    tol
        Length tolerance [m], both for collinearity (distance between the two
        edges' lines, measured at the ends of their overlap) and for the minimum
        overlap length. Default ``1e-6 * model_scale(node_x, node_y)``. Directions
        are grouped with the angle tolerance ``tol / model_scale``.

    Returns
    -------
    dict with ``blocks`` (n, 2) int64, ``x`` and ``y`` (n, 2) float64.

    Orientation: side 0 is the block whose outward normal ``n`` (pointing into
    side 1) has angle in (-90 deg, +90 deg], i.e. ``n_x > 0``, or ``n_x == 0`` and
    ``n_y > 0``, where "== 0" means within the angle tolerance (so a bed joint of
    a slightly rotated wall keeps the lower block as side 0). Hence a horizontal
    bed joint has the lower block as side 0 (n = +y), a vertical head joint the
    left block (n = +x). The end points are ordered along the tangent
    ``t = (n_y, -n_x)``: end 0 first (a bed joint left to right, a head joint top
    to bottom). The end points are vertices of the two blocks (exact copies, no
    interpolation). Rows are sorted by side-0 block, side-1 block, then position
    along the tangent.
    """
    x, y, counts = _validated_layout(node_x, node_y, block_node_count)
    scale = model_scale(x, y)
    tol = 1e-6 * scale if tol is None else float(tol)
    if not np.isfinite(tol) or tol <= 0:
        raise ModelError(f"interface tolerance tol must be a positive length, got {tol!r}")
    angle_tol = tol / scale

    edges = _edges(x, y, counts, tol)
    if edges["block"].size == 0:
        return _empty()
    _canonical_directions(edges)
    _line_groups(edges, angle_tol, tol)
    plus, minus = _candidate_pairs(edges, tol)
    keep = _verified(edges, plus, minus, tol)
    return _oriented_sorted(edges, plus[keep], minus[keep], angle_tol)


def _empty() -> dict:
    return {
        "blocks": np.zeros((0, 2), dtype=np.int64),
        "x": np.zeros((0, 2), dtype=float),
        "y": np.zeros((0, 2), dtype=float),
    }


def _validated_layout(node_x, node_y, block_node_count):
    x = np.asarray(node_x, dtype=float).ravel()
    y = np.asarray(node_y, dtype=float).ravel()
    counts = np.asarray(block_node_count).ravel()
    if x.shape != y.shape:
        raise ModelError(f"node_x has {x.size} values but node_y has {y.size}")
    if counts.size and (not np.issubdtype(counts.dtype, np.integer) and np.any(counts != np.round(counts))):
        raise ModelError("block_node_count must hold whole numbers")
    counts = counts.astype(np.int64)
    if np.any(counts < 0):
        bad = int(np.flatnonzero(counts < 0)[0])
        raise ModelError(f"block {bad}: block_node_count is negative ({counts[bad]})")
    if counts.sum() != x.size:
        raise ModelError(
            f"block_node_count sums to {int(counts.sum())} but node_x/node_y hold {x.size} vertices"
        )
    finite = np.isfinite(x) & np.isfinite(y)
    if not finite.all():
        node = int(np.flatnonzero(~finite)[0])
        raise ModelError(
            f"block {int(node_block(counts)[node])}: vertex {node} has a non-finite coordinate "
            f"({x[node]}, {y[node]})"
        )
    return x, y, counts


def _edges(x, y, counts, tol) -> dict:
    """Every polygon edge longer than ``tol``: end points, owner block, outward unit normal.

    Coordinates are shifted to the bounding-box centre so that line offsets keep
    full precision for walls far from the origin. Each edge keeps the index of its
    start and end vertex, so interface ends are exact vertex copies.
    """
    owner = node_block(counts)
    start = np.arange(x.size)
    end = next_node(counts)
    cx = 0.5 * (x.min() + x.max()) if x.size else 0.0
    cy = 0.5 * (y.min() + y.max()) if y.size else 0.0
    xs, ys = x - cx, y - cy
    # Signed area by block (bincount tolerates blocks with 0 vertices).
    cross = xs * ys[end] - xs[end] * ys
    orientation = np.where(np.bincount(owner, cross, minlength=counts.size) < 0, -1.0, 1.0)[owner]
    dx, dy = xs[end] - xs, ys[end] - ys
    length = np.hypot(dx, dy)
    keep = length > tol
    length = length[keep]
    # Outward normal of a counter-clockwise polygon: the edge direction turned by -90 deg.
    nx = orientation[keep] * dy[keep] / length
    ny = -orientation[keep] * dx[keep] / length
    return {
        "block": owner[keep],
        "v0": start[keep],
        "v1": end[keep],
        "x0": xs[keep], "y0": ys[keep], "x1": xs[end][keep], "y1": ys[end][keep],
        "nx": nx, "ny": ny,
        "x": x, "y": y,
    }


def _canonical_directions(edges: dict) -> None:
    """Canonical line normal ``m``, its angle ``psi`` and the edge's sign (+1: m is outward).

    ``m`` lies in the half-plane of angles (-90, 90] deg. The cyclic cut of the
    angles (mod 180 deg) is then moved into the widest gap between the edge
    directions, so that nearly horizontal edges (angle close to +-90 deg) are
    not split across the cut; edges below the cut are flipped (angle + 180 deg).
    """
    nx, ny = edges["nx"], edges["ny"]
    plus = (nx > 0) | ((nx == 0) & (ny > 0))
    sign = np.where(plus, 1.0, -1.0)
    mx, my = sign * nx, sign * ny
    psi = np.arctan2(my, mx)
    ordered = np.sort(psi)
    gaps = np.diff(ordered)
    wrap_gap = ordered[0] + np.pi - ordered[-1]
    if gaps.size and gaps.max() > wrap_gap:
        cut = ordered[int(np.argmax(gaps)) + 1]
        below = psi < cut
        sign[below] *= -1.0
        mx[below] *= -1.0
        my[below] *= -1.0
        psi[below] += np.pi
    edges.update(sign=sign, mx=mx, my=my, psi=psi)


def _chain_groups(sorted_values: np.ndarray, gap: float, breaks: np.ndarray | None = None) -> np.ndarray:
    """Group ids of sorted values: a new group wherever consecutive values differ by more than ``gap``."""
    new = np.empty(sorted_values.size, dtype=bool)
    new[:1] = True
    new[1:] = np.diff(sorted_values) > gap
    if breaks is not None:
        new[1:] |= breaks
    return np.cumsum(new) - 1


def _line_groups(edges: dict, angle_tol: float, tol: float) -> None:
    """Assign every edge a line id and its interval ``[lo, hi]`` along that line's tangent."""
    order = np.argsort(edges["psi"], kind="stable")
    direction = np.empty(order.size, dtype=np.int64)
    direction[order] = _chain_groups(edges["psi"][order], angle_tol)
    # Representative normal of each direction group: the normalised mean canonical normal.
    ndir = int(direction.max()) + 1
    gx = np.bincount(direction, edges["mx"], minlength=ndir)
    gy = np.bincount(direction, edges["my"], minlength=ndir)
    norm = np.hypot(gx, gy)
    gx, gy = (gx / norm)[direction], (gy / norm)[direction]
    h0 = gx * edges["x0"] + gy * edges["y0"]
    h1 = gx * edges["x1"] + gy * edges["y1"]
    s0 = gy * edges["x0"] - gx * edges["y0"]  # tangent (m_y, -m_x)
    s1 = gy * edges["x1"] - gx * edges["y1"]
    offset = 0.5 * (h0 + h1)
    order = np.lexsort((offset, direction))
    line = np.empty(order.size, dtype=np.int64)
    line[order] = _chain_groups(offset[order], 2.0 * tol, breaks=np.diff(direction[order]) != 0)
    edges.update(line=line, h0=h0, h1=h1, s0=s0, s1=s1, lo=np.minimum(s0, s1), hi=np.maximum(s0, s1))


def _count_before(major, minor, q_major, q_minor, *, inclusive: bool) -> np.ndarray:
    """For each query, how many items are lexicographically before it.

    Items ``(major, minor)`` count when ``(major, minor) < (q_major, q_minor)``
    (or ``<=`` when ``inclusive``). One joint sort of items and queries; this is
    ``searchsorted`` for keys made of an integer group and a float value.
    """
    n, m = major.size, q_major.size
    is_query = np.concatenate((np.zeros(n, dtype=bool), np.ones(m, dtype=bool)))
    tie = is_query if inclusive else ~is_query  # equal keys: queries after items when inclusive
    order = np.lexsort((tie, np.concatenate((minor, q_minor)), np.concatenate((major, q_major))))
    items_so_far = np.cumsum(~is_query[order])
    result = np.empty(m, dtype=np.int64)
    at_query = is_query[order]
    result[order[at_query] - n] = items_so_far[at_query]
    return result


def _segmented_cummax(values: np.ndarray, segment: np.ndarray) -> np.ndarray:
    """Running maximum of ``values`` restarting at every new ``segment`` id (segments sorted).

    Done exactly on integer ranks: ``segment * n + rank`` is increasing across
    segments, so one plain ``maximum.accumulate`` serves all segments.
    """
    n = values.size
    order = np.argsort(values, kind="stable")
    rank = np.empty(n, dtype=np.int64)
    rank[order] = np.arange(n)
    running = np.maximum.accumulate(segment.astype(np.int64) * n + rank) - segment.astype(np.int64) * n
    return values[order][running]


def _candidate_pairs(edges: dict, tol: float):
    """Index pairs (plus edge, minus edge) on the same line whose intervals may overlap by >= tol.

    Plus edges of each line are sorted by ``lo``; for a minus edge ``[lo, hi]``
    the candidates are the plus edges from the first whose running maximum of
    ``hi`` exceeds ``lo + tol`` up to the last whose ``lo`` is below ``hi - tol``.
    The verification step drops the few in between that do not overlap.
    """
    line, lo, hi = edges["line"], edges["lo"], edges["hi"]
    plus = np.flatnonzero(edges["sign"] > 0)
    minus = np.flatnonzero(edges["sign"] < 0)
    plus = plus[np.lexsort((lo[plus], line[plus]))]
    running_hi = _segmented_cummax(hi[plus], line[plus])
    first = _count_before(line[plus], running_hi, line[minus], lo[minus] + tol, inclusive=False)
    stop = _count_before(line[plus], lo[plus], line[minus], hi[minus] - tol, inclusive=True)
    count = np.maximum(stop - first, 0)
    pair_minus = np.repeat(minus, count)
    within = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    pair_plus = plus[np.repeat(first, count) + within]
    return pair_plus, pair_minus


def _height_at(edges: dict, e: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Offset (along the line group's normal) of edge ``e`` at tangent coordinate ``s``."""
    s0, s1 = edges["s0"][e], edges["s1"][e]
    h0, h1 = edges["h0"][e], edges["h1"][e]
    return h0 + (h1 - h0) * (s - s0) / (s1 - s0)


def _verified(edges: dict, a: np.ndarray, b: np.ndarray, tol: float) -> np.ndarray:
    """Mask of candidate pairs that really touch: other block, overlap >= tol, lines within tol."""
    lo = np.maximum(edges["lo"][a], edges["lo"][b])
    hi = np.minimum(edges["hi"][a], edges["hi"][b])
    other_block = edges["block"][a] != edges["block"][b]
    long_enough = hi - lo >= tol
    gap_lo = np.abs(_height_at(edges, a, lo) - _height_at(edges, b, lo))
    gap_hi = np.abs(_height_at(edges, a, hi) - _height_at(edges, b, hi))
    return other_block & long_enough & (gap_lo <= tol) & (gap_hi <= tol)


def _overlap_vertices(edges: dict, a: np.ndarray, b: np.ndarray):
    """Vertex indices at the two ends of the overlap of edges ``a`` and ``b``.

    The overlap starts at the larger of the two ``lo`` ends and stops at the
    smaller ``hi`` end; each of these is a vertex of one of the edges.
    """
    def vertex_at(e, use_lo):
        s0_is_lo = edges["s0"][e] <= edges["s1"][e]
        take_v0 = s0_is_lo == use_lo
        return np.where(take_v0, edges["v0"][e], edges["v1"][e])

    start = np.where(edges["lo"][a] >= edges["lo"][b], vertex_at(a, True), vertex_at(b, True))
    stop = np.where(edges["hi"][a] <= edges["hi"][b], vertex_at(a, False), vertex_at(b, False))
    return start, stop


def _oriented_sorted(edges: dict, a: np.ndarray, b: np.ndarray, angle_tol: float) -> dict:
    """Interfaces with side 0, end order and row order as documented in :func:`detect_interfaces`."""
    start, stop = _overlap_vertices(edges, a, b)
    # Pair normal from a into b, symmetric in the two edges.
    px = edges["nx"][a] - edges["nx"][b]
    py = edges["ny"][a] - edges["ny"][b]
    norm = np.hypot(px, py)
    px, py = px / norm, py / norm
    a_is_side0 = (px > angle_tol) | ((np.abs(px) <= angle_tol) & (py > 0))
    side0 = np.where(a_is_side0, edges["block"][a], edges["block"][b])
    side1 = np.where(a_is_side0, edges["block"][b], edges["block"][a])
    nx = np.where(a_is_side0, px, -px)
    ny = np.where(a_is_side0, py, -py)
    x, y = edges["x"], edges["y"]
    # Tangent t = (n_y, -n_x); end 0 comes first along t.
    along_start = ny * x[start] - nx * y[start]
    along_stop = ny * x[stop] - nx * y[stop]
    swap = along_stop < along_start
    end0 = np.where(swap, stop, start)
    end1 = np.where(swap, start, stop)
    order = np.lexsort((np.minimum(along_start, along_stop), side1, side0))
    end0, end1 = end0[order], end1[order]
    return {
        "blocks": np.stack((side0[order], side1[order]), axis=1).astype(np.int64),
        "x": np.stack((x[end0], x[end1]), axis=1),
        "y": np.stack((y[end0], y[end1]), axis=1),
    }
