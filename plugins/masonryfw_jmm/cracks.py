"""Map plastic quadrature points onto the block model's joints: ``crack_indicator``.

Each quadrature point goes to its nearest interface segment (a KD-tree of points
sampled along every interface at a quarter of the mesh size, so no point-to-segment
loop); an interface's indicator is the fraction of its points that are plastic.
"""
from __future__ import annotations

import numpy as np
import xarray as xr
from scipy.spatial import cKDTree


def nearest_interface(model: xr.Dataset, x: np.ndarray, y: np.ndarray, spacing: float) -> np.ndarray:
    """Index of the interface nearest to each point ``(x, y)`` (within ``spacing / 2`` of the true one)."""
    ix, iy = model.interface_x.values, model.interface_y.values
    length = np.hypot(ix[:, 1] - ix[:, 0], iy[:, 1] - iy[:, 0])
    samples = np.maximum(np.ceil(length / spacing).astype(int), 1) + 1
    owner = np.repeat(np.arange(length.size), samples)
    start = np.cumsum(samples) - samples
    fraction = (np.arange(samples.sum()) - np.repeat(start, samples)) / np.repeat(samples - 1, samples)
    sx = ix[owner, 0] + fraction * (ix[owner, 1] - ix[owner, 0])
    sy = iy[owner, 0] + fraction * (iy[owner, 1] - iy[owner, 0])
    _, nearest = cKDTree(np.c_[sx, sy]).query(np.c_[x, y])
    return owner[nearest]


def crack_indicator(model: xr.Dataset, x: np.ndarray, y: np.ndarray, plastic: np.ndarray,
                    spacing: float) -> np.ndarray:
    """Fraction of the quadrature points nearest to each interface that are plastic (0 if none is near)."""
    owner = nearest_interface(model, x, y, spacing)
    n = model.sizes["interface"]
    total = np.bincount(owner, minlength=n)
    hits = np.bincount(owner, weights=plastic.astype(float), minlength=n)
    return np.divide(hits, total, out=np.zeros(n), where=total > 0)
