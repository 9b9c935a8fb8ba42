"""Contacts of a moved configuration: one interface per pair of blocks that touch, by separating axes.

Two convex blocks touch when no edge of either separates them by more than ``gap``: the edge that
separates them most (or overlaps them least) is the reference face, its outward normal the contact
normal (from its block, side 0, into the other, side 1). The other block's edge that faces it most
squarely is the incident edge; the part of it that lies over the reference face (between the face's
ends) and within ``gap`` of it is the contact, whose two ends are the interface's. Two
flush faces give the ends of their overlap, as the model's interfaces; a corner on a face gives an
interface whose ends are where the incident edge comes within ``gap`` of the face, a short hinge.
Joints that open by more than ``gap`` have no contact; blocks that come to touch get one; blocks
that went into each other (by at most ``overlap``) touch on the face they overlap least across.
A corner on a corner (four units at a cross joint) gives no interface between blocks that met that
way in the model and have not moved apart since (``cornered``): la has none there either.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import masonryfw.plugin_api as mfp


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
        return mfp.next_node(self.counts)


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


def candidate_pairs(polygons: Polygons, pad: float, skip: np.ndarray, group: np.ndarray) -> np.ndarray:
    """``(pair, 2)`` polygons ``a < b`` whose boxes, grown by ``pad``, overlap (core's broad phase,
    ``mfp.box_pairs``); none of one ``group`` (the pieces of one block) and none where ``skip`` holds for both
    groups."""
    xmin, xmax, ymin, ymax = mfp.block_bounds(polygons.x, polygons.y, polygons.counts)
    a, b = mfp.box_pairs(np.c_[xmin, ymin], np.c_[xmax, ymax], pad)
    near = (group[a] != group[b]) & ~(skip[group[a]] & skip[group[b]])
    return np.c_[a[near], b[near]]


def separations(polygons: Polygons, pairs: np.ndarray):
    """Every edge of both polygons of every pair: the pair, its polygon and the other, its first node, its outward
    normal and how far the other polygon lies beyond it (the least of its vertices' signed distances)."""
    n_pair = pairs.shape[0]
    edge_block = np.concatenate([pairs[:, 0], pairs[:, 1]])
    vert_block = np.concatenate([pairs[:, 1], pairs[:, 0]])
    which = np.tile(np.arange(n_pair), 2)
    n_vert = polygons.counts[vert_block]
    combos = polygons.counts[edge_block] * n_vert
    owner = np.repeat(np.arange(edge_block.size), combos)
    k = np.arange(combos.sum()) - np.repeat(np.cumsum(combos) - combos, combos)
    e0 = polygons.offsets[edge_block][owner] + k // n_vert[owner]
    vertex = polygons.offsets[vert_block][owner] + k % n_vert[owner]
    e1 = polygons.next_node()[e0]
    x, y = polygons.x, polygons.y
    length = np.hypot(x[e1] - x[e0], y[e1] - y[e0])
    nx, ny = (y[e1] - y[e0]) / length, -(x[e1] - x[e0]) / length  # outward: counter-clockwise polygons
    g = (x[vertex] - x[e0]) * nx + (y[vertex] - y[e0]) * ny
    starts = np.flatnonzero(np.r_[True, e0[1:] != e0[:-1]] | np.r_[True, owner[1:] != owner[:-1]])
    separation = np.minimum.reduceat(g, starts) if g.size else g
    edge = e0[starts]
    side = owner[starts]
    return which[side], edge_block[side], vert_block[side], edge, nx[starts], ny[starts], separation


def find_contacts(polygons: Polygons, skip: np.ndarray, gap: float, overlap: float,
                  cornered: np.ndarray | None = None, group: np.ndarray | None = None) -> Contacts:
    """The interfaces of the configuration (module docstring) between blocks; ``group``: the block of every
    polygon (the convex pieces of a non-convex block, ``mfp.convex_pieces``; default one polygon per block);
    ``skip``: blocks whose mutual contacts do not count (the supports: ground against ground); ``cornered``:
    sorted block pair keys ``a * n + b`` whose corner-on-corner contacts do not count (none when None)."""
    group = np.arange(polygons.counts.size) if group is None else np.asarray(group)
    n_block = int(group.max(initial=-1)) + 1
    pairs = candidate_pairs(polygons, gap, skip, group)
    pair, ref_polygon, inc_polygon, edge, nx, ny, separation = separations(polygons, pairs)
    # per pair, the edge that separates most (ties: the first)
    best = np.full(pairs.shape[0], -np.inf)
    np.maximum.at(best, pair, separation)
    chosen = np.flatnonzero(separation == best[pair])
    chosen = chosen[np.unique(pair[chosen], return_index=True)[1]]
    chosen = chosen[(separation[chosen] <= gap) & (separation[chosen] >= -overlap)]
    deepest = float(-best.min(initial=0.0))  # the pair that overlaps most, across its least overlapping face
    pair, ref_polygon, inc_polygon, edge, nx, ny = (v[chosen] for v in (pair, ref_polygon, inc_polygon, edge, nx, ny))
    i0, i1 = incident_edges(polygons, inc_polygon, nx, ny)
    ref_block, inc_block = group[ref_polygon], group[inc_polygon]
    x, y = polygons.x, polygons.y
    e1 = polygons.next_node()[edge]
    length = np.hypot(x[e1] - x[edge], y[e1] - y[edge])
    tx, ty = -ny, nx  # along the reference edge, from its first node
    s0 = (x[i0] - x[edge]) * tx + (y[i0] - y[edge]) * ty
    s1 = (x[i1] - x[edge]) * tx + (y[i1] - y[edge]) * ty
    g0 = (x[i0] - x[edge]) * nx + (y[i0] - y[edge]) * ny
    g1 = (x[i1] - x[edge]) * nx + (y[i1] - y[edge]) * ny
    lo, hi = np.zeros(pair.size), np.ones(pair.size)
    for a, b, low, high in ((s0, s1, 0.0, length), (g0, g1, -np.inf, gap)):
        lo, hi = clipped(a, b, low, high, lo, hi)
    touching = lo <= hi
    if cornered is not None:
        key = np.minimum(ref_block, inc_block) * n_block + np.maximum(ref_block, inc_block)
        span = np.abs(hi - lo) * np.hypot(x[i1] - x[i0], y[i1] - y[i0])
        touching &= ~(np.isin(key, cornered) & (span <= 2 * gap))
    lo, hi = lo[touching], hi[touching]
    i0, i1, nx, ny = i0[touching], i1[touching], nx[touching], ny[touching]
    ends_x = np.c_[x[i0] + lo * (x[i1] - x[i0]), x[i0] + hi * (x[i1] - x[i0])]
    ends_y = np.c_[y[i0] + lo * (y[i1] - y[i0]), y[i0] + hi * (y[i1] - y[i0])]
    # the ends projected onto the reference face: the contact points of the face the normal is the face's
    return Contacts(
        sides=np.c_[ref_block[touching], inc_block[touching]],
        end_x=ends_x,
        end_y=ends_y,
        normal=np.c_[nx, ny],
        tangent=np.c_[ny, -nx],
        length=np.hypot(ends_x[:, 1] - ends_x[:, 0], ends_y[:, 1] - ends_y[:, 0]),
        overlap=deepest,
    )


def clipped(a: np.ndarray, b: np.ndarray, low, high, lo: np.ndarray, hi: np.ndarray):
    """Narrow the parameter intervals ``[lo, hi]`` of segments whose value runs linearly from ``a`` to ``b`` to
    where it lies within ``[low, high]``."""
    slope = b - a
    flat = np.abs(slope) < 1e-300
    with np.errstate(divide="ignore", invalid="ignore"):
        t_low, t_high = (low - a) / slope, (high - a) / slope
    enter = np.where(flat, np.where((a >= low) & (a <= high), -np.inf, np.inf), np.minimum(t_low, t_high))
    leave = np.where(flat, np.where((a >= low) & (a <= high), np.inf, -np.inf), np.maximum(t_low, t_high))
    return np.maximum(lo, enter), np.minimum(hi, leave)


def incident_edges(polygons: Polygons, block: np.ndarray, nx: np.ndarray, ny: np.ndarray):
    """The first and second node of each block's edge that faces the normal ``n`` most squarely (its outward
    normal most opposed to ``n``)."""
    counts = polygons.counts[block]
    owner = np.repeat(np.arange(block.size), counts)
    node = polygons.offsets[block][owner] + np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    nxt = polygons.next_node()[node]
    ex, ey = polygons.x[nxt] - polygons.x[node], polygons.y[nxt] - polygons.y[node]
    facing = (ey * nx[owner] - ex * ny[owner]) / np.hypot(ex, ey)  # outward normal . n
    order = np.lexsort((facing, owner))
    first = np.searchsorted(owner[order], np.arange(block.size))
    pick = node[order][first]
    return pick, polygons.next_node()[pick]
