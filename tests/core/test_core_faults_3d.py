"""Nothing lost, nothing hung on the surfaces of buildings, 3D meshes, outlines and diagnosis options (docs/faults.md,
"Buildings, meshes and outlines"): each hostile input is refused before the work, with a message naming the key,
the block, the entity or the option, never a traceback; the inputs are left as they were and nothing but ``-o``
is written.

A case is a folder of files and a command; each runs through the command line in this process (click's runner,
under ``MASONRYFW_MEMORY_LIMIT=1GiB``), a few through a real process where the peak memory or a signal is what is
looked at (tests/support.py).
"""
from __future__ import annotations

import copy
import hashlib
import json
import os
import signal
import time
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from click.testing import CliRunner
from support import Command, peak_memory

from masonryfw.cli import cli
from masonryfw.readers.spec import dump_toml, read_spec

ROOT = Path(__file__).resolve().parents[2]
HOUSE = read_spec(ROOT / "datasets" / "house-tunnel.toml")[0]
CORNER = (ROOT / "datasets" / "drawings" / "drawn-corner.toml").read_text()
GABLE = (ROOT / "datasets" / "drawings" / "gable-house.toml").read_text()
CRACKS = ROOT / "datasets" / "surveys" / "facade-1-cracks.geojson"
LIMIT = {"MASONRYFW_MEMORY_LIMIT": "1GiB"}


def digests(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.iterdir() if p.is_file()}


def refused_in_process(folder: Path, args: list[str], status: int, *words: str) -> str:
    """Run ``masonryfw ARGS`` in ``folder`` in this process: it exits ``status`` (1: the input refused; 2: a usage
    error) with ``words`` in its message and no traceback, changes no file there and writes nothing."""
    before = digests(folder)
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        done = CliRunner().invoke(cli, args, env=LIMIT)
    finally:
        os.chdir(cwd)
    assert done.exit_code == status, (done.exit_code, done.output, done.exception)
    assert isinstance(done.exception, SystemExit) and "Traceback" not in done.output, done.output
    for word in words:
        assert word in done.output, (word, done.output)
    assert digests(folder) == before, "an input was changed or an output written"
    return done.output


def house(**changes) -> dict:
    """The bundled house with ``changes`` (``"a.b.0.c"``: keys and list indices) made."""
    spec = copy.deepcopy(HOUSE)
    for path, value in changes.items():
        *keys, last = path.split(".")
        table = spec
        for key in keys:
            table = table[int(key)] if isinstance(table, list) else table[key]
        table[int(last) if isinstance(table, list) else last] = value
    return spec


# ---------------------------------------------------------------- 1. size before the work

BUILDINGS = {
    "a tiny unit": ({"building.unit": {"length": 0.0044, "height": 0.0022}}, ["building.unit", "blocks", "memory"]),
    "a unit of 1e-300 m": ({"building.unit": {"length": 1e-300, "height": 1e-300}}, ["more than 1e+308 blocks"]),
    "a tiny unit height": ({"building.unit": {"length": 0.44, "height": 2.2e-5}}, ["blocks", "memory"]),
    "a huge height": ({f"building.walls.{k}.height": 2.2e5 for k in range(4)}, ["2.2e+05 m high", "memory"]),
    "a height of 400 digits": ({"building.walls.0.height": 10**400}, ["'building.walls[0].height'", "finite"]),
    "a huge wall": ({"building.walls.0.end": [6.6e6, 0.0]}, ["6.6e+06 m in all", "memory"]),
    "tiny ground segments": ({"settlement.segment": 1e-300}, ["'settlement.segment'", "the 6.6 m ground"]),
    "tiny building segments": ({"building.segment": 1e-5}, ["'building.segment'", "finer than a hundredth"]),
    "ground blocks of no depth": ({"building.support_depth": 1e-300}, ["'building.support_depth'", "deep"]),
}


@pytest.mark.parametrize("case", sorted(BUILDINGS))
def test_a_building_too_big_or_too_fine_is_refused_by_its_keys_before_it_is_laid(tmp_path, case):
    """Counted from the keys (blocks, ground segments), not by the allocator: a tiny unit asked numpy for 35 GiB,
    1e-300 m ended in 'Maximum allowed size exceeded', a huge height or tiny segments ran on for minutes, the
    segments were checked against a hard-coded 1 m of ground."""
    changes, words = BUILDINGS[case]
    (tmp_path / "b.toml").write_text(dump_toml(house(**changes)))
    refused_in_process(tmp_path, ["build", "b.toml", "-o", "b.nc"], 1, *words)


def _outline_dxf(path: Path, scale: float = 1.0, closed: bool = True, extra=None) -> None:
    doc = ezdxf.new()
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (6000 * scale, 0), (6000 * scale, 4000 * scale), (0, 4000 * scale)], close=closed,
                       dxfattribs={"layer": "OUTLINE"})
    msp.add_lwpolyline([(1000, 1000, 0), (2000, 1000, 0), (2000, 2000, 1), (1000, 2000, 0)], format="xyb", close=True,
                       dxfattribs={"layer": "OPENINGS"})
    if extra:
        extra(msp)
    doc.saveas(path)


def _outline_spec(**replace) -> str:
    text = GABLE.replace('dxf = "gable-house.dxf"', 'dxf = "o.dxf"\ndrawing_unit = "mm"').replace("center = 9.5",
                                                                                                  "center = 5.0")
    for old, new in replace.items():
        text = text.replace(old, new)
    return text


PARAMETRIC = """title = "p"
[wall]
width = 6.0
height = 4.0
thickness = 0.2
gable_height = 6.0
[unit]
length = 0.4
height = 0.2
[material]
unit_weight = 18000.0
friction_angle = 30.0
[settlement]
profile = "tunnel"
volume_loss = 1.5
diameter = 6.0
depth = 15.0
center = 5.0
[loading]
type = "settlement"
"""

OUTLINES = {
    "a tiny unit": (1.0, _outline_spec(**{"length = 0.225": "length = 0.000225", "height = 0.075": "height = 0.000075"}),
                    ["the outline of the drawing 'o.dxf'", "blocks", "drawing_unit"]),
    "millimetres read as metres": (1.0, _outline_spec(**{'drawing_unit = "mm"': 'drawing_unit = "m"'}),
                                   ["6000 x 4000 m", "drawing_unit"]),
    "coordinates of 1e300": (1e296, _outline_spec(), ["more than 1e+308 blocks"]),
    "a huge gable": (None, PARAMETRIC.replace("gable_height = 6.0", "gable_height = 1e9"), ["spec table 'wall'", "blocks"]),
    "a huge width": (None, PARAMETRIC.replace("width = 6.0", "width = 1e9"), ["1e+09 x 6 m"]),
    "an outline of 1e300": (None, PARAMETRIC.replace("gable_height = 6.0", "outline = [[0,0],[1e300,0],[1e300,1e300],"
                                                     "[0,1e300]]"), ["more than 1e+308 blocks"]),
    "a tiny parametric unit": (None, PARAMETRIC.replace("length = 0.4", "length = 1e-6").replace(
        "height = 0.2\n[material]", "height = 1e-6\n[material]"), ["blocks", "length_unit"]),
}


@pytest.mark.parametrize("case", sorted(OUTLINES))
def test_an_outline_too_big_for_its_units_is_refused_before_it_is_laid(tmp_path, case):
    """A tiny unit, an outline in mm read as m, a huge gable or width ran on for minutes or asked for 37 GiB;
    coordinates of 1e300 ended in a GEOS or numpy traceback."""
    scale, spec, words = OUTLINES[case]
    if scale is not None:
        _outline_dxf(tmp_path / "o.dxf", scale)
    (tmp_path / "w.toml").write_text(spec)
    refused_in_process(tmp_path, ["build", "w.toml", "-o", "w.nc"], 1, *words)


def test_a_pyramid_of_too_many_sides_is_refused_before_the_solve(tmp_path):
    """100,000 sides took 3.8 GiB inside the solve, 1e30 a ValueError."""
    for sides in ("100000", "1e30"):
        refused_in_process(tmp_path, ["solve", "drawn-corner", "--plugin", "la", "--option", f"pyramid_sides={sides}",
                                      "-o", "r.nc"], 1, "'pyramid_sides'", "<= 64")


def test_ctrl_c_while_a_building_is_laid_is_answered_at_once(tmp_path):
    """The bundled house in units a sixth of its own (about 40,000 blocks) is laid for tens of seconds; SIGINT
    once the laying has begun (``-X importtime``'s line for the building module, imported when the build starts)
    ends it with 130 and one line. Measured on a quiet machine: 0.4-0.7 s (docs/faults.md)."""
    spec = house(**{"building.unit": {"length": 0.44 / 6, "height": 0.22 / 6}, "settlement.segment": 0.44 / 6})
    (tmp_path / "h.toml").write_text(dump_toml(spec))
    running = Command(["build", "h.toml", "-o", "h.nc"], tmp_path, python=("-X", "importtime"))
    running.wait_for(r"import time:.*\| +masonryfw\.builders\.building\n")
    status, stderr, answered = running.signal(signal.SIGINT)
    assert status == 130 and stderr.rstrip().endswith("interrupted: nothing written"), stderr[-2000:]
    assert answered < 10, f"answered {answered:.1f} s after the signal"
    assert not (tmp_path / "h.nc").exists()


# ---------------------------------------------------------------- 2. 3D meshes that are not masonry

def _box(name: str, low, high, first: int) -> list[str]:
    (x0, y0, z0), (x1, y1, z1) = low, high
    corners = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1),
               (x0, y1, z1)]
    faces = [(1, 4, 3, 2), (5, 6, 7, 8), (1, 2, 6, 5), (2, 3, 7, 6), (3, 4, 8, 7), (4, 1, 5, 8)]
    return ([f"o {name}"] if name else []) + [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in corners] + \
        ["f " + " ".join(str(first + i) for i in face) for face in faces]


#: A short wall of two courses of 0.24 x 0.12 x 0.12 m bricks, running bond.
ROW = [((0.24 * i, 0, 0), (0.24 * (i + 1), 0.12, 0.12)) for i in range(6)] + \
      [((0.24 * i + 0.12, 0, 0.12), (0.24 * (i + 1) + 0.12, 0.12, 0.24)) for i in range(5)]


def _mesh(boxes, one_object_from: int | None = None, scale: float = 1.0) -> str:
    lines = []
    for k, (low, high) in enumerate(boxes):
        name = "" if one_object_from is not None and k > one_object_from else f"brick {k}"
        lines += _box(name, np.multiply(low, scale), np.multiply(high, scale), 8 * k)
    return "\n".join(lines) + "\n"


def _mesh_spec(mesh: str = "m.obj", snap: float | None = None) -> str:
    text = CORNER.replace('mesh = "drawn-corner.obj"', f'mesh = "{mesh}"').replace(
        '[geometry.layers]\nLINTEL = "lintel"\n', "")
    return text if snap is None else text.replace('drawing_unit = "m"', f'drawing_unit = "m"\nsnap_tolerance = {snap}')


MESHES = {
    "the same block twice": (_mesh(ROW + [ROW[3]]), ["'brick 3' (line 55)", "'brick 11'", "the same block drawn twice"]),
    "two blocks that overlap": (_mesh(ROW + [((0.30, 0, 0), (0.54, 0.12, 0.12))]), ["laid into one another",
                                                                                     "m3 in common"]),
    "a block inside another": (_mesh(ROW + [((0.26, 0.01, 0.01), (0.40, 0.1, 0.1))]), ["one inside the other"]),
    "a block floating apart": (_mesh(ROW + [((5, 5, 5), (5.24, 5.12, 5.12))]), ["'brick 11'", "touches nothing",
                                                                                "would fall"]),
    "a block on a floating block": (_mesh(ROW + [((5, 5, 5), (5.24, 5.12, 5.12)), ((5, 5, 5.12), (5.24, 5.12, 5.24))]),
                                    ["'brick 11'", "'brick 12'", "touches only blocks that do not reach the ground"]),
    "an object of two solids": (_mesh(ROW[:10] + [ROW[10], ((3.0, 0, 0), (3.24, 0.12, 0.12))], one_object_from=10),
                                ["'brick 10'", "is 2 separate solids", "its own object"]),
    "coordinates near 1e308": (_mesh(ROW, scale=1e306), ["beyond 1e+10 drawing units"]),
}


@pytest.mark.parametrize("case", sorted(MESHES))
def test_a_mesh_that_is_not_masonry_is_refused_naming_its_blocks(tmp_path, case):
    """Two identical blocks, two that overlap, one inside another, a block floating apart, an object of two solids
    were all built with exit 0; coordinates near 1e308 ended in the snapping's overflow traceback."""
    mesh, words = MESHES[case]
    (tmp_path / "m.obj").write_text(mesh)
    (tmp_path / "w.toml").write_text(_mesh_spec())
    refused_in_process(tmp_path, ["build", "w.toml", "-o", "w.nc"], 1, *words)


def test_a_plain_mesh_of_the_same_bricks_builds(tmp_path):
    """The cases above are refused for what was done to them: the wall itself is masonry."""
    (tmp_path / "m.obj").write_text(_mesh(ROW))
    (tmp_path / "w.toml").write_text(_mesh_spec())
    done = CliRunner().invoke(cli, ["build", str(tmp_path / "w.toml"), "-o", str(tmp_path / "w.nc")])
    assert done.exit_code == 0 and "wrote" in done.output, done.output


def test_a_mesh_path_that_is_not_a_file_says_what_it_is(tmp_path):
    (tmp_path / "gone.obj").symlink_to(tmp_path / "nowhere" / "x.obj")
    (tmp_path / "dir.obj").mkdir()
    (tmp_path / "a.toml").write_text(_mesh_spec("gone.obj"))
    (tmp_path / "b.toml").write_text(_mesh_spec("dir.obj"))
    refused_in_process(tmp_path, ["build", "a.toml", "-o", "a.nc"], 1, "'geometry.mesh' = 'gone.obj'",
                       "no such file (a broken symbolic link)")
    refused_in_process(tmp_path, ["build", "b.toml", "-o", "b.nc"], 1, "'geometry.mesh' = 'dir.obj'", "is a directory")


def test_a_snap_tolerance_as_large_as_the_drawing_is_refused_for_what_it_is(tmp_path):
    """A snap of 1e300 was blamed on a face ('fewer than three distinct vertices')."""
    (tmp_path / "m.obj").write_text(_mesh(ROW))
    (tmp_path / "w.toml").write_text(_mesh_spec(snap=1e300))
    refused_in_process(tmp_path, ["build", "w.toml", "-o", "w.nc"], 1, "'geometry.snap_tolerance' = 1e+300",
                       "of the drawing's size")


def test_a_mesh_too_big_for_the_memory_is_refused_by_its_faces_before_it_is_read(tmp_path):
    """A 20,000-block mesh ended in 'MemoryError: std::bad_alloc'; its faces are counted before they are read
    (3,000 blocks under a limit of 10 MiB here, to keep the test short)."""
    bricks = [((0.24 * (i % 50), 0, 0.12 * (i // 50)), (0.24 * (i % 50 + 1), 0.12, 0.12 * (i // 50 + 1)))
              for i in range(3000)]
    (tmp_path / "m.obj").write_text(_mesh(bricks))
    (tmp_path / "w.toml").write_text(_mesh_spec())
    before = digests(tmp_path)
    done = CliRunner().invoke(cli, ["build", str(tmp_path / "w.toml"), "-o", str(tmp_path / "w.nc")],
                              env={"MASONRYFW_MEMORY_LIMIT": "10MiB"})
    assert done.exit_code == 1 and "18,000 faces, about 3,000 blocks" in done.output, done.output
    assert digests(tmp_path) == before


# ---------------------------------------------------------------- 3. outlines and their heads

HEADS = {
    "a bearing of 1e300": ({"bearing = 0.15": "bearing = 1e300"}, ["'heads.bearing' = 1e+300", "more than the wall"]),
    "a fractional head": ({"courses = 2": "courses = 1.5"}, ["'heads.courses' = 1.5", "whole number"]),
    "an absurd head": ({"courses = 2": "courses = 1000000000000"}, ["'heads.courses' = 1000000000000", "deeper"]),
    "a tiny chord tolerance": ({'drawing_unit = "mm"': 'drawing_unit = "mm"\nchord_tolerance = 1e-300'},
                               ["chord_tolerance = 1e-300", "millions of chords"]),
}


@pytest.mark.parametrize("case", sorted(HEADS))
def test_an_outline_key_out_of_reason_is_refused_naming_it(tmp_path, case):
    """A huge bearing ended in shapely's 'linearrings' ValueError or a GEOS NaN/Inf traceback, a fractional head
    was taken as its integer part, an absurd one passed with a numpy warning, a tiny chord tolerance ended in
    ezdxf's 'Bezier4P flattening error' (a RecursionError)."""
    replace, words = HEADS[case]
    _outline_dxf(tmp_path / "o.dxf")
    (tmp_path / "w.toml").write_text(_outline_spec(**replace))
    refused_in_process(tmp_path, ["build", "w.toml", "-o", "w.nc"], 1, *words)


def test_an_outline_drawn_open_or_with_loose_arcs_is_refused_naming_the_entity(tmp_path):
    """An outline that was not closed was closed silently by its last edge; an ARC on the openings layer was
    left out, so the opening vanished."""
    (tmp_path / "w.toml").write_text(_outline_spec())
    _outline_dxf(tmp_path / "o.dxf", closed=False)
    refused_in_process(tmp_path, ["build", "w.toml", "-o", "w.nc"], 1, "LWPOLYLINE", "on layer OUTLINE", "open")
    _outline_dxf(tmp_path / "o.dxf", extra=lambda msp: msp.add_arc((4000, 2500), 400, 0, 180,
                                                                   dxfattribs={"layer": "OPENINGS"}))
    refused_in_process(tmp_path, ["build", "w.toml", "-o", "w.nc"], 1, "ARC #", "on layer OPENINGS",
                       "one closed polyline")


def test_a_round_window_drawn_as_a_circle_is_an_opening_and_the_default_chord_is_said(tmp_path):
    """A CIRCLE on the openings layer (an oculus) is an opening (it was left out); the arcs made chords by the
    default tolerance are said in the laying notes (they passed silently)."""
    import masonryfw as mf

    _outline_dxf(tmp_path / "o.dxf", extra=lambda msp: msp.add_circle((4000, 2700), 300,
                                                                      dxfattribs={"layer": "OPENINGS"}))
    (tmp_path / "w.toml").write_text(_outline_spec())
    model = mf.build(tmp_path / "w.toml", validate=False)
    assert "made chords within 1 mm (the default; geometry.chord_tolerance sets it)" in model.attrs["laying_notes"]
    assert not masonry_at(model, 4.0, 2.7), "a block covers the oculus' centre"


def masonry_at(model, x: float, y: float) -> bool:
    """Whether a masonry block of a 2D ``model`` covers the point (x, y)."""
    import shapely

    import masonryfw.plugin_api as mfp

    counts = model.block_node_count.values
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    rings = [np.c_[model.node_x.values[a:a + n], model.node_y.values[a:a + n]] for a, n in zip(starts, counts)]
    return any(shapely.Polygon(rings[b]).contains(shapely.Point(x, y))
               for b in np.flatnonzero(mfp.masonry_blocks(model.block_role.values)))


def test_geojson_holes_outside_or_across_the_outline_are_refused(tmp_path):
    outline = [[0, 0], [6000, 0], [6000, 4000], [0, 4000], [0, 0]]
    spec = _outline_spec(**{'dxf = "o.dxf"': 'polygons = "o.geojson"'})
    (tmp_path / "w.toml").write_text(spec)
    for hole, where in (([[7000, 1000], [8000, 1000], [8000, 2000], [7000, 2000], [7000, 1000]], "x 7..8 m"),
                        ([[5000, 1000], [7000, 1000], [7000, 2000], [5000, 2000], [5000, 1000]], "x 5..7 m")):
        feature = {"type": "Feature", "properties": {"layer": "OUTLINE"},
                   "geometry": {"type": "Polygon", "coordinates": [outline, hole]}}
        (tmp_path / "o.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
        refused_in_process(tmp_path, ["build", "w.toml", "-o", "w.nc"], 1, "feature 0 hole 0", where,
                           "not inside the wall's outline")


# ---------------------------------------------------------------- 4. diagnosis options, 5. runs and images

OPTIONS = {
    "--scheduler notanaddress": (["--scheduler", "notanaddress"], ["'notanaddress' is not a scheduler's address"]),
    "--scheduler http://": (["--scheduler", "http://localhost:1"], ["tcp://host:port"]),
    "--levelling-sigma nan": (["--levelling-sigma", "nan"], ["'--levelling-sigma'", "a finite number > 0"]),
    "--levelling-sigma inf": (["--levelling-sigma", "inf"], ["'--levelling-sigma'", "a finite number > 0"]),
    "--levelling-sigma 1e308": (["--levelling-sigma", "1e308"], ["'--levelling-sigma'", "<= 1000"]),
    "--budget nan": (["--budget", "nan"], ["'--budget'", "a finite number >= 0"]),
}


@pytest.mark.parametrize("case", sorted(OPTIONS))
def test_a_diagnosis_option_out_of_reason_is_a_usage_error(tmp_path, case):
    """Tracebacks from distributed for an address that is none; NaN scores reported with exit 0."""
    extra, words = OPTIONS[case]
    refused_in_process(tmp_path, ["diagnose", "facade-1", "--cracks", str(CRACKS), "--rerank", "0", "--no-progress",
                                  *extra, "-o", "d.nc"], 2, *words)


@pytest.mark.parametrize("value", ["-1", "0", "nan", "inf", "1e6"])
def test_capacity_names_the_volume_loss_it_refuses(tmp_path, value):
    """``--volume-loss -1 | 0 | nan | inf`` were reported as '--settlement ...', and 1e6 % started a run of 785 h."""
    refused_in_process(tmp_path, ["capacity", "tunnel-facade", "--volume-loss", value, "-o", "c.nc"], 2,
                       "'--volume-loss'", "a finite number > 0 and <= 100")


def test_a_run_estimated_too_long_is_refused_however_its_end_is_given(tmp_path):
    """``capacity --settlement 1e3`` (and so any run whose settlement was given) skipped the guard of ``solve``."""
    refused_in_process(tmp_path, ["capacity", "tunnel-facade", "--settlement", "1e3", "-o", "c.nc"], 1,
                       "fdem: expect about", "h", "--force")
    refused_in_process(tmp_path, ["solve", "tunnel-facade", "--plugin", "fdem", "--option", "settlement=1e3",
                                  "-o", "c.nc"], 1, "over the 12 h a run starts without asking")


def test_capacity_with_a_solver_that_has_no_history_is_refused_before_the_solve(tmp_path):
    """``capacity --plugin la`` solved the house for 17 s and then refused."""
    started = time.process_time()
    refused_in_process(tmp_path, ["capacity", "house-tunnel", "--plugin", "la", "-o", "c.nc"], 1,
                       "la: its result has no history", "fdem", "la-incremental")
    assert time.process_time() - started < 5  # CPU seconds of this process: nothing was solved


def test_a_figure_too_large_to_draw_is_refused_before_it_is_drawn(tmp_path):
    """``--size 54x54 --dpi 1200`` ended in bad_alloc, ``20x20`` took 2.3 GiB: the image buffer is estimated."""
    refused_in_process(tmp_path, ["plot", "panel-1", "--kind", "model", "--size", "20x20", "--dpi", "1200",
                                  "-o", "p.png"], 1, "24,000 x 24,000 pixels", "memory", ".svg")
    refused_in_process(tmp_path, ["plot", "panel-1", "--kind", "model", "--size", "60x60", "--dpi", "1200",
                                  "-o", "p.png"], 1, "at most 65,535 a side")


def test_an_estimate_of_an_absurd_run_is_said_in_a_few_characters(tmp_path):
    """``la-incremental settlement=1e300`` printed an 884-character number."""
    message = refused_in_process(tmp_path, ["solve", "panel-1", "--plugin", "la-incremental", "--option",
                                            "settlement=1e300", "-o", "r.nc"], 1, "la-incremental")
    assert max(map(len, message.split())) < 40, message


# ---------------------------------------------------------------- 6. messages, 7. plausibility

def test_diagnose_on_a_3d_spec_says_it_diagnoses_walls(tmp_path):
    """It said "unknown spec key 'loading'" of a building spec or a drawn 3D spec given by its file."""
    for spec in (ROOT / "datasets" / "house-tunnel.toml", ROOT / "datasets" / "drawings" / "drawn-corner.toml"):
        refused_in_process(tmp_path, ["diagnose", str(spec), "--cracks", str(CRACKS), "--no-progress", "-o", "d.nc"],
                           1, "the spec is 3D", "masonryfw diagnose handles 2D walls")


def test_an_absurd_floor_load_is_warned_naming_its_key():
    import warnings

    import masonryfw as mf

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mf.build(house(**{"building.floors.0.load": 1e300}), validate=False)
    said = [str(w.message) for w in caught if issubclass(w.category, mf.PlausibilityWarning)]
    assert any("building.floors[0].load = 1e+300 N/m" in s for s in said), said
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mf.build(house(**{"building.floors.0.load": 5.5}), validate=False)  # kN/m typed as N/m
    assert any("probably kN/m were meant, in N/m: 5500" in str(w.message) for w in caught)


# ---------------------------------------------------------------- whole processes: memory and no hang

@pytest.mark.parametrize("args, spec", [
    (["build", "b.toml", "-o", "b.nc"], "tiny unit"),
    (["build", "w.toml", "-o", "w.nc"], "outline in mm read as m"),
])
def test_refused_before_the_work_means_little_memory_and_little_time(tmp_path, args, spec):
    """Under MASONRYFW_MEMORY_LIMIT=1GiB, the refusals above take what the interpreter and the imports take."""
    (tmp_path / "b.toml").write_text(dump_toml(house(**{"building.unit": {"length": 0.0044, "height": 0.0022}})))
    _outline_dxf(tmp_path / "o.dxf")
    (tmp_path / "w.toml").write_text(_outline_spec(**{'drawing_unit = "mm"': 'drawing_unit = "m"'}))
    done, peak = peak_memory(args, tmp_path, env=LIMIT)
    assert done.returncode == 1 and "Traceback" not in done.stderr and "memory" in done.stderr, done.stderr
    assert peak < 400 * 2**20, f"{peak / 2**20:.0f} MiB"

