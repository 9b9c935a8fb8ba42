"""Nothing lost on the surfaces that came with drawings, tunnels and surveys (docs/faults.md): locks that are not
locks, outputs onto the files a command reads, inputs that would take the machine's memory or time, interrupted
verifications, markup in a report, and hostile values that used to end in a traceback or in silent garbage.

Each test runs ``python -m masonryfw`` as a user would (tests/support.py) over a class of inputs, and looks from
outside: the exit status, the message, the files left, the memory taken.
"""
from __future__ import annotations

import hashlib
import html.parser
import json
import os
import re
import signal
import time
from pathlib import Path

import numpy as np
import pytest
from support import Command, cli, hidden, peak_memory, refused, tilted_drawing_spec

import masonryfw as mf
import masonryfw.plugin_api as mfp

DATASETS = Path(mf.bundled_spec_path("panel-1")).parent  # the installed package's bundled cases and drawings
SURVEYS = Path(__file__).resolve().parents[2] / "datasets" / "surveys"  # the clone's: surveys are not installed
CRACKS = (SURVEYS / "facade-1-cracks.geojson").read_text()
LEVELLING = (SURVEYS / "facade-1-levelling.csv").read_text()
MB = 2**20
WALL = """title = "w"
[wall]
width = 1.1
height = 0.6
thickness = 0.1
[unit]
length = 0.1
height = 0.05
[material]
unit_weight = 18000.0
friction_angle = 30.0
"""
TUNNEL = WALL + """[settlement]
profile = "tunnel"
volume_loss = {volume_loss}
diameter = {diameter}
depth = {depth}
center = {center}
segment = {segment}
[loading]
type = "settlement"
"""


def tunnel(volume_loss=1.0, diameter=6.0, depth=15.0, segment=0.05, center=1.5) -> str:
    return TUNNEL.format(volume_loss=volume_loss, diameter=diameter, depth=depth, segment=segment, center=center)


def digests(folder: Path) -> dict[str, str]:
    """Every regular file under ``folder`` (links not followed) and the hash of its bytes."""
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and not p.is_symlink()}


def _line(coordinates, properties=None) -> str:
    feature = {"type": "Feature", "properties": properties or {},
               "geometry": {"type": "LineString", "coordinates": coordinates}}
    return json.dumps({"type": "FeatureCollection", "features": [feature]})


# ---------------------------------------------------------------- locks that are not locks

def _link_to_model(folder):
    os.symlink("m.nc", folder / ".out.nc.lock")


def _link_to_other(folder):
    (folder / "precious.txt").write_text("precious")
    os.symlink("precious.txt", folder / ".out.nc.lock")


def _dangling_link(folder):
    os.symlink("nowhere.txt", folder / ".out.nc.lock")


def _fifo(folder):
    os.mkfifo(folder / ".out.nc.lock")


def _hard_link(folder):
    (folder / "precious.txt").write_text("precious")
    os.link(folder / "precious.txt", folder / ".out.nc.lock")


def _notes(folder):
    (folder / ".out.nc.lock").write_text("my notes about the wall")


def _folder(folder):
    (folder / ".out.nc.lock").mkdir()


@pytest.mark.parametrize("plant, kind", [
    (_link_to_model, "a symbolic link"), (_link_to_other, "a symbolic link"), (_dangling_link, "a symbolic link"),
    (_fifo, "a FIFO"), (_hard_link, "a file with 2 names"), (_notes, "not a lock"), (_folder, "a directory")])
def test_a_lock_file_that_is_not_a_lock_of_ours_is_refused_and_nothing_is_written_through_it(tmp_path, plant, kind):
    """A symbolic link planted as the lock was followed: the pid was written into the model it pointed at, or
    into any file, exit 0. Now only a regular file of ours holding a pid is a lock; anything else is named."""
    mf.save(mf.open_model("panel-1"), tmp_path / "m.nc")
    plant(tmp_path)
    before = digests(tmp_path)
    refused(cli(["solve", "m.nc", "--plugin", "la", "-o", "out.nc"], tmp_path, timeout=60),
            "its lock file", ".out.nc.lock", kind, "remove it if no masonryfw process is writing there")
    assert digests(tmp_path) == before and not (tmp_path / "out.nc").exists()


def test_a_stale_lock_of_ours_is_reused(tmp_path):
    """A process killed outright leaves its lock file (its pid, unlocked): the next command takes it."""
    (tmp_path / ".out.nc.lock").write_text("999999\n")
    done = cli(["solve", "panel-1", "--plugin", "la", "-o", "out.nc"], tmp_path, timeout=60)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out.nc").exists() and hidden(tmp_path) == []


# ---------------------------------------------------------------- outputs onto what a command reads

DRAWN = tilted_drawing_spec("wall.dxf", unit="mm", thickness=0.3, unit_weight=20000.0, title="d")


def _drawn_folder(folder):
    (folder / "w.toml").write_text(DRAWN)
    (folder / "wall.dxf").write_bytes((DATASETS / "drawings" / "lact3-wall.dxf").read_bytes())
    (folder / "c.geojson").write_text(CRACKS)
    (folder / "l.csv").write_text(LEVELLING)
    (folder / "s.toml").write_text((DATASETS / "drawings" / "stepped-units.toml").read_text())
    (folder / "stepped-units.geojson").write_text((DATASETS / "drawings" / "stepped-units.geojson").read_text())
    for name in ("gable-house.toml", "gable-house.dxf", "drawn-corner.toml", "drawn-corner.obj"):
        (folder / name).write_bytes((DATASETS / "drawings" / name).read_bytes())
    os.symlink("wall.dxf", folder / "alias.nc")
    os.link(folder / "c.geojson", folder / "twin.nc")


@pytest.mark.parametrize("args, shown", [
    (["build", "w.toml", "-o", "wall.dxf"], "wall.dxf"),
    (["solve", "w.toml", "--plugin", "la", "-o", "wall.dxf"], "wall.dxf"),
    (["build", "w.toml", "-o", "alias.nc"], "wall.dxf"),
    (["diagnose", "facade-1", "--cracks", "c.geojson", "-o", "c.geojson"], "c.geojson"),
    (["diagnose", "facade-1", "--cracks", "c.geojson", "-o", "twin.nc"], "c.geojson"),
    (["diagnose", "facade-1", "--cracks", "c.geojson", "--levelling", "l.csv", "-o", "l.csv"], "l.csv"),
    (["diagnose", "s.toml", "--cracks", "c.geojson", "-o", "stepped-units.geojson"], "stepped-units.geojson"),
    (["build", "s.toml", "-o", "stepped-units.geojson"], "stepped-units.geojson"),
    (["build", "gable-house.toml", "-o", "gable-house.dxf"], "gable-house.dxf"),
    (["solve", "gable-house.toml", "--plugin", "la", "-o", "gable-house.dxf"], "gable-house.dxf"),
    (["build", "drawn-corner.toml", "-o", "drawn-corner.obj"], "drawn-corner.obj"),
    (["solve", "drawn-corner.toml", "--plugin", "la", "-o", "drawn-corner.obj"], "drawn-corner.obj"),
], ids=["build onto its drawing", "solve onto its drawing", "through a link", "onto the crack map",
        "through a hard link", "onto the levelling", "onto a drawn spec's GeoJSON", "build onto its GeoJSON",
        "build onto an outline's DXF", "solve onto an outline's DXF", "build onto a 3D drawing's OBJ",
        "solve onto a 3D drawing's OBJ"])
def test_no_output_is_written_onto_a_file_the_command_reads(tmp_path, args, shown):
    """``-o wall.dxf`` of a drawn spec replaced the drawing with a netCDF file, exit 0. Every file a command
    reads (the spec, its drawing, the crack map, the levelling) is refused as an output, through links too."""
    _drawn_folder(tmp_path)
    before = digests(tmp_path)
    refused(cli(args, tmp_path), "refusing to overwrite", shown)
    assert digests(tmp_path) == before


@pytest.mark.parametrize("spec, drawing", [
    ("w.toml", "wall.dxf"), ("s.toml", "stepped-units.geojson"), ("gable-house.toml", "gable-house.dxf"),
    ("drawn-corner.toml", "drawn-corner.obj")], ids=["drawn DXF", "drawn GeoJSON", "outline DXF", "3D OBJ"])
def test_every_kind_of_spec_names_its_drawing_before_it_is_built(tmp_path, monkeypatch, spec, drawing):
    """The files a command checks its output against come from the kinds' one table, without building: an outline
    spec's DXF and a 3D drawing's OBJ were missed, and ``-o`` onto them was refused only after the build."""
    import dataclasses

    import masonryfw.builders.kinds as kinds

    _drawn_folder(tmp_path)  # nothing may be built to name the files
    monkeypatch.setattr(kinds, "SPEC_KINDS", tuple(dataclasses.replace(k, builds=None) for k in kinds.SPEC_KINDS))
    assert mfp.input_files(tmp_path / spec) == [tmp_path / spec, tmp_path / drawing]


# ---------------------------------------------------------------- memory and time, estimated first

@pytest.mark.parametrize("segment, words", [
    ("1e-5", ["110,000 segments", "give at least 0.001 m"]),
    ("1e-9", ["1,100,000,000 segments"]),
    ("2.0", ["would be 1 piece", "give at most 0.55 m"]),
])
def test_a_tunnel_segment_that_no_ground_needs_is_refused_by_its_key(tmp_path, segment, words):
    """``segment = 1e-5`` under a 1.1 m wall took 23.3 GB and was killed; ``1e-9`` ended in a traceback; ``2`` made
    one ground piece moving the wall as one body."""
    (tmp_path / "t.toml").write_text(tunnel(segment=segment))
    done, peak = peak_memory(["build", "t.toml", "-o", "t.nc"], tmp_path, env={"MASONRYFW_MEMORY_LIMIT": "1GiB"})
    refused(done, "spec key 'settlement.segment'", *words)
    assert peak < 400 * MB


@pytest.mark.parametrize("args, words", [
    (["--segment", "1e-4"], ["--segment = 0.0001 m", "15,000 segments", "give at least 0.001 m"]),
    (["--segment", "1e-3"], ["1,100 pieces", "about 622,648 scenarios", "over the 20,000 a search tries",
                             "--segment of at least"]),
    (["--segment", "1e-300"], ["1.5e+300 segments"]),
    (["--segment", "2"], ["would be 1 piece"]),
])
def test_a_diagnosis_counts_its_scenarios_before_it_searches_and_refuses_what_no_search_needs(tmp_path, args, words):
    """``--segment 1e-4`` took 12.1 GB under a 1 GiB limit; ``1e-3`` began 600,000 scenarios without a word."""
    (tmp_path / "c.geojson").write_text(CRACKS)
    done, peak = peak_memory(["diagnose", "facade-1", "--cracks", "c.geojson", *args], tmp_path,
                             env={"MASONRYFW_MEMORY_LIMIT": "1GiB"})
    refused(done, *words)
    assert peak < 600 * MB
    advised = re.search(r"--segment of at least ([0-9.e-]+) m", done.stderr)
    if advised:  # the advice holds: that segment's search is within the limit
        from masonryfw_diagnose.diagnosis import MAX_SCENARIOS, prepare
        from masonryfw_diagnose.survey import read_cracks

        diagnosis = prepare(mf.open_model("facade-1"), read_cracks(tmp_path / "c.geojson"),
                            segment=float(advised.group(1)))
        assert MAX_SCENARIOS * 0.8 < len(diagnosis.tables) <= MAX_SCENARIOS


def test_a_diagnosis_says_its_scenario_count_and_time_before_it_starts(tmp_path):
    (tmp_path / "c.geojson").write_text(CRACKS)
    done = cli(["diagnose", "facade-1", "--cracks", "c.geojson", "--profiles", "step", "--no-progress", "--rerank",
                "0"], tmp_path)
    assert done.returncode == 0, done.stderr
    said = re.match(r"diagnose: (\d+) scenarios \(step\) with la on (\d+) ground pieces; expect about \d", done.stderr)
    pieces = int(said.group(2))
    assert int(said.group(1)) == pieces * (pieces + 1) // 2 - 1  # every run of pieces but the whole base


@pytest.mark.parametrize("name, text, words", [
    ("l.csv", "x,y,dy\n" + "".join(f"{k * 1.5e-6:.7f},0.125,-0.0001\n" for k in range(1_000_000)),
     ["levelling 'l.csv'", "over 10,000 rows"]),
    ("c.csv", "crack,x,y\n" + "".join(f"c{k // 2},{0.1 + 1e-6 * k:.7f},0.2\n" for k in range(400_000)),
     ["crack map 'c.csv'", "over 200,000 rows"]),
    ("c.geojson", json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "LineString", "coordinates": [[x, 0.2], [x, 0.3]]}}
        for x in np.linspace(0.1, 1.4, 30_000).tolist()]}), ["crack map 'c.geojson'", "30,000 lines"]),
], ids=["levelling of a million rows", "crack map of 400,000 points", "crack map of 30,000 lines"])
def test_a_survey_too_big_to_be_one_is_refused_at_once_under_a_memory_limit(tmp_path, name, text, words):
    """A levelling of 1e6 rows took 8 GB and 40 s a scenario; a map of 300,000 lines 2.35 GB under a 1 GiB limit."""
    (tmp_path / name).write_text(text)
    (tmp_path / "c.geojson").write_text(CRACKS) if name == "l.csv" else None
    survey = ["--cracks", "c.geojson", "--levelling", name] if name == "l.csv" else ["--cracks", name]
    started = time.monotonic()
    done, peak = peak_memory(["diagnose", "facade-1", *survey], tmp_path, env={"MASONRYFW_MEMORY_LIMIT": "1GiB"})
    refused(done, *words)
    assert peak < 600 * MB and time.monotonic() - started < 60


def test_a_model_of_a_million_blocks_is_refused_by_its_block_count_before_it_is_read(tmp_path):
    """A model of 1e6 blocks under a 1 GiB limit was refused only after 47 s and 2.9 GB: its checks take about
    3 kB a block, counted from the file's header now."""
    import netCDF4

    with netCDF4.Dataset(tmp_path / "m.nc", "w") as file:
        file.createDimension("block", 1_000_000)
        file.createDimension("node", 4_000_000)
        for name, dim in (("node_x", "node"), ("node_y", "node"), ("block_thickness", "block")):
            file.createVariable(name, "f8", (dim,), zlib=True, complevel=1)[:] = 0.0
        file.masonryfw_format = "model"
    done, peak = peak_memory(["check", "m.nc"], tmp_path, env={"MASONRYFW_MEMORY_LIMIT": "1GiB"})
    refused(done, "m.nc", "checking its 1,000,000 blocks", "MASONRYFW_MEMORY_LIMIT")
    assert peak < 300 * MB


def test_implausible_tunnel_values_warn_and_a_run_of_hundreds_of_hours_asks_first(tmp_path):
    """``volume_loss = 1e6`` built without a word, and fdem started a run of 785 hours."""
    (tmp_path / "t.toml").write_text(tunnel(volume_loss=1e6))
    built = cli(["build", "t.toml", "-o", "t.nc"], tmp_path)
    assert built.returncode == 0
    assert "warning: settlement.volume_loss = 1e+06 %: tunnels lose 0.1-5 %" in built.stderr
    assert "is more than the wall's height (0.6 m)" in built.stderr
    refused(cli(["solve", "t.nc", "--plugin", "fdem", "-o", "r.nc"], tmp_path), "over the 12 h a run starts",
            "--force", "--option settlement=")
    assert not (tmp_path / "r.nc").exists()
    (tmp_path / "f.toml").write_text(tunnel(volume_loss=0.01))
    assert "probably a fraction was given for a percentage: 1" in cli(["build", "f.toml", "-o", "f.nc"], tmp_path).stderr


# ---------------------------------------------------------------- interrupts honoured

def test_an_interrupted_verification_is_not_a_verification(tmp_path):
    """``diagnose --verify fdem`` interrupted exited 0 and stored the cut-short fdem numbers as verified."""
    (tmp_path / "c.geojson").write_text(CRACKS)
    running = Command(["diagnose", "facade-1", "--cracks", "c.geojson", "--profiles", "step", "--verify", "fdem",
                       "--rerank", "0", "-o", "d.nc"], tmp_path)
    try:
        running.wait_for(r"verify: .* with fdem")
        status, stderr, _ = running.signal(signal.SIGINT)
    finally:
        running.stop()
    assert status == 130 and "Traceback" not in stderr, stderr[-2000:]
    assert "the verification with fdem was interrupted: 0 candidate(s) verified" in stderr
    assert "the run cut short is not kept as a verification" in stderr
    diagnosis = mf.open_dataset(tmp_path / "d.nc")
    verified = [name for name in diagnosis.data_vars if name.startswith("candidate_verified")]
    assert all(np.isnan(diagnosis[name].values).all() for name in verified)


# ---------------------------------------------------------------- the report quotes, never runs

MARKUP = '<img src=x onerror=alert(1)><script>alert(2)</script>'


class _Tags(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.found = []

    def handle_starttag(self, tag, attrs):
        self.found.append((tag, dict(attrs)))


def test_markup_in_every_string_a_user_controls_is_quoted_as_text_in_the_report(tmp_path):
    """The crack map's path in the diagnosis's history line and its ``solver`` attribute became live HTML."""
    crack_map = MARKUP.split("<script>")[0] + ".geojson"  # a file's name holds no "/"
    (tmp_path / crack_map).write_text(CRACKS)
    spec = (DATASETS / "facade-1.toml").read_text().replace('title = "', f'title = "{MARKUP}', 1)
    (tmp_path / "f.toml").write_text(spec.replace('description = """', f'description = """{MARKUP}', 1))
    assert cli(["solve", "f.toml", "--plugin", "la", "-o", "f.la.nc"], tmp_path).returncode == 0
    done = cli(["diagnose", "f.toml", "--cracks", crack_map, "--profiles", "step", "--rerank", "0", "-o", "d.nc"],
               tmp_path)
    assert done.returncode == 0, done.stderr
    assert cli(["report", "f.la.nc", "d.nc", "-o", "r.html"], tmp_path).returncode == 0
    page = (tmp_path / "r.html").read_text()
    tags = _Tags()
    tags.feed(page)
    assert not [tag for tag, _ in tags.found if tag == "script"]
    assert not [attrs for tag, attrs in tags.found if "onerror" in attrs]
    assert page.count("&lt;script&gt;alert(2)&lt;/script&gt;") >= 2  # the title and the description: quoted
    assert "&lt;img src=x onerror=alert(1)&gt;.geojson" in page  # the crack map's name


def test_a_report_or_plot_of_a_damaged_diagnosis_names_the_damage(tmp_path):
    """A diagnosis whose scores are NaN ended in a matplotlib traceback."""
    import netCDF4

    (tmp_path / "c.geojson").write_text(CRACKS)
    assert cli(["diagnose", "facade-1", "--cracks", "c.geojson", "--profiles", "step", "--rerank", "0", "-o", "d.nc"],
               tmp_path).returncode == 0
    with netCDF4.Dataset(tmp_path / "d.nc", "a") as file:
        file["candidate_score"][:] = np.nan
    for args in (["report", "d.nc", "-o", "r.html"], ["plot", "d.nc", "--kind", "diagnosis", "-o", "d.png"]):
        done = cli(args, tmp_path)
        assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr[-2000:]
        assert "d.nc: not a valid diagnosis dataset" in done.stderr and "candidate_score at candidate 0 = nan" in done.stderr


# ---------------------------------------------------------------- tracebacks and silent garbage: a message each

_BIG = "1" + "0" * 400
HOSTILE_MAPS = {
    "a 400-digit coordinate": ("c.geojson", _line([[0.1, 0.1], [0.2, 0.1]]).replace("0.2", _BIG),
                               "coordinate 10000000000000000000... is not a finite number"),
    "a 400-digit width": ("c.geojson", _line([[0.1, 0.1], [0.2, 0.1]], {"width_mm": 1}).replace(": 1}", f": {_BIG}}}"),
                          "width_mm 10000000000000000000... is not a finite number"),
    "features = 5": ("c.geojson", '{"type": "FeatureCollection", "features": 5}', "its features are a JSON int"),
    "100,000 nested arrays": ("c.geojson", "[" * 100_000 + "]" * 100_000, "not readable JSON (RecursionError)"),
    "a zero-length GeoJSON crack": ("c.geojson", _line([[0.1, 0.1], [0.1, 0.1]]), "has no length"),
    "a zero-length CSV crack": ("c.csv", "crack,x,y\na,0.1,0.1\na,0.1,0.1\n", "crack 'a': has no length"),
    "width_mm = 1e308": ("c.geojson", _line([[0.1, 0.1], [0.2, 0.1]], {"width_mm": 1e308}),
                         "width_mm = 1e+308 is not a crack width in mm"),
}


@pytest.mark.parametrize("case", list(HOSTILE_MAPS))
def test_a_hostile_crack_map_gets_a_message_naming_the_crack_and_the_fault(tmp_path, case):
    name, text, words = HOSTILE_MAPS[case]
    (tmp_path / name).write_text(text)
    refused(cli(["diagnose", "facade-1", "--cracks", name], tmp_path), f"crack map {name!r}", words)


@pytest.mark.parametrize("fault, words", [("nan", "a coordinate is not a finite number"),
                                          ("zero", "has no length")])
def test_a_hostile_dxf_crack_gets_a_message_naming_its_entity(tmp_path, fault, words):
    import ezdxf

    document = ezdxf.new()
    document.header["$INSUNITS"] = 6
    end = (float("nan"), 0.2) if fault == "nan" else (0.1, 0.1)
    line = document.modelspace().add_line((0.1, 0.1), end)
    document.saveas(tmp_path / "c.dxf")
    refused(cli(["diagnose", "facade-1", "--cracks", "c.dxf"], tmp_path), f"LINE #{line.dxf.handle}", words)


@pytest.mark.parametrize("option, value", [("--segment", "nan"), ("--segment", "inf"), ("--segment", "-1"),
                                           ("--tolerance", "nan"), ("--tolerance", "0")])
def test_a_length_that_is_not_one_is_a_usage_error(tmp_path, option, value):
    (tmp_path / "c.geojson").write_text(CRACKS)
    done = cli(["diagnose", "facade-1", "--cracks", "c.geojson", option, value], tmp_path)
    assert done.returncode == 2 and f"{value!r} is not a positive, finite length" in done.stderr


def test_a_levelling_of_absurd_values_is_refused_not_scored_as_nan(tmp_path):
    """``dy = +-1e300`` gave exit 0 and every score NaN ("best score is nan")."""
    (tmp_path / "c.geojson").write_text(CRACKS)
    (tmp_path / "l.csv").write_text("x,y,dy\n0.1,0.125,1e300\n0.5,0.125,-1e300\n1.0,0.125,1e300\n")
    refused(cli(["diagnose", "facade-1", "--cracks", "c.geojson", "--levelling", "l.csv"], tmp_path),
            "levelling 'l.csv' row 2", "dy = 1e+300 m is more than the wall is high")


@pytest.mark.parametrize("given, right", [("mm", "m"), ("cm", "m")])
def test_a_crack_map_read_in_the_wrong_unit_is_named_so(tmp_path, given, right):
    """A map in metres read as millimetres lies in one corner of the wall: it said only "nothing explains"."""
    (tmp_path / "c.geojson").write_text(CRACKS)
    refused(cli(["diagnose", "facade-1", "--cracks", "c.geojson", "--unit", given], tmp_path),
            f"read in {given}", "far from its joints", f"give --unit {right}")


def test_an_absurd_tunnel_is_named_not_a_traceback(tmp_path):
    (tmp_path / "t.toml").write_text(tunnel(diameter=1e200, depth=1e201))
    refused(cli(["build", "t.toml", "-o", "t.nc"], tmp_path), "'settlement.diameter'", "are not finite lengths")


def test_a_slope_steeper_than_one_is_written_as_such(tmp_path):
    """la printed "stage 1 slope 1/0" on a trough steeper than 1/1 (the steepest: S_max e^-1/2 / i at x = 1.1 m,
    one i from the axis: 23.9 m x 0.607 / 5.25 m = 2.76)."""
    (tmp_path / "t.toml").write_text(tunnel(volume_loss=100.0, diameter=20.0, depth=10.5, center=6.35))
    done = cli(["solve", "t.toml", "--plugin", "la", "-o", "r.nc"], tmp_path)
    assert done.returncode == 0, done.stderr
    assert "stage 1 slope 2.76/1, settlement" in done.stdout


def test_a_run_that_stops_short_of_the_target_says_so_and_where_its_stages_are(tmp_path):
    """jmm stopped at its step limit at 5 of 15 mm and the CLI gave the stages at 5 mm as if they were the answer."""
    (tmp_path / "t.toml").write_text(tunnel())
    done = cli(["solve", "t.toml", "--plugin", "fdem", "--option", "max_steps=20000", "-o", "r.nc"], tmp_path,
               timeout=300)
    assert done.returncode == 0, done.stderr
    result = mf.open_dataset(tmp_path / "r.nc")
    reached = float(result.step_settlement.values[-1])
    assert reached < float(result.settlement_target.values)
    assert f"at S = {1e3 * reached:.3g} mm, reached, short of the model's 15 mm (step limit)" in done.stdout


# ---------------------------------------------------------------- drawn grounds that carry nothing

def test_a_ground_layer_naming_the_masonry_is_refused(tmp_path):
    """``ground_layer`` pointing at the masonry built an upside-down model that ``check`` called OK."""
    spec = (DATASETS / "drawings" / "arch-settlement.toml").read_text()
    spec = spec.split("[supports.left]")[0] + '[settlement]\nprofile = "step"\nstart = 0.0\nend = 0.5\n' \
        'ground_layer = "ARCH"\n[loading]\ntype = "settlement"\n'
    (tmp_path / "a.toml").write_text(spec)
    (tmp_path / "arch-settlement.dxf").write_bytes((DATASETS / "drawings" / "arch-settlement.dxf").read_bytes())
    refused(cli(["build", "a.toml", "-o", "a.nc"], tmp_path), "'settlement.ground_layer'", "above the middle of the "
            "masonry", "is it the masonry's layer?")


def _piers_csv() -> str:
    """Two piers of two courses (0..0.4 m and 0.8..1.2 m) under a lintel, each on its own drawn ground block:
    the drawn ground has a gap under the door."""
    rows = ["block,x,y,layer"]

    def box(name, x0, x1, y0, y1, layer):
        rows.extend(f"{name},{x},{y},{layer}" for x, y in ((x0, y0), (x1, y0), (x1, y1), (x0, y1)))

    for course in range(2):
        for k, x0 in enumerate((0.0, 0.2, 0.8, 1.0)):
            box(f"u{course}{k}", x0, x0 + 0.2, 0.1 * course, 0.1 * course + 0.1, "UNITS")
    box("lintel", 0.0, 1.2, 0.2, 0.3, "UNITS")
    box("g1", 0.0, 0.4, -0.1, 0.0, "GROUND")
    box("g2", 0.8, 1.2, -0.1, 0.0, "GROUND")
    return "\n".join(rows) + "\n"


def test_a_profile_that_moves_only_a_gap_of_the_drawn_ground_is_refused_by_its_keys(tmp_path):
    """A step over a gap in a drawn ground said "no live load: the collapse multiplier is undefined"."""
    (tmp_path / "piers.csv").write_text(_piers_csv())
    (tmp_path / "p.toml").write_text('title = "piers"\n[geometry]\npolygons = "piers.csv"\ndrawing_unit = "m"\n'
                                     '[wall]\nthickness = 0.1\n[material]\nunit_weight = 18000.0\n'
                                     'friction_angle = 30.0\n[settlement]\nprofile = "step"\nstart = 0.45\n'
                                     'end = 0.75\nground_layer = "GROUND"\n[loading]\ntype = "settlement"\n')
    refused(cli(["build", "p.toml", "-o", "p.nc"], tmp_path), "spec table 'settlement'",
            "moves none of the ground that carries masonry", "x = 0..0.4, 0.8..1.2 m", "fill the gap")


def test_ctrl_c_is_answered_within_seconds_however_long_a_record_of_the_run_is(tmp_path):
    """An fdem run on a huge tunnel ignored SIGINT for over 12 minutes: a record of its history (a kernel call)
    held 200 million steps. A call now runs about a quarter of a second (the tunnel facade's 3,000 blocks: 200
    steps); with one record for the whole run, Ctrl-C still ends it at once (held at most to numba's next
    compile event on a first run)."""
    running = Command(["solve", "tunnel-facade", "--plugin", "fdem", "--option", "records=1", "-o", "r.nc"], tmp_path)
    try:
        running.wait_for(r"fdem: dt = ")
        status, stderr, answered = running.signal(signal.SIGINT)
    finally:
        running.stop()
    assert status == 130 and "Traceback" not in stderr and "nothing written" in stderr, stderr[-2000:]
    assert answered < 60, f"answered {answered:.1f} s after the signal"


@pytest.mark.parametrize("geometry", ["mesh = 5", 'dxf = 5\noutline_layer = "o"', "polygons = [1]"],
                         ids=["OBJ", "outline DXF", "drawn polygons"])
def test_a_drawing_key_that_is_no_path_is_named_by_every_walk_of_the_kinds(tmp_path, geometry):
    """The kinds' table reads a spec's drawing key before any build: a number there is refused with a message, never
    a traceback (``-o`` of a command finds the files a spec reads; a 3D drawing's ``mesh = 5`` raised TypeError)."""
    (tmp_path / "w.toml").write_text(f'title = "w"\n[geometry]\n{geometry}\n')
    assert mfp.input_files(tmp_path / "w.toml") == [tmp_path / "w.toml"]
    with pytest.raises(mf.SpecError):
        mf.build(tmp_path / "w.toml")
    if geometry.startswith("mesh"):
        with pytest.raises(mf.SpecError, match="'geometry.mesh' = 5: must be the path of an OBJ file"):
            mf.load_spec(tmp_path / "w.toml")
    refused(cli(["build", "w.toml", "-o", "w.nc"], tmp_path), "spec")
