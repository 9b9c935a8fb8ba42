"""Benchmark of importing drawings: read + clean + interfaces + check, against the number of blocks.

Running-bond walls of 200 x 100 mm units drawn as DXF (and, at the largest size, as CSV and GeoJSON
too), with a share of the units merged in pairs into stepped non-convex blocks (the overlap test
then works on their convex pieces). Each size: the median of 3 builds, and its parts (reading and
cleaning the drawing alone; the whole ``mf.build``: that, interfaces, loads, ``check``).
Run from the benchmarks folder: ``python bench_import.py``. Writes the ``import`` section of docs/benchmarks.md.
"""
from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from _report import command_line, write_section

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.datasets.drawings import generate

SIZES = ((20, 25), (40, 50), (80, 80))  # (courses, units per course): ~500, ~2,000, ~5,000 blocks merged


def wall(courses: int, units: int, merged: bool):
    """The stepped-wall generator at another size (its rules: generate.stepped_wall)."""
    saved = dict(generate.STEPPED)
    generate.STEPPED.update(units=units, courses=courses, settling_from=units * 200.0 * 0.6)
    try:
        return generate.stepped_wall(merged)
    finally:
        generate.STEPPED.update(saved)


def spec(path: Path) -> dict:
    key = "dxf" if path.suffix == ".dxf" else "polygons"
    return {"title": "bench", "geometry": {key: str(path), "drawing_unit": "mm"}, "wall": {"thickness": 0.1},
            "material": {"unit_weight": 18000.0, "friction_angle": 30.0},
            "supports": {"base": {"kind": "fixed", "layer": "BASE"}, "settling": {"kind": "moving", "layer": "SETTLE"}},
            "loading": {"type": "settlement"}}


def timed(function, repeat: int = 3) -> tuple[float, object]:
    times, value = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        value = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), value


def row(folder: Path, courses: int, units: int, merged: bool, kind: str = "dxf") -> str:
    polygons, layers = wall(courses, units, merged)
    path = folder / f"wall-{courses}-{units}-{int(merged)}.{kind}"
    if kind == "dxf":
        generate.write_dxf(path, polygons, layers)
    elif kind == "geojson":
        generate.write_geojson(path, polygons, layers)
    else:
        with open(path, "w") as handle:
            handle.write("block,x,y,layer\n")
            for i, (polygon, layer) in enumerate(zip(polygons, layers)):
                handle.writelines(f"{i},{x},{y},{layer}\n" for x, y in polygon)
    read, drawing = timed(lambda: mfp.read_drawing(path, "mm"))
    total, model = timed(lambda: mf.build(spec(path)))
    non_convex = int((~mfp.convex_blocks(model.node_x.values, model.node_y.values,
                                        model.block_node_count.values)).sum())
    return f"| {kind} | {model.sizes['block']} | {non_convex} | {model.sizes['interface']} | {read:.2f} | {total:.2f} |"


def main() -> None:
    load = os.getloadavg()[0]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for courses, units in SIZES:
            rows.append(row(folder, courses, units, merged=True))
        courses, units = SIZES[-1]
        rows.append(row(folder, courses, units, merged=False))
        rows += [row(folder, courses, units, True, kind) for kind in ("csv", "geojson")]
        for line in rows:
            print(line, file=sys.stderr)
    body = (
        f"`mf.build` of a `[geometry]` spec: read and clean the drawing (ezdxf, snapping, simplification, "
        f"validity through shapely), then interfaces, loads and `check` (overlaps through convex pieces). "
        f"Running-bond walls of 200 x 100 mm units, a sixth of them merged in pairs into stepped "
        f"non-convex blocks (the last DXF row: all rectangles). Medians of 3, load average {load:.2f} at the "
        "start. Target: < 5 s at 5,000 blocks.\n\n"
        "| drawing | blocks | non-convex | interfaces | read + clean [s] | build + check, total [s] |\n"
        "|---|---:|---:|---:|---:|---:|\n" + "\n".join(rows)
    )
    write_section("import", "Import: drawings to checked models", body)


if __name__ == "__main__":
    command_line(__doc__).parse_args()
    main()
