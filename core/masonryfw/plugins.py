"""The plugin manager: loading, lookup by name, and the ``solve`` / ``compare`` / ``render`` entry points.

Every plugin, built-in or third-party, is found through the entry-point group
``masonryfw``; nothing is special-cased. A plugin that fails to load becomes a
:class:`PluginLoadWarning` naming the entry point and the error, and the other
plugins stay usable. Records (solvers, comparators, plotters) are looked up by
name; the same name contributed twice is an error naming both plugins.
"""
from __future__ import annotations

import functools
import hashlib
import importlib.util
import json
import sys
import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any

import click
import numpy as np
import pluggy
import xarray as xr

from .checks import check
from .damage import DERIVED_STEP_VARIABLES, damage_variables
from .dofs import block_motion
from .errors import MasonryError, ModelError, PluginError, SolveError
from .hookspecs import (
    PROJECT,
    Comparator,
    Estimate,
    MasonryfwSpec,
    Plotter,
    Solver,
    resolve_options,
    unknown_name_message,
)
from .hookspecs import resolved as resolved_function
from .io import CONVENTIONS, add_history, content_sha256
from .model import checked_model
from .progress import ProgressCallback, no_progress
from .resources import require_memory
from .schema import FORMAT_VERSION, variable_attrs
from .semantics import DERIVED_RESULT_VARIABLES, FLOW_RULES, ROTATIONS, derived_variables, plastic_crack_indicator

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
        raise PluginError(unknown_name_message(kind, name, list(named)))
    return named[name]


def installed_solvers() -> list[Solver]:
    """Every installed solver record, in name order."""
    return [item.record for _, item in sorted(_by_name("solver").items())]


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
    """The contributing distribution's version (the masonryfw version for a plugin registered by hand)."""
    from . import __version__

    dist = _distributions.get(item.plugin)
    return dist[1] if dist else __version__


def _problem_list(problems) -> str:
    return "\n".join(f"  - {p}" for p in problems)


def _require_valid_input(ds: xr.Dataset, what: str, kind: str) -> None:
    """Raise one :class:`ModelError` listing every problem of an input dataset."""
    problems = check(ds, kind=kind)
    if problems:
        raise ModelError(f"{what} is invalid ({len(problems)} problem(s))", problems)


def _require_valid_output(ds: xr.Dataset, what: str, error: type[MasonryError], model_checked: bool = False) -> None:
    """Raise ``error`` listing every problem of a dataset a plugin produced."""
    problems = check(ds, model_checked=model_checked)
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
    clash = sorted(map(str, set(produced.data_vars) & set(reserved.data_vars)))
    if clash:
        raise error(
            f"{kind} {name} returned variable(s) {', '.join(clash)} that belong to its input; "
            "a plugin returns only the variables it computes"
        )
    try:
        return xr.merge([base, produced], compat="no_conflicts", join="exact", combine_attrs="override")
    except (ValueError, xr.MergeError) as exc:
        raise error(f"{kind} {name} returned variables that do not fit its input: {exc}") from exc


def _package_files(module_name: str) -> tuple[Path, list[Path]]:
    """The folder and the ``.py`` files of the top-level package of ``module_name`` (or of the module alone)."""
    top = module_name.split(".")[0]
    try:
        spec = importlib.util.find_spec(top)
    except (ImportError, ValueError):
        spec = None
    if spec is not None and spec.submodule_search_locations:
        root = Path(next(iter(spec.submodule_search_locations)))
        return root, sorted(root.rglob("*.py"))
    module = sys.modules.get(module_name) or sys.modules.get(top)
    origin = getattr(module, "__file__", None) or (spec.origin if spec is not None else None)
    if origin and Path(origin).is_file():
        return Path(origin).parent, [Path(origin)]
    return Path("."), []


@functools.cache
def code_digest(module_name: str) -> str:
    """First 12 hex digits of the SHA-256 of the code of the package holding ``module_name``.

    Every ``.py`` file of the package in sorted order, by its path relative to
    the package and its bytes: the same code gives the same digest wherever it
    is installed, and any edit changes it.
    """
    root, files = _package_files(module_name)
    digest = hashlib.sha256()
    for path in files:
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:12]


def core_version() -> str:
    """masonryfw's version plus a digest of the core's code (what derives the comparable fields)."""
    from . import __version__

    return f"{__version__}+{code_digest(__name__)}"


def record_version(item: _Contribution, function) -> str:
    """The recorded version of a record: its declared version (else its distribution's) plus its code's digest.

    Any change of the plugin's code changes it, so a store keyed on it never
    returns the result of older code.
    """
    base = item.record.version or _plugin_version(item)
    return f"{base}+{code_digest(function.__module__)}"


def solver_version(name: str) -> str:
    """The version :func:`solve` records for the solver called ``name`` (see :func:`record_version`)."""
    item = _lookup("solver", name)
    return record_version(item, item.record.solve)


def _derive_comparable_fields(name: str, model: xr.Dataset, produced: xr.Dataset) -> xr.Dataset:
    """``produced`` with the fields :mod:`.semantics` derives from its ``block_displacement`` or ``qp_failure``
    and those :mod:`.damage` derives from its history."""
    derived_too = sorted(map(str, set(produced.data_vars) & set(DERIVED_STEP_VARIABLES)))
    if derived_too:
        raise SolveError(f"solver {name} returned {', '.join(derived_too)}; the core derives them from "
                         "step_crack_width_max and step_settlement (docs/format.md): return only those")
    produced = produced.assign(damage_variables(model, produced))
    if "step" in produced.dims and "step" not in produced.coords:  # labelled records for plain xarray
        produced = produced.assign_coords(step=("step", np.arange(produced.sizes["step"], dtype=np.int32),
                                                variable_attrs("step")))
    primary = "block_displacement" if "block_displacement" in produced else "qp_failure"
    if primary not in produced:
        return produced
    derived_too = sorted(map(str, set(produced.data_vars) & set(DERIVED_RESULT_VARIABLES)))
    if derived_too:
        raise SolveError(
            f"solver {name} returned {', '.join(derived_too)} with {primary}; the core derives "
            f"them from {primary} (docs/format.md): return only the primary fields"
        )
    if primary == "qp_failure":
        indicator = plastic_crack_indicator(model, produced.qp_x.values, produced.qp_y.values,
                                            produced.qp_failure.values > 0)
        return produced.assign(crack_indicator=("interface", indicator, variable_attrs("crack_indicator")))
    for attribute, choices in (("rotations", ROTATIONS), ("flow_rule", FLOW_RULES)):
        if produced.attrs.get(attribute) not in choices:
            raise SolveError(
                f"solver {name} returned block_displacement without the attribute {attribute!r} "
                f"(one of {', '.join(choices)}; docs/format.md)"
            )
    if "block_rotation" not in produced:
        raise SolveError(f"solver {name} returned block_displacement without block_rotation (docs/format.md)")
    derived = derived_variables(model, block_motion(produced), produced.attrs["rotations"],
                                produced.attrs["flow_rule"])
    return produced.assign(derived)


def estimate(model: xr.Dataset, plugin: str, options: Mapping[str, Any] | None = None) -> Estimate | None:
    """The time and peak memory the solver called ``plugin`` expects on ``model`` (None if it gives none).

    Raises :class:`SolveError` when the memory would not fit (:func:`masonryfw.resources.require_memory`):
    the check :func:`solve` makes before it starts.
    """
    model = checked_model(model)
    solver: Solver = _lookup("solver", plugin).record
    resolved = resolve_options(f"solver {solver.name!r}", solver.options, dict(options or {}))
    return _checked_estimate(solver, model, resolved)


def _checked_estimate(solver: Solver, model: xr.Dataset, resolved: Mapping[str, Any]) -> Estimate | None:
    if solver.estimate is None:
        return None
    function = _call_plugin("solver", solver.name, resolved_function, solver.estimate)
    expected = _call_plugin("solver", solver.name, function, model, resolved)
    if not isinstance(expected, Estimate):
        raise SolveError(f"solver {solver.name}'s estimate returned {type(expected).__name__}, not an Estimate")
    require_memory(solver.name, expected)
    return expected


def solve(
    model: xr.Dataset,
    plugin: str,
    options: Mapping[str, Any] | None = None,
    progress: ProgressCallback | None = None,
) -> xr.Dataset:
    """Run the solver called ``plugin`` on ``model`` and return the result dataset.

    The model is checked unless it already is (:func:`masonryfw.checked_model`;
    every problem raises one :class:`ModelError`); the options are resolved and
    checked against the solver's declared rules; a run whose estimated memory
    (:func:`estimate`) exceeds what is available is refused. The result holds the model's
    variables, the solver's primary variables, the comparable fields the core
    derives from ``block_displacement`` (:mod:`masonryfw.semantics`) and the
    provenance attributes of docs/format.md. A result may be given: its model is
    solved. ``wall_time_s`` leaves out the ``compile_time_s`` a solver reports.
    A ``KeyboardInterrupt`` the solver lets through propagates (nothing computed).
    """
    model = checked_model(model)
    item = _lookup("solver", plugin)
    solver: Solver = item.record
    resolved = resolve_options(f"solver {solver.name!r}", solver.options, dict(options or {}))
    _checked_estimate(solver, model, resolved)  # a run that cannot fit in memory is refused here
    function = _call_plugin("solver", solver.name, resolved_function, solver.solve)  # imported before the clock

    start = time.perf_counter()
    produced = _call_plugin("solver", solver.name, function, model, resolved, progress or no_progress)
    wall_time = time.perf_counter() - start
    if not isinstance(produced, xr.Dataset):
        raise SolveError(f"solver {solver.name} returned {type(produced).__name__}, not an xarray.Dataset")
    produced = _derive_comparable_fields(solver.name, model, produced)

    result = _merge_result("solver", solver.name, model, model, produced)
    compile_time = float(produced.attrs.get("compile_time_s", 0.0))
    result.attrs = {**model.attrs, **produced.attrs}
    result.attrs.update(
        masonryfw_format="result",
        masonryfw_format_version=FORMAT_VERSION,
        plugin=item.plugin,
        plugin_version=_plugin_version(item),
        solver=solver.name,
        solver_version=record_version(item, solver.solve),
        core_version=core_version(),
        solver_options=options_json(resolved),
        wall_time_s=float(wall_time - compile_time),
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
    _require_valid_output(result, f"the result of solver {solver.name}", _failure("solver"), model_checked=True)
    return result


def options_json(options: Mapping[str, Any]) -> str:
    """Resolved options as canonical JSON (sorted keys, tuples as lists): how results and stores record them."""
    return json.dumps(options, sort_keys=True, default=str)


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
    attributes ``schemas/comparison-2.json`` requires. ``input_a_sha256`` /
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
        "Conventions": CONVENTIONS,
        "masonryfw_format": "comparison",
        "masonryfw_format_version": FORMAT_VERSION,
        "title": title_a if title_a == title_b else f"{title_a} vs {title_b}",
        "comparator": record.name,
        "comparator_version": record_version(item, record.compare),
        "plugin": item.plugin,
        "plugin_version": _plugin_version(item),
        "comparator_options": options_json(resolved),
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
    (no pyplot, no GUI backend), one panel-width wider per dataset for a ``side_by_side`` kind.
    Returns the figure.
    """
    record: Plotter = _lookup("plotter", kind).record
    resolved = resolve_options(f"plotter {record.name!r}", record.options, dict(options or {}))
    datasets = list(datasets)
    if ax is None:
        from matplotlib.figure import Figure

        width = max(FIGURE_SIZE[0], PANEL_WIDTH * len(datasets)) if record.side_by_side else FIGURE_SIZE[0]
        ax = Figure(figsize=(width, FIGURE_SIZE[1]), layout="constrained").add_subplot()
    _call_plugin("plotter", record.name, record.plot, datasets, ax, resolved)
    return ax.figure


def plot_table(
    datasets: Sequence[xr.Dataset], kind: str | None = None, options: Mapping[str, Any] | None = None,
) -> tuple[list[str], list[list]]:
    """The numbers behind the curves of the plot kind ``kind``: ``(header, rows)`` (``plot --format csv``).

    Raises :class:`PluginError` for a kind that draws no curves, naming the kinds that do.
    """
    record: Plotter = _lookup("plotter", kind).record
    if record.table is None:
        with_tables = sorted(name for name, item in _by_name("plotter").items() if item.record.table is not None)
        raise PluginError(f"the {record.name} plot draws no curves to write as CSV; kinds with curves: "
                          f"{', '.join(with_tables) or 'none installed'}")
    resolved = resolve_options(f"plotter {record.name!r}", record.options, dict(options or {}))
    return _call_plugin("plotter", record.name, record.table, list(datasets), resolved)
