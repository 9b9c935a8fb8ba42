"""The ``sweep`` and ``archive`` commands this plugin adds to the ``masonryfw`` CLI."""
from __future__ import annotations

import contextlib
import importlib.util
import sys
from pathlib import Path

import click

import masonryfw as mf
import masonryfw.plugin_api as mfp

#: At most this many failed points are listed on the terminal (all are in the output file).
LISTED_FAILURES = 10


def _default_output(spec: str, solver: str) -> Path:
    stem = Path(spec).stem if Path(spec).is_file() else spec
    return Path(f"{stem}.{solver}.sweep.nc")


@contextlib.contextmanager
def _progress(total: int, enabled: bool):
    """``on_point(done, record)`` drawing a click bar on stderr, or doing nothing when off or not a terminal."""
    if not (enabled and sys.stderr.isatty()):
        yield None
        return
    with click.progressbar(length=total, label="sweep", file=sys.stderr, show_pos=True) as bar:
        yield lambda done, record: bar.update(1)


@click.command("sweep")
@click.argument("spec")
@click.option("--plugin", "solver", required=True, help="Name of the solver (see `masonryfw plugins`).")
@click.option("--param", "params", multiple=True, required=True, metavar="KEY=VALUES",
              help="A swept spec key (dotted path, e.g. supports.settling.start) or option.<name>, with values "
                   "start:stop:step (stop included), a comma list 18,21.8,30, or a TOML array. Repeatable.")
@click.option("--zip", "zipped", is_flag=True,
              help="Pair the values of all --param (same count) instead of taking every combination.")
@click.option("--option", "options", multiple=True, metavar="KEY=VALUE", help="A solver option for every point (repeatable).")
@click.option("--scheduler", type=mfp.ADDRESS, help="Use the running dask cluster at ADDRESS (tcp://host:port); left running.")
@click.option("--workers", type=click.IntRange(min=1),
              help="Worker processes of the local cluster [default: one per core].")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="[default: <spec>.<plugin>.sweep.nc]")
@click.option("--store", type=click.Path(file_okay=False),
              help="Result store; points already in it are reused [default: <output stem>.store beside the output].")
@click.option("--no-progress", is_flag=True, help="Do not draw a progress bar.")
def sweep_command(spec: str, solver: str, params: tuple[str, ...], zipped: bool, options: tuple[str, ...],
                  scheduler: str | None, workers: int | None, output: str | None, store: str | None,
                  no_progress: bool) -> None:
    """Solve SPEC (a spec file or a bundled case name) at every point of a parameter grid, on dask.

    Writes one dataset with the swept keys as dimensions, and every point's
    result to a content-addressed store; a re-run reuses what the store holds.
    """
    from .store import Store  # imported here, as the rest: the CLI starts without xarray or dask
    from .sweep import dask_client, failed_points, plan_sweep, run_sweep

    if scheduler and workers:
        raise click.UsageError("--workers sizes the local cluster; it cannot be used with --scheduler")
    plan = plan_sweep(spec, solver, params, mfp.parse_option_pairs(options), zipped)
    out = Path(output) if output else _default_output(spec, solver)
    mfp.check_output_path(out, mfp.input_files(spec))
    store_dir = Path(store) if store else out.with_name(out.name.removesuffix(".nc") + ".store")
    if not store_dir.is_dir():
        mfp.check_output_path(store_dir)  # its folder exists and is writable: the store is made in it
    mfp.claim(store_dir.resolve(), f"sweep store {store_dir}")  # two sweeps on one store would solve its points twice
    command = mfp.command_line()
    kept: list[int] = []
    try:
        with dask_client(scheduler, workers) as client, _progress(len(plan.points), not no_progress) as on_point:
            def counted(done: int, record: dict) -> None:
                kept.append(int(record["status"] == "ok" and not record["reused"]))
                if on_point is not None:
                    on_point(done, record)

            sweep = run_sweep(plan, client, store_dir, out.resolve().parent, counted, command)
    except KeyboardInterrupt:
        raise mf.Interrupted(f"sweep interrupted after {len(kept)} of {len(plan.points)} point(s) ({sum(kept)} newly "
                             f"solved); the store {store_dir} keeps {Store(store_dir).committed()} result(s), which a "
                             f"re-run reuses; {out} is not written") from None
    mf.save(sweep, out, command=command)
    reused = int(sweep.from_store.where(sweep.status == 0, 0).sum())
    failures = failed_points(sweep)
    click.echo(f"sweep: {sweep.status.size} point(s), {sweep.status.size - len(failures)} solved or reused "
               f"({reused} from the store), {len(failures)} failed")
    for where, message in failures[:LISTED_FAILURES]:
        click.echo(f"  failed: {where}: {message.splitlines()[0] if message else ''}", err=True)
    if len(failures) > LISTED_FAILURES:
        click.echo(f"  ... and {len(failures) - LISTED_FAILURES} more (see status/message in {out})", err=True)
    click.echo(f"result: {out}")
    click.echo(f"store: {store_dir}")
    if failures:
        click.get_current_context().exit(1)


@click.command("archive")
@click.argument("directory", type=click.Path(file_okay=False))
@click.option("--from", "sweep_file", type=click.Path(exists=True, dir_okay=False),
              help="The sweep dataset (written by `masonryfw sweep`) to archive into DIRECTORY.")
@click.option("--verify", is_flag=True, help="Check DIRECTORY against its manifest instead of writing it.")
def archive_command(directory: str, sweep_file: str | None, verify: bool) -> None:
    """Write a self-describing archive of a sweep into DIRECTORY, or --verify one.

    The archive holds the sweep dataset, specs, models, results, package
    versions, the command lines and a manifest of checksums. --verify re-checks
    every checksum and that every file reopens; it exits with 1 and lists every
    mismatch.
    """
    from .archive import verify_archive, write_archive

    if verify == bool(sweep_file):
        raise click.UsageError("give either --from SWEEP.nc (to write an archive) or --verify (to check one)")
    if verify:
        problems = verify_archive(directory)
        for problem in problems:
            click.echo(f"  - {problem}")
        if problems:
            click.echo(f"error: {directory}: {len(problems)} mismatch(es)", err=True)
            click.get_current_context().exit(1)
        click.echo(f"OK: {directory}: every checksum matches and every file reopens")
        return
    target = write_archive(directory, sweep_file, mfp.command_line())
    click.echo(f"archive: {target}")


COMMANDS = (sweep_command, archive_command)
#: What ``masonryfw plugins`` and ``--help`` say of ``sweep`` when dask.distributed is not installed.
NEEDS_DASK = "needs dask, not installed: pip install 'masonryfw[sweep]'"


def available_commands() -> list[click.Command]:
    """The commands, ``sweep`` saying what it needs when dask.distributed is missing (looked up, not imported)."""
    if importlib.util.find_spec("distributed") is None:
        sweep_command.short_help = NEEDS_DASK
    return list(COMMANDS)
