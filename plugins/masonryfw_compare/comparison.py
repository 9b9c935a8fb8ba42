"""The ``crack`` comparator: agreement scores of two results of the same model.

Scores (each present only where both results carry what it needs; see
docs/agreement.md for the definitions and the choice of the threshold):

- ``crack_indicator`` (per interface): counts, precision, recall, F1 and Jaccard
  of the cracked sets (the core's, at ``threshold``), the length-weighted overlap
  ``sum(L min) / sum(L max)`` and the Spearman rank correlation of the indicators;
- ``macro_block``: adjusted Rand index of the two partitions of the masonry blocks;
- ``block_displacement``: cosine of the two rigid displacement fields;
- the failure locus (cracked joints, or plastic points of a continuum result):
  mean distance from one locus to the other, normalised by the model size.

Result ``a`` is the reference: precision is the share of ``b``'s cracks that ``a``
also has.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from . import comparison3d, scores
from .result_scores import multiplier_values, partition_scores
from .shapes import distance_to_points, distance_to_segments, segment_samples

# Model variables that must be present to tell two models apart and to score them, in 2D and in 3D.
GEOMETRY_VARIABLES = (
    "node_x", "node_y", "block_node_count", "block_role",
    "interface_blocks", "interface_x", "interface_y",
)
GEOMETRY_VARIABLES_3D = (
    "node_x", "node_y", "node_z", "block_node_count", "block_face_count", "face_node_count", "face_nodes",
    "block_role", "interface_blocks", "interface_node_count", "interface_node_x", "interface_node_y",
    "interface_node_z",
)


def _first_difference(a: np.ndarray, b: np.ndarray) -> int | None:
    """Index (flat) of the first element that differs beyond round-off, or None."""
    if a.dtype.kind == "f" or b.dtype.kind == "f":
        a, b = a.astype(float), b.astype(float)
        tol = 1e-9 * max(np.max(np.abs(a), initial=0.0), np.max(np.abs(b), initial=0.0))
        differs = ~(np.abs(a - b) <= tol)
    else:
        differs = a != b
    hits = np.flatnonzero(differs)
    return int(hits[0]) if hits.size else None


def _different_models(a: xr.Dataset, b: xr.Dataset, detail: str) -> mf.ModelError:
    """The refusal, with the recorded model hashes when both results carry them."""
    message = f"cannot compare results of different models: {detail}"
    hashes = a.attrs.get("model_sha256"), b.attrs.get("model_sha256")
    if all(hashes):
        message += f" (model_sha256 {hashes[0][:12]}... vs {hashes[1][:12]}...)"
    return mf.ModelError(message)


def ensure_same_model(a: xr.Dataset, b: xr.Dataset) -> None:
    """Refuse (ModelError) two results that were not computed on the same model.

    Compares the block, node and interface counts, then every model variable
    both results hold (geometry, roles, materials, loads, supports) value by value.
    """
    in_3d = mfp.space(a) == 3
    if mfp.space(b) != mfp.space(a):
        raise _different_models(a, b, f"a {mfp.space(a)}D and a {mfp.space(b)}D model")
    for which, ds in (("a", a), ("b", b)):
        missing = [n for n in (GEOMETRY_VARIABLES_3D if in_3d else GEOMETRY_VARIABLES) if n not in ds]
        if missing:
            raise mf.ModelError(f"result {which} has no {', '.join(missing)}: it holds no model to compare")
    for dim in ("block", "node", "interface"):
        if a.sizes.get(dim, 0) != b.sizes.get(dim, 0):
            raise _different_models(
                a, b, f"{a.sizes.get(dim, 0)} vs {b.sizes.get(dim, 0)} {dim}s "
                f"({a.attrs.get('title', '?')!r} vs {b.attrs.get('title', '?')!r})",
            )
    for name in mfp.load_schema("model3d" if in_3d else "model")["variables"]:
        if name not in a or name not in b:
            continue
        va, vb = np.asarray(a[name].values), np.asarray(b[name].values)
        if va.shape != vb.shape:
            raise _different_models(a, b, f"{name} has shape {va.shape} vs {vb.shape}")
        where = _first_difference(va.ravel(), vb.ravel())
        if where is not None:
            index = np.unravel_index(where, va.shape)
            at = ", ".join(f"{d} {i}" for d, i in zip(a[name].dims, index))
            raise _different_models(a, b, f"{name} differs at {at} ({va.ravel()[where].item()!r} vs {vb.ravel()[where].item()!r})")


def interface_scores(a: xr.Dataset, b: xr.Dataset, length: np.ndarray) -> dict:
    """Scores on ``crack_indicator`` (derived at the comparison's threshold): the cracked sets' scores and
    the scores of the indicators themselves."""
    if "crack_indicator" not in a or "crack_indicator" not in b:
        return {}
    ca = a.crack_indicator.values.astype(float)
    cb = b.crack_indicator.values.astype(float)
    out = scores.confusion_scores(ca > 0, cb > 0)
    out["crack_overlap"] = scores.weighted_overlap(ca, cb, length)
    out["crack_spearman"] = scores.spearman(ca, cb)
    return out


def mechanism_scores(a: xr.Dataset, b: xr.Dataset, geo: xr.Dataset, masonry: np.ndarray) -> dict:
    """Cosine of the rigid displacement fields over the masonry blocks."""
    if "block_displacement" not in a or "block_displacement" not in b:
        return {}
    area = geo.block_area.values
    polar = mfp.polar_moment(geo.node_x.values, geo.node_y.values, geo.block_node_count.values)
    return {
        "mechanism_cosine": scores.rigid_field_cosine(
            mfp.block_motion(a)[masonry], mfp.block_motion(b)[masonry], area[masonry], polar[masonry],
        )
    }


@dataclass(frozen=True)
class Locus:
    """Where a result fails: weighted sample points and, for joints, the segments themselves."""

    x: np.ndarray
    y: np.ndarray
    weight: np.ndarray
    segments_x: np.ndarray | None = None
    segments_y: np.ndarray | None = None

    def distance_from(self, px: np.ndarray, py: np.ndarray) -> np.ndarray:
        """Distance from each point to the nearest element of this locus."""
        if self.segments_x is not None:
            return distance_to_segments(px, py, self.segments_x, self.segments_y)
        return distance_to_points(px, py, self.x, self.y)


def failure_locus(ds: xr.Dataset) -> Locus | None:
    """Plastic points (qp_failure != 0) of a continuum result, else its cracked joints; None if empty.

    Joints are sampled along their length (midpoint rule) and weighted by length,
    so a long crack counts more than a short one.
    """
    if "qp_failure" in ds:
        plastic = ds.qp_failure.values != mfp.flags("qp_failure")["elastic"]
        if not plastic.any():
            return None
        x, y = ds.qp_x.values[plastic], ds.qp_y.values[plastic]
        return Locus(x, y, np.ones(x.size))
    if "crack_indicator" not in ds:
        return None
    cracked = ds.crack_indicator.values > 0
    if not cracked.any():
        return None
    sx, sy = ds.interface_x.values[cracked], ds.interface_y.values[cracked]
    x, y, weight = segment_samples(sx, sy)
    return Locus(x, y, weight, sx, sy)


def locus_scores(a: xr.Dataset, b: xr.Dataset, size: float) -> dict:
    """Mean distance between the failure loci, both ways and averaged, over the model size."""
    la, lb = failure_locus(a), failure_locus(b)
    if la is None or lb is None:
        return {}
    a_to_b = float(np.average(lb.distance_from(la.x, la.y), weights=la.weight)) / size
    b_to_a = float(np.average(la.distance_from(lb.x, lb.y), weights=lb.weight)) / size
    return {
        "locus_distance_a_to_b": a_to_b,
        "locus_distance_b_to_a": b_to_a,
        "locus_distance": 0.5 * (a_to_b + b_to_a),
    }


def comparison_variables(values: Mapping[str, float | int | None]) -> xr.Dataset:
    """One scalar variable per computable score (None = not computable, left out), attributes from the schema.

    The core (:func:`masonryfw.compare`) adds the global attributes: comparator,
    options, the inputs' hashes and the history line.
    """
    spec = mfp.load_schema("comparison")["variables"]
    data = {}
    for name, value in values.items():
        if value is None:
            continue
        attrs = {key: spec[name][key] for key in ("units", "long_name", "comment") if key in spec[name]}
        dtype = np.int64 if spec[name]["dtype"] == "int" else np.float64
        data[name] = xr.Variable((), np.asarray(value, dtype=dtype), attrs)
    return xr.Dataset(data)


def compare(a: xr.Dataset, b: xr.Dataset, options: Mapping[str, Any]) -> xr.Dataset:
    """Score result ``b`` against result ``a`` (same model), both read at the option ``threshold``
    (:func:`masonryfw.at_threshold`); returns the score variables."""
    ensure_same_model(a, b)
    a, b = mf.at_threshold(a, options["threshold"]), mf.at_threshold(b, options["threshold"])
    if mfp.space(a) == 3:
        return comparison_variables(comparison3d.scores_3d(a, b))
    geo = mfp.derive_geometry(a[list(GEOMETRY_VARIABLES)])
    masonry = mfp.masonry_blocks(geo.block_role.values)
    size = mfp.model_scale(geo.node_x.values, geo.node_y.values)
    values: dict[str, float | int | None] = {"length_scale": size}
    values.update(multiplier_values(a, b))
    values.update(interface_scores(a, b, geo.interface_length.values))
    values.update(partition_scores(a, b, masonry))
    values.update(mechanism_scores(a, b, geo, masonry))
    values.update(locus_scores(a, b, size))
    return comparison_variables(values)
