"""Geometry the comparison and the pictures need, vectorised over all blocks/interfaces.

Rigid-block kinematics follow docs/architecture.md: a block moves with the
centroid displacement ``(ux, uy)`` and the rotation ``rz`` about its centroid;
the relative motion at an interface end is side 1 minus side 0, ``opening = dv . n``
and ``slip = dv . t``.
"""
from __future__ import annotations

import numpy as np
import xarray as xr
from scipy.spatial import cKDTree

import masonryfw as mf

# Sample points per joint when a crack segment is integrated along its length
# (midpoint rule, equal weights): exact for a distance that is constant along
# the joint, and within 1/(2*16) of the joint length otherwise.
SAMPLES_PER_SEGMENT = 16


def with_geometry(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` with the derived geometry (areas, centroids, interface frames) recomputed."""
    return mf.derive_geometry(ds)


def padded_block_nodes(block_node_count: np.ndarray) -> np.ndarray:
    """(block, max_count) node indices; short polygons repeat their last vertex.

    A repeated vertex adds a zero-length edge, which changes no area, outline or
    drawing, so all polygons fit one rectangular array.
    """
    counts = np.asarray(block_node_count, dtype=np.int64)
    start = mf.block_offsets(counts)[:-1]
    columns = np.arange(counts.max(initial=1))
    return start[:, None] + np.minimum(columns[None, :], counts[:, None] - 1)


def block_polar_moment(node_x, node_y, block_node_count) -> np.ndarray:
    """Polar second moment of area of every block about its own centroid [m4].

    Shoelace sums in coordinates local to each block's first vertex (full
    precision far from the origin), moved to the centroid with the parallel-axis
    theorem. For a b x h rectangle: A (b^2 + h^2) / 12.
    """
    x = np.asarray(node_x, dtype=float)
    y = np.asarray(node_y, dtype=float)
    counts = np.asarray(block_node_count, dtype=np.int64)
    start = mf.block_offsets(counts)[:-1]
    owner = mf.node_block(counts)
    xs, ys = x - x[start][owner], y - y[start][owner]
    following = np.arange(x.size) + 1
    following[start + counts - 1] = start
    xn, yn = xs[following], ys[following]
    cross = xs * yn - xn * ys
    area = 0.5 * np.add.reduceat(cross, start)
    sx = np.add.reduceat((xs + xn) * cross, start) / 6.0  # first moments (area * centroid)
    sy = np.add.reduceat((ys + yn) * cross, start) / 6.0
    ixx = np.add.reduceat((ys * ys + ys * yn + yn * yn) * cross, start) / 12.0
    iyy = np.add.reduceat((xs * xs + xs * xn + xn * xn) * cross, start) / 12.0
    return ixx + iyy - (sx * sx + sy * sy) / area


def rigid_point_motion(displacement, centroid_x, centroid_y, px, py, owner):
    """Linearised rigid motion ``u_c + rz x (p - c)`` of points ``p`` carried by block ``owner``."""
    u = np.asarray(displacement, dtype=float)[owner]
    dx = np.asarray(px) - np.asarray(centroid_x)[owner]
    dy = np.asarray(py) - np.asarray(centroid_y)[owner]
    return u[..., 0] - u[..., 2] * dy, u[..., 1] + u[..., 2] * dx


def deformed_points(geo: xr.Dataset, displacement, amplification: float, px, py, owner):
    """Points ``p`` carried by blocks ``owner`` after the rigid motion ``amplification * displacement``.

    The rotation is applied exactly (not linearised), so amplified blocks keep
    their shape.
    """
    cx, cy = geo.block_centroid_x.values[owner], geo.block_centroid_y.values[owner]
    u = amplification * np.asarray(displacement, dtype=float)[owner]
    cos, sin = np.cos(u[..., 2]), np.sin(u[..., 2])
    dx, dy = np.asarray(px) - cx, np.asarray(py) - cy
    return cx + u[..., 0] + cos * dx - sin * dy, cy + u[..., 1] + sin * dx + cos * dy


def deformed_nodes(geo: xr.Dataset, displacement, amplification: float):
    """Block vertices after the rigid motion ``amplification * displacement``."""
    owner = mf.node_block(geo.block_node_count.values)
    return deformed_points(geo, displacement, amplification, geo.node_x.values, geo.node_y.values, owner)


def largest_vertex_motion(geo: xr.Dataset, displacement) -> float:
    """Largest (linearised) displacement of any block vertex [m]."""
    owner = mf.node_block(geo.block_node_count.values)
    ux, uy = rigid_point_motion(
        displacement, geo.block_centroid_x.values, geo.block_centroid_y.values,
        geo.node_x.values, geo.node_y.values, owner,
    )
    return float(np.max(np.hypot(ux, uy), initial=0.0))


def interface_relative_motion(geo: xr.Dataset, displacement):
    """Opening and slip (interface, end) implied by rigid block displacements."""
    blocks = geo.interface_blocks.values.astype(np.int64)
    px, py = geo.interface_x.values, geo.interface_y.values
    cx, cy = geo.block_centroid_x.values, geo.block_centroid_y.values
    u0x, u0y = rigid_point_motion(displacement, cx, cy, px, py, blocks[:, [0, 0]])
    u1x, u1y = rigid_point_motion(displacement, cx, cy, px, py, blocks[:, [1, 1]])
    dvx, dvy = u1x - u0x, u1y - u0y
    nx, ny = geo.interface_normal_x.values[:, None], geo.interface_normal_y.values[:, None]
    tx, ty = geo.interface_tangent_x.values[:, None], geo.interface_tangent_y.values[:, None]
    return dvx * nx + dvy * ny, dvx * tx + dvy * ty


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
