"""A two-worker dask cluster over loopback, shared by the sweep tests, and the reference solves.

Workers are separate processes (``processes=True``), one thread each: the
points really travel to other interpreters, as on a real cluster.
"""
from __future__ import annotations

import copy
import logging

import pytest
from distributed import Client, LocalCluster

import masonryfw as mf

CASE = "test-12c"


@pytest.fixture(scope="session")
def cluster():
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=logging.ERROR) as local:
        yield local


@pytest.fixture(scope="session")
def client(cluster):
    # Not the default scheduler: xarray would then take its file locks through the cluster in this process.
    with Client(cluster, set_as_default=False) as connected:
        yield connected


@pytest.fixture(scope="session")
def base_spec() -> dict:
    return mf.load_spec(mf.bundled_spec_path(CASE))


@pytest.fixture(scope="session")
def reference_solve(base_spec):
    """The reference: ``solve(settling_start, fixed_end=None, **options)``, one ``mf.solve`` in
    this process on the bundled spec edited by hand (not through the sweep's key paths)."""

    def solve(settling_start: float, fixed_end: float | None = None, **options):
        spec = copy.deepcopy(base_spec)
        spec["supports"]["settling"]["start"] = settling_start
        if fixed_end is not None:
            spec["supports"]["fixed"]["end"] = fixed_end
        return mf.solve(mf.build(spec), "la", options)

    return solve
