"""The share of the machine's cores a run gets now (masonryfw.runtime.cores): the load is the tasks runnable now."""
from __future__ import annotations

import subprocess
import sys

import pytest

from masonryfw.runtime import cores


@pytest.mark.skipif(cores.runnable_tasks() is None, reason="needs Linux's /proc/loadavg")
def test_the_load_counts_processes_started_a_moment_ago():
    """Two spinning processes just started: the one-minute average has barely moved, the load now says two. Each
    says when it spins (a busy machine may take seconds to start a Python), so nothing waits on a clock."""
    spinners = [subprocess.Popen([sys.executable, "-c", "print(flush=True)\nwhile True: pass"], stdout=subprocess.PIPE)
                for _ in range(2)]
    try:
        for spinner in spinners:
            spinner.stdout.readline()
        assert cores.machine_load() >= 2
    finally:
        for spinner in spinners:
            spinner.kill()
            spinner.wait()


def test_without_proc_the_load_is_the_one_minute_average(monkeypatch):
    monkeypatch.setattr(cores, "runnable_tasks", lambda: None)
    monkeypatch.setattr(cores.os, "getloadavg", lambda: (1.25, 0.5, 0.25))
    assert cores.machine_load() == 1.25


def test_a_busy_machine_gives_a_share_of_a_core():
    """A free core: a whole one; two cores and two other runnable tasks: each of three shares 2/3 of a core."""
    assert cores.core_share(2, load=0.5) == 1.0
    assert cores.core_share(2, load=2.0) == pytest.approx(2 / 3)
    assert cores.free_cores(2, load=3.0) == 0.0
