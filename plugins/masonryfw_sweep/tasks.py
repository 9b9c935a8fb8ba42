"""One sweep point, as run on a dask worker: build, look up the store, solve, store, summarise.

:func:`run_point` never raises: a failure becomes a record with a status and
its message, so one bad point cannot stop the sweep. It returns only small
scalars (never datasets), which keeps the scheduler's memory flat however many
points a sweep has.
"""
from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import Any

import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .params import KeyPath, with_values
from .store import Store, content_key, model_hash

#: Status flags of a point; a failure's class names the stage that failed.
STATUS = {"ok": 0, "spec_error": 1, "model_error": 2, "solve_error": 3, "plugin_error": 4, "error": 5}
_STATUS_OF_ERROR = (
    (mf.SpecError, "spec_error"),
    (mf.ModelError, "model_error"),
    (mf.SolveError, "solve_error"),
    (mf.PluginError, "plugin_error"),
)

WALL_TIME = "wall_time_s"


def status_of(exc: BaseException) -> str:
    """The status name of a failure: the masonryfw error class, else ``error``."""
    return next((status for kind, status in _STATUS_OF_ERROR if isinstance(exc, kind)), "error")


def failure_message(exc: BaseException) -> str:
    """The message of a failure; errors that are not masonryfw's also name their type."""
    return str(exc) if isinstance(exc, mf.MasonryError) else f"{type(exc).__name__}: {exc}"


def scalar_outputs(result: xr.Dataset) -> dict[str, tuple[Any, dict]]:
    """``{name: (value, attrs)}``: the result's key numbers (:func:`masonryfw.key_numbers`) and the wall time."""
    out = {n.name: (n.value, {"units": n.units, "long_name": n.long_name}) for n in mf.key_numbers(result)}
    out[WALL_TIME] = (float(result.attrs[WALL_TIME]), {"units": "s", "long_name": "wall time of the solve"})
    return out


def run_point(
    base_spec: Mapping,
    assignments: Sequence[tuple[KeyPath, Any]],
    solver_name: str,
    options: Mapping[str, Any],
    store_root: str,
    provenance: Mapping[str, Any],
) -> dict:
    """Solve one point and return its record (status, message, key, result file, scalars, timing).

    A result already in the store under the point's content key, and verified,
    is reused instead of solved (``reused`` is True).
    """
    import dask  # present wherever this runs: on a dask worker

    clock = time.perf_counter()
    record: dict[str, Any] = {"status": "ok", "message": "", "key": "", "result": "", "reused": False, "scalars": {}}
    # xarray picks its netCDF write lock after the active dask scheduler: on a worker that is the
    # cluster, whose lock costs a scheduler round trip per variable written (about 1 s per file).
    # A point writes only its own files (temporary name, then rename), so a local lock is enough.
    with dask.config.set(scheduler="synchronous"):
        _solve_point(record, base_spec, assignments, solver_name, options, store_root, provenance)
    record["task_time_s"] = time.perf_counter() - clock
    return record


def _solve_point(record: dict, base_spec, assignments, solver_name, options, store_root, provenance) -> None:
    """Fill ``record`` (see :func:`run_point`) for one point; failures become its status and message."""
    try:
        model = mf.build(with_values(base_spec, assignments))
        model_sha256 = model_hash(model)
        key = content_key(model_sha256, solver_name, mfp.solver_version(solver_name), mfp.core_version(),
                          options)
        store = Store(store_root)
        result = store.load_verified(key)
        record["reused"] = result is not None
        if result is None:
            result = mf.solve(model, solver_name, options)
            store.put(key, model_sha256, result, provenance)
        record.update(key=key, result=str(store.result_path(key)), scalars=scalar_outputs(result))
    except Exception as exc:  # recorded, never raised: see the module docstring
        record.update(status=status_of(exc), message=failure_message(exc))
