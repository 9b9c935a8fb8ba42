"""Benchmark of ``masonryfw diagnose``: scenarios per second on a 300-block facade, against the segment length.

The bundled survey of Facade 1 (322 blocks; datasets/surveys: fdem's cracks of its right 0.3 m settling
6.65 mm, with a levelling) diagnosed with la at ground segments of 0.15, 0.1 (the default, a unit length),
0.075 and 0.05 m: the number of scenarios, the wall time of the whole diagnosis (ground, every scenario, the
scoring, the kept mechanisms), per scenario, and the answer's error against the known cause (the step's
inner edge at 1.2 m, the settlement 6.65 mm). Facade 3 (482 blocks, its own la cracks) adds a larger wall.
Facade 3 again on two forked processes (``--workers 2``), and the re-ranking of Facade 1's best five by fdem
(what the command does by default). Each run twice, the median kept. Run from the benchmarks folder:
``python bench_diagnose.py``. Writes the ``diagnose`` section of docs/benchmarks.md.
"""
from __future__ import annotations

import os
import statistics
import time
from pathlib import Path

import numpy as np
from _report import command_line, write_section

import masonryfw as mf
from masonryfw_diagnose import (
    Survey,
    describe,
    diagnose,
    local_processes,
    prepare,
    read_cracks,
    read_levelling,
    rerank,
    search,
    visible_cracks,
)

SURVEYS = Path(__file__).resolve().parents[1] / "datasets" / "surveys"
SEGMENTS = (0.15, 0.1, 0.075, 0.05)
RUNS = 2
EDGE, SETTLEMENT = 1.2, 6.65e-3


def timed(model, survey, segment, runner=None):
    times, diagnosis = [], None
    for _ in range(RUNS):
        start = time.perf_counter()
        if runner is None:
            diagnosis = diagnose(model, survey, segment=segment)
        else:
            diagnosis = search(prepare(model, survey, segment=segment), runner=runner)
        times.append(time.perf_counter() - start)
    return statistics.median(times), diagnosis


def main() -> None:
    survey = read_cracks(SURVEYS / "facade-1-cracks.geojson")
    survey = survey.with_levelling(read_levelling(SURVEYS / "facade-1-levelling.csv"), "facade-1-levelling.csv")
    facade = mf.open_model("facade-1")
    diagnose(facade, survey, families=("step",), segment=0.3)  # imports and first calls outside the clock
    load = os.getloadavg()
    rows = []
    for segment in SEGMENTS:
        seconds, diagnosis = timed(facade, survey, segment)
        best = diagnosis.best
        tried = len(diagnosis.candidates) + len(diagnosis.failed)
        edge = min(abs(best.table.get(k, np.inf) - EDGE) for k in ("start", "end"))
        rows.append(f"| Facade 1 | {segment:g} | {tried} | {seconds:.1f} | {1e3 * seconds / tried:.0f} | "
                    f"{best.table['profile']} {best.table.get('start', float('nan')):.3g}..{best.table.get('end', float('nan')):.3g} | "
                    f"{1e3 * edge:.0f} | {100 * (best.score.magnitude / SETTLEMENT - 1):+.0f} % | {len(diagnosis.plausible)} |")
        print(rows[-1], flush=True)
    big = mf.open_model("facade-3")
    result = mf.solve(big, "la", {})
    lines = tuple(np.c_[result.interface_x.values[j], result.interface_y.values[j]] for j in visible_cracks(result))
    own = Survey(lines, (None,) * len(lines), tuple(map(str, range(len(lines)))), sources={"unit": "m"})
    seconds, diagnosis = timed(big, own, None)
    tried = len(diagnosis.candidates) + len(diagnosis.failed)
    best = diagnosis.best.table
    rows.append(f"| Facade 3 (own la cracks) | {diagnosis.segment:.3g} | {tried} | {seconds:.1f} | "
                f"{1e3 * seconds / tried:.0f} | {best['profile']} {best.get('start', float('nan')):.3g}.."
                f"{best.get('end', float('nan')):.3g} | - | - | {len(diagnosis.plausible)} |")
    print(rows[-1], flush=True)
    with local_processes(2) as runner:
        seconds, diagnosis = timed(big, own, None, runner)
    best = diagnosis.best.table
    rows.append(f"| Facade 3, 2 processes | {diagnosis.segment:.3g} | {tried} | {seconds:.1f} | "
                f"{1e3 * seconds / tried:.0f} | {best['profile']} {best.get('start', float('nan')):.3g}.."
                f"{best.get('end', float('nan')):.3g} | - | - | {len(diagnosis.plausible)} |")
    print(rows[-1], flush=True)
    diagnosis = diagnose(facade, survey)
    start = time.perf_counter()
    rerank(diagnosis, 5)
    reranking = time.perf_counter() - start
    first = diagnosis.best
    body = f"""
The whole `diagnose` (ground model, every scenario solved by la and scored, the best three solved again
for their mechanisms), median of {RUNS} runs in one process (load average before: {load[0]:.2f},
{load[1]:.2f}, {load[2]:.2f}). Facade 1 (322 blocks) with the bundled survey (datasets/surveys: fdem's
cracks of its right 0.3 m settling 6.65 mm and a levelling): the error of the best candidate's inner edge
against 1.2 m and of its settlement (from the levelling) against 6.65 mm. Facade 3: 482 blocks, its own
la cracks, the default segment, in one process and on two. Then the re-ranking of Facade 1's best five by
fdem to their settlements: {reranking:.1f} s, the best after it """ + describe(first.table) + f""" (fdem's
score {first.reranked:.2f}).

| wall | segment [m] | scenarios | wall time [s] | per scenario [ms] | best | edge error [mm] | settlement error | plausible |
|---|---:|---:|---:|---:|---|---:|---:|---:|
""" + "\n".join(rows) + "\n"
    write_section("diagnose", "Diagnosis (`masonryfw diagnose`)", body)


if __name__ == "__main__":
    command_line(__doc__).parse_args()
    main()
