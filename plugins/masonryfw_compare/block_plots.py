"""The one-result plot kinds drawn on the blocks: ``model``, ``mechanism``, ``cracks``, ``forces`` and
``plastic`` (the drawing functions behind the ``Plotter`` records of :mod:`.records`).

Cracks are the core's: a joint is drawn cracked where :func:`masonryfw.cracked_joints` says so at the
plot's ``threshold``, and the mechanism's macro-blocks are derived at that threshold too.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.colors import Normalize
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

import masonryfw as mf
import masonryfw.plugin_api as mfp

from . import axonometric
from .figure_parts import (
    SUPPORT_COLOUR,
    block_vertices,
    draw_blocks,
    draw_outline,
    finish_axes,
    legend_beside,
    line_scale,
    require_variables,
    segment_array,
    single_result,
    supports_of,
)
from .records import MODEL_INTERFACES_UP_TO
from .shapes import deformed_nodes, deformed_points, largest_vertex_motion

# Default amplification: the largest vertex displacement drawn as this share of the model size.
DRAWN_MOTION_SHARE = 0.10
STATE_COLOURS = {"open": "tab:red", "slide": "tab:blue", "open_slide": "tab:purple"}
FAILURE_COLOURS = {"tensile": "tab:blue", "shear": "0.55", "tensile_shear": "navy"}
SMALL_PIECE_COLOUR = "0.82"
WIDEST_COLOUR = "#d00000"
WIDEST_LINE = 6.0  # pt: the widest opening's line when the cracks plot draws widths
FRICTION_MAP = "plasma_r"  # dark: sliding; light: far from it
DOMINANT_SHARE = 0.02  # a macro-block holding this share of the masonry area is numbered ...
MOST_NUMBERED = 10  # ... up to this many
THRUST_REFERENCE_PERCENTILE = 95.0



@dataclass(frozen=True)
class Pieces:
    """The masonry's macro-blocks by size: ``number[block]`` is 1, 2, ... for the blocks of the
    dominant pieces (largest first) and 0 for the small pieces and the supports."""

    number: np.ndarray
    dominant: int
    small: int


def dominant_pieces(ds: xr.Dataset, geo: xr.Dataset) -> Pieces:
    """Number the macro-blocks holding at least :data:`DOMINANT_SHARE` of the masonry area (at most
    :data:`MOST_NUMBERED`), largest first; the others are small pieces."""
    masonry = mfp.masonry_blocks(geo.block_role.values)
    number = np.zeros(geo.sizes["block"], dtype=np.int64)
    if "macro_block" not in ds or not masonry.any():
        return Pieces(number, 0, 0)
    labels, inverse = np.unique(ds.macro_block.values[masonry], return_inverse=True)
    size = geo.block_volume.values if "block_volume" in geo else np.abs(geo.block_area.values)  # 3D: volumes
    area = np.bincount(inverse, weights=size[masonry])
    order = np.argsort(-area, kind="stable")
    big = order[area[order] >= DOMINANT_SHARE * area.sum()][:MOST_NUMBERED]
    rank = np.zeros(labels.size, dtype=np.int64)
    rank[big] = np.arange(1, big.size + 1)
    number[masonry] = rank[inverse]
    return Pieces(number, int(big.size), int(labels.size - big.size))


def piece_colours(geo: xr.Dataset, pieces: Pieces) -> np.ndarray:
    """Dominant pieces in tab10's colours (cycled), small pieces in one neutral grey."""
    palette = colormaps["tab10"].colors
    colours = np.array([SMALL_PIECE_COLOUR] * geo.sizes["block"], dtype=object)
    for block in np.flatnonzero(pieces.number):
        colours[block] = palette[(pieces.number[block] - 1) % len(palette)]
    return colours


def _number_pieces(ax, geo: xr.Dataset, pieces: Pieces, x: np.ndarray, y: np.ndarray) -> None:
    """Write (1), (2), ... on each dominant piece, at its block nearest to the piece's area centroid (so the
    label lies on the piece even when the piece is not convex), in the deformed configuration."""
    owner = mfp.node_block(geo.block_node_count.values)
    count = np.bincount(owner, minlength=geo.sizes["block"])
    bx = np.bincount(owner, weights=x, minlength=geo.sizes["block"]) / np.maximum(count, 1)
    by = np.bincount(owner, weights=y, minlength=geo.sizes["block"]) / np.maximum(count, 1)
    area = np.abs(geo.block_area.values)
    for k in range(1, pieces.dominant + 1):
        blocks = np.flatnonzero(pieces.number == k)
        cx, cy = np.average(bx[blocks], weights=area[blocks]), np.average(by[blocks], weights=area[blocks])
        at = blocks[np.argmin(np.hypot(bx[blocks] - cx, by[blocks] - cy))]
        ax.text(bx[at], by[at], f"({k})", ha="center", va="center", fontsize="medium", fontweight="bold", zorder=5,
                bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none", "alpha": 0.8})


@dataclass(frozen=True)
class WidestCrack:
    """The widest crack at a result's last record: its joint, width [m] and damage category (-1: none given)."""

    interface: int
    width: float
    category: int

    def label(self) -> str:
        names = {value: name.replace("_", " ") for name, value in mfp.flags("step_damage_category").items()}
        category = f":\ndamage category {self.category} {names.get(self.category, '')}" if self.category >= 0 else ""
        return f"widest crack {self.width * 1000:.3g} mm{category}".rstrip()


def widest_crack(ds: xr.Dataset) -> WidestCrack | None:
    """The widest crack at the last record (the state the plots draw), None where the result has no crack widths
    (limit analysis: a mechanism's shape, not its size) or nothing opens."""
    if not {"step_crack_width_max", "step_crack_interface"} <= set(ds.variables) or not ds.step_crack_width_max.size:
        return None
    interface, width = int(ds.step_crack_interface.values[-1]), float(ds.step_crack_width_max.values[-1])
    if interface < 0 or not width > 0:
        return None
    category = int(ds.step_damage_category.values[-1]) if "step_damage_category" in ds else -1
    return WidestCrack(interface, width, category)


def _mark_widest(ax, ds: xr.Dataset, widest: WidestCrack | None, point: tuple[float, float] | None,
                 handles: list) -> None:
    """A ring round the ``widest`` crack at ``point`` and its legend entry; for a result without widths, a legend
    line saying why there is none."""
    if widest is None or point is None:
        if "collapse_multiplier" in ds:
            handles.append(Line2D([], [], color="none", label="no crack widths: limit analysis gives the\n"
                                                              "mechanism's shape, not its size"))
        return
    ax.plot(*point, marker="o", markersize=16, markerfacecolor="none", markeredgecolor=WIDEST_COLOUR,
            markeredgewidth=2.2, zorder=6)
    handles.append(Line2D([], [], marker="o", markersize=10, markerfacecolor="none", markeredgecolor=WIDEST_COLOUR,
                          markeredgewidth=2.0, linestyle="none", label=widest.label()))


def _deformed_crack_faces(geo: xr.Dataset, u, amplification: float, cracked: np.ndarray) -> np.ndarray:
    """The cracked joints as drawn on the deformed blocks: each joint once on either side's face
    (the two faces of a crack part as the blocks move apart), shape (2 * cracked, 2, 2)."""
    blocks = geo.interface_blocks.values[cracked].astype(np.int64)
    px, py = geo.interface_x.values[cracked], geo.interface_y.values[cracked]
    faces = [deformed_points(geo, u, amplification, px, py, blocks[:, [side, side]]) for side in (0, 1)]
    return np.concatenate([segment_array(fx, fy) for fx, fy in faces])


def default_amplification(geo: xr.Dataset, displacement) -> float:
    """Factor that draws the largest vertex displacement as 10 % of the model size (1 if nothing moves)."""
    largest = largest_vertex_motion(geo, displacement)
    size = mfp.model_scale(geo.node_x.values, geo.node_y.values)
    return DRAWN_MOTION_SHARE * size / largest if largest > 0 else 1.0



ROLE_COLOURS = {"unit": "#f3e3c8", "voussoir": "#d9bf94", "lintel": "#8c6d46", "fixed_support": SUPPORT_COLOUR,
                "moving_support": "#e0a020"}
KIND_COLOURS = {"bed": "tab:blue", "head": "tab:green", "other": "tab:purple", "support": "tab:red"}


def draw_model(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """A model as imported: blocks by role (supports hatched, a moving one with an arrow along its
    settlement direction), interfaces coloured by kind, block numbers on request."""
    ds = single_result(datasets, "model")
    if mfp.space(ds) == 3:
        return axonometric.draw_model_3d(ds, ax, ROLE_COLOURS)
    geo = ds if "block_centroid_x" in ds else mfp.derive_geometry(ds)
    names = {value: name for name, value in mfp.ROLE.items()}
    roles = np.array([names[int(r)] for r in geo.block_role.values])
    verts = block_vertices(geo, geo.node_x.values, geo.node_y.values)
    support = supports_of(geo)
    fill = np.array([ROLE_COLOURS[r] for r in roles], dtype=object)
    ax.add_collection(PolyCollection(list(verts[~support]), facecolors=list(fill[~support]), edgecolors="0.35",
                                     linewidths=0.4 * line_scale(geo), zorder=1))
    if support.any():
        ax.add_collection(PolyCollection(list(verts[support]), facecolors=list(fill[support]), edgecolors="0.2",
                                         linewidths=0.4, hatch="////", zorder=1))
    kinds = {value: name for name, value in mfp.flags("interface_kind").items()}
    kind = np.array([kinds[int(k)] for k in geo.interface_kind.values]) if "interface_kind" in geo else np.array([])
    handles = []
    drawn = options["interfaces"] == "yes" or (options["interfaces"] == "auto"
                                               and geo.sizes["block"] <= MODEL_INTERFACES_UP_TO)
    for name, colour in KIND_COLOURS.items() if drawn else ():
        chosen = kind == name
        if chosen.any():
            segments = segment_array(geo.interface_x.values[chosen], geo.interface_y.values[chosen])
            ax.add_collection(LineCollection(segments, colors=colour, linewidths=1.2, zorder=2))
            handles.append(Line2D([], [], color=colour, lw=1.5, label=f"{name} ({int(chosen.sum())})"))
    size = mfp.model_scale(geo.node_x.values, geo.node_y.values)
    moving = np.flatnonzero(roles == "moving_support")
    starts, motions = _ground_arrows(geo, moving)
    fastest = float(np.linalg.norm(motions, axis=1).max(initial=0.0))
    for start, motion in zip(starts, motions):  # as long as the rates: a settlement profile shows its shape
        if np.linalg.norm(motion) > 0:
            tip = start + 0.08 * size * motion / fastest
            ax.annotate("", xy=tip, xytext=start,
                        arrowprops={"arrowstyle": "-|>", "color": "#b00000", "lw": 1.2}, zorder=3)
            ax.update_datalim([tip])
    if options["numbers"]:
        for block in range(geo.sizes["block"]):
            ax.text(geo.block_centroid_x.values[block], geo.block_centroid_y.values[block], str(block),
                    ha="center", va="center", fontsize=options["font_size"], zorder=4)
    if handles:
        legend_beside(ax, handles=handles, title="interfaces", fontsize="small")
    finish_axes(ax, ds)


def _ground_arrows(geo: xr.Dataset, moving: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per moving support: the middle of its top edge and that point's motion per unit settlement (a
    support that turns moves its centroid sideways, its top edge less)."""
    xmin, xmax, _, ymax = mfp.block_bounds(geo.node_x.values, geo.node_y.values, geo.block_node_count.values)
    points = np.c_[0.5 * (xmin + xmax), ymax][moving]
    d = geo.settlement_direction.values[moving]
    arm = points - np.c_[geo.block_centroid_x.values[moving], geo.block_centroid_y.values[moving]]
    return points, np.c_[d[:, 0] - d[:, 2] * arm[:, 1], d[:, 1] + d[:, 2] * arm[:, 0]]


def mechanism_amplification(ds: xr.Dataset, options: Mapping[str, Any]) -> float:
    """The factor the mechanism plot draws ``ds``'s displacements by: the option ``amplification``, or
    :func:`default_amplification`."""
    return options["amplification"] or default_amplification(mfp.derive_geometry(ds), mfp.block_motion(ds))


def draw_mechanism(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """The wall in its amplified deformed configuration: the dominant macro-blocks coloured and numbered
    (1), (2), ... by size, the small pieces in one grey, the cracks drawn on the blocks' faces; macro-blocks
    and cracks at the option ``threshold``."""
    ds = single_result(datasets, "mechanism")
    require_variables(ds, ["block_displacement"], "mechanism", "block displacements (la, fdem, jmm or jmm-limit)")
    ds = mf.at_threshold(ds, options["threshold"])
    geo = mfp.derive_geometry(ds)
    if mfp.space(ds) == 3:
        pieces = dominant_pieces(ds, geo)
        return axonometric.draw_mechanism_3d(ds, ax, options, pieces, piece_colours(geo, pieces))
    u = mfp.block_motion(ds)
    amplification = mechanism_amplification(ds, options)
    scale = line_scale(geo)
    draw_outline(ax, geo)
    x, y = deformed_nodes(geo, u, amplification)
    pieces = dominant_pieces(ds, geo)
    draw_blocks(ax, geo, x, y, piece_colours(geo, pieces))
    handles = [Patch(facecolor=colormaps["tab10"].colors[0], edgecolor="0.3",
                     label=f"(1) .. ({pieces.dominant}) macro-blocks, largest first" if pieces.dominant > 1
                     else "(1) the macro-block")] if pieces.dominant else []
    if pieces.small:
        handles.append(Patch(facecolor=SMALL_PIECE_COLOUR, edgecolor="0.3", label=f"small pieces ({pieces.small})"))
    if "crack_indicator" in ds:
        cracked = mf.cracked_joints(ds, options["threshold"])
        ax.add_collection(LineCollection(_deformed_crack_faces(geo, u, amplification, cracked), colors="k",
                                         linewidths=1.6 * scale + 0.4, zorder=3, capstyle="round"))
        handles.append(Line2D([], [], color="k", lw=2.0, label=f"cracked joints ({int(cracked.sum())})"))
    _number_pieces(ax, geo, pieces, x, y)
    widest = widest_crack(ds)
    point = None
    if widest is not None:
        k = widest.interface
        px, py = deformed_points(geo, u, amplification, np.array([geo.interface_x.values[k].mean()]),
                                 np.array([geo.interface_y.values[k].mean()]),
                                 np.array([int(geo.interface_blocks.values[k, 0])]))
        point = (float(px[0]), float(py[0]))
    _mark_widest(ax, ds, widest, point, handles)
    legend_beside(ax, handles=handles, fontsize="small", frameon=False, title=f"displacements x {amplification:.3g}",
                  title_fontsize="small")
    finish_axes(ax, ds)


def draw_cracks(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """Joints coloured by how they fail (opening, sliding, or both) over the undeformed wall.

    A joint is drawn where it is cracked at the option ``threshold``, in the state the core
    derives there (:func:`masonryfw.at_threshold`), as the comparison counts cracks.
    """
    ds = single_result(datasets, "cracks")
    require_variables(ds, ["interface_opening", "interface_slip"], "cracks",
             "the relative motion at the joints (a result with block displacements: la, fdem)")
    if mfp.space(ds) == 3:
        return axonometric.draw_cracks_3d(ds, ax, options["threshold"], STATE_COLOURS)
    geo = mfp.derive_geometry(ds)
    state = mf.at_threshold(ds, options["threshold"]).interface_state.values
    draw_blocks(ax, geo, geo.node_x.values, geo.node_y.values, np.array(["0.93"] * geo.sizes["block"], dtype=object))
    segments = segment_array(geo.interface_x.values, geo.interface_y.values)
    flag = mfp.flags("interface_state")
    handles = []
    opening = np.maximum(ds.interface_opening.values, 0.0).max(axis=1)  # at its wider end, as a crack is measured
    in_masonry = ~mfp.support_blocks(geo.block_role.values)[geo.interface_blocks.values.astype(np.int64)].any(axis=1)
    widest_opening = float(opening[(state > 0) & in_masonry].max(initial=0.0))  # a base gap is no crack
    drawn_widths = options["widths"] and widest_opening > 0
    widths = (0.8 + (WIDEST_LINE - 0.8) * np.minimum(opening / widest_opening, 1.0) if drawn_widths
              else np.full(opening.size, 2.2))
    for meaning, colour in STATE_COLOURS.items():
        chosen = state == flag[meaning]
        ax.add_collection(LineCollection(segments[chosen], colors=colour, linewidths=widths[chosen], zorder=3))
        handles.append(Line2D([], [], color=colour, lw=2.2, label=f"{meaning.replace('_', ' + ')} ({chosen.sum()})"))
    if drawn_widths:
        handles.append(Line2D([], [], color="0.3", lw=WIDEST_LINE,
                              label=f"line width: the joint's opening at the last record,\nup to "
                                    f"{widest_opening * 1000:.3g} mm in the masonry" + _over_the_run(ds, widest_opening)))
    widest = widest_crack(ds)
    point = None if widest is None else (float(geo.interface_x.values[widest.interface].mean()),
                                         float(geo.interface_y.values[widest.interface].mean()))
    _mark_widest(ax, ds, widest, point, handles)
    legend_beside(ax, handles=handles, fontsize="small", frameon=False)
    finish_axes(ax, ds)


def _over_the_run(ds: xr.Dataset, at_the_end: float) -> str:
    """``(the widest of the run, 1.24 mm, was earlier)`` when the run's widest crack is wider than the last
    record's: the legend and the marker then say why they differ."""
    if "step_crack_width_max" not in ds or not ds.step_crack_width_max.size:
        return ""
    widest = float(np.max(ds.step_crack_width_max.values))
    return f"\n(the run's widest, {widest * 1000:.3g} mm, was earlier)" if widest > at_the_end * (1 + 1e-6) else ""


def loaded_joints(normal: np.ndarray) -> np.ndarray:
    """Interfaces whose resultant normal force is more than round-off (1e-9 of the largest)."""
    total = normal[:, 0] + normal[:, 1]
    return total > 1e-9 * max(np.max(np.abs(total), initial=0.0), np.finfo(float).tiny)


def thrust_segments(geo: xr.Dataset, normal, shear, scale: float):
    """Per loaded interface: point of application, resultant force on side 1, and its drawn segment.

    The resultant normal force N = N0 + N1 acts at ``(N0 p0 + N1 p1) / N`` (the
    centre of pressure of the linear distribution between the ends); the force on
    side 1 is ``N n + V t``. Segments are centred on the point of application,
    along the force, ``scale`` median interface lengths long at the 95th percentile
    of the magnitudes and proportionally shorter below it; the few stronger forces
    (typically a support corner) are drawn at that length, so that they do not
    shrink every other segment to a dot.
    """
    n0, n1 = normal[:, 0], normal[:, 1]
    total = n0 + n1
    loaded = loaded_joints(normal)
    w = n1[loaded] / total[loaded]
    ix, iy = geo.interface_x.values[loaded], geo.interface_y.values[loaded]
    px, py = ix[:, 0] + w * (ix[:, 1] - ix[:, 0]), iy[:, 0] + w * (iy[:, 1] - iy[:, 0])
    v = shear[loaded].sum(axis=1)
    fx = total[loaded] * geo.interface_normal_x.values[loaded] + v * geo.interface_tangent_x.values[loaded]
    fy = total[loaded] * geo.interface_normal_y.values[loaded] + v * geo.interface_tangent_y.values[loaded]
    magnitude = np.hypot(fx, fy)
    if not magnitude.size:
        return px, py, magnitude, np.zeros((0, 2, 2))
    reference = float(np.percentile(magnitude, THRUST_REFERENCE_PERCENTILE))
    drawn = scale * float(np.median(geo.interface_length.values)) * np.minimum(magnitude / reference, 1.0)
    hx, hy = 0.5 * drawn * fx / magnitude, 0.5 * drawn * fy / magnitude
    segments = np.stack([np.stack([px - hx, px + hx], -1), np.stack([py - hy, py + hy], -1)], axis=-1)
    return px, py, magnitude, segments


def friction_used(geo: xr.Dataset, normal, shear) -> np.ndarray:
    """Per loaded interface (:func:`loaded_joints`): |V| / (mu N), 1 where it slides."""
    total = normal[:, 0] + normal[:, 1]
    loaded = loaded_joints(normal)
    mu = geo.interface_friction.values[loaded]
    v = np.abs(shear[loaded].sum(axis=1))
    return np.where(mu > 0, v / np.maximum(mu * total[loaded], np.finfo(float).tiny), np.inf)


def draw_forces(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """Contact forces at collapse: a segment through each joint's centre of pressure along the joint's
    resultant, its length and width growing with the force, its colour the share of the friction used."""
    ds = single_result(datasets, "forces")
    require_variables(
        ds, ["interface_normal_force", "interface_shear_force"], "forces",
        "contact forces (a limit analysis la result)",
    )
    geo = mfp.derive_geometry(ds)
    draw_blocks(ax, geo, geo.node_x.values, geo.node_y.values, np.array(["0.93"] * geo.sizes["block"], dtype=object))
    normal, shear = ds.interface_normal_force.values, ds.interface_shear_force.values
    px, py, magnitude, segments = thrust_segments(geo, normal, shear, options["scale"])
    handles = []
    if magnitude.size:
        reference = float(np.percentile(magnitude, THRUST_REFERENCE_PERCENTILE))
        width = (0.5 + 2.5 * np.minimum(magnitude / reference, 1.0)) * line_scale(geo)
        used = np.minimum(friction_used(geo, normal, shear), 1.0)
        lines = LineCollection(segments, cmap=FRICTION_MAP, norm=Normalize(0.0, 1.0), linewidths=width, zorder=3)
        lines.set_array(used)
        ax.add_collection(lines)
        ax.scatter(px, py, s=1.5 * line_scale(geo) ** 2, c="0.35", zorder=4, linewidths=0)
        bar = ax.figure.colorbar(lines, cax=ax.inset_axes((1.03, 0.1, 0.03, 0.8)))  # follows the equal-aspect box
        bar.set_label("friction used |V| / (mu N); 1 = sliding", fontsize="small")
        handles = [
            Line2D([], [], color="0.3", lw=3.0, label=f"joint resultant, full length = {reference:.3g} N (95th pct.)"),
            Line2D([], [], ls="none", marker=".", color="0.35", label="centre of pressure"),
            Line2D([], [], ls="none", label=f"largest {magnitude.max():.3g} N, {magnitude.size} loaded joints"),
        ]
    legend_beside(ax, below=True, handles=handles, fontsize="small", frameon=False)
    finish_axes(ax, ds)


def _mesh_faces(ds: xr.Dataset) -> np.ndarray:
    """(face, max_nodes, 2) vertices; padding (negative or fill) indices repeat the last valid node."""
    faces = np.asarray(ds.mesh_face_nodes.to_masked_array().filled(-1), dtype=np.int64)
    count = np.maximum((faces >= 0).sum(axis=1), 1)
    idx = np.take_along_axis(faces, np.minimum(np.arange(faces.shape[1])[None, :], count[:, None] - 1), axis=1)
    return np.stack([ds.mesh_node_x.values[idx], ds.mesh_node_y.values[idx]], axis=-1)


def draw_plastic(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """Plastic quadrature points over the mesh: blue tensile, grey shear, navy both."""
    ds = single_result(datasets, "plastic")
    require_variables(ds, ["qp_failure", "qp_x", "qp_y"], "plastic", "a continuum (jmm) result")
    draw_outline(ax, mfp.derive_geometry(ds))
    if "mesh_face_nodes" in ds:
        ax.add_collection(PolyCollection(list(_mesh_faces(ds)), facecolors="none", edgecolors="0.9", linewidths=0.3))
    failure = ds.qp_failure.values
    flag = mfp.flags("qp_failure")
    for meaning, colour in FAILURE_COLOURS.items():
        chosen = failure == flag[meaning]
        ax.scatter(ds.qp_x.values[chosen], ds.qp_y.values[chosen], s=options["marker_size"], c=colour,
                   label=f"{meaning.replace('_', ' + ')} ({chosen.sum()})", zorder=3, linewidths=0)
    legend_beside(ax, fontsize="small", frameon=False, markerscale=2)
    finish_axes(ax, ds)


#: The one-result kinds and the variable each needs (the first the drawing reads).
SINGLE_RESULT_KINDS = {"mechanism": "block_displacement", "cracks": "interface_opening",
                       "forces": "interface_normal_force", "plastic": "qp_failure"}


def drawable_kinds(ds: xr.Dataset) -> list[str]:
    """The one-result kinds ``ds`` can be drawn as, in the order of :data:`SINGLE_RESULT_KINDS`; then ``ltsm``
    for a result over a settlement profile with a settlement to assess (and walls: a wall, or a building's)."""
    kinds = [kind for kind, needs in SINGLE_RESULT_KINDS.items() if needs in ds]
    if mfp.space(ds) == 3:  # the kinds that draw in 3D (their records' spaces)
        kinds = [kind for kind in kinds if mf.get_plotter(kind).spaces != (2,)]
    assessed = ("step_settlement" in ds and ds.step_settlement.size) or "settlement_target" in ds
    walls = mfp.space(ds) == 2 or "building_walls" in ds.attrs  # a drawing's blocks name no walls to assess
    return kinds + (["ltsm"] if ds.attrs.get("settlement_profile") and assessed and walls else [])
