"""A surveyor's crack map drawn from a forward result: the known answer a diagnosis is tested against.

The cracked joints of a result (the core's, at its crack threshold, or an opening wider than a width
for an incremental result) are joined into cracks (joints sharing an end), then drawn as a surveyor would:
every line offset sideways (and kept on the wall), some joints left out (gaps), short cracks missed
altogether, and a few spurious hairlines added where nothing cracked. Used by the tests and docs/diagnose.md's studies.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp


@dataclass(frozen=True)
class Surveyor:
    """How a surveyor draws cracks (lengths in unit heights h, shares in [0, 1])."""

    offset: float = 0.0  # standard deviation of each line's sideways offset [h]
    gaps: float = 0.0  # share of a crack's joints left out
    missing: float = 0.0  # cracks shorter than this many h are not drawn
    spurious: int = 0  # hairlines drawn where nothing cracked
    spurious_length: float = 2.0  # their length [h]
    jitter: float = 0.0  # standard deviation of every vertex's own displacement [h]
    width_step: float = 0.0  # widths written rounded to this [mm] (0: as measured)


def visible_cracks(result: xr.Dataset, threshold: float = mf.CRACK_THRESHOLD, width: float | None = None) -> np.ndarray:
    """Joints between masonry blocks (a surveyor draws no base gap) that ``result`` cracks: an opening or
    slip over ``width`` [m] at the last record when given, else the core's cracked joints at ``threshold``
    (:func:`masonryfw.cracked_joints`)."""
    masonry = mfp.masonry_blocks(result.block_role.values)
    inner = masonry[result.interface_blocks.values.astype(np.int64)].all(axis=1)
    if width is not None:
        motion = np.maximum(np.abs(result.interface_opening.values), np.abs(result.interface_slip.values)).max(axis=1)
        return np.flatnonzero(inner & (motion > width))
    return np.flatnonzero(inner & mf.cracked_joints(result, threshold))


def chains(result: xr.Dataset, joints: np.ndarray) -> list[np.ndarray]:
    """``joints`` grouped into cracks: connected through shared ends (to a micrometre)."""
    if joints.size == 0:
        return []
    ends = np.round(np.stack([result.interface_x.values[joints], result.interface_y.values[joints]], axis=-1), 6)
    keys = {}
    parent = list(range(joints.size))

    def root(k: int) -> int:
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    for k in range(joints.size):
        for end in map(tuple, ends[k]):
            if end in keys:
                parent[root(k)] = root(keys[end])
            else:
                keys[end] = k
    groups: dict[int, list[int]] = {}
    for k in range(joints.size):
        groups.setdefault(root(k), []).append(k)
    return [joints[np.array(members)] for members in groups.values()]


def draw(result: xr.Dataset, joints: np.ndarray, surveyor: Surveyor, rng: np.random.Generator,
         widths_mm: dict[int, float] | None = None) -> dict:
    """A GeoJSON FeatureCollection of ``joints`` (the cracked ones) drawn by ``surveyor`` (module docstring):
    one MultiLineString per crack, with its ``width_mm`` when ``widths_mm`` (per joint) is given."""
    masonry = mfp.masonry_blocks(result.block_role.values)
    xmin, xmax, ymin, ymax = mfp.block_bounds(result.node_x.values, result.node_y.values,
                                             result.block_node_count.values)
    h = float(np.median(ymax[masonry] - ymin[masonry]))
    box = (xmin[masonry].min(), xmax[masonry].max(), ymin[masonry].min(), ymax[masonry].max())
    features = []
    for chain in chains(result, joints):
        lengths = result.interface_length.values[chain]
        if lengths.sum() < surveyor.missing * h:
            continue
        drawn = chain[rng.random(chain.size) >= surveyor.gaps] if surveyor.gaps else chain
        if drawn.size == 0:
            continue
        shift = rng.normal(0.0, surveyor.offset * h, 2) if surveyor.offset else np.zeros(2)
        lines = [np.clip(np.c_[result.interface_x.values[j], result.interface_y.values[j]] + shift
                         + (rng.normal(0.0, surveyor.jitter * h, (2, 2)) if surveyor.jitter else 0.0),
                         [box[0], box[2]], [box[1], box[3]]).tolist()
                 for j in drawn]
        properties = {"name": f"crack {len(features) + 1}"}
        if widths_mm is not None:
            width = float(max(widths_mm.get(int(j), 0.0) for j in chain))
            if surveyor.width_step:  # a surveyor writes 0.5 mm steps, and never 0 for a crack seen
                width = max(surveyor.width_step, surveyor.width_step * round(width / surveyor.width_step))
            properties["width_mm"] = width
        features.append({"type": "Feature", "properties": properties,
                         "geometry": {"type": "MultiLineString", "coordinates": lines}})
    for k in range(surveyor.spurious):
        start = np.array([rng.uniform(box[0], box[1]), rng.uniform(box[2], box[3])])
        angle = rng.uniform(0.0, np.pi)
        end = start + surveyor.spurious_length * h * np.array([np.cos(angle), np.sin(angle)])
        end = np.clip(end, [box[0], box[2]], [box[1], box[3]])
        features.append({"type": "Feature", "properties": {"name": f"hairline {k + 1}"},
                         "geometry": {"type": "LineString", "coordinates": [start.tolist(), end.tolist()]}})
    return {"type": "FeatureCollection", "features": features}


def levelling(result: xr.Dataset, y: float, scale: float = 1.0, noise: float = 0.0,
              rng: np.random.Generator | None = None) -> np.ndarray:
    """``(m, 3)`` x, y, dy of a levelling along the course at height ``y``: one point at the middle of every
    masonry block the line crosses, its vertical motion (the block's ``block_displacement`` and
    ``block_rotation``, times ``scale``: the settlement for a mechanism per unit settlement) plus a normal
    error of standard deviation ``noise`` [m]."""
    masonry = np.flatnonzero(mfp.masonry_blocks(result.block_role.values))
    _, _, ymin, ymax = mfp.block_bounds(result.node_x.values, result.node_y.values, result.block_node_count.values)
    crossed = masonry[(ymin[masonry] < y) & (ymax[masonry] > y)]
    geometry = mfp.derive_geometry(result)
    x = geometry.block_centroid_x.values[crossed]
    u = result.block_displacement.values[crossed]
    dy = scale * u[:, 1]  # at the centroid's x the rotation adds nothing
    if noise:
        dy = dy + (rng or np.random.default_rng()).normal(0.0, noise, dy.size)
    order = np.argsort(x)
    return np.c_[x[order], np.full(x.size, y), dy[order]]


#: Units a random wall is built of: (length, height) [m].
UNITS = ((0.2, 0.05), (0.25, 0.065), (0.3, 0.1))


def random_wall(rng: np.random.Generator) -> dict:
    """A parametric spec of a random dry-joint wall (size, unit, bond, up to two openings with lintels), without
    supports or a profile: :func:`random_truth` adds the settlement."""
    length, height = UNITS[rng.integers(len(UNITS))]
    columns, courses = int(rng.integers(5, 11)), int(rng.integers(6, 15))
    width = columns * length
    spec = {"title": f"random wall {columns} x {courses} units", "length_unit": "m",
            "wall": {"width": width, "height": courses * height, "thickness": 0.1},
            "unit": {"length": length, "height": height},
            "bond": {"pattern": "running" if rng.random() < 0.85 else "stack",
                     "first_course": "full" if rng.random() < 0.5 else "half"},
            "material": {"unit_weight": 12000.0, "friction_angle": 21.8, "cohesion": 0.0, "tensile_strength": 0.0,
                         "young_modulus": 1.1448e9, "poisson_ratio": 0.2}}
    openings = []
    for _ in range(int(rng.integers(0, 3)) if courses >= 8 and columns >= 6 else 0):
        wide, tall = int(rng.integers(1, 3)), int(rng.integers(3, max(4, courses // 2)))
        column, course = int(rng.integers(1, columns - wide)), int(rng.integers(2, max(3, courses - tall - 1)))
        box = (column, course, column + wide, course + tall)
        if all(box[2] + 1 <= o[0] or o[2] + 1 <= box[0] or box[3] + 1 <= o[1] or o[3] + 1 <= box[1]
               for o in openings):
            openings.append(box)
    if openings:
        spec["openings"] = [{"x": a * length, "y": b * height, "width": (c - a) * length, "height": (d - b) * height,
                             "lintel_bearing": length / 2} for a, b, c, d in openings]
    return spec


def random_truth(spec: dict, rng: np.random.Generator) -> dict:
    """A random ``[settlement]`` table under a :func:`random_wall`: a step at one end (20 to 50 % of the wall), a
    Gaussian trough (axis from a quarter wall beyond either end, i from 0.15 to 1 wall length) or a tilt."""
    width, unit = spec["wall"]["width"], spec["unit"]["length"]
    family = ("step", "gaussian", "linear")[rng.integers(3)]
    if family == "gaussian":
        return {"profile": "gaussian", "center": float(rng.uniform(-0.25, 1.25) * width),
                "width": float(rng.uniform(0.15, 1.0) * width)}
    edge = round(float(rng.uniform(0.2, 0.5)) * width / unit) * unit
    left = rng.random() < 0.5
    if family == "step":
        return {"profile": "step", "start": 0.0, "end": edge} if left else {
            "profile": "step", "start": width - edge, "end": width}
    return {"profile": "linear", "start": width - edge, "end": 0.0} if left else {
        "profile": "linear", "start": edge, "end": width}


def judged(diagnosis, truth: dict, settlement: float | None = None) -> dict:
    """A diagnosis judged against the ``truth`` (a ``[settlement]`` table) it should find (docs/diagnose.md):
    what it determined (``side``, ``edge`` within two segments, ``mode``: right only where determined), the
    ``family`` of its best candidate and whether it ``claims`` one (a single family plausible), the ``place``
    (the family right and the edge within two segments), the truth ``in_plausible`` (a plausible candidate of
    its family with its side and mode and its edge within two segments) and the ``magnitude`` ratio, the
    differential settlement under the wall determined over the truth's at the ``settlement`` reached."""
    from .features import feature

    extent, segment = diagnosis.extent, diagnosis.segment
    tolerance = 2 * segment + 1e-9 * (extent[1] - extent[0])
    true = feature(truth, extent)
    determined = diagnosis.determined()
    best = diagnosis.best.table

    def alike(table: dict) -> bool:
        mine = feature(table, extent)
        return (table["profile"] == truth["profile"] and mine.side == true.side and mine.mode == true.mode
                and abs(mine.edge - true.edge) <= tolerance)

    edge = abs(determined.edge_best - true.edge) <= tolerance
    magnitude = determined.magnitude_best
    settlement = None if settlement is None else settlement * true.differential
    return {"side": determined.side == true.side, "edge": bool(edge), "mode": determined.mode == true.mode,
            "side_and_edge": determined.side == true.side and bool(edge),
            "family": best["profile"] == truth["profile"], "claims": len(determined.families) == 1,
            "place": best["profile"] == truth["profile"] and bool(edge),
            "in_plausible": any(alike(c.table) for c in diagnosis.plausible),
            "magnitude_ratio": None if magnitude is None or not settlement else magnitude / settlement,
            "true_side": true.side, "true_edge": true.edge, "true_mode": true.mode,
            "found_side": determined.side, "found_edge": determined.edge_best, "found_mode": determined.mode,
            "families": list(determined.families), "plausible": len(diagnosis.plausible)}
