"""Geometry the comparison and the pictures need, vectorised over all blocks/interfaces.

What block results mean (relative motion, states, macro-blocks, polar moments)
is the core's (:mod:`masonryfw.results.semantics`); here are only drawing and distance helpers.
"""
from __future__ import annotations

import numpy as np
import xarray as xr
from scipy.spatial import cKDTree

import masonryfw.plugin_api as mfp

# Sample points per joint when a crack segment is integrated along its length
# (midpoint rule, equal weights): exact for a distance that is constant along
# the joint, and within 1/(2*16) of the joint length otherwise.
SAMPLES_PER_SEGMENT = 16


def padded_block_nodes(block_node_count: np.ndarray) -> np.ndarray:
    """(block, max_count) node indices; short polygons repeat their last vertex.

    A repeated vertex adds a zero-length edge, which changes no area, outline or
    drawing, so all polygons fit one rectangular array.
    """
    counts = np.asarray(block_node_count, dtype=np.int64)
    start = mfp.block_offsets(counts)[:-1]
    columns = np.arange(counts.max(initial=1))
    return start[:, None] + np.minimum(columns[None, :], counts[:, None] - 1)


def segment_samples(x, y, samples: int = SAMPLES_PER_SEGMENT):
    """Midpoint-rule points along segments (n, 2 ends) and their weights (length / samples)."""
    x = np.asarray(x, dtype=float).reshape(-1, 2)
    y = np.asarray(y, dtype=float).reshape(-1, 2)
    s = (np.arange(samples) + 0.5) / samples
    sx = x[:, :1] + (x[:, 1:] - x[:, :1]) * s[None, :]
    sy = y[:, :1] + (y[:, 1:] - y[:, :1]) * s[None, :]
    length = np.hypot(x[:, 1] - x[:, 0], y[:, 1] - y[:, 0])
    weight = np.repeat(length / samples, samples)
    return sx.ravel(), sy.ravel(), weight


def distance_to_segments(px, py, x, y, chunk_bytes: float = 32e6) -> np.ndarray:
    """Exact distance from every point to the nearest of the segments (n, 2 ends).

    Points are processed in chunks so the points x segments work array stays
    below ``chunk_bytes``.
    """
    px = np.asarray(px, dtype=float)
    py = np.asarray(py, dtype=float)
    x = np.asarray(x, dtype=float).reshape(-1, 2)
    y = np.asarray(y, dtype=float).reshape(-1, 2)
    ax, ay = x[:, 0], y[:, 0]
    ex, ey = x[:, 1] - ax, y[:, 1] - ay
    length2 = np.maximum(ex * ex + ey * ey, np.finfo(float).tiny)
    step = max(1, int(chunk_bytes // (8 * 6 * max(ax.size, 1))))
    out = np.empty(px.size)
    for lo in range(0, px.size, step):
        qx = px[lo:lo + step, None] - ax[None, :]
        qy = py[lo:lo + step, None] - ay[None, :]
        s = np.clip((qx * ex + qy * ey) / length2, 0.0, 1.0)
        out[lo:lo + step] = np.sqrt(np.min((qx - s * ex) ** 2 + (qy - s * ey) ** 2, axis=1))
    return out


def distance_to_points(px, py, tx, ty) -> np.ndarray:
    """Distance from every point ``p`` to the nearest of the points ``t`` (k-d tree)."""
    distance, _ = cKDTree(np.column_stack([tx, ty])).query(np.column_stack([px, py]))
    return distance


def vertex_motion(geo: xr.Dataset, displacement, rotations: str = "small"):
    """Motion ``(ux, uy)`` of every block vertex under block motions ``displacement`` (block, 3)."""
    owner = mfp.node_block(geo.block_node_count.values)
    return mfp.point_motion(displacement, geo.block_centroid_x.values, geo.block_centroid_y.values,
                           geo.node_x.values, geo.node_y.values, owner, rotations)


def deformed_points(geo: xr.Dataset, displacement, amplification: float, px, py, owner):
    """Points ``p`` carried by blocks ``owner`` after the rigid motion ``amplification * displacement``.

    The rotation is applied exactly (not linearised), so amplified blocks keep their shape.
    """
    ux, uy = mfp.point_motion(amplification * np.asarray(displacement, dtype=float), geo.block_centroid_x.values,
                             geo.block_centroid_y.values, px, py, owner, "finite")
    return np.asarray(px) + ux, np.asarray(py) + uy


def deformed_nodes(geo: xr.Dataset, displacement, amplification: float):
    """Block vertices after the rigid motion ``amplification * displacement``."""
    owner = mfp.node_block(geo.block_node_count.values)
    return deformed_points(geo, displacement, amplification, geo.node_x.values, geo.node_y.values, owner)


def largest_vertex_motion(geo: xr.Dataset, displacement) -> float:
    """Largest (linearised) displacement of any block vertex [m]."""
    ux, uy = vertex_motion(geo, displacement)
    return float(np.max(np.hypot(ux, uy), initial=0.0))
