"""Blocks from drawings: CAD files (DXF), polygon tables (CSV) and GeoJSON, cleaned into simple polygons.

One block per closed polyline (DXF ``LWPOLYLINE`` or 2D ``POLYLINE``, also inside
block references), per ``block`` id of a CSV table (``block, x, y`` rows, an
optional ``layer`` column) or per GeoJSON Polygon (``properties.layer``). What a
drawing holds besides (text, points, lines, hatches) is left out and counted.

Cleaning, in this order (every length in metres from here on):

1. **snap**: vertices closer than the snap tolerance (default 1e-6 of the
   drawing's size, the interface detection's tolerance) become one, the first
   drawn, so two blocks drawn to the same corner share it exactly;
2. **per polygon**: drop repeated vertices and a closing repeat of the first one
   (a polyline that goes round twice is cut after its first round), drop
   vertices on the straight line between their neighbours (T-junction marks,
   redundant points, spikes), turn the vertex order counter-clockwise;
3. **refuse** with the entity and its coordinates: an open polyline, arcs
   without a chord tolerance, fewer than three vertices left, zero area, a
   polygon that crosses or touches itself.

Overlapping blocks are found afterwards by :func:`masonryfw.check`, like in
every model. Arcs (DXF bulges) become chords no farther than
``chord_tolerance`` from the arc; two blocks sharing an arc get the same chords.
"""
from __future__ import annotations

import csv
import io
import json
import logging
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..geometry.graph import connected_components
from ..geometry.polygons import block_offsets, polygon_area_centroid
from ..runtime.errors import SpecError
from ..runtime.inputs import DRAWING_BYTES_FACTOR, fits_in_memory, read_text, regular_file
from ..runtime.resources import size_text

#: Metres per drawing unit.
DRAWING_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}
#: DXF ``$INSUNITS`` codes of the drawing units above.
INSUNITS = {4: "mm", 5: "cm", 6: "m"}
#: Snap tolerance, relative to the drawing's bounding-box diagonal.
RELATIVE_SNAP = 1e-6
#: The first bytes of a binary DXF file.
BINARY_DXF = b"AutoCAD Binary DXF"
SUFFIXES = {".dxf": "dxf", ".csv": "csv", ".geojson": "geojson", ".json": "geojson"}


@dataclass(frozen=True)
class Drawing:
    """Cleaned blocks of a drawing in the ragged layout (metres, counter-clockwise)."""

    node_x: np.ndarray
    node_y: np.ndarray
    block_node_count: np.ndarray
    layers: tuple[str, ...]  # per block
    sources: tuple[str, ...]  # per block: what it was in the drawing, for messages
    ignored: dict[str, int]  # entity types left out, and how many

    def label(self, block: int) -> str:
        """``"LWPOLYLINE #2BE on layer 0"``: where block ``block`` came from."""
        return f"{self.sources[block]} on layer {self.layers[block]}"


@dataclass(frozen=True)
class _Ring:
    x: np.ndarray
    y: np.ndarray
    layer: str
    source: str
    closed: bool = True  # False: a polyline not flagged closed, closed only if it ends where it starts (snapped)
    curved: bool = False  # arcs (bulges) or a circle, made chords


def read_drawing(path: str | Path, drawing_unit: str | None = None, chord_tolerance: float | None = None,
                 snap_tolerance: float | None = None) -> Drawing:
    """The cleaned blocks of a drawing file (``.dxf``, ``.csv``, ``.geojson``/``.json``).

    ``drawing_unit`` (m, cm, mm) overrides the DXF ``$INSUNITS`` and is required
    for the other formats; ``chord_tolerance`` and ``snap_tolerance`` are in
    drawing units. Raises :class:`SpecError` naming the entity (DXF handle, CSV
    row, GeoJSON feature) and its coordinates.
    """
    path = drawing_file(path)
    kind = SUFFIXES.get(path.suffix.lower())
    if kind is None:
        raise SpecError(f"drawing {str(path)!r}: unknown file type {path.suffix!r}; "
                        f"use {', '.join(sorted(SUFFIXES))}")
    if drawing_unit is not None and drawing_unit not in DRAWING_UNITS:
        raise SpecError(f"drawing unit {drawing_unit!r}: must be one of {', '.join(DRAWING_UNITS)}")
    if kind == "dxf":
        rings, unit, ignored = _read_dxf(path, drawing_unit, chord_tolerance)
    else:
        if drawing_unit is None:
            raise SpecError(f"drawing {str(path)!r}: a {kind.upper()} file carries no unit; "
                            "give geometry.drawing_unit (m, cm or mm)")
        rings, unit, ignored = (_read_csv(path) if kind == "csv" else _read_geojson(path)), drawing_unit, {}
    if not rings:
        raise SpecError(f"drawing {str(path)!r}: no closed polyline or polygon in it"
                        + (f" (left out: {_counted(ignored)})" if ignored else ""))
    scale = DRAWING_UNITS[unit]
    rings = [_Ring(r.x * scale, r.y * scale, r.layer, r.source, r.closed, r.curved) for r in rings]
    snap = None if snap_tolerance is None else snap_tolerance * scale
    return clean(rings, snap, ignored)


#: An elevation's arcs (an arched window's head) become chords within this [m] unless the spec says otherwise.
ELEVATION_CHORD = 1e-3


@dataclass(frozen=True)
class Elevation:
    """An architect's elevation in metres: the wall's outline and its openings (each with what it was in the
    drawing, for messages)."""

    outline: np.ndarray  # (n, 2)
    outline_source: str
    openings: tuple[np.ndarray, ...]
    opening_sources: tuple[str, ...]
    notes: tuple[str, ...] = ()  # what reading did (arcs made chords by the default tolerance)


def read_elevation(path: str | Path, drawing_unit: str | None, outline_layer: str, openings_layer: str | None,
                   chord_tolerance: float | None = None) -> Elevation:
    """The outline (the one closed polyline, or polygon, on ``outline_layer``) and the openings of an elevation
    drawing: those on ``openings_layer``, else every other closed one inside the outline, and the holes of a
    GeoJSON outline. Units as :func:`read_drawing`; arcs become chords within ``chord_tolerance`` (drawing units,
    default :data:`ELEVATION_CHORD`); a SpecError names the layer or the entity at fault."""
    path = drawing_file(path)
    kind = SUFFIXES.get(path.suffix.lower())
    if kind is None:
        raise SpecError(f"drawing {str(path)!r}: unknown file type {path.suffix!r}; use {', '.join(sorted(SUFFIXES))}")
    if kind == "dxf":
        rings, unit, _ = _read_dxf(path, drawing_unit, chord_tolerance, ELEVATION_CHORD,
                                   {outline_layer, openings_layer} - {None})
    else:
        if drawing_unit is None:
            raise SpecError(f"drawing {str(path)!r}: a {kind.upper()} file carries no unit; "
                            "give geometry.drawing_unit (m, cm or mm)")
        rings, unit = (_read_csv(path) if kind == "csv" else _read_geojson(path, holes=True)), drawing_unit
    outlines = [r for r in rings if r.layer == outline_layer]
    if len(outlines) != 1:
        layers = ", ".join(sorted({r.layer for r in rings})) or "none"
        raise SpecError(f"drawing {path.name!r}: {len(outlines)} closed polyline(s) on outline_layer "
                        f"{outline_layer!r}; an elevation has one outline (the drawing's layers: {layers})")
    scale = DRAWING_UNITS[unit]
    outline = np.c_[outlines[0].x, outlines[0].y] * scale
    if openings_layer is not None:
        chosen = [r for r in rings if r.layer in (openings_layer, f"{outline_layer}/hole")]
    else:
        import shapely

        shape = shapely.Polygon(outline / scale)
        chosen = [r for r in rings if r is not outlines[0] and shapely.Polygon(np.c_[r.x, r.y]).within(shape)]
    for ring in [outlines[0], *chosen]:
        _refuse_open_ring(ring, scale, path)
    notes = []
    if chord_tolerance is None and any(r.curved for r in [outlines[0], *chosen]):
        notes.append(f"arcs and circles of {path.name!r} made chords within {ELEVATION_CHORD * 1e3:g} mm (the "
                     "default; geometry.chord_tolerance sets it)")
    return Elevation(outline, outlines[0].source, tuple(np.c_[r.x, r.y] * scale for r in chosen),
                     tuple(r.source for r in chosen), tuple(notes))


def _refuse_open_ring(ring: _Ring, scale: float, path: Path) -> None:
    """An elevation's outline or opening drawn as a polyline that is not closed and does not come back to its
    start: refused, with its ends (it used to be closed silently by its last edge)."""
    size = max(float(np.ptp(ring.x)), float(np.ptp(ring.y)), 1e-300)
    gap = float(np.hypot(ring.x[-1] - ring.x[0], ring.y[-1] - ring.y[0]))
    if ring.closed or gap <= RELATIVE_SNAP * size:
        return
    start, end = _told_apart((ring.x[0] * scale, ring.y[0] * scale), (ring.x[-1] * scale, ring.y[-1] * scale))
    raise SpecError(f"drawing {path.name!r}: {ring.source} on layer {ring.layer}: open: it starts at {start} m and "
                    f"ends at {end} m; an outline or an opening is one closed polyline (close it)")


def _counted(ignored: dict[str, int]) -> str:
    return ", ".join(f"{n} {kind}" for kind, n in sorted(ignored.items()))


# ---------------------------------------------------------------- readers

def drawing_file(path: str | Path) -> Path:
    """``path`` if it is a regular file whose reading fits in memory (an :class:`InputError` if not)."""
    file = regular_file(path, "drawing")
    size = file.stat().st_size
    fits_in_memory(size * DRAWING_BYTES_FACTOR, f"drawing {str(path)!r} ({size_text(size)})")
    return file


def _open_dxf(path: Path):
    """The ezdxf document of a DXF file, text (repaired where it can be) or binary; ezdxf's own repair
    messages are not printed (they quote the file's lines), a failure is ours to say."""
    import ezdxf  # here, not at the top: only a drawing needs it
    from ezdxf import recover

    with path.open("rb") as handle:
        head = handle.read(4096)
    binary = head.startswith(BINARY_DXF)
    if not binary and not _text_dxf(head):
        raise SpecError(f"drawing {str(path)!r}: not a DXF file (a text DXF starts with the group code 0 and "
                        "SECTION, or a 999 comment; a binary one with 'AutoCAD Binary DXF')")
    ezdxf_log = logging.getLogger("ezdxf")
    level = ezdxf_log.level
    ezdxf_log.setLevel(logging.CRITICAL)
    try:  # recover repairs damaged text files; a binary DXF ("AutoCAD Binary DXF") reads as it is
        return ezdxf.readfile(str(path)) if binary else recover.readfile(str(path))[0]
    except (OSError, ezdxf.DXFError, UnicodeDecodeError) as exc:
        raise SpecError(f"drawing {str(path)!r}: not a readable DXF file ({type(exc).__name__})") from None
    finally:
        ezdxf_log.setLevel(level)


def _text_dxf(head: bytes) -> bool:
    """Whether ``head`` (a file's first bytes) starts as a text DXF does: group code 0 then SECTION, or 999."""
    lines = [line.strip() for line in head.lstrip(b"\xef\xbb\xbf").splitlines() if line.strip()][:2]
    return lines[:1] == [b"999"] or lines == [b"0", b"SECTION"]


@dataclass(frozen=True)
class DxfLines:
    """The open lines of a DXF drawing, in drawing units, with their entities and the drawing's $INSUNITS."""

    lines: tuple[np.ndarray, ...]  # (n, 2) each
    sources: tuple[tuple[str, str], ...]  # (entity type, handle)
    insunits: int


def read_dxf_lines(path: str | Path, layer: str | None = None) -> DxfLines:
    """Every ``LINE``, ``LWPOLYLINE`` and 2D ``POLYLINE`` of a DXF drawing (on ``layer`` when given) as a
    polyline in drawing units (arcs flattened to 1e-3 drawing units): a crack map drawn over a wall."""
    from ezdxf import path as dxf_path

    path = drawing_file(path)
    doc = _open_dxf(path)
    lines, sources = [], []
    for entity in _flat_entities(doc.modelspace()):
        kind = entity.dxftype()
        if kind not in ("LINE", "LWPOLYLINE", "POLYLINE") or (layer is not None and entity.dxf.get("layer") != layer):
            continue
        if kind == "POLYLINE" and not entity.is_2d_polyline:
            continue
        points = np.array([(v.x, v.y) for v in dxf_path.make_path(entity).flattening(distance=1e-3)])
        if points.shape[0] >= 2:
            lines.append(points)
            sources.append((kind, str(entity.dxf.get("handle", "?"))))
    return DxfLines(tuple(lines), tuple(sources), int(doc.header.get("$INSUNITS", 0)))


def _read_dxf(path: Path, drawing_unit: str | None, chord_tolerance: float | None, default_chord: float | None = None,
              outlined: set[str] = frozenset()):
    """The closed polylines of a DXF drawing (and, in an elevation, its circles and ellipses), its unit and the
    entities left out. An arc needs a chord tolerance (drawing units): ``chord_tolerance``, else ``default_chord``
    metres, else an error. On the ``outlined`` layers (an elevation's outline and openings) nothing else may be
    drawn: a line or an arc there is refused, named (it was left out silently, and an opening drawn so
    vanished)."""
    doc = _open_dxf(path)
    unit = drawing_unit
    if unit is None:
        code = int(doc.header.get("$INSUNITS", 0))
        unit = INSUNITS.get(code)
        if unit is None:
            raise SpecError(f"drawing {str(path)!r}: its $INSUNITS = {code} is not m, cm or mm "
                            "(1 = inches is common in drawings made in mm); give geometry.drawing_unit")
    if chord_tolerance is None and default_chord is not None:
        chord_tolerance = default_chord / DRAWING_UNITS[unit]
    rings: list[_Ring] = []
    ignored: Counter = Counter()
    for entity in _flat_entities(doc.modelspace()):
        kind = entity.dxftype()
        if kind in POLYLINES or outlined and kind in CURVES:
            rings.append(_polyline_ring(entity, path, chord_tolerance))
        elif entity.dxf.get("layer", "0") in outlined and kind not in ANNOTATIONS:
            raise SpecError(f"drawing {path.name!r}: {kind} #{entity.dxf.get('handle', '?')} on layer "
                            f"{entity.dxf.get('layer', '0')}: an outline or an opening is one closed polyline (its "
                            "arcs drawn as bulges) or a circle; join its pieces into a closed polyline")
        else:
            ignored[kind] += 1
    return rings, unit, dict(ignored)


#: The DXF entities read as closed outlines: polylines (their arcs as bulges); in an elevation also circles and
#: ellipses (a round window: :func:`read_elevation`).
POLYLINES = ("LWPOLYLINE", "POLYLINE")
CURVES = ("CIRCLE", "ELLIPSE")
#: Entities that draw no geometry (left out on any layer).
ANNOTATIONS = ("TEXT", "MTEXT", "DIMENSION", "POINT", "LEADER", "MLEADER", "HATCH")
#: The finest chord tolerance of an arc, relative to the size of the entity it is in: finer, an arc of the size of
#: the entity would become more than about 10,000 chords (and ezdxf's flattening recurses past Python's limit).
FINEST_CHORD = 1e-7


def _flat_entities(layout):
    """Every entity of ``layout``, block references (INSERT) exploded into their entities."""
    for entity in layout:
        if entity.dxftype() == "INSERT":
            yield from _flat_entities(entity.virtual_entities())
        else:
            yield entity


def _polyline_ring(entity, path: Path, chord_tolerance: float | None) -> _Ring:
    from ezdxf import path as dxf_path

    handle = entity.dxf.get("handle", "?")
    layer = str(entity.dxf.get("layer", "0"))
    source = f"{entity.dxftype()} #{handle}"
    where = f"drawing {path.name!r}: {source} on layer {layer}"
    if entity.dxftype() == "POLYLINE" and not entity.is_2d_polyline:
        raise SpecError(f"{where}: a 3D polyline or mesh, not a block outline; draw each block as a closed 2D polyline")
    curved = entity.dxftype() in ("CIRCLE", "ELLIPSE") or entity.has_arc
    if curved and chord_tolerance is None:
        raise SpecError(f"{where}: has arc segments (bulges, or is a circle); give geometry.chord_tolerance (drawing "
                        "units) to replace them by chords, or draw straight segments")
    if chord_tolerance is not None and not chord_tolerance > 0:
        raise SpecError(f"geometry.chord_tolerance = {chord_tolerance!r}: must be > 0")
    outline = dxf_path.make_path(entity)
    corners = np.array([(v.x, v.y, v.z) for v in outline.control_vertices()])
    size = float(np.ptp(corners[:, :2], axis=0).max()) if corners.size else 0.0
    if not np.isfinite(corners).all() or not np.isfinite(size):
        raise SpecError(f"{where}: its coordinates are not finite numbers")
    if curved and chord_tolerance < FINEST_CHORD * size:
        raise SpecError(f"geometry.chord_tolerance = {chord_tolerance:.3g} (drawing units) is finer than "
                        f"{FINEST_CHORD:g} of the size of {source} on layer {layer} ({size:.4g}): its arcs would "
                        f"become millions of chords; give at least {FINEST_CHORD * size:.3g}")
    try:
        points = np.array([(v.x, v.y, v.z) for v in outline.flattening(distance=chord_tolerance or 1.0)])
    except (RecursionError, ValueError, OverflowError) as exc:
        raise SpecError(f"{where}: its arcs cannot be made chords ({exc}); are its coordinates what was meant?") from None
    if points.shape[0] and np.ptp(points[:, 2]) > 0:
        raise SpecError(f"{where}: its vertices are not in one plane parallel to the drawing (z varies)")
    x, y = points[:, 0], points[:, 1]
    closed = entity.dxftype() in ("CIRCLE", "ELLIPSE") or bool(entity.closed)
    return _Ring(x, y, layer, source, closed, curved)


def _number(text: str, where: str, column: str) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise SpecError(f"{where}: {column} = {text!r} is not a number") from None
    if not np.isfinite(value):
        raise SpecError(f"{where}: {column} = {text!r} is not finite")
    return value


def _read_csv(path: Path) -> list[_Ring]:
    with io.StringIO(read_text(path, "drawing"), newline="") as handle:
        reader = csv.DictReader(handle)
        columns = [c.strip() for c in (reader.fieldnames or [])]
        missing = [c for c in ("block", "x", "y") if c not in columns]
        if missing:
            raise SpecError(f"drawing {path.name!r}: needs the columns block, x, y (and optionally layer) in "
                            f"its first row; {', '.join(missing)} missing{_found_columns(columns)}")
        points: dict[str, list] = {}
        layers: dict[str, str] = {}
        for number, row in enumerate(reader, start=2):
            row = {k.strip(): (v or "").strip() for k, v in row.items() if k is not None}
            where = f"drawing {path.name!r} row {number}"
            block = row["block"]
            if not block:
                raise SpecError(f"{where}: the block column is empty")
            points.setdefault(block, []).append((_number(row["x"], where, "x"), _number(row["y"], where, "y")))
            layer = row.get("layer") or "0"
            if layers.setdefault(block, layer) != layer:
                raise SpecError(f"{where}: block {block!r} is on layer {layers[block]!r} in an earlier row, "
                                f"{layer!r} here")
    return [_Ring(np.array([p[0] for p in pts]), np.array([p[1] for p in pts]), layers[name], f"block {name!r}")
            for name, pts in points.items()]


def _found_columns(columns: list[str]) -> str:
    """``" (found X, Y)"`` when the first row looks like column names; nothing when it does not (the file may
    be anything: a message never quotes what is not a drawing)."""
    if columns and all(re.fullmatch(r"[\w .-]{1,32}", c) for c in columns):
        return f" (found {', '.join(columns)})"
    return " (its first row is not a row of column names: is it a CSV drawing?)"


def _read_geojson(path: Path, holes: bool = False) -> list[_Ring]:
    """One ring per Polygon feature; with ``holes``, a polygon's holes too (rings on the layer ``<layer>/hole``:
    an outline's openings), else a hole is refused."""
    try:
        data = json.loads(read_text(path, "drawing"))
    except ValueError as exc:  # JSONDecodeError says where (line, column), not what is there
        raise SpecError(f"drawing {path.name!r}: not readable JSON ({exc})") from None
    features = data.get("features") if isinstance(data, dict) and data.get("type") == "FeatureCollection" else [data]
    if not isinstance(features, list):
        raise SpecError(f"drawing {path.name!r}: 'features' is a {type(features).__name__}, not a list of features")
    rings = []
    for index, feature in enumerate(features):
        where = f"drawing {path.name!r} feature {index}"
        if not isinstance(feature, dict):
            raise SpecError(f"{where}: a JSON {_json_kind(feature)}, not a Feature object")
        geometry = feature.get("geometry", feature)
        properties = feature.get("properties") if isinstance(feature.get("properties"), dict) else {}
        if not isinstance(geometry, dict) or geometry.get("type") != "Polygon":
            kind = geometry.get("type") if isinstance(geometry, dict) else f"JSON {_json_kind(geometry)}"
            raise SpecError(f"{where}: a {kind}, not a Polygon; one Polygon per block")
        outline, *inner = _polygon_rings(geometry.get("coordinates"), where, holes)
        name = properties.get("name", properties.get("id", index))
        layer = str(properties.get("layer", "0"))
        rings.append(_Ring(outline[:, 0], outline[:, 1], layer, f"feature {name}"))
        rings += [_Ring(hole[:, 0], hole[:, 1], f"{layer}/hole", f"feature {name} hole {k}")
                  for k, hole in enumerate(inner)]
    return rings


def _json_kind(value) -> str:
    return {dict: "object", list: "array", str: "string", bool: "boolean", type(None): "null"}.get(
        type(value), "number")


def _is_position(value) -> bool:
    return isinstance(value, list) and 2 <= len(value) <= 3 and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)


def _polygon_rings(coordinates, where: str, holes: bool) -> list[np.ndarray]:
    """The rings of a GeoJSON Polygon's ``coordinates`` (the outline first, then its holes when ``holes``) as
    ``(n, 2)`` arrays, or a SpecError saying what is wrong where (never quoting more than a position)."""
    if not isinstance(coordinates, list) or not coordinates:
        raise SpecError(f"{where}: its coordinates are a JSON {_json_kind(coordinates)}"
                        f"{' (empty)' if coordinates == [] else ''}, not a list of rings")
    if _is_position(coordinates[0]):
        raise SpecError(f"{where}: its coordinates are one ring of [x, y] positions, not a list of rings; "
                        "wrap the ring in one more [ ]")
    if len(coordinates) != 1 and not holes:
        raise SpecError(f"{where}: a polygon with {len(coordinates) - 1} hole(s); a block is one outline without holes"
                        " (an elevation's outline with openings is laid by geometry.outline_layer)")
    return [_ring_positions(ring, where if k == 0 else f"{where} hole {k - 1}") for k, ring in enumerate(coordinates)]


def _ring_positions(ring, where: str) -> np.ndarray:
    if isinstance(ring, list) and ring and isinstance(ring[0], list) and ring[0] and isinstance(ring[0][0], list):
        raise SpecError(f"{where}: its coordinates are nested one level too deep (a Polygon's are [[[x, y], ...]]; "
                        "a MultiPolygon's are not read)")
    if not isinstance(ring, list) or len(ring) < 3:
        raise SpecError(f"{where}: its ring is a JSON {_json_kind(ring)}"
                        f"{f' of {len(ring)} position(s)' if isinstance(ring, list) else ''}, not a list of at "
                        "least 3 [x, y] positions")
    for k, position in enumerate(ring):
        if not _is_position(position):
            shown = f"a JSON {_json_kind(position)}" if not isinstance(position, list) else (
                "a list of lists (one level too deep)" if position and isinstance(position[0], list)
                else f"[{', '.join(_json_kind(v) for v in position)}]")
            raise SpecError(f"{where}: position {k} is {shown}, not [x, y] numbers")
        try:
            values = [float(v) for v in position[:2]]
        except OverflowError:
            values = [np.inf]
        if not np.isfinite(values).all():
            raise SpecError(f"{where}: position {k} has a coordinate too large for a number (not finite)")
    return np.array([[float(p[0]), float(p[1])] for p in ring])


# ---------------------------------------------------------------- cleaning

def clean(rings: list[_Ring], snap: float | None = None, ignored: dict[str, int] | None = None) -> Drawing:
    """Snap, simplify, orient and validate ``rings`` (metres): the steps of the module docstring."""
    x = np.concatenate([r.x for r in rings])
    y = np.concatenate([r.y for r in rings])
    size = float(np.hypot(np.ptp(x), np.ptp(y))) or 1.0
    derived = snap is None
    snap = RELATIVE_SNAP * size if snap is None else snap
    if not snap > 0:
        raise SpecError(f"geometry.snap_tolerance: must be > 0, got {snap!r}")
    if derived:
        _refuse_stray_vertex(rings, x, y, snap)
    raw_x, raw_y = x, y
    x, y = snapped(x, y, snap)
    counts = np.array([r.x.size for r in rings])
    starts = block_offsets(counts)
    _refuse_open(rings, starts, x, y, raw_x, raw_y, snap)
    cleaned_x, cleaned_y, cleaned_counts = [], [], []
    for i, ring in enumerate(rings):
        rx, ry = _simplified(x[starts[i]:starts[i + 1]], y[starts[i]:starts[i + 1]], snap, ring)
        cleaned_x.append(rx)
        cleaned_y.append(ry)
        cleaned_counts.append(rx.size)
    node_x, node_y = np.concatenate(cleaned_x), np.concatenate(cleaned_y)
    counts = np.array(cleaned_counts, dtype=np.int32)
    _refuse_self_intersections(node_x, node_y, counts, rings)
    node_x, node_y = _counter_clockwise(node_x, node_y, counts, rings, snap)
    return Drawing(node_x, node_y, counts, tuple(r.layer for r in rings), tuple(r.source for r in rings),
                   dict(ignored or {}))


def _refuse_stray_vertex(rings: list[_Ring], x: np.ndarray, y: np.ndarray, snap: float) -> None:
    """A SpecError naming the vertex that makes the drawing so large that its snap tolerance swallows blocks
    (one vertex typed at 1e12 among blocks of 0.25 m): the vertex farthest from the median of them all."""
    sizes = np.array([np.hypot(np.ptp(r.x), np.ptp(r.y)) if r.x.size else 0.0 for r in rings])
    if not (sizes < 10 * snap).any():
        return
    far = int(np.argmax(np.hypot(x - np.median(x), y - np.median(y))))
    owner = int(np.searchsorted(block_offsets(np.array([r.x.size for r in rings])), far, side="right") - 1)
    others = np.ones(x.size, dtype=bool)
    others[far] = False
    rest = float(np.hypot(np.ptp(x[others]), np.ptp(y[others]))) if others.any() else 0.0
    if 0 < rest * RELATIVE_SNAP * 10 < sizes.min():  # without that vertex the blocks would survive
        raise SpecError(f"{rings[owner].source} on layer {rings[owner].layer}: its vertex ({x[far]:.6g}, "
                        f"{y[far]:.6g}) m lies far from every other one (which span {rest:.6g} m), so that the "
                        f"snap tolerance ({RELATIVE_SNAP:g} of the drawing's size, {snap:.3g} m) is larger than "
                        "the blocks; is that vertex a mistake?")


def _refuse_open(rings, starts, x, y, raw_x, raw_y, snap: float) -> None:
    """A SpecError naming the first ring not flagged closed that never comes back to its first vertex (after
    snapping: a polyline that ends a hair from its start is closed; one that goes on past it is cut later)
    with the gap and the ends written with as many digits as it takes to tell them apart."""
    for i, ring in enumerate(rings):
        first, last = starts[i], starts[i + 1] - 1
        back = (x[first + 2:last + 1] == x[first]) & (y[first + 2:last + 1] == y[first])
        if ring.closed or back.any():
            continue
        gap = float(np.hypot(raw_x[last] - raw_x[first], raw_y[last] - raw_y[first]))
        start, end = _told_apart((raw_x[first], raw_y[first]), (raw_x[last], raw_y[last]))
        raise SpecError(f"{ring.source} on layer {ring.layer}: open: it starts at {start} m and ends at {end} m, "
                        f"{gap:.3g} m apart, more than the snap tolerance {snap:.3g} m; close it (or raise "
                        "geometry.snap_tolerance)")


def _told_apart(a, b) -> tuple[str, str]:
    """Two points written with the fewest significant digits (at least 6) that show how they differ."""
    for digits in range(6, 18):
        left = f"({a[0]:.{digits}g}, {a[1]:.{digits}g})"
        right = f"({b[0]:.{digits}g}, {b[1]:.{digits}g})"
        if left != right:
            return left, right
    return left, right


def snapped(x: np.ndarray, y: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices within ``tol`` of each other (chains included) moved onto the first of them."""
    from scipy.spatial import cKDTree

    pairs = cKDTree(np.c_[x, y]).query_pairs(tol, output_type="ndarray")
    label = connected_components(x.size, pairs)
    first = np.full(label.max(initial=-1) + 1, x.size)
    np.minimum.at(first, label, np.arange(x.size))
    return x[first[label]], y[first[label]]


def _simplified(x: np.ndarray, y: np.ndarray, tol: float, ring: _Ring) -> tuple[np.ndarray, np.ndarray]:
    """One polygon without repeats, retraces and straight-line vertices."""
    where = ring.source + f" on layer {ring.layer}"
    keep = np.r_[True, (x[1:] != x[:-1]) | (y[1:] != y[:-1])]
    x, y = x[keep], y[keep]
    back = np.flatnonzero((x[1:] == x[0]) & (y[1:] == y[0])) + 1
    if back.size:  # closed by repeating the first vertex, perhaps going on round again
        tail = set(zip(x[back[0]:], y[back[0]:]))
        if not tail <= set(zip(x[:back[0]], y[:back[0]])):
            raise SpecError(f"{where}: passes through its first vertex ({x[0]:.6g}, {y[0]:.6g}) m and goes on "
                            "elsewhere: it touches itself; draw one closed outline per block")
        x, y = x[:back[0]], y[:back[0]]
    while x.size >= 3:
        distinct = (x != np.roll(x, 1)) | (y != np.roll(y, 1))
        x, y = x[distinct], y[distinct]
        straight = _straight_vertices(x, y, tol)
        if not straight.any():
            break
        straight &= ~np.roll(straight, 1)  # never two neighbours in one pass: each goes against its own chord
        x, y = x[~straight], y[~straight]
    if x.size < 3:
        raise SpecError(f"{where}: fewer than 3 distinct vertices after snapping (near ({ring.x[0]:.6g}, "
                        f"{ring.y[0]:.6g}) m): not a block")
    return x, y


def _counter_clockwise(x, y, counts, rings, tol):
    """Every polygon turned counter-clockwise; one with (nearly) no area is refused."""
    area = polygon_area_centroid(x, y, counts)[0]
    starts = block_offsets(counts)
    for b in np.flatnonzero(area < 0):
        x[starts[b]:starts[b + 1]] = x[starts[b]:starts[b + 1]][::-1].copy()
        y[starts[b]:starts[b + 1]] = y[starts[b]:starts[b + 1]][::-1].copy()
    owner = np.repeat(np.arange(counts.size), counts)
    following = np.arange(x.size) + 1
    following[starts[1:] - 1] = starts[:-1]
    perimeter = np.bincount(owner, np.hypot(x[following] - x, y[following] - y), minlength=counts.size)
    for b in np.flatnonzero(np.abs(area) <= tol * perimeter):
        raise SpecError(f"{rings[b].source} on layer {rings[b].layer}: zero area near ({x[starts[b]]:.6g}, "
                        f"{y[starts[b]]:.6g}) m: not a block")
    return x, y


def _straight_vertices(x: np.ndarray, y: np.ndarray, tol: float) -> np.ndarray:
    """Vertices within ``tol`` of the straight line through their neighbours, and spike tips."""
    px, py = np.roll(x, 1), np.roll(y, 1)
    nx, ny = np.roll(x, -1), np.roll(y, -1)
    chord = np.hypot(nx - px, ny - py)
    cross = (x - px) * (ny - py) - (y - py) * (nx - px)
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = np.where(chord > 0, np.abs(cross) / chord, 0.0)
    return offset <= tol


def _refuse_self_intersections(x, y, counts, rings) -> None:
    """A SpecError naming the first polygon whose edges cross or touch (other than at its vertices in turn)."""
    import shapely

    rings_of = shapely.linearrings(np.c_[x, y], indices=np.repeat(np.arange(counts.size), counts))
    simple = shapely.is_simple(rings_of)
    for b in np.flatnonzero(~simple):
        reason = shapely.is_valid_reason(shapely.polygons(rings_of[b]))
        raise SpecError(f"{rings[b].source} on layer {rings[b].layer}: the outline crosses or touches itself "
                        f"({reason}, coordinates in m); draw each block as one simple closed outline")
