"""What a plugin contributes, as records the core looks up by name: a :class:`Solver` (with its :class:`Estimate`
and :class:`Variant` option sets), a :class:`Comparator`, a :class:`Plotter`. The hooks that return them are in
:mod:`masonryfw.contract.hookspecs`; the data contract of a solve is in its module docstring."""
from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..runtime.progress import ProgressCallback
from .options import Option

if TYPE_CHECKING:  # annotations only: listing the plugins does not import xarray
    import xarray as xr


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

    ``spaces``: the model dimensions it solves (2D walls, 3D models: ``masonryfw_space``); the core refuses
    any other before the solve starts.

    ``history``: whether its result is a history of steps (``step_settlement``, ``step_reaction``,
    ``step_crack_width_max``) that damage can be read from: ``masonryfw capacity`` refuses a solver without one
    before any work.

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
    spaces: tuple[int, ...] = (2,)
    history: bool = False


@dataclass(frozen=True)
class Comparator:
    """A named comparator: ``compare(a, b, options) -> comparison variables``."""

    name: str
    summary: str
    compare: Callable[[xr.Dataset, xr.Dataset, Mapping[str, Any]], xr.Dataset]
    version: str | None = None
    options: tuple[Option, ...] = field(default_factory=tuple)
    #: The dimensions of the results it compares (as :class:`Solver`'s).
    spaces: tuple[int, ...] = (2,)


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
    #: The dimensions of the models and results it draws (as :class:`Solver`'s).
    spaces: tuple[int, ...] = (2,)
