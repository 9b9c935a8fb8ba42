"""The wall builder: a TOML spec in, a complete model dataset (docs/format.md) out.

A spec describes a plane wall of rectangular units in courses, its openings
with lintels, its support ranges along the base, the material and the loading
(see ``datasets/README.md`` for the full key list and the bundled examples).

Generation rules (the model is always in SI; ``length_unit`` only scales input):

* **Courses.** ``wall.height / unit.height`` courses (a whole number). Running bond:
  a course starts at the left with a full or a half unit, alternately
  (``bond.first_course`` says which for the bottom course); stack bond: every
  course like the bottom one. A course ends wherever the wall width ends, so a
  width that is not a whole number of units ends with a cut unit.
* **Openings** have their bottom and top on bed joints and cut the courses they
  span exactly at their vertical edges; the part of a unit inside the opening
  goes. A **lintel** is one block, one course high, directly on the opening,
  spanning the opening plus ``lintel_bearing`` on each side; it cuts its course
  the same way.
* **No slivers.** After cutting, a piece of a course shorter than half a unit
  is merged with its neighbour across a head joint (the one on its right if
  that side is a head joint, else the one on its left). Hence a unit mostly
  inside an opening disappears, its small remnant joining the next unit, and a
  unit at most half inside is trimmed to the opening edge. A piece with no
  head joint on either side (e.g. a narrow pier between an opening and the
  wall end) stays as it is. Every block is a rectangle.
* **Supports** are rectangular blocks one unit high under the wall, one per
  support range.
* **Interfaces, kinds and loads** as every model gets them (:mod:`masonryfw.blocks`):
  self-weight of units and lintels; settlement loading puts ``+R`` dead and
  ``-R`` live (vertical) on every moving support, ``R = W L_m / L_total`` from
  the support contacts actually found; tilt loading puts the weight
  horizontally as live load on every unit and lintel and holds every support.
"""
from __future__ import annotations

import difflib
import json
import math
import os
import re
from dataclasses import dataclass, replace

import numpy as np
import xarray as xr

from . import blocks
from .errors import SpecError
from .model import checked_model
from .schema import flags

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

LENGTH_UNITS = {"m": 1.0, "mm": 1.0e-3}
#: Relative tolerance on "a whole number of courses" (heights divided by the unit height).
COURSE_TOLERANCE = 1.0e-6
#: Position tolerance, relative to the wall size.
POSITION_TOLERANCE = 1.0e-9

_REQUIRED = object()


# --------------------------------------------------------------------------- reading


def load_spec(path_or_text) -> dict:
    """Read and validate a spec: a path (str or PathLike or Traversable) or the TOML text itself.

    Returns the spec as a plain dict (as written, not normalised), ready to be
    modified (e.g. by a parameter sweep) and passed to :func:`build`.
    """
    spec, _ = _read_spec(path_or_text)
    parse_spec(spec)
    return spec


def _read_spec(source) -> tuple[dict, str]:
    """``(spec dict, TOML text)`` from a path, a Traversable, TOML text or a dict."""
    if isinstance(source, dict):
        return source, dump_toml(source)
    if isinstance(source, os.PathLike) or hasattr(source, "read_text"):  # a path or a Traversable
        text = _read_text(source)
    elif isinstance(source, str):
        if os.path.isfile(source):
            text = _read_text(source)
        elif "=" in source or "\n" in source:
            text = source
        else:
            raise SpecError(f"spec file {source!r} not found (and the text is not TOML)")
    else:
        raise SpecError(f"a spec is a path, TOML text or a dict, not {type(source).__name__}")
    try:
        return tomllib.loads(text), text
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"spec is not valid TOML: {exc}") from None


def _read_text(path) -> str:
    try:
        if hasattr(path, "read_text"):
            return path.read_text(encoding="utf-8")
        with open(path, encoding="utf-8") as handle:
            return handle.read()
    except OSError as exc:
        raise SpecError(f"cannot read spec file {str(path)!r}: {exc.strerror}") from None


# --------------------------------------------------------------------------- validation


@dataclass(frozen=True)
class Opening:
    """An opening in SI, with its course range ``[course0, course1)``."""

    key: str
    x0: float
    x1: float
    course0: int
    course1: int
    lintel_bearing: float


@dataclass(frozen=True)
class Support:
    """A support range along the base, in SI."""

    name: str
    kind: str
    start: float
    end: float
    motion: str
    pivot: tuple[float, float] | None


@dataclass(frozen=True)
class Wall:
    """A validated spec, every length in metres."""

    title: str
    description: str
    width: float
    courses: int
    thickness: float
    unit_length: float
    unit_height: float
    pattern: str
    first_course: str
    unit_weight: float
    friction: float
    cohesion: float
    tensile_strength: float
    young_modulus: float | None
    poisson_ratio: float | None
    openings: tuple[Opening, ...]
    supports: tuple[Support, ...]
    loading: str
    tilt_direction: int

    @property
    def height(self) -> float:
        return self.courses * self.unit_height

    @property
    def tol(self) -> float:
        return POSITION_TOLERANCE * max(self.width, self.height)


class _Table:
    """One table of a spec: typed access to its keys; unknown keys are rejected up front."""

    def __init__(self, table, path: str, allowed: tuple[str, ...], scale: float = 1.0):
        if not isinstance(table, dict):
            raise SpecError(f"spec key {path!r} must be a table, got {table!r}")
        self.table, self.path, self.scale = table, path, scale
        for name in table:
            if name not in allowed:
                guess = difflib.get_close_matches(name, allowed, n=1)
                hint = f" (did you mean {self.key(guess[0])!r}?)" if guess else f" (known keys: {', '.join(allowed)})"
                raise SpecError(f"unknown spec key {self.key(name)!r}{hint}")

    def key(self, name: str) -> str:
        return f"{self.path}.{name}" if self.path else name

    def has(self, name: str) -> bool:
        return name in self.table

    def raw(self, name: str, default=_REQUIRED):
        if name not in self.table:
            if default is _REQUIRED:
                raise SpecError(f"missing spec key {self.key(name)!r}")
            return default
        return self.table[name]

    def number(self, name: str, default=_REQUIRED, *, length=False, positive=False,
               minimum=None, below=None):
        value = self.raw(name, default)
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be a number")
        if not math.isfinite(value):
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be finite")
        if positive and value <= 0:
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be positive")
        if minimum is not None and value < minimum:
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be at least {minimum}")
        if below is not None and value >= below:
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be less than {below}")
        return float(value) * (self.scale if length else 1.0)

    def choice(self, name: str, choices: tuple[str, ...], default=_REQUIRED) -> str:
        value = self.raw(name, default)
        if value not in choices:
            raise SpecError(
                f"spec key {self.key(name)!r} = {value!r}: must be one of {', '.join(map(repr, choices))}"
            )
        return value

    def text(self, name: str, default=_REQUIRED) -> str:
        value = self.raw(name, default)
        if not isinstance(value, str):
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be a string")
        return value

    def point(self, name: str) -> tuple[float, float]:
        value = self.raw(name)
        if (not isinstance(value, list) or len(value) != 2
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) for v in value)):
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be a pair of numbers [x, y]")
        return float(value[0]) * self.scale, float(value[1]) * self.scale

    def sub(self, name: str, allowed: tuple[str, ...], default=_REQUIRED) -> _Table:
        return _Table(self.raw(name, default), self.key(name), allowed, self.scale)


_TOP_KEYS = ("title", "description", "length_unit", "wall", "unit", "bond", "material",
             "openings", "supports", "loading")
_MATERIAL_KEYS = ("unit_weight", "friction_angle", "friction", "cohesion", "tensile_strength",
                  "young_modulus", "poisson_ratio")
_OPENING_KEYS = ("x", "y", "width", "height", "lintel_bearing")
_SUPPORT_KEYS = ("kind", "start", "end", "motion", "pivot")


def parse_spec(spec: dict) -> Wall:
    """Validate a spec dict and return it in SI; a :class:`SpecError` names the offending key."""
    top = _Table(spec, "", _TOP_KEYS)
    unit_name = top.choice("length_unit", tuple(LENGTH_UNITS), "m")
    top.scale = LENGTH_UNITS[unit_name]

    wall = top.sub("wall", ("width", "height", "thickness"))
    width = wall.number("width", length=True, positive=True)
    height = wall.number("height", length=True, positive=True)
    thickness = wall.number("thickness", length=True, positive=True)
    unit = top.sub("unit", ("length", "height"))
    unit_length = unit.number("length", length=True, positive=True)
    unit_height = unit.number("height", length=True, positive=True)
    courses = _whole_courses(height, unit_height, wall.key("height"), wall.raw("height"))
    bond = top.sub("bond", ("pattern", "first_course"), {})

    material = top.sub("material", _MATERIAL_KEYS)
    friction = _friction(material)

    supports = _supports(top, width)
    loading = top.sub("loading", ("type", "direction"))
    kind = loading.choice("type", ("settlement", "tilt"))
    direction = 0
    if kind == "tilt":
        direction = loading.raw("direction")
        if direction not in (1, -1) or isinstance(direction, bool):
            raise SpecError(f"spec key 'loading.direction' = {direction!r}: must be +1 (towards +x) or -1")
        direction = int(direction)
    elif loading.has("direction"):
        raise SpecError("spec key 'loading.direction' only applies to loading.type = 'tilt'")
    elif not any(s.kind == "moving" for s in supports):
        raise SpecError("spec key 'loading.type' = 'settlement': needs at least one support with kind = 'moving'")

    result = Wall(
        title=top.text("title"),
        description=top.text("description", ""),
        width=width,
        courses=courses,
        thickness=thickness,
        unit_length=unit_length,
        unit_height=unit_height,
        pattern=bond.choice("pattern", ("running", "stack"), "running"),
        first_course=bond.choice("first_course", ("full", "half"), "full"),
        unit_weight=material.number("unit_weight", positive=True),
        friction=friction,
        cohesion=material.number("cohesion", 0.0, minimum=0.0),
        tensile_strength=material.number("tensile_strength", 0.0, minimum=0.0),
        young_modulus=material.number("young_modulus", None, positive=True),
        poisson_ratio=material.number("poisson_ratio", None, minimum=-1.0, below=0.5),
        openings=(),
        supports=supports,
        loading=kind,
        tilt_direction=direction,
    )
    openings = _openings(top, result)
    return replace(result, openings=openings)


def _whole_courses(value: float, unit_height: float, key: str, shown) -> int:
    """``value / unit_height`` if it is a whole number (relative tolerance), else a SpecError."""
    ratio = value / unit_height
    count = round(ratio)
    if abs(ratio - count) > COURSE_TOLERANCE * max(1.0, ratio):
        raise SpecError(f"spec key {key!r} = {shown!r}: must be a whole number of courses "
                        f"({ratio:.4g} times unit.height)")
    return int(count)


def _friction(material: _Table) -> float:
    if material.has("friction_angle") and material.has("friction"):
        raise SpecError("spec keys 'material.friction_angle' and 'material.friction': give one of them, not both")
    if material.has("friction"):
        return material.number("friction", minimum=0.0)
    if not material.has("friction_angle"):
        raise SpecError("missing spec key 'material.friction_angle' (or 'material.friction')")
    angle = material.number("friction_angle", minimum=0.0, below=90.0)
    return math.tan(math.radians(angle))


def _supports(top: _Table, width: float) -> tuple[Support, ...]:
    table = top.raw("supports")
    if not isinstance(table, dict) or not table:
        raise SpecError(f"spec key 'supports' = {table!r}: must hold at least one [supports.<name>] table")
    tol = POSITION_TOLERANCE * width
    supports = []
    for name in table:
        entry = _Table(table[name], f"supports.{name}", _SUPPORT_KEYS, top.scale)
        kind = entry.choice("kind", ("fixed", "moving"))
        start = entry.number("start", length=True, minimum=0.0)
        end = entry.number("end", length=True)
        if end > width + tol:
            raise SpecError(f"spec key {entry.key('end')!r} = {entry.raw('end')!r}: beyond the wall's right end")
        if end <= start + tol:
            raise SpecError(f"spec key {entry.key('end')!r} = {entry.raw('end')!r}: must exceed start")
        motion, pivot = "none", None
        if kind == "moving":
            motion = entry.choice("motion", ("translation", "rotation"), "translation")
            if motion == "rotation":
                pivot = entry.point("pivot")
                if abs(pivot[0] - 0.5 * (start + end)) <= tol:
                    raise SpecError(
                        f"spec key {entry.key('pivot')!r} = {entry.raw('pivot')!r}: the pivot must lie left or "
                        "right of the support's centre (a rotation about it must move the support down)"
                    )
            elif entry.has("pivot"):
                raise SpecError(f"spec key {entry.key('pivot')!r} only applies to motion = 'rotation'")
        elif entry.has("motion") or entry.has("pivot"):
            bad = "motion" if entry.has("motion") else "pivot"
            raise SpecError(f"spec key {entry.key(bad)!r} only applies to kind = 'moving'")
        supports.append(Support(name, kind, min(start, width), min(end, width), motion, pivot))
    ordered = sorted(supports, key=lambda s: s.start)
    for left, right in zip(ordered, ordered[1:]):
        if right.start < left.end - tol:
            raise SpecError(f"spec keys 'supports.{left.name}' and 'supports.{right.name}': the ranges overlap")
    return tuple(supports)


def _openings(top: _Table, wall: Wall) -> tuple[Opening, ...]:
    entries = top.raw("openings", [])
    if not isinstance(entries, list):
        raise SpecError(f"spec key 'openings' must be an array of tables ([[openings]]), got {entries!r}")
    tol = wall.tol
    openings = []
    for index, table in enumerate(entries):
        entry = _Table(table, f"openings[{index}]", _OPENING_KEYS, top.scale)
        x0 = entry.number("x", length=True, minimum=0.0)
        y0 = entry.number("y", length=True, minimum=0.0)
        width = entry.number("width", length=True, positive=True)
        height = entry.number("height", length=True, positive=True)
        bearing = entry.number("lintel_bearing", length=True, minimum=0.0)
        course0 = _whole_courses(y0, wall.unit_height, entry.key("y"), entry.raw("y"))
        course1 = course0 + _whole_courses(height, wall.unit_height, entry.key("height"), entry.raw("height"))
        if x0 + width > wall.width + tol:
            raise SpecError(f"spec key {entry.key('width')!r} = {entry.raw('width')!r}: "
                            "the opening passes the wall's right end")
        if course1 >= wall.courses:
            raise SpecError(f"spec key {entry.key('height')!r} = {entry.raw('height')!r}: "
                            "the opening reaches the top of the wall")
        if bearing > 0 and course1 + 1 > wall.courses:
            raise SpecError(f"spec key {entry.key('lintel_bearing')!r}: no course left above the opening for the lintel")
        if bearing > 0 and (x0 - bearing < -tol or x0 + width + bearing > wall.width + tol):
            raise SpecError(f"spec key {entry.key('lintel_bearing')!r} = {entry.raw('lintel_bearing')!r}: "
                            "the lintel passes the end of the wall")
        openings.append(Opening(entry.path, x0, min(x0 + width, wall.width), course0, course1, bearing))
    _no_overlapping_openings(openings, tol)
    return tuple(openings)


def _no_overlapping_openings(openings: list[Opening], tol: float) -> None:
    """Openings (each with its lintel) may touch but not overlap."""
    x0, x1, c0, c1, owner = _void_boxes(openings)
    rows = np.minimum(c1[:, None], c1) - np.maximum(c0[:, None], c0)
    span = np.minimum(x1[:, None], x1) - np.maximum(x0[:, None], x0)
    clash = np.argwhere((rows > 0) & (span > tol) & (owner[:, None] < owner))
    if clash.size:
        first, second = openings[owner[clash[0, 0]]], openings[owner[clash[0, 1]]]
        raise SpecError(f"spec keys {first.key!r} and {second.key!r}: the openings (with their lintels) overlap")


def _void_boxes(openings):
    """``(x0, x1, course0, course1, opening index)`` of every opening and lintel: the regions cut out of courses."""
    rows = [(o.x0, o.x1, o.course0, o.course1, i) for i, o in enumerate(openings)]
    rows += [(o.x0 - o.lintel_bearing, o.x1 + o.lintel_bearing, o.course1, o.course1 + 1, i)
             for i, o in enumerate(openings) if o.lintel_bearing > 0]
    x0, x1, c0, c1, owner = zip(*rows) if rows else [()] * 5
    return (np.array(x0, dtype=float), np.array(x1, dtype=float), np.array(c0, dtype=np.int64),
            np.array(c1, dtype=np.int64), np.array(owner, dtype=np.int64))


# --------------------------------------------------------------------------- geometry


def course_starts_full(wall: Wall) -> np.ndarray:
    """Per course, whether it starts at the left with a full unit."""
    course = np.arange(wall.courses)
    first_full = wall.first_course == "full"
    if wall.pattern == "stack":
        return np.full(wall.courses, first_full)
    return (course % 2 == 0) == first_full


def _bond_joints(wall: Wall, start_full: bool) -> np.ndarray:
    """Head-joint positions of one course, wall ends included."""
    first = wall.unit_length if start_full else 0.5 * wall.unit_length
    count = max(0, math.ceil((wall.width - wall.tol - first) / wall.unit_length))
    inner = first + wall.unit_length * np.arange(count)
    inner = inner[inner < wall.width - wall.tol]
    return np.concatenate(([0.0], inner, [wall.width]))


def _course_breakpoints(wall: Wall):
    """Sorted breakpoints ``(course, x, is_head_joint)`` of all courses: head joints and cut edges."""
    starts_full = course_starts_full(wall)
    courses = np.arange(wall.courses)
    xs, cs, joint = [], [], []
    for full in (True, False):
        rows = courses[starts_full == full]
        line = _bond_joints(wall, full)
        xs.append(np.tile(line, rows.size))
        cs.append(np.repeat(rows, line.size))
        inner = np.ones(line.size, dtype=bool)
        inner[[0, -1]] = False  # the wall ends are no head joints
        joint.append(np.tile(inner, rows.size))
    vx0, vx1, vc0, vc1, _ = _void_boxes(wall.openings)
    span = vc1 - vc0
    void_course = np.repeat(vc0, span) + np.arange(span.sum()) - np.repeat(np.cumsum(span) - span, span)
    for edge in (vx0, vx1):
        xs.append(np.clip(np.repeat(edge, span), 0.0, wall.width))
        cs.append(void_course)
        joint.append(np.zeros(void_course.size, dtype=bool))
    x, c, j = np.concatenate(xs), np.concatenate(cs), np.concatenate(joint)
    order = np.lexsort((x, c))
    x, c, j = x[order], c[order], j[order]
    # Coincident points (a cut on a head joint, a cut at a wall end) become one cut.
    new = np.ones(x.size, dtype=bool)
    new[1:] = (c[1:] != c[:-1]) | (x[1:] - x[:-1] > wall.tol)
    first = np.flatnonzero(new)
    return c[first], x[first], np.logical_and.reduceat(j, first)


def _segments(c, x):
    """Consecutive breakpoint pairs of the same course: ``(left index, course, x0, x1)``."""
    left = np.flatnonzero(c[:-1] == c[1:])
    return left, c[left], x[left], x[left + 1]


def _in_voids(course, x0, x1, voids) -> np.ndarray:
    vx0, vx1, vc0, vc1 = voids
    mid = 0.5 * (x0 + x1)[:, None]
    row = course[:, None]
    return np.any((mid > vx0) & (mid < vx1) & (row >= vc0) & (row < vc1), axis=1)


def unit_rectangles(wall: Wall):
    """``(course, x0, x1)`` of every unit after the bond, the cuts and the sliver merging."""
    c, x, joint = _course_breakpoints(wall)
    voids = _void_boxes(wall.openings)[:4]
    while True:
        left, course, x0, x1 = _segments(c, x)
        solid = ~_in_voids(course, x0, x1, voids)
        # A head joint can go only between two solid pieces of the same course.
        solid_left = np.zeros(x.size, dtype=bool)
        solid_right = np.zeros(x.size, dtype=bool)
        solid_left[left + 1] = solid
        solid_right[left] = solid
        removable = joint & solid_left & solid_right
        short = solid & (x1 - x0 < 0.5 * wall.unit_length - wall.tol)
        right_end, left_end = left[short] + 1, left[short]
        drop = np.where(removable[right_end], right_end, np.where(removable[left_end], left_end, -1))
        drop = np.unique(drop[drop >= 0])
        if drop.size == 0:
            return course[solid], x0[solid], x1[solid]
        keep = np.ones(x.size, dtype=bool)
        keep[drop] = False
        c, x, joint = c[keep], x[keep], joint[keep]


def masonry_blocks(wall: Wall):
    """``(x0, x1, y0, y1, role)`` of units and lintels, course by course, left to right."""
    role = flags("block_role")
    course, x0, x1 = unit_rectangles(wall)
    lintels = [o for o in wall.openings if o.lintel_bearing > 0]
    l_course = np.array([o.course1 for o in lintels], dtype=np.int64)
    l_x0 = np.array([o.x0 - o.lintel_bearing for o in lintels], dtype=float)
    l_x1 = np.array([o.x1 + o.lintel_bearing for o in lintels], dtype=float)
    course = np.concatenate((course, l_course))
    x0 = np.clip(np.concatenate((x0, l_x0)), 0.0, wall.width)
    x1 = np.clip(np.concatenate((x1, l_x1)), 0.0, wall.width)
    kinds = np.concatenate((np.full(x0.size - l_x0.size, role["unit"]), np.full(l_x0.size, role["lintel"])))
    order = np.lexsort((x0, course))
    y0 = course[order] * wall.unit_height
    return x0[order], x1[order], y0, y0 + wall.unit_height, kinds[order].astype(np.int8)


# --------------------------------------------------------------------------- the dataset


def build(spec, *, validate: bool = True) -> xr.Dataset:
    """Build the model dataset of a wall spec (a dict, a path, a Traversable or TOML text).

    Blocks come course by course, left to right (units and lintels), then the
    supports in spec order; interfaces, kinds and loads as every model gets them
    (:mod:`masonryfw.blocks`). Raises :class:`SpecError` naming the key at fault.
    The model is returned checked (:func:`masonryfw.checked_model`), unless
    ``validate`` is False.
    """
    spec_dict, text = _read_spec(spec)
    wall = parse_spec(spec_dict)
    mx0, mx1, my0, my1, m_role = masonry_blocks(wall)
    s_x0 = np.array([s.start for s in wall.supports])
    s_x1 = np.array([s.end for s in wall.supports])
    x0, x1 = np.concatenate((mx0, s_x0)), np.concatenate((mx1, s_x1))
    y0 = np.concatenate((my0, np.full(s_x0.size, -wall.unit_height)))
    y1 = np.concatenate((my1, np.zeros(s_x0.size)))
    role = np.concatenate((m_role, np.full(s_x0.size, flags("block_role")["fixed_support"], dtype=np.int8)))
    supports = [blocks.Support(f"spec key 'supports.{s.name}'", s.kind, s.motion, s.pivot) for s in wall.supports]
    material = blocks.Material(wall.unit_weight, wall.friction, wall.cohesion, wall.tensile_strength,
                               wall.young_modulus, wall.poisson_ratio)
    attrs = {"title": wall.title, "source_spec": text}
    if wall.description:
        attrs["comment"] = wall.description
    ds = blocks.model_from_blocks(*blocks.rectangle_nodes(x0, x1, y0, y1), role, wall.thickness, material, supports,
                                  wall.loading, wall.tilt_direction, attrs)
    return checked_model(ds, repr(wall.title)) if validate else ds


# --------------------------------------------------------------------------- TOML output

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.match(key) else json.dumps(key)


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise SpecError(f"cannot write a {type(value).__name__} value ({value!r}) to TOML")


def dump_toml(spec: dict, _prefix: str = "") -> str:
    """TOML text of a spec dict (scalars, arrays, tables, arrays of tables): the ``source_spec`` of a dict."""
    lines, tables = [], []
    for key, value in spec.items():
        if isinstance(value, dict):
            tables.append((key, value, False))
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            tables.append((key, value, True))
        else:
            lines.append(f"{_toml_key(key)} = {_toml_value(value)}")
    text = "\n".join(lines) + ("\n" if lines else "")
    for key, value, is_array in tables:
        name = _prefix + _toml_key(key)
        if is_array:
            for item in value:
                text += f"\n[[{name}]]\n" + dump_toml(item, name + ".")
        else:
            body = dump_toml(value, name + ".")
            has_scalars = not value or not all(isinstance(v, dict) for v in value.values())
            text += (f"\n[{name}]\n" if has_scalars else "") + body
    return text
