"""Benchmark of fdem over a settlement trough: Facade 1 to S_max = 20 mm against its single settling support.

A: the bundled ``facade-1-trough`` (a Gaussian trough, i = 0.25 m, under the middle pier, on a
continuous ground of the default quarter-unit segments); B: the bundled ``facade-1`` (one settling support).
Both run to 20 mm (``plateau_tolerance=0``) at the default loading rate, in A B A B ... pairs
in this one process (so a drift of the shared machine's speed hits both alike); the ratio is
taken pair by pair. Time against error: the trough again at half the loading rate (twice the
steps), its minimum reaction and widest crack as the reference of the default run's.
Run from the benchmarks folder: ``python bench_settlements.py``. Writes the ``settlements``
section of docs/benchmarks.md.
"""
from __future__ import annotations

import os
import statistics
import time

from _report import command_line, write_section

import masonryfw as mf
import masonryfw.plugin_api as mfp

PAIRS = 3
OPTIONS = {"settlement": 0.02, "plateau_tolerance": 0.0}


def timed(model, options):
    start = time.perf_counter()
    result = mf.solve(model, "fdem", options)
    return time.perf_counter() - start, result


def numbers(result) -> dict:
    return {n.name: n.value for n in mf.key_numbers(result)}


def main() -> None:
    trough = mf.build(mf.bundled_spec_path("facade-1-trough"))
    single = mf.build(mf.bundled_spec_path("facade-1"))
    timed(single, {"settlement": 0.001})  # compile (or load) the kernels outside the clock
    load = os.getloadavg()
    a_times, b_times, ratios = [], [], []
    for _ in range(PAIRS):
        a, result_a = timed(trough, OPTIONS)
        b, result_b = timed(single, OPTIONS)
        a_times.append(a)
        b_times.append(b)
        ratios.append(a / b)
    slow, reference = timed(trough, {**OPTIONS, "loading_rate": 1e-3})
    default, fine = numbers(result_a), numbers(reference)
    moving = int((trough.block_role.values == mfp.flags("block_role")["moving_support"]).sum())
    body = f"""
fdem (rigid blocks) to S_max = 20 mm, `plateau_tolerance=0`, {PAIRS} A/B pairs in one process
(load average before: {load[0]:.2f}, {load[1]:.2f}, {load[2]:.2f}). A: `facade-1-trough`
({moving} settling segments of a continuous ground); B: `facade-1` (one settling support).

| run | median [s] | min .. max [s] | steps |
|---|---:|---:|---:|
| A: trough | {statistics.median(a_times):.2f} | {min(a_times):.2f} .. {max(a_times):.2f} | {result_a.attrs['fdem_steps']} |
| B: single support | {statistics.median(b_times):.2f} | {min(b_times):.2f} .. {max(b_times):.2f} | {result_b.attrs['fdem_steps']} |

Median A/B ratio (pair by pair): **{statistics.median(ratios):.3f}** (pairs: {', '.join(f'{r:.3f}' for r in ratios)}).
The step count is the same: it is set by the target and the loading rate, not by the supports;
the trough's cost per step is that of its extra support blocks and their contacts.

Time against error (the trough at half the loading rate as the reference, {slow:.1f} s):

| quantity | default rate | half rate | difference |
|---|---:|---:|---:|
| minimum reaction [N] | {default['minimum_reaction']:.2f} | {fine['minimum_reaction']:.2f} | {abs(default['minimum_reaction'] - fine['minimum_reaction']) / fine['dead_reaction']:.2%} of R0 |
| widest crack to 20 mm [mm] | {1e3 * default['crack_width']:.3f} | {1e3 * fine['crack_width']:.3f} | {abs(default['crack_width'] - fine['crack_width']) / fine['crack_width']:.2%} |
| largest damage category to 20 mm | {int(default['damage_category'])} | {int(fine['damage_category'])} | |
"""
    write_section("settlements", "Settlement troughs (fdem)", body)
    print(body)


if __name__ == "__main__":
    command_line(__doc__).parse_args()
    main()
