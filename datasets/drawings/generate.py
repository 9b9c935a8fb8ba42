"""The drawn example walls: their geometry, and the drawings and specs written from it.

``python -m masonryfw.datasets.drawings.generate`` (or this file run as a script)
rewrites every ``<name>.dxf``/``.geojson`` and ``<name>.toml`` in this folder.

- ``lact3-wall``, ``lact3-portal``, ``lact3-arch``: walls equivalent to the three
  public sample drawings of LACT3 (Hua, Buzzetti, Pingaro, da Silva, Milani,
  2025, github.com/GabrieleMilani/LACT3_v1.0, ``sample/wall.dxf``,
  ``Portale.dxf``, ``arch_1.dxf``), drawn here from their published geometry (block
  coordinates to 0.001 mm; the wall and the arch are parametric) and not copied.
  LACT3's solver test gives their tilting-table collapse angles: 16.73 deg
  (wall, phi = 26 deg), 27.30 deg (portal) and 17.10 deg (arch, phi = 30 deg),
  c = 0. The quirks of the originals are kept on purpose, as import tests: the
  blocks on layer 0 (but the blocks that bridge an opening, on layer LINTEL: for
  the limit analysis and fdem a lintel is a block like any other, for jmm an
  elastic one), the wall's ``$INSUNITS`` says inches for a drawing in mm,
  mid-edge vertices marking T-junctions, polylines closed by repeating their
  first vertex instead of the closed flag, one that goes on past its start, a
  non-convex base that carries the arch's springers, and POINT entities.
- ``arch-settlement``: a semicircular arch ring of 17 voussoirs (intrados and
  extrados drawn as arcs, DXF bulges) on two masonry piers; the right pier's
  base settles.
- ``gable-house``: an architect's elevation, not a drawing of blocks: the outline of a three-storey
  gable-fronted terraced house (6.5 m wide, eaves 8.5 m, ridge 10.5 m, on layer OUTLINE) and its door and
  five windows (layer OPENINGS; the top one has a semicircular head, drawn as an arc), in mm, as
  architects draw them. The spec lays an English bond in it (``geometry.outline_layer``).
- ``drawn-corner``: a corner of a building drawn block by block in 3D, as a modeller exports it (an OBJ file,
  one object per brick, the lintel on its own material): two walls 2.4 and 1.8 m long, 1.2 m high, one brick
  (0.12 m) thick, toothed course by course, a window with a lintel; written here brick by brick, not by
  masonryfw's building laying.
- ``stepped-units``: a running-bond wall whose units are partly merged in pairs
  into stepped (non-convex) blocks, as a GeoJSON polygon file; the right part of
  its base settles. ``stepped_wall(merged=False)`` is the same wall in rectangles.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

HERE = Path(__file__).parent
Polygon = list  # [(x, y), ...] in mm


# ---------------------------------------------------------------- LACT3-like walls

def lact3_wall() -> tuple[list[Polygon], list[str]]:
    """Piers and two openings of 250 x 55.6 mm units on a base; the lintel and several units carry
    T-junction vertices, the lintel is closed by repeating its first vertex."""
    h = 500.0 / 9.0
    polygons: list[Polygon] = []

    def course(k: int, spans) -> None:
        y0, y1 = 150.0 + k * h, 150.0 + (k + 1) * h
        for x0, x1 in spans:
            middle = [(0.5 * (x0 + x1), y1)] if x1 - x0 > 200 else []  # the drawing's T-junction marks
            polygons.append([(x0, y0), (x1, y0), (x1, y1), *middle, (x0, y1)])

    full = [(250.0 + 250 * i, 500.0 + 250 * i) for i in range(8)]
    course(0, full)
    for k in range(1, 25):
        odd = k % 2 == 1
        spans = [(250, 375), (375, 500)] if odd else [(250, 500)]
        spans += [(750, 875), (875, 1125)] if odd else [(750, 1000)] + ([(1000, 1125)] if k < 24 else [])
        spans += [(1125, 1375), (1375, 1625)] if k == 1 else []
        if odd:
            spans += [(1625, 1875), (1875, 2125), (2125, 2250)]
        else:
            spans += ([(1625, 1750)] if k < 24 else []) + [(1750, 2000), (2000, 2250)]
        course(k, spans)
    course(25, [(250, 375)] + [(375.0 + 250 * i, 625.0 + 250 * i) for i in range(7)] + [(2125, 2250)])
    course(26, full)
    y0, y1 = 150.0 + 24 * h, 150.0 + 25 * h
    polygons.append([(1000, y0), (1000, y1), (1125, y1), (1375, y1), (1625, y1), (1750, y1), (1750, y0),
                     (1625, y0), (1125, y0), (1000, y0)])  # the lintel, closed by its repeated first vertex
    base = [(2250, 150), (2520.731, 150), (2520.731, 0), (0, 0), (0, 150)] + [(250.0 * i, 150) for i in range(1, 10)]
    polygons.append(base)
    layers = ["0"] * len(polygons)
    layers[-2] = "LINTEL"  # the drawn lintel over the window
    for i, polygon in enumerate(polygons):  # the two units of course 25 that bridge the door
        if polygon[0][1] == 150.0 + 25 * h and polygon[0][0] in (375.0, 625.0):
            layers[i] = "LINTEL"
    return polygons, layers


#: The portal's blocks [mm], in the order of the original drawing; the base first.
PORTAL = [
    [(0, 0), (0, 300), (150, 300), (536.365, 300), (650, 300), (1850, 300), (1963.635, 300), (2350, 300),
     (2500, 300), (2500, 0)],
    [(150, 300), (150, 450), (343.183, 450), (536.365, 450), (536.365, 300)],
    [(536.365, 300), (536.365, 450), (650, 450), (650, 300)],
    [(150, 450), (150, 600), (290.496, 600), (343.183, 450)],
    [(343.183, 450), (290.496, 600), (530.068, 600), (650, 600), (650, 450), (536.365, 450)],
    [(150, 600), (150, 800), (421.938, 800), (530.068, 800), (530.068, 600), (290.496, 600)],
    [(530.068, 600), (530.068, 800), (650, 800), (650, 600)],
    [(150, 800), (150, 900), (421.938, 900), (421.938, 800)],
    [(421.938, 800), (421.938, 900), (421.938, 1018.614), (650, 1018.614), (650, 800), (530.068, 800)],
    [(650, 1018.614), (421.938, 1018.614), (254.482, 1018.614), (254.482, 1093.079), (452.241, 1093.079),
     (650, 1093.079)],
    [(150, 900), (150, 1018.614), (254.482, 1018.614), (421.938, 1018.614), (421.938, 900)],
    [(150, 1018.614), (150, 1300), (254.482, 1300), (254.482, 1093.079), (254.482, 1018.614)],
    [(2350, 300), (2350, 450), (2156.817, 450), (1963.635, 450), (1963.635, 300)],
    [(1963.635, 300), (1963.635, 450), (1850, 450), (1850, 300)],
    [(2350, 450), (2350, 600), (2209.504, 600), (2156.817, 450)],
    [(2156.817, 450), (2209.504, 600), (1969.932, 600), (1850, 600), (1850, 450), (1963.635, 450)],
    [(2350, 600), (2350, 800), (2078.062, 800), (1969.932, 800), (1969.932, 600), (2209.504, 600)],
    [(1969.932, 600), (1969.932, 800), (1850, 800), (1850, 600)],
    [(2350, 800), (2350, 900), (2078.062, 900), (2078.062, 800)],
    [(2078.062, 800), (2078.062, 900), (2078.062, 1018.614), (1850, 1018.614), (1850, 800), (1969.932, 800)],
    [(1850, 1018.614), (2078.062, 1018.614), (2245.518, 1018.614), (2245.518, 1093.079), (2047.759, 1093.079),
     (1850, 1093.079)],
    [(2350, 900), (2350, 1018.614), (2245.518, 1018.614), (2078.062, 1018.614), (2078.062, 900)],
    [(2350, 1018.614), (2350, 1300), (2245.518, 1300), (2245.518, 1093.079), (2245.518, 1018.614)],
    [(452.241, 1093.079), (452.241, 1271.801), (844.424, 1271.801), (1179.862, 1271.801), (1574.884, 1271.801),
     (2047.759, 1271.801), (2047.759, 1093.079), (1850, 1093.079), (650, 1093.079)],
    [(254.482, 1093.079), (254.482, 1300), (452.241, 1271.801), (452.241, 1093.079)],
    [(2047.759, 1093.079), (2047.759, 1271.801), (2245.518, 1300), (2245.518, 1093.079)],
    [(150, 1300), (254.482, 1300), (254.482, 1415.799), (150, 1415.799)],
    [(254.482, 1300), (254.482, 1415.799), (662.060, 1415.799), (844.424, 1415.799), (844.424, 1271.801),
     (452.241, 1271.801)],
    [(844.424, 1271.801), (844.424, 1415.799), (1012.143, 1415.799), (1179.862, 1415.799), (1179.862, 1271.801)],
    [(1179.862, 1271.801), (1179.862, 1415.799), (1574.884, 1415.799), (1574.884, 1271.801)],
    [(1574.884, 1271.801), (1574.884, 1415.799), (1574.884, 1523.850), (2047.759, 1523.850), (2047.759, 1271.801)],
    [(2047.759, 1271.801), (2047.759, 1523.850), (2245.518, 1523.850), (2245.518, 1300)],
    [(2245.518, 1300), (2245.518, 1523.850), (2350, 1523.850), (2350, 1300)],
    [(1012.143, 1415.799), (1012.143, 1598.825), (1446.175, 1598.825), (1574.884, 1598.825), (1574.884, 1523.850),
     (1574.884, 1415.799), (1179.862, 1415.799)],
    [(150, 1415.799), (150, 1598.825), (662.060, 1598.825), (662.060, 1415.799), (254.482, 1415.799)],
    [(662.060, 1415.799), (662.060, 1598.825), (890.804, 1598.825), (1012.143, 1598.825), (1012.143, 1415.799),
     (844.424, 1415.799)],
    [(1574.884, 1523.850), (1574.884, 1598.825), (2350, 1598.825), (2350, 1523.850), (2245.518, 1523.850),
     (2047.759, 1523.850)],
    [(150, 1598.825), (150, 1940.227), (890.804, 1940.227), (890.804, 1598.825), (662.060, 1598.825)],
    [(890.804, 1598.825), (890.804, 1940.227), (1446.175, 1940.227), (1446.175, 1769.526), (1446.175, 1598.825),
     (1012.143, 1598.825)],
    [(1446.175, 1598.825), (1446.175, 1769.526), (2350, 1769.526), (2350, 1598.825), (1574.884, 1598.825)],
    [(1446.175, 1769.526), (1446.175, 1940.227), (2350, 1940.227), (2350, 1769.526)],
]


#: The portal's lintel (the block over the opening) in :data:`PORTAL`.
PORTAL_LINTEL = 23


def lact3_portal() -> tuple[list[Polygon], list[str]]:
    """Two jambs of irregular stones, a lintel on inclined bearings, a wall above, on one base."""
    polygons = [list(p) for p in PORTAL]
    return polygons, ["LINTEL" if i == PORTAL_LINTEL else "0" for i in range(len(polygons))]


def _on_circle(centre, radius: float, angle: float) -> tuple[float, float]:
    return centre[0] + radius * math.cos(angle), centre[1] + radius * math.sin(angle)


def lact3_arch() -> tuple[list[Polygon], list[str]]:
    """A semicircular ring of 27 equal voussoirs (intrados radius 317, extrados 373.3 mm) whose two
    springers are part of the base: a non-convex base block, as in the original."""
    centre, inner, outer, count = (623.3, 75.0), 317.0, 373.3, 27
    step = math.pi / count
    polygons = []
    for k in range(1, count - 1):
        a0, a1 = k * step, (k + 1) * step
        polygons.append([_on_circle(centre, inner, a0), _on_circle(centre, outer, a0),
                         _on_circle(centre, outer, a1), _on_circle(centre, inner, a1)])
    polygons[4] = polygons[4] + polygons[4][:2]  # as in the original: this polyline goes on past its start
    base = [_on_circle(centre, outer, 0.0), _on_circle(centre, outer, step), _on_circle(centre, inner, step),
            _on_circle(centre, inner, 0.0), _on_circle(centre, inner, math.pi),
            _on_circle(centre, inner, math.pi - step), _on_circle(centre, outer, math.pi - step),
            _on_circle(centre, outer, math.pi), (0.0, 75.0), (0.0, 0.0), (1246.6, 0.0), (1246.6, 75.0)]
    polygons.append(base + [base[0]])  # closed by repeating its first vertex
    return polygons, ["0"] * len(polygons)


# ---------------------------------------------------------------- an arch under settlement

#: Arch on piers [mm]: ring centre, radii, voussoirs; piers' width, course height and courses.
ARCH = {"centre": (1850.0, 1200.0), "inner": 1000.0, "outer": 1250.0, "voussoirs": 17,
        "pier": 600.0, "course": 300.0, "courses": 4}


def settling_arch() -> tuple[list[list], list[str]]:
    """Voussoirs as ``(x, y, bulge)`` vertices (arcs on the intrados and extrados), piers of two
    alternating courses, and two base blocks (layers BASE and SETTLE)."""
    a = ARCH
    centre, inner, outer, count = a["centre"], a["inner"], a["outer"], a["voussoirs"]
    step = math.pi / count
    bulge = math.tan(step / 4.0)
    polygons, layers = [], []
    for k in range(count):
        a0, a1 = k * step, (k + 1) * step
        polygons.append([(*_on_circle(centre, inner, a0), 0.0), (*_on_circle(centre, outer, a0), bulge),
                         (*_on_circle(centre, outer, a1), 0.0), (*_on_circle(centre, inner, a1), -bulge)])
        layers.append("ARCH")
    for side in (-1, 1):
        inner_edge = centre[0] + side * inner
        outer_edge = centre[0] + side * (outer + a["pier"] - (outer - inner))
        x0, x1 = min(inner_edge, outer_edge), max(inner_edge, outer_edge)
        middle = 0.5 * (x0 + x1)
        for c in range(a["courses"]):
            y0, y1 = c * a["course"], (c + 1) * a["course"]
            spans = [(x0, x1)] if c % 2 == 0 else [(x0, middle), (middle, x1)]
            for s0, s1 in spans:
                polygons.append([(s0, y0, 0.0), (s1, y0, 0.0), (s1, y1, 0.0), (s0, y1, 0.0)])
                layers.append("PIERS")
        polygons.append([(x0 - 200, -300, 0.0), (x1 + 200, -300, 0.0), (x1 + 200, 0.0, 0.0), (x0 - 200, 0.0, 0.0)])
        layers.append("BASE" if side < 0 else "SETTLE")
    return polygons, layers


# ---------------------------------------------------------------- units merged into non-convex blocks

#: Stepped wall [mm]: unit length and height, units per course, courses; the base's settling share.
STEPPED = {"length": 200.0, "height": 100.0, "units": 6, "courses": 6, "settling_from": 700.0}


def stepped_wall(merged: bool = True) -> tuple[list[Polygon], list[str]]:
    """A running-bond wall (half units at the ends of odd courses) on a fixed and a settling base block.

    ``merged``: in the even courses but the last two, every second unit is one block
    with the unit above its right half: a stepped (Z-shaped, non-convex) block, or an
    L at the wall's end.
    """
    s = STEPPED
    b, h, n, courses = s["length"], s["height"], s["units"], s["courses"]
    width = n * b

    def joints(c: int) -> list[float]:
        inner = [b * i for i in range(1, n)] if c % 2 == 0 else [b * i - b / 2 for i in range(1, n + 1)]
        return [0.0, *inner, width]

    rows = [[(x0, x1, c * h, (c + 1) * h) for x0, x1 in zip(joints(c)[:-1], joints(c)[1:])] for c in range(courses)]
    polygons, absorbed = [], set()
    for c, row in enumerate(rows):
        for i, (x0, x1, y0, y1) in enumerate(row):
            if (c, i) in absorbed:
                continue
            if merged and c % 2 == 0 and c + 1 < courses - 1 and i % 2 == 1:
                u0, u1, _, v1 = rows[c + 1][i + 1]  # the unit above this one's right half
                absorbed.add((c + 1, i + 1))
                polygons.append([(x0, y0), (x1, y0), (x1, y1), (u1, y1), (u1, v1), (u0, v1), (u0, y1), (x0, y1)])
            else:
                polygons.append([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
    split = s["settling_from"]
    polygons += [[(-b / 2, -h), (split, -h), (split, 0.0), (-b / 2, 0.0)],
                 [(split, -h), (width + b / 2, -h), (width + b / 2, 0.0), (split, 0.0)]]
    return polygons, ["UNITS"] * (len(polygons) - 2) + ["BASE", "SETTLE"]


# ---------------------------------------------------------------- an architect's elevation

#: The gable house [mm]: width, eaves and ridge; openings (x, sill, width, height); the arched window's
#: (x, sill, width, springing height above the sill).
GABLE_HOUSE = {"width": 6500.0, "eaves": 8500.0, "ridge": 10500.0,
               # as an architect dimensions them (not on the 75 mm courses): the laying moves them
               "openings": [(2750.0, 0.0, 1000.0, 2200.0),  # the door
                            (750.0, 850.0, 1200.0, 1500.0), (4550.0, 850.0, 1200.0, 1500.0),
                            (750.0, 3800.0, 1200.0, 1650.0), (4550.0, 3800.0, 1200.0, 1650.0)],
               "arched": (2800.0, 6500.0, 900.0, 1200.0)}


def gable_house() -> tuple[list[list], list[str]]:
    """The outline (one closed polyline) and the openings (rectangles, and one window whose head is a
    semicircle: a bulge of 1 on its top edge)."""
    g = GABLE_HOUSE
    w = g["width"]
    polygons = [[(0.0, 0.0, 0.0), (w, 0.0, 0.0), (w, g["eaves"], 0.0), (0.5 * w, g["ridge"], 0.0),
                 (0.0, g["eaves"], 0.0)]]
    for x, y, width, height in g["openings"]:
        polygons.append([(x, y, 0.0), (x + width, y, 0.0), (x + width, y + height, 0.0), (x, y + height, 0.0)])
    x, y, width, springing = g["arched"]
    polygons.append([(x, y, 0.0), (x + width, y, 0.0), (x + width, y + springing, 1.0), (x, y + springing, 0.0)])
    return polygons, ["OUTLINE"] + ["OPENINGS"] * (len(polygons) - 1)


#: The drawn corner [m]: brick length, height and depth; the walls' lengths; the window (x0, x1, courses) in
#: the long wall and its lintel's bearing.
CORNER = {"brick": (0.24, 0.12, 0.12), "long": 2.4, "short": 1.8, "courses": 10, "window": (0.96, 1.44, 3, 6),
          "bearing": 0.12}


def _cut(a: float, b: float, first_joint: float, unit: float) -> list[tuple[float, float]]:
    """``[a, b]`` in units from ``first_joint`` on, a piece under a quarter unit joined to its neighbour."""
    joints = [a] + [j for j in (first_joint + k * unit for k in range(200)) if a + 1e-9 < j < b - 1e-9] + [b]
    pieces = list(zip(joints[:-1], joints[1:]))
    if len(pieces) > 1 and pieces[-1][1] - pieces[-1][0] < 0.25 * unit - 1e-9:
        pieces[-2:] = [(pieces[-2][0], pieces[-1][1])]
    return pieces


def drawn_corner() -> tuple[list[tuple[tuple, tuple]], list[str]]:
    """The corner's bricks as boxes ``((x0, y0, z0), (x1, y1, z1))`` and their materials: the long wall along x
    from x = 0 (y from 0 to the depth), the short one along y at its end; in even courses the long wall runs
    to the corner's outside, in odd ones the short wall does; running bond from each wall's free end."""
    c = CORNER
    length, height, depth = c["brick"]
    x0, x1, k0, k1 = c["window"]
    boxes, materials = [], []
    for k in range(c["courses"]):
        z = (k * height, (k + 1) * height)
        shift = 0.5 * length * (k % 2)
        end = c["long"] if k % 2 == 0 else c["long"] - depth
        spans = [(0.0, end)] if not k0 <= k < k1 else [(0.0, x0), (x1, end)]
        if k == k1:  # the lintel's course
            lintel = (x0 - c["bearing"], x1 + c["bearing"])
            spans = [(0.0, lintel[0]), (lintel[1], end)]
            boxes.append(((lintel[0], 0.0, z[0]), (lintel[1], depth, z[1])))
            materials.append("LINTEL")
        for a, b in spans:
            for p, q in _cut(a, b, shift + length if shift else length, length):
                boxes.append(((p, 0.0, z[0]), (q, depth, z[1])))
                materials.append("BRICK")
        start = depth if k % 2 == 0 else 0.0  # the short wall, from the corner to its free end at y = short
        for p, q in _cut(start, c["short"], c["short"] - (length if k % 2 == 0 else 1.5 * length) - 20 * length,
                         length):
            boxes.append(((c["long"] - depth, p, z[0]), (c["long"], q, z[1])))
            materials.append("BRICK")
    return boxes, materials


# ---------------------------------------------------------------- writing


def write_obj(path: Path, boxes: list[tuple[tuple, tuple]], materials: list[str]) -> None:
    """One object per box (eight vertices, six quadrilaterals turned outward), its material named."""
    lines = ["# drawn-corner: one object per brick, metres (masonryfw datasets/drawings/generate.py)"]
    faces = ((1, 4, 3, 2), (5, 6, 7, 8), (1, 2, 6, 5), (2, 3, 7, 6), (3, 4, 8, 7), (4, 1, 5, 8))
    for number, ((x0, y0, z0), (x1, y1, z1)) in enumerate(boxes):
        first = 8 * number
        lines += [f"o brick {number + 1}", f"usemtl {materials[number]}"]
        lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for z in (z0, z1) for x, y in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))]
        lines += ["f " + " ".join(str(first + v) for v in face) for face in faces]
    path.write_text("\n".join(lines) + "\n")


def write_dxf(path: Path, polygons: list, layers: list[str], insunits: int = 4, points: bool = False) -> None:
    """One LWPOLYLINE per block (``(x, y)`` or ``(x, y, bulge)`` vertices). A polygon whose last vertex
    repeats its first is written open, as some CAD drawings are; the others with the closed flag."""
    import ezdxf

    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = insunits
    for layer in sorted(set(layers) - {"0"}):
        doc.layers.add(layer)
    msp = doc.modelspace()
    for polygon, layer in zip(polygons, layers):
        vertices = [(p[0], p[1], 0.0, 0.0, p[2] if len(p) > 2 else 0.0) for p in polygon]
        repeats_start = tuple(polygon[-1][:2]) == tuple(polygon[0][:2])
        msp.add_lwpolyline(vertices, format="xyseb", close=not repeats_start, dxfattribs={"layer": layer})
        if points:
            for p in polygon:
                msp.add_point((p[0], p[1]))
    doc.saveas(path)


def write_geojson(path: Path, polygons: list, layers: list[str]) -> None:
    """A FeatureCollection of Polygons (first vertex repeated at the end, as GeoJSON wants), layer in the properties."""
    features = [{"type": "Feature", "properties": {"layer": layer, "name": f"b{i}"},
                 "geometry": {"type": "Polygon", "coordinates": [[list(p) for p in polygon] + [list(polygon[0])]]}}
                for i, (polygon, layer) in enumerate(zip(polygons, layers))]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}, indent=1) + "\n")


def write_all(folder: Path = HERE) -> None:
    """Every drawing of this folder (the specs are written by hand)."""
    write_dxf(folder / "lact3-wall.dxf", *lact3_wall(), insunits=1)  # inches, as the original says
    write_dxf(folder / "lact3-portal.dxf", *lact3_portal())
    write_dxf(folder / "lact3-arch.dxf", *lact3_arch(), points=True)
    write_dxf(folder / "arch-settlement.dxf", *settling_arch())
    write_geojson(folder / "stepped-units.geojson", *stepped_wall())
    write_dxf(folder / "gable-house.dxf", *gable_house())
    write_obj(folder / "drawn-corner.obj", *drawn_corner())


if __name__ == "__main__":
    write_all()
