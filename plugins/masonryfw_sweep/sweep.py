"""Plan a sweep (every check before any work), run its points as dask tasks, combine the records.

The combined result is ONE dataset: the swept keys are its dimensions (grid)
or coordinates along ``point`` (zip); every scalar output of the solver is a
variable over them, with each point's ``status``, ``message``, store ``key``,
``result_path`` (relative to the sweep file's folder), ``from_store`` and
``task_time_s``.

dask is imported only inside the functions that need it: the ``masonryfw`` CLI
loads every plugin on every command, and ``import distributed`` alone takes
about a second.
"""
from __future__ import annotations

import contextlib
import logging
import os
import secrets
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .params import (
    Param,
    check_names,
    check_spec_params,
    parse_param,
    point_assignments,
    point_indices,
    resolve_option_params,
)
from .tasks import STATUS, failure_message, run_point, status_of

ZIP_DIM = "point"
_RESERVED = {"status", "message", "key", "result_path", "from_store", "task_time_s", ZIP_DIM}


@dataclass(frozen=True)
class SweepPlan:
    """A checked sweep: base spec, solver, options, parameters and the points."""

    spec: dict
    spec_text: str
    solver: str
    solver_version: str
    options: dict
    params: tuple[Param, ...]
    zipped: bool
    shape: tuple[int, ...]
    points: tuple[tuple[int, ...], ...]

    def point_options(self, indices: tuple[int, ...]) -> dict:
        """The resolved options of one point: the base options with its swept options."""
        return {**self.options, **point_assignments(self.params, indices)[1]}


def _spec_source(spec: str | os.PathLike | dict):
    """``(spec dict, spec text)`` of a path, a bundled case name, TOML text or a dict."""
    if isinstance(spec, dict):
        return mf.load_spec(spec), mf.dump_toml(spec)
    if isinstance(spec, str) and ("=" in spec or "\n" in spec):  # TOML text (may be too long for a file name)
        return mf.load_spec(spec), spec
    if Path(spec).is_file():
        return mf.load_spec(spec), Path(spec).read_text(encoding="utf-8")
    path = mf.bundled_spec_path(str(spec))
    return mf.load_spec(path), path.read_text(encoding="utf-8")


def plan_sweep(
    spec: str | os.PathLike | dict,
    solver: str,
    params: Sequence[str | Param],
    options: Mapping[str, Any] | None = None,
    zipped: bool = False,
) -> SweepPlan:
    """Check everything a sweep needs before any point runs; errors name the key at fault.

    ``spec`` is a spec file, a bundled case name, TOML text or a dict; ``params``
    are ``KEY=VALUES`` strings (see :mod:`.params`) or :class:`Param`.
    """
    spec_dict, text = _spec_source(spec)
    solver_record = mf.get_solver(solver)
    parsed = [p if isinstance(p, Param) else parse_param(p) for p in params]
    if not parsed:
        raise mf.SpecError("a sweep needs at least one --param KEY=VALUES")
    check_names(parsed)
    clash = [p.key for p in parsed if p.name in _RESERVED]
    if clash:
        raise mf.SpecError(f"--param {clash[0]}: its name is taken by a variable of the sweep dataset")
    parsed = resolve_option_params(solver_record, parsed)
    check_spec_params(spec_dict, parsed)
    shape, points = point_indices(parsed, zipped)
    return SweepPlan(
        spec=spec_dict,
        spec_text=text,
        solver=solver_record.name,
        solver_version=mfp.solver_version(solver_record.name),
        options=mfp.resolve_options(f"solver {solver_record.name!r}", solver_record.options, dict(options or {})),
        params=tuple(parsed),
        zipped=zipped,
        shape=shape,
        points=tuple(points),
    )


def _distributed(*names: str) -> tuple:
    """Names from ``distributed``, imported here rather than at the top (see the module docstring)."""
    try:
        import distributed
    except ImportError as exc:
        raise mf.PluginError(
            f"masonryfw sweep needs dask.distributed ({exc}); install it with: pip install 'masonryfw[sweep]'"
        ) from exc
    return tuple(getattr(distributed, name) for name in names)


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity where the platform tells it)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None) -> Iterator[Any]:
    """A client of the cluster at ``scheduler`` (left running), or of a new local cluster.

    The local cluster has ``workers`` processes (default: one per core available
    to this process), one thread each (numba's too: fdem's parallel loops would otherwise
    start a thread per core in every process), no dashboard; it is closed on exit.
    """
    Client, LocalCluster = _distributed("Client", "LocalCluster")

    if scheduler is not None:
        with Client(scheduler) as client:
            yield client
        return
    with LocalCluster(n_workers=workers or available_cores(), threads_per_worker=1, processes=True,
                      dashboard_address=None, silence_logs=logging.ERROR,
                      env={"NUMBA_NUM_THREADS": "1"}) as cluster, Client(cluster) as client:
        try:
            yield client
        except KeyboardInterrupt:
            quiet_shutdown()
            raise


#: The loggers of the event loop and of dask, which report a callback that fails while a cluster closes.
SHUTDOWN_LOGGERS = ("tornado", "distributed", "asyncio")


def quiet_shutdown() -> None:
    """After Ctrl-C the cluster closes with its workers already stopping: a comm closed under a pending callback is
    logged with its traceback (twice in CI runs, the interrupted sweep's message came with one). The user asked
    it to stop and is told what the store kept: nothing else is worth saying. Every logger under these names is
    quieted, not only the top ones: distributed's configuration gives ``tornado.application``, which reports a
    failed callback, its own level (ERROR) and handler, so quieting ``tornado`` alone left it talking."""
    names = [name for name in list(logging.root.manager.loggerDict) if name.split(".")[0] in SHUTDOWN_LOGGERS]
    for name in {*SHUTDOWN_LOGGERS, *names}:
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


def run_sweep(
    plan: SweepPlan,
    client,
    store: str | os.PathLike,
    output_dir: str | os.PathLike = ".",
    on_point: Callable[[int, dict], None] | None = None,
    command: str = "",
) -> xr.Dataset:
    """Run every point of ``plan`` as a dask task on ``client`` and return the combined dataset.

    ``store`` must be reachable under the same path from every worker.
    ``on_point(done, record)`` is called as each point finishes (for a progress bar).
    """
    (as_completed,) = _distributed("as_completed")
    store_root = str(Path(store).resolve())
    Path(store_root).mkdir(parents=True, exist_ok=True)
    provenance = {"command": command}
    [spec_future] = client.scatter([plan.spec], hash=False)
    token = secrets.token_hex(4)
    futures = []
    for index, indices in enumerate(plan.points):
        assignments, _ = point_assignments(plan.params, indices)
        futures.append(client.submit(
            run_point, spec_future, assignments, plan.solver, plan.point_options(indices), store_root, provenance,
            key=f"masonryfw-sweep-{token}-{index}", pure=False,
        ))
    index_of = {future.key: index for index, future in enumerate(futures)}
    records: list[dict | None] = [None] * len(futures)
    for done, future in enumerate(as_completed(futures, loop=client.loop), start=1):
        try:
            record = future.result()
        except Exception as exc:  # the task itself never raises: a lost worker, a cancellation...
            record = {"status": status_of(exc), "message": failure_message(exc), "key": "", "result": "",
                      "reused": False, "scalars": {}, "task_time_s": float("nan")}
        records[index_of[future.key]] = record
        future.release()
        if on_point is not None:
            on_point(done, record)
    futures.clear()
    spec_future.release()
    return combine(plan, records, Path(output_dir).resolve(), store_root, command)


# --------------------------------------------------------------------------- the combined dataset


def _coordinate(param: Param) -> tuple[np.ndarray, dict]:
    values = list(param.values)
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)
    if numeric:
        array = np.asarray(values, dtype=np.int64 if all(isinstance(v, int) for v in values) else float)
    elif all(isinstance(v, bool) for v in values):
        array = np.asarray(values, dtype=np.int8)
    else:
        array = np.asarray([v if isinstance(v, str) else repr(v) for v in values], dtype=str)
    what = f"solver option {param.option_name}" if param.is_option else f"spec key {param.key}"
    return array, {"long_name": f"swept {what}", "sweep_key": param.key}


def _scalar_variables(records: Sequence[dict]) -> dict[str, tuple[str, dict]]:
    """``{name: (kind, attrs)}`` of every scalar output of any point; kind is 'number' or 'text'."""
    found: dict[str, tuple[str, dict]] = {}
    for record in records:
        for name, (value, attrs) in record["scalars"].items():
            found.setdefault(name, ("text" if isinstance(value, str) else "number", attrs))
    return dict(sorted(found.items()))


def combine(plan: SweepPlan, records: Sequence[dict], output_dir: Path, store_root: str,
            command: str = "") -> xr.Dataset:
    """The sweep dataset of the point ``records`` (in ``plan.points`` order)."""
    if plan.zipped:
        dims = (ZIP_DIM,)
        coords = {p.name: (ZIP_DIM, *_coordinate(p)) for p in plan.params}
    else:
        dims = tuple(p.name for p in plan.params)
        coords = {p.name: (p.name, *_coordinate(p)) for p in plan.params}

    def grid(values, dtype) -> np.ndarray:
        return np.asarray(values, dtype=dtype).reshape(plan.shape)

    status_names = list(STATUS)
    data = {
        "status": (dims, grid([STATUS[r["status"]] for r in records], np.int8), {
            "long_name": "outcome of the point", "units": "1",
            "flag_values": np.arange(len(status_names), dtype=np.int8), "flag_meanings": " ".join(status_names)}),
        "message": (dims, grid([r["message"] for r in records], str), {
            "long_name": "error message of a failed point (empty when it succeeded)"}),
        "key": (dims, grid([r["key"] for r in records], str), {
            "long_name": "content key of the point's result in the store (sha256)"}),
        "result_path": (dims, grid([os.path.relpath(r["result"], output_dir) if r["result"] else "" for r in records],
                                   str), {"long_name": "result file of the point, relative to this file's folder"}),
        "from_store": (dims, grid([r["reused"] for r in records], np.int8), {
            "long_name": "1 where the result was found in the store and verified instead of solved",
            "units": "1", "flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": "solved from_store"}),
        "task_time_s": (dims, grid([r["task_time_s"] for r in records], float), {
            "long_name": "wall time of the point's task: build, store lookup, solve, store writes", "units": "s"}),
    }
    for name, (kind, attrs) in _scalar_variables(records).items():
        missing = "" if kind == "text" else np.nan
        values = [r["scalars"].get(name, (missing, None))[0] for r in records]
        data[name] = (dims, grid(values, str if kind == "text" else float), dict(attrs))
    attrs = {
        **mfp.format_header("sweep"),
        "title": f"sweep of {plan.spec.get('title', '')}".strip(),
        "solver": plan.solver,
        "solver_version": plan.solver_version,
        "solver_options": mfp.options_json(plan.options),
        "sweep_mode": "zip" if plan.zipped else "grid",
        "sweep_keys": " ".join(p.key for p in plan.params),
        "sweep_store": store_root,
        "sweep_command": command,
        "source_spec": plan.spec_text,
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def failed_points(sweep: xr.Dataset) -> list[tuple[str, str]]:
    """``(point, message)`` of every failed point of a sweep dataset, in order; the point as ``key=value, ...``."""
    status = sweep.status
    out = []
    for index in zip(*np.nonzero(status.values != STATUS["ok"])):
        point = sweep[["message"]].isel(dict(zip(status.dims, index)))
        where = ", ".join(f"{point[c].attrs['sweep_key']}={point[c].values.item()!r}"
                          for c in point.coords if "sweep_key" in point[c].attrs)
        out.append((where, str(point.message.values)))
    return out
