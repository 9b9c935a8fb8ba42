"""Settlement profiles: the ``[settlement]`` table of a spec cut into moving and fixed support segments.

A profile gives the rate ``r(x)`` at which the ground under the wall settles
per unit of the settlement parameter ``t`` (for a trough, ``t`` is ``S_max``):

- ``gaussian``: a greenfield trough (Peck 1969), ``r = exp(-(x - x0)^2 / (2 i^2))``
  with ``center`` x0 and ``width`` i (the distance from the axis to the
  inflection point); with ``depth`` z0 the ground also moves towards the axis
  (O'Reilly & New 1982): horizontal ``-(x - x0) / z0`` times the vertical rate;
- ``tunnel``: the same trough from the tunnel's parameters (Mair, Taylor & Burland
  1996): ``volume_loss`` V_L [%], ``diameter`` D, ``depth`` z0 of its axis,
  ``trough_width_factor`` K (default 0.5), ``center``, ``horizontal`` (default
  true): ``i = K z0`` and ``S_max = V_L / 100 pi D^2 / 4 / (sqrt(2 pi) i)``, which
  the model records as its ``settlement_target`` (t is S_max);
- ``linear``: a tilt, ``r = (x - start) / (end - start)``, 0 before ``start``
  (defaults: the wall's left end and its right end, so r = 1 at the right end);
- ``table``: measured rates ``points = [[x, r], ...]``, linearly interpolated,
  constant beyond the first and last points;
- ``step``: the ground under ``[start, end]`` drops at rate 1 and the rest stays
  (the paper's loading): not continuous but a step at each end; a segment settles,
  translating, when its middle lies in ``[start, end]``.

**The ground is continuous.** The base ``[0, wall width]`` is cut into
``round(width / segment)`` equal segments (at least one); ``segment`` defaults to
a quarter of the unit length (``DEFAULT_SEGMENT_UNITS``: where the widest crack has
converged to within 10 %, docs/settlements.md). The ground's motion is known at the segment ends (the
*nodes*): the profile's rate there less ``cutoff`` c (default 0.01), over ``1 - c``,
and 0 where the rate is at most c: the far field stays still, the ground joins it
without a step or a ramp, a rate of 1 stays 1 (t is still S_max), and the ground
is within c of the profile everywhere. Every
segment moves as a rigid block whose top edge follows the straight line between
its two nodes: it translates and rotates (small rotations), and two
neighbouring segments meet at their common node at every settlement; the
imposed ground is the piecewise-linear interpolation of the profile (error
``O(segment^2)`` times its curvature). A segment whose two nodes both stay
still is fixed, and adjacent fixed segments merge; a segment with no masonry on
it (under a door) gets no block.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..format.schema import variable_attrs
from ..readers.spec import SpecTable, is_finite_number
from ..runtime.errors import SpecError

if TYPE_CHECKING:  # annotations only
    import xarray as xr

PROFILES = ("gaussian", "tunnel", "linear", "table", "step")
SETTLEMENT_KEYS = ("profile", "center", "width", "start", "end", "points", "segment", "cutoff", "depth",
                   "volume_loss", "diameter", "trough_width_factor", "horizontal")
#: A segment whose rate is at most this stays fixed unless ``cutoff`` says otherwise.
DEFAULT_CUTOFF = 0.01
#: The default segment length in unit lengths (the convergence study of docs/settlements.md).
DEFAULT_SEGMENT_UNITS = 0.25
#: The finest ground: a hundredth of a unit length (the damage converged at a quarter unit, docs/settlements.md; a
#: segment of 1e-5 m under a 1.1 m wall took 23 GB).
MAX_SEGMENTS_PER_UNIT = 100
#: K, the trough width factor of a tunnel (i = K z0) when the spec does not give it: clays (Mair et al. 1996).
DEFAULT_TROUGH_WIDTH_FACTOR = 0.5
_TUNNEL_ONLY = ("volume_loss", "diameter", "trough_width_factor", "horizontal")
_ONLY = {"center": ("gaussian", "tunnel"), "width": ("gaussian",), "depth": ("gaussian", "tunnel"),
         "start": ("linear", "step"), "end": ("linear", "step"), "points": ("table",),
         **{k: ("tunnel",) for k in _TUNNEL_ONLY}}


@dataclass(frozen=True)
class Profile:
    """A validated ``[settlement]`` table, lengths in metres."""

    kind: str
    segment: float
    cutoff: float
    center: float = 0.0
    width: float = 1.0  # i
    depth: float | None = None  # z0: with it (and ``sideways``), the ground also moves towards the axis
    start: float = 0.0
    end: float = 1.0
    points: tuple[tuple[float, float], ...] = ()
    sideways: bool = True
    target: float | None = None  # the settlement expected [m] (a tunnel's S_max)
    volume_loss: float | None = None  # a tunnel's V_L [%], D [m] and K, as given
    diameter: float | None = None
    trough_width_factor: float | None = None

    def rate(self, x: np.ndarray) -> np.ndarray:
        """Vertical settlement rate at ``x`` (per unit of the settlement parameter)."""
        x = np.asarray(x, dtype=float)
        if self.kind in ("gaussian", "tunnel"):
            return np.exp(-0.5 * ((x - self.center) / self.width) ** 2)
        if self.kind == "linear":
            return np.maximum((x - self.start) / (self.end - self.start), 0.0)
        if self.kind == "step":
            return ((x >= self.start) & (x <= self.end)).astype(float)
        px, pr = np.array(self.points).T
        return np.interp(x, px, pr)

    def horizontal(self, x: np.ndarray) -> np.ndarray:
        """Horizontal ground motion per unit of the settlement parameter (towards the trough's axis)."""
        x = np.asarray(x, dtype=float)
        if self.depth is None or not self.sideways:
            return np.zeros_like(x)
        return -(x - self.center) / self.depth * self.rate(x)


@dataclass(frozen=True)
class Segment:
    """One support block under the wall: its range and the ground's motion at its two ends (the nodes), per
    unit settlement parameter: downward rate and horizontal motion (x positive), 0 where the ground is still."""

    start: float
    end: float
    down: tuple[float, float]
    horizontal: tuple[float, float]

    @property
    def moving(self) -> bool:
        return max(self.down) > 0


def read_profile(table: SpecTable, x0: float, x1: float, unit_length: float, ground: float | None = None) -> Profile:
    """A spec's ``[settlement]`` table (with its length scale) under a wall from ``x0`` to ``x1`` [m]; ``segment``
    defaults to :data:`DEFAULT_SEGMENT_UNITS` unit lengths and is checked against the length of ``ground`` it
    cuts (``x1 - x0`` unless given: a building's longest wall)."""
    kind = table.choice("profile", PROFILES)
    for key, kinds in _ONLY.items():
        if table.has(key) and kind not in kinds:
            raise SpecError(f"spec key {table.key(key)!r} only applies to profile = "
                            f"{' or '.join(map(repr, kinds))}")
    segment = table.number("segment", DEFAULT_SEGMENT_UNITS * unit_length / table.scale, length=True, positive=True)
    segment_count(x1 - x0 if ground is None else ground, segment, unit_length, f"spec key {table.key('segment')!r}")
    cutoff = table.number("cutoff", DEFAULT_CUTOFF, minimum=0.0, below=1.0)
    if kind == "gaussian":
        return Profile(kind, segment, cutoff, center=table.number("center", length=True),
                       width=table.number("width", length=True, positive=True),
                       depth=table.number("depth", None, length=True, positive=True))
    if kind == "tunnel":
        return _tunnel(table, segment, cutoff)
    if kind == "step":
        start, end = table.number("start", length=True), table.number("end", length=True)
        if not end > start:
            raise SpecError(f"spec key {table.key('end')!r} = {table.raw('end')!r}: must exceed "
                            f"{table.key('start')!r} = {table.raw('start')!r}")
        return Profile(kind, segment, cutoff, start=start, end=end)
    if kind == "linear":
        start = table.number("start", x0 / table.scale, length=True)
        end = table.number("end", x1 / table.scale, length=True)
        if abs(end - start) <= 1e-9 * (x1 - x0):
            raise SpecError(f"spec keys {table.key('start')!r} and {table.key('end')!r}: must differ "
                            "(the rate grows from 0 at start to 1 at end)")
        return Profile(kind, segment, cutoff, start=start, end=end)
    return Profile(kind, segment, cutoff, points=_table_points(table))


def settlement_profile(table: dict, x0: float, x1: float, unit_length: float) -> Profile:
    """A ``[settlement]`` table given as a dict in metres (what a spec holds, what a diagnosis proposes) under a
    wall from ``x0`` to ``x1``, checked like a spec's (a :class:`SpecError` names the key)."""
    return read_profile(SpecTable(table, "settlement", SETTLEMENT_KEYS), x0, x1, unit_length)


def _tunnel(table: SpecTable, segment: float, cutoff: float) -> Profile:
    """A tunnel's greenfield trough (module docstring): i = K z0, S_max from the volume loss."""
    volume_loss = table.number("volume_loss", positive=True)
    diameter = table.number("diameter", length=True, positive=True)
    depth = table.number("depth", length=True, positive=True)
    if depth <= 0.5 * diameter:
        raise SpecError(f"spec key {table.key('depth')!r} = {table.raw('depth')!r}: the tunnel's crown would be above "
                        f"the ground (the depth of its axis must exceed half its diameter, {table.raw('diameter')!r})")
    factor = table.number("trough_width_factor", DEFAULT_TROUGH_WIDTH_FACTOR, positive=True)
    width = factor * depth
    try:
        s_max = volume_loss / 100.0 * math.pi * diameter**2 / 4.0 / (math.sqrt(2.0 * math.pi) * width)
    except OverflowError:  # a diameter of 1e200
        s_max = math.inf
    if not (math.isfinite(width) and math.isfinite(s_max) and s_max > 0):
        raise SpecError(f"spec keys {table.key('volume_loss')!r}, {table.key('diameter')!r} and {table.key('depth')!r} "
                        f"= {table.raw('volume_loss')!r}, {table.raw('diameter')!r}, {table.raw('depth')!r}: the "
                        f"trough's i = {width:.3g} m and S_max = {s_max:.3g} m are not finite lengths")
    return Profile("tunnel", segment, cutoff, center=table.number("center", length=True), width=width, depth=depth,
                   sideways=table.flag("horizontal", True), target=s_max, volume_loss=volume_loss, diameter=diameter,
                   trough_width_factor=factor)


def _table_points(table: SpecTable) -> tuple[tuple[float, float], ...]:
    raw = table.raw("points")
    shown = f"spec key {table.key('points')!r}"
    if (not isinstance(raw, list) or len(raw) < 2
            or any(not isinstance(p, list) or len(p) != 2 for p in raw)
            or any(isinstance(v, bool) or not is_finite_number(v)
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


def contact_lengths(edges: np.ndarray, base: np.ndarray) -> np.ndarray:
    """Per segment ``[edges[k], edges[k+1]]``: the length of its overlap with the ``base`` intervals ``(n, 2)``
    (the masonry's bottom edges)."""
    lo = np.maximum(edges[:-1, None], base[:, 0])
    hi = np.minimum(edges[1:, None], base[:, 1])
    return np.maximum(hi - lo, 0.0).sum(axis=1)


def node_motion(profile: Profile, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(down, horizontal)`` rates of the ground at the nodes ``x``: the profile's rate less the cutoff c, over
    ``1 - c`` (so a rate of 1 stays 1, S_max stays t), 0 where the rate is at most c; the horizontal motion
    scaled alike. Continuous, and within c of the profile everywhere."""
    down, share = beyond_cutoff(profile, profile.rate(x))
    return down, profile.horizontal(x) * share


def beyond_cutoff(profile: Profile, rate: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(down, share)``: a greenfield ``rate`` less the profile's cutoff c, over ``1 - c``, 0 where it is at most
    c; and ``down / rate``, what the horizontal motion is scaled by."""
    down = np.maximum(rate - profile.cutoff, 0.0) / (1.0 - profile.cutoff)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(rate > 0, down / rate, 0.0)
    return down, share


def segment_edges(profile: Profile, x0: float, x1: float) -> np.ndarray:
    """The ends of the ``round((x1 - x0) / segment)`` equal segments from ``x0`` to ``x1`` (at least one)."""
    return np.linspace(x0, x1, max(1, round((x1 - x0) / profile.segment)) + 1)


def segment_count(length: float, segment: float, unit_length: float, key: str) -> int:
    """How many equal segments about ``segment`` long [m] cut a ground ``length`` long: refused, naming ``key``,
    when ``segment`` is not a positive finite length, leaves fewer than two pieces (the ground would move as one
    body) or is finer than :data:`MAX_SEGMENTS_PER_UNIT` a unit length ``unit_length``."""
    if not (math.isfinite(segment) and segment > 0):
        raise SpecError(f"{key} = {segment!r}: must be a positive, finite length")
    refuse_fine_segments(length, segment, unit_length, key)
    count = round(length / segment)
    if count < 2:
        raise SpecError(f"{key} = {segment:.6g} m: the {length:.6g} m ground would be {max(count, 1)} piece, moving "
                        f"as one body; give at most {length / 2:.6g} m")
    return count


def refuse_fine_segments(length: float, segment: float, unit_length: float, key: str) -> None:
    """Refuse, naming ``key``, ground segments finer than :data:`MAX_SEGMENTS_PER_UNIT` a unit length: they would cut
    a ground ``length`` long into more pieces than any convergence needs."""
    finest = unit_length / MAX_SEGMENTS_PER_UNIT
    if segment < finest * (1 - 1e-9):
        count = length / segment
        shown = f"{count:,.0f}" if count < 1e12 else f"{count:.3g}"
        raise SpecError(f"{key} = {segment:.3g} m: it would cut the {length:.6g} m ground into {shown} segments, "
                        f"finer than a hundredth of a unit ({unit_length:.6g} m), which no convergence needs (a "
                        f"quarter unit is the default); give at least {finest:.3g} m")


def segment_motions(profile: Profile, edges: np.ndarray) -> list[Segment]:
    """Every segment between consecutive ``edges``, moving with the ground: a continuous ground's segment follows
    its two nodes (:func:`node_motion`), a step's translates if its middle lies under the step."""
    if profile.kind == "step":
        down = profile.rate(0.5 * (edges[:-1] + edges[1:]))
        return [Segment(float(a), float(b), (float(d), float(d)), (0.0, 0.0))
                for a, b, d in zip(edges[:-1], edges[1:], down)]
    down, horizontal = node_motion(profile, edges)
    return [Segment(float(edges[k]), float(edges[k + 1]), (float(down[k]), float(down[k + 1])),
                    (float(horizontal[k]), float(horizontal[k + 1]))) for k in range(edges.size - 1)]


def profile_segments(profile: Profile, x0: float, x1: float, base: np.ndarray) -> list[Segment]:
    """The support segments of a profile under a wall from ``x0`` to ``x1`` whose masonry rests on the ``base``
    intervals (module docstring): moving segments one by one, adjacent fixed ones merged."""
    edges = segment_edges(profile, x0, x1)
    bare = contact_lengths(edges, base) <= 1e-9 * (x1 - x0)
    motions = segment_motions(profile, edges)
    segments: list[Segment] = []
    for k in np.flatnonzero(~bare):
        segment = motions[k]
        last = segments[-1] if segments else None
        if not segment.moving and last is not None and not last.moving and last.end == segment.start:
            segment = Segment(last.start, segment.end, (0.0, 0.0), (0.0, 0.0))
            segments.pop()
        segments.append(segment)
    if not any(s.moving for s in segments):
        raise SpecError(f"spec table 'settlement': the ground settles at most {profile.cutoff:g} (the cutoff) times "
                        "S_max under every segment: nothing settles under the wall (move the profile under it "
                        "or lower the cutoff)")
    return segments


def with_profile(model: xr.Dataset, profile: Profile | None) -> xr.Dataset:
    """``model`` recording the greenfield ``profile`` it is built over (its ``settlement_profile`` attribute, JSON in
    SI, what the engineers' assessment reads: :mod:`masonryfw.ground.assessment`) and the settlement it expects
    (``settlement_target``, a tunnel's S_max), if any."""
    if profile is None:
        return model
    model = model.assign_attrs(settlement_profile=json.dumps(
        {k: v for k, v in asdict(profile).items() if v is not None}, sort_keys=True))
    if profile.target is None:
        return model
    return model.assign(settlement_target=((), profile.target, variable_attrs("settlement_target")))


def model_profile(model: xr.Dataset) -> Profile | None:
    """The greenfield profile a model was built over (its ``settlement_profile`` attribute), None without one."""
    text = model.attrs.get("settlement_profile")
    if not text:
        return None
    fields = json.loads(text)
    fields["points"] = tuple(tuple(p) for p in fields.get("points", ()))
    return Profile(**fields)
