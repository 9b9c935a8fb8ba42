"""Walls given by their outline: the bond laid in an elevation (:mod:`masonryfw.builders.bond`), then a model as every
other wall gets one.

An outline comes from

* a **drawing** whose ``[geometry]`` names ``outline_layer`` (the one closed polyline of the wall's outline)
  and, optionally, ``openings_layer`` (else every other closed polyline inside the outline is an opening; a
  GeoJSON outline's holes are openings too), in the drawing's coordinates; or
* a **parametric spec** whose ``[wall]`` has ``width`` and ``height`` (the eaves) and a ``gable_height`` (the
  ridge, over the middle), or an ``outline`` of ``[x, y]`` points, with ``[[openings]]`` of ``shape``
  rectangle, ``arched`` (a rectangle and a circular head of ``rise``, half the width by default: a
  semicircle), ``round`` (a round window of diameter ``width``, its box's lower left corner at ``x``, ``y``) or
  ``polygon`` (``points``).

``[unit]`` gives the unit's length and course height; ``[bond]`` its ``pattern`` (running, stack, english,
flemish), ``first_course`` and ``min_piece``; ``[heads]`` the head over every opening (``kind``: lintel,
flat_arch, arch, none; ``courses`` deep; ``bearing`` each side), an opening's own ``head``, ``head_courses``
and ``lintel_bearing`` overriding it (an arched opening gets an arch by default). Supports as for a parametric
wall: ``[supports.*]`` ranges along the base (in the outline's coordinates) or a ``[settlement]`` profile,
each a block one course high under the base. What the laying did (openings moved onto bed joints, a cut top
course, slivers merged) is the model's ``laying_notes``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..format.model import checked_model
from ..format.roles import ROLE
from ..ground.profiles import SETTLEMENT_KEYS, read_profile, with_profile
from ..readers.drawing import DRAWING_UNITS, read_elevation
from ..readers.spec import (
    SpecTable,
    is_finite_number,
    model_attributes,
    open_spec,
    read_loading,
    read_material,
    refuse_ground_twice,
    shown,
    spec_relative,
)
from ..runtime.errors import SpecError
from ..runtime.inputs import fits_in_memory
from ..runtime.resources import count_text
from . import blocks
from .bond import HEADS, PATTERNS, Bond, Head, LaidWall, lay
from .supports import profile_supports, read_supports, support_rectangles

if TYPE_CHECKING:  # annotations only
    import xarray as xr
    from shapely.geometry import Polygon

_TOP_KEYS = ("title", "description", "space", "length_unit", "geometry", "wall", "unit", "bond", "heads", "openings",
             "material", "supports", "settlement", "loading")
_GEOMETRY_KEYS = ("dxf", "polygons", "drawing_unit", "chord_tolerance", "outline_layer", "openings_layer")
_WALL_KEYS = ("width", "height", "thickness", "gable_height", "outline")
_OPENING_KEYS = ("x", "y", "width", "height", "lintel_bearing", "shape", "rise", "points", "head", "head_courses")
_SHAPES = ("rectangle", "arched", "polygon", "round")
#: Chord tolerance of an arched opening's head, in its radii.
ARC_CHORD = 1e-3


def is_outlined(spec: dict) -> bool:
    """Whether a spec dict is a wall the core lays by its outline (module docstring): a drawing with an
    ``outline_layer``, or a parametric spec with a gable, an outline, a shaped opening or head, a head table, an
    English or Flemish bond, or a height that is not a whole number of courses."""
    if not isinstance(spec, dict):
        return False
    geometry = spec.get("geometry")
    if isinstance(geometry, dict):
        return "outline_layer" in geometry
    wall, unit, bond = (spec.get(k) if isinstance(spec.get(k), dict) else {} for k in ("wall", "unit", "bond"))
    openings = spec.get("openings") if isinstance(spec.get("openings"), list) else []
    shaped = any(isinstance(o, dict) and {"shape", "head", "head_courses", "rise", "points"} & set(o)
                 for o in openings)
    return ("gable_height" in wall or "outline" in wall or "heads" in spec or shaped
            or bond.get("pattern") in ("english", "flemish") or "min_piece" in bond
            or _not_whole_courses(wall.get("height"), unit.get("height")))


def _not_whole_courses(height, unit_height) -> bool:
    numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0 for v in (height, unit_height))
    if not numbers or not math.isfinite(height / unit_height):
        return False
    ratio = height / unit_height
    return abs(ratio - round(ratio)) > 1e-6 * max(1.0, ratio)


@dataclass(frozen=True)
class ElevationToLay:
    """What is laid: the outline and the openings (metres), each opening's head and name."""

    outline: Polygon
    openings: list[Polygon]
    heads: list[Head]
    names: list[str]
    source: Path | None  # the drawing, if any
    notes: tuple[str, ...] = ()  # what reading the drawing did


def build_outlined(spec_dict: dict, text: str, base_dir: Path | None, validate: bool = True) -> xr.Dataset:
    """The model of a wall laid in its outline (module docstring); checked unless ``validate`` is False."""
    top = open_spec(spec_dict, _TOP_KEYS)
    unit = top.sub("unit", ("length", "height"))
    bond_table = top.sub("bond", ("pattern", "first_course", "min_piece"), {})
    bond = Bond(unit.number("length", length=True, positive=True), unit.number("height", length=True, positive=True),
                bond_table.choice("pattern", PATTERNS, "running"),
                bond_table.choice("first_course", ("full", "half"), "full"),
                bond_table.number("min_piece", 0.5, minimum=0.0, below=1.0))
    elevation = _drawn(top, base_dir, bond) if top.has("geometry") else _parametric(top, bond)
    _refuse_too_big(elevation, bond, top)
    laid = lay(elevation.outline, elevation.openings, bond, elevation.heads, elevation.names)
    _refuse_one_block(laid, elevation)
    x0, y0, x1, _ = elevation.outline.bounds
    base = np.array([(p[:, 0].min(), p[:, 0].max()) for p in laid.polygons if p[:, 1].min() <= y0 + 1e-9 * (x1 - x0)])
    refuse_ground_twice(top)
    profile = None
    if top.has("settlement"):
        profile = read_profile(top.sub("settlement", SETTLEMENT_KEYS), x0, x1, bond.unit_length)
        supports = profile_supports(profile, x0, x1, base, y0)
    else:
        supports = read_supports(top, x0, x1)
    loading, direction = read_loading(top, profile is not None or any(s.kind == "moving" for s in supports))
    s_x0, s_x1, s_y0, s_y1, described = support_rectangles(supports, y0, bond.unit_height)
    rectangles = [np.array([[a, c], [b, c], [b, d], [a, d]]) for a, b, c, d in zip(s_x0, s_x1, s_y0, s_y1)]
    rings = laid.polygons + rectangles
    roles = np.array(laid.roles + [ROLE["fixed_support"]] * len(rectangles), dtype=np.int8)
    attrs = model_attributes(top.text("title"), top.text("description", ""), text, drawing=elevation.source, notes=[*elevation.notes, *laid.notes])
    wall = top.sub("wall", _WALL_KEYS)
    ds = blocks.model_from_blocks(np.concatenate([r[:, 0] for r in rings]), np.concatenate([r[:, 1] for r in rings]),
                                  np.array([len(r) for r in rings], dtype=np.int32), roles,
                                  wall.number("thickness", length=True, positive=True), read_material(top), described,
                                  loading, direction, attrs)
    ds = with_profile(ds, profile)
    return checked_model(ds, repr(attrs["title"])) if validate else ds


def _refuse_too_big(elevation: ElevationToLay, bond: Bond, top: SpecTable) -> None:
    """Refuse, before any laying, an outline whose units (counted from its extent) would not fit in the memory
    available, naming what sizes it: a drawing in mm read as metres, a unit in the wrong unit."""
    x0, y0, x1, y1 = elevation.outline.bounds
    with np.errstate(over="ignore", invalid="ignore"):
        units = np.float64(x1 - x0) * np.float64(y1 - y0) / (bond.unit_length * bond.unit_height)
    where = f"the drawing {elevation.source.name!r}" if elevation.source is not None else "spec table 'wall'"
    fits_in_memory((units + 2.0 * (x1 - x0) / bond.unit_length) * blocks.BYTES_PER_BLOCK,
                   f"the outline of {where} ({x1 - x0:.4g} x {y1 - y0:.4g} m) in units of [unit] = {bond.unit_length:.4g}"
                   f" x {bond.unit_height:.4g} m ({count_text(units)} blocks)",
                   "are [unit] and the drawing's unit (geometry.drawing_unit) what was meant?" if elevation.source
                   else "are [unit], [wall] and length_unit what was meant?")


def _refuse_one_block(laid: LaidWall, elevation: ElevationToLay) -> None:
    """A wall of one block is no masonry wall (a unit as large as the outline): refused, not warned."""
    if len(laid.polygons) < 2:
        x0, y0, x1, y1 = elevation.outline.bounds
        raise SpecError(f"the wall's outline ({x1 - x0:.4g} x {y1 - y0:.4g} m) holds {len(laid.polygons)} unit(s) of "
                        "[unit]: is [unit] in the drawing's unit, or the outline in metres?")


# ---------------------------------------------------------------- a drawing's outline

def drawing_paths(spec: dict, base_dir: Path | None) -> dict[str, Path]:
    """The drawing an outline spec names, by its key (``dxf`` or ``polygons``): none for a parametric outline."""
    geometry = spec.get("geometry")
    geometry = geometry if isinstance(geometry, dict) else {}
    return {k: spec_relative(geometry[k], base_dir) for k in ("dxf", "polygons") if isinstance(geometry.get(k), str)}


def _drawn(top: SpecTable, base_dir: Path | None, bond: Bond) -> ElevationToLay:
    from shapely.geometry import Polygon

    geometry = top.sub("geometry", _GEOMETRY_KEYS)
    sources = [k for k in ("dxf", "polygons") if geometry.has(k)]
    if len(sources) != 1:
        raise SpecError("spec table 'geometry': give exactly one of 'geometry.dxf' and 'geometry.polygons'")
    written = geometry.text(sources[0])
    path = spec_relative(written, base_dir)
    if not path.exists():
        raise SpecError(f"spec key 'geometry.{sources[0]}' = {written!r}: no such file ({path})")
    unit = geometry.raw("drawing_unit", None)
    if unit is not None and unit not in DRAWING_UNITS:
        geometry.choice("drawing_unit", tuple(DRAWING_UNITS))
    for key in ("width", "height", "gable_height", "outline"):
        if top.has("wall") and key in top.raw("wall"):
            raise SpecError(f"spec key 'wall.{key}' does not apply to a wall drawn by its outline (the drawing gives "
                            "its shape)")
    drawn = read_elevation(path, unit, geometry.text("outline_layer"), geometry.text("openings_layer", "") or None,
                           geometry.number("chord_tolerance", None, positive=True))
    heads = _heads(top, len(drawn.openings), bond, _extent(drawn.outline))
    names = [f"openings[{k}] ({source} in {path.name!r})" for k, source in enumerate(drawn.opening_sources)]
    return ElevationToLay(_valid(Polygon(drawn.outline), f"the outline ({drawn.outline_source} in {path.name!r})"),
                     [_valid(Polygon(o), name) for o, name in zip(drawn.openings, names)],
                     [_arched_default(h, o) for h, o in zip(heads, drawn.openings)], names, path, drawn.notes)


def _heads(top: SpecTable, count: int, bond: Bond, extent: tuple[float, float],
           entries: list[SpecTable] | None = None) -> list[Head]:
    """Every opening's head: ``[heads]`` as the default, an opening's own keys over it; courses a whole number no
    more than the wall's, a bearing no longer than the wall (``extent``: its width and height in metres)."""
    table = top.sub("heads", ("kind", "courses", "bearing"), {})
    kind = table.choice("kind", HEADS, "lintel")
    courses = _head_courses(table, "courses", 1, bond, extent)
    bearing = _bearing(table, "bearing", 0.5 * bond.unit_length / top.scale, extent)
    heads = []
    for k in range(count):
        entry = entries[k] if entries else None
        if entry is None:
            heads.append(Head(kind, courses, bearing))
            continue
        own = entry.choice("head", HEADS, kind if entry.has("head") or not _is_arched(entry) else "arch")
        heads.append(Head(own, _head_courses(entry, "head_courses", courses, bond, extent),
                          _bearing(entry, "lintel_bearing", bearing / top.scale, extent)))
    return heads


def _head_courses(table: SpecTable, key: str, default: int, bond: Bond, extent: tuple[float, float]) -> int:
    courses = table.integer(key, default, minimum=1)
    most = max(1, math.ceil(extent[1] / bond.unit_height))
    if courses > most:
        raise SpecError(f"spec key {table.key(key)!r} = {shown(courses)}: a head deeper than the wall's {most} "
                        "courses")
    return courses


def _bearing(table: SpecTable, key: str, default: float, extent: tuple[float, float]) -> float:
    bearing = table.number(key, default, length=True, minimum=0.0)
    if bearing > extent[0]:
        raise SpecError(f"spec key {table.key(key)!r} = {shown(table.raw(key))}: bears {bearing:.4g} m into the "
                        f"masonry, more than the wall is wide ({extent[0]:.4g} m)")
    return bearing


def _arched_default(head: Head, ring: np.ndarray) -> Head:
    """A drawn opening whose head is curved (more than four corners) gets an arch where ``[heads]`` said lintel."""
    return Head("arch", head.courses, head.bearing) if head.kind == "lintel" and len(ring) > 6 else head


def _valid(polygon: Polygon, name: str) -> Polygon:
    if not polygon.is_valid or polygon.area <= 0:
        raise SpecError(f"{name}: not a simple polygon (its edges cross, or it has no area)")
    return polygon


# ---------------------------------------------------------------- a parametric outline

def _parametric(top: SpecTable, bond: Bond) -> ElevationToLay:
    from shapely.geometry import Polygon

    wall = top.sub("wall", _WALL_KEYS)
    if wall.has("outline"):
        outline = _points(wall, "outline")
    else:
        width, height = wall.number("width", length=True, positive=True), wall.number("height", length=True, positive=True)
        outline = [(0.0, 0.0), (width, 0.0), (width, height)]
        if wall.has("gable_height"):
            ridge = wall.number("gable_height", length=True, positive=True)
            if ridge <= height:
                raise SpecError(f"spec key {wall.key('gable_height')!r} = {wall.raw('gable_height')!r}: the ridge must "
                                f"stand above the eaves ({wall.key('height')} = {wall.raw('height')!r})")
            outline.append((0.5 * width, ridge))
        outline.append((0.0, height))
    entries = top.raw("openings", [])
    if not isinstance(entries, list):
        raise SpecError(f"spec key 'openings' must be an array of tables ([[openings]]), got {entries!r}")
    tables = [SpecTable(t, f"openings[{k}]", _OPENING_KEYS, top.scale) for k, t in enumerate(entries)]
    names = [f"spec key {t.path!r}" for t in tables]
    openings = [_valid(_opening(t), name) for t, name in zip(tables, names)]
    return ElevationToLay(_valid(Polygon(outline), "spec key 'wall.outline'"), openings,
                     _heads(top, len(tables), bond, _extent(outline), tables), names, None)


def _extent(points: list[tuple[float, float]]) -> tuple[float, float]:
    """The width and height of the box around ``points``."""
    xy = np.asarray(points, dtype=float)
    return tuple(np.ptp(xy, axis=0).tolist())  # type: ignore[return-value]


def _points(table: SpecTable, key: str) -> list[tuple[float, float]]:
    raw = table.raw(key)
    if (not isinstance(raw, list) or len(raw) < 3 or any(not isinstance(p, list) or len(p) != 2 for p in raw)
            or any(isinstance(v, bool) or not is_finite_number(v) for p in raw
                   for v in p)):
        raise SpecError(f"spec key {table.key(key)!r}: must be at least three [x, y] points (numbers)")
    return [(float(x) * table.scale, float(y) * table.scale) for x, y in raw]


def _is_arched(entry: SpecTable) -> bool:
    """Whether the opening has a circular head (arched, round): its head is an arch by default."""
    return entry.raw("shape", "rectangle") in ("arched", "round")


def _opening(entry: SpecTable) -> Polygon:
    from shapely.geometry import Polygon, box

    shape = entry.choice("shape", _SHAPES, "rectangle")
    if shape == "polygon":
        return Polygon(_points(entry, "points"))
    x0, y0 = entry.number("x", length=True), entry.number("y", length=True)
    if shape == "round":  # a round window (an oculus): x, y its box's lower left corner, width its diameter
        if entry.has("height") or entry.has("rise"):
            raise SpecError(f"spec key {entry.key('height' if entry.has('height') else 'rise')!r}: a round opening "
                            "is given by its width (the diameter) alone")
        radius = 0.5 * entry.number("width", length=True, positive=True)
        steps = 4 * max(4, int(math.ceil(0.5 * math.pi / math.sqrt(8 * ARC_CHORD))))  # its box: the diameter
        angles = np.linspace(0.0, 2 * math.pi, steps, endpoint=False)
        return Polygon(np.c_[x0 + radius * (1 + np.cos(angles)), y0 + radius * (1 + np.sin(angles))])
    width, height = entry.number("width", length=True, positive=True), entry.number("height", length=True,
                                                                                    positive=True)
    if shape == "rectangle":
        return box(x0, y0, x0 + width, y0 + height)
    rise = entry.number("rise", 0.5 * width / entry.scale, length=True, positive=True)
    if rise > 0.5 * width * (1 + 1e-9):
        raise SpecError(f"spec key {entry.key('rise')!r} = {entry.raw('rise')!r}: at most half the width (a "
                        "semicircle)")
    radius = (0.25 * width * width + rise * rise) / (2 * rise)
    cx, cy = x0 + 0.5 * width, y0 + height - radius
    half = math.asin(min(1.0, 0.5 * width / radius))
    steps = max(8, int(math.ceil(2 * half / math.sqrt(8 * ARC_CHORD))))
    angles = np.linspace(math.pi / 2 - half, math.pi / 2 + half, steps + 1)[1:-1]
    head = [(cx + radius * math.cos(a), cy + radius * math.sin(a)) for a in angles]
    springing = y0 + height - rise
    return Polygon([(x0, y0), (x0 + width, y0), (x0 + width, springing), *head, (x0, springing)])
