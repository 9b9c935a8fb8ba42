"""The plugin contract: small, typed, documented hooks.

A plugin is a module (or object) with functions decorated by :data:`hookimpl`
whose names match the hooks below. Each hook returns a list of *records*
(:class:`Solver`, :class:`Comparator`, :class:`Plotter`) that the core looks up
by name. A plugin is registered through the entry-point group ``masonryfw``::

    [project.entry-points.masonryfw]
    mysolver = "my_package"

Data contract: a solve function receives a model dataset (FORMAT.md, with the
derived geometry added by the core) and returns a dataset holding only its
result variables; the core merges them with the model and adds the result
attributes (``plugin``, ``plugin_version``, ``solver``, ``solver_options``,
``wall_time_s``), the input hash and the history line.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import pluggy
import xarray as xr

from .errors import PluginError
from .progress import ProgressCallback

PROJECT = "masonryfw"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)

_TRUE = {"1", "true", "yes", "on"}
_FALSE = {"0", "false", "no", "off"}


@dataclass(frozen=True)
class Option:
    """One option a solver/comparator/plotter accepts (``--option name=value``)."""

    name: str
    type: type
    default: Any
    help: str = ""
    choices: tuple | None = None

    def parse(self, value: Any) -> Any:
        """Convert ``value`` (a string from the CLI or a Python value) to ``type``."""
        try:
            if self.type is bool and isinstance(value, str):
                low = value.strip().lower()
                if low not in _TRUE | _FALSE:
                    raise ValueError(value)
                parsed = low in _TRUE
            else:
                parsed = self.type(value)
        except (TypeError, ValueError):
            raise PluginError(
                f"option {self.name!r}: cannot read {value!r} as {self.type.__name__}"
            ) from None
        if self.choices is not None and parsed not in self.choices:
            raise PluginError(
                f"option {self.name!r}: {parsed!r} is not one of "
                + ", ".join(map(repr, self.choices))
            )
        return parsed


def parse_option_pairs(pairs: Sequence[str]) -> dict[str, str]:
    """``["solver=highs", "tolerance=1e-9"]`` -> ``{"solver": "highs", "tolerance": "1e-9"}`` (CLI ``--option``)."""
    options = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key.strip():
            raise PluginError(f"--option {pair!r} is not KEY=VALUE")
        options[key.strip()] = value
    return options


def resolve_options(
    owner: str, declared: Sequence[Option], given: Mapping[str, Any]
) -> dict[str, Any]:
    """Defaults overlaid by ``given``; unknown names raise a message listing the valid ones."""
    by_name = {o.name: o for o in declared}
    unknown = sorted(set(given) - set(by_name))
    if unknown:
        valid = ", ".join(sorted(by_name)) or "(none)"
        raise PluginError(f"{owner}: unknown option(s) {', '.join(unknown)}; valid options: {valid}")
    resolved = {o.name: o.default for o in declared}
    resolved.update({k: by_name[k].parse(v) for k, v in given.items()})
    return resolved


def lazy(target: str) -> Callable[..., Any]:
    """A callable that imports ``"package.module:function"`` on its first call.

    Plugins build their records with ``lazy(...)`` callables, so listing the
    plugins or running one solver never imports another plugin's heavy
    dependencies (numba, matplotlib, dask, ...).
    """
    module_name, _, attribute = target.partition(":")
    if not module_name or not attribute:
        raise PluginError(f"lazy target {target!r} is not of the form 'package.module:function'")

    def call(*args: Any, **kwargs: Any) -> Any:
        return getattr(importlib.import_module(module_name), attribute)(*args, **kwargs)

    call.__name__ = call.__qualname__ = attribute
    call.__module__ = module_name
    call.__doc__ = f"Calls {target} (imported on first use)."
    return call


@dataclass(frozen=True)
class Solver:
    """A named solver: ``solve(model, options, progress) -> result variables``."""

    name: str
    summary: str
    solve: Callable[[xr.Dataset, Mapping[str, Any], ProgressCallback], xr.Dataset]
    version: str
    options: tuple[Option, ...] = field(default_factory=tuple)


@dataclass(frozen=True)
class Comparator:
    """A named comparator: ``compare(a, b, options) -> comparison variables``."""

    name: str
    summary: str
    compare: Callable[[xr.Dataset, xr.Dataset, Mapping[str, Any]], xr.Dataset]
    version: str
    options: tuple[Option, ...] = field(default_factory=tuple)


@dataclass(frozen=True)
class Plotter:
    """A named plot kind: ``plot(datasets, ax, options)`` draws on a matplotlib Axes.

    ``datasets`` is a sequence of result (or model) datasets; most kinds use one.
    """

    name: str
    summary: str
    plot: Callable[[Sequence[xr.Dataset], Any, Mapping[str, Any]], None]
    version: str
    options: tuple[Option, ...] = field(default_factory=tuple)


class MasonryfwSpec:
    """Hook specifications. Every hook takes no arguments and returns a list."""

    @hookspec
    def masonryfw_solvers(self) -> list[Solver]:
        """Return the solvers this plugin contributes."""

    @hookspec
    def masonryfw_comparators(self) -> list[Comparator]:
        """Return the comparators this plugin contributes."""

    @hookspec
    def masonryfw_plotters(self) -> list[Plotter]:
        """Return the plot kinds this plugin contributes."""

    @hookspec
    def masonryfw_commands(self) -> list[Any]:
        """Return extra ``click.Command`` objects added to the ``masonryfw`` CLI.

        For whole workflows a plugin owns (e.g. ``gallery``, ``export``); a command
        whose name is already taken is an error naming both plugins.
        """
