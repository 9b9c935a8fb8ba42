"""Benchmark of la in 3D: time against the block count, the friction pyramid against the cone, and the house.

- The running-bond settlement walls of about 300, 1,000 and 2,400 units (the paper's material) built one block
  thick in 3D (``space = 3``): the build (contacts found from the faces, the checks) and la's solve with a
  pyramid of 8 sides, of 4, and with the cone (Clarabel, the default), against the planar la of the same
  wall; alpha's difference from the planar one.
- The bundled ``house-tunnel`` (a two-storey house over a tunnel, 1,126 blocks): build and solve.
- The same house in units of a half and a third of its own (about 4,400 and 9,800 blocks): the whole process
  ``masonryfw solve SPEC --plugin la`` (start-up, build, solve, write) timed, and its peak memory.

Whole ``mf.build`` / ``mf.solve`` calls, one run each (the house's solve three times), this process.
Run from the benchmarks folder: ``python bench_la3d.py``. Writes the ``la3d`` section of docs/benchmarks.md.
"""
from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

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


def whole_process() -> list[str]:
    rows = ["| units | blocks | whole process | peak memory | alpha |", "|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as folder:
        for divisor in (1, 2, 3):
            spec = house_in_smaller_units(divisor, Path(folder))
            result = spec.with_suffix(".nc")
            start = time.perf_counter()
            done = subprocess.run([sys.executable, "-c", WATCHER, sys.executable, "-m", "masonryfw", "solve", str(spec),
                                   "--plugin", "la", "--no-progress", "-o", str(result)],
                                  capture_output=True, text=True, check=True)
            seconds = time.perf_counter() - start
            peak = float(done.stderr.strip().splitlines()[-1]) / 2**20
            solved = mf.open_checked(result)
            rows.append(f"| {0.44 / divisor:.3g} x {0.22 / divisor:.3g} m | {solved.sizes['block']:,} | {seconds:.1f} s | "
                        f"{peak:.2f} GiB | {float(solved.collapse_multiplier):.4f} |")
            print(rows[-1], flush=True)
    return rows


def main() -> None:
    command_line(__doc__).parse_args()
    body = ["The running-bond walls one block thick in 3D against the planar la (one run each; alpha relative to the "
            "planar la's):", "", *walls(), "",
            *house(), "", "The house in smaller units, `masonryfw solve SPEC --plugin la` as a user runs it (the cone):",
            "", *whole_process()]
    write_section("la3d", "la in 3D: time against size, the pyramid against the cone, a house", "\n".join(body))


if __name__ == "__main__":
    main()
