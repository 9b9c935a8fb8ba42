"""Real DXF drawings written by other programs (tests/data/dxf/README.md): each builds, and solves to its
published collapse angle where it has one, or is refused with the reason named, through the real CLI."""
from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from support import tilted_drawing_spec

import masonryfw as mf
from masonryfw.cli import cli
from masonryfw.readers.drawing import read_drawing

CORPUS = Path(__file__).parents[1] / "data" / "dxf"
#: LACT3's solver test (LACT3_SolverTest.m): tilting-table collapse angle [deg] and friction angle, c = 0.
PUBLISHED = {"lact3-arch_1.dxf": (17.10, 30.0, 26), "lact3-Portal.dxf": (27.30, 30.0, 41),
             "lact3-wall.dxf": (16.73, 26.0, 183)}
REFUSED = {
    "ezdxf-POLI-ALL210_12.DXF": r"POLYLINE #29 on layer T-2DPLINE-ALL: its vertices are not in one plane",
    "ezdxf-cc_dxflib.dxf": r"POLYLINE #8 on layer POLYLINE_001: a 3D polyline or mesh, not a block outline",
    "ezdxf-bin_dxf_r12.dxf": r"no closed polyline or polygon in it \(left out: 3 LINE\)",
    "ezdxf-Leica_Disto_S910.dxf": r"no closed polyline or polygon in it \(left out: 10 LINE, 11 POINT, 11 TEXT\)",
    "ezdxf-empty_handles.dxf": r"no closed polyline or polygon in it \(left out: 8 LINE\)",
    "ezdxf-R12_with_trash_beyond_EOF.dxf": r"no closed polyline or polygon in it \(left out: 1 CIRCLE\)",
}


def spec(tmp_path: Path, drawing: str, friction: float = 30.0) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(tilted_drawing_spec(CORPUS / drawing, unit="mm", thickness=1.0, unit_weight=25000.0,
                                        friction=friction, title=drawing))
    return path


def test_the_corpus_is_what_its_readme_lists():
    listed = set(re.findall(r"^\| `([^`]+)`", (CORPUS / "README.md").read_text(), flags=re.M))
    present = {p.name for p in CORPUS.iterdir() if p.suffix.lower() == ".dxf"}
    assert listed == present == set(PUBLISHED) | set(REFUSED)


@pytest.mark.parametrize("drawing", sorted(PUBLISHED))
def test_lact3_drawings_solve_to_their_published_angle(tmp_path, drawing):
    """The originals, quirks and all (the arch's polylines end 6e-13 drawing units from their start without
    the closed flag): alpha = tan(theta) to 1e-3 (the angles are published to 0.01 deg)."""
    angle, friction, blocks = PUBLISHED[drawing]
    run = CliRunner().invoke(cli, ["build", str(spec(tmp_path, drawing, friction)), "-o", str(tmp_path / "m.nc")])
    assert run.exit_code == 0, run.output
    assert f"wrote {tmp_path / 'm.nc'}: {blocks} blocks" in run.output
    alpha = float(mf.solve(mf.open_model(tmp_path / "m.nc"), "la").collapse_multiplier)
    assert alpha == pytest.approx(math.tan(math.radians(angle)), abs=1e-3)


@pytest.mark.parametrize("drawing", sorted(REFUSED))
def test_drawings_without_block_outlines_are_refused_by_name(tmp_path, drawing):
    run = CliRunner().invoke(cli, ["build", str(spec(tmp_path, drawing)), "-o", str(tmp_path / "m.nc")])
    assert run.exit_code == 1
    assert "Traceback" not in run.output and "skipped invalid handle" not in run.output
    assert re.search(REFUSED[drawing], run.output), run.output
    assert not (tmp_path / "m.nc").exists()


def test_an_open_polyline_shows_the_numbers_that_differ(tmp_path):
    """A polyline that stops short of its start by more than the snap tolerance is refused with both ends
    written to the digits that tell them apart, the gap and the tolerance."""
    import ezdxf

    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 50), (0, 50), (0, 0.001)])  # not closed: 1 micron short
    msp.add_lwpolyline([(0, -50), (100, -50), (100, 0), (0, 0)], close=True)
    doc.saveas(tmp_path / "open.dxf")
    text = spec(tmp_path, "x").read_text().replace(str(CORPUS / "x"), str(tmp_path / "open.dxf"))
    (tmp_path / "spec.toml").write_text(text)
    run = CliRunner().invoke(cli, ["build", str(tmp_path / "spec.toml"), "-o", str(tmp_path / "m.nc")])
    assert run.exit_code == 1
    assert "open: it starts at (0, 0) m and ends at (0, 1e-06) m, 1e-06 m apart, more than the snap tolerance " \
           "1.41e-07 m" in run.output  # 1e-6 of the drawing's diagonal, 0.141 m


def test_ends_a_hair_apart_are_written_to_the_digits_that_differ():
    """LACT3's arch with a snap tolerance below its 6e-13 mm gaps: refused, its ends written with the 15 digits
    that tell them apart (at 6 they read the same)."""
    with pytest.raises(mf.SpecError, match=r"LWPOLYLINE #2E0 on layer 0: open: it starts at "
                                           r"\(0\.252524121054933, 0\.118337484842948\) m and ends at "
                                           r"\(0\.252524121054933, 0\.118337484842949\) m, 6\.07e-16 m apart"):
        read_drawing(CORPUS / "lact3-arch_1.dxf", "mm", snap_tolerance=1e-14)
