"""Scale: every solver on running-bond walls of 300 to 10,000 units, as a user runs them.

The walls keep the proportions of the big-wall targets (8 m x 3 m for 2,400 units of 200 x 50 mm: 40 units
a course, 60 courses; the right 40 % of the base settling); ``courses = sqrt(1.5 n)``.
Each solve is one CLI process (``masonryfw solve WALL.nc --plugin P``, solver defaults),
timed from outside with its peak resident memory (``os.wait4``); one that outlives the
time limit is interrupted with Ctrl-C (SIGINT), which keeps an incremental solver's history
(exit 130), so the table says how far it got. Key numbers come from the result file.

    python bench_scale.py [--sizes 300,1000,2400,10000] [--solvers la,fdem,jmm] [--limit 600] [--la-sizes 40000]

Writes the ``scale`` section of docs/benchmarks.md.
"""
from __future__ import annotations

import argparse
import math
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _report import write_section
from _walls import scale_spec

import masonryfw as mf

SIZES = (300, 1_000, 2_400, 10_000)
SOLVERS = ("la", "fdem", "jmm", "jmm-limit")


def run(command: list[str], limit: float) -> tuple[float, float, int]:
    """Wall seconds, peak RSS [MiB] and exit status of ``command``; SIGINT after ``limit`` seconds."""
    start = time.perf_counter()
    # SIGINT back to its default in the child: started from a background job it would inherit "ignored",
    # and Python would then install no KeyboardInterrupt handler (a Ctrl-C that never arrives)
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    interrupted = False
    while True:
        pid, status, usage = os.wait4(process.pid, os.WNOHANG)
        if pid:
            break
        if not interrupted and time.perf_counter() - start > limit:
            process.send_signal(signal.SIGINT)
            interrupted = True
        time.sleep(0.05)
    code = os.waitstatus_to_exitcode(status)
    return time.perf_counter() - start, usage.ru_maxrss / 1024, code


def numbers(path: Path) -> str:
    """The result's key numbers, briefly."""
    if not path.exists():
        return "no result"
    with mf.open_dataset(path) as result:
        result.load()
    shown = {k.name: k.value for k in mf.key_numbers(result)}
    parts = []
    if "alpha" in shown:
        parts.append(f"alpha {shown['alpha']:.4f}")
    for name in ("collapse_reaction", "minimum_reaction", "plateau_reaction"):
        if name in shown:
            parts.append(f"{name.split('_')[0]} {shown[name] / 1e3:.2f} kN")
    if "step_settlement" in result and result.step_settlement.size:
        parts.append(f"to {1e3 * float(result.step_settlement.values[-1]):.2f} mm")
    if int(result.attrs.get("interrupted", 0)):
        parts.append("interrupted")
    return ", ".join(parts)


def growth(finished: dict[str, list[tuple[int, float]]]) -> str:
    """``k`` of ``time ~ blocks^k`` between consecutive finished runs of each solver."""
    parts = []
    for solver, runs in finished.items():
        steps = [f"{a:,}-{b:,}: {math.log(tb / ta) / math.log(b / a):.2f}"
                 for (a, ta), (b, tb) in zip(runs, runs[1:])]
        if steps:
            parts.append(f"{solver} " + ", ".join(steps))
    return "; ".join(parts) or "fewer than two finished sizes"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)))
    parser.add_argument("--solvers", default=",".join(SOLVERS))
    parser.add_argument("--limit", type=float, default=600.0, help="seconds before a solve is interrupted")
    parser.add_argument("--la-sizes", default="40000", help="more sizes, for la alone")
    args = parser.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    solvers = args.solvers.split(",")
    la_sizes = [int(s) for s in args.la_sizes.split(",") if s]
    load = os.getloadavg()
    rows = []
    finished: dict[str, list[tuple[int, float]]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for size in sizes + la_sizes:
            if size not in sizes and "la" not in solvers:
                continue
            spec = Path(tmp, f"wall-{size}.toml")
            spec.write_text(mf.dump_toml(scale_spec(size)))
            model = Path(tmp, f"wall-{size}.nc")
            seconds, peak, code = run([sys.executable, "-m", "masonryfw", "build", str(spec), "-o", str(model)],
                                      args.limit)
            with mf.open_dataset(model) as built:
                wall = mf.checked_model(built.load())
            blocks = wall.sizes["block"]
            print(f"{size}: {blocks} blocks, built in {seconds:.1f} s", flush=True)
            for solver in solvers if size in sizes else ["la"]:
                out = Path(tmp, f"wall-{size}.{solver}.nc")
                expected = mf.estimate(wall, solver)
                seconds, peak, code = run([sys.executable, "-m", "masonryfw", "solve", str(model), "--plugin",
                                           solver, "-o", str(out), "--no-progress"], args.limit)
                rows.append(f"| {size:,} | {blocks:,} | {solver} | {seconds:.1f} | {expected.seconds:.1f} | {peak:.0f} "
                            f"| {expected.memory / 2**20:.0f} | {code} | {numbers(out)} |")
                print(rows[-1], flush=True)
                if code == 0:
                    finished.setdefault(solver, []).append((blocks, seconds))
    body = f"""
Running-bond walls of 200 x 50 mm units in the proportions of the big-wall targets (2,400 units: 8 m x 3 m; the right
40 % of the base settling; gamma 18 kN/m3, mu = tan 30 deg, E = 3 GPa), each solver at its defaults,
one CLI process per solve, timed from outside with its peak memory; interrupted (Ctrl-C, the history
kept, exit 130) after {args.limit:.0f} s. "Estimated": what the solver's `estimate` hook said before the
run (the CLI prints it for runs over a minute; fdem's is to the target settlement, jmm's assumes 500
Newton iterations). Load average before: {load[0]:.2f}, {load[1]:.2f}, {load[2]:.2f}.

| units | blocks | solver | wall time [s] | estimated [s] | peak memory [MiB] | estimated [MiB] | exit | key numbers |
|---:|---:|---|---:|---:|---:|---:|---:|---|
{chr(10).join(rows)}

Growth of the whole-process time (about 1 s of it is start-up) with the number of blocks, time ~ blocks^k between consecutive finished
sizes: {growth(finished)}.
"""
    write_section("scale", "Scale: every solver against the number of units", body)
    print(body)


if __name__ == "__main__":
    main()
