"""The plugin manager: loading, lookup by name, and the ``solve`` / ``compare`` / ``render`` entry points.

Every plugin, built-in or third-party, is found through the entry-point group
``masonryfw``; nothing is special-cased. A plugin that fails to load becomes a
:class:`PluginLoadWarning` naming the entry point and the error, and the other
plugins stay usable. Records (solvers, comparators, plotters) are looked up by
name; the same name contributed twice is an error naming both plugins.
"""
from __future__ import annotations

import json
import time
import warnings
from dataclasses import dataclass
from importlib.metadata import entry_points
from typing import Any, Mapping, Sequence

import click
import pluggy
import xarray as xr

from .checks import check
from .errors import MasonryError, ModelError, PluginError, SolveError
from .geometry import derive_geometry
from .hookspecs import PROJECT, Comparator, MasonryfwSpec, Plotter, Solver, resolve_options
from .io import DERIVED_GEOMETRY_VARIABLES, add_history, content_sha256
from .progress import ProgressCallback, no_progress
from .schema import FORMAT_VERSION, load_schema

#: record kind -> (hook name, record type)
_HOOKS = {
    "solver": ("masonryfw_solvers", Solver),
    "comparator": ("masonryfw_comparators", Comparator),
    "plotter": ("masonryfw_plotters", Plotter),
    "command": ("masonryfw_commands", click.Command),
}


class PluginLoadWarning(UserWarning):
    """A plugin could not be loaded or one of its hooks failed; the others still work."""


@dataclass(frozen=True)
class PluginInfo:
    """An installed plugin: its entry-point name, distribution and what it contributes."""

    name: str
    distribution: str | None
    version: str | None
    solvers: tuple[Solver, ...]
    comparators: tuple[Comparator, ...]
    plotters: tuple[Plotter, ...]
    commands: tuple[click.Command, ...]


@dataclass(frozen=True)
class _Contribution:
    record: Any
    plugin: str


_manager: pluggy.PluginManager | None = None
_distributions: dict[str, tuple[str, str]] = {}  # plugin name -> (distribution, version)


def plugin_manager() -> pluggy.PluginManager:
    """The process-wide plugin manager, created (and the entry points loaded) on first use."""
    global _manager
    if _manager is None:
        manager = pluggy.PluginManager(PROJECT)
        manager.add_hookspecs(MasonryfwSpec)
        for entry_point in entry_points(group=PROJECT):
            _load_entry_point(manager, entry_point)
        _manager = manager
    return _manager


def reset() -> None:
    """Forget the plugin manager so that the next use reloads the entry points (for tests)."""
    global _manager
    _manager = None
    _distributions.clear()


def _load_entry_point(manager: pluggy.PluginManager, entry_point) -> None:
    dist = getattr(entry_point, "dist", None)
    origin = f"{dist.name} {dist.version}" if dist is not None else "unknown distribution"
    try:
        manager.register(entry_point.load(), name=entry_point.name)
        try:
            manager.check_pending()  # a misspelt hook name would otherwise be ignored silently
        except pluggy.PluginValidationError:
            manager.unregister(name=entry_point.name)
            raise
    except Exception as exc:  # a broken plugin must not take the others down
        warnings.warn(
            f"masonryfw plugin {entry_point.name!r} ({entry_point.value}, from {origin}) "
            f"failed to load: {type(exc).__name__}: {exc}",
            PluginLoadWarning,
            stacklevel=3,
        )
        return
    if dist is not None:
        _distributions[entry_point.name] = (dist.name, dist.version)


def _describe_plugin(plugin: str) -> str:
    dist = _distributions.get(plugin)
    return f"{plugin!r} (distribution {dist[0]} {dist[1]})" if dist else repr(plugin)


def _contributions(kind: str) -> list[_Contribution]:
    """Every record of ``kind`` from every plugin, in registration order, duplicates included."""
    hook_name, record_type = _HOOKS[kind]
    found = []
    for impl in getattr(plugin_manager().hook, hook_name).get_hookimpls():
        try:
            records = list(impl.function() or ())
        except Exception as exc:
            warnings.warn(
                f"masonryfw plugin {impl.plugin_name!r}: {hook_name}() failed: {type(exc).__name__}: {exc}",
                PluginLoadWarning,
                stacklevel=3,
            )
            continue
        for record in records:
            if isinstance(record, record_type):
                found.append(_Contribution(record, impl.plugin_name))
            else:
                warnings.warn(
                    f"masonryfw plugin {impl.plugin_name!r}: {hook_name}() returned "
                    f"{type(record).__name__}, not a {record_type.__name__}; ignored",
                    PluginLoadWarning,
                    stacklevel=3,
                )
    return found


def _by_name(kind: str) -> dict[str, _Contribution]:
    """Records of ``kind`` by name; a name contributed twice raises naming both plugins."""
    named: dict[str, _Contribution] = {}
    for item in _contributions(kind):
        first = named.get(item.record.name)
        if first is not None:
            raise PluginError(
                f"{kind} {item.record.name!r} is provided twice: by plugin "
                f"{_describe_plugin(first.plugin)} and by plugin {_describe_plugin(item.plugin)}; "
                "uninstall or disable one of them"
            )
        named[item.record.name] = item
    return named


def _lookup(kind: str, name: str | None) -> _Contribution:
    """The record ``name`` of ``kind``; with ``name=None``, the only one installed."""
    named = _by_name(kind)
    if not named:
        raise PluginError(f"no {kind} is installed")
    if name is None:
        if len(named) == 1:
            return next(iter(named.values()))
        raise PluginError(f"several {kind}s are installed ({', '.join(sorted(named))}); choose one by name")
    if name not in named:
        raise PluginError(f"unknown {kind} {name!r}; installed {kind}s: {', '.join(sorted(named))}")
    return named[name]


def get_solver(name: str) -> Solver:
    """The solver record called ``name``."""
    return _lookup("solver", name).record


def get_comparator(name: str) -> Comparator:
    """The comparator record called ``name``."""
    return _lookup("comparator", name).record


def get_plotter(name: str) -> Plotter:
    """The plotter record (plot kind) called ``name``."""
    return _lookup("plotter", name).record


def plugin_commands() -> dict[str, click.Command]:
    """Extra CLI commands contributed by plugins, by name (a name given twice raises naming both)."""
    return {name: item.record for name, item in _by_name("command").items()}


def command_plugin(name: str) -> str:
    """A description of the plugin that contributes the CLI command ``name``."""
    return _describe_plugin(_lookup("command", name).plugin)


def installed_plugins() -> list[PluginInfo]:
    """Every loaded plugin with its distribution and records, sorted by plugin name."""
    manager = plugin_manager()
    by_plugin: dict[str, dict[str, list]] = {
        name: {kind: [] for kind in _HOOKS} for name, _ in manager.list_name_plugin()
    }
    for kind in _HOOKS:
        for item in _contributions(kind):
            by_plugin[item.plugin][kind].append(item.record)
    infos = []
    for name, records in sorted(by_plugin.items()):
        dist, version = _distributions.get(name, (None, None))
        infos.append(PluginInfo(name, dist, version, *(tuple(records[kind]) for kind in _HOOKS)))
    return infos


def _plugin_version(item: _Contribution) -> str:
    """The contributing distribution's version; the record's own version for a plugin registered by hand."""
    dist = _distributions.get(item.plugin)
    return dist[1] if dist else item.record.version


def _problem_list(problems) -> str:
    return "\n".join(f"  - {p}" for p in problems)


def _require_valid_input(ds: xr.Dataset, what: str, kind: str) -> None:
    """Raise one :class:`ModelError` listing every problem of an input dataset."""
    problems = check(ds, kind=kind)
    if problems:
        raise ModelError(f"{what} is invalid ({len(problems)} problem(s))", problems)


def _require_valid_output(ds: xr.Dataset, what: str, error: type[MasonryError]) -> None:
    """Raise ``error`` listing every problem of a dataset a plugin produced."""
    problems = check(ds)
    if problems:
        raise error(f"{what} is invalid ({len(problems)} problem(s)):\n{_problem_list(problems)}")


def _failure(kind: str) -> type[MasonryError]:
    """The error a failing plugin function of ``kind`` raises."""
    return SolveError if kind == "solver" else PluginError


def _call_plugin(kind: str, name: str, function, *args):
    """Call a plugin function: MasonryErrors pass through, anything else names the plugin."""
    try:
        return function(*args)
    except MasonryError:
        raise
    except Exception as exc:
        raise _failure(kind)(f"{kind} {name} failed: {type(exc).__name__}: {exc}") from exc


def _merge_result(kind: str, name: str, base: xr.Dataset, reserved: xr.Dataset, produced: Any) -> xr.Dataset:
    """``base`` plus the variables a plugin ``produced``; a plugin may not overwrite ``reserved`` variables."""
    error = _failure(kind)
    if not isinstance(produced, xr.Dataset):
        raise error(f"{kind} {name} returned {type(produced).__name__}, not an xarray.Dataset")
    clash = sorted(set(produced.data_vars) & set(reserved.data_vars))
    if clash:
        raise error(
            f"{kind} {name} returned variable(s) {', '.join(clash)} that belong to its input; "
            "a plugin returns only the variables it computes"
        )
    try:
        return xr.merge([base, produced], compat="no_conflicts", join="exact", combine_attrs="override")
    except (ValueError, xr.MergeError) as exc:
        raise error(f"{kind} {name} returned variables that do not fit its input: {exc}") from exc


#: CF attributes describing a dataset that a model keeps when taken out of a result.
_DESCRIPTIVE_ATTRIBUTES = ("comment", "institution", "references", "source")


def model_part(ds: xr.Dataset) -> xr.Dataset:
    """The model a dataset holds: a model as is; for a result, its model variables and attributes.

    What a solver added (result variables, the solver's and the plugin's
    attributes) is dropped, so that solving a result anew attributes nothing of
    the old solve to the new solver. Encoding (source file, file hash) is kept.
    """
    if ds.attrs.get("masonryfw_format") != "result":
        return ds
    schema = load_schema("model")
    keep_vars = set(schema["variables"]) | set(DERIVED_GEOMETRY_VARIABLES)
    keep_attrs = set(schema["global_attributes"]) | set(_DESCRIPTIVE_ATTRIBUTES)
    model = ds.drop_vars([name for name in ds.variables if name not in keep_vars])
    model.attrs = {k: v for k, v in ds.attrs.items() if k in keep_attrs}
    model.attrs["masonryfw_format"] = "model"
    model.encoding = dict(ds.encoding)
    return model


def solve(
    model: xr.Dataset,
    plugin: str,
    options: Mapping[str, Any] | None = None,
    progress: ProgressCallback | None = None,
) -> xr.Dataset:
    """Run the solver called ``plugin`` on ``model`` and return the result dataset.

    Options are validated against the solver's declared options; the model is
    checked (every problem raises one :class:`ModelError`) and given its derived
    geometry. The result holds the model's variables, the solver's variables and
    the provenance attributes of FORMAT.md, and passes :func:`masonryfw.check`.
    A result may be given: its model is solved (see :func:`model_part`).
    """
    if not isinstance(model, xr.Dataset):
        raise TypeError(f"solve needs an xarray.Dataset model, got {type(model).__name__}")
    model = model_part(model)
    item = _lookup("solver", plugin)
    solver: Solver = item.record
    resolved = resolve_options(f"solver {solver.name!r}", solver.options, dict(options or {}))
    _require_valid_input(model, f"model {model.attrs.get('title', '')!r}", kind="model")
    geometric = derive_geometry(model)

    start = time.perf_counter()
    produced = _call_plugin("solver", solver.name, solver.solve, geometric, resolved, progress or no_progress)
    wall_time = time.perf_counter() - start

    result = _merge_result("solver", solver.name, model, geometric, produced)
    result.attrs = {**model.attrs, **getattr(produced, "attrs", {})}
    result.attrs.update(
        masonryfw_format="result",
        masonryfw_format_version=FORMAT_VERSION,
        plugin=item.plugin,
        plugin_version=_plugin_version(item),
        solver=solver.name,
        solver_version=solver.version,
        solver_options=json.dumps(resolved, sort_keys=True, default=str),
        wall_time_s=float(wall_time),
        title=model.attrs.get("title", ""),
        model_sha256=content_sha256(model),
    )
    if model.encoding.get("source"):
        result.attrs["source_file"] = str(model.encoding["source"])
    if model.encoding.get("sha256"):
        result.attrs["input_sha256"] = str(model.encoding["sha256"])
    result = add_history(
        result, f"solve: solver {solver.name} (plugin {item.plugin}) options {result.attrs['solver_options']}"
    )
    _require_valid_output(result, f"the result of solver {solver.name}", _failure("solver"))
    return result


def _input_hash(ds: xr.Dataset) -> str:
    """The file's hash for a dataset read from a file, else the content hash."""
    return str(ds.encoding.get("sha256") or content_sha256(ds))


def compare(
    a: xr.Dataset,
    b: xr.Dataset,
    comparator: str | None = None,
    options: Mapping[str, Any] | None = None,
) -> xr.Dataset:
    """Compare two results with the comparator called ``comparator`` (default: the only one installed).

    Returns a ``comparison`` dataset: the comparator's variables plus the
    attributes ``schemas/comparison-1.json`` requires. ``input_a_sha256`` /
    ``input_b_sha256`` are the files' hashes when the results were read from
    files, otherwise their content hashes.
    """
    item = _lookup("comparator", comparator)
    record: Comparator = item.record
    resolved = resolve_options(f"comparator {record.name!r}", record.options, dict(options or {}))
    for label, ds in (("A", a), ("B", b)):
        _require_valid_input(ds, f"result {label}", kind="result")
    produced = _call_plugin("comparator", record.name, record.compare, a, b, resolved)
    comparison = _merge_result("comparator", record.name, xr.Dataset(), xr.Dataset(), produced)
    title_a, title_b = a.attrs.get("title", ""), b.attrs.get("title", "")
    comparison.attrs = {
        **getattr(produced, "attrs", {}),
        "Conventions": "CF-1.11",
        "masonryfw_format": "comparison",
        "masonryfw_format_version": FORMAT_VERSION,
        "title": title_a if title_a == title_b else f"{title_a} vs {title_b}",
        "comparator": record.name,
        "comparator_version": record.version,
        "plugin": item.plugin,
        "plugin_version": _plugin_version(item),
        "comparator_options": json.dumps(resolved, sort_keys=True, default=str),
        "input_a_sha256": _input_hash(a),
        "input_b_sha256": _input_hash(b),
        "input_a_solver": str(a.attrs.get("solver", "")),
        "input_b_solver": str(b.attrs.get("solver", "")),
    }
    comparison = add_history(
        comparison, f"compare: comparator {record.name} options {comparison.attrs['comparator_options']}"
    )
    _require_valid_output(comparison, f"the comparison of comparator {record.name}", _failure("comparator"))
    return comparison


FIGURE_SIZE = (7.0, 4.5)  # inches, one panel
PANEL_WIDTH = 4.5  # inches per dataset when several are drawn side by side


def render(
    datasets: Sequence[xr.Dataset],
    kind: str | None = None,
    options: Mapping[str, Any] | None = None,
    ax=None,
):
    """Draw ``datasets`` with the plotter called ``kind`` (default: the only one installed).

    Draws into ``ax`` when given, else into a new :class:`matplotlib.figure.Figure`
    (no pyplot, no GUI backend) one panel-width wider per extra dataset. Returns the figure.
    """
    record: Plotter = _lookup("plotter", kind).record
    resolved = resolve_options(f"plotter {record.name!r}", record.options, dict(options or {}))
    datasets = list(datasets)
    if ax is None:
        from matplotlib.figure import Figure

        width = max(FIGURE_SIZE[0], PANEL_WIDTH * len(datasets))
        ax = Figure(figsize=(width, FIGURE_SIZE[1]), layout="constrained").add_subplot()
    _call_plugin("plotter", record.name, record.plot, datasets, ax, resolved)
    return ax.figure
