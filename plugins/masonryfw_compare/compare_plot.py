"""The ``compare`` plot kind: results of one model side by side, each later panel titled with its
scores against the first (the ``crack`` comparator at the plot's ``threshold``)."""
from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.collections import LineCollection

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .axonometric import draw_cracks_3d
from .block_plots import STATE_COLOURS, draw_mechanism, draw_plastic, mechanism_amplification
from .figure_parts import TITLE_WIDTH, draw_blocks, finish_axes, segment_array


def panel_kind(ds: xr.Dataset) -> str:
    """How a result is best drawn in a comparison: its mechanism, its plastic points, or its cracks."""
    if "block_displacement" in ds:
        return "mechanism"
    if "qp_failure" in ds:
        return "plastic"
    if "crack_indicator" in ds:
        return "indicator"
    raise mf.MasonryError(
        "result has no block_displacement, qp_failure or crack_indicator: the compare plot has nothing to draw"
    )


def draw_indicator(ds: xr.Dataset, ax, threshold: float) -> None:
    """The joints cracked at ``threshold`` (:func:`masonryfw.cracked_joints`) drawn heavy over the undeformed
    wall."""
    geo = mfp.derive_geometry(ds)
    draw_blocks(ax, geo, geo.node_x.values, geo.node_y.values, np.array(["0.93"] * geo.sizes["block"], dtype=object))
    cracked = mf.cracked_joints(ds, threshold)
    ax.add_collection(LineCollection(
        segment_array(geo.interface_x.values[cracked], geo.interface_y.values[cracked]), colors="k", linewidths=2.2,
    ))
    finish_axes(ax, ds)


def draw_in_3d(ds: xr.Dataset, panel, kind: str, options: Mapping[str, Any]) -> None:
    """A 3D result's panel in axonometry: its mechanism (the plot's amplification, or the 3D default), or its cracked
    joints by state (a continuum's plastic points have no 3D drawing)."""
    if kind == "mechanism":
        draw_mechanism([ds], panel, options)
    elif kind == "indicator":
        draw_cracks_3d(ds, panel, options["threshold"], STATE_COLOURS)
    else:
        raise mf.MasonryError("the compare plot draws a 3D result's mechanism or cracks: this one has neither "
                              "block_displacement nor crack_indicator")


def score_caption(comparison: xr.Dataset) -> str:
    """Short caption of the main scores of a comparison (only those computed)."""
    parts = [
        (label, comparison[name].item()) for label, name in (
            ("F1", "crack_f1"), ("ARI", "macro_block_ari"), ("cos", "mechanism_cosine"), ("d", "locus_distance"),
        ) if name in comparison
    ]
    return ", ".join(f"{label} {value:.2f}" for label, value in parts) or "no common score"


def panel_axes(ax, count: int, projection: str | None = None) -> list:
    """``count`` side-by-side Axes in the place of ``ax`` (which stays as an invisible frame), 3D ones for
    ``projection="3d"``."""
    figure = ax.figure
    spec = ax.get_subplotspec()
    ax.set_axis_off()
    if spec is not None:
        grid = spec.subgridspec(1, count)
        return [figure.add_subplot(grid[0, i], projection=projection) for i in range(count)]
    left, bottom, width, height = ax.get_position().bounds
    return [figure.add_axes((left + i * width / count, bottom, width / count, height), projection=projection)
            for i in range(count)]


def draw_compare(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """Results side by side, the first titled with the wall; each later panel's title carries its scores
    against the first. The panels keep their drawings and drop their legends (the single-result kinds
    explain them); a mechanism's amplification goes under its panel (3D: in axonometry, the amplification and
    the motion's reference, its legend's title, under the panel's title)."""
    if len(datasets) < 2:
        raise mf.MasonryError(f"the compare plot needs two or more results of one model, got {len(datasets)}")
    kinds = [panel_kind(ds) for ds in datasets]
    captions = ["reference"] + [
        score_caption(mf.compare(datasets[0], ds, "crack", {"threshold": options["threshold"]})) for ds in datasets[1:]
    ]
    wall = str(datasets[0].attrs.get("title", ""))
    in_3d = mfp.space(datasets[0]) == 3
    panels = panel_axes(ax, len(datasets), "3d" if in_3d else None)
    for k, (panel, ds, kind, caption) in enumerate(zip(panels, datasets, kinds, captions)):
        if in_3d:
            draw_in_3d(ds, panel, kind, options)
        elif kind == "mechanism":
            amplification = mechanism_amplification(ds, options)
            draw_mechanism([ds], panel, {**options, "amplification": amplification})
            panel.set_xlabel(f"x [m]; displacements x {amplification:.3g}")
        elif kind == "plastic":
            draw_plastic([ds], panel, {"marker_size": 4.0})
        else:
            draw_indicator(ds, panel, options["threshold"])
        legend, legend_title = panel.get_legend(), ""
        if legend is not None:
            legend_title = legend.get_title().get_text().replace("\n", " ") if in_3d else ""
            legend.remove()
        alpha = f", alpha = {ds.collapse_multiplier.item():.4g}" if "collapse_multiplier" in ds else ""
        heading = f"{wall}\n" if k == 0 and wall else ""
        width = max(20, int(TITLE_WIDTH * ax.figure.get_size_inches()[0] / 7.0 / len(datasets)))  # a panel's share
        lines = [f"{mf.result_label(ds)}{alpha}", caption] + ([legend_title] if legend_title else [])
        panel.set_title(heading + "\n".join(textwrap.fill(line, width) for line in lines), fontsize="medium")

