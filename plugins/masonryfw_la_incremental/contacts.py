"""Contacts of a moved configuration: where a vertex of one block touches an edge of another.

Every vertex that lies within ``gap`` outside an edge of another block and at most ``overlap``
inside it, between the edge's ends, touches that edge, provided both of its own edges leave it
outwards (the block's interior is on the far side of the edge: this rejects the other edge through a
shared corner). A touching vertex is a point contact whose normal is the edge's, pointing into the
vertex's block. The point contacts of one pair of blocks along one normal are one interface whose two
ends are the extreme points along the tangent: two flush faces give the ends of their overlap, as the
model's interfaces; a corner on a face gives an interface with its two ends at the corner (a hinge); a
corner on a corner gives the faces of both corners (the corner may go into neither: blocks coming to
rest corner to corner hold each other), but none between blocks that met corner to corner in the model
and have not moved apart since (four units at a cross joint: la has no interface there either).
Joints that open by more than ``gap`` have no contact; blocks that come to touch get one.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Normals within this angle [rad] are one face; a vertex's edges may dip this much into the other block.
ANGLE_TOLERANCE = 1e-2


@dataclass(frozen=True)
class Polygons:
    """Ragged polygons (counter-clockwise): the current vertices and their blocks."""

    x: np.ndarray
    y: np.ndarray
    counts: np.ndarray
    offsets: np.ndarray  # (block + 1,)
    owner: np.ndarray  # (node,)

    @classmethod
    def of(cls, x: np.ndarray, y: np.ndarray, counts: np.ndarray) -> Polygons:
        counts = np.asarray(counts, dtype=np.int64)
        offsets = np.concatenate([[0], np.cumsum(counts)])
        return cls(x, y, counts, offsets, np.repeat(np.arange(counts.size), counts))

    def next_node(self) -> np.ndarray:
        local = np.arange(self.x.size) - self.offsets[self.owner]
        return self.offsets[self.owner] + (local + 1) % self.counts[self.owner]

    def previous_node(self) -> np.ndarray:
        local = np.arange(self.x.size) - self.offsets[self.owner]
        return self.offsets[self.owner] + (local - 1) % self.counts[self.owner]


@dataclass(frozen=True)
class Contacts:
    """Interfaces of a configuration in the layout of the model's (side 0 to side 1 normal)."""

    sides: np.ndarray  # (interface, 2)
    end_x: np.ndarray  # (interface, 2)
    end_y: np.ndarray
    normal: np.ndarray  # (interface, 2)
    tangent: np.ndarray
    length: np.ndarray
    overlap: float  # the deepest vertex inside another block [m] (0 when none)
    overlap_at: tuple[int, int]  # (vertex's block, other block) of the deepest, (-1, -1) when none


def candidate_pairs(polygons: Polygons, pad: float, skip: np.ndarray) -> np.ndarray:
    """``(pair, 2)`` blocks ``a < b`` whose boxes, grown by ``pad``, overlap; none where ``skip`` holds for both."""
    n = polygons.counts.size
    start = polygons.offsets[:-1]
    xmin, xmax = np.minimum.reduceat(polygons.x, start), np.maximum.reduceat(polygons.x, start)
    ymin, ymax = np.minimum.reduceat(polygons.y, start), np.maximum.reduceat(polygons.y, start)
    order = np.argsort(xmin, kind="stable")
    sorted_min = xmin[order]
    stop = np.searchsorted(sorted_min, xmax[order] + pad, side="right")
    count = np.maximum(stop - np.arange(n) - 1, 0)
    first = np.repeat(np.arange(n), count)
    second = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count) + first + 1
    a, b = order[first], order[second]
    near = (ymin[a] <= ymax[b] + pad) & (ymin[b] <= ymax[a] + pad) & ~(skip[a] & skip[b])
    pairs = np.sort(np.c_[a[near], b[near]], axis=1)
    return pairs


def touching_vertices(polygons: Polygons, pairs: np.ndarray, gap: float, overlap: float):
    """Every (vertex, edge of the other block) of the pairs, both ways: the touching ones and the deepest overlap."""
    vert_block = np.concatenate([pairs[:, 0], pairs[:, 1]])
    edge_block = np.concatenate([pairs[:, 1], pairs[:, 0]])
    n_edge = polygons.counts[edge_block]
    combos = polygons.counts[vert_block] * n_edge
    which = np.repeat(np.arange(vert_block.size), combos)
    k = np.arange(combos.sum()) - np.repeat(np.cumsum(combos) - combos, combos)
    vertex = polygons.offsets[vert_block][which] + k // n_edge[which]
    e0 = polygons.offsets[edge_block][which] + k % n_edge[which]
    e1 = polygons.next_node()[e0]
    x, y = polygons.x, polygons.y
    ex, ey = x[e1] - x[e0], y[e1] - y[e0]
    length = np.hypot(ex, ey)
    dx, dy = ex / length, ey / length
    nx, ny = dy, -dx  # outward normal of a counter-clockwise polygon
    px, py = x[vertex] - x[e0], y[vertex] - y[e0]
    g = px * nx + py * ny
    s = px * dx + py * dy
    # the deepest overlap: a vertex inside a convex block is behind all its edges (each group is one vertex's)
    group_start = np.flatnonzero(np.r_[True, (vertex[1:] != vertex[:-1]) | (which[1:] != which[:-1])])
    nearest_face = np.maximum.reduceat(g, group_start) if g.size else g
    inside = nearest_face < 0
    deepest = float(-nearest_face[inside].min()) if inside.any() else 0.0
    where = (-1, -1)
    if inside.any():
        g_idx = group_start[inside][np.argmin(nearest_face[inside])]
        where = (int(vert_block[which[g_idx]]), int(edge_block[which[g_idx]]))
    touch = (g <= gap) & (g >= -overlap) & (s >= -gap) & (s <= length + gap)
    touch &= leaves_outwards(polygons, vertex, nx, ny)
    at_corner = (s[touch] <= gap) | (s[touch] >= length[touch] - gap)
    return (vertex[touch], vert_block[which[touch]], edge_block[which[touch]], nx[touch], ny[touch], at_corner,
            deepest, where)


def leaves_outwards(polygons: Polygons, vertex: np.ndarray, nx: np.ndarray, ny: np.ndarray) -> np.ndarray:
    """Both edges of the vertex's own polygon point away from the face (normal ``n``) or along it."""
    ok = np.ones(vertex.size, dtype=bool)
    for other in (polygons.next_node()[vertex], polygons.previous_node()[vertex]):
        ux, uy = polygons.x[other] - polygons.x[vertex], polygons.y[other] - polygons.y[vertex]
        ok &= (ux * nx + uy * ny) >= -ANGLE_TOLERANCE * np.hypot(ux, uy)
    return ok


def find_contacts(polygons: Polygons, skip: np.ndarray, gap: float, overlap: float,
                  cornered: np.ndarray | None = None) -> Contacts:
    """The interfaces of the configuration (module docstring); ``skip``: blocks whose mutual contacts do not
    count (the supports: ground against ground); ``cornered``: sorted pair keys ``a * n + b`` whose corner-on-
    corner contacts do not count (all when None)."""
    pairs = candidate_pairs(polygons, gap, skip)
    vertex, v_block, e_block, nx, ny, at_corner, deepest, where = touching_vertices(polygons, pairs, gap, overlap)
    # side 0 the lower block index: the normal from side 0 into side 1
    flip = e_block > v_block
    side0, side1 = np.where(flip, v_block, e_block), np.where(flip, e_block, v_block)
    sign = np.where(flip, -1.0, 1.0)
    nx, ny = nx * sign, ny * sign
    angle = np.arctan2(ny, nx)
    order = np.lexsort((angle, side1, side0))
    side0, side1, angle, nx, ny, vertex, at_corner = (a[order] for a in (side0, side1, angle, nx, ny, vertex,
                                                                         at_corner))
    new = np.r_[True, (side0[1:] != side0[:-1]) | (side1[1:] != side1[:-1]) | (np.diff(angle) > ANGLE_TOLERANCE)]
    group = np.cumsum(new) - 1
    n_group = int(group[-1]) + 1 if group.size else 0
    gx = np.bincount(group, nx, n_group)
    gy = np.bincount(group, ny, n_group)
    norm = np.hypot(gx, gy)
    gx, gy = gx / norm, gy / norm
    px, py = polygons.x[vertex], polygons.y[vertex]
    along = px * gy[group] - py * gx[group]  # tangent t = (n_y, -n_x)
    lo, hi = extremes(group, along, n_group)
    end_x, end_y = np.c_[px[lo], px[hi]], np.c_[py[lo], py[hi]]
    starts = np.flatnonzero(new)
    length = np.hypot(end_x[:, 1] - end_x[:, 0], end_y[:, 1] - end_y[:, 0])
    # a corner on a corner has no face: no contact (once it slips onto a face, that face holds it)
    keep = (length > gap) | (np.bincount(group, ~at_corner, n_group) > 0)
    if cornered is not None:
        key = side0[starts] * polygons.counts.size + side1[starts]
        keep |= ~np.isin(key, cornered)
    return Contacts(
        sides=np.c_[side0[starts], side1[starts]][keep],
        end_x=end_x[keep],
        end_y=end_y[keep],
        normal=np.c_[gx, gy][keep],
        tangent=np.c_[gy, -gx][keep],
        length=length[keep],
        overlap=deepest,
        overlap_at=where,
    )


def extremes(group: np.ndarray, value: np.ndarray, n_group: int) -> tuple[np.ndarray, np.ndarray]:
    """The indices of the smallest and the largest ``value`` of every group."""
    order = np.lexsort((value, group))
    first = np.searchsorted(group[order], np.arange(n_group), side="left")
    last = np.searchsorted(group[order], np.arange(n_group), side="right") - 1
    return order[first], order[last]
