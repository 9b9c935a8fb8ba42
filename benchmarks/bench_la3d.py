"""Benchmark of la in 3D: time against the block count, the friction pyramid against the cone, and the house.

- The running-bond settlement walls of about 300, 1,000 and 2,400 units (the paper's material) built one block
  thick in 3D (``space = 3``): the build (contacts found from the faces, the checks) and la's solve with a
  pyramid of 8 sides, of 4, and with the cone (Clarabel, the default), against the planar la of the same
  wall; alpha's difference from the planar one.
- The bundled ``house-tunnel`` (a two-storey house over a tunnel, 1,126 blocks): build and solve.
- The same house in units of a half and a third of its own (4,390 and 9,663 blocks), the bundled ``brick-house``
  (20,884 bricks, two leaves, English bond) and ``brick-terrace`` (39,660): the whole process ``masonryfw solve
  SPEC --plugin la`` (start-up, build, solve, write) timed, and its peak memory, with the cone solved by our
  interior point (the default) and, up to ``--clarabel-up-to`` blocks, by Clarabel: alpha's difference between
  the two, and the time's exponent in the blocks.

Whole ``mf.build`` / ``mf.solve`` calls, one run each (the house's solve three times), this process.
Run from the benchmarks folder: ``python bench_la3d.py [--hog] [--only-scale]``. ``--hog`` runs a CPU hog
(``python -c "while True: pass"``) beside the whole-process runs. Writes the ``la3d`` section of
docs/benchmarks.md (``--only-scale``: the whole-process table alone, in the ``la3d-scale`` section).
"""
from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr
from _report import command_line, write_section

import masonryfw as mf

sys.path.insert(0, os.path.dirname(__file__))
from _walls import running_bond_spec  # noqa: E402

SIZES = ((12, 25), (22, 45), (36, 67))  # courses x units per course: about 300, 1,000 and 2,400 units
FRICTION = ((8, "pyramid, 8 sides"), (4, "pyramid, 4 sides"), (0, "cone (default)"))


def timed(function, *args):
    start = time.perf_counter()
    value = function(*args)
    return time.perf_counter() - start, value


def walls() -> list[str]:
    rows = ["| blocks | interfaces (3D) | build 3D | planar la | " + " | ".join(f"la 3D, {name}" for _, name in FRICTION)
            + " |", "|---|---|---|---|" + "---|" * len(FRICTION)]
    for courses, per_course in SIZES:
        spec = running_bond_spec(courses, per_course)
        planar_seconds, planar = timed(mf.solve, mf.build(mf.dump_toml(spec)), "la")
        build_seconds, model = timed(mf.build, mf.dump_toml({**spec, "space": 3}))
        cells = []
        for sides, _ in FRICTION:
            seconds, result = timed(mf.solve, model, "la", {"pyramid_sides": sides})
            alpha, reference = float(result.collapse_multiplier), float(planar.collapse_multiplier)
            cells.append(f"{seconds:.2f} s, {int(result.lp_iterations)} its, alpha {(alpha - reference) / reference:+.1e}")
        rows.append(f"| {model.sizes['block']:,} | {model.sizes['interface']:,} | {build_seconds:.2f} s | "
                    f"{planar_seconds:.2f} s | {' | '.join(cells)} |")
        print(rows[-1], flush=True)
    return rows


def house() -> list[str]:
    build_seconds, model = timed(mf.build, mf.bundled_spec_path("house-tunnel"))
    solves = []
    for _ in range(3):
        seconds, result = timed(mf.solve, model, "la")
        solves.append(seconds)
    numbers = {n.name: n.value for n in mf.key_numbers(result)}
    return [f"house-tunnel: {model.sizes['block']:,} blocks, {model.sizes['interface']:,} interfaces; built and "
            f"checked in {build_seconds:.2f} s, solved by la in {statistics.median(solves):.2f} s (the median of 3: "
            f"{', '.join(f'{s:.2f}' for s in solves)} s; alpha {numbers['alpha']:.4f}, "
            f"{int(numbers['cracked_joints'])} cracked interfaces, {int(numbers['macro_blocks'])} macro-blocks)."]


def house_in_smaller_units(divisor: int, folder: Path) -> Path:
    """``house-tunnel``'s spec with units ``divisor`` times smaller (its openings stay on the finer courses)."""
    spec = dict(mf.load_spec(mf.bundled_spec_path("house-tunnel")))
    building = dict(spec["building"])
    building["unit"] = {k: v / divisor for k, v in building["unit"].items()}
    spec["building"] = building
    spec["settlement"] = {**spec["settlement"], "segment": spec["settlement"]["segment"] / divisor}
    path = folder / f"house-{divisor}.toml"
    path.write_text(mf.dump_toml(spec))
    return path


#: Runs a command and prints its peak resident memory [KiB] on stderr (its own only child: an exact peak per run).
WATCHER = ("import resource, subprocess, sys\n"
           "done = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL)\n"
           "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, file=sys.stderr)\n"
           "sys.exit(done.returncode)\n")


def scale_cases(folder: Path) -> list[str]:
    """The specs of the whole-process table: the house in units of 1, 1/2 and 1/3, the brick house and terrace."""
    return [str(house_in_smaller_units(divisor, folder)) for divisor in (1, 2, 3)] + ["brick-house", "brick-terrace"]


def solved_whole(spec: str, folder: Path, backend: str) -> tuple[float, float, xr.Dataset]:
    """``masonryfw solve SPEC --plugin la --option solver=BACKEND`` as a process: its seconds, peak GiB, result."""
    result = folder / f"{Path(spec).stem}.{backend}.nc"
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", WATCHER, sys.executable, "-m", "masonryfw", "solve", spec,
                           "--plugin", "la", "--option", f"solver={backend}", "--no-progress", "-o", str(result)],
                          capture_output=True, text=True, check=True)
    seconds = time.perf_counter() - start
    return seconds, float(done.stderr.strip().splitlines()[-1]) / 2**20, mf.open_checked(result)


def whole_process(clarabel_up_to: int) -> list[str]:
    rows = ["| model | blocks | cone points | ipm: whole process, peak memory | its, status | clarabel: whole "
            "process, peak memory | its | alpha (ipm) | ipm - clarabel |", "|---|---|---|---|---|---|---|---|---|"]
    sizes, times = [], []
    with tempfile.TemporaryDirectory() as folder:
        for spec in scale_cases(Path(folder)):
            seconds, peak, ours = solved_whole(spec, Path(folder), "ipm")
            blocks, alpha = ours.sizes["block"], float(ours.collapse_multiplier)
            sizes.append(blocks)
            times.append(seconds)
            cells = "not run (4.5x ipm's time at 9,663 blocks)", "", ""
            if blocks <= clarabel_up_to:
                other_seconds, other_peak, other = solved_whole(spec, Path(folder), "clarabel")
                reference = float(other.collapse_multiplier)
                cells = (f"{other_seconds:.1f} s, {other_peak:.2f} GiB", f"{int(other.lp_iterations)}",
                         f"{(alpha - reference) / reference:+.1e}")
            name = Path(spec).stem if spec.endswith(".toml") else spec
            rows.append(f"| {name} | {blocks:,} | {ours.sizes['interface_node']:,} | {seconds:.1f} s, {peak:.2f} GiB | "
                        f"{int(ours.lp_iterations)}, {ours.lp_status.item()} | {cells[0]} | {cells[1]} | {alpha:.6f} | "
                        f"{cells[2]} |")
            print(rows[-1], flush=True)
    slope = np.polyfit(np.log(sizes), np.log(times), 1)[0]
    return rows + ["", f"Time against blocks (ipm, whole process, least squares in logs over the {len(sizes)} models): "
                       f"blocks^{slope:.2f}."]


def main() -> None:
    parser = command_line(__doc__)
    parser.add_argument("--hog", action="store_true", help="a CPU hog beside the whole-process runs")
    parser.add_argument("--only-scale", action="store_true", help="the whole-process table alone")
    parser.add_argument("--clarabel-up-to", type=int, default=10_000, help="blocks up to which Clarabel runs too")
    args = parser.parse_args()
    hog = subprocess.Popen([sys.executable, "-c", "while True: pass"]) if args.hog else None
    try:
        scale = whole_process(args.clarabel_up_to)
    finally:
        if hog is not None:
            hog.kill()
    load = "with a CPU hog (`python -c \"while True: pass\"`) beside each run" if args.hog else "quiet"
    scale_text = ["The cone at scale, `masonryfw solve SPEC --plugin la` as a user runs it (whole process, one run "
                  f"each, {load}):", "", *scale]
    if args.only_scale:
        write_section("la3d-scale" + ("-hog" if args.hog else ""), "la in 3D at scale: our interior point on the cone"
                      + (", beside a CPU hog" if args.hog else ""), "\n".join(scale_text))
        return
    body = ["The running-bond walls one block thick in 3D against the planar la (one run each; alpha relative to the "
            "planar la's):", "", *walls(), "", *house(), "", *scale_text]
    write_section("la3d", "la in 3D: time against size, the pyramid against the cone, a house", "\n".join(body))


if __name__ == "__main__":
    main()
