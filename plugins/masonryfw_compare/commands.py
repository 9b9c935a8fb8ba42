"""Click commands this plugin adds to the ``masonryfw`` CLI (hook ``masonryfw_commands``)."""
from __future__ import annotations

from pathlib import Path

import click

import masonryfw as mf
import masonryfw.plugin_api as mfp


@click.command("gallery")
@click.option("-o", "--output", type=click.Path(file_okay=False), default="docs/gallery", show_default=True,
              help="Folder of the pictures (<case>.png).")
@click.option("--agreement", type=click.Path(dir_okay=False), default=None,
              help="Markdown table of the scores [default: agreement.md beside the output folder].")
@click.option("--case", "cases", multiple=True, help="Only this bundled case (repeatable) [default: all ten].")
@click.option("--method", "methods", multiple=True,
              help="Only this method among la, fdem, jmm (repeatable) [default: all installed].")
@click.option("--option", "options", multiple=True, metavar="METHOD.KEY=VALUE",
              help="A solver option of one method, e.g. jmm.mesh_size=0.05 (repeatable).")
@click.option("--skip", "skips", multiple=True, metavar="METHOD:CASE",
              help="Do not run METHOD on bundled case CASE, e.g. jmm:facade-3 (repeatable).")
@click.option("--notes", type=click.Path(dir_okay=False, exists=True), default=None,
              help="Markdown file put into the agreement file as its Discussion section.")
def gallery_command(
    output: str, agreement: str | None, cases: tuple[str, ...], methods: tuple[str, ...], options: tuple[str, ...],
    skips: tuple[str, ...], notes: str | None,
) -> None:
    """Solve every bundled wall with every chosen method, draw and score them."""
    from .gallery import gallery_command_line, run_gallery  # imported here: the CLI starts without matplotlib

    out = Path(output)
    table = Path(agreement) if agreement else out.parent / "agreement.md"
    command = gallery_command_line(output, str(table), methods, options, skips, cases, notes)
    for path in run_gallery(out, table, list(cases) or None, echo=click.echo, methods=list(methods) or None,
                            options=options, skips=skips, command=command,
                            notes=Path(notes) if notes else None):
        click.echo(f"wrote {path}")


@click.command("export")
@click.argument("result", type=click.Path(dir_okay=False))
@click.option("--format", "file_format", type=click.Choice(["vtk"]), default="vtk", show_default=True)
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="[default: <result>.vtu]")
def export_command(result: str, file_format: str, output: str | None) -> None:
    """Write RESULT as VTK files for ParaView: blocks, joints, mesh, plastic points, and a .vtm index."""
    from .export import export_vtk  # imported here: the CLI starts without meshio

    dataset = mf.open_dataset(result)
    for path in export_vtk(dataset, Path(output) if output else Path(result).with_suffix(".vtu")):
        click.echo(f"wrote {path}")


@click.command("report")
@click.argument("results", nargs=-1, required=True, type=click.Path(dir_okay=False, exists=True))
@click.option("-o", "--output", type=click.Path(dir_okay=False), required=True, help="The HTML file to write.")
@mfp.PROGRESS
def report_command(results: tuple[str, ...], output: str, progress: bool | None) -> None:
    """Write one self-contained HTML report of RESULTS (one model): the wall, its spec, the key numbers,
    every figure, the agreement of the results and their provenance; a diagnosis file (`masonryfw diagnose`)
    among them adds its verdict, ranked candidates and figure."""
    from .report import report_html  # imported here: the CLI starts without matplotlib

    mfp.check_output_path(output, list(results), (".html", ".htm"))
    context = click.get_current_context()
    bar = mfp.progress_bar(progress)
    try:
        text = report_html(list(results), context.find_root().obj["command_line"], bar)
    finally:
        if bar is not None:
            bar.close()
    mfp.save_text(text, output, protect=list(results), suffixes=(".html", ".htm"))
    click.echo(f"report: {output} ({len(text) / 1e6:.2g} MB, {text.count('<img ')} figures)")


COMMANDS = (gallery_command, export_command, report_command)
