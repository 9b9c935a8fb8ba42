"""Buildings in 3D from a spec's ``[building]`` table: walls on base lines in plan, laid course by course, toothed
at their corners, with openings, lintels, floor loads and the ground cut into segments that follow a
settlement profile in plan (docs/buildings.md).

A wall runs from ``start`` to ``end`` (its base line, the middle of its thickness), ``height`` high in whole
courses. Units are boxes ``unit.length`` long, ``unit.height`` high and ``unit.depth`` deep (the wall's
thickness unless given: one leaf); a wall is a whole number of leaves. The bond is running (every other course
shifted by half a unit, every leaf alike and unbound but by its collar joints), English (a course of headers
through the wall's thickness every ``header_every`` courses, 2 by default, the courses between in running bond)
or Flemish (stretcher and header alternating in every course, each header centred on the stretcher below),
the patterns of the 2D walls (:func:`masonryfw.builders.bond.pattern_cells`) with the unit's depth as the header.
Where two walls meet end to end, at any angle of :data:`MIN_ANGLE` or more, the corner is toothed: in even
courses the wall listed first runs through the corner to the other's outer face and the other stops at its
inner face; in odd courses the other way round. A wall ending on another's base line (a T) stops at its face
in even courses and runs through it in odd ones; two walls crossing run through in turn; walls drawn to a
common point make the same junctions (:func:`meeting`). Where a wall meets
another at an angle its end follows the other's face: the end blocks are prisms with a slanted end
(:class:`Cut`), the rest boxes. An opening takes its courses
(its sill and head moved onto the nearest bed joints, said in ``laying_notes``) and a lintel one course high
bears ``lintel_bearing`` into the masonry on either side. Floors are line loads [N/m] on the course at their
height. Every wall stands on support blocks ``support_depth`` deep, cut into segments ``segment`` long under
its first course; a segment follows the settlement profile at its two ends (settles by its mean rate and
turns about the horizontal axis across the wall with the slope between them).
"""
from __future__ import annotations

import itertools
import json
import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import shapely
import xarray as xr

from ..format.roles import ROLE
from ..format.schema import variable_attrs
from ..geometry import polyhedra
from ..ground.ground_plan import SETTLEMENT_3D_KEYS, GroundInPlan, profile_in_plan
from ..ground.profiles import refuse_fine_segments, with_profile
from ..readers.material import Material
from ..readers.spec import SpecTable, model_attributes, open_spec, read_material
from ..runtime.errors import SpecError
from ..runtime.inputs import fits_in_memory
from ..runtime.resources import count_text
from .bond import pattern_cells
from .on_ground import model_on_ground

BUILDING_KEYS = ("unit", "walls", "floors", "support_depth", "segment", "bond", "header_every")
WALL_KEYS = ("name", "start", "end", "height", "thickness", "openings", "bond", "header_every")
BONDS = ("running", "english", "flemish")
OPENING_KEYS = ("x", "y", "width", "height", "lintel_bearing")
FLOOR_KEYS = ("walls", "height", "load")
TOP_KEYS = ("title", "description", "space", "length_unit", "building", "material", "settlement")
#: A piece of a unit shorter than this share of the unit length joins its neighbour.
SLIVER = 0.25
#: Walls meeting at less than this angle [degrees] are refused: a slanted end would run far along the wall.
MIN_ANGLE = 30.0
#: Bytes of memory a block of a building takes while it is laid and made a model (the house at 1,126 to 9,663
#: blocks took 20-27 kB a block at its peak, ``/usr/bin/time``): what :func:`refuse_too_big` counts.
BYTES_PER_BLOCK = 32 * 2**10
#: The least depth of the ground blocks, in courses: a thinner block has faces closer than the contacts' tolerance.
MIN_SUPPORT_DEPTH = 0.01


@dataclass(frozen=True)
class PlanWall:
    name: str
    start: np.ndarray  # (2,) [m]
    end: np.ndarray
    height: float
    thickness: float
    openings: tuple[tuple[float, float, float, float, float], ...]  # x, y, width, height, lintel bearing
    bond: str = "running"
    header_every: int = 2  # English bond: a course of headers every this many courses
    leaves: int = 1

    @property
    def depth(self) -> float:
        """A leaf's depth: a unit's, and a header's length along the wall."""
        return self.thickness / self.leaves

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.end - self.start))

    @property
    def along(self) -> np.ndarray:
        return (self.end - self.start) / self.length

    @property
    def across(self) -> np.ndarray:
        """The left normal: (along, across, z) is right-handed."""
        return np.array([-self.along[1], self.along[0]])


def is_building(spec: dict) -> bool:
    return "building" in spec


def read_walls(building: SpecTable, unit_length: float, unit_height: float, unit_depth: float | None,
               notes: list[str]) -> list[PlanWall]:
    raw = building.raw("walls")
    if not isinstance(raw, list) or not raw:
        raise SpecError(f"spec key {building.key('walls')!r} must be a list of tables [[building.walls]]")
    walls = []
    for i, table in enumerate(raw):
        wall = SpecTable(table, f"{building.key('walls')}[{i}]", WALL_KEYS, building.scale)
        start, end = np.array(wall.point("start")), np.array(wall.point("end"))
        if np.linalg.norm(end - start) <= 1e-9 * (1.0 + np.linalg.norm(start)):
            raise SpecError(f"spec keys {wall.key('start')!r} and {wall.key('end')!r}: the wall has no length")
        height = wall.number("height", length=True, positive=True)
        courses = height / unit_height
        if abs(courses - round(courses)) > 1e-6 * courses:
            raise SpecError(f"spec key {wall.key('height')!r} = {wall.raw('height')!r}: not whole courses of "
                            f"{unit_height / building.scale:g} ({courses:.4g} courses)")
        thickness = wall.number("thickness", length=True, positive=True)
        name = wall.text("name", f"wall {i}")
        bond = wall.choice("bond", BONDS, building.choice("bond", BONDS, "running"))
        every = wall.integer("header_every", building.integer("header_every", 2, minimum=2), minimum=2)
        leaves = read_leaves(wall, name, bond, thickness, unit_length, unit_depth, notes)
        walls.append(PlanWall(name, start, end, round(courses) * unit_height, thickness, read_openings(wall, unit_length),
                          bond, every, leaves))
    names = [w.name for w in walls]
    if len(set(names)) != len(names):
        raise SpecError(f"spec key {building.key('walls')!r}: two walls are named {next(n for n in names if names.count(n) > 1)!r}")
    return walls


def read_leaves(wall: SpecTable, name: str, bond: str, thickness: float, unit_length: float,
                unit_depth: float | None, notes: list[str]) -> int:
    """How many leaves a wall of ``thickness`` is, of units ``unit_depth`` deep (one leaf when it is not given, in
    running bond; a header's length, half a unit, in English and Flemish): a whole number, and at least two in
    the bonds whose headers bind leaves."""
    depth = unit_depth if unit_depth is not None else (thickness if bond == "running" else 0.5 * unit_length)
    leaves = thickness / depth
    if abs(leaves - round(leaves)) > 1e-6 * leaves or round(leaves) < 1:
        raise SpecError(f"spec key {wall.key('thickness')!r}: wall {name!r} is {thickness:g} m thick, not a whole "
                        f"number of leaves of units {depth:g} m deep ({leaves:.4g})")
    if bond != "running" and round(leaves) < 2:
        raise SpecError(f"spec key {wall.key('bond')!r}: wall {name!r} in {bond} bond is one leaf ({thickness:g} m "
                        f"thick, units {depth:g} m deep); its headers bind two leaves or more")
    if bond != "running" and depth >= unit_length * (1 - 1e-9):
        raise SpecError(f"spec key 'building.unit.depth': units {depth:g} m deep and {unit_length:g} m long: a "
                        "header (the unit's depth along the wall) must be shorter than a stretcher")
    if bond != "running" and abs(thickness - unit_length) > 1e-9 * unit_length:
        notes.append(f"wall {name!r}: its headers run through its {thickness:.4g} m thickness (units "
                     f"{unit_length:.4g} m long)")
    return round(leaves)


def read_openings(wall: SpecTable, unit_length: float) -> tuple[tuple[float, float, float, float, float], ...]:
    raw = wall.raw("openings", [])
    if not isinstance(raw, list):
        raise SpecError(f"spec key {wall.key('openings')!r} must be a list of tables")
    openings = []
    for i, table in enumerate(raw):
        opening = SpecTable(table, f"{wall.key('openings')}[{i}]", OPENING_KEYS, wall.scale)
        openings.append((opening.number("x", length=True, minimum=0.0), opening.number("y", length=True, minimum=0.0),
                         opening.number("width", length=True, positive=True),
                         opening.number("height", length=True, positive=True),
                         opening.number("lintel_bearing", 0.5 * unit_length / wall.scale, length=True, minimum=0.0)))
    return tuple(openings)


class Cut(NamedTuple):
    """A vertical plane across a wall, in the wall's frame: ``s = at + slope * q`` along its base line at ``q``
    across it. A free end, a head joint or an opening's side is square to the wall (slope 0); where it meets
    another wall at an angle, the other wall's face is slanted."""

    at: float
    slope: float = 0.0

    def at_face(self, q: float) -> float:
        return self.at + self.slope * q

    def span(self, half: float) -> tuple[float, float]:
        """Its least and greatest ``s`` over a wall ``2 half`` thick."""
        return self.at - abs(self.slope) * half, self.at + abs(self.slope) * half


class End(NamedTuple):
    """How a wall's end meets another wall: in the courses the wall owns it runs through to the other's far face
    (or, ``continued`` by a wall in line with it, stops at the point they meet), in the others it stops at the
    other's near face."""

    other: int
    even_owner: int  # the wall that owns the even courses
    continued: bool = False


class Junctions(NamedTuple):
    """Where walls meet: ``ends[(wall, end)]`` (end 0: its start, 1: its end), and where a wall is cut for another
    running through it, ``cuts``: (the wall cut, the wall through it, the parity of the courses cut)."""

    ends: dict[tuple[int, int], End]
    cuts: list[tuple[int, int, int]]


def junctions(walls: list[PlanWall], tol: float) -> Junctions:
    """The corners (two walls' ends at one point), T-junctions (a wall's end on another's base line between its
    ends, or three walls' ends at a point, two of them in line) and crossings (two base lines crossing between
    their ends, or four walls' ends at a point in two lines) of ``walls``, each at :data:`MIN_ANGLE` or more. A
    corner's first-listed wall runs through in even courses; a T's through wall (or the two walls in line) in
    even courses and the abutting wall in odd ones; at a crossing the first-listed wall (or line) in even
    courses and the other in odd ones. Other meetings are refused, naming the walls."""
    meets: dict[tuple[int, int], End] = {}
    for group in ends_together(walls, tol):
        meets.update(meeting(walls, group))
    cuts = []
    for w, wall in enumerate(walls):
        for e, point in ((0, wall.start), (1, wall.end)):
            if (w, e) in meets:
                continue
            for v, other in enumerate(walls):
                offset = float((point - other.start) @ other.along)
                if v != w and abs(float((point - other.start) @ other.across)) <= tol and 0 < offset < other.length:
                    steep_enough(walls, w, v)
                    meets[(w, e)] = End(v, v)
                    cuts.append((v, w, 1))
    for first, second in itertools.combinations(range(len(walls)), 2):
        crossing = base_lines_cross(walls[first], walls[second], tol)
        if crossing:
            steep_enough(walls, first, second)
            cuts += [(first, second, 1), (second, first, 0)]
    return Junctions(meets, cuts)


def ends_together(walls: list[PlanWall], tol: float) -> list[list[tuple[int, int]]]:
    """The walls' ends, ``(wall, end)``, grouped by the point they are at (within ``tol``), groups of two or more."""
    groups: list[tuple[np.ndarray, list[tuple[int, int]]]] = []
    for w, wall in enumerate(walls):
        for e, point in ((0, wall.start), (1, wall.end)):
            group = next((g for p, g in groups if np.linalg.norm(point - p) <= tol), None)
            if group is None:
                groups.append((point, [(w, e)]))
            else:
                group.append((w, e))
    return [group for _, group in groups if len(group) > 1]


def meeting(walls: list[PlanWall], group: list[tuple[int, int]]) -> dict[tuple[int, int], End]:
    """How the walls whose ends are at one point meet: two at an angle (a corner), three of which two are in line
    (a T), four in two lines (a crossing)."""
    def outward(w: int, e: int) -> np.ndarray:
        return walls[w].along if e == 0 else -walls[w].along

    names = ", ".join(repr(walls[w].name) for w, _ in group)
    point = (walls[group[0][0]].start, walls[group[0][0]].end)[group[0][1]]
    lines = [(a, b) for a, b in itertools.combinations(group, 2) if float(outward(*a) @ outward(*b)) < -1 + 1e-9]
    if len(group) == 2 and not lines:
        (wa, _), (wb, _) = group
        steep_enough(walls, wa, wb)
        return {group[0]: End(wb, min(wa, wb)), group[1]: End(wa, min(wa, wb))}
    in_line = {end for line in lines for end in line}
    if len(group) == 3 and len(lines) == 1 or len(group) == 4 and len(lines) == 2 and len(in_line) == 4:
        lines = sorted(lines, key=lambda line: min(line[0][0], line[1][0]))  # the first-listed wall's line first
        through = lines[0]
        crossing = lines[1] if len(lines) > 1 else tuple(end for end in group if end not in in_line)
        for line in lines:
            if abs(walls[line[0][0]].thickness - walls[line[1][0]].thickness) > 1e-9:
                raise SpecError(f"walls {walls[line[0][0]].name!r} and {walls[line[1][0]].name!r} continue each "
                                "other in a line with different thicknesses; the walls meeting them would not fit")
        steep_enough(walls, through[0][0], crossing[0][0])
        owner = through[0][0]
        ends = {end: End(crossing[0][0], end[0], continued=True) for end in through}
        ends.update({end: End(owner, owner, continued=len(crossing) == 2) for end in crossing})
        return ends
    if len(group) == 2:
        raise SpecError(f"walls {names} continue each other in a line at ({point[0]:.6g}, {point[1]:.6g}): make "
                        "them one wall (a wall's openings may be anywhere along it)")
    raise SpecError(f"walls {names} meet at ({point[0]:.6g}, {point[1]:.6g}): at a point, two walls (a corner), three "
                    "of which two are in line (a T) or four in two lines (a crossing) are toothed, not this")


def base_lines_cross(a: PlanWall, b: PlanWall, tol: float) -> bool:
    """Whether the base lines of ``a`` and ``b`` cross between the ends of both (further than ``tol`` from every
    end)."""
    matrix = np.c_[a.along, -b.along]
    if abs(np.linalg.det(matrix)) < 1e-12:
        return False
    s, r = np.linalg.solve(matrix, b.start - a.start)
    return bool(tol < s < a.length - tol and tol < r < b.length - tol)


def steep_enough(walls: list[PlanWall], a: int, b: int) -> None:
    """Refuse two meeting walls at less than :data:`MIN_ANGLE` to each other."""
    sine = abs(float(walls[a].along @ walls[b].across))
    if sine < math.sin(math.radians(MIN_ANGLE)):
        raise SpecError(f"walls {walls[a].name!r} and {walls[b].name!r} meet at "
                        f"{math.degrees(math.asin(min(sine, 1.0))):.4g} degrees: walls are toothed at {MIN_ANGLE:g} "
                        "degrees or more")


def face_cut(wall: PlanWall, other: PlanWall, side: float) -> Cut:
    """Where ``other``'s face on ``side`` (+1: its left, -1: its right) crosses ``wall``, in ``wall``'s frame."""
    along, across = float(wall.along @ other.across), float(wall.across @ other.across)
    return Cut((0.5 * side * other.thickness - float((wall.start - other.start) @ other.across)) / along,
               -across / along)


def course_extent(walls: list[PlanWall], joins: Junctions, courses: list[int], w: int, course: int) -> tuple[Cut, Cut]:
    """The wall's ends in ``course``: through a junction it runs through in this course (to the other wall's far
    face), short of one it does not (to the other's near face); square where it is free (or the other wall has
    no such course)."""
    wall = walls[w]
    extent = [Cut(0.0), Cut(wall.length)]
    for e, inwards in ((0, wall.along), (1, -wall.along)):
        if (w, e) not in joins.ends or course >= courses[joins.ends[(w, e)].other]:
            continue
        other, even_owner, continued = joins.ends[(w, e)]
        owner = even_owner if course % 2 == 0 else (w if even_owner == other else other)
        if owner == w and continued:  # its line runs on through the other wall's place: it stops where they meet
            continue
        near = math.copysign(1.0, float(inwards @ walls[other].across))  # the other's face on this wall's side
        extent[e] = face_cut(wall, walls[other], -near if owner == w else near)
    return extent[0], extent[1]


def junction_gaps(walls: list[PlanWall], joins: Junctions, courses: list[int], v: int
                  ) -> dict[int, list[tuple[Cut, Cut]]]:
    """``{course: [(start, end)]}``: where another wall runs through wall ``v`` (a T's abutting wall in odd
    courses, a crossing wall in the courses it runs through), between its two faces."""
    gaps: dict[int, list[tuple[Cut, Cut]]] = {}
    for cut, w, parity in joins.cuts:
        if cut == v:
            faces = sorted((face_cut(walls[v], walls[w], side) for side in (1.0, -1.0)), key=lambda c: c.at)
            for k in range(parity, min(courses[v], courses[w]), 2):
                gaps.setdefault(k, []).append((faces[0], faces[1]))
    return gaps


def course_cells(wall: PlanWall, course: int, origin: float, a: float, b: float, unit_length: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The starts of the bond's cells covering ``[a, b]`` in ``course`` (the pattern repeated both ways from
    ``origin``) and whether each is a header (through the wall's thickness) or a stretcher (one per leaf)."""
    depth = wall.depth
    if wall.bond == "english":
        header_course = course % wall.header_every == wall.header_every - 1
        first, lengths = pattern_cells(1, "english", unit_length, depth) if header_course else \
            pattern_cells(course % wall.header_every, "running", unit_length, depth)
        headers = [header_course] * len(lengths)
    else:
        first, lengths = pattern_cells(course, wall.bond, unit_length, depth)
        headers = [wall.bond == "flemish" and length == depth for length in lengths]
    period = sum(lengths)
    offsets = np.concatenate(([0.0], np.cumsum(lengths)[:-1]))
    repeats = np.arange(math.floor((a - origin - first) / period) - 1, math.ceil((b - origin - first) / period) + 1)
    return (origin + first + repeats[:, None] * period + offsets).ravel(), np.tile(headers, repeats.size)


def pieces(a: Cut, b: Cut, starts: np.ndarray, headers: np.ndarray, unit_length: float, half: float
           ) -> list[tuple[Cut, Cut, bool]]:
    """The range from ``a`` to ``b`` of a wall ``2 half`` thick cut at the cells' ``starts`` (square head joints,
    none where a slanted end passes), each piece a header if its cell is; a piece shorter than :data:`SLIVER` of
    a unit on either face joins its neighbour (and takes its kind)."""
    tol = 1e-9 * unit_length

    def shortest(p: Cut, q: Cut) -> float:
        return min(q.at_face(side * half) - p.at_face(side * half) for side in (-1.0, 1.0))

    if shortest(a, b) <= tol:
        return []
    inside = starts[(starts > a.span(half)[1] + tol) & (starts < b.span(half)[0] - tol)]
    cuts = [a, *(Cut(float(x)) for x in inside), b]
    parts = [(p, q, bool(headers[np.searchsorted(starts, 0.5 * (p.at + q.at), side="right") - 1]))
             for p, q in zip(cuts[:-1], cuts[1:]) if shortest(p, q) > tol]
    sliver = SLIVER * unit_length - tol
    if len(parts) > 1 and shortest(*parts[0][:2]) < sliver:
        parts[:2] = [(parts[0][0], parts[1][1], parts[1][2])]
    if len(parts) > 1 and shortest(*parts[-1][:2]) < sliver:
        parts[-2:] = [(parts[-2][0], parts[-1][1], parts[-2][2])]
    return parts


def whole_at_end(parts: list[tuple[Cut, Cut, bool]], unit_length: float) -> list[tuple[Cut, Cut, bool]]:
    """Stretchers ``parts`` ending square with a whole unit last (the quoin of a corner the course runs through)
    and the rest of the last two in the piece before it (a closer; one longer piece when the closer would be a
    sliver)."""
    if len(parts) < 2 or parts[-1][1].at - parts[-1][0].at >= unit_length * (1 - 1e-9):
        return parts
    start, end = parts[-2][0], parts[-1][1]
    if end.at - start.at - unit_length < SLIVER * unit_length:
        return parts[:-2] + [(start, end, False)]
    return parts[:-2] + [(start, Cut(end.at - unit_length), False), (Cut(end.at - unit_length), end, False)]


@dataclass
class LaidMasonry:
    """Blocks in walls' frames as they are laid: wall, along from ``s0`` to ``s1`` (their ends' cuts: boxes, or
    prisms with a slanted end where walls meet at an angle), across [q0, q1] (from the wall's base line), course
    (z0, z1), role, extra dead load."""

    wall: list[int] = field(default_factory=list)
    s0: list[Cut] = field(default_factory=list)
    s1: list[Cut] = field(default_factory=list)
    q0: list[float] = field(default_factory=list)
    q1: list[float] = field(default_factory=list)
    z0: list[float] = field(default_factory=list)
    z1: list[float] = field(default_factory=list)
    role: list[int] = field(default_factory=list)
    load: list[float] = field(default_factory=list)  # a floor's line load times the length and share [N], down

    def add(self, wall: int, s: tuple[Cut, Cut], q: tuple[float, float], z: tuple[float, float], role: int):
        for name, value in zip(("wall", "s0", "s1", "q0", "q1", "z0", "z1", "role", "load"),
                               (wall, *s, *q, *z, role, 0.0)):
            getattr(self, name).append(value)


def lay_masonry(walls: list[PlanWall], joins: Junctions, unit_length: float, unit_height: float, notes: list[str]) -> LaidMasonry:
    """Every wall's courses: units in its bond between its course extents, openings left out, a lintel over each
    opening (module docstring)."""
    courses = [round(wall.height / unit_height) for wall in walls]
    laid = LaidMasonry()
    for w, wall in enumerate(walls):
        gaps = junction_gaps(walls, joins, courses, w)  # course: the ranges left open (by openings, other walls)
        lintels: dict[int, list[tuple[Cut, Cut]]] = {}  # course: the ranges of the lintels
        for number, (x, y, width, height, bearing) in enumerate(wall.openings):
            k0, k1 = round(y / unit_height), round((y + height) / unit_height)
            if abs(k0 * unit_height - y) > 1e-9 or abs(k1 * unit_height - y - height) > 1e-9:
                notes.append(f"wall {wall.name!r} openings[{number}]: sill and head moved onto bed joints "
                             f"(y {k0 * unit_height:.4g} m, height {(k1 - k0) * unit_height:.4g} m)")
            if k1 <= k0 or x + width > wall.length or k1 > courses[w]:
                raise SpecError(f"wall {wall.name!r} openings[{number}]: x {x:g}, y {y:g}, width {width:g}, height "
                                f"{height:g} m does not fit in the wall ({wall.length:.6g} m long, {wall.height:.6g} "
                                "m high, at least a course high)")
            for k in range(k0, k1):
                gaps.setdefault(k, []).append((Cut(x), Cut(x + width)))
            if k1 < courses[w]:
                lintels.setdefault(k1, []).append((Cut(max(x - bearing, 0.0)),
                                                   Cut(min(x + width + bearing, wall.length))))
        origin = course_extent(walls, joins, courses, w, 0)[0].at  # the bond starts with a full unit there
        half = 0.5 * wall.thickness
        leaves = [(-half + j * wall.depth, -half + (j + 1) * wall.depth) for j in range(wall.leaves)]
        for k in range(courses[w]):
            a, b = course_extent(walls, joins, courses, w, k)
            z = (k * unit_height, (k + 1) * unit_height)
            starts, headers = course_cells(wall, k, origin, a.span(half)[0], b.span(half)[1], unit_length)
            cut = sorted(gaps.get(k, []) + lintels.get(k, []), key=lambda gap: gap[0].at)
            bounds = [a, *(c for gap in cut for c in gap), b]
            if any(p.span(half)[1] > q.span(half)[0] + 1e-9 * unit_length for p, q in zip(bounds[:-1], bounds[1:])):
                raise SpecError(f"wall {wall.name!r}: its openings, lintels and the walls it meets overlap in course "
                                f"{k} ({k * unit_height:.4g} to {(k + 1) * unit_height:.4g} m); move them apart by a "
                                "unit or more")
            for p, q in zip(bounds[0::2], bounds[1::2]):
                parts = pieces(p, q, starts, headers, unit_length, half)
                if q.slope == 0 and q.at > wall.length + 1e-9 * unit_length and not headers.any():  # a quoin there
                    parts = whole_at_end(parts, unit_length)
                for s0, s1, header in parts:
                    for across in [(-half, half)] if header else leaves:
                        laid.add(w, (s0, s1), across, z, ROLE["unit"])
            for s in lintels.get(k, []):
                laid.add(w, s, (-half, half), z, ROLE["lintel"])
    return laid


def plan_corners(walls: list[PlanWall], laid: LaidMasonry) -> np.ndarray:
    """``(block, 4, 2)``: every laid block's corners in plan, anticlockwise: its ends' cuts at its two faces."""
    w = np.asarray(laid.wall)
    start = np.array([wall.start for wall in walls])[w]
    along = np.array([wall.along for wall in walls])[w]
    across = np.array([wall.across for wall in walls])[w]
    q = np.c_[laid.q0, laid.q0, laid.q1, laid.q1]
    at = np.array([[c.at for c in laid.s0], [c.at for c in laid.s1]]).T
    slope = np.array([[c.slope for c in laid.s0], [c.slope for c in laid.s1]]).T
    s = at[:, [0, 1, 1, 0]] + slope[:, [0, 1, 1, 0]] * q
    return start[:, None] + s[..., None] * along[:, None] + q[..., None] * across[:, None]


def refuse_overlaps(walls: list[PlanWall], laid: LaidMasonry, unit_length: float) -> None:
    """Refuse walls laid into one another (parallel walls closer than their half thicknesses, a wall ending inside
    another short of its base line): two boxes of one course whose plans share an area, the walls and the place
    named."""
    corners = plan_corners(walls, laid)
    level = np.round(np.asarray(laid.z0) / unit_length, 6)
    for z in np.unique(level):
        boxes = np.flatnonzero(level == z)
        polygons = shapely.polygons(corners[boxes])
        pairs = shapely.STRtree(polygons).query(polygons, predicate="intersects")
        pairs = pairs[:, pairs[0] < pairs[1]]
        if not pairs.shape[1]:
            continue
        common = shapely.area(shapely.intersection(polygons[pairs[0]], polygons[pairs[1]]))
        worst = int(np.argmax(common))
        if common[worst] > 1e-9 * unit_length**2:
            a, b = boxes[pairs[:, worst]]
            x, y = shapely.centroid(shapely.intersection(polygons[pairs[0, worst]], polygons[pairs[1, worst]])).coords[0]
            raise SpecError(f"walls {walls[laid.wall[a]].name!r} and {walls[laid.wall[b]].name!r} are laid into one "
                            f"another at ({x:.6g}, {y:.6g}), {laid.z0[a]:.4g} m up ({common[worst]:.3g} m2 in plan): "
                            "walls meet at their ends or on another's base line, or keep clear of each other")


def oriented_boxes(walls: list[PlanWall], laid: LaidMasonry) -> polyhedra.Polyhedra:
    """The laid blocks: their plans (:func:`plan_corners`) from ``z0`` to ``z1``, eight vertices and six faces
    each (a box, or a prism with a slanted end)."""
    plan = plan_corners(walls, laid)[:, [0, 1, 3, 2]]  # the box template's order: along fastest, then across
    z = np.c_[laid.z0, laid.z1]
    vertices = np.concatenate([np.tile(plan, (1, 2, 1)), np.repeat(z, 4, axis=1)[..., None]], axis=2).reshape(-1, 3)
    w = np.asarray(laid.wall)
    template = polyhedra.boxes(np.zeros((1, 3)), np.ones((1, 3)))
    n = w.size
    return polyhedra.Polyhedra(vertices, np.full(n, 8), np.full(n, 6), np.full(6 * n, 4),
                               np.tile(template.face_nodes, n))


def segment_motion(ground: GroundInPlan, ends: np.ndarray, along: np.ndarray, across: np.ndarray, depth: float
                   ) -> np.ndarray:
    """``(segment, 6)``: a ground segment's motion per unit t at its centroid, ``depth`` below the middle of its top
    edge from ``ends[:, 0]`` to ``ends[:, 1]`` (plan): the top edge follows the ground at both ends as in 2D
    (:meth:`GroundInPlan.motion`: down linear between them, sideways by the mean of theirs, turned about the
    wall's horizontal axis ``across``)."""
    down, horizontal = ground.motion(ends.reshape(-1, 2))
    down, horizontal = down.reshape(-1, 2), horizontal.reshape(-1, 2, 2)
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    theta = (down[:, 1] - down[:, 0]) / length  # about ``across``: (along x across) = z
    motion = np.zeros((ends.shape[0], 6))
    motion[:, :2] = horizontal.mean(axis=1) - (theta * 0.5 * depth)[:, None] * along
    motion[:, 2] = -down.mean(axis=1)
    motion[:, 3:5] = theta[:, None] * across
    return motion + 0.0


class BuildingPlan(NamedTuple):
    """A ``[building]`` spec read and checked, before anything is laid (what ``load_spec`` validates)."""

    top: SpecTable
    walls: list[PlanWall]
    joins: Junctions
    floors: list[Floor]
    material: Material
    ground_plan: GroundInPlan
    unit_length: float
    unit_height: float
    support_depth: float
    segment: float
    notes: list[str]


def read_building(spec: dict) -> BuildingPlan:
    """A ``[building]`` spec's keys read and checked, its walls' junctions found and its size weighed against the
    memory available, without laying a block; a :class:`SpecError` names the key."""
    top = open_spec(spec, TOP_KEYS, three_d="a [building]")
    building = top.sub("building", BUILDING_KEYS)
    unit = building.sub("unit", ("length", "height", "depth"))
    unit_length = unit.number("length", length=True, positive=True)
    unit_height = unit.number("height", length=True, positive=True)
    unit_depth = unit.number("depth", length=True, positive=True) if unit.has("depth") else None
    notes: list[str] = []
    walls = read_walls(building, unit_length, unit_height, unit_depth, notes)
    material = read_material(top)
    if not top.has("settlement"):
        raise SpecError("spec table 'settlement' is missing: a building stands on ground that moves by a profile "
                        "in plan ([settlement] with profile, axis_angle, center_x, center_y)")
    settlement = top.sub("settlement", SETTLEMENT_3D_KEYS)
    ground_plan = profile_in_plan(settlement, unit_length, max(w.length for w in walls))
    profile = ground_plan.profile
    depth = building.number("support_depth", unit_height / top.scale, length=True, positive=True)
    if depth < MIN_SUPPORT_DEPTH * unit_height:
        raise SpecError(f"spec key {building.key('support_depth')!r} = {building.raw('support_depth')!r}: the ground "
                        f"blocks would be {depth:.3g} m deep, less than {MIN_SUPPORT_DEPTH:g} of a course "
                        f"({unit_height:.4g} m); give at least {MIN_SUPPORT_DEPTH * unit_height / top.scale:.3g}")
    segment = building.number("segment", profile.segment / top.scale, length=True, positive=True)
    if building.has("segment"):
        refuse_fine_segments(max(w.length for w in walls), segment, unit_length, f"spec key {building.key('segment')!r}")
    refuse_too_big(walls, unit_length, unit_height, segment, building, top)
    joins = junctions(walls, 1e-6 * max(w.length for w in walls))
    return BuildingPlan(top, walls, joins, read_floors(building, walls, unit_height), material, ground_plan,
                        unit_length, unit_height, depth, segment, notes)


def build_building(spec: dict, text: str) -> xr.Dataset:
    """The 3D model of a spec with a ``[building]`` table (module docstring); a :class:`SpecError` names the key."""
    (top, walls, joins, floors, material, ground_plan, unit_length, unit_height, depth, segment,
     notes) = read_building(spec)
    profile = ground_plan.profile
    tol = 1e-6 * max(w.length for w in walls)
    laid = lay_masonry(walls, joins, unit_length, unit_height, notes)
    add_floors(floors, walls, laid, unit_height)
    courses = [round(w.height / unit_height) for w in walls]
    n_masonry = len(laid.wall)
    for w, wall in enumerate(walls):  # the ground under the first course, less where a crossing wall's ground is
        half = 0.5 * wall.thickness
        a, b = course_extent(walls, joins, courses, w, 0)
        crossed = sorted(junction_gaps(walls, joins, courses, w).get(0, []), key=lambda gap: gap[0].at)
        bounds = [a, *(c for gap in crossed for c in gap), b]
        for p, q in zip(bounds[0::2], bounds[1::2]):
            inner = np.linspace(p.at, q.at, max(1, round((q.at - p.at) / segment)) + 1)[1:-1]
            inner = inner[(inner > p.span(half)[1] + 1e-9 * segment) & (inner < q.span(half)[0] - 1e-9 * segment)]
            cuts = [p, *(Cut(float(x)) for x in inner), q]
            for s0, s1 in zip(cuts[:-1], cuts[1:]):
                laid.add(w, (s0, s1), (-half, half), (-depth, 0.0), ROLE["fixed_support"])
    refuse_overlaps(walls, laid, unit_length)
    poly = oriented_boxes(walls, laid)
    attrs = model_attributes(top.text("title"), top.text("description", ""), text, notes=notes, settlement_axis=ground_plan.axis_attr(), building_walls=json.dumps(
        [{"name": w.name, "start": w.start.tolist(), "end": w.end.tolist(), "height": w.height,
          "thickness": w.thickness, "ground": [c.at for c in course_extent(walls, joins, courses, k, 0)]}
         for k, w in enumerate(walls)]))
    model = _dataset(walls, laid, n_masonry, poly, material, ground_plan, depth, attrs, tol)
    return with_profile(model, profile)


def expected_blocks(walls: list[PlanWall], unit_length: float, unit_height: float) -> float:
    """About how many units and lintels the walls lay (a bound within about twice the count): per course, a leaf's
    row of stretchers on each leaf, and a row of headers where the bond has them."""
    count = 0.0
    for wall in walls:
        courses = wall.height / unit_height
        row = wall.length / unit_length + 2.0
        headers = wall.length / wall.depth + 2.0 if wall.bond != "running" else 0.0
        count += courses * (row * wall.leaves + headers)
    return count


def refuse_too_big(walls: list[PlanWall], unit_length: float, unit_height: float, segment: float, building: SpecTable,
                   top: SpecTable) -> None:
    """Refuse, before any laying, a building whose blocks and ground segments (counted from its keys) would not fit
    in the memory available (:func:`masonryfw.runtime.inputs.fits_in_memory`), naming the keys that size it."""
    blocks = expected_blocks(walls, unit_length, unit_height)
    segments = sum(wall.length / segment + 2.0 for wall in walls)
    unit = building.sub("unit", ("length", "height", "depth"))
    sized = (f"spec: {len(walls)} wall(s) of {sum(w.length for w in walls):.4g} m in all, up to "
             f"{max(w.height for w in walls):.4g} m high, in units of {building.key('unit')} = "
             f"{unit.raw('length')!r} x {unit.raw('height')!r} {top.raw('length_unit', 'm')}, on ground segments "
             f"{segment:.3g} m long ({count_text(blocks)} blocks and {count_text(segments)} ground segments)")
    fits_in_memory((blocks + segments) * BYTES_PER_BLOCK, sized,
                   "are the unit, the walls and length_unit what was meant?")


class Floor(NamedTuple):
    """A ``[[building.floors]]`` line load: ``load`` [N/m] on the course ``course`` (from 0) of the walls ``on``."""

    on: tuple[str, ...]
    course: int
    load: float


def read_floors(building: SpecTable, walls: list[PlanWall], unit_height: float) -> list[Floor]:
    """Each ``[[building.floors]]`` on the named walls' course whose top is nearest its height; a
    :class:`SpecError` names a wall that is not there or a height where none of its walls has a course."""
    names = [wall.name for wall in walls]
    courses = {wall.name: round(wall.height / unit_height) for wall in walls}
    floors = []
    for i, table in enumerate(building.raw("floors", [])):
        floor = SpecTable(table, f"{building.key('floors')}[{i}]", FLOOR_KEYS, building.scale)
        on = floor.raw("walls")
        if not isinstance(on, list) or not on or any(name not in names for name in on):
            raise SpecError(f"spec key {floor.key('walls')!r} = {on!r}: must list walls by name ({', '.join(names)})")
        course = round(floor.number("height", length=True, positive=True) / unit_height) - 1
        if not any(0 <= course < courses[name] for name in on):
            raise SpecError(f"spec key {floor.key('height')!r} = {floor.raw('height')!r}: no course of the walls "
                            f"{', '.join(on)} ends there")
        floors.append(Floor(tuple(on), course, floor.number("load", minimum=0.0)))
    return floors


def add_floors(floors: list[Floor], walls: list[PlanWall], laid: LaidMasonry, unit_height: float) -> None:
    """Each floor's line load on its walls' course, a block taking the load on its length and on its share of the
    wall's thickness."""
    for floor in floors:
        for b, (w, z0) in enumerate(zip(laid.wall, laid.z0)):
            if walls[w].name in floor.on and round(z0 / unit_height) == floor.course:
                share = (laid.q1[b] - laid.q0[b]) / walls[w].thickness
                middle = 0.5 * (laid.q0[b] + laid.q1[b])
                laid.load[b] += floor.load * (laid.s1[b].at_face(middle) - laid.s0[b].at_face(middle)) * share


def _dataset(walls, laid, n_masonry, poly, material, ground_plan, depth, attrs, tol) -> xr.Dataset:
    volume, _ = polyhedra.volumes_centroids(poly)
    weight = material.unit_weight * volume[:n_masonry] + np.array(laid.load[:n_masonry])
    wall = np.array(laid.wall[n_masonry:])
    starts = np.array([w.start for w in walls])[wall]
    along = np.array([w.along for w in walls])[wall]
    across = np.array([w.across for w in walls])[wall]
    s = np.array([[c.at for c in laid.s0[n_masonry:]], [c.at for c in laid.s1[n_masonry:]]]).T
    ends = starts[:, None, :] + s[..., None] * along[:, None, :]
    motion = segment_motion(ground_plan, ends, along, across, depth)
    z0 = np.asarray(laid.z0)
    model = model_on_ground(poly, np.array(laid.role[:n_masonry]), weight, motion, material, attrs, tol,
                            "segment of every wall", lambda b: f"wall {walls[laid.wall[b]].name!r}'s block {b} "
                                                           f"({z0[b]:.4g} m up)")
    model["block_wall"] = ("block", np.array(laid.wall, dtype=np.int32), variable_attrs("block_wall", "model3d"))
    return model
