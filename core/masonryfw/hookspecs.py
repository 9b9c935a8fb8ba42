"""The plugin contract: small, typed, documented hooks.

A plugin is a module (or object) with functions decorated by :data:`hookimpl`
whose names match the hooks below. Each hook returns a list of *records*
(:class:`Solver`, :class:`Comparator`, :class:`Plotter`) that the core looks up
by name. A plugin is registered through the entry-point group ``masonryfw``::

    [project.entry-points.masonryfw]
    mysolver = "my_package"

Data contract (docs/format.md): a solve function receives a checked model with
its derived geometry and the options resolved by the core (defaults filled in,
every rule checked once, here); it returns a dataset holding only its primary
result variables. The core derives the comparable fields (relative motion at
the joints, joint states, crack indicator, macro-blocks) from
``block_displacement`` the same way for every solver, merges everything with the
model and stamps the provenance (``plugin``, ``solver``, ``solver_version``,
``solver_options``, ``wall_time_s``, hashes, a history line).
"""
from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import pluggy

from .errors import PluginError
from .options import Option
from .progress import ProgressCallback

if TYPE_CHECKING:  # annotations only: listing the plugins does not import xarray
    import xarray as xr

PROJECT = "masonryfw"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)

def lazy(target: str) -> Callable[..., Any]:
    """A callable that imports ``"package.module:function"`` on its first call.

    Plugins build their records with ``lazy(...)`` callables, so listing the
    plugins or running one solver never imports another plugin's heavy
    dependencies (numba, matplotlib, dask, ...).
    """
    module_name, _, attribute = target.partition(":")
    if not module_name or not attribute:
        raise PluginError(f"lazy target {target!r} is not of the form 'package.module:function'")

    def resolve() -> Callable[..., Any]:
        return getattr(importlib.import_module(module_name), attribute)

    def call(*args: Any, **kwargs: Any) -> Any:
        return resolve()(*args, **kwargs)

    call.__name__ = call.__qualname__ = attribute
    call.__module__ = module_name
    call.__doc__ = f"Calls {target} (imported on first use)."
    call.resolve = resolve  # type: ignore[attr-defined]  # the target itself: imports it now
    return call


def resolved(function: Callable[..., Any]) -> Callable[..., Any]:
    """The function a :func:`lazy` callable stands for (imported now); any other callable as it is."""
    resolve = getattr(function, "resolve", None)
    return resolve() if callable(resolve) else function


@dataclass(frozen=True)
class Variant:
    """A named set of options a solver declares worth running on its own (e.g. each LP backend)."""

    label: str
    options: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Estimate:
    """What a solve will cost, known before it starts (:attr:`Solver.estimate`).

    ``seconds`` and ``memory`` (peak resident bytes of the whole process) are rough: a
    solver fits them to its own benchmarks (docs/benchmarks.md, section "scale") and says
    in ``basis`` what they scale with. ``advice`` says which option makes the run smaller
    (``"--option mesh_size=... larger than 0.025 m"``); the core repeats it when it refuses a
    run that cannot fit.
    """

    seconds: float
    memory: float
    basis: str
    advice: str = ""


@dataclass(frozen=True)
class Solver:
    """A named solver: ``solve(model, options, progress) -> primary result variables``.

    ``version``: None (the default) records the distribution's version plus a
    digest of the plugin package's code, so that any change of the code changes
    the recorded ``solver_version`` (and a sweep recomputes). ``variants``: option
    sets the gallery runs side by side. ``gallery``: whether ``masonryfw gallery``
    runs it by default (a failure analysis with something to draw).

    Interruption: a solve that catches ``KeyboardInterrupt`` returns what it has
    computed with the attribute ``interrupted = 1``; with nothing to return it
    lets the ``KeyboardInterrupt`` propagate.

    ``estimate`` (optional): ``estimate(model, options) -> Estimate``, cheap (counts,
    no factorisation, no time stepping). The core refuses a run whose memory does
    not fit before it starts, and the CLI prints the estimate of a run longer than a
    minute.
    """

    name: str
    summary: str
    solve: Callable[[xr.Dataset, Mapping[str, Any], ProgressCallback], xr.Dataset]
    version: str | None = None
    options: tuple[Option, ...] = field(default_factory=tuple)
    variants: tuple[Variant, ...] = field(default_factory=tuple)
    gallery: bool = True
    estimate: Callable[[xr.Dataset, Mapping[str, Any]], Estimate] | None = None


@dataclass(frozen=True)
class Comparator:
    """A named comparator: ``compare(a, b, options) -> comparison variables``."""

    name: str
    summary: str
    compare: Callable[[xr.Dataset, xr.Dataset, Mapping[str, Any]], xr.Dataset]
    version: str | None = None
    options: tuple[Option, ...] = field(default_factory=tuple)


@dataclass(frozen=True)
class Plotter:
    """A named plot kind: ``plot(datasets, ax, options)`` draws on a matplotlib Axes.

    ``datasets`` is a sequence of result (or model) datasets; most kinds use one, kinds that
    overlay or set side by side take several.
    """

    name: str
    summary: str
    plot: Callable[[Sequence[xr.Dataset], Any, Mapping[str, Any]], None]
    version: str | None = None
    options: tuple[Option, ...] = field(default_factory=tuple)
    #: Draws several datasets side by side (the figure ``render`` makes is one panel wider per dataset);
    #: False for a kind that draws one dataset or overlays several on one panel.
    side_by_side: bool = False
    #: The numbers behind the curves, ``table(datasets, options) -> (header, rows)`` (``plot --format csv``);
    #: None for a kind that draws no curves.
    table: Callable[[Sequence[xr.Dataset], Mapping[str, Any]], tuple[list[str], list[list]]] | None = None


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
