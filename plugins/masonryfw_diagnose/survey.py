"""What an engineer brings from site: a crack map (lines on the elevation, widths in mm) and a levelling.

Crack maps: GeoJSON ``LineString``/``MultiLineString`` features (``properties.width_mm`` optional), CSV rows
``crack, x, y[, width_mm]`` (the points of each crack in order, its width on any of its rows), or a DXF's
``LINE``/``LWPOLYLINE``/``POLYLINE`` entities (on one layer with ``layer``). A levelling: CSV ``x, y, dy``,
points of a course laid level and how far each now lies from level (negative down). Coordinates and ``dy``
in ``unit`` (m, cm, mm; a DXF's own ``$INSUNITS`` when no unit is given), widths always in mm. Every
refusal names the file and the item (row, feature, entity).
"""
from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp

UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}
INSUNITS = {4: "mm", 5: "cm", 6: "m"}
CRACK_FORMATS = (".geojson", ".json", ".csv", ".dxf")
#: The most lines and points a crack map may hold, and points a levelling: a survey draws tens to hundreds of
#: cracks and levels a point or a few a unit; a map of 300,000 lines took 2.3 GB and 4.5 minutes.
MAX_CRACKS = 10_000
MAX_CRACK_POINTS = 200_000
MAX_LEVELLING_POINTS = 10_000
#: The widest crack width a map may give [mm]: Burland's worst category starts at 25 mm.
MAX_WIDTH_MM = 1000.0
#: Memory while reading, per byte of a GeoJSON crack map (json.loads of a 53 MB map took 4.6 times its size).
JSON_BYTES_FACTOR = 6


@dataclass(frozen=True)
class Survey:
    """Observed cracks as polylines in metres (each with its width in mm, or None) and a levelling (or None)."""

    cracks: tuple[np.ndarray, ...]  # (n, 2) each
    widths_mm: tuple[float | None, ...]
    names: tuple[str, ...]
    levelling: np.ndarray | None = None  # (m, 3): x, y, dy [m]
    sources: dict = field(default_factory=dict)  # what was read from where, for messages

    def with_levelling(self, levelling: np.ndarray, source: str) -> Survey:
        return dataclasses.replace(self, levelling=levelling, sources={**self.sources, "levelling": source})


def read_cracks(path: str | Path, unit: str | None = None, layer: str | None = None) -> Survey:
    """The crack map at ``path`` (module docstring)."""
    path = mfp.regular_file(path, "crack map")
    suffix = path.suffix.lower()
    if suffix not in CRACK_FORMATS:
        raise mf.SpecError(f"crack map {str(path)!r}: unknown file type {suffix!r}; use {', '.join(CRACK_FORMATS)}")
    if unit is not None and unit not in UNITS:
        raise mf.SpecError(f"--unit {unit!r}: must be one of {', '.join(UNITS)}")
    if suffix == ".dxf":
        lines, widths, names, unit = _dxf_cracks(path, unit, layer)
    else:
        if layer is not None:
            raise mf.SpecError(f"crack map {path.name!r}: --cracks-layer applies to a DXF drawing only")
        lines, widths, names = (_csv_cracks if suffix == ".csv" else _geojson_cracks)(path)
        unit = unit or "m"
    if not lines:
        raise mf.SpecError(f"crack map {path.name!r}: no crack in it" + (f" on layer {layer!r}" if layer else ""))
    _check_size(path, len(lines), sum(len(line) for line in lines))
    scale = UNITS[unit]
    cracks = tuple(np.asarray(line, dtype=float) * scale for line in lines)
    for name, line in zip(names, cracks):
        _check_line(path, name, line, unit)
    return Survey(cracks, tuple(widths), tuple(names), sources={"cracks": path.name, "unit": unit})


def _check_size(path: Path, lines: int, points: int) -> None:
    if lines > MAX_CRACKS or points > MAX_CRACK_POINTS:
        raise mf.SpecError(f"crack map {path.name!r}: {lines:,} lines of {points:,} points; a survey has tens to "
                           f"hundreds of cracks, and at most {MAX_CRACKS:,} lines of {MAX_CRACK_POINTS:,} points are "
                           "read: is it a crack map?")


def _check_line(path: Path, name: str, line: np.ndarray, unit: str) -> None:
    """A crack is a line of finite points (a DXF may hold NaN) with a length."""
    where = f"crack map {path.name!r}: crack {name!r}"
    if not np.isfinite(line).all():
        raise mf.SpecError(f"{where}: a coordinate is not a finite number")
    if not np.hypot(*np.diff(line, axis=0).T).sum() > 0:
        x, y = line[0] / UNITS[unit]
        raise mf.SpecError(f"{where}: has no length (its points all lie at ({x:.6g}, {y:.6g}) {unit}); a crack is a line")


def _number(value, where: str, what: str) -> float:
    """``value`` (a JSON number) as a finite float; a :class:`SpecError` naming ``what`` otherwise (an integer of
    400 digits overflows a float)."""
    shown = f"{str(value)[:20]}..." if len(str(value)) > 24 else repr(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise mf.SpecError(f"{where}: {what} {shown} is not a number")
    try:
        number = float(value)
    except OverflowError:
        number = math.inf
    if not math.isfinite(number):
        raise mf.SpecError(f"{where}: {what} {shown} is not a finite number")
    return number


def _coordinate(value, where: str) -> float:
    return _number(value, where, "coordinate")


def _points(raw, where: str) -> list[tuple[float, float]]:
    if not isinstance(raw, list) or len(raw) < 2:
        raise mf.SpecError(f"{where}: a line needs at least two points, got {str(raw)[:60]}")
    points = []
    for point in raw:
        if not isinstance(point, list) or len(point) < 2:
            raise mf.SpecError(f"{where}: {str(point)[:60]} is not an [x, y] point")
        points.append((_coordinate(point[0], where), _coordinate(point[1], where)))
    return points


def _width(value, where: str) -> float | None:
    if value is None:
        return None
    width = _number(value, where, "width_mm")
    if not 0 <= width <= MAX_WIDTH_MM:
        raise mf.SpecError(f"{where}: width_mm = {width:.6g} is not a crack width in mm (0 to {MAX_WIDTH_MM:g})")
    return width


def _geojson_cracks(path: Path):
    text = mfp.read_text(path, "crack map")
    mfp.fits_in_memory(JSON_BYTES_FACTOR * len(text), f"crack map {path.name!r}: reading it")
    try:
        data = json.loads(text)
    except (ValueError, RecursionError) as exc:  # RecursionError: arrays nested thousands deep
        raise mf.SpecError(f"crack map {path.name!r}: not readable JSON ({type(exc).__name__})") from None
    features = data.get("features") if isinstance(data, dict) and data.get("type") == "FeatureCollection" else [data]
    if not isinstance(features, list):
        raise mf.SpecError(f"crack map {path.name!r}: its features are a JSON {type(features).__name__}, not a list "
                           "of Feature objects")
    if len(features) > MAX_CRACKS:
        _check_size(path, len(features), len(features))
    lines, widths, names = [], [], []
    for index, feature in enumerate(features or []):
        where = f"crack map {path.name!r} feature {index}"
        geometry = feature.get("geometry") if isinstance(feature, dict) else None
        properties = (feature.get("properties") or {}) if isinstance(feature, dict) else {}
        kind = geometry.get("type") if isinstance(geometry, dict) else type(geometry).__name__
        if kind == "LineString":
            parts = [geometry.get("coordinates")]
        elif kind == "MultiLineString":
            parts = geometry.get("coordinates")
            if not isinstance(parts, list):
                raise mf.SpecError(f"{where}: a MultiLineString's coordinates must be a list of lines")
        else:
            raise mf.SpecError(f"{where}: a {kind}, not a LineString or MultiLineString; a crack is a line")
        width = _width(properties.get("width_mm") if isinstance(properties, dict) else None, where)
        name = str(properties.get("name", properties.get("id", index))) if isinstance(properties, dict) else str(index)
        for k, part in enumerate(parts):
            lines.append(_points(part, where))
            widths.append(width)
            names.append(name if len(parts) == 1 else f"{name}.{k}")
    return lines, widths, names


def _csv_rows(path: Path, what: str, needed: tuple[str, ...], limit: int):
    """``(row number, {column: text})`` of a CSV file whose first row names ``needed`` columns (others kept),
    read one row at a time; refused past ``limit`` rows."""
    try:
        reader = csv.reader(io.StringIO(mfp.read_text(path, what), newline=""))
        header = [c.strip() for c in next(reader, [])]
        missing = [c for c in needed if c not in header]
        if header and missing:
            raise mf.SpecError(f"{what} {path.name!r}: needs the columns {', '.join(needed)} in its first row; "
                               f"{', '.join(missing)} missing")
        for number, row in enumerate(reader, start=2):
            if number - 1 > limit:
                raise mf.SpecError(f"{what} {path.name!r}: over {limit:,} rows; at most {limit:,} are read (a survey "
                                   "has a point or a few a unit): is it the right file?")
            yield number, {name: value.strip() for name, value in zip(header, row)}
    except csv.Error as exc:
        raise mf.SpecError(f"{what} {path.name!r}: not a readable CSV file ({type(exc).__name__})") from None


def _csv_number(text: str, where: str, name: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise mf.SpecError(f"{where}: {name} = {text[:24]!r} is not a number") from None
    if not math.isfinite(value):
        raise mf.SpecError(f"{where}: {name} = {text[:24]!r} is not finite")
    return value


def _csv_cracks(path: Path):
    points: dict[str, list] = {}
    widths: dict[str, float | None] = {}
    for number, row in _csv_rows(path, "crack map", ("crack", "x", "y"), MAX_CRACK_POINTS):
        where = f"crack map {path.name!r} row {number}"
        name = row.get("crack", "")
        if not name:
            raise mf.SpecError(f"{where}: the crack column is empty")
        points.setdefault(name, []).append((_csv_number(row.get("x", ""), where, "x"),
                                            _csv_number(row.get("y", ""), where, "y")))
        if row.get("width_mm"):
            widths[name] = _width(_csv_number(row["width_mm"], where, "width_mm"), where)
    for name, line in points.items():
        if len(line) < 2:
            raise mf.SpecError(f"crack map {path.name!r}: crack {name!r} has one point; a line needs two")
    return list(points.values()), [widths.get(name) for name in points], list(points)


def _dxf_cracks(path: Path, unit: str | None, layer: str | None):
    """Lines of a DXF drawing; the unit its ``$INSUNITS`` says unless ``unit`` is given."""
    drawing = mfp.read_dxf_lines(path, layer)
    if unit is None:
        unit = INSUNITS.get(drawing.insunits)
        if unit is None:
            raise mf.SpecError(f"crack map {path.name!r}: its $INSUNITS = {drawing.insunits} is not m, cm or mm; "
                               "give --unit")
    names = [f"{kind} #{handle}" for kind, handle in drawing.sources]
    return list(drawing.lines), [None] * len(drawing.lines), names, unit


def read_levelling(path: str | Path, unit: str = "m") -> np.ndarray:
    """``(m, 3)`` x, y, dy [m] of a levelling CSV (module docstring)."""
    path = mfp.regular_file(path, "levelling")
    values = []
    for number, row in _csv_rows(path, "levelling", ("x", "y", "dy"), MAX_LEVELLING_POINTS):
        where = f"levelling {path.name!r} row {number}"
        values.append([_csv_number(row.get(name, ""), where, name) for name in ("x", "y", "dy")])
    if len(values) < 3:
        raise mf.SpecError(f"levelling {path.name!r}: {len(values)} point(s); a levelling needs at least three")
    return np.asarray(values) * UNITS[unit]
