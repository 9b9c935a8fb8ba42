"""``sweep``: parameter sweeps on dask and reproducible archives (CLI commands ``sweep`` and ``archive``).

Registration only; the work lives in :mod:`.params` (keys and values),
:mod:`.tasks` (one point on a worker), :mod:`.store` (the content-addressed
result store), :mod:`.sweep` (planning, running, combining) and
:mod:`.archive`. The core stays free of dask: it is imported only when a sweep runs.

From Python::

    from masonryfw_sweep import dask_client, plan_sweep, run_sweep
    plan = plan_sweep("test-12c", "la", ["supports.settling.start=0.5:0.9:0.1"])
    with dask_client(workers=2) as client:
        sweep = run_sweep(plan, client, store="12c.store")
"""
from __future__ import annotations

import lazy_loader

import masonryfw.plugin_api as mfp

from .commands import available_commands

#: The Python API, imported on first access (lazy_loader, Scientific Python's SPEC 1): registering the plugin stays cheap.
# no __dir__: pluggy finds the hook implementations by dir(module)
__getattr__, _, __all__ = lazy_loader.attach(__name__, submod_attrs={
    "archive": ["verify_archive", "write_archive"],
    "params": ["Param", "parse_param", "point_assignments", "with_values"],
    "store": ["Store", "content_key"],
    "tasks": ["run_point"],
    "sweep": ["SweepPlan", "combine", "dask_client", "failed_points", "plan_sweep", "run_sweep"],
})


@mfp.hookimpl
def masonryfw_commands():
    return available_commands()
