"""The ``diagnose`` command this plugin adds to the ``masonryfw`` CLI."""
from __future__ import annotations

import contextlib
import json
import time
from pathlib import Path

import click

import masonryfw as mf
import masonryfw.plugin_api as mfp


def _families(ctx, param, value: str) -> tuple[str, ...]:
    from .scenarios import FAMILIES

    names = tuple(dict.fromkeys(v.strip() for v in value.split(",") if v.strip()))
    unknown = [n for n in names if n not in FAMILIES]
    if unknown or not names:
        raise click.BadParameter(f"{', '.join(unknown) or 'none given'}: choose among {', '.join(FAMILIES)}")
    return names


def _default_output(wall: str) -> Path:
    return Path(f"{Path(wall).stem if Path(wall).is_file() else wall}.diagnosis.nc")


def _echo(text: str, as_json: bool) -> None:
    """The human lines: on stdout, or on stderr when stdout carries the JSON."""
    click.echo(text, err=as_json)


def _ranking_lines(diagnosis, top: int) -> list[str]:
    from . import scenarios

    x_a, x_b = diagnosis.extent
    levelled = diagnosis.survey.levelling is not None
    forward = f"  {diagnosis.ranked_by:>5}" if diagnosis.reranked else ""
    header = f"{'rank':>4}{forward}  {'score':>5}  {'cracks':>6}  {'level':>5}  {'t [mm]':>7}  {'':1}  scenario"
    lines = [header]
    shown = max(top, 1)
    for c in diagnosis.candidates[:shown]:
        level = f"{c.score.levelling:5.2f}" if levelled and c.score.levelling is not None else f"{'-':>5}"
        magnitude = f"{1e3 * c.score.magnitude:7.3g}" if c.score.magnitude is not None else f"{'-':>7}"
        shape = scenarios.shape(c.table, x_a, x_b)
        again = (f"  {c.reranked:5.2f}" if c.reranked is not None else f"  {'-':>5}") if forward else ""
        lines.append(f"{c.rank:>4}{again}  {c.score.total:5.2f}  {c.score.crack:6.2f}  {level}  {magnitude}  "
                     f"{'*' if c.plausible else ' '}  {scenarios.describe(c.table)}{f' ({shape})' if shape else ''}")
    plausible = len(diagnosis.plausible)
    if plausible > shown:
        lines.append(f"   ... {plausible - shown} more plausible candidate(s) (* marks the plausible set; all in the "
                     "output file)")
    return lines


def _levelling_lines(diagnosis) -> list[str]:
    """The levelling's evidence: its noise, the families' probabilities, the free profile."""
    import numpy as np

    if diagnosis.free is None:
        return []
    free = diagnosis.free
    probabilities = ", ".join(f"{family} {p:.2f}" for family, p in sorted(diagnosis.family_probability.items(),
                                                                           key=lambda item: -item[1]))
    deepest = float(free.x[int(np.argmax(free.settlement))])
    return [f"levelling: sigma {1e3 * diagnosis.sigma:.2g} mm ({'given' if diagnosis.sigma_given else 'from the data'});"
            f" the families by its evidence: {probabilities}",
            f"free ground profile (the course following its ground): settles most at {deepest:.3g} m, "
            f"{1e3 * free.magnitude:.3g} mm over its least settling point"]


def _table_lines(table: dict) -> list[str]:
    from .dataset import settlement_table

    values = settlement_table(table)
    return ["[settlement]", *(f"{k} = {json.dumps(v)}" if isinstance(v, str) else f"{k} = {v:g}" for k, v in
                              values.items())]


@click.command("diagnose")
@click.argument("wall")
@click.option("--cracks", "cracks", required=True, type=click.Path(dir_okay=False),
              help="The surveyed cracks: GeoJSON (LineString, MultiLineString; properties.width_mm), CSV "
                   "(crack, x, y[, width_mm]) or DXF (LINE, LWPOLYLINE, POLYLINE).")
@click.option("--cracks-layer", help="The DXF layer holding the cracks [default: every layer].")
@click.option("--levelling", type=click.Path(dir_okay=False),
              help="CSV x, y, dy of a course laid level (dy from level, negative down).")
@click.option("--unit", type=click.Choice(["m", "cm", "mm"]),
              help="Unit of the crack and levelling coordinates and dy [default: m, or the DXF's own]; widths "
                   "are always mm.")
@click.option("--profiles", "families", default="step,gaussian,linear", show_default=True, callback=_families,
              help="The scenario families to try, comma separated.")
@click.option("--segment", type=mfp.LENGTH,
              help="Length of the ground segments [m] [default: the median unit length].")
@click.option("--tolerance", type=mfp.LENGTH,
              help="How far a surveyed line may lie from the joint it follows [m] [default: half the median unit "
                   "height].")
@click.option("--plugin", "solver", default="la", show_default=True,
              help="The solver whose cracks are matched (la: its collapse mechanism).")
@click.option("--option", "options", multiple=True, metavar="KEY=VALUE", help="A solver option (repeatable).")
@click.option("--levelling-sigma", "sigma_mm", type=mfp.Number("mm", above=0.0, at_most=1000.0), metavar="MM",
              help="The levelling's noise, its standard deviation [mm] [default: read from the data, the median "
                   "absolute deviation of its second differences].")
@click.option("--rerank", type=click.IntRange(min=0), metavar="N",
              help="Re-rank the best N candidates by forward fdem runs to their settlements, scored on fdem's "
                   "cracks (0: rank by the search's solver alone) [default: as many of the best 5 as fit in "
                   "--budget].")
@click.option("--budget", type=mfp.Number("seconds", at_least=0.0, at_most=1e7), default=120.0, show_default=True,
              metavar="SECONDS",
              help="The time the default re-ranking may take, by fdem's estimate.")
@click.option("--workers", type=click.IntRange(min=1), default=1, show_default=True,
              help="Solve the scenarios on this many local processes.")
@click.option("--scheduler", type=mfp.ADDRESS,
              help="Solve the scenarios on the running dask cluster at ADDRESS (tcp://host:port); left running.")
@click.option("--verify", "verify_with", metavar="SOLVER",
              help="Run the best candidates (at most 3, at most --top) forward with SOLVER (e.g. fdem) to their "
                   "estimated settlement.")
@click.option("--top", type=click.IntRange(min=1), default=5, show_default=True,
              help="Candidates listed (the JSON also lists every plausible one).")
@click.option("--json", "as_json", is_flag=True, help="Print the diagnosis as one JSON object on stdout.")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="[default: <wall>.diagnosis.nc]")
@mfp.PROGRESS
def diagnose_command(wall: str, cracks: str, cracks_layer: str | None, levelling: str | None, unit: str | None,
                     families: tuple[str, ...], segment: float | None, tolerance: float | None, solver: str,
                     options: tuple[str, ...], sigma_mm: float | None, rerank: int | None, budget: float,
                     workers: int, scheduler: str | None, verify_with: str | None, top: int, as_json: bool,
                     output: str | None, progress: bool | None) -> None:
    """Which settlement of the ground under WALL explains the surveyed cracks?

    WALL is a bundled case, a spec (parametric or drawn; its supports, [settlement] and [loading] may be left
    out) or a model file. Its ground is cut into segments and every scenario of the chosen families (a step,
    a Gaussian trough, a tilt) is solved and scored against the cracks (and the levelling); the candidates
    are ranked best first, with the plausible set (within 0.05 of the best score) marked. Writes the
    diagnosis dataset (`masonryfw plot OUT --kind diagnosis`, `masonryfw report OUT`). Ctrl-C writes what
    was ranked so far (exit status 130).
    """
    from . import dataset, parallel
    from .diagnosis import KEPT, prepare, search, verify, wall_model
    from .reranking import affordable
    from .reranking import rerank as rerank_by
    from .survey import read_cracks, read_levelling

    if scheduler and workers > 1:
        raise click.UsageError("--workers sizes the local processes; it cannot be used with --scheduler")
    inputs = mfp.input_files(wall, cracks, levelling)
    out = Path(output) if output else _default_output(wall)
    mfp.check_output_path(out, inputs)
    survey = read_cracks(cracks, unit, cracks_layer)
    if levelling:
        survey = survey.with_levelling(read_levelling(levelling, survey.sources["unit"]), Path(levelling).name)
    solver_options = mfp.parse_option_pairs(options)
    mf.get_solver(solver)  # an unknown solver named before the wall is built
    if verify_with:
        mf.get_solver(verify_with)
    model = wall_model(wall)
    mfp.require_space([model], (2,), "masonryfw diagnose")
    sigma = None if sigma_mm is None else 1e-3 * sigma_mm
    diagnosis = prepare(model, survey, families, segment, solver, solver_options, tolerance, sigma)
    share = 1 if scheduler else workers  # a cluster's size is its own
    expected = (f"; expect about {mfp.duration_text(diagnosis.expected.seconds / share)}"
                f"{f' on {workers} processes' if workers > 1 else ''}" if diagnosis.expected else "")
    click.echo(f"diagnose: {len(diagnosis.tables):,} scenarios ({', '.join(families)}) with {solver} on "
               f"{len(diagnosis.model.block) - int(mfp.masonry_blocks(diagnosis.model.block_role.values).sum())} "
               f"ground pieces{expected}; Ctrl-C keeps the ranking of those tried", err=True)
    bar = mfp.progress_bar(progress)
    started = time.perf_counter()
    try:
        where = (parallel.dask_cluster(scheduler) if scheduler else parallel.local_processes(workers)
                 if workers > 1 else contextlib.nullcontext(parallel.serial))
        with where as runner:
            search(diagnosis, solver_options, progress=bar or mfp.no_progress, runner=runner)
        count = (rerank if rerank is not None else affordable(diagnosis, budget)) if not diagnosis.interrupted else 0
        if count:
            click.echo(f"diagnose: re-ranking the best {count} by forward fdem runs to their settlements", err=True)
            rerank_by(diagnosis, count, progress=bar or mfp.no_progress)
        if verify_with and not (diagnosis.interrupted or diagnosis.rerank_interrupted):
            verify(diagnosis, verify_with, min(top, KEPT), progress=bar or mfp.no_progress)
    finally:
        if bar is not None:
            bar.close()
    seconds = time.perf_counter() - started
    mf.save(dataset.to_dataset(diagnosis, wall), out, command=mfp.command_line(), protect=inputs)
    _report(diagnosis, wall, top, as_json, seconds, out)
    if diagnosis.rerank_interrupted:
        raise mf.Interrupted(f"the re-ranking was interrupted after {diagnosis.reranked} forward run(s): the ranking "
                             f"with those is written to {out}")
    if diagnosis.interrupted:
        raise mf.Interrupted(f"interrupted after {len(diagnosis.candidates) + len(diagnosis.failed)} scenario(s): "
                             f"the ranking of those is written to {out}")
    if diagnosis.verify_interrupted:
        done = sum(c.verified is not None for c in diagnosis.candidates)
        raise mf.Interrupted(f"the verification with {verify_with} was interrupted: {done} candidate(s) verified "
                             f"before it; the run cut short is not kept as a verification; the ranking and those are "
                             f"written to {out}")


def _report(diagnosis, wall: str, top: int, as_json: bool, seconds: float, out: Path) -> None:
    from . import dataset, scenarios

    survey = diagnosis.survey
    ground = int(mfp.support_blocks(diagnosis.model.block_role.values).sum())
    _echo(f"diagnose {wall}: {ground} ground segments of {diagnosis.segment:.4g} m "
          f"({'given' if diagnosis.segment_given else 'the median unit length'}); {len(survey.cracks)} surveyed "
          f"line(s) run along {diagnosis.observed.joints.size} joints within {diagnosis.wall.tolerance:.3g} m, "
          f"{len(diagnosis.observed.unmatched)} match no joint", as_json)
    for k in diagnosis.observed.unmatched:
        _echo(f"  no joint near crack {survey.names[k]!r}: drawn across units, or off the wall's joints", as_json)
    failed = f", {len(diagnosis.failed)} could not be solved" if diagnosis.failed else ""
    again = f"; re-ranked the best {diagnosis.reranked} with {diagnosis.ranked_by}" if diagnosis.reranked else ""
    if diagnosis.rerank_failed:
        again += f" ({len(diagnosis.rerank_failed)} forward run(s) failed: {diagnosis.rerank_failed[0][1]})"
    _echo(f"tried {len(diagnosis.candidates) + len(diagnosis.failed)} scenarios with {diagnosis.solver}{failed}{again}"
          f"; {seconds:.3g} s in all", as_json)
    for line in _ranking_lines(diagnosis, top):
        _echo(line, as_json)
    _echo(diagnosis.verdict(), as_json)
    for line in _levelling_lines(diagnosis):
        _echo(line, as_json)
    best = diagnosis.best
    if best.score.unexplained:
        names = ", ".join(repr(survey.names[k]) for k in best.score.unexplained[:8])
        more = f" and {len(best.score.unexplained) - 8} more" if len(best.score.unexplained) > 8 else ""
        _echo(f"the best leaves {len(best.score.unexplained)} surveyed line(s) unexplained: {names}{more}", as_json)
    if best.score.unobserved:
        _echo(f"the best cracks {best.score.unobserved} joint(s) nobody surveyed", as_json)
    for candidate in diagnosis.candidates[:top]:
        if candidate.verified:
            v = candidate.verified
            width = "-" if v.get("crack_width") is None else f"{1e3 * v['crack_width']:.3g} mm"
            category = "-" if v.get("damage_category") is None else f"{v['damage_category']:.0f}"
            _echo(f"verified with {diagnosis.verified_with}: {scenarios.describe(candidate.table)} at "
                  f"{1e3 * candidate.score.magnitude:.3g} mm: widest crack {width}, damage category {category}",
                  as_json)
    _echo("the best candidate, to paste into a spec:", as_json)
    for line in _table_lines(best.table):
        _echo(f"  {line}", as_json)
    _echo(f"result: {out}", as_json)
    if as_json:
        click.echo(dataset.json_text(diagnosis, top))


COMMANDS = (diagnose_command,)
