"""Settlement profiles: the ``[settlement]`` table of a spec cut into moving and fixed support segments.

A profile gives the rate ``r(x)`` at which the ground under the wall settles
per unit of the settlement parameter ``t`` (for a trough, ``t`` is ``S_max``):

- ``gaussian``: a greenfield trough (Peck 1969), ``r = exp(-(x - x0)^2 / (2 i^2))``
  with ``center`` x0 and ``width`` i (the distance from the axis to the
  inflection point); with ``depth`` z0 the ground also moves towards the axis
  (O'Reilly & New 1982): horizontal ``-(x - x0) / z0`` times the vertical rate;
- ``linear``: a tilt, ``r = (x - start) / (end - start)``, 0 before ``start``
  (defaults: the wall's left end and its right end, so r = 1 at the right end);
- ``table``: measured rates ``points = [[x, r], ...]``, linearly interpolated,
  constant beyond the first and last points.

The base ``[0, wall width]`` is cut into ``round(width / segment)`` equal
segments (at least one). A segment is evaluated at ``x_mid``, the midpoint of
its contact with the masonry (a door leaves part of the base bare; a segment
with no masonry on it gets no support block); it stays fixed when its rate is at
most ``cutoff`` (default 0.01), and adjacent fixed segments merge into one.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import SpecError
from .spec import SpecTable

PROFILES = ("gaussian", "linear", "table")
SETTLEMENT_KEYS = ("profile", "center", "width", "start", "end", "points", "segment", "cutoff", "depth")
#: A segment whose rate is at most this stays fixed unless ``cutoff`` says otherwise.
DEFAULT_CUTOFF = 0.01
_ONLY = {"center": ("gaussian",), "width": ("gaussian",), "depth": ("gaussian",),
         "start": ("linear",), "end": ("linear",), "points": ("table",)}


@dataclass(frozen=True)
class Profile:
    """A validated ``[settlement]`` table, lengths in metres."""

    kind: str
    segment: float
    cutoff: float
    center: float = 0.0
    width: float = 1.0
    depth: float | None = None
    start: float = 0.0
    end: float = 1.0
    points: tuple[tuple[float, float], ...] = ()

    def rate(self, x: np.ndarray) -> np.ndarray:
        """Vertical settlement rate at ``x`` (per unit of the settlement parameter)."""
        x = np.asarray(x, dtype=float)
        if self.kind == "gaussian":
            return np.exp(-0.5 * ((x - self.center) / self.width) ** 2)
        if self.kind == "linear":
            return np.maximum((x - self.start) / (self.end - self.start), 0.0)
        px, pr = np.array(self.points).T
        return np.interp(x, px, pr)

    def horizontal(self, x: np.ndarray) -> np.ndarray:
        """Horizontal ground motion per unit of the settlement parameter (towards the trough's axis)."""
        x = np.asarray(x, dtype=float)
        if self.depth is None:
            return np.zeros_like(x)
        return -(x - self.center) / self.depth * self.rate(x)


@dataclass(frozen=True)
class Segment:
    """One support block under the wall: its range, and its motion per unit settlement parameter."""

    start: float
    end: float
    x_mid: float  # midpoint of the masonry resting on it
    rate: float  # vertical, 0 when fixed
    horizontal: float

    @property
    def moving(self) -> bool:
        return self.rate > 0


def read_profile(top: SpecTable, wall_width: float) -> Profile:
    """The ``[settlement]`` table of a spec (``top``: the whole spec, with its length scale)."""
    table = top.sub("settlement", SETTLEMENT_KEYS)
    kind = table.choice("profile", PROFILES)
    for key, kinds in _ONLY.items():
        if table.has(key) and kind not in kinds:
            raise SpecError(f"spec key {table.key(key)!r} only applies to profile = "
                            f"{' or '.join(map(repr, kinds))}")
    segment = table.number("segment", length=True, positive=True)
    cutoff = table.number("cutoff", DEFAULT_CUTOFF, minimum=0.0)
    if kind == "gaussian":
        return Profile(kind, segment, cutoff, center=table.number("center", length=True),
                       width=table.number("width", length=True, positive=True),
                       depth=table.number("depth", None, length=True, positive=True))
    if kind == "linear":
        start = table.number("start", 0.0, length=True)
        end = table.number("end", wall_width / top.scale, length=True)
        if abs(end - start) <= 1e-9 * wall_width:
            raise SpecError(f"spec keys {table.key('start')!r} and {table.key('end')!r}: must differ "
                            "(the rate grows from 0 at start to 1 at end)")
        return Profile(kind, segment, cutoff, start=start, end=end)
    return Profile(kind, segment, cutoff, points=_table_points(table))


def _table_points(table: SpecTable) -> tuple[tuple[float, float], ...]:
    raw = table.raw("points")
    shown = f"spec key {table.key('points')!r}"
    if (not isinstance(raw, list) or len(raw) < 2
            or any(not isinstance(p, list) or len(p) != 2 for p in raw)
            or any(isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)
                   for p in raw for v in p)):
        raise SpecError(f"{shown} = {raw!r}: must be at least two pairs [x, rate] of numbers")
    x = np.array([p[0] for p in raw], dtype=float) * table.scale
    rate = np.array([p[1] for p in raw], dtype=float)
    if np.any(np.diff(x) <= 0):
        bad = int(np.flatnonzero(np.diff(x) <= 0)[0]) + 1
        raise SpecError(f"{shown}: point {bad} ({raw[bad]!r}) must lie right of the one before (x increasing)")
    if np.any(rate < 0):
        bad = int(np.flatnonzero(rate < 0)[0])
        raise SpecError(f"{shown}: point {bad} ({raw[bad]!r}) has a negative rate (the ground settles: rate >= 0)")
    return tuple(zip(x.tolist(), rate.tolist()))


def contact_midpoints(edges: np.ndarray, base: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per segment ``[edges[k], edges[k+1]]``: the length and midpoint of its overlap with the ``base``
    intervals ``(n, 2)`` (the masonry's bottom edges); midpoint nan where nothing rests on it."""
    a, b = edges[:-1, None], edges[1:, None]
    lo, hi = np.maximum(a, base[:, 0]), np.minimum(b, base[:, 1])
    piece = np.maximum(hi - lo, 0.0)
    length = piece.sum(axis=1)
    moment = (piece * 0.5 * (lo + hi)).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return length, np.where(length > 0, moment / length, np.nan)


def profile_segments(profile: Profile, width: float, base: np.ndarray) -> list[Segment]:
    """The support segments of a profile under a wall of ``width`` whose masonry rests on the ``base``
    intervals (module docstring): moving segments one by one, adjacent fixed ones merged."""
    count = max(1, round(width / profile.segment))
    edges = np.linspace(0.0, width, count + 1)
    length, mid = contact_midpoints(edges, base)
    tol = 1e-9 * width
    segments: list[Segment] = []
    for k in np.flatnonzero(length > tol):
        rate = float(profile.rate(mid[k]))
        if rate <= profile.cutoff:
            last = segments[-1] if segments else None
            if last is not None and not last.moving and abs(last.end - edges[k]) <= tol:
                joined = (last.end - last.start) + (edges[k + 1] - edges[k])
                segments[-1] = Segment(last.start, float(edges[k + 1]), last.start + 0.5 * joined, 0.0, 0.0)
            else:
                segments.append(Segment(float(edges[k]), float(edges[k + 1]), float(mid[k]), 0.0, 0.0))
            continue
        segments.append(Segment(float(edges[k]), float(edges[k + 1]), float(mid[k]), rate,
                                float(profile.horizontal(mid[k]))))
    if not any(s.moving for s in segments):
        raise SpecError(f"spec table 'settlement': every segment's rate is at most the cutoff {profile.cutoff:g}: "
                        "nothing settles under the wall (move the profile under it or lower the cutoff)")
    return segments
