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
  support range, or one per segment of a ``[settlement]`` profile
  (:mod:`masonryfw.ground.profiles`: a greenfield trough, a tilt or measured rates).
* **Interfaces, kinds and loads** as every model gets them (:mod:`masonryfw.builders.blocks`):
  self-weight of units and lintels; settlement loading puts ``+R`` dead and
  ``-R`` live (vertical) on every moving support, ``R = W L_m / L_total`` from
  the support contacts actually found; tilt loading puts the weight
  horizontally as live load on every unit and lintel and holds every support.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..format.model import checked_model
from ..format.roles import ROLE
from ..ground.profiles import SETTLEMENT_KEYS, Profile, read_profile, with_profile
from ..readers.material import Material
from ..readers.spec import (
    SpecTable,
    model_attributes,
    open_spec,
    read_loading,
    read_material,
    refuse_ground_twice,
)
from ..runtime.errors import SpecError
from ..runtime.inputs import fits_in_memory
from . import blocks
from .bond import pattern_cells
from .supports import Support, profile_supports, read_supports, support_rectangles

if TYPE_CHECKING:  # annotations only
    import xarray as xr

#: Relative tolerance on "a whole number of courses" (heights divided by the unit height).
COURSE_TOLERANCE = 1.0e-6
#: Position tolerance, relative to the wall size.
POSITION_TOLERANCE = 1.0e-9

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
class ParametricWall:
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
    material: Material
    openings: tuple[Opening, ...]
    supports: tuple[Support, ...]
    loading: str
    tilt_direction: int
    profile: Profile | None = None

    @property
    def height(self) -> float:
        return self.courses * self.unit_height

    @property
    def tol(self) -> float:
        return POSITION_TOLERANCE * max(self.width, self.height)


_TOP_KEYS = ("title", "description", "space", "length_unit", "wall", "unit", "bond", "material",
             "openings", "supports", "settlement", "loading")
_OPENING_KEYS = ("x", "y", "width", "height", "lintel_bearing")


def parse_spec(spec: dict) -> ParametricWall:
    """Validate a spec dict and return it in SI; a :class:`SpecError` names the offending key."""
    top = open_spec(spec, _TOP_KEYS)
    unit_name = top.raw("length_unit", "m")

    wall = top.sub("wall", ("width", "height", "thickness"))
    width = wall.number("width", length=True, positive=True)
    height = wall.number("height", length=True, positive=True)
    thickness = wall.number("thickness", length=True, positive=True)
    unit = top.sub("unit", ("length", "height"))
    unit_length = unit.number("length", length=True, positive=True)
    unit_height = unit.number("height", length=True, positive=True)
    courses = _whole_courses(height, unit_height, wall.key("height"), wall.raw("height"))
    blocks_expected = courses * (math.ceil(width / unit_length) + 1)
    sized = (f"spec: {wall.key('width')} = {wall.raw('width')!r} {unit_name} and {wall.key('height')} = "
             f"{wall.raw('height')!r} {unit_name} in units of {unit.raw('length')!r} x {unit.raw('height')!r} "
             f"{unit_name}")
    fits_in_memory(blocks_expected * blocks.BYTES_PER_BLOCK, f"{sized} (about {blocks_expected:.3g} blocks)",
                   "is the size or the length_unit what was meant?")
    bond = top.sub("bond", ("pattern", "first_course"), {})

    material = read_material(top)
    refuse_ground_twice(top)
    supports = () if top.has("settlement") else read_supports(top, 0.0, width)
    kind, direction = read_loading(top, top.has("settlement") or any(s.kind == "moving" for s in supports))

    result = ParametricWall(
        title=top.text("title"),
        description=top.text("description", ""),
        width=width,
        courses=courses,
        thickness=thickness,
        unit_length=unit_length,
        unit_height=unit_height,
        pattern=bond.choice("pattern", ("running", "stack"), "running"),
        first_course=bond.choice("first_course", ("full", "half"), "full"),
        material=material,
        openings=(),
        supports=supports,
        loading=kind,
        tilt_direction=direction,
    )
    result = replace(result, openings=_openings(top, result))
    if top.has("settlement"):
        table = top.sub("settlement", SETTLEMENT_KEYS)
        result = replace(result, profile=read_profile(table, 0.0, result.width, result.unit_length))
        segments = round(result.width / result.profile.segment)
        fits_in_memory((blocks_expected + segments) * blocks.BYTES_PER_BLOCK,
                       f"{sized} over {segments:,} ground segments of {table.key('segment')} = "
                       f"{result.profile.segment:.3g} m (about {blocks_expected + segments:.3g} blocks)",
                       "a longer segment")
        mx0, mx1, my0, _, _ = masonry_rectangles(result)
        bottom = my0 <= result.tol
        result = replace(result, supports=profile_supports(result.profile, 0.0, result.width,
                                                           np.c_[mx0[bottom], mx1[bottom]]))
    return result


def _whole_courses(value: float, unit_height: float, key: str, shown) -> int:
    """``value / unit_height`` if it is a whole number (relative tolerance), else a SpecError."""
    ratio = value / unit_height
    count = round(ratio)
    if abs(ratio - count) > COURSE_TOLERANCE * max(1.0, ratio):
        raise SpecError(f"spec key {key!r} = {shown!r}: must be a whole number of courses "
                        f"({ratio:.4g} times unit.height)")
    return int(count)


def _openings(top: SpecTable, wall: ParametricWall) -> tuple[Opening, ...]:
    entries = top.raw("openings", [])
    if not isinstance(entries, list):
        raise SpecError(f"spec key 'openings' must be an array of tables ([[openings]]), got {entries!r}")
    tol = wall.tol
    openings = []
    for index, table in enumerate(entries):
        entry = SpecTable(table, f"openings[{index}]", _OPENING_KEYS, top.scale)
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


def first_joints(wall: ParametricWall) -> np.ndarray:
    """Per course, its first head joint from the wall's left end: the bond's one definition of where a course
    starts (:func:`masonryfw.builders.bond.pattern_cells`: a half unit in, or a full one)."""
    return np.array([pattern_cells(course, wall.pattern, wall.unit_length, wall.unit_length, wall.first_course)[0]
                     or wall.unit_length for course in range(wall.courses)])


def _bond_joints(wall: ParametricWall, first: float) -> np.ndarray:
    """Head-joint positions of a course whose first joint is at ``first``, wall ends included: the pattern's
    cells of one unit (running and stack bond) repeated across the width."""
    count = max(0, math.ceil((wall.width - wall.tol - first) / wall.unit_length))
    inner = first + wall.unit_length * np.arange(count)
    inner = inner[inner < wall.width - wall.tol]
    return np.concatenate(([0.0], inner, [wall.width]))


def _course_breakpoints(wall: ParametricWall):
    """Sorted breakpoints ``(course, x, is_head_joint)`` of all courses: head joints and cut edges. The fast
    path of a rectangular wall in running or stack bond (the other bonds and outlines are laid by
    :func:`masonryfw.builders.bond.lay`): the courses that start alike share one row of joints."""
    first_joint = first_joints(wall)
    courses = np.arange(wall.courses)
    xs, cs, joint = [], [], []
    for first in np.unique(first_joint)[::-1]:
        rows = courses[first_joint == first]
        line = _bond_joints(wall, float(first))
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


def unit_rectangles(wall: ParametricWall):
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


def masonry_rectangles(wall: ParametricWall):
    """``(x0, x1, y0, y1, role)`` of units and lintels, course by course, left to right."""
    course, x0, x1 = unit_rectangles(wall)
    lintels = [o for o in wall.openings if o.lintel_bearing > 0]
    l_course = np.array([o.course1 for o in lintels], dtype=np.int64)
    l_x0 = np.array([o.x0 - o.lintel_bearing for o in lintels], dtype=float)
    l_x1 = np.array([o.x1 + o.lintel_bearing for o in lintels], dtype=float)
    course = np.concatenate((course, l_course))
    x0 = np.clip(np.concatenate((x0, l_x0)), 0.0, wall.width)
    x1 = np.clip(np.concatenate((x1, l_x1)), 0.0, wall.width)
    kinds = np.concatenate((np.full(x0.size - l_x0.size, ROLE["unit"]), np.full(l_x0.size, ROLE["lintel"])))
    order = np.lexsort((x0, course))
    y0 = course[order] * wall.unit_height
    return x0[order], x1[order], y0, y0 + wall.unit_height, kinds[order].astype(np.int8)


# --------------------------------------------------------------------------- the dataset


def build_parametric(spec_dict: dict, text: str, validate: bool = True) -> xr.Dataset:
    """The model of a wall of rectangular units (module docstring); checked unless ``validate`` is False."""
    wall = parse_spec(spec_dict)
    mx0, mx1, my0, my1, m_role = masonry_rectangles(wall)
    s_x0, s_x1, s_y0, s_y1, supports = support_rectangles(wall.supports, 0.0, wall.unit_height)
    x0, x1 = np.concatenate((mx0, s_x0)), np.concatenate((mx1, s_x1))
    y0, y1 = np.concatenate((my0, s_y0)), np.concatenate((my1, s_y1))
    role = np.concatenate((m_role, np.full(s_x0.size, ROLE["fixed_support"], dtype=np.int8)))
    attrs = model_attributes(wall.title, wall.description, text)
    ds = blocks.model_from_blocks(*blocks.rectangle_nodes(x0, x1, y0, y1), role, wall.thickness, wall.material,
                                  supports, wall.loading, wall.tilt_direction, attrs)
    ds = with_profile(ds, wall.profile)
    return checked_model(ds, repr(wall.title)) if validate else ds
