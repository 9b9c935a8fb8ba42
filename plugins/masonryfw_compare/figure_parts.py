"""What every plot kind shares: its checks, block drawing, segments and title.

Every kind draws on one matplotlib Axes with equal axes, metres on both axes and a title made of the
model's ``title``, the solver and the result's headline (alpha and the collapse reaction, or the dead,
smallest and plateau reactions). A kind that needs a variable the result lacks raises a
:class:`masonryfw.MasonryError` naming the variable and the kind of result it needs.
"""
from __future__ import annotations

import textwrap
from collections.abc import Sequence

import numpy as np
import xarray as xr
from matplotlib.collections import PolyCollection

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .shapes import padded_block_nodes

SUPPORT_COLOUR = "0.45"
TITLE_WIDTH = 75  # characters of a title line on a 7 in wide figure at the medium size (more or fewer as it is)
#: A page this much taller than wide is portrait: legends go below the drawing, not beside it (on a narrow
#: portrait page the legend column left a band of white as wide as the drawing).
PORTRAIT = 1.1
# damage categories 0..5: green to dark red
DAMAGE_COLOURS = ("#1a9850", "#91cf60", "#fee08b", "#fc8d59", "#d73027", "#7f0000")


def require_variables(ds: xr.Dataset, names: Sequence[str], kind: str, needs: str) -> None:
    """Raise a MasonryError naming the first missing variable and what the plot kind needs."""
    for name in names:
        if name not in ds:
            raise mf.MasonryError(f"result has no {name}: the {kind} plot needs {needs}")


def single_result(datasets: Sequence[xr.Dataset], kind: str) -> xr.Dataset:
    if len(datasets) != 1:
        raise mf.MasonryError(f"the {kind} plot draws one result, got {len(datasets)}")
    return datasets[0]


def title_of(ds: xr.Dataset) -> str:
    """``<model title> - <solver>`` (``model`` when the dataset holds no result)."""
    label = mf.result_label(ds) if "solver" in ds.attrs else "model"
    return f"{ds.attrs.get('title', 'untitled')} - {label}"


def portrait(ax) -> bool:
    """Whether the figure ``ax`` is on is a portrait page (:data:`PORTRAIT`)."""
    width, height = ax.figure.get_size_inches()
    return height > PORTRAIT * width


def legend_beside(ax, gap: float = 0.01, below: bool = False, **kwargs):
    """The legend beside the drawing: to its right on a landscape page (``gap`` of the axes' width clear of them),
    under it (two columns) on a portrait one, or ``below`` always (a building in axonometry wants the width)."""
    if below or portrait(ax):  # the figure's own legend: the constrained layout keeps it clear of the axis labels
        handles = kwargs.pop("handles", None) or ax.get_legend_handles_labels()[0]
        return ax.figure.legend(handles=handles, loc="outside lower center", ncol=1 if portrait(ax) else 2, **kwargs)
    return ax.legend(loc="upper left", bbox_to_anchor=(1.0 + gap, 1.0), **kwargs)


def title_text(ax, ds: xr.Dataset) -> str:
    """The model, the solver and the headline, wrapped to the width of the figure (a title wider than a small
    page was cut at its left edge)."""
    width = max(30, int(TITLE_WIDTH * ax.figure.get_size_inches()[0] / 7.0))
    lines = [title_of(ds), mf.headline_text(ds)]
    return "\n".join(textwrap.fill(line, width) for line in lines if line)


def finish_axes(ax, ds: xr.Dataset) -> None:
    """Equal axes in metres fitted to the drawing, titled with the model, the solver and the headline."""
    ax.set_aspect("equal", adjustable="box")
    ax.autoscale_view()
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title_text(ax, ds), fontsize="medium")


def line_scale(geo: xr.Dataset) -> float:
    """1 up to 300 blocks, then shrinking as 1/sqrt(blocks): lines stay apart on a 3,000-block wall."""
    return float(min(1.0, np.sqrt(300.0 / max(geo.sizes["block"], 1))))


def block_vertices(geo: xr.Dataset, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    idx = padded_block_nodes(geo.block_node_count.values)
    return np.stack([x[idx], y[idx]], axis=-1)


def supports_of(geo: xr.Dataset) -> np.ndarray:
    return mfp.support_blocks(geo.block_role.values)


def draw_blocks(ax, geo, x, y, facecolors, *, edge="0.3", width=None, zorder=1) -> None:
    """Masonry blocks filled with ``facecolors`` (per block), supports hatched grey."""
    width = 0.3 * line_scale(geo) ** 2 if width is None else width  # edges fade out faster than the cracks
    verts = block_vertices(geo, x, y)
    support = supports_of(geo)
    colours = np.asarray(facecolors, dtype=object)
    ax.add_collection(PolyCollection(
        list(verts[~support]), facecolors=list(colours[~support]), edgecolors=edge, linewidths=width, zorder=zorder,
    ))
    if support.any():
        ax.add_collection(PolyCollection(
            list(verts[support]), facecolors=SUPPORT_COLOUR, edgecolors="0.2", linewidths=width,
            hatch="////", zorder=zorder,
        ))


def draw_outline(ax, geo) -> None:
    """The undeformed blocks as faint outlines (the reference configuration)."""
    verts = block_vertices(geo, geo.node_x.values, geo.node_y.values)
    ax.add_collection(PolyCollection(list(verts), facecolors="none", edgecolors="0.8", linewidths=0.4, zorder=0))


def segment_array(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(n, 2 ends) coordinates to a LineCollection's (n, 2, 2) array."""
    return np.stack([x, y], axis=-1)

