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

import masonryfw as mf

from .archive import verify_archive, write_archive
from .commands import COMMANDS
from .params import Param, parse_param
from .store import Store, content_key
from .sweep import SweepPlan, combine, dask_client, failed_points, plan_sweep, run_sweep

__version__ = mf.__version__
__all__ = [
    "Param", "Store", "SweepPlan", "combine", "content_key", "dask_client", "failed_points", "parse_param",
    "plan_sweep", "run_sweep", "verify_archive", "write_archive",
]


@mf.hookimpl
def masonryfw_commands():
    return list(COMMANDS)
