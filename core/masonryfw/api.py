"""The entry points every command and script goes through: ``solve``, ``estimate``, ``compare``,
``render`` and ``plot_table``. Each looks its record up in the registry, resolves the options, checks
what goes in and what comes out, derives the comparable fields (:mod:`.semantics`, :mod:`.damage`) and
records the provenance (:mod:`.provenance`)."""
from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from .contract.lazy import resolved as resolved_function
from .contract.options import resolve_options
from .contract.provenance import core_version, input_hash, options_json, plugin_version, record_version
from .contract.records import Comparator, Estimate, Plotter, Solver
from .contract.registry import by_name, lookup
from .format.checks import check
from .format.dofs import block_motion
from .format.io import add_history, content_sha256
from .format.model import checked_model, contents_digest, made_once
from .format.model3d import require_space, space
from .format.schema import FORMAT_VERSION, format_header, variable_attrs
from .results.damage import DERIVED_STEP_VARIABLES, damage_variables, refuse_not_standing
from .results.semantics import (
    CRACK_THRESHOLD,
    DERIVED_RESULT_VARIABLES,
    FLOW_RULES,
    ROTATIONS,
    derived_variables,
    indicator_attrs,
    plastic_crack_indicator,
)
from .results.semantics3d import derived_variables_3d
from .runtime.errors import MasonryError, ModelError, PluginError, SolveError
from .runtime.progress import ProgressCallback, no_progress
from .runtime.resources import require_memory

_VALID = "masonryfw_valid"  # encoding key: (kind, contents digest) of an input found valid


def _problem_list(problems) -> str:
    return "\n".join(f"  - {p}" for p in problems)


def _require_valid_input(ds: xr.Dataset, what: str, kind: str) -> None:
    """Raise one :class:`ModelError` listing every problem of an input dataset. A dataset found valid is
    marked with the digest of its contents (:func:`.model.contents_digest`) and not checked again while
    the digest holds: ``compare`` of N results checks each once."""
    digest = contents_digest(ds)
    if ds.encoding.get(_VALID) == (kind, digest):
        return
    problems = check(ds, kind=kind)
    if problems:
        raise ModelError(f"{what} is invalid ({len(problems)} problem(s))", problems)
    ds.encoding[_VALID] = (kind, digest)


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
        return produced.assign(crack_indicator=("interface", indicator, indicator_attrs(CRACK_THRESHOLD)))
    for attribute, choices in (("rotations", ROTATIONS), ("flow_rule", FLOW_RULES)):
        if produced.attrs.get(attribute) not in choices:
            raise SolveError(
                f"solver {name} returned block_displacement without the attribute {attribute!r} "
                f"(one of {', '.join(choices)}; docs/format.md)"
            )
    if "block_rotation" not in produced:
        raise SolveError(f"solver {name} returned block_displacement without block_rotation (docs/format.md)")
    derive = derived_variables_3d if space(model) == 3 else derived_variables
    derived = derive(model, block_motion(produced), produced.attrs["rotations"], produced.attrs["flow_rule"])
    return produced.assign(derived)


@dataclass(frozen=True)
class SolvePlan:
    """A solve ready to start (:func:`solve_plan`): the checked model, the solver (and the plugin it comes
    from), its options resolved and checked, and its estimate (None when the solver gives none), each made
    once; :meth:`run` solves."""

    model: xr.Dataset
    item: Any  # the registry's entry: the solver record and its plugin
    options: Mapping[str, Any]
    estimate: Estimate | None

    @property
    def solver(self) -> Solver:
        return self.item.record

    def run(self, progress: ProgressCallback | None = None) -> xr.Dataset:
        """Run the solver and return the result dataset (:func:`solve` says what it holds)."""
        model, solver, item, resolved = self.model, self.solver, self.item, self.options
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
            plugin_version=plugin_version(item),
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


def solve_plan(model: xr.Dataset, plugin: str, options: Mapping[str, Any] | None = None) -> SolvePlan:
    """The solve of ``model`` by the solver called ``plugin``, ready to start: the model checked unless it already
    is (:func:`masonryfw.checked_model`; every problem raises one :class:`ModelError`), the solver looked up, the
    options resolved and checked against its declared rules, and its estimate made, once each; a run whose
    estimated memory exceeds what is available is refused (:func:`masonryfw.runtime.resources.require_memory`).
    The command line prints the estimate, then runs the plan."""
    model = checked_model(model)
    item = lookup("solver", plugin)
    solver: Solver = item.record
    if space(model) not in solver.spaces:
        solves = " and ".join(f"{d}D" for d in solver.spaces)
        raise SolveError(f"solver {solver.name} solves {solves} models; {model.attrs.get('title', 'this model')!r} "
                         f"is {space(model)}D (masonryfw_space = {space(model)}): solve it with a solver that "
                         f"declares {space(model)}D (masonryfw plugins)")
    resolved = resolve_options(f"solver {solver.name!r}", solver.options, dict(options or {}))
    return SolvePlan(model, item, resolved, _checked_estimate(solver, model, resolved))


def estimate(model: xr.Dataset, plugin: str, options: Mapping[str, Any] | None = None) -> Estimate | None:
    """The time and peak memory the solver called ``plugin`` expects on ``model`` (None if it gives none).

    Raises :class:`SolveError` when the memory would not fit (:func:`masonryfw.runtime.resources.require_memory`):
    the check :func:`solve` makes before it starts.
    """
    return solve_plan(model, plugin, options).estimate


def _checked_estimate(solver: Solver, model: xr.Dataset, resolved: Mapping[str, Any]) -> Estimate | None:
    """The solver's estimate on a checked ``model``, made once per model contents and options
    (:func:`masonryfw.plugin_api.made_once`), and the memory it needs refused when it does not fit."""
    if solver.estimate is None:
        return None

    def make(model: xr.Dataset) -> Estimate:
        function = _call_plugin("solver", solver.name, resolved_function, solver.estimate)
        expected = _call_plugin("solver", solver.name, function, model, resolved)
        if not isinstance(expected, Estimate):
            raise SolveError(f"solver {solver.name}'s estimate returned {type(expected).__name__}, not an Estimate")
        return expected

    expected = made_once(model, f"estimate {solver.name} {options_json(resolved)}", make)
    require_memory(solver.name, expected.memory, expected.basis, expected.advice)
    return expected


def solve(
    model: xr.Dataset,
    plugin: str,
    options: Mapping[str, Any] | None = None,
    progress: ProgressCallback | None = None,
) -> xr.Dataset:
    """Run the solver called ``plugin`` on ``model`` and return the result dataset: :func:`solve_plan`, run.

    The result holds the model's variables, the solver's primary variables, the comparable fields the core
    derives from ``block_displacement`` (:mod:`masonryfw.results.semantics`) and the provenance attributes of
    docs/format.md. A result may be given: its model is solved. ``wall_time_s`` leaves out the
    ``compile_time_s`` a solver reports. A ``KeyboardInterrupt`` the solver lets through propagates (nothing
    computed).
    """
    return solve_plan(model, plugin, options).run(progress)


def compare(
    a: xr.Dataset,
    b: xr.Dataset,
    comparator: str | None = None,
    options: Mapping[str, Any] | None = None,
) -> xr.Dataset:
    """Compare two results with the comparator called ``comparator`` (default: the only one installed).

    Returns a ``comparison`` dataset: the comparator's variables plus the
    attributes ``schemas/comparison-2.json`` requires. A result whose masonry did not stand under its own weight
    is refused (:func:`masonryfw.results.damage.standing_text`): its cracks are no settlement's damage. ``input_a_sha256`` /
    ``input_b_sha256`` are the files' hashes when the results were read from
    files, otherwise their content hashes.
    """
    item = lookup("comparator", comparator)
    record: Comparator = item.record
    require_space((a, b), record.spaces, f"comparator {record.name}")
    resolved = resolve_options(f"comparator {record.name!r}", record.options, dict(options or {}))
    for label, ds in (("A", a), ("B", b)):
        _require_valid_input(ds, f"result {label}", kind="result")
    refuse_not_standing((a, b), f"comparator {record.name}: no damage to compare")
    produced = _call_plugin("comparator", record.name, record.compare, a, b, resolved)
    comparison = _merge_result("comparator", record.name, xr.Dataset(), xr.Dataset(), produced)
    title_a, title_b = a.attrs.get("title", ""), b.attrs.get("title", "")
    comparison.attrs = {
        **getattr(produced, "attrs", {}),
        **format_header("comparison"),
        "title": title_a if title_a == title_b else f"{title_a} vs {title_b}",
        "comparator": record.name,
        "comparator_version": record_version(item, record.compare),
        "plugin": item.plugin,
        "plugin_version": plugin_version(item),
        "comparator_options": options_json(resolved),
        "input_a_sha256": input_hash(a),
        "input_b_sha256": input_hash(b),
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
    size: tuple[float, float] | None = None,
):
    """Draw ``datasets`` with the plotter called ``kind`` (default: the only one installed).

    Draws into ``ax`` when given, else into a new :class:`matplotlib.figure.Figure`
    (no pyplot, no GUI backend) of ``size`` (width, height) inches, by default
    :data:`FIGURE_SIZE`, one panel-width wider per dataset for a ``side_by_side`` kind.
    Returns the figure.
    """
    record: Plotter = lookup("plotter", kind).record
    datasets = list(datasets)
    require_space(datasets, record.spaces, f"the {record.name} plot")
    resolved = resolve_options(f"plotter {record.name!r}", record.options, dict(options or {}))
    if ax is None:
        from matplotlib.figure import Figure

        width = max(FIGURE_SIZE[0], PANEL_WIDTH * len(datasets)) if record.side_by_side else FIGURE_SIZE[0]
        ax = Figure(figsize=size or (width, FIGURE_SIZE[1]), layout="constrained").add_subplot()
    figure = ax.figure  # kept: a kind may put other axes in the place of ``ax`` (a 3D model's axonometry)
    figure.masonryfw_size_asked = size is not None  # a kind chooses its own size only when none was asked
    _call_plugin("plotter", record.name, record.plot, datasets, ax, resolved)
    if size is not None:  # asked for: it wins over a size the kind chose for itself
        figure.set_size_inches(*size)
        _fit_text(figure)
    return figure


def size_asked(figure) -> bool:
    """Whether the figure :func:`render` made for a plot kind has a size the user asked for (``--size``): a kind
    that lays out panels of its own sizes the figure only when none was (it wraps its text to the size it has)."""
    return bool(getattr(figure, "masonryfw_size_asked", False))


#: The smallest share of its size a figure's text is scaled to, to fit a page asked for.
SMALLEST_TEXT = 0.5


def _fit_text(figure) -> None:
    """Scale the text of ``figure`` down until what is drawn fits its page (titles and legends beside the axes
    stick out of a small one), at most to :data:`SMALLEST_TEXT` of its size; a page still too small is warned
    of."""
    import warnings

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.text import Text

    canvas = FigureCanvasAgg(figure)
    width, height = figure.get_size_inches()
    scale = 1.0
    for _ in range(6):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # constrained layout on a page too small: handled here
            canvas.draw()
            box = figure.get_tightbbox(canvas.get_renderer())
        margin = 0.01  # inches
        if box.x0 >= -margin and box.y0 >= -margin and box.x1 <= width + margin and box.y1 <= height + margin:
            return
        spill = max(box.width / width, box.height / height, 1.03)  # at least a step when it is only off-centre
        factor = max(SMALLEST_TEXT / scale, 0.97 / spill)
        if scale <= SMALLEST_TEXT + 1e-9:
            break
        scale *= factor
        for text in figure.findobj(Text):
            text.set_fontsize(text.get_fontsize() * factor)
        for axes in figure.axes:  # tick labels made at the next draw take the size too (one size an axis)
            axes.tick_params(which="both", labelsize=_tick_size(axes) * factor)
    warnings.warn(f"a figure of {width:.3g} x {height:.3g} in is too small for what it shows, even with its text at "
                  f"{SMALLEST_TEXT:.0%} of its size: ask for a larger --size", UserWarning, stacklevel=3)


def _tick_size(axes) -> float:
    """The size [pt] of the tick labels ``axes`` draws now."""
    labels = axes.xaxis.get_ticklabels()
    if labels:
        return labels[0].get_fontsize()
    from matplotlib import rcParams
    from matplotlib.font_manager import FontProperties

    return FontProperties(size=rcParams["xtick.labelsize"]).get_size_in_points()


def plot_table(
    datasets: Sequence[xr.Dataset], kind: str | None = None, options: Mapping[str, Any] | None = None,
) -> tuple[list[str], list[list]]:
    """The numbers behind the curves of the plot kind ``kind``: ``(header, rows)`` (``plot --format csv``).

    Raises :class:`PluginError` for a kind that draws no curves, naming the kinds that do.
    """
    record: Plotter = lookup("plotter", kind).record
    if record.table is None:
        with_tables = sorted(name for name, item in by_name("plotter").items() if item.record.table is not None)
        raise PluginError(f"the {record.name} plot draws no curves to write as CSV; kinds with curves: "
                          f"{', '.join(with_tables) or 'none installed'}")
    datasets = list(datasets)
    require_space(datasets, record.spaces, f"the {record.name} plot")
    resolved = resolve_options(f"plotter {record.name!r}", record.options, dict(options or {}))
    return _call_plugin("plotter", record.name, record.table, datasets, resolved)
