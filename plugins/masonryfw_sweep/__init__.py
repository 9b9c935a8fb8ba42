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

import importlib

import masonryfw as mf

from .commands import available_commands

#: The Python API, imported on first access (PEP 562): registering the plugin stays cheap.
_PUBLIC = {
    "Param": "params", "parse_param": "params", "Store": "store", "content_key": "store",
    "SweepPlan": "sweep", "combine": "sweep", "dask_client": "sweep", "failed_points": "sweep",
    "plan_sweep": "sweep", "run_sweep": "sweep", "verify_archive": "archive", "write_archive": "archive",
}
__all__ = sorted(_PUBLIC)


def __getattr__(name: str):
    if name in _PUBLIC:
        return getattr(importlib.import_module(f".{_PUBLIC[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@mf.hookimpl
def masonryfw_commands():
    return available_commands()
