"""The command line keeps its promises: each one found by trying it, each tested on the real CLI in a subprocess.

- an output path is checked (folder, not an input, writable) before any work, by every command that writes;
- Ctrl-C keeps an incremental solver's partial result, says where it stopped and exits with 130; a run
  stopped before it has a result to keep writes nothing and says so;
- a closed pipe ends a listing quietly;
- a missing spec file is called missing; a spec file solves directly;
- the cracks plot honours its threshold;
- the headline line gives the numbers a user came for;
- a sweep with failed points exits 1, a misspelt sweep key gets "did you mean";
- numba's compilation is not counted in wall_time_s.
"""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from support import tilted_drawing_spec

import masonryfw as mf

SPEC = textwrap.dedent("""\
    title = "Promise wall"
    [wall]
    width = 0.8
    height = 0.3
    thickness = 0.1
    [unit]
    length = 0.2
    height = 0.1
    [material]
    unit_weight = 12000.0
    friction_angle = 30.0
    [supports.left]
    kind = "fixed"
    start = 0.0
    end = 0.5
    [supports.right]
    kind = "moving"
    start = 0.5
    end = 0.8
    [loading]
    type = "settlement"
""")

SPY = '''
"""A solver that leaves a mark when it runs (the promise: nothing runs before the output path is checked)."""
import os
from pathlib import Path

import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp


def solve(model, options, progress):
    Path(os.environ["MASONRYFW_SPY_MARK"]).write_text("ran")
    return xr.Dataset({"collapse_multiplier": ((), 0.5, mfp.variable_attrs("collapse_multiplier"))})


def estimate(model, options):
    return mfp.Estimate(seconds=float(os.environ.get("MASONRYFW_SPY_SECONDS", "1")), memory=1e6,
                       basis="the spy's guess")


@mfp.hookimpl
def masonryfw_solvers():
    return [mfp.Solver("spy", "leaves a mark", solve, estimate=estimate)]
'''


def run(args, cwd, *, env=None, timeout=300):
    """``python -m masonryfw ARGS`` in a fresh process."""
    return subprocess.run([sys.executable, "-m", "masonryfw", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env={**os.environ, **(env or {})}, timeout=timeout)


@pytest.fixture
def spec(tmp_path):
    path = tmp_path / "wall.toml"
    path.write_text(SPEC)
    return path


@pytest.fixture(scope="module")
def spy_site(tmp_path_factory):
    """A site folder holding the spy plugin as pip would install it (module + dist-info entry point)."""
    root = tmp_path_factory.mktemp("spy")
    (root / "spy_mf.py").write_text(SPY)
    info = root / "spy_mf-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: spy_mf\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[masonryfw]\nspy = spy_mf\n")
    return root


# ---------------------------------------------------------------- output paths before the work

def test_solve_checks_its_output_path_before_solving(spec, tmp_path, spy_site):
    mark = tmp_path / "mark"
    env = {"PYTHONPATH": str(spy_site), "MASONRYFW_SPY_MARK": str(mark)}
    for output, message, code in ((tmp_path / "nodir" / "x.nc", "does not exist", 1),
                                  (spec, "refusing to overwrite", 1), (tmp_path, "is a directory", 2)):
        done = run(["solve", spec, "--plugin", "spy", "-o", output], tmp_path, env=env)
        assert done.returncode == code and message in done.stderr, done.stderr
        assert "Traceback" not in done.stderr
        assert not mark.exists()  # the solver never ran
    done = run(["solve", spec, "--plugin", "spy", "-o", tmp_path / "x.nc"], tmp_path, env=env)
    assert done.returncode == 0 and mark.exists()


def test_unwritable_folder_is_refused_before_solving(spec, tmp_path, spy_site):
    if os.geteuid() == 0:  # root writes anywhere: the permission cannot be taken away here
        locked = Path("/proc/masonryfw-no-such-folder")
        message = "does not exist"
    else:
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        message = "no permission"
    mark = tmp_path / "mark"
    done = run(["solve", spec, "--plugin", "spy", "-o", locked / "x.nc"], tmp_path,
               env={"PYTHONPATH": str(spy_site), "MASONRYFW_SPY_MARK": str(mark)})
    assert done.returncode == 1 and message in done.stderr and not mark.exists()


# ---------------------------------------------------------------- estimates and memory before the work

def test_a_long_run_prints_its_estimate_first(spec, tmp_path, spy_site):
    env = {"PYTHONPATH": str(spy_site), "MASONRYFW_SPY_MARK": str(tmp_path / "mark")}
    quick = run(["solve", spec, "--plugin", "spy", "-o", tmp_path / "a.nc"], tmp_path, env=env)
    assert quick.returncode == 0 and "expect about" not in quick.stderr
    long = run(["solve", spec, "--plugin", "spy", "-o", tmp_path / "b.nc"], tmp_path,
               env={**env, "MASONRYFW_SPY_SECONDS": "5400"})
    assert long.returncode == 0 and "spy: expect about 90 min and 1 MiB (the spy's guess)" in long.stderr


def test_a_run_that_cannot_fit_in_memory_is_refused_naming_the_option(spec, tmp_path):
    out = tmp_path / "r.nc"
    done = run(["solve", spec, "--plugin", "jmm", "-o", out], tmp_path, env={"MASONRYFW_MEMORY_LIMIT": "150MiB"})
    assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
    for words in ("needs about", "150 MiB is available", "--option mesh_size", "MASONRYFW_MEMORY_LIMIT"):
        assert words in done.stderr, done.stderr
    assert not out.exists()
    coarse = run(["solve", spec, "--plugin", "jmm-limit", "-o", out, "--option", "mesh_size=0.1"], tmp_path,
                 env={"MASONRYFW_MEMORY_LIMIT": "1GiB"})
    assert coarse.returncode == 0, coarse.stderr


@pytest.fixture(scope="module")
def la_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("la")
    (folder / "wall.toml").write_text(SPEC)
    for name in ("a", "b"):
        assert run(["solve", "wall.toml", "--plugin", "la", "-o", f"{name}.nc"], folder).returncode == 0
    return folder


@pytest.mark.parametrize("args", [
    ["build", "wall.toml", "-o", "nodir/m.nc"],
    ["compare", "a.nc", "b.nc", "-o", "nodir/c.nc"],
    ["plot", "a.nc", "--kind", "mechanism", "-o", "nodir/m.png"],
    ["export", "a.nc", "-o", "nodir/a.vtu"],
    ["gallery", "--case", "test-12c", "--method", "la", "-o", "nodir/gallery", "--agreement", "nodir/a.md"],
    ["sweep", "wall.toml", "--plugin", "la", "--param", "material.friction_angle=25,30", "-o", "nodir/s.nc"],
    ["archive", "nodir/archive", "--from", "a.nc"],
], ids=lambda a: a[0])
def test_every_writing_command_checks_its_output_folder_first(la_files, args):
    done = run(args, la_files)
    assert done.returncode == 1, done.stderr
    assert re.search(r"nodir.*does not exist", done.stderr), done.stderr
    assert "Traceback" not in done.stderr
    assert not (la_files / "nodir").exists()


# ---------------------------------------------------------------- Ctrl-C

@pytest.mark.parametrize("solver, options, stepping", [
    ("fdem", ["--option", "loading_rate=2e-5"], r"settlement \d+% of target"),
    ("jmm", ["--option", "max_steps=400", "--option", "first_increment=0.002", "--option", "max_increment=0.002"],
     r"step 2: settlement"),
])
def test_ctrl_c_keeps_the_partial_result_and_exits_130(tmp_path, command, solver, options, stepping):
    running = command(["solve", "test-12c", "--plugin", solver, "--progress", *options, "-o", "part.nc"], tmp_path)
    running.wait_for(stepping)
    status, err, _ = running.signal(signal.SIGINT)
    assert status == 130, err
    match = re.search(r"interrupted at settlement ([0-9.e+-]+) m: partial result written to part.nc", err)
    assert match, err
    result = mf.open_dataset(tmp_path / "part.nc")
    assert int(result.attrs["interrupted"]) == 1 and result.attrs["stop_reason"] == "interrupted"
    assert float(match.group(1)) == pytest.approx(float(result.step_settlement.values[-1]), rel=1e-5)
    assert mf.check(result) == []
    assert "Traceback" not in err


def test_ctrl_c_before_the_first_step_writes_nothing_and_says_so(tmp_path, command):
    running = command(["solve", "test-12c", "--plugin", "jmm", "--progress", "--option", "mesh_size=0.008",
                       "-o", "none.nc"], tmp_path)
    running.wait_for("gravity")
    status, err, _ = running.signal(signal.SIGINT)
    assert status == 130, err
    assert "interrupted before the solver had a result to keep: nothing written" in err
    assert not (tmp_path / "none.nc").exists() and not list(tmp_path.glob(".*tmp*"))


# ---------------------------------------------------------------- pipes, spec files, plots, headlines

def test_a_closed_pipe_ends_a_listing_quietly(tmp_path):
    done = subprocess.run(f"{sys.executable} -m masonryfw datasets 2> err.txt | head -1", shell=True, cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert done.stdout.startswith("test-8c")
    assert (tmp_path / "err.txt").read_text() == ""


def test_a_missing_spec_file_is_called_missing(tmp_path):
    done = run(["build", "nothere.toml"], tmp_path)
    assert done.returncode == 1 and done.stderr.strip() == "error: nothere.toml: no such file"
    done = run(["build", "nothere"], tmp_path)
    assert "nothere: no such file, and not a bundled case" in done.stderr


def test_a_spec_file_builds_and_solves_in_one_step(spec, tmp_path):
    done = run(["solve", spec.name, "--plugin", "la"], tmp_path)
    assert done.returncode == 0, done.stderr
    result = mf.open_dataset(tmp_path / "wall.la.nc")
    assert result.attrs["title"] == "Promise wall"
    assert float(result.collapse_multiplier) == pytest.approx(
        float(mf.solve(mf.build(spec), "la").collapse_multiplier), abs=1e-12)


def crack_segments_drawn(svg: Path) -> int:
    """Line segments drawn in the cracks plot's state colours (matplotlib's tab:red, tab:blue, tab:purple),
    less the legend's three sample lines."""
    text = svg.read_text()
    return sum(len(re.findall(rf"stroke: {colour}", text)) for colour in ("#d62728", "#1f77b4", "#9467bd")) - 3


def test_the_cracks_plot_draws_the_joints_above_its_threshold(la_files):
    result = mf.open_dataset(la_files / "a.nc")
    for threshold in (0.05, 0.5):
        done = run(["plot", "a.nc", "--kind", "cracks", "--option", f"threshold={threshold}", "-o", f"c{threshold}.svg"],
                   la_files)
        assert done.returncode == 0, done.stderr
        opening, slip = result.interface_opening.values, result.interface_slip.values
        motion = np.hypot(np.maximum(opening, 0.0), slip).max(axis=1)  # docs/format.md, by hand
        ground = np.isin(result.block_role.values, [2, 3])[result.interface_blocks.values].all(axis=1)
        expected = int((~ground & (motion > threshold * motion[~ground].max())).sum())
        assert crack_segments_drawn(la_files / f"c{threshold}.svg") == expected


def test_the_headline_gives_the_numbers_a_user_came_for(spec, tmp_path):
    la = run(["solve", spec.name, "--plugin", "la"], tmp_path)
    alpha = float(mf.open_dataset(tmp_path / "wall.la.nc").collapse_multiplier)
    assert re.search(rf"la: alpha = {alpha:.6g}, dead_reaction = [0-9.]+ N, collapse_reaction = [0-9.]+ N",
                     la.stdout), la.stdout
    jmm = run(["solve", spec.name, "--plugin", "jmm", "--option", "max_steps=5"], tmp_path)
    line = jmm.stdout.splitlines()[-1]
    for name in ("dead_reaction", "minimum_reaction", "plateau_reaction", "plateau_settlement"):
        assert f"{name} = " in line, line
    assert "mesh" not in line


# ---------------------------------------------------------------- sweeps

def test_a_sweep_with_failed_points_exits_1_after_writing_the_rest(spec, tmp_path):
    done = run(["sweep", spec.name, "--plugin", "la", "--workers", "1", "--no-progress",
                "--param", "supports.right.start=0.5,0.9", "-o", "s.nc"], tmp_path)
    assert done.returncode == 1, done.stderr
    assert "1 failed" in done.stdout and "supports.right.start=0.9" in done.stderr
    sweep = mf.open_dataset(tmp_path / "s.nc")
    assert sweep.status.values.tolist() == [0, 1]
    assert np.isfinite(sweep.alpha.values[0])


def test_a_misspelt_sweep_key_is_named_with_a_guess(spec, tmp_path):
    done = run(["sweep", spec.name, "--plugin", "la", "--param", "supports.rigth.start=0.5,0.6"], tmp_path)
    assert done.returncode == 1
    assert "unknown key 'supports.rigth' (did you mean 'supports.right'?)" in done.stderr, done.stderr
    assert not list(tmp_path.glob("*.store"))


def test_a_sweep_tabulates_the_key_numbers_of_an_incremental_solver(spec, tmp_path):
    done = run(["sweep", spec.name, "--plugin", "jmm", "--workers", "1", "--no-progress",
                "--param", "option.max_steps=3,4", "-o", "j.nc"], tmp_path)
    assert done.returncode == 0, done.stderr
    sweep = xr.open_dataset(tmp_path / "j.nc")
    assert {"dead_reaction", "minimum_reaction", "plateau_reaction"} <= set(sweep.data_vars)
    assert "mesh" not in sweep.data_vars


# ---------------------------------------------------------------- compile time

@pytest.mark.slow  # 25 s: it compiles fdem's kernels afresh
def test_numba_compilation_is_recorded_apart_from_the_wall_time(spec, tmp_path):
    """An empty numba cache forces the fdem kernels to compile (seconds) for a run of a fraction of that."""
    done = run(["solve", spec.name, "--plugin", "fdem", "-o", "f.nc"], tmp_path,
               env={"NUMBA_CACHE_DIR": str(tmp_path / "numba-cache")})
    assert done.returncode == 0, done.stderr
    attrs = mf.open_dataset(tmp_path / "f.nc").attrs
    assert attrs["compile_time_s"] > 1.0
    assert attrs["wall_time_s"] < attrs["compile_time_s"]
    assert json.loads(attrs["solver_options"])["mode"] == "rigid"


# ---------------------------------------------------------------- drawings

DRAWN_SPEC = tilted_drawing_spec("wall.dxf", unit_weight=12000.0)


def test_a_broken_drawing_is_named_and_an_overlapping_one_can_still_be_drawn(tmp_path):
    """An open polyline: exit 1, the entity and its ends, no traceback, nothing written. Overlapping
    blocks: build refuses naming both entities; plot --kind model draws the model all the same."""
    import ezdxf

    (tmp_path / "wall.toml").write_text(DRAWN_SPEC)
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline([(0, 0), (200, 0), (200, 100)], close=False)
    doc.saveas(tmp_path / "wall.dxf")
    done = run(["build", "wall.toml", "-o", "wall.nc"], tmp_path)
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert re.search(r"LWPOLYLINE #\w+ on layer 0: open: it starts at \(0, 0\) m and ends at \(0.2, 0.1\) m", done.stderr)
    assert not (tmp_path / "wall.nc").exists()
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    for corners in ([(0, 0), (200, 0), (200, 100), (0, 100)], [(150, 0), (350, 0), (350, 100), (150, 100)],
                    [(-50, -50), (400, -50), (400, 0), (-50, 0)]):
        doc.modelspace().add_lwpolyline(corners, close=True)
    doc.saveas(tmp_path / "wall.dxf")
    done = run(["build", "wall.toml", "-o", "wall.nc"], tmp_path)
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert re.search(r"block 0 \(LWPOLYLINE #\w+ on layer 0\): overlaps block 1 \(LWPOLYLINE", done.stderr)
    drawn = run(["plot", "wall.toml", "--kind", "model", "-o", "model.png"], tmp_path)
    assert drawn.returncode == 0, drawn.stderr
    assert (tmp_path / "model.png").stat().st_size > 10_000
