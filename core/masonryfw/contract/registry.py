"""The plugin registry: the entry points loaded into one pluggy manager, the records looked up by name.

Every plugin, built-in or third-party, is found through the entry-point group
``masonryfw``; nothing is special-cased. A plugin that fails to load becomes a
:class:`PluginLoadWarning` naming the entry point and the error, and the other
plugins stay usable. Records (solvers, comparators, plotters, commands) are looked up by
name; the same name contributed twice is an error naming both plugins.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from importlib.metadata import entry_points
from typing import Any

import click
import pluggy

from ..runtime.errors import PluginError
from .hookspecs import PROJECT, MasonryfwSpec
from .options import unknown_name_message
from .records import Comparator, Plotter, Solver

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
class Contribution:
    record: Any
    plugin: str


_manager: pluggy.PluginManager | None = None


# plugin name -> its distribution, whose name and version are read only when asked: reading them parses the
# package's metadata (2 ms a plugin, 15 ms of every CLI process with the bundled plugins)
_distributions: dict[str, Any] = {}


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
    try:
        manager.register(entry_point.load(), name=entry_point.name)
        try:
            manager.check_pending()  # a misspelt hook name would otherwise be ignored silently
        except pluggy.PluginValidationError:
            manager.unregister(name=entry_point.name)
            raise
    except Exception as exc:  # a broken plugin must not take the others down
        origin = f"{dist.name} {dist.version}" if dist is not None else "unknown distribution"
        warnings.warn(
            f"masonryfw plugin {entry_point.name!r} ({entry_point.value}, from {origin}) "
            f"failed to load: {type(exc).__name__}: {exc}",
            PluginLoadWarning,
            stacklevel=3,
        )
        return
    if dist is not None:
        _distributions[entry_point.name] = dist


def describe_plugin(plugin: str) -> str:
    dist = distribution(plugin)
    return f"{plugin!r} (distribution {dist[0]} {dist[1]})" if dist else repr(plugin)


def contributions(kind: str) -> list[Contribution]:
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
                found.append(Contribution(record, impl.plugin_name))
            else:
                warnings.warn(
                    f"masonryfw plugin {impl.plugin_name!r}: {hook_name}() returned "
                    f"{type(record).__name__}, not a {record_type.__name__}; ignored",
                    PluginLoadWarning,
                    stacklevel=3,
                )
    return found


def by_name(kind: str) -> dict[str, Contribution]:
    """Records of ``kind`` by name; a name contributed twice raises naming both plugins."""
    named: dict[str, Contribution] = {}
    for item in contributions(kind):
        first = named.get(item.record.name)
        if first is not None:
            raise PluginError(
                f"{kind} {item.record.name!r} is provided twice: by plugin "
                f"{describe_plugin(first.plugin)} and by plugin {describe_plugin(item.plugin)}; "
                "uninstall or disable one of them"
            )
        named[item.record.name] = item
    return named


def lookup(kind: str, name: str | None) -> Contribution:
    """The record ``name`` of ``kind``; with ``name=None``, the only one installed."""
    named = by_name(kind)
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
    return [item.record for _, item in sorted(by_name("solver").items())]


def get_solver(name: str) -> Solver:
    """The solver record called ``name``."""
    return lookup("solver", name).record


def get_comparator(name: str) -> Comparator:
    """The comparator record called ``name``."""
    return lookup("comparator", name).record


def get_plotter(name: str) -> Plotter:
    """The plotter record (plot kind) called ``name``."""
    return lookup("plotter", name).record


def plugin_commands() -> dict[str, click.Command]:
    """Extra CLI commands contributed by plugins, by name (a name given twice raises naming both)."""
    return {name: item.record for name, item in by_name("command").items()}


def command_plugin(name: str) -> str:
    """A description of the plugin that contributes the CLI command ``name``."""
    return describe_plugin(lookup("command", name).plugin)


def installed_plugins() -> list[PluginInfo]:
    """Every loaded plugin with its distribution and records, sorted by plugin name."""
    manager = plugin_manager()
    by_plugin: dict[str, dict[str, list]] = {
        name: {kind: [] for kind in _HOOKS} for name, _ in manager.list_name_plugin()
    }
    for kind in _HOOKS:
        for item in contributions(kind):
            by_plugin[item.plugin][kind].append(item.record)
    infos = []
    for name, records in sorted(by_plugin.items()):
        dist, version = distribution(name) or (None, None)
        infos.append(PluginInfo(name, dist, version, *(tuple(records[kind]) for kind in _HOOKS)))
    return infos


def distribution(plugin: str) -> tuple[str, str] | None:
    """``(distribution, version)`` of the plugin registered under ``plugin`` (None: registered by hand)."""
    dist = _distributions.get(plugin)
    return None if dist is None else (dist.name, dist.version)

