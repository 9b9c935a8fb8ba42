"""The share of this machine's cores a run gets now, for solvers' estimates and their thread counts.

A 2-core machine beside another job gives a run a fraction of a core: the scheduler shares the cores evenly
between the runnable tasks. The other work is read as the tasks runnable now, not the one-minute load average,
which lags a minute behind: it still counts a job that ended a minute ago and barely counts one that started a
second ago (measured: the 10,067-block wall run right after another job was estimated at 407 s from the
average, 210 s from the runnable tasks, and took 188 s).
"""
from __future__ import annotations

import os
import time

#: Samples of the runnable tasks whose median is the machine's load now (:func:`machine_load`), and their spacing.
LOAD_SAMPLES = 5
LOAD_SAMPLE_SECONDS = 0.002


def cores() -> int:
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def free_cores(cores: int, load: float) -> float:
    """Cores the machine's other work leaves (``load``: :func:`machine_load`, before the run)."""
    return max(cores - load, 0.0)


def machine_load() -> float:
    """The other work on the machine now: the median, over a few milliseconds, of the tasks the kernel has
    runnable, less this one (Linux's ``/proc/loadavg``); elsewhere the one-minute load average (0 where the
    system does not tell). The average lags a minute behind: just after another job ends it still counts it."""
    samples = []
    for _ in range(LOAD_SAMPLES):
        running = runnable_tasks()
        if running is None:
            break
        samples.append(running - 1)
        time.sleep(LOAD_SAMPLE_SECONDS)
    if samples:
        return float(sorted(samples)[len(samples) // 2])
    try:
        return os.getloadavg()[0]
    except OSError:
        return 0.0


def runnable_tasks() -> int | None:
    """The tasks running or ready to run now, this one included (None where ``/proc/loadavg`` is missing)."""
    try:
        with open("/proc/loadavg") as stream:
            return int(stream.read().split()[3].split("/")[0])
    except (OSError, IndexError, ValueError):
        return None


def core_share(cores: int, load: float) -> float:
    """The share of a core one busy thread of the run gets: 1 while a core is free, else cores / (load + 1)
    (the scheduler shares the cores evenly; measured with fdem on Facade 3 beside two busy processes: 1.5x
    slower, as 2 / 3 says)."""
    return 1.0 if free_cores(cores, load) >= 1.0 else cores / (load + 1.0)
