"""Click commands this plugin adds to the ``masonryfw`` CLI (hook ``masonryfw_commands``)."""
from __future__ import annotations

from pathlib import Path

import click

import masonryfw as mf


@click.command("gallery")
@click.option("-o", "--output", type=click.Path(file_okay=False), default="docs/gallery", show_default=True,
              help="Folder of the pictures (<case>.png).")
@click.option("--agreement", type=click.Path(dir_okay=False), default=None,
              help="Markdown table of the scores [default: agreement.md beside the output folder].")
@click.option("--case", "cases", multiple=True, help="Only this bundled case (repeatable) [default: all ten].")
def gallery_command(output: str, agreement: str | None, cases: tuple[str, ...]) -> None:
    """Solve every bundled wall with every installed method, draw and score them."""
    from .gallery import run_gallery  # imported here: the CLI starts without matplotlib

    out = Path(output)
    table = Path(agreement) if agreement else out.parent / "agreement.md"
    for path in run_gallery(out, table, list(cases) or None, echo=click.echo):
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


COMMANDS = (gallery_command, export_command)
