"""Sweeps on dask: speed-up of 1 vs 2 workers, per-task overhead, scheduler memory of 1,000 points.

Run ``python benchmarks/bench_sweep.py``; writes the ``sweep`` section of docs/benchmarks.md.

1. 40 LA solves of Test 12C (settling support start 0.50..0.89 m) on a local
   cluster of 1 and of 2 worker processes (1 thread each), workers warmed up
   (imports and plugin loading done) before the clock starts, a fresh store
   each time so every point is solved.
2. The same 40 points in this process: ``mf.solve`` alone, and the sweep's
   own task function (build, content hash, solve, atomic store writes) called
   directly. The per-task overhead of dask is the 1-worker time per point minus
   the in-process task time.
3. 1,000 points of the ``statics`` example solver on a 4-unit wall, on a
   cluster started as separate processes (``dask scheduler`` and
   ``dask worker``, as an existing cluster would be, reached through
   ``--scheduler``): the scheduler's RSS before and after, and its peak RSS
   during the sweep (Linux ``VmHWM``, reset before it), read on the scheduler
   with ``client.run_on_scheduler``.
"""
from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import masonryfw as mf
from masonryfw_sweep import dask_client, plan_sweep, point_assignments, run_point, run_sweep, with_values

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import command_line, write_section  # noqa: E402

LA_POINTS = "supports.settling.start=0.5:0.89:0.01"  # 40 values
MEMORY_POINTS = "material.unit_weight=10000:19990:10"  # 1,000 values
SMALL_WALL = """
title = "Small wall"
[wall]
width = 0.4
height = 0.1
thickness = 0.1
[unit]
length = 0.2
height = 0.05
[material]
unit_weight = 12000.0
friction_angle = 30.0
[supports.fixed]
kind = "fixed"
start = 0.0
end = 0.2
[supports.settling]
kind = "moving"
start = 0.2
end = 0.4
[loading]
type = "settlement"
"""


def _warm(client) -> None:
    """Import masonryfw and load the plugins on every worker, so that the timings are of the work."""
    client.run(lambda: mf.get_solver("la").name)


def timed_sweep(plan, workers: int, folder: Path) -> tuple[float, float, object]:
    """``(wall seconds, CPU seconds of the workers, sweep dataset)`` of one run on a fresh store."""
    with dask_client(workers=workers) as client:
        _warm(client)
        cpu = sum(client.run(_cpu_seconds).values())
        start = time.perf_counter()
        sweep = run_sweep(plan, client, folder / f"store-{workers}", folder)
        wall = time.perf_counter() - start
        return wall, sum(client.run(_cpu_seconds).values()) - cpu, sweep


def in_process(plan, folder: Path) -> dict:
    """Mean wall and CPU seconds per point of ``mf.solve`` alone and of the sweep task, in this process."""
    mf.solve(mf.build(plan.spec), plan.solver, plan.options)  # first call: imports and plugin loading
    times = {"solve_wall": [], "solve_cpu": [], "task_wall": [], "task_cpu": []}
    for indices in plan.points:
        assignments, _ = point_assignments(plan.params, indices)
        model = mf.build(with_values(plan.spec, assignments))
        wall, cpu = time.perf_counter(), time.process_time()
        mf.solve(model, plan.solver, plan.point_options(indices))
        times["solve_wall"].append(time.perf_counter() - wall)
        times["solve_cpu"].append(time.process_time() - cpu)
        wall, cpu = time.perf_counter(), time.process_time()
        record = run_point(plan.spec, assignments, plan.solver, plan.point_options(indices),
                           str(folder / "in-process"), {})
        times["task_wall"].append(time.perf_counter() - wall)
        times["task_cpu"].append(time.process_time() - cpu)
        assert record["status"] == "ok" and not record["reused"], record
    return {name: statistics.mean(values) for name, values in times.items()}


def _reset_peak() -> None:
    """Reset this process's peak RSS (Linux: ``VmHWM``), so that the next peak is the sweep's."""
    Path("/proc/self/clear_refs").write_text("5")


def _memory() -> dict:
    """RSS and peak RSS (``VmHWM``) of this process, in bytes."""
    fields = dict(line.split(":", 1) for line in Path("/proc/self/status").read_text().splitlines() if ":" in line)
    kib = {name: int(fields[name].split()[0]) * 1024 for name in ("VmRSS", "VmHWM")}
    return {"rss": kib["VmRSS"], "peak": kib["VmHWM"]}


def _cpu_seconds() -> float:
    """User + system CPU time of this process so far."""
    times = os.times()
    return times.user + times.system


def scheduler_memory(folder: Path) -> dict:
    """Scheduler RSS around a 1,000-point ``statics`` sweep on a cluster of separate processes."""
    scheduler_file = folder / "scheduler.json"
    dask = str(Path(sys.executable).with_name("dask"))
    processes = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                   "--scheduler-file", str(scheduler_file)], stderr=subprocess.DEVNULL)]
    try:
        while not scheduler_file.exists():
            time.sleep(0.2)
        processes.append(subprocess.Popen([dask, "worker", "--scheduler-file", str(scheduler_file), "--nworkers", "2",
                                           "--nthreads", "1", "--no-dashboard"], stderr=subprocess.DEVNULL))
        address = json.loads(scheduler_file.read_text())["address"]
        spec = folder / "small.toml"
        spec.write_text(SMALL_WALL)
        plan = plan_sweep(str(spec), "statics", [MEMORY_POINTS])
        with dask_client(address) as client:
            client.wait_for_workers(2)
            _warm(client)
            client.run_on_scheduler(_reset_peak)
            before = client.run_on_scheduler(_memory)
            start = time.perf_counter()
            sweep = run_sweep(plan, client, folder / "store-memory", folder)
            elapsed = time.perf_counter() - start
            after = client.run_on_scheduler(_memory)
        assert int((sweep.status == 0).sum()) == sweep.status.size == 1000
        return {"points": sweep.status.size, "seconds": elapsed, "before": before, "after": after}
    finally:
        for process in reversed(processes):
            process.terminate()
            process.wait(timeout=30)


def main() -> None:
    load_before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        plan = plan_sweep("test-12c", "la", [LA_POINTS])
        assert len(plan.points) == 40
        one, cpu_one, sweep_one = timed_sweep(plan, 1, folder)
        two, cpu_two, sweep_two = timed_sweep(plan, 2, folder)
        assert (sweep_one.alpha == sweep_two.alpha).all()
        local = in_process(plan, folder)
        memory = scheduler_memory(folder)
    load_after = os.getloadavg()[0]

    n = len(plan.points)
    mib = 2.0**20
    per_point_one = one / n
    body = f"""
**Speed-up.** {n} LA solves of Test 12C (72 units; `--param {LA_POINTS}`), each point a dask task
(build, content hash, solve, atomic store writes), local cluster of worker processes with 1 thread
each, workers warmed up first (cluster start-up and the workers' first imports are not timed;
they cost about 5 s and 5-10 s once per sweep on this machine). Load average (1 min) of the
machine when the run started / ended: {load_before:.1f} / {load_after:.1f} on {os.cpu_count()} cores
(other jobs were running: every time is an upper bound).

| workers | wall time [s] | per point [s] | speed-up | workers' CPU time [s] | CPU / (wall x workers) |
|---:|---:|---:|---:|---:|---:|
| 1 | {one:.2f} | {one / n:.3f} | 1.00 | {cpu_one:.2f} | {cpu_one / one:.0%} |
| 2 | {two:.2f} | {two / n:.3f} | {one / two:.2f} | {cpu_two:.2f} | {cpu_two / (2 * two):.0%} |

The last column is the share of their cores the workers used; below 100 % they waited: for a
core (other jobs were running), for the disk (every point fsyncs its result and its record) or
for the scheduler. The speed-up is what this machine gave at the time, not what two idle cores give.

**Per-task overhead.** The same {n} points in this process (mean per point, wall / CPU):
`mf.solve` alone {local['solve_wall']:.3f} / {local['solve_cpu']:.3f} s; the sweep's task function
called directly (build, content hash, `mf.solve`, result written with `mf.save`, record written)
{local['task_wall']:.3f} / {local['task_cpu']:.3f} s, so the store and the build cost
{(local['task_cpu'] - local['solve_cpu']) * 1e3:.0f} ms of CPU per point on top of the solve.
Through dask with 1 worker a point takes {per_point_one:.3f} s of wall time and
{cpu_one / n:.3f} s of the worker's CPU: dask adds {(cpu_one / n - local['task_cpu']) * 1e3:.0f} ms of
worker CPU per task (serialisation, the worker's own threads), and
{(per_point_one - local['task_wall']) * 1e3:.0f} ms of wall time per task (waiting included: in this process
too the task spends {1 - local['task_cpu'] / local['task_wall']:.0%} of its wall time off the CPU).

**Scheduler memory.** {memory['points']:,} points of the `statics` example solver on a 4-unit wall,
on a cluster of separate processes (`dask scheduler`, `dask worker --nworkers 2 --nthreads 1`,
reached like `--scheduler`), {memory['seconds']:.1f} s in all ({memory['seconds'] / memory['points'] * 1e3:.0f} ms per point
with 2 workers). Scheduler RSS before the sweep {memory['before']['rss'] / mib:.0f} MiB, after it
{memory['after']['rss'] / mib:.0f} MiB, peak during the sweep {memory['after']['peak'] / mib:.0f} MiB
(`VmHWM`, reset just before the sweep): {(memory['after']['peak'] - memory['before']['rss']) / memory['points'] / 1024:.0f} KiB
per point at the peak, while all points are queued. A task returns only its scalars and status (never a dataset), and
each finished future is released at once, so the scheduler holds no results.
"""
    write_section("sweep", "Parameter sweeps on dask (`masonryfw sweep`)", body)
    print(body)


if __name__ == "__main__":
    command_line(__doc__).parse_args()
    main()
