"""Time building, interface detection and model validation on running-bond walls of growing size.

The benchmarks' running-bond walls (``_walls.running_bond_spec``: R courses of C units of 200 x 50 mm, odd
courses starting with a half unit; a fixed and a settling support), built by ``mf.build`` unchecked.
Each timing is the median of 3 runs. The growth exponent k fits t ~ n^k
(least squares on log-log) over the sizes measured.

Run: ``python benchmarks/bench_interfaces.py``
"""
from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

import masonryfw as mf

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import command_line, write_section  # noqa: E402
from _walls import running_bond_spec  # noqa: E402

WALLS = [(10, 10), (32, 31), (100, 100), (200, 200)]  # (courses, units a course)
REPEATS = 3


def median_time(function, *args) -> tuple[float, object]:
    times, out = [], None
    for _ in range(REPEATS):
        start = time.perf_counter()
        out = function(*args)
        times.append(time.perf_counter() - start)
    return statistics.median(times), out


def growth_exponent(sizes, times) -> float:
    return float(np.polyfit(np.log(sizes), np.log(times), 1)[0])


def main() -> None:
    rows = []
    for courses, units in WALLS:
        t_build, model = median_time(lambda spec: mf.build(spec, validate=False), running_bond_spec(courses, units))
        node_x, node_y, counts = model.node_x.values, model.node_y.values, model.block_node_count.values
        t_detect, found = median_time(mf.detect_interfaces, node_x, node_y, counts)
        t_check, problems = median_time(mf.check, model)
        if problems:
            raise SystemExit(f"benchmark model is invalid: {problems[:3]}")
        rows.append((courses, units, counts.size, len(found["blocks"]), t_detect, t_check, t_build))
        print(f"{counts.size:>7} blocks {len(found['blocks']):>7} interfaces  build {t_build:.4f} s  "
              f"detect {t_detect:.4f} s  check {t_check:.4f} s")
    blocks = [r[2] for r in rows]
    k_detect = growth_exponent(blocks, [r[4] for r in rows])
    k_check = growth_exponent(blocks, [r[5] for r in rows])
    lines = [
        "Running-bond walls (R courses x C units of 200 x 50 mm, half units at the ends of odd courses, a fixed "
        "and a settling support);",
        f"median of {REPEATS} runs. `build` = `build` of the spec without its checks (laying, interfaces, loads),",
        "`detect` = `detect_interfaces`, `check` = `check` of the full model",
        "(all format, polygon, overlap, interface and mechanics checks; the model is valid, no problem found).",
        "",
        "| courses x units | blocks | interfaces | build [s] | detect [s] | check [s] |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    lines += [f"| {r[0]} x {r[1]} | {r[2]:,} | {r[3]:,} | {r[6]:.4f} | {r[4]:.4f} | {r[5]:.4f} |" for r in rows]
    k_detect_large = growth_exponent(blocks[-2:], [r[4] for r in rows[-2:]])
    k_check_large = growth_exponent(blocks[-2:], [r[5] for r in rows[-2:]])
    lines += [
        "",
        f"Growth exponent (t ~ n^k, log-log fit over all sizes): detect k = {k_detect:.2f}, check k = {k_check:.2f};",
        f"between the two largest walls: detect k = {k_detect_large:.2f}, check k = {k_check_large:.2f}",
        "(a fixed per-call cost of reading the dataset dominates `check` on small walls).",
    ]
    write_section("interfaces", "Interface detection and validation", "\n".join(lines))


if __name__ == "__main__":
    command_line(__doc__).parse_args()
    main()
