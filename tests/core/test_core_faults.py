"""Faults and hostile input, through the real command line: nothing lost, hung or leaked (docs/faults.md).

Each test runs ``python -m masonryfw`` as a user would and looks from outside: exit status, stderr, the
files left in the folder, the peak memory of the process.
"""
from __future__ import annotations

import json
import os
import re
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from support import Command, cli, hidden, open_files, peak_memory, refused, stopped, tilted_drawing_spec

import masonryfw as mf
import masonryfw.plugin_api as mfp

#: A wall of 23,090 blocks: its model takes about 0.3 s to write, long enough to signal the writer.
BIG_SPEC = """title = "big"
[wall]
width = 60.0
height = 12.0
thickness = 0.25
[unit]
length = 0.25
height = 0.125
[material]
unit_weight = 18000.0
friction_angle = 30.0
[supports.fixed]
kind = "fixed"
start = 0.0
end = 40.0
[supports.settling]
kind = "moving"
start = 40.0
end = 60.0
motion = "translation"
[loading]
type = "settlement"
"""
MB = 2**20


# ---------------------------------------------------------------- 1. a signal while a file is written

def _signal_the_writer(folder: Path, signum: int, moment: str) -> tuple[int, str, str]:
    """Build the big wall; stop the command (SIGSTOP) at ``moment`` and send ``signum`` while it stands still there:
    ``"writing"``, its temporary output open in the netCDF library; ``"in place"``, its output renamed into place
    (the process not yet ended). The status, stdout and stderr."""
    for _ in range(20):
        process = Command(["build", "big.toml", "-o", "out.nc"], folder).process
        sent = False
        while process.poll() is None and not sent:
            temporaries = [n for n in os.listdir(folder) if n.startswith(".out.nc.") and n.endswith(".tmp.nc")]
            if not (temporaries if moment == "writing" else (folder / "out.nc").exists()):
                time.sleep(0.0005)
                continue
            with stopped(process) as running:
                if moment == "writing":
                    there = running and any(name.endswith(tuple(temporaries)) for name in open_files(process.pid))
                else:
                    there = running
                if there:
                    process.send_signal(signum)
                    sent = True
            if not sent and moment == "writing":  # closed, not yet renamed: a state this test does not promise
                break
        out, err = process.communicate(timeout=120)  # the hang this guards against lasted minutes
        if sent:
            return process.returncode, out, err
        (folder / "out.nc").unlink(missing_ok=True)  # ended before it was seen there: again
    raise AssertionError(f"the command was never seen {moment} while it ran")


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
@pytest.mark.parametrize("moment", ["writing", "in place"])
def test_a_signal_while_a_model_is_written_completes_the_file(tmp_path, signum, moment):
    """Ctrl-C during the netCDF write used to hang in xarray's lock for minutes; SIGTERM left the hidden
    temporary file. Now a signal while the file is written is held: the file is completed, renamed, and the
    command exits 130 (143) saying so. Once the output is in place the outcome is settled: a signal then changes
    nothing, and the command exits 0 saying what it wrote. The signal is sent while the process is stopped in
    the state named, so the promise tested never depends on the scheduler."""
    (tmp_path / "big.toml").write_text(BIG_SPEC)
    code, out, err = _signal_the_writer(tmp_path, signum, moment)
    if moment == "writing":
        assert code == 128 + signum, err
        assert "interrupted after writing" in err and "out.nc (complete)" in err and "Traceback" not in err
    else:
        assert code == 0 and err == "", err
        assert out.startswith("wrote out.nc: 23090 blocks"), out
    assert mf.open_dataset(tmp_path / "out.nc").sizes["block"] == 23090
    assert hidden(tmp_path) == []


# ---------------------------------------------------------------- 2. outputs that are not regular files

def test_an_output_that_is_a_fifo_is_refused_and_left_a_fifo(tmp_path):
    os.mkfifo(tmp_path / "out.nc")
    refused(cli(["build", "panel-1", "-o", "out.nc"], tmp_path, timeout=30), "is a FIFO", "not a regular file")
    assert stat.S_ISFIFO(os.stat(tmp_path / "out.nc").st_mode)


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0,
                    reason="making a device node (a copy of /dev/null in a temporary folder) needs root")
def test_an_output_that_is_a_device_is_refused_and_left_a_device(tmp_path):
    """As root, ``-o /dev/null`` used to replace the device with a regular file; a copy of /dev/null made in a
    temporary folder stands in for it (the real one is never put at risk)."""
    os.mknod(tmp_path / "null", 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    refused(cli(["solve", "panel-1", "--plugin", "la", "-o", "null"], tmp_path), "is a character device")
    assert stat.S_ISCHR(os.stat(tmp_path / "null").st_mode)
    assert hidden(tmp_path) == []


# ---------------------------------------------------------------- 3. memory: estimated and refused first

def test_a_device_given_as_a_spec_is_refused_before_reading(tmp_path):
    done, peak = peak_memory(["build", "/dev/zero", "-o", "m.nc"], tmp_path, timeout=30)
    refused(done, "/dev/zero", "is a character device")
    assert peak < 400 * MB


@pytest.mark.parametrize("width, blocks", [("1e6", "3.84e+08"), ("1e9", "3.84e+11")])
def test_a_wall_too_big_for_the_memory_is_refused_before_it_is_built(tmp_path, width, blocks):
    """``width = 1e6`` passed 4 GB in 18 s; ``1e9`` ended in a numpy traceback, and its message blamed the
    supports. Now: the blocks are counted first (courses x units a course), the memory they need compared with
    what is available, and the message names the keys."""
    (tmp_path / "w.toml").write_text(BIG_SPEC.replace("width = 60.0", f"width = {width}"))
    started = time.perf_counter()
    done, peak = peak_memory(["build", "w.toml", "-o", "m.nc"], tmp_path)
    refused(done, f"wall.width = {float(width)!r}", f"about {blocks} blocks", "memory")
    assert "supports" not in done.stderr
    assert peak < 400 * MB and time.perf_counter() - started < 30


def test_tiny_units_are_refused_by_their_count_not_by_the_allocator(tmp_path):
    spec = BIG_SPEC.replace("length = 0.25", "length = 0.000001").replace("height = 0.125", "height = 0.000001")
    (tmp_path / "w.toml").write_text(spec.replace("height = 12.0", "height = 12.000000"))
    done, peak = peak_memory(["build", "w.toml", "-o", "m.nc"], tmp_path)
    refused(done, "blocks", "PiB of memory")
    assert peak < 400 * MB


def test_a_netcdf_bomb_is_refused_under_the_memory_limit_before_it_is_read(tmp_path):
    """1.7 MB on disk, 400 MB once read (50 million compressed zeros): under MASONRYFW_MEMORY_LIMIT=100MiB
    ``check`` refuses it, naming the variable and its dimension, without reading it."""
    import netCDF4

    with netCDF4.Dataset(tmp_path / "bomb.nc", "w") as bomb:
        bomb.createDimension("huge", 50_000_000)
        junk = bomb.createVariable("junk", "f8", ("huge",), zlib=True, complevel=1, chunksizes=(1_000_000,))
        for start in range(0, 50_000_000, 1_000_000):
            junk[start:start + 1_000_000] = np.zeros(1_000_000)
        bomb.masonryfw_format = "model"
    assert (tmp_path / "bomb.nc").stat().st_size < 5 * MB
    done, peak = peak_memory(["check", "bomb.nc"], tmp_path, env={"MASONRYFW_MEMORY_LIMIT": "100MiB"})
    refused(done, "bomb.nc", "'junk'", "huge = 50,000,000", "MASONRYFW_MEMORY_LIMIT")
    assert peak < 250 * MB


def test_a_drawing_too_big_for_the_memory_is_refused_before_it_is_read(tmp_path):
    (tmp_path / "wall.dxf").write_bytes(b"0\nSECTION\n" + b"999\npadding\n" * 200_000)
    _drawn_spec(tmp_path, "wall.dxf", "dxf")
    refused(cli(["build", "w.toml", "-o", "m.nc"], tmp_path, env={"MASONRYFW_MEMORY_LIMIT": "20MiB"}),
            "drawing", "wall.dxf", "memory")


# ---------------------------------------------------------------- 4. a command interrupted at any moment

#: Panel 5 by fdem is interrupted where its stderr says each phase begins: the imports (``-X importtime`` prints a
#: line as each module is loaded; click is the command line's first), numba's compilation (a cache of its own,
#: empty), the gravity phase and the settlement phase (the installation's own cache, warm). Marks, not delays, and after each mark
#: far more work than the test needs to answer: the compilation alone takes 20 s on a fresh install, and the
#: settlement is loaded ten times slower than by default (:data:`SLOW`: 40 s of steps instead of 4 s), so
#: the signal lands in the phase named however busy the machine is (it slows the command as much as the test).
PHASES = {
    "start-up": (r"import time:.*\| +click\n", "cold"),
    "compiling": (r"fdem: compiling the solver once", "cold"),
    "gravity": (r"fdem: gravity", "warm"),
    "settlement": (r"fdem: settlement", "warm"),
}
#: fdem's settlement loaded ten times slower than its default (2e-3 m/s): Panel 5's then takes 40 s. (A hundred
#: times slower, the gravity phase ends before its first line: its records are spaced by the loading.)
SLOW = ("--option", "loading_rate=2e-4")


@pytest.fixture(scope="module")
def warm_cache_env(tmp_path_factory):
    """The environment of a run whose numba cache holds fdem's kernels: the installation's own cache, warmed by
    one short run (at once when a test before compiled them; a cache of the module's own cost 38 s to fill)."""
    folder = tmp_path_factory.mktemp("warm")
    done = cli(["solve", "panel-5", "--plugin", "fdem", "--option", "settlement=0.0002", "-o", "warm.nc"], folder,
               timeout=600)
    assert done.returncode == 0, done.stderr
    return {}


@pytest.mark.parametrize("phase, signum", [("start-up", signal.SIGINT), ("compiling", signal.SIGINT),
                                           ("compiling", signal.SIGTERM), ("gravity", signal.SIGINT),
                                           ("settlement", signal.SIGTERM), ("settlement", signal.SIGINT)])
def test_a_signal_in_any_phase_of_an_fdem_run_ends_it_with_one_line_and_keeps_what_it_can(
        tmp_path, warm_cache_env, command, phase, signum):
    """A fresh-clone CI run ended with status -2 and no word: a Ctrl-C in the imports or the compilation of a
    first fdem run was outside the command's handling, dropped by LLVM's callbacks (the run went on to exit 0),
    or turned by CPython into a death by SIGINT after the command had said 130. Now every phase ends with
    128 + the signal and one line; from the gravity phase on, a readable partial result is kept."""
    mark, cache = PHASES[phase]
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "cold-cache")} if cache == "cold" else warm_cache_env
    running = command(["solve", "panel-5", "--plugin", "fdem", *SLOW, "-o", "r.nc"], tmp_path, env=env,
                      python=("-X", "importtime") if phase == "start-up" else ())
    running.wait_for(mark)
    status, stderr, answered = running.signal(signum)
    assert status == 128 + signum and "Traceback" not in stderr, stderr[-3000:]
    last = stderr.rstrip("\n").splitlines()[-1]
    if phase in ("start-up", "compiling"):
        assert last.endswith("nothing written") and not (tmp_path / "r.nc").exists(), last
    else:
        assert re.fullmatch(r"interrupted at settlement \S+ m: partial result written to r.nc", last), last
        result = mf.open_dataset(tmp_path / "r.nc")
        assert int(result.attrs["interrupted"]) == 1 and np.isfinite(result.step_reaction.values).all()
        assert (result.step_phase.values == 1).any() or phase == "gravity"  # the mark follows its phase's record
    if phase == "compiling":
        assert answered < 60, f"answered {answered:.1f} s after the signal (numba's events came < 5 s apart)"
    assert hidden(tmp_path) == []


def test_a_signal_inherited_ignored_stays_ignored_and_sigterm_still_ends_the_run(tmp_path, warm_cache_env):
    """A shell script's background job inherits SIGINT ignored, so that a Ctrl-C meant for the foreground leaves
    it running; it stays so, and SIGTERM still ends the run at once with a partial result. SIGINT and SIGTERM are
    sent together: were SIGINT taken, the status would say 130 (the first signal taken, and Linux delivers the
    lower-numbered SIGINT first), so 143 proves it was ignored without waiting for anything."""
    process = subprocess.Popen(
        [sys.executable, "-m", "masonryfw", "solve", "panel-5", "--plugin", "fdem", *SLOW, "-o", "r.nc"],
        cwd=tmp_path, text=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
        env={**os.environ, **warm_cache_env},
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    seen = ""
    while "fdem: settlement" not in seen:
        seen += process.stderr.readline()
    with stopped(process) as running:
        assert running
        process.send_signal(signal.SIGINT)
        process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 143 and "partial result written to r.nc" in stderr, stderr


# ---------------------------------------------------------------- 5, 7, 9. bad input: the cause, named

def _geojson(coordinates) -> str:
    feature = {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": coordinates}}
    return json.dumps({"type": "FeatureCollection", "features": [feature]})


_RING = [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]
_GEOJSON_CASES = {
    "nested one level too deep": (_geojson([[_RING]]), "nested one level too deep"),
    "coordinates = 5": (_geojson(5), "coordinates are a JSON number, not a list of rings"),
    "an integer of 10^400": (_geojson([[[0, 0], [1, 0], [1, 1], [0, 1]]]).replace("[0, 1]", "[0, 1" + "0" * 400 + "]"),
                             "too large for a number"),
    "a null coordinate": (_geojson([[[0, 0], [1, None], [1, 1], [0, 1]]]), "position 1 is [number, null]"),
    "a bare ring": (_geojson(_RING), "one ring of [x, y] positions, not a list of rings"),
    "a string feature": (json.dumps({"type": "FeatureCollection", "features": ["abc"]}),
                         "a JSON string, not a Feature object"),
}


def _drawn_spec(folder: Path, drawing: str, key: str = "polygons", name: str = "w.toml") -> None:
    """A spec of a wall drawn in ``drawing`` (in metres) standing on its lowest block, tilted."""
    (folder / name).write_text(tilted_drawing_spec(drawing, key, "m", title="w"))


@pytest.mark.parametrize("case", list(_GEOJSON_CASES))
def test_a_malformed_geojson_drawing_gets_a_message_naming_the_feature_and_the_fault(tmp_path, case):
    text, words = _GEOJSON_CASES[case]
    (tmp_path / "wall.geojson").write_text(text)
    _drawn_spec(tmp_path, "wall.geojson")
    refused(cli(["build", "w.toml", "-o", "m.nc"], tmp_path), "wall.geojson", "feature 0", words)


def test_files_that_are_not_what_they_are_given_for_are_named_for_what_they_are(tmp_path):
    model = tmp_path / "m.nc"
    assert cli(["build", "panel-1", "-o", model], tmp_path).returncode == 0
    refused(cli(["build", model, "-o", "again.nc"], tmp_path), "is a netCDF file", "not a spec")
    refused(cli(["sweep", model, "--plugin", "la", "--param", "wall.thickness=0.1,0.2"], tmp_path),
            "is a netCDF file", "not a spec")
    (tmp_path / "latin1.toml").write_bytes('title = "Fa\xe7ade"\n'.encode("latin-1"))
    refused(cli(["build", "latin1.toml", "-o", "x.nc"], tmp_path), "not UTF-8 text", "byte 0xe7 at line 1, column 12")
    (tmp_path / "latin1.csv").write_bytes("block,x,y\nb\xe9,0,0\n".encode("latin-1"))
    _drawn_spec(tmp_path, "latin1.csv")
    refused(cli(["build", "w.toml", "-o", "x.nc"], tmp_path), "latin1.csv", "not UTF-8 text", "line 2")
    sweep = mf.open_dataset(model)
    sweep.attrs["masonryfw_format"] = "sweep"
    mf.save(sweep, tmp_path / "s.nc")
    refused(cli(["solve", "s.nc", "--plugin", "la", "-o", "r.nc"], tmp_path), "a sweep dataset", "not a model")


def test_a_fifo_or_a_device_given_as_an_input_is_refused_at_once(tmp_path):
    os.mkfifo(tmp_path / "f.toml")
    refused(cli(["build", "f.toml", "-o", "m.nc"], tmp_path, timeout=30), "f.toml", "is a FIFO")
    os.mkfifo(tmp_path / "wall.csv")
    _drawn_spec(tmp_path, "wall.csv")
    refused(cli(["build", "w.toml", "-o", "m.nc"], tmp_path, timeout=30), "wall.csv", "is a FIFO")
    _drawn_spec(tmp_path, "/dev/zero")
    refused(cli(["build", "w.toml", "-o", "m.nc"], tmp_path, timeout=30), "/dev/zero", "is a character device")


def _csv_wall(scale: float = 1.0, stray: tuple[float, float] | None = None) -> str:
    rows = ["block,x,y"] + [f"base,{x * scale!r},{y * scale!r}" for x, y in ((0, -0.1), (1.625, -0.1), (1.625, 0), (0, 0))]
    for course in range(4):
        for k in range(6):
            x0, y0 = k * 0.25 + (0.125 if course % 2 else 0.0), course * 0.125
            rows += [f"u{course}_{k},{x * scale!r},{y * scale!r}"
                     for x, y in ((x0, y0), (x0 + 0.25, y0), (x0 + 0.25, y0 + 0.125), (x0, y0 + 0.125))]
    if stray is not None:
        rows[6] = f"u0_0,{stray[0]!r},{stray[1]!r}"
    return "\n".join(rows) + "\n"


@pytest.mark.parametrize("kind", ["dxf", "csv"])
def test_a_drawing_with_one_stray_vertex_is_refused_naming_that_vertex(tmp_path, kind):
    """One vertex typed at 1e12 made the snap tolerance (1e-6 of the drawing's size) swallow every block, and
    the message said "fewer than 3 distinct vertices after snapping"."""
    rows = [line.split(",") for line in _csv_wall(stray=(1e12, 0.0)).splitlines()[1:]]
    if kind == "csv":
        (tmp_path / "wall.csv").write_text(_csv_wall(stray=(1e12, 0.0)))
        owner = "block 'u0_0'"
    else:
        import ezdxf

        document = ezdxf.new()
        names = list(dict.fromkeys(row[0] for row in rows))
        for name in names:
            points = [(float(x), float(y)) for block, x, y in rows if block == name]
            polyline = document.modelspace().add_lwpolyline(points, close=True)
            if name == "u0_0":
                owner = f"LWPOLYLINE #{polyline.dxf.handle}"
        document.saveas(tmp_path / "wall.dxf")
    _drawn_spec(tmp_path, f"wall.{kind}", "dxf" if kind == "dxf" else "polygons")
    refused(cli(["build", "w.toml", "-o", "m.nc"], tmp_path), owner, "(1e+12, 0) m",
            "far from every other one", "is that vertex a mistake?")


def test_a_drawing_in_the_wrong_unit_is_built_with_a_warning(tmp_path):
    (tmp_path / "wall.csv").write_text(_csv_wall(scale=1e12))
    _drawn_spec(tmp_path, "wall.csv")
    done = cli(["build", "w.toml", "-o", "m.nc"], tmp_path)
    assert done.returncode == 0, done.stderr
    assert "warning: the drawing: the masonry is" in done.stderr and "more than 1000 m" in done.stderr


# ---------------------------------------------------------------- 6. a full disk

def _in_a_full_disk(tmp_path: Path, size: str, command: str) -> subprocess.CompletedProcess:
    """``command`` (a shell line) in a private mount namespace where ``tmp_path/small`` is a tmpfs of ``size``;
    skipped where the machine does not allow one (no ``unshare`` or no user namespaces)."""
    small = tmp_path / "small"
    small.mkdir(exist_ok=True)
    script = f"mount -t tmpfs -o size={size} tmpfs {small} && cd {small} && {command}; echo status=$? >&2; ls -A"
    try:
        done = subprocess.run(["unshare", "-rm", "sh", "-c", script], capture_output=True, text=True, timeout=120)
    except FileNotFoundError:
        pytest.skip("a full disk is simulated with unshare (util-linux), not installed here")
    if "status=" not in done.stderr:
        pytest.skip(f"this machine refuses a private mount namespace: {done.stderr.strip()[:200]}")
    return done


def test_a_full_disk_is_said_to_be_full_and_leaves_nothing_behind(tmp_path):
    model = tmp_path / "m.nc"
    mf.save(mf.open_model("facade-3"), model)
    python = f"{sys.executable} -m masonryfw"
    done = _in_a_full_disk(tmp_path, "64k", f"{python} build facade-3 -o m.nc")
    assert "status=1" in done.stderr and "Traceback" not in done.stderr
    assert "m.nc: could not write (the disk is full" in done.stderr and done.stdout.strip() == ""
    result = tmp_path / "r.nc"
    mf.save(mf.solve(mf.open_model("facade-3"), "la"), result)
    done = _in_a_full_disk(tmp_path, "40k", f"{python} export {result} -o e.vtu")
    assert "status=1" in done.stderr and "the disk is full" in done.stderr
    assert "none of its 3 files is written or changed" in done.stderr and done.stdout.strip() == ""


# ---------------------------------------------------------------- 8. what a message may quote

def test_a_message_never_quotes_a_file_that_is_not_the_users_drawing(tmp_path):
    """A spec can point its drawing at any file (a symbolic link to a private one): the message says what is
    wrong with it, without its contents; a file that is not a DXF is not handed to the DXF reader."""
    private = tmp_path / "private"
    private.write_text("SECRET:x:0:0:the first line of a private file\nmore,secret,text\n")
    (tmp_path / "wall.csv").symlink_to(private)
    _drawn_spec(tmp_path, "wall.csv")
    done = cli(["build", "w.toml", "-o", "m.nc"], tmp_path)
    refused(done, "wall.csv", "is it a CSV drawing?")
    assert "SECRET" not in done.stderr + done.stdout
    (tmp_path / "wall.dxf").symlink_to(private)
    _drawn_spec(tmp_path, "wall.dxf", "dxf", "d.toml")
    done = cli(["build", "d.toml", "-o", "m.nc"], tmp_path)
    refused(done, "not a DXF file")
    assert "SECRET" not in done.stderr + done.stdout


# ---------------------------------------------------------------- 10. one writer per output and per store

def test_a_second_command_writing_the_same_output_is_refused_while_the_first_runs(tmp_path):
    """Two solves writing one file both exited 0 and one result was lost. The first claims the output when it
    checks it (before its work); the second is refused at once, naming the holder; the first's result stands.
    The first is loaded a hundred times slower than by default (minutes of steps), so it still runs whenever the
    second starts; it is then interrupted and keeps its partial result."""
    first = Command(["solve", "test-12c", "--plugin", "fdem", "--option", "loading_rate=2e-5", "-o", "r.nc"], tmp_path)
    try:
        first.wait_for(r"fdem: settlement")
        second = cli(["solve", "test-12c", "--plugin", "la", "-o", "r.nc"], tmp_path)
        status, stderr, _ = first.signal(signal.SIGINT)
    finally:
        first.stop()
    refused(second, "r.nc", "being written by another masonryfw process", f"pid {first.process.pid}")
    assert status == 130 and "partial result written to r.nc" in stderr, stderr[-2000:]
    assert mf.open_dataset(tmp_path / "r.nc").attrs["solver"] == "fdem"
    assert hidden(tmp_path) == []


def test_a_sweep_refuses_a_store_another_sweep_is_using(tmp_path):
    store = (tmp_path / "s.store").resolve()
    store.mkdir()
    mfp.claim(store, f"sweep store {store}")  # this process stands in for the other sweep
    try:
        done = cli(["sweep", "panel-1", "--plugin", "la", "--param", "wall.thickness=0.05,0.1", "--store", store,
                    "-o", "s.nc", "--no-progress"], tmp_path)
    finally:
        mfp.release(store)
    refused(done, "sweep store", "being written by another masonryfw process", f"pid {os.getpid()}")
    assert not (store / "results").exists()


def test_an_interrupted_sweep_says_what_its_store_kept(tmp_path):
    """It said "interrupted: nothing written" while its store kept the points solved so far."""
    sweep = Command(["sweep", "panel-1", "--plugin", "fdem", "--param", "wall.thickness=0.05,0.06,0.07,0.08,0.09,0.1",
                     "--workers", "1", "--no-progress", "-o", "s.nc"], tmp_path).process
    results = tmp_path / "s.store" / "results"
    while not list(results.glob("*.json")):  # five fdem runs to go: far more than the test needs to answer
        assert sweep.poll() is None, sweep.communicate()[1]
        time.sleep(0.05)
    sweep.send_signal(signal.SIGINT)
    _, stderr = sweep.communicate(timeout=120)
    kept = len(list(results.glob("*.json")))
    assert sweep.returncode == 130 and kept >= 1, stderr
    assert f"the store s.store keeps {kept} result(s), which a re-run reuses; s.nc is not written" in stderr, stderr
    assert not (tmp_path / "s.nc").exists() and "Traceback" not in stderr
