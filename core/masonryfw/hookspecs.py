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

import difflib
import importlib
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import pluggy
import xarray as xr

from .errors import PluginError
from .progress import ProgressCallback

PROJECT = "masonryfw"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)

_TRUE = {"1", "true", "yes", "on"}
_FALSE = {"0", "false", "no", "off"}
#: The word that asks for an option's automatic value (an option whose default is None).
AUTO = "auto"
_TYPES = (bool, int, float, str)


@dataclass(frozen=True)
class Option:
    """One option a solver, comparator or plotter accepts (``--option name=value``).

    ``type`` is the type of one value: bool, int, float or str. Rules, checked by
    the core once for every call (:func:`resolve_options`):

    - ``choices``: the value must be one of these;
    - ``above`` / ``at_least`` / ``below`` / ``at_most``: bounds (strict / inclusive);
    - ``default=None`` makes the option *automatic*: ``auto`` (or None) lets the
      plugin choose, and ``help`` must say how;
    - ``many=True``: a list of values (comma-separated on the command line), each
      obeying the rules; resolved as a tuple.
    """

    name: str
    type: type
    default: Any
    help: str = ""
    choices: tuple | None = None
    above: float | None = None
    at_least: float | None = None
    below: float | None = None
    at_most: float | None = None
    many: bool = False

    def __post_init__(self):
        if self.type not in _TYPES:
            raise PluginError(f"option {self.name!r}: type must be one of bool, int, float, str, not {self.type!r}")

    @property
    def auto(self) -> bool:
        """True when the option has an automatic value (its default is None)."""
        return self.default is None

    def rule(self) -> str:
        """The option's rules in words, e.g. ``> 0 and < 1`` (empty when there are none)."""
        parts = [f"{sign} {bound:g}" for sign, bound in (
            (">", self.above), (">=", self.at_least), ("<", self.below), ("<=", self.at_most)) if bound is not None]
        if self.choices is not None:
            parts.append("one of " + ", ".join(map(str, self.choices)))
        return " and ".join(parts)

    def usage(self) -> str:
        """``<float> > 0 and < 1 (default 1e-09)``: what the command line accepts."""
        kind = f"{self.type.__name__}[,{self.type.__name__}...]" if self.many else self.type.__name__
        rule = f" {self.rule()}" if self.rule() else ""
        shown = AUTO if self.auto else ",".join(map(str, self.default)) if self.many else repr(self.default)
        return f"<{kind}>{rule} (default {shown})"

    def parse(self, value: Any, owner: str = "") -> Any:
        """``value`` (a string from the command line or a Python value) converted and checked.

        Raises :class:`PluginError` naming the owner, the option, the value and the rule broken.
        """
        where = f"{owner}: option {self.name!r}" if owner else f"option {self.name!r}"
        if value is None or (isinstance(value, str) and value.strip().lower() == AUTO):
            if self.auto:
                return None
            raise PluginError(f"{where}: has no automatic value; give a {self.type.__name__}")
        if self.many:
            if isinstance(value, str):
                items = [v for v in value.split(",") if v.strip()]
            else:
                items = list(value) if isinstance(value, (list, tuple)) else [value]
            return tuple(self._one(item, where) for item in items)
        return self._one(value, where)

    def _one(self, value: Any, where: str) -> Any:
        parsed: Any
        try:
            if self.type is bool and isinstance(value, str):
                low = value.strip().lower()
                if low not in _TRUE | _FALSE:
                    raise ValueError(value)
                parsed = low in _TRUE
            elif self.type is int and isinstance(value, float) and not value.is_integer():
                raise ValueError(value)
            elif self.type is int and isinstance(value, str):
                number = float(value)
                if not number.is_integer():
                    raise ValueError(value)
                parsed = int(number)
            else:
                parsed = self.type(value.strip() if isinstance(value, str) and self.type is not str else value)
        except (TypeError, ValueError, OverflowError):
            raise PluginError(f"{where} = {value!r}: not a{'n' if self.type is int else ''} {self.type.__name__}") \
                from None
        if self.type in (int, float) and not math.isfinite(parsed):
            raise PluginError(f"{where} = {value!r}: must be finite")
        broken = self._broken_rule(parsed)
        if broken:
            raise PluginError(f"{where} = {parsed!r}: must be {broken}")
        return parsed

    def _broken_rule(self, value) -> str:
        if self.choices is not None and value not in self.choices:
            return "one of " + ", ".join(map(repr, self.choices))
        if self.type in (int, float) and any((
            self.above is not None and not value > self.above,
            self.at_least is not None and not value >= self.at_least,
            self.below is not None and not value < self.below,
            self.at_most is not None and not value <= self.at_most,
        )):
            return self.rule()
        return ""


def parse_option_pairs(pairs: Sequence[str]) -> dict[str, str]:
    """``["solver=highs", "tolerance=1e-9"]`` -> ``{"solver": "highs", "tolerance": "1e-9"}`` (CLI ``--option``)."""
    options = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key.strip():
            raise PluginError(f"--option {pair!r} is not KEY=VALUE")
        options[key.strip()] = value
    return options


def unknown_name_message(kind: str, name: str, valid: Sequence[str]) -> str:
    """``unknown option 'tolerence' (did you mean 'tolerance'?); valid: ...``: one message style for every lookup."""
    guess = difflib.get_close_matches(name, list(valid), n=1)
    hint = f" (did you mean {guess[0]!r}?)" if guess else ""
    return f"unknown {kind} {name!r}{hint}; valid {kind}s: {', '.join(sorted(valid)) or '(none)'}"


def resolve_options(owner: str, declared: Sequence[Option], given: Mapping[str, Any]) -> dict[str, Any]:
    """The options of one call: defaults overlaid by ``given``, every value parsed and checked.

    The only place option rules are applied; an unknown name, a value of the
    wrong type or outside its rules raises one :class:`PluginError` naming
    ``owner`` and the option.
    """
    by_name = {o.name: o for o in declared}
    for name in given:
        if name not in by_name:
            raise PluginError(f"{owner}: {unknown_name_message('option', name, list(by_name))}")
    resolved = {o.name: o.default for o in declared}
    resolved.update({name: by_name[name].parse(value, owner) for name, value in given.items()})
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
