"""Laying a bond into an outline: an architect's elevation (an outline, its openings) made a wall of units.

The rules, each stated in the notes :func:`lay` returns where it acts:

* **Courses** rise from the outline's base in steps of the unit height. A wall whose height is not a whole
  number of courses ends with a cut course; a remainder under :data:`MIN_COURSE` of a course is added to the
  course below instead (that course is stretched), so no course is a sliver.
* **Openings** are moved onto bed joints: a sill to the nearest joint, and a rectangular opening's head too
  (its height changes); an arched or polygonal opening moves as a whole. The shift is noted.
* **Heads** bridge every opening, as the spec says: a *lintel* (one block, ``courses`` high, bearing
  ``bearing`` on each side), a *flat arch* (the same region cut into voussoirs whose joints radiate from a
  point a span below the soffit, so its ends are skewbacks), an *arch* (a ring of voussoirs ``courses`` deep
  on the opening's circular head, about a course wide each) or *none*.
* **Head joints** follow the pattern from the outline's left end at the base: *running* (a full unit, or a
  half, to start alternate courses), *stack*, *English* (courses of stretchers and of headers, a quarter
  closer starting each header course) and *Flemish* (stretchers and headers alternating in every course,
  each header centred on the stretcher below). A header is half a unit long.
* **Units** are cut by the outline (a gable's slope, an arch's curve) and by the openings and heads; a piece
  shorter than ``min_piece`` of a unit length is merged with its neighbour across a head joint (the right
  one if there is one), else with the piece below it (a gable's tip): no sliver stands alone.

Plain geometry (shapely) on polygons in metres; :mod:`masonryfw.builders.outlined` turns specs and drawings into
its inputs and its units into models.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely.geometry import Polygon, box

from ..format.roles import ROLE
from ..runtime.errors import SpecError

PATTERNS = ("running", "stack", "english", "flemish")
HEADS = ("lintel", "flat_arch", "arch", "none")
#: A top remainder under this share of a course joins the course below (stretched) instead of making its own.
MIN_COURSE = 0.25
#: Lengths under this share of the outline's diagonal are nothing: vertices closer, or nearer their neighbours'
#: chord, are dropped from a block (a model's check counts a quarter of it as zero, 1e-6 of its size).
CLEAN = 4e-6
#: The overlays' grid, a share of the outline's diagonal (rounded down to a power of ten); the area a snap to it
#: moves is about this share of the wall's.
GRID = 1e-11
#: Points a voussoir's curved edges get per radian of the arch (chords within 0.1 % of the radius).
ARC_POINTS_PER_RADIAN = 12


@dataclass(frozen=True)
class Bond:
    """How the units are laid: their length and (course) height, the pattern and how the bottom course starts,
    and the shortest piece kept alone (a share of a unit length)."""

    unit_length: float
    unit_height: float
    pattern: str = "running"
    first_course: str = "full"
    min_piece: float = 0.5

    @property
    def header(self) -> float:
        return 0.5 * self.unit_length


@dataclass(frozen=True)
class Head:
    """What bridges one opening (:data:`HEADS`), how many courses deep, and its bearing on each side."""

    kind: str = "lintel"
    courses: int = 1
    bearing: float = 0.0


@dataclass
class LaidWall:
    """The wall laid: every block's polygon (counter-clockwise, no repeated last point) and role, course by
    course and left to right, then the heads; and the notes that say what the rules did."""

    polygons: list[np.ndarray] = field(default_factory=list)
    roles: list[int] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def lay(outline: Polygon, openings: list[Polygon], bond: Bond, heads: list[Head], names: list[str] | None = None
        ) -> LaidWall:
    """The units and heads of ``outline`` less ``openings`` (each bridged by its ``heads`` entry; ``names`` say
    which opening a note speaks of); see the module docstring."""
    names = names or [f"openings[{k}]" for k in range(len(openings))]
    laid = LaidWall()
    size = math.hypot(outline.bounds[2] - outline.bounds[0], outline.bounds[3] - outline.bounds[1])
    tol = 1e-9 * size
    clean = CLEAN * size
    # every overlay snaps to a grid of a round length (GRID of the size): shared edges come out the same,
    # coordinates a spec gives in millimetres stay as given, and the area is kept to far better than 1e-9
    grid = 10.0 ** math.floor(math.log10(GRID * size))
    edges = _course_edges(outline, bond, tol, laid.notes)
    openings = [_on_bed_joints(o, edges, tol, name, laid.notes) for o, name in zip(openings, names)]
    _refuse_misplaced(outline, openings, names, tol)
    head_parts = [_head(o, h, bond, outline, name, laid.notes, grid) for o, h, name in zip(openings, heads, names)]
    voids = shapely.union_all([*openings, *(p for parts, _ in head_parts for p in parts)], grid_size=grid)
    masonry = _polygonal(shapely.difference(outline, voids, grid_size=grid)) if not voids.is_empty else outline
    pieces = [_course_pieces(masonry, edges[k], edges[k + 1], _joints(k, bond, outline.bounds, tol), clean, grid)
              for k in range(len(edges) - 1)]
    heads_laid = [part for parts, _ in head_parts for part in parts]
    merged = _merge_slivers(pieces, heads_laid, bond, clean, grid)
    if merged:
        laid.notes.append(f"{merged} piece(s) shorter than {bond.min_piece:g} of a unit length merged with a "
                          "neighbour (in their course, or the one below)")
    blocks = [piece for course in pieces for piece in course] + heads_laid
    roles = [ROLE["unit"]] * sum(map(len, pieces)) + [role for parts, role in head_parts for _ in parts]
    rings = [_ring(block) for block in shared_boundaries(blocks, grid, clean)]
    laid.polygons = [_without_straight(ring, tol) for ring in _settled_junctions(rings, tol, clean)]
    laid.roles = roles
    return laid


def shared_boundaries(blocks: list[Polygon], grid: float, clean: float) -> list[Polygon]:
    """``blocks`` (they tile a region) with every boundary they share laid once: their boundaries noded into one
    network on the overlays' ``grid`` (lines the overlays left a grid step apart become one), each run of it
    between two junctions cleaned once (its vertices within ``clean`` of the chord dropped: a curve's chord
    vertex a hair from where a joint meets the curve), and the blocks made again as the faces of that network, in
    their order. Two neighbours then have exactly the same boundary: cleaned one by one, a unit and the voussoir
    beside it kept different vertices along their curve and overlapped by tens of micrometres. A face keeps the
    vertices where its neighbours' joints meet its edges only where they turn it (:func:`_ring`)."""
    network = shapely.line_merge(shapely.union_all([block.boundary for block in blocks], grid_size=grid))
    runs = shapely.simplify(shapely.get_parts(network), clean, preserve_topology=False)
    faces = [face for face in shapely.get_parts(shapely.polygonize(runs)) if face.area > 0]
    owner = shapely.STRtree(blocks).query(shapely.point_on_surface(faces), predicate="within")
    made: list[list[Polygon]] = [[] for _ in blocks]
    for face, block in zip(owner[0], owner[1]):
        made[int(block)].append(faces[int(face)])
    return [pieces[0] if len(pieces) == 1 else _joined(pieces, block, grid) for pieces, block in zip(made, blocks)]


def _joined(pieces: list[Polygon], block: Polygon, grid: float) -> Polygon:
    """A block made of several faces of the network (a block that touched itself), or the block as it was where
    the network has none of it."""
    if not pieces:
        return block
    joined = shapely.union_all(pieces, grid_size=grid)
    return joined if isinstance(joined, Polygon) else max(shapely.get_parts(joined), key=lambda p: p.area)


# ---------------------------------------------------------------- courses and openings

def _course_edges(outline: Polygon, bond: Bond, tol: float, notes: list[str]) -> np.ndarray:
    """The bed joints from the base to the top: whole courses, the last cut or stretched (module docstring)."""
    y0, y1 = outline.bounds[1], outline.bounds[3]
    whole = int(math.floor((y1 - y0) / bond.unit_height + 1e-9))
    edges = y0 + bond.unit_height * np.arange(whole + 1)
    rest = y1 - edges[-1]
    if rest <= tol:
        return edges
    if rest >= MIN_COURSE * bond.unit_height or whole == 0:
        notes.append(f"the wall is {whole} courses and {rest:.4g} m high: its top course is cut to {rest:.4g} m")
        return np.append(edges, y1)
    notes.append(f"the wall is {whole} courses and {rest:.4g} m high: its top course is {rest:.4g} m higher "
                 f"(under {MIN_COURSE:g} of a course, not a course of its own)")
    edges[-1] = y1
    return edges


def _nearest(edges: np.ndarray, y: float) -> float:
    return float(edges[np.argmin(np.abs(edges - y))])


def _is_rectangle(polygon: Polygon, tol: float) -> bool:
    return abs(polygon.area - shapely.box(*polygon.bounds).area) <= 1e3 * tol * max(polygon.length, 1.0)


def _on_bed_joints(opening: Polygon, edges: np.ndarray, tol: float, name: str, notes: list[str]) -> Polygon:
    """``opening`` moved so that its sill lies on a bed joint (a rectangle: its head too)."""
    x0, y0, x1, y1 = opening.bounds
    sill = _nearest(edges, y0)
    if _is_rectangle(opening, tol):
        head = _nearest(edges[edges > sill + tol], y1) if (edges > sill + tol).any() else y1
        moved = box(x0, sill, x1, head)
        moves = [f"its {what} by {1e3 * (new - old):+.3g} mm" for what, new, old in (("sill", sill, y0), ("head", head, y1))
                 if abs(new - old) > tol]
        if moves:
            notes.append(f"{name} (x {x0:.4g}..{x1:.4g} m): {' and '.join(moves)}, onto bed joints")
        return moved
    if abs(sill - y0) > tol:
        notes.append(f"{name} (x {x0:.4g}..{x1:.4g} m): moved by {1e3 * (sill - y0):+.3g} mm, its sill onto a bed "
                     "joint")
    return shapely.affinity.translate(opening, 0.0, sill - y0)


def _refuse_misplaced(outline: Polygon, openings: list[Polygon], names: list[str], tol: float) -> None:
    grown = outline.buffer(10 * tol)
    for name, opening in zip(names, openings):
        if not opening.within(grown):
            raise SpecError(f"{name} (x {opening.bounds[0]:.4g}..{opening.bounds[2]:.4g} m, y {opening.bounds[1]:.4g}.."
                            f"{opening.bounds[3]:.4g} m) is not inside the wall's outline")
    for a in range(len(openings)):
        for b in range(a + 1, len(openings)):
            if openings[a].intersection(openings[b]).area > tol * max(openings[a].length, openings[b].length):
                raise SpecError(f"{names[a]} and {names[b]} overlap")


# ---------------------------------------------------------------- heads

def _head(opening: Polygon, head: Head, bond: Bond, outline: Polygon, name: str, notes: list[str], grid: float
          ) -> tuple[list[Polygon], int]:
    """The blocks over ``opening`` and their role (a lintel, or voussoirs)."""
    if head.kind == "none":
        return [], ROLE["unit"]
    x0, _, x1, top = opening.bounds
    depth = head.courses * bond.unit_height
    if head.kind == "arch":
        return _arch(opening, depth, outline, name, grid), ROLE["voussoir"]
    region = shapely.intersection(box(x0 - head.bearing, top, x1 + head.bearing, top + depth), outline, grid_size=grid)
    if region.is_empty or region.area <= 0:
        raise SpecError(f"{name}: no masonry above it for its {head.kind.replace('_', ' ')} (the outline ends at its "
                        "head)")
    if region.area < 0.999 * (x1 - x0 + 2 * head.bearing) * depth:
        notes.append(f"{name}: its {head.kind.replace('_', ' ')} is cut by the outline")
    if head.kind == "lintel":
        return _parts(region), ROLE["lintel"]
    return _flat_arch(region, x0 - head.bearing, x1 + head.bearing, top, bond, grid), ROLE["voussoir"]


def _flat_arch(region, x0: float, x1: float, soffit: float, bond: Bond, grid: float) -> list[Polygon]:
    """``region`` cut into an odd number of voussoirs about a course wide on the soffit, their joints radiating
    from a point one span below the soffit's middle."""
    span = x1 - x0
    count = max(3, int(round(span / bond.unit_height)) | 1)
    centre = np.array([0.5 * (x0 + x1), soffit - span])
    top = region.bounds[3]
    far = (top - centre[1]) / (soffit - centre[1])
    parts = []
    for k in range(count):
        a, b = x0 + span * k / count, x0 + span * (k + 1) / count
        wedge = Polygon([tuple(centre + (np.array([x, soffit]) - centre) * s) for x, s in
                         ((a, 1.0), (b, 1.0), (b, far), (a, far))])
        parts += _parts(shapely.intersection(region, wedge, grid_size=grid))
    return parts


def _arch(opening: Polygon, depth: float, outline: Polygon, name: str, grid: float) -> list[Polygon]:
    """A ring of voussoirs ``depth`` deep on the circular head of ``opening`` (a circle fitted to the points of
    its boundary above its springing, where its straight sides end); all round a round window (an oculus: no
    straight side), its voussoirs radiating from its centre (it was laid over three quarters of its
    circumference and bricks cut round the rest, which carried nothing in fdem)."""
    x, y = np.asarray(opening.exterior.coords)[:-1].T
    if _is_round(x, y):
        cx, cy, radius = _circle_fit(x, y)
        springing, start, end = cy - 2 * (radius + depth), -0.5 * math.pi, 1.5 * math.pi
    else:
        upright = np.abs(np.diff(np.append(x, x[0]))) <= 1e-6 * opening.length
        springing = max((max(y[k], y[(k + 1) % x.size]) for k in np.flatnonzero(upright)), default=y.min())
        on_head = y >= springing - 1e-9 * opening.length
        if on_head.sum() < 3:
            raise SpecError(f"{name}: head = 'arch' needs a curved head (an arched opening); use 'lintel' or "
                            "'flat_arch'")
        left, right = x[on_head].min(), x[on_head].max()
        cx, cy, radius = _circle_through(x[on_head], y[on_head], left, right, springing)
        start, end = math.atan2(springing - cy, right - cx), math.atan2(springing - cy, left - cx)
        if end < start:
            end += 2 * math.pi
    mid = radius + 0.5 * depth
    count = max(3, int(round((end - start) * mid / depth)) | 1)
    parts = []
    inside = 0.8 * radius  # the sectors start inside the opening: its own boundary is their intrados
    above = box(cx - 2 * (radius + depth), springing, cx + 2 * (radius + depth), cy + 2 * (radius + depth))
    for k in range(count):
        a = start + (end - start) * k / count
        b = start + (end - start) * (k + 1) / count
        steps = max(2, int(math.ceil((b - a) * ARC_POINTS_PER_RADIAN)) + 1)
        angles = np.linspace(a, b, steps)
        inner = np.c_[cx + inside * np.cos(angles), cy + inside * np.sin(angles)]
        outer = np.c_[cx + (radius + depth) * np.cos(angles), cy + (radius + depth) * np.sin(angles)][::-1]
        sector = shapely.intersection(Polygon(np.vstack([inner, outer])), above, grid_size=grid)
        voussoir = shapely.difference(sector, opening, grid_size=grid)
        parts += _parts(shapely.intersection(voussoir, outline, grid_size=grid))
    return parts


def _circle_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """The circle through the points ``(x, y)`` by least squares (Kasa's algebraic fit): centre and radius."""
    design = np.c_[2 * x, 2 * y, np.ones_like(x)]
    (cx, cy, c), *_ = np.linalg.lstsq(design, x * x + y * y, rcond=None)
    return float(cx), float(cy), math.sqrt(c + cx * cx + cy * cy)


def _is_round(x: np.ndarray, y: np.ndarray) -> bool:
    """Whether the points lie on one circle (within 1 % of its radius): a round window, not a polygon."""
    cx, cy, radius = _circle_fit(x, y)
    return bool(np.abs(np.hypot(x - cx, y - cy) - radius).max() <= 0.01 * radius) and x.size >= 8


def _circle_through(x: np.ndarray, y: np.ndarray, left: float, right: float, springing: float
                    ) -> tuple[float, float, float]:
    """The circle through the two springing points ``(left, springing)`` and ``(right, springing)`` that fits
    the head's points best (least squares on its centre's height): the voussoirs then spring exactly from the
    opening's corners, their first and last joints bearing on the masonry's bed joint."""
    cx, half = 0.5 * (left + right), 0.5 * (right - left)
    # (x - cx)^2 + (y - cy)^2 = half^2 + (springing - cy)^2, linear in cy
    a = 2.0 * (springing - y)
    b = half * half + springing * springing - (x - cx) ** 2 - y * y
    cy = float(np.dot(a, b) / np.dot(a, a))
    return cx, cy, math.hypot(half, springing - cy)


# ---------------------------------------------------------------- courses of units

def pattern_cells(course: int, pattern: str, unit: float, header: float, first_course: str = "full"
                  ) -> tuple[float, list[float]]:
    """Where ``course``'s first head joint lies from the course origin and the lengths that repeat after it
    (module docstring): running and stack (a full unit, or a half, first), English (courses of stretchers, then
    of headers starting with a closer of half a header) and Flemish (stretcher and header alternating, each
    header centred on the stretcher below). One definition for walls in 2D and buildings in 3D."""
    even = course % 2 == 0
    if pattern in ("running", "stack"):
        full = first_course == "full"
        if pattern == "running":
            full = full == even
        return (0.0 if full else 0.5 * unit), [unit]
    if pattern == "english":
        return (0.0, [unit]) if even else (0.5 * header, [header])
    return (0.0, [unit, header]) if even else (0.5 * (unit - header), [header, unit])  # flemish


def _joints(course: int, bond: Bond, bounds, tol: float) -> np.ndarray:
    """The head joints of ``course`` across the outline's width, from its left end at the base (module docstring);
    a joint beyond either end stands for the end."""
    x0, _, x1, _ = bounds
    first, lengths = pattern_cells(course, bond.pattern, bond.unit_length, bond.header, bond.first_course)
    repeats = int(math.ceil((x1 - x0) / sum(lengths))) + 1
    joints = x0 + first + np.concatenate(([0.0], np.cumsum(np.tile(lengths, repeats))))
    inside = joints[(joints > x0 + tol) & (joints < x1 - tol)]
    return np.concatenate(([x0 - 1.0], inside, [x1 + 1.0]))


def _course_pieces(masonry, y0: float, y1: float, joints: np.ndarray, clean: float, grid: float) -> list[Polygon]:
    """The pieces of the masonry in the course between ``y0`` and ``y1`` cut at ``joints``, left to right (none
    thinner than ``clean``)."""
    band = _polygonal(shapely.intersection(masonry, box(joints[0], y0, joints[-1], y1), grid_size=grid))
    if band.is_empty:
        return []
    cells = shapely.intersection(shapely.box(joints[:-1], y0, joints[1:], y1), band, grid_size=grid)
    pieces = [part for cell in cells for part in _parts(cell)]  # a hair of a piece is merged, not lost
    return sorted(pieces, key=lambda p: p.bounds[0])


def _polygonal(geometry):
    """The polygons of an overlay's result as one (Multi)Polygon: the lines and points it may hold, where two
    regions only touch, dropped."""
    return shapely.multipolygons(_parts(geometry)) if geometry.geom_type != "Polygon" else geometry


def _parts(geometry) -> list[Polygon]:
    """The polygons of a geometry (a polygon, a collection), collinear vertices dropped."""
    geometry = shapely.simplify(geometry, 0.0)
    return [p for p in shapely.get_parts(geometry) if isinstance(p, Polygon) and p.area > 0]


def _merge_slivers(courses: list[list[Polygon]], heads: list[Polygon], bond: Bond, clean: float, grid: float) -> int:
    """Merge every sliver (narrower than ``min_piece`` unit lengths, or of a tenth of that piece's area) with its
    neighbour across a head joint (the right one first), or, alone in its course (a gable's tip) or a mere
    fleck, with the piece below (module docstring); a fleck with none of those (a hair of masonry between an
    arch's extrados and a bed joint) joins the piece above or the head it borders. How many were merged. A
    narrow piece with neither (a pier between an opening and the outline) stays."""
    merged = 0
    narrow = bond.min_piece * bond.unit_length - clean
    fleck = 0.1 * bond.min_piece * bond.unit_length * bond.unit_height
    for k, course in enumerate(courses):
        j = 0
        while j < len(course):
            piece = course[j]
            small = piece.area < fleck
            if piece.bounds[2] - piece.bounds[0] >= narrow and not small:
                j += 1
                continue
            neighbour = _touching(course, j, 0.0 if small else 10 * clean)  # a fleck joins any neighbour it borders
            alone = len(course) == 1 or small
            below = _longest_bed(courses[k - 1], piece, clean) if neighbour is None and alone and k else None
            above = _longest_bed(courses[k + 1], piece, 0.0) if small and neighbour is below is None and \
                k + 1 < len(courses) else None
            head = _longest_bed(heads, piece, 0.0) if small and neighbour is below is above is None else None
            if neighbour is not None:
                course[neighbour] = _union(course[neighbour], piece, grid)
            elif below is not None:
                courses[k - 1][below] = _union(courses[k - 1][below], piece, grid)
            elif above is not None:
                courses[k + 1][above] = _union(courses[k + 1][above], piece, grid)
            elif head is not None:
                heads[head] = _union(heads[head], piece, grid)
            else:
                j += 1
                continue
            del course[j]
            merged += 1
            j = 0
    return merged


def _touching(course: list[Polygon], j: int, least: float) -> int | None:
    """The neighbour of piece ``j`` in its course sharing the longest boundary with it (across a head joint), if
    longer than ``least``; or None."""
    shared = [other.intersection(course[j]).length if other is not course[j] else 0.0 for other in course]
    unit = max(least / 10, 1e-300)
    best = max(range(len(course)), key=lambda i: (round(shared[i] / unit), i > j))  # a tie: the right one
    return best if shared[best] > least else None


def _longest_bed(course: list[Polygon], piece: Polygon, tol: float) -> int | None:
    shared = [p.intersection(piece).length for p in course]
    best = int(np.argmax(shared)) if shared else -1
    return best if best >= 0 and shared[best] > 10 * tol else None


def _union(a: Polygon, b: Polygon, grid: float) -> Polygon:
    joined = shapely.simplify(shapely.union(a, b, grid_size=grid), 0.0)
    return joined if isinstance(joined, Polygon) else max(shapely.get_parts(joined), key=lambda p: p.area)


def _ring(polygon: Polygon) -> np.ndarray:
    """The exterior of ``polygon`` counter-clockwise, without its repeated last point."""
    return np.asarray(shapely.geometry.polygon.orient(polygon, 1.0).exterior.coords)[:-1]


def _offsets(ring: np.ndarray) -> np.ndarray:
    """How far each vertex of ``ring`` lies from the chord of its two neighbours."""
    before, after = np.roll(ring, 1, axis=0), np.roll(ring, -1, axis=0)
    chord, away = after - before, ring - before
    return np.abs(chord[:, 0] * away[:, 1] - chord[:, 1] * away[:, 0]) / np.maximum(np.hypot(*chord.T), 1e-300)


def _settled_junctions(rings: list[np.ndarray], tol: float, clean: float) -> list[np.ndarray]:
    """The blocks' vertices within ``clean`` of their neighbours' chord (but not within ``tol``: a neighbour's joint
    meeting an edge, which :func:`_without_straight` drops from that block alone) settled in every block that has
    them alike, so that neighbours stay alike: a vertex two blocks share at most (along a curve, or on the outline)
    is dropped; where it is a junction (three blocks or more meet there: a bed joint meeting an arch's extrados a
    hair from a chord vertex), the nearer of its neighbours is dropped if that one is not a junction, else the two
    junctions (a voussoir's joint and a bed joint meeting the extrados a hair apart) become one point. A block
    keeps three vertices at least."""
    for _ in range(8):
        owners: dict[tuple[float, float], int] = {}
        for ring in rings:
            for point in map(tuple, ring.tolist()):
                owners[point] = owners.get(point, 0) + 1
        dropped: set[tuple[float, float]] = set()
        merged: dict[tuple[float, float], tuple[float, float]] = {}
        for ring in rings:
            offset = _offsets(ring)
            for k in np.flatnonzero((offset > tol) & (offset <= clean)):
                point = tuple(ring[k].tolist())
                if point in dropped or point in merged:
                    continue
                if owners[point] <= 2:
                    dropped.add(point)
                    continue
                near = tuple(min((ring[k - 1], ring[(k + 1) % len(ring)]),
                                 key=lambda n: float(np.hypot(*(n - ring[k])))).tolist())
                if owners[near] <= 2:
                    dropped.add(near)
                elif near not in merged and near not in dropped:
                    merged[point] = near
        if not dropped and not merged:
            break
        rings = [_settled(ring, dropped, merged) for ring in rings]
    return rings


def _settled(ring: np.ndarray, dropped: set, merged: dict) -> np.ndarray:
    """``ring`` less its ``dropped`` points, its ``merged`` ones moved onto their partners (no point twice in a
    row); as it was if fewer than three would be left."""
    points = [merged.get(p, p) for p in map(tuple, ring.tolist()) if p not in dropped]
    points = [p for k, p in enumerate(points) if p != points[k - 1]]
    return np.array(points) if len(points) >= 3 else ring


def _without_straight(ring: np.ndarray, tol: float) -> np.ndarray:
    """``ring`` without its vertices within ``tol`` of their neighbours' chord (where a neighbour's joint meets its
    edge, or a meeting point :func:`_settled_junctions` moved onto it)."""
    while len(ring) > 3:
        straight = _offsets(ring) <= tol
        if not straight.any():
            break
        straight &= ~np.roll(straight, 1)  # never two neighbours in one pass: each is judged against its own chord
        ring = ring[~straight]
    return ring
