"""The crack comparator's scores of two 3D results (same model): the 2D scores with areas for lengths, the
inertia tensor for the polar moment, and the interfaces' centroids for their segments.

- crack F1, Jaccard, overlap (weighted by interface area) and Spearman: :mod:`.scores` on ``crack_indicator``;
- macro-block ARI over the masonry blocks;
- mechanism cosine: the L2 inner product of two rigid fields over a block is ``V t_a . t_b + w_a . J w_b`` (the
  first moment about the centroid vanishes), ``J`` the block's inertia tensor about its centroid
  (:func:`masonryfw.plugin_api.second_moments`);
- locus distance: from every cracked interface's centroid (weighted by its area) to the nearest cracked
  interface centroid of the other result, both ways, over the model size.
"""
from __future__ import annotations

import numpy as np
import xarray as xr
from scipy.spatial import cKDTree

import masonryfw.plugin_api as mfp

from . import scores
from .result_scores import multiplier_values, partition_scores


def scores_3d(a: xr.Dataset, b: xr.Dataset) -> dict:
    """Every score of two 3D results read at one threshold (module docstring)."""
    geo = mfp.derive_geometry(a)
    points = np.c_[geo.node_x.values, geo.node_y.values, geo.node_z.values]
    size = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    masonry = mfp.masonry_blocks(geo.block_role.values)
    values: dict[str, float | int | None] = {"length_scale": size}
    values.update(multiplier_values(a, b))
    if "crack_indicator" in a and "crack_indicator" in b:
        ca, cb = a.crack_indicator.values.astype(float), b.crack_indicator.values.astype(float)
        values.update(scores.confusion_scores(ca > 0, cb > 0))
        values["crack_overlap"] = scores.weighted_overlap(ca, cb, geo.interface_area.values)
        values["crack_spearman"] = scores.spearman(ca, cb)
        values.update(locus_scores_3d(geo, ca > 0, cb > 0, size))
    values.update(partition_scores(a, b, masonry))
    if "block_displacement" in a and "block_displacement" in b:
        values["mechanism_cosine"] = rigid_field_cosine_3d(mfp.block_motion(a)[masonry], mfp.block_motion(b)[masonry],
                                                           geo.block_volume.values[masonry],
                                                           inertia(mfp.polyhedra_of(geo))[masonry])
    return values


def inertia(poly: mfp.Polyhedra) -> np.ndarray:
    """``(block, 3, 3)``: every block's inertia tensor about its centroid (unit density), ``tr(C) I - C``."""
    moments = mfp.second_moments(poly)
    return np.trace(moments, axis1=1, axis2=2)[:, None, None] * np.eye(3) - moments


def rigid_field_cosine_3d(u_a: np.ndarray, u_b: np.ndarray, volume: np.ndarray, tensor: np.ndarray) -> float | None:
    """Cosine of two rigid-block fields ``(block, 6)`` in L2 over the blocks' volume (module docstring)."""

    def inner(p, q):
        return float(np.sum(volume * np.einsum("bi,bi->b", p[:, :3], q[:, :3]))
                     + np.einsum("bi,bij,bj->", p[:, 3:], tensor, q[:, 3:]))

    norm = np.sqrt(inner(u_a, u_a) * inner(u_b, u_b))
    return float(np.clip(inner(u_a, u_b) / norm, -1.0, 1.0)) if norm > 0 else None


def locus_scores_3d(geo: xr.Dataset, cracked_a: np.ndarray, cracked_b: np.ndarray, size: float) -> dict:
    """Mean distance between the cracked interfaces' centroids of ``a`` and ``b``, both ways, over ``size``."""
    if not cracked_a.any() or not cracked_b.any():
        return {}
    count = geo.interface_node_count.values.astype(np.int64)
    points = mfp.interface_points(geo)
    centre = np.add.reduceat(points, mfp.block_offsets(count)[:-1], axis=0) / count[:, None]
    area = geo.interface_area.values

    def one_way(source, target):
        distance, _ = cKDTree(centre[target]).query(centre[source])
        return float(np.average(distance, weights=area[source])) / size

    a_to_b, b_to_a = one_way(cracked_a, cracked_b), one_way(cracked_b, cracked_a)
    return {"locus_distance_a_to_b": a_to_b, "locus_distance_b_to_a": b_to_a, "locus_distance": 0.5 * (a_to_b + b_to_a)}
