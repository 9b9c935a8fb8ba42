"""How well a scenario's cracks explain a survey's (docs/diagnose.md gives the definitions).

Everything is measured on points sampled along the lines and along the joints every quarter of a unit
height ``h`` (the median masonry block height):

- a **joint is observed** when at least half of its points lie within the tolerance (default h / 2) of a
  surveyed line; a **line matches no joint** when none of its points does;
- **predicted cracks** are the joints within the masonry that the scenario's mechanism opens or slides,
  read at :data:`SURVEY_THRESHOLD` (the core's definition, :func:`masonryfw.plugin_api.indicator_at`), each point
  weighted by its joint's ``crack_indicator``;
- a point at distance d from the other side counts ``w(d) = exp(-(d / 0.7 h)^2 / 2)``: 1 on it, 0.78 half a
  joint off, 0.36 a joint (one unit height) off, 0.02 two joints off. **Recall** is the mean ``w`` of the surveyed points (how much
  of what was seen the scenario explains), **precision** the weighted mean ``w`` of the predicted points
  (how much of what it cracks was seen), the **crack score** their harmonic mean (1: every surveyed crack
  explained, nothing else cracked);
- with a levelling, the course fitted by the mechanism's motion and the ground's (:mod:`.levelling`); the
  **levelling score** (set when the candidates are ranked: it compares each fit with the best) and the
  score the geometric mean of both;
- the **magnitude**: from the levelling when there is one, else the widest surveyed crack over the
  widest opening the mechanism gives per unit settlement.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import xarray as xr

import masonryfw.plugin_api as mfp

from . import levelling

#: The distance scale of the weights, in unit heights (docs/diagnose.md: chosen so that random lines score
#: under 0.5 while a crack drawn a third of a joint off keeps 0.94 and one a whole joint off about 0.6).
SCALE = 0.7
#: The crack threshold a scenario's mechanism is read at: a survey draws hairlines of a tenth of a millimetre
#: beside cracks of centimetres, so joints moving 1 % of the mechanism's widest are cracks a surveyor shows
#: (the core's threshold, a tenth, is for pictures and comparisons of results). Measured on the 30 random
#: walls of docs/diagnose.md: with fdem's surveys the family is right in 20 of 30 at 1 % and 13 at 10 %
#: (steps 8 of 13 against 1); with la's, 24 and 26.
SURVEY_THRESHOLD = 0.01


@dataclass(frozen=True)
class Samples:
    """Points along polylines, each with the polyline it belongs to and the length it stands for."""

    xy: np.ndarray  # (n, 2)
    owner: np.ndarray  # (n,)
    length: np.ndarray  # (n,)


def sample(polylines, spacing: float) -> Samples:
    """Points at most ``spacing`` apart along every polyline (its ends included)."""
    points, owners, lengths = [], [], []
    for k, line in enumerate(polylines):
        line = np.asarray(line, dtype=float)
        for a, b in zip(line[:-1], line[1:]):
            piece = float(np.hypot(*(b - a)))
            count = max(1, int(np.ceil(piece / spacing)))
            fractions = (np.arange(count) + 0.5) / count
            points.append(a + fractions[:, None] * (b - a))
            owners.append(np.full(count, k))
            lengths.append(np.full(count, piece / count))
    if not points:
        return Samples(np.zeros((0, 2)), np.zeros(0, dtype=np.int64), np.zeros(0))
    return Samples(np.concatenate(points), np.concatenate(owners), np.concatenate(lengths))


def distances(points: np.ndarray, to: np.ndarray) -> np.ndarray:
    """Each point's distance to the nearest of ``to`` (inf when ``to`` is empty)."""
    from scipy.spatial import cKDTree

    if to.shape[0] == 0:
        return np.full(points.shape[0], np.inf)
    return cKDTree(to).query(points)[0]


@dataclass(frozen=True)
class WallJoints:
    """What scoring needs of the wall, computed once: its joints within the masonry, sampled."""

    unit_height: float
    tolerance: float
    inner: np.ndarray  # (interface,) bool: a joint between two masonry blocks
    joints: Samples  # the inner joints' points (owner: interface index)


def wall_joints(model: xr.Dataset, tolerance: float | None = None) -> WallJoints:
    role = model.block_role.values
    masonry = mfp.masonry_blocks(role)
    _, _, ymin, ymax = mfp.block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    height = float(np.median(ymax[masonry] - ymin[masonry]))
    inner = masonry[model.interface_blocks.values.astype(np.int64)].all(axis=1)
    index = np.flatnonzero(inner)
    lines = [np.c_[model.interface_x.values[i], model.interface_y.values[i]] for i in index]
    joints = sample(lines, height / 4)
    joints = Samples(joints.xy, index[joints.owner], joints.length)
    return WallJoints(height, 0.5 * height if tolerance is None else tolerance, inner, joints)


@dataclass(frozen=True)
class Observed:
    """A survey's cracks as points, and the joints they run along."""

    points: Samples
    joints: np.ndarray  # interface indices of the observed joints
    unmatched: tuple[int, ...]  # lines within the tolerance of no joint


def observe(wall: WallJoints, cracks) -> Observed:
    points = sample(cracks, wall.unit_height / 4)
    near_line = distances(wall.joints.xy, points.xy) <= wall.tolerance
    share = np.bincount(wall.joints.owner, weights=near_line * wall.joints.length, minlength=wall.inner.size)
    total = np.bincount(wall.joints.owner, weights=wall.joints.length, minlength=wall.inner.size)
    with np.errstate(invalid="ignore", divide="ignore"):
        observed = np.flatnonzero((total > 0) & (share >= 0.5 * total))
    near_joint = distances(points.xy, wall.joints.xy) <= wall.tolerance
    matched = np.bincount(points.owner, weights=near_joint, minlength=len(cracks))
    return Observed(points, observed, tuple(int(k) for k in np.flatnonzero(matched == 0)))


def weight(d: np.ndarray, scale: float) -> np.ndarray:
    return np.exp(-0.5 * (d / (SCALE * scale)) ** 2)


@dataclass(frozen=True)
class Match:
    """How well a pattern of cracked joints explains the surveyed cracks (module docstring)."""

    crack: float
    precision: float
    recall: float
    unexplained: tuple[int, ...]  # surveyed lines whose points the pattern explains less than half
    unobserved: int  # predicted cracked joints whose points were mostly not seen


@dataclass(frozen=True)
class Score(Match):
    """A scenario's match to the survey's cracks, its magnitude and its fit to the levelling."""

    magnitude: float | None
    levelling: float | None = None  # levelling score (set when the candidates are ranked), None without a levelling
    fit: levelling.Fit | None = None  # the fit to the levelling

    @property
    def total(self) -> float:
        return self.crack if self.levelling is None else float(np.sqrt(self.crack * self.levelling))


def match(wall: WallJoints, observed: Observed, indicator: np.ndarray) -> Match:
    """The crack score of joints cracked as ``indicator`` says (``(interface,)`` in [0, 1], 0: uncracked)."""
    predicted = wall.inner[wall.joints.owner] & (indicator[wall.joints.owner] > 0)
    pred_xy = wall.joints.xy[predicted]
    c = indicator[wall.joints.owner][predicted] * wall.joints.length[predicted]
    seen = weight(distances(observed.points.xy, pred_xy), wall.unit_height)
    recall = float(np.average(seen, weights=observed.points.length))
    found = weight(distances(pred_xy, observed.points.xy), wall.unit_height)
    precision = float(np.average(found, weights=c)) if c.sum() > 0 else 0.0
    crack = 2 * precision * recall / (precision + recall) if precision + recall > 0 else 0.0
    per_line = np.bincount(observed.points.owner, weights=seen * observed.points.length) / np.maximum(
        np.bincount(observed.points.owner, weights=observed.points.length), 1e-300)
    owners = wall.joints.owner[predicted]
    unseen = np.bincount(owners, weights=(found < 0.5) * c, minlength=wall.inner.size) > 0.5 * np.bincount(
        owners, weights=c, minlength=wall.inner.size)
    return Match(crack, precision, recall, tuple(int(k) for k in np.flatnonzero(per_line < 0.5)), int(unseen.sum()))


def score(wall: WallJoints, observed: Observed, result: xr.Dataset, widths_mm, levelled: np.ndarray | None = None,
          ground_rate: np.ndarray | None = None, sigma: float = 0.0) -> Score:
    """How well ``result`` (a mechanism per unit settlement) explains the survey's cracks (module docstring), and
    its fit to the levelling ``levelled`` (``x, y, dy``; the ground's rate under each point ``ground_rate``, the
    noise ``sigma``: :mod:`.levelling`) when there is one."""
    matched = match(wall, observed, mfp.indicator_at(result, SURVEY_THRESHOLD))
    magnitude, fit = None, None
    if levelled is not None:
        fit = levelling.fit(levelled[:, 2], vertical_motion(result, levelled[:, 0], levelled[:, 1]), -ground_rate, sigma)
        magnitude = fit.magnitude
    elif any(w is not None for w in widths_mm):
        opening = np.maximum(result.interface_opening.values, 0.0).max(axis=1)[wall.inner]
        widest = float(opening.max(initial=0.0))
        magnitude = 1e-3 * max(w for w in widths_mm if w is not None) / widest if widest > 0 else None
    return Score(**dataclasses.asdict(matched), magnitude=magnitude, fit=fit)


def vertical_motion(result: xr.Dataset, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The vertical motion (per unit settlement) at points, of the masonry block nearest each (by centroid among
    the blocks whose box holds the point, else the nearest centroid)."""
    masonry = np.flatnonzero(mfp.masonry_blocks(result.block_role.values))
    cx, cy = result.block_centroid_x.values[masonry], result.block_centroid_y.values[masonry]
    xmin, xmax, ymin, ymax = (b[masonry] for b in mfp.block_bounds(result.node_x.values, result.node_y.values,
                                                                   result.block_node_count.values))
    inside = (x[:, None] >= xmin) & (x[:, None] <= xmax) & (y[:, None] >= ymin) & (y[:, None] <= ymax)
    far = np.hypot(x[:, None] - cx, y[:, None] - cy) + np.where(inside, 0.0, 1e9)
    block = masonry[np.argmin(far, axis=1)]
    u = mfp.block_motion(result)
    return u[block, 1] + u[block, 2] * (x - result.block_centroid_x.values[block])
