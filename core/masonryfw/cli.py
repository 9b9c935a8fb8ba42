"""The ``masonryfw`` command line: a thin click layer over the public API.

Every :class:`masonryfw.MasonryError` (and every ``OSError`` on a user's path)
becomes ``error: <message>`` on stderr and exit code 1, without a traceback,
unless ``--debug`` is given; usage errors exit with 2 (click's default).
"""
from __future__ import annotations

import itertools
import json
import shlex
import signal
import sys
import textwrap
import warnings
from pathlib import Path
from typing import Any

import click
import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.command_kit import FIGURE, OPTIONS, PROGRESS, command_line
from masonryfw.contract.registry import command_plugin, installed_plugins, installed_solvers, plugin_commands
from masonryfw.runtime import inputs, signals
from masonryfw.runtime.locks import release_all

LONG_RUN = 60.0  # seconds: the solve command prints the estimate of a run longer than this
#: Seconds: a run estimated longer starts only with --force or its end set (--option settlement=): a volume loss typed
#: as 1e6 % made fdem start a run of 785 hours.
UNASKED_RUN = 12 * 3600.0


def _error_message(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.filename is not None:
        return f"{exc.filename}: {exc.strerror or exc}"
    return str(exc)


class _MasonryGroup(click.Group):
    """Adds the plugins' commands, remembers the command line (for history lines) and
    turns errors into messages."""

    def _plugin_commands(self, ctx) -> dict[str, click.Command]:
        """Commands contributed by plugins; one that reuses a built-in name is an error."""
        extra = plugin_commands()
        taken = sorted(set(extra) & set(super().list_commands(ctx)))
        if taken:
            raise mf.PluginError(
                f"command {taken[0]!r} of plugin {command_plugin(taken[0])} clashes with the built-in command"
            )
        return extra

    def list_commands(self, ctx):
        try:
            extra = self._plugin_commands(ctx)
        except mf.MasonryError as exc:  # --help must still work
            click.echo(f"warning: {exc}", err=True)
            extra = {}
        return sorted([*super().list_commands(ctx), *extra])

    def get_command(self, ctx, name):
        return super().get_command(ctx, name) or self._plugin_commands(ctx).get(name)

    def make_context(self, info_name, args, parent=None, **extra):
        extra.setdefault("obj", {})["command_line"] = shlex.join(["masonryfw", *args])
        return super().make_context(info_name, args, parent, **extra)

    def invoke(self, ctx):
        try:
            with warnings.catch_warnings():
                warnings.showwarning = _show_warning
                warnings.simplefilter("default", mf.PlausibilityWarning)  # each shown, whoever catches warnings
                return super().invoke(ctx)
        except mf.Interrupted as exc:
            click.echo(str(exc), err=True)
            ctx.exit(signals.exit_status())
        except (mf.MasonryError, OSError) as exc:
            if ctx.params.get("debug"):
                raise
            click.echo(f"error: {_error_message(exc)}", err=True)
            ctx.exit(1)
        finally:
            release_all()  # the claims of outputs a failed or interrupted command did not write


@click.group(cls=_MasonryGroup)
@click.option("--debug", is_flag=True, help="Show the full traceback of an error.")
@click.version_option(mf.__version__, prog_name="masonryfw")
def cli(debug: bool) -> None:
    """Failure analysis of dry-joint masonry walls under foundation settlements."""




# ---------------------------------------------------------------- progress

# ---------------------------------------------------------------- build, check, info, datasets

@cli.command()
@click.argument("spec")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Model file to write [default: <spec stem>.nc].")
def build(spec: str, output: str | None) -> None:
    """Build a model from SPEC (a TOML file or a bundled case name)."""
    spec_path = mfp.source_path(spec)
    read_files = mfp.input_files(spec)
    out = Path(output) if output else Path(f"{Path(spec).stem}.nc")
    mfp.check_output_path(out, read_files)
    model = mf.build(spec_path)
    mf.save(model, out, command=command_line(), protect=read_files)
    click.echo(f"wrote {out}: {model.sizes['block']} blocks, {model.sizes.get('interface', 0)} interfaces")
    for note in filter(None, str(model.attrs.get("laying_notes", "")).splitlines()):
        click.echo(f"  laid: {note}")


@cli.command(name="check")
@click.argument("file")
@click.option("--strict", is_flag=True, help="Count implausible values (warnings) as problems: exit 1.")
def check_command(file: str, strict: bool) -> None:
    """Check FILE (model, result or comparison) and print every problem found, then every value outside
    the range of real masonry (a warning; a problem with --strict)."""
    ds = mf.open_dataset(file)
    problems = mf.check(ds)
    implausible = mf.plausibility(ds) if "block_role" in ds and not problems else []
    for problem in problems:
        click.echo(f"  - {problem}")
    for message in implausible:
        click.echo(f"  - {'' if strict else 'warning: '}{message}")
    if problems or (strict and implausible):
        counted = len(problems) + (len(implausible) if strict else 0)
        click.echo(f"error: {file}: {counted} problem(s)", err=True)
        click.get_current_context().exit(1)
    if implausible:
        click.echo(f"{file}: {len(implausible)} implausible value(s) (warnings; --strict makes them errors)", err=True)
    if ds.attrs.get("masonryfw_format") == "comparison":
        click.echo(f"OK: comparison by {ds.attrs.get('comparator', '?')} of {ds.attrs.get('title', '')}")
    else:
        click.echo(f"OK: {ds.sizes.get('block', 0)} blocks, {ds.sizes.get('interface', 0)} interfaces")


@cli.command()
@click.argument("model")
def info(model: str) -> None:
    """Describe MODEL (a file or a bundled case name)."""
    for line in mf.describe_model(mf.open_model(model)):
        click.echo(line)


@cli.command()
def datasets() -> None:
    """List the bundled cases (the paper's walls, then the drawn examples) with their titles and block counts."""
    for name in mf.BUNDLED_NAMES:
        model = mf.build(mf.bundled_spec_path(name), validate=False)
        click.echo(f"{name:<16} {model.attrs.get('title', ''):<24} {model.sizes['block']:>5} blocks")


# ---------------------------------------------------------------- plugins

def _record_lines(kind: str, record) -> list[str]:
    lines = [f"  {kind} {record.name}: {record.summary}"]
    for option in record.options:
        lines.append(f"      --option {option.name}={option.usage()}  {option.help}".rstrip())
    for variant in getattr(record, "variants", ()):
        lines.append(f"      variant {variant.label}: {json.dumps(dict(variant.options))}")
    return lines


@cli.command()
def plugins() -> None:
    """List the installed plugins and their solvers, comparators and plotters with their options."""
    for plugin in installed_plugins():
        origin = f"{plugin.distribution} {plugin.version}" if plugin.distribution else "registered in-process"
        click.echo(f"{plugin.name} ({origin})")
        records: list[tuple[str, Any]] = [("solver", r) for r in plugin.solvers]
        records += [("comparator", r) for r in plugin.comparators] + [("plotter", r) for r in plugin.plotters]
        for kind, record in records:
            for line in _record_lines(kind, record):
                click.echo(line)
        for command in plugin.commands:
            click.echo(f"  command {command.name}: {command.get_short_help_str(limit=70)}")
        if not records and not plugin.commands:
            click.echo("  (contributes nothing)")


# ---------------------------------------------------------------- solve, compare, plot

def _scalar_summary(ds, names) -> str:
    parts = []
    for name in names:
        variable = ds[name]
        if variable.ndim == 0 and np.issubdtype(variable.dtype, np.number):
            units = variable.attrs.get("units", "")
            parts.append(f"{name} = {float(variable):.6g}{' ' + units if units not in ('', '1') else ''}")
    return ", ".join(parts)


def _open_input(path_or_name: str, validate: bool = True):
    """A dataset file as it is (model, result); a spec file or a bundled case name as its model
    (not checked with ``validate`` False: to draw a model that is wrong)."""
    path = Path(path_or_name)
    if path.is_file() and not mfp.is_spec(path):
        return mf.open_checked(path) if validate else mf.open_dataset(path)
    return mf.open_model(path_or_name, validate=validate)


def _solved(model: str, solver: str, output: str | None, options: dict[str, str], progress: bool | None,
            force: bool):
    """Solve and write the result (``solve`` and ``capacity``): the output path checked before the work, long
    runs announced, Ctrl-C keeping what an incremental solver computed (exit 130)."""
    read_files = mfp.input_files(model)
    out = Path(output) if output else Path(f"{Path(model).stem if read_files else model}.{solver}.nc")
    mfp.check_output_path(out, read_files)
    plan = mf.solve_plan(mf.open_model(model), solver, options)  # checked, looked up, resolved, estimated: once
    expected = plan.estimate
    if expected is not None and not expected.seconds <= UNASKED_RUN and not force:
        sooner = "a smaller settlement" if "settlement" in options else "--option settlement=..."
        raise mf.MasonryError(f"{solver}: expect about {mfp.duration_text(expected.seconds)} ({expected.basis}), over "
                              f"the {UNASKED_RUN / 3600:g} h a run starts without asking; is the model (see its "
                              f"warnings) and the settlement what was meant? Run it with --force, or end it sooner "
                              f"with {sooner}")
    if expected is not None and expected.seconds > LONG_RUN:
        click.echo(f"{solver}: expect about {mfp.duration_text(expected.seconds)} and "
                   f"{mfp.size_text(expected.memory)} ({expected.basis}); Ctrl-C keeps what is computed", err=True)
    bar = mfp.progress_bar(progress)
    try:
        result = plan.run(progress=bar)
    except KeyboardInterrupt:
        raise mf.Interrupted(f"solve {solver}: interrupted before the solver had a result to keep: nothing written") \
            from None
    finally:
        if bar is not None:
            bar.close()
    mf.save(result, out, command=command_line(), protect=read_files)
    if int(result.attrs.get("interrupted", 0)):
        raise mf.Interrupted(f"interrupted at settlement {_last_settlement(result)}: partial result written to {out}")
    return result, out, plan


def SOLVER_RUN(command):  # a decorator, named like OPTIONS and PROGRESS
    """``-o``, ``--option``, ``--progress`` and ``--force``: the options of one solver run (solve, capacity)."""
    for option in reversed((
        click.option("-o", "--output", type=click.Path(dir_okay=False), help="[default: <model>.<plugin>.nc]"),
        OPTIONS,
        PROGRESS,
        click.option("--force", is_flag=True, help=f"Start a run estimated longer than {UNASKED_RUN / 3600:g} h."),
    )):
        command = option(command)
    return command


@cli.command()
@click.argument("model")
@click.option("--plugin", "solver", required=True, help="Name of the solver (see `masonryfw plugins`).")
@SOLVER_RUN
def solve(model: str, solver: str, output: str | None, options: dict[str, str], progress: bool | None,
          force: bool) -> None:
    """Solve MODEL (a model file, a spec file or a bundled case name) with a solver plugin.

    Prints the headline numbers: alpha and the reaction at collapse (limit
    analysis); the dead, smallest and plateau reactions with their settlements
    (incremental solvers); else the solver's scalar outputs. Ctrl-C keeps what an incremental solver has computed
    so far (exit status 130).
    """
    result, out, plan = _solved(model, solver, output, options, progress, force)
    numbers = ", ".join(map(str, mf.key_numbers(result))) or _scalar_summary(
        result, [name for name in result.data_vars if name not in plan.model.variables])
    stop = f"; {result.attrs['stop_reason']}" if result.attrs.get("stop_reason") else ""
    click.echo(f"result: {out}")
    headline = mf.headline_text(result)
    if headline:
        click.echo(f"in short: {headline}")
    click.echo(f"{solver}: {numbers + stop + '; ' if numbers else ''}wall time {result.attrs['wall_time_s']:.3g} s")
    stages = mf.stages_text(result)
    if stages:
        click.echo(f"stages {stages}")
    walls = mf.walls_text(result)
    if walls:
        click.echo(walls)


#: A solver option that spaces its records (la-incremental's steps grow while its mechanism holds): capacity asks
#: for at least this many over the run, so that the settlement of each category is known to a hundredth of it.
RECORDS = "records"
CAPACITY_RECORDS = 100
#: A solver option that ends a run at its reaction plateau, before the damage the capacity asks for.
PLATEAU_STOP = "plateau_tolerance"


@cli.command()
@click.argument("model")
@click.option("--plugin", "solver", default="fdem", show_default=True,
              help="An incremental solver with crack widths: fdem or la-incremental.")
@click.option("--category", type=click.IntRange(1, 5), help="Say first where this damage category is reached.")
@click.option("--settlement", type=mfp.LENGTH, help="Run to this settlement parameter [m] (a tunnel's S_max).")
@click.option("--volume-loss", "volume_loss", type=mfp.Number("%", above=0.0, at_most=100.0),
              help="Run a tunnel to this volume loss [%].")
@SOLVER_RUN
def capacity(model: str, solver: str, category: int | None, settlement: float | None, volume_loss: float | None,
             output: str | None, options: dict[str, str], progress: bool | None, force: bool) -> None:
    """How much settlement (a tunnel: volume loss) MODEL takes before each damage category, from one run.

    The run's widest crack gives the settlement at which each category is first reached (stage 3), beside
    the LTSM's (stage 2) and the greenfield screen's (stage 1) over the model's settlement profile. A
    tunnel's S_max is proportional to its volume loss and the trough keeps its shape, so one run to a larger
    settlement answers every smaller volume loss. The result file keeps them (``category_settlement``, ...).
    A solver that stops at a reaction plateau (fdem) runs to the end. MODEL may be an incremental solver's
    result instead (``masonryfw solve``'s to a tunnel's S_max): its history is read, nothing is run again.
    """
    if _is_result(model):
        given = [name for name, value in (("--settlement", settlement), ("--volume-loss", volume_loss),
                                          ("--option", options), ("-o", output)) if value]
        if given:
            raise mf.InputError(f"{model} is a result: it is read, not run again ({', '.join(given)} would run it); "
                                "give its model to run a new one")
        return _capacity_text_of(mf.open_checked(model), model, category)
    if settlement is not None and volume_loss is not None:
        raise mf.InputError("give --settlement or --volume-loss, not both")
    if volume_loss is not None:
        per_metre = mfp.volume_loss_per_settlement(mf.open_model(model))
        if per_metre is None:
            raise mf.InputError(f"--volume-loss: {model} is not over a tunnel's trough; give --settlement [m]")
        settlement = volume_loss / per_metre
    if settlement is not None:
        options = {**options, "settlement": repr(settlement)}
    if not mf.get_solver(solver).history:
        raise mf.SolveError(f"{solver}: its result has no history of crack widths to find the damage categories in; "
                            f"use one of {', '.join(s.name for s in installed_solvers() if s.history)}")
    declared = {o.name: o for o in mf.get_solver(solver).options}
    if PLATEAU_STOP in declared and PLATEAU_STOP not in options:
        options = {**options, PLATEAU_STOP: "0"}  # the categories past a reaction plateau are what is asked
    if RECORDS in declared and RECORDS not in options and declared[RECORDS].default < CAPACITY_RECORDS:
        options = {**options, RECORDS: str(CAPACITY_RECORDS)}  # each category's settlement known to a hundredth
    result, out, _ = _solved(model, solver, output, options, progress, force)
    _capacity_text_of(result, out, category, f"capacity (the result is written to {out})")


def _is_result(path: str) -> bool:
    """Whether ``path`` is a result file (not a spec, a model or a bundled case's name)."""
    file = Path(path)
    return file.is_file() and not mfp.is_spec(file) and mf.open_dataset(file).attrs.get("masonryfw_format") == "result"


def _capacity_text_of(result, out, category: int | None, what: str = "capacity") -> None:
    """Print where each damage category is first reached in ``result`` (written to, or read from, ``out``)."""
    mfp.refuse_not_standing([result], what)
    solver = result.attrs.get("solver", "the run")
    text = mf.capacity_text(result, category)
    if not text:
        raise mf.SolveError(f"{solver}: its result has no crack-width history to find the damage categories in; "
                            "use fdem or la-incremental")
    click.echo(f"result: {out}")
    stop = f" ({result.attrs['stop_reason']})" if result.attrs.get("stop_reason") else ""
    click.echo(f"{solver}: wall time {result.attrs['wall_time_s']:.3g} s{stop}")
    click.echo(text)


def _last_settlement(result) -> str:
    if "step_settlement" in result and result.step_settlement.size:
        return f"{float(result.step_settlement.values[-1]):.6g} m"
    return "0 m"


@cli.command()
@click.argument("results", nargs=-1, required=True)
@click.option("--comparator", help="Name of the comparator [default: the only one installed].")
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Write the comparison dataset here (two results only).")
@OPTIONS
@click.option("--json", "as_json", is_flag=True, help="Print the scalar scores as JSON.")
def compare(
    results: tuple[str, ...], comparator: str | None, output: str | None, options: dict[str, str], as_json: bool
) -> None:
    """Compare two or more RESULTS of one model: their headline numbers, then every pair's scores.

    The first result is the reference (a) of each pair it is in. Each score comes with what it
    measures and its range.
    """
    if len(results) < 2:
        raise click.UsageError(f"compare needs two or more results, got {len(results)}")
    if output and len(results) != 2:
        raise mf.MasonryError(f"-o writes the comparison of two results, got {len(results)}: compare them in pairs")
    if output:
        mfp.check_output_path(output, list(results))
    datasets = [mf.open_dataset(r) for r in results]
    standing = [mfp.standing_text(ds) is None for ds in datasets]  # a run whose masonry fell has no damage to score
    pairs = [(i, j) for i, j in itertools.combinations(range(len(results)), 2) if standing[i] and standing[j]]
    comparisons = [mf.compare(datasets[i], datasets[j], comparator, options) for i, j in pairs]
    if output:
        mf.save(comparisons[0], output, command=command_line(), protect=list(results))
    if as_json:
        click.echo(json.dumps(_comparison_json(results, pairs, comparisons), default=str, allow_nan=False))
        return
    letters = [chr(ord("A") + i) if i < 26 else f"R{i + 1}" for i in range(len(results))]
    for letter, path, ds in zip(letters, results, datasets):
        click.echo(f"{letter}: {path} ({mf.result_label(ds)})")
    click.echo("")
    click.echo(mfp.text_table(["", *letters], mfp.headline_rows(datasets)))
    for said in (mfp.r0_text(datasets, letters), mf.damage_text(datasets, letters)):
        if said:
            click.echo(textwrap.fill(said, 100))
    click.echo("")
    if not comparisons:
        click.echo("no pair to score: " + "; ".join(f"{letter} did not stand under its own weight" for letter, ok
                                                     in zip(letters, standing) if not ok))
        return
    rows = mfp.score_rows(comparisons)
    header = [f"{comparisons[0].attrs['comparator']} score", *(f"{letters[i]}-{letters[j]}" for i, j in pairs)]
    click.echo(mfp.text_table(header, rows) if rows else "(no scalar scores)")
    if output:
        click.echo(f"comparison: {output}")


def _json_number(value):
    """A score as JSON has it: a number, or null where it is not one (NaN and inf are not JSON)."""
    return None if isinstance(value, float) and not np.isfinite(value) else value


def _comparison_json(results, pairs, comparisons) -> dict:
    """``{"comparator", "scores"}`` for two results; with more, ``"pairs"`` of ``{"a", "b", "scores"}``."""
    scores = [{str(n): _json_number(c[n].values.item()) for n in c.data_vars if c[n].ndim == 0} for c in comparisons]
    out: dict[str, Any] = {"comparator": comparisons[0].attrs["comparator"]}
    if len(results) == 2:
        out["scores"] = scores[0]
    else:
        out["pairs"] = [{"a": results[i], "b": results[j], "scores": s} for (i, j), s in zip(pairs, scores)]
    return out


@cli.command()
@click.argument("results", nargs=-1, required=True)
@click.option("--kind", help="Plot kind (see `masonryfw plugins`) [default: the only one installed].")
@click.option("-o", "--output", type=click.Path(dir_okay=False), required=True,
              help="Image file (png, svg, pdf), or a .csv file of the curves' numbers.")
@click.option("--format", "file_format", type=click.Choice(["png", "svg", "pdf", "csv"]), default=None,
              help="[default: from the output's suffix] csv: the numbers behind the curves (history).")
@FIGURE
@OPTIONS
def plot(results: tuple[str, ...], kind: str | None, output: str, file_format: str | None,
         size: tuple[float, float] | None, dpi: int, options: dict[str, str]) -> None:
    """Plot one or more RESULTS (result or model files, spec files, bundled case names) with a plotter plugin.

    Kinds that overlay (history) or set side by side (compare) take several results.
    """
    read_files = mfp.input_files(*results)
    wanted = f".{file_format}" if file_format else Path(output).suffix.lower()
    if wanted != Path(output).suffix.lower():
        raise mf.MasonryError(f"{output}: --format {file_format} needs a file ending in {wanted}")
    if wanted == ".csv":
        mfp.check_output_path(output, read_files, (".csv",))
        header, rows = mf.plot_table([_open_input(r) for r in results], kind, options)
        mfp.save_text(mfp.csv_text(header, rows), output, protect=read_files, suffixes=(".csv",))
        click.echo(f"table: {output} ({len(rows)} rows)")
        return
    mfp.check_output_path(output, read_files, mfp.FIGURE_FORMATS)
    figure = mf.render([_open_input(r, validate=kind != "model") for r in results], kind, options, size=size)
    mf.save_figure(figure, output, protect=read_files, dpi=dpi, cropped=size is None)
    width, height = figure.get_size_inches()
    click.echo(f"plot: {output} ({width:.3g} x {height:.3g} in at {dpi} dpi)")


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    click.echo(f"warning: {message}", err=True)


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``masonryfw`` script and of ``python -m masonryfw``.

    A closed output pipe (``masonryfw datasets | head -1``) ends the command
    quietly, as for any Unix tool; Ctrl-C ends it with status 130 and a line
    saying what was kept (see the commands).
    """
    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    signals.install()
    inputs.guard_reads()
    try:
        code = cli.main(args=argv, prog_name="masonryfw", standalone_mode=False)
    except click.ClickException as exc:  # usage errors: exit 2
        exc.show()
        sys.exit(exc.exit_code)
    except click.exceptions.Abort as exc:  # click's form of a KeyboardInterrupt outside a solve
        cause = exc.__cause__ or exc.__context__
        if isinstance(cause, mf.WriteInterrupted) and cause.signum not in signals.RECEIVED:
            signals.RECEIVED.append(cause.signum)
        click.echo(signals.kept(), err=True)
        sys.exit(signals.exit_status())
    sys.exit(code if isinstance(code, int) else 0)
