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

UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}
INSUNITS = {4: "mm", 5: "cm", 6: "m"}
CRACK_FORMATS = (".geojson", ".json", ".csv", ".dxf")


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
    path = mf.regular_file(path, "crack map")
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
    scale = UNITS[unit]
    return Survey(tuple(np.asarray(line, dtype=float) * scale for line in lines), tuple(widths), tuple(names),
                  sources={"cracks": path.name, "unit": unit})


def _coordinate(value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise mf.SpecError(f"{where}: coordinate {value!r} is not a number")
    number = float(value)
    if not math.isfinite(number):
        raise mf.SpecError(f"{where}: coordinate {value!r} is not finite")
    return number


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
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
        raise mf.SpecError(f"{where}: width_mm = {value!r} must be a number >= 0")
    return float(value)


def _geojson_cracks(path: Path):
    try:
        data = json.loads(mf.read_text(path, "crack map"))
    except ValueError as exc:
        raise mf.SpecError(f"crack map {path.name!r}: not readable JSON ({type(exc).__name__})") from None
    features = data.get("features") if isinstance(data, dict) and data.get("type") == "FeatureCollection" else [data]
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


def _csv_cracks(path: Path):
    try:
        rows = list(csv.DictReader(io.StringIO(mf.read_text(path, "crack map"), newline="")))
        columns = [c.strip() for c in (rows[0].keys() if rows else [])]
    except csv.Error as exc:
        raise mf.SpecError(f"crack map {path.name!r}: not a readable CSV file ({type(exc).__name__})") from None
    missing = [c for c in ("crack", "x", "y") if c not in columns]
    if rows and missing:
        raise mf.SpecError(f"crack map {path.name!r}: needs the columns crack, x, y (and optionally width_mm) in its "
                           f"first row; {', '.join(missing)} missing")
    points: dict[str, list] = {}
    widths: dict[str, float | None] = {}
    for number, row in enumerate(rows, start=2):
        row = {str(k).strip(): (v or "").strip() for k, v in row.items() if k is not None}
        where = f"crack map {path.name!r} row {number}"
        name = row["crack"]
        if not name:
            raise mf.SpecError(f"{where}: the crack column is empty")
        try:
            x, y = float(row["x"]), float(row["y"])
        except ValueError:
            raise mf.SpecError(f"{where}: x = {row['x']!r}, y = {row['y']!r} are not numbers") from None
        if not (math.isfinite(x) and math.isfinite(y)):
            raise mf.SpecError(f"{where}: x = {row['x']!r}, y = {row['y']!r} are not finite")
        points.setdefault(name, []).append((x, y))
        if row.get("width_mm"):
            try:
                widths[name] = _width(float(row["width_mm"]), where)
            except ValueError:
                raise mf.SpecError(f"{where}: width_mm = {row['width_mm']!r} is not a number") from None
    for name, line in points.items():
        if len(line) < 2:
            raise mf.SpecError(f"crack map {path.name!r}: crack {name!r} has one point; a line needs two")
    return list(points.values()), [widths.get(name) for name in points], list(points)


def _dxf_cracks(path: Path, unit: str | None, layer: str | None):
    """Lines of a DXF drawing; the unit its ``$INSUNITS`` says unless ``unit`` is given."""
    drawing = mf.read_dxf_lines(path, layer)
    if unit is None:
        unit = INSUNITS.get(drawing.insunits)
        if unit is None:
            raise mf.SpecError(f"crack map {path.name!r}: its $INSUNITS = {drawing.insunits} is not m, cm or mm; "
                               "give --unit")
    names = [f"{kind} #{handle}" for kind, handle in drawing.sources]
    return list(drawing.lines), [None] * len(drawing.lines), names, unit


def read_levelling(path: str | Path, unit: str = "m") -> np.ndarray:
    """``(m, 3)`` x, y, dy [m] of a levelling CSV (module docstring)."""
    path = Path(path)
    try:
        rows = list(csv.DictReader(io.StringIO(mf.read_text(path, "levelling"), newline="")))
    except csv.Error as exc:
        raise mf.SpecError(f"levelling {path.name!r}: not a readable CSV file ({type(exc).__name__})") from None
    values = []
    for number, row in enumerate(rows, start=2):
        row = {str(k).strip(): (v or "").strip() for k, v in row.items() if k is not None}
        missing = [c for c in ("x", "y", "dy") if c not in row]
        if missing:
            raise mf.SpecError(f"levelling {path.name!r}: needs the columns x, y, dy; {', '.join(missing)} missing")
        try:
            point = [float(row["x"]), float(row["y"]), float(row["dy"])]
        except ValueError:
            raise mf.SpecError(f"levelling {path.name!r} row {number}: x, y, dy must be numbers, got "
                               f"{row['x']!r}, {row['y']!r}, {row['dy']!r}") from None
        if not all(math.isfinite(v) for v in point):
            raise mf.SpecError(f"levelling {path.name!r} row {number}: x, y, dy must be finite")
        values.append(point)
    if len(values) < 3:
        raise mf.SpecError(f"levelling {path.name!r}: {len(values)} point(s); a levelling needs at least three")
    return np.asarray(values) * UNITS[unit]
