"""Plot kinds: the drawing functions behind the ``Plotter`` records of :mod:`.records`.

Every kind draws on one matplotlib Axes with equal axes, metres on both axes and
a title made of the model's ``title``, the solver and the result's headline (alpha and
the collapse reaction, or the dead, smallest and plateau reactions); ``history`` plots
reaction against settlement instead, of several results at once. A kind that needs a variable the result lacks raises
a :class:`masonryfw.MasonryError` naming the variable and the kind of result it needs.
"""
from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.colors import Normalize
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

import masonryfw as mf

from .shapes import deformed_nodes, deformed_points, largest_vertex_motion, padded_block_nodes

# Default amplification: the largest vertex displacement drawn as this share of the model size.
DRAWN_MOTION_SHARE = 0.10
STATE_COLOURS = {"open": "tab:red", "slide": "tab:blue", "open_slide": "tab:purple"}
FAILURE_COLOURS = {"tensile": "tab:blue", "shear": "0.55", "tensile_shear": "navy"}
SUPPORT_COLOUR = "0.45"
SMALL_PIECE_COLOUR = "0.82"
FRICTION_MAP = "plasma_r"  # dark: sliding; light: far from it
# damage categories 0..5: green to dark red
STRIP_SHARE = 0.035  # of the axes' height: one damage strip
DAMAGE_COLOURS = ("#1a9850", "#91cf60", "#fee08b", "#fc8d59", "#d73027", "#7f0000")
DOMINANT_SHARE = 0.02  # a macro-block holding this share of the masonry area is numbered ...
MOST_NUMBERED = 10  # ... up to this many
THRUST_REFERENCE_PERCENTILE = 95.0


def _require(ds: xr.Dataset, names: Sequence[str], kind: str, needs: str) -> None:
    """Raise a MasonryError naming the first missing variable and what the plot kind needs."""
    for name in names:
        if name not in ds:
            raise mf.MasonryError(f"result has no {name}: the {kind} plot needs {needs}")


def _single(datasets: Sequence[xr.Dataset], kind: str) -> xr.Dataset:
    if len(datasets) != 1:
        raise mf.MasonryError(f"the {kind} plot draws one result, got {len(datasets)}")
    return datasets[0]


def title_of(ds: xr.Dataset) -> str:
    """``<model title> - <solver>`` (``model`` when the dataset holds no result)."""
    label = mf.result_label(ds) if "solver" in ds.attrs else "model"
    return f"{ds.attrs.get('title', 'untitled')} - {label}"


def _finish(ax, ds: xr.Dataset) -> None:
    """Equal axes in metres fitted to the drawing, titled with the model, the solver and the headline."""
    ax.set_aspect("equal", adjustable="box")
    ax.autoscale_view()
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    headline = mf.headline_text(ds)
    ax.set_title(title_of(ds) + (f"\n{headline}" if headline else ""), fontsize="medium")


def line_scale(geo: xr.Dataset) -> float:
    """1 up to 300 blocks, then shrinking as 1/sqrt(blocks): lines stay apart on a 3,000-block wall."""
    return float(min(1.0, np.sqrt(300.0 / max(geo.sizes["block"], 1))))


def _block_verts(geo: xr.Dataset, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    idx = padded_block_nodes(geo.block_node_count.values)
    return np.stack([x[idx], y[idx]], axis=-1)


def _supports(geo: xr.Dataset) -> np.ndarray:
    return mf.support_blocks(geo.block_role.values)


def _draw_blocks(ax, geo, x, y, facecolors, *, edge="0.3", width=None, zorder=1) -> None:
    """Masonry blocks filled with ``facecolors`` (per block), supports hatched grey."""
    width = 0.3 * line_scale(geo) ** 2 if width is None else width  # edges fade out faster than the cracks
    verts = _block_verts(geo, x, y)
    support = _supports(geo)
    colours = np.asarray(facecolors, dtype=object)
    ax.add_collection(PolyCollection(
        list(verts[~support]), facecolors=list(colours[~support]), edgecolors=edge, linewidths=width, zorder=zorder,
    ))
    if support.any():
        ax.add_collection(PolyCollection(
            list(verts[support]), facecolors=SUPPORT_COLOUR, edgecolors="0.2", linewidths=width,
            hatch="////", zorder=zorder,
        ))


def _draw_outline(ax, geo) -> None:
    """The undeformed blocks as faint outlines (the reference configuration)."""
    verts = _block_verts(geo, geo.node_x.values, geo.node_y.values)
    ax.add_collection(PolyCollection(list(verts), facecolors="none", edgecolors="0.8", linewidths=0.4, zorder=0))


def _segments(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(n, 2 ends) coordinates to a LineCollection's (n, 2, 2) array."""
    return np.stack([x, y], axis=-1)


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
    masonry = mf.masonry_blocks(geo.block_role.values)
    number = np.zeros(geo.sizes["block"], dtype=np.int64)
    if "macro_block" not in ds or not masonry.any():
        return Pieces(number, 0, 0)
    labels, inverse = np.unique(ds.macro_block.values[masonry], return_inverse=True)
    area = np.bincount(inverse, weights=np.abs(geo.block_area.values[masonry]))
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
    owner = mf.node_block(geo.block_node_count.values)
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


def _deformed_crack_faces(geo: xr.Dataset, u, amplification: float, cracked: np.ndarray) -> np.ndarray:
    """The cracked joints as drawn on the deformed blocks: each joint once on either side's face
    (the two faces of a crack part as the blocks move apart), shape (2 * cracked, 2, 2)."""
    blocks = geo.interface_blocks.values[cracked].astype(np.int64)
    px, py = geo.interface_x.values[cracked], geo.interface_y.values[cracked]
    faces = [deformed_points(geo, u, amplification, px, py, blocks[:, [side, side]]) for side in (0, 1)]
    return np.concatenate([_segments(fx, fy) for fx, fy in faces])


def default_amplification(geo: xr.Dataset, displacement) -> float:
    """Factor that draws the largest vertex displacement as 10 % of the model size (1 if nothing moves)."""
    largest = largest_vertex_motion(geo, displacement)
    size = mf.model_scale(geo.node_x.values, geo.node_y.values)
    return DRAWN_MOTION_SHARE * size / largest if largest > 0 else 1.0


ROLE_COLOURS = {"unit": "#f3e3c8", "lintel": "#8c6d46", "fixed_support": SUPPORT_COLOUR, "moving_support": "#e0a020"}
KIND_COLOURS = {"bed": "tab:blue", "head": "tab:green", "other": "tab:purple", "support": "tab:red"}


def draw_model(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """A model as imported: blocks by role (supports hatched, a moving one with an arrow along its
    settlement direction), interfaces coloured by kind, block numbers on request."""
    ds = _single(datasets, "model")
    geo = ds if "block_centroid_x" in ds else mf.derive_geometry(ds)
    names = {value: name for name, value in mf.flags("block_role").items()}
    roles = np.array([names[int(r)] for r in geo.block_role.values])
    verts = _block_verts(geo, geo.node_x.values, geo.node_y.values)
    support = _supports(geo)
    fill = np.array([ROLE_COLOURS[r] for r in roles], dtype=object)
    ax.add_collection(PolyCollection(list(verts[~support]), facecolors=list(fill[~support]), edgecolors="0.35",
                                     linewidths=0.4, zorder=1))
    if support.any():
        ax.add_collection(PolyCollection(list(verts[support]), facecolors=list(fill[support]), edgecolors="0.2",
                                         linewidths=0.4, hatch="////", zorder=1))
    kinds = {value: name for name, value in mf.flags("interface_kind").items()}
    kind = np.array([kinds[int(k)] for k in geo.interface_kind.values]) if "interface_kind" in geo else np.array([])
    handles = []
    for name, colour in KIND_COLOURS.items():
        chosen = kind == name
        if chosen.any():
            segments = _segments(geo.interface_x.values[chosen], geo.interface_y.values[chosen])
            ax.add_collection(LineCollection(segments, colors=colour, linewidths=1.2, zorder=2))
            handles.append(Line2D([], [], color=colour, lw=1.5, label=f"{name} ({int(chosen.sum())})"))
    size = mf.model_scale(geo.node_x.values, geo.node_y.values)
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
        ax.legend(handles=handles, title="interfaces", fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    _finish(ax, ds)


def _ground_arrows(geo: xr.Dataset, moving: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per moving support: the middle of its top edge and that point's motion per unit settlement (a
    support that turns moves its centroid sideways, its top edge less)."""
    xmin, xmax, _, ymax = mf.block_bounds(geo.node_x.values, geo.node_y.values, geo.block_node_count.values)
    points = np.c_[0.5 * (xmin + xmax), ymax][moving]
    d = geo.settlement_direction.values[moving]
    arm = points - np.c_[geo.block_centroid_x.values[moving], geo.block_centroid_y.values[moving]]
    return points, np.c_[d[:, 0] - d[:, 2] * arm[:, 1], d[:, 1] + d[:, 2] * arm[:, 0]]


def draw_mechanism(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """The wall in its amplified deformed configuration: the dominant macro-blocks coloured and numbered
    (1), (2), ... by size, the small pieces in one grey, the cracks drawn on the blocks' faces."""
    ds = _single(datasets, "mechanism")
    _require(ds, ["block_displacement"], "mechanism", "block displacements (la, fdem, jmm or jmm-limit)")
    geo = mf.derive_geometry(ds)
    u = mf.block_motion(ds)
    amplification = options["amplification"] or default_amplification(geo, u)
    scale = line_scale(geo)
    _draw_outline(ax, geo)
    x, y = deformed_nodes(geo, u, amplification)
    pieces = dominant_pieces(ds, geo)
    _draw_blocks(ax, geo, x, y, piece_colours(geo, pieces))
    handles = [Patch(facecolor=colormaps["tab10"].colors[0], edgecolor="0.3",
                     label=f"(1) .. ({pieces.dominant}) macro-blocks, largest first" if pieces.dominant > 1
                     else "(1) the macro-block")] if pieces.dominant else []
    if pieces.small:
        handles.append(Patch(facecolor=SMALL_PIECE_COLOUR, edgecolor="0.3", label=f"small pieces ({pieces.small})"))
    if "crack_indicator" in ds:
        cracked = ds.crack_indicator.values > options["threshold"]
        ax.add_collection(LineCollection(_deformed_crack_faces(geo, u, amplification, cracked), colors="k",
                                         linewidths=1.6 * scale + 0.4, zorder=3, capstyle="round"))
        handles.append(Line2D([], [], color="k", lw=2.0, label=f"cracked joints ({int(cracked.sum())})"))
    _number_pieces(ax, geo, pieces, x, y)
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False,
              title=f"displacements x {amplification:.3g}", title_fontsize="small")
    _finish(ax, ds)


def draw_cracks(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """Joints coloured by how they fail (opening, sliding, or both) over the undeformed wall.

    A joint is drawn where its ``crack_indicator`` exceeds ``threshold`` (as the
    comparison counts cracks); its state is the core's definition with that
    threshold (:func:`masonryfw.states_at`).
    """
    ds = _single(datasets, "cracks")
    _require(ds, ["interface_opening", "interface_slip"], "cracks",
             "the relative motion at the joints (a result with block displacements: la, fdem)")
    geo = mf.derive_geometry(ds)
    state = mf.states_at(ds, options["threshold"])
    _draw_blocks(ax, geo, geo.node_x.values, geo.node_y.values, np.array(["0.93"] * geo.sizes["block"], dtype=object))
    segments = _segments(geo.interface_x.values, geo.interface_y.values)
    flag = mf.flags("interface_state")
    handles = []
    for meaning, colour in STATE_COLOURS.items():
        chosen = state == flag[meaning]
        ax.add_collection(LineCollection(segments[chosen], colors=colour, linewidths=2.2, zorder=3))
        handles.append(Line2D([], [], color=colour, lw=2.2, label=f"{meaning.replace('_', ' + ')} ({chosen.sum()})"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False)
    _finish(ax, ds)


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
    ds = _single(datasets, "forces")
    _require(
        ds, ["interface_normal_force", "interface_shear_force"], "forces",
        "contact forces (a limit analysis la result)",
    )
    geo = mf.derive_geometry(ds)
    _draw_blocks(ax, geo, geo.node_x.values, geo.node_y.values, np.array(["0.93"] * geo.sizes["block"], dtype=object))
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
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize="small",
              frameon=False)
    _finish(ax, ds)


def _mesh_faces(ds: xr.Dataset) -> np.ndarray:
    """(face, max_nodes, 2) vertices; padding (negative or fill) indices repeat the last valid node."""
    faces = np.asarray(ds.mesh_face_nodes.to_masked_array().filled(-1), dtype=np.int64)
    count = np.maximum((faces >= 0).sum(axis=1), 1)
    idx = np.take_along_axis(faces, np.minimum(np.arange(faces.shape[1])[None, :], count[:, None] - 1), axis=1)
    return np.stack([ds.mesh_node_x.values[idx], ds.mesh_node_y.values[idx]], axis=-1)


def draw_plastic(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """Plastic quadrature points over the mesh: blue tensile, grey shear, navy both."""
    ds = _single(datasets, "plastic")
    _require(ds, ["qp_failure", "qp_x", "qp_y"], "plastic", "a continuum (jmm) result")
    _draw_outline(ax, mf.derive_geometry(ds))
    if "mesh_face_nodes" in ds:
        ax.add_collection(PolyCollection(list(_mesh_faces(ds)), facecolors="none", edgecolors="0.9", linewidths=0.3))
    failure = ds.qp_failure.values
    flag = mf.flags("qp_failure")
    for meaning, colour in FAILURE_COLOURS.items():
        chosen = failure == flag[meaning]
        ax.scatter(ds.qp_x.values[chosen], ds.qp_y.values[chosen], s=options["marker_size"], c=colour,
                   label=f"{meaning.replace('_', ' + ')} ({chosen.sum()})", zorder=3, linewidths=0)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False, markerscale=2)
    _finish(ax, ds)


def distinct_labels(datasets: Sequence[xr.Dataset]) -> list[str]:
    """Each result's label (:func:`masonryfw.result_label`); results that share one get the solver options
    in which they differ, e.g. ``fdem (mode=deformable)``, else their titles, else their file names, else
    their place in the list: no two results share a label."""
    labels = [mf.result_label(ds) for ds in datasets]
    details = [
        lambda ds: mf.result_options(ds),
        lambda ds: {"": ds.attrs.get("title", "")},
        lambda ds: {"": Path(str(ds.encoding.get("source", ""))).name},
    ]
    for detail in details:
        labels = _told_apart(labels, [detail(ds) for ds in datasets])
    counts = Counter(labels)
    seen: Counter = Counter()
    out = []
    for label in labels:
        seen[label] += 1
        out.append(f"{label} #{seen[label]}" if counts[label] > 1 else label)
    return out


def _told_apart(labels: list[str], facts: list[dict]) -> list[str]:
    """Labels that several results share get the facts (key -> value) in which those results differ."""
    out = []
    for i, label in enumerate(labels):
        twins = [j for j, other in enumerate(labels) if other == label]
        keys = sorted({k for j in twins for k in facts[j]})
        differ = [k for k in keys if len({repr(facts[j].get(k)) for j in twins}) > 1]
        detail = ", ".join(f"{k}={facts[i].get(k)}" if k else str(facts[i].get(k)) for k in differ)
        out.append(f"{label} ({detail})" if len(twins) > 1 and detail else label)
    return out


def _is_sweep(ds: xr.Dataset) -> bool:
    return ds.attrs.get("masonryfw_format") == "sweep"


def _split_history(datasets: Sequence[xr.Dataset], kind: str):
    """The incremental results (with a history), the limit analyses (with alpha) and the sweeps of an
    incremental solver (with each point's smallest reaction) among ``datasets``."""
    sweeps = [ds for ds in datasets if _is_sweep(ds)]
    incremental = [ds for ds in datasets if "step_settlement" in ds and "step_reaction" in ds]
    limits = [ds for ds in datasets if "collapse_multiplier" in ds and "step_settlement" not in ds]
    for ds in datasets:
        if _is_sweep(ds) and not {"minimum_reaction", "minimum_reaction_settlement"} <= set(ds.data_vars):
            raise mf.MasonryError(f"{ds.attrs.get('title', 'a sweep')} has no minimum_reaction_settlement: the {kind} "
                                  f"plot draws the points of sweeps of an incremental solver (fdem, jmm), not "
                                  f"{ds.attrs.get('solver', '?')}'s")
        if not _is_sweep(ds) and "step_settlement" not in ds and "collapse_multiplier" not in ds:
            raise mf.MasonryError(f"{title_of(ds)} has neither step_settlement nor collapse_multiplier: "
                                  f"the {kind} plot draws incremental (fdem, jmm) histories, sweeps of them "
                                  "and la references")
    if not incremental and not sweeps:
        raise mf.MasonryError(f"the {kind} plot needs an incremental (fdem or jmm) result with step_settlement "
                              "and step_reaction, or a sweep of one")
    return incremental, limits, sweeps


def sweep_points(sweep: xr.Dataset) -> list[tuple[str, float, float, float, float]]:
    """Per solved point of a sweep: ``(point, smallest reaction's settlement, smallest reaction, plateau's
    settlement, plateau reaction)``, the point as ``key=value, ...``; NaN where a number is missing."""
    attrs = sweep.status.attrs if "status" in sweep else {}
    meanings = dict(zip(str(attrs.get("flag_meanings", "")).split(), np.atleast_1d(attrs.get("flag_values", []))))
    if "ok" not in meanings:
        raise mf.MasonryError(f"{sweep.attrs.get('title', 'the sweep')}: its status variable has no 'ok' flag "
                              "(flag_meanings): not a sweep written by masonryfw sweep")
    ok = sweep.status.values == meanings["ok"]
    names = ("minimum_reaction_settlement", "minimum_reaction", "plateau_settlement", "plateau_reaction")
    values = [sweep[n].values if n in sweep else np.full(ok.shape, np.nan) for n in names]
    out = []
    for index in zip(*np.nonzero(ok)):
        where = ", ".join(f"{sweep[c].attrs.get('sweep_key', c)}={sweep[c].values[index[sweep.status.dims.index(d)]]}"
                          for d in sweep.status.dims for c in sweep.coords if sweep[c].dims == (d,))
        out.append((where, *(float(v[index]) for v in values)))
    return out


def _draw_sweeps(ax, sweeps: Sequence[xr.Dataset], first_colour: int) -> list:
    """Each sweep point's smallest reaction (filled) and plateau (hollow) at their settlements."""
    handles = []
    for k, sweep in enumerate(sweeps):
        colour = f"C{(first_colour + k) % 10}"
        points = sweep_points(sweep)
        keys = sweep.attrs.get("sweep_keys", "")
        x, y = 1e3 * np.array([p[1] for p in points]), np.array([p[2] for p in points])
        handles.append(ax.scatter(x, y, marker="o", s=22, color=colour, zorder=4,
                                  label=f"sweep of {keys}: smallest reaction ({len(points)} points)"))
        handles.append(ax.scatter(1e3 * np.array([p[3] for p in points]), [p[4] for p in points], marker="s", s=22,
                                  facecolors="none", edgecolors=colour, zorder=4, label=f"sweep of {keys}: plateau"))
        if len(points) <= 12:
            for (where, *_), xi, yi in zip(points, x, y):
                ax.annotate(where.split("=", 1)[-1] if "," not in where else where, (xi, yi), fontsize="x-small",
                            xytext=(3, 3), textcoords="offset points", color=colour)
    return handles


def gravity_records(settlement: np.ndarray) -> int:
    """Number of records before the first settlement: the gravity stage (the last of them is the dead state)."""
    moved = np.flatnonzero(np.asarray(settlement) > 0)
    return int(moved[0]) if moved.size else int(np.size(settlement))


def _damage_strips(ax, incremental: Sequence[xr.Dataset]) -> tuple[list, int]:
    """A thin strip per result along the top of ``ax``, coloured by the damage category along the settlement;
    returns the legend's handles and the number of strips."""
    names = {v: k.replace("_", " ") for k, v in mf.flags("step_damage_category").items()}
    seen: set[int] = set()
    row = 0
    for ds in incremental:
        if "step_damage_category" not in ds or ds.step_damage_category.size < 2:
            continue
        s = 1e3 * ds.step_settlement.values
        category = ds.step_damage_category.values.astype(int)
        top = 1.0 - STRIP_SHARE * row
        for k in range(s.size - 1):
            if s[k + 1] > s[k]:
                ax.axvspan(s[k], s[k + 1], ymin=top - 0.85 * STRIP_SHARE, ymax=top, color=DAMAGE_COLOURS[category[k]], lw=0)
        seen.update(category.tolist())
        row += 1
    return [Patch(color=DAMAGE_COLOURS[c], label=f"damage {c} {names[c]}") for c in sorted(seen)], row


def _room_for_strips(ax, rows: int) -> None:
    """Raise the top of ``ax`` so that ``rows`` damage strips sit above the curves, not on them."""
    if rows:
        low, high = ax.get_ylim()
        ax.set_ylim(low, low + (high - low) / (1.0 - STRIP_SHARE * rows - 0.01))


def _profiled(results: Sequence[xr.Dataset]) -> bool:
    """Whether any result settles several supports (a profile): its reaction is then the settlement reaction
    (``mf.settlement_reaction``: each support weighted by its motion), not one support's."""
    moving = mf.flags("block_role")["moving_support"]
    return any(int((ds.block_role.values == moving).sum()) > 1 for ds in results if "block_role" in ds)


def draw_history(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """The reaction on the moving supports (or the damage) against the settlement, of one or more
    incremental results overlaid, with the dead load R0 and, for every la result given, its collapse
    reaction (1 - alpha) R0 as reference lines; the gravity stage as the spread of reactions at zero
    settlement; the damage category as strips along the top."""
    incremental, limits, sweeps = _split_history(datasets, "history")
    labels = distinct_labels(incremental)
    colours = [f"C{i % 10}" for i in range(len(incremental))]
    ax.grid(True, lw=0.3)
    ax.set_xlabel("settlement [mm]")
    log = options["xscale"] == "log"
    ax.set_xscale("log" if log else "linear")
    if options["quantity"] == "damage":
        if sweeps or not incremental:
            raise mf.MasonryError("history --option quantity=damage draws incremental results, not sweeps")
        _draw_damage(ax, incremental, labels, colours)
    else:
        handles = []
        for ds, label, colour in zip(incremental, labels, colours):
            s, r = 1e3 * ds.step_settlement.values, ds.step_reaction.values
            first = max(gravity_records(s) - 1, 0)
            shown = slice(first + 1 if log else first, None)
            handles += ax.plot(s[shown], r[shown], color=colour, lw=1.2, label=label)
            if first > 0 and not log:  # the reactions of the gravity stage, at zero settlement
                low, high = float(r[:first + 1].min()), float(r[:first + 1].max())
                handles.append(ax.vlines(0.0, low, high, color=colour, lw=4, alpha=0.35,
                                         label=f"{label}: gravity stage, {first + 1} records, {low:.4g}..{high:.4g} N"))
        handles += _draw_sweeps(ax, sweeps, len(incremental))
        references = [*incremental, *limits]
        r0 = mf.dead_reaction(references[0]) if references else 0.0
        if r0 > 0:
            handles.append(ax.axhline(r0, ls="--", lw=0.9, color="0.35", label=f"dead reaction R0 = {r0:.4g} N"))
        for ds, style in zip(limits, (":", "-.", (0, (1, 3)), (0, (5, 2)))):
            collapse = (1 - float(ds.collapse_multiplier.values)) * mf.dead_reaction(ds)
            handles.append(ax.axhline(collapse, ls=style, lw=1.2, color="k",
                                      label=f"{mf.result_label(ds)}: (1 - alpha) R0 = {collapse:.4g} N"))
        strips, rows = _damage_strips(ax, incremental)
        ax.set_ylabel("settlement reaction [N]" if _profiled(references) else "reaction on the moving support [N]")
        ax.set_ylim(bottom=min(0.0, ax.get_ylim()[0]))
        ax.legend(handles=handles + strips, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2,
                  fontsize="small", frameon=False)
    if options["settlement_max"] is not None:
        ax.set_xlim(right=options["settlement_max"], left=None if log else -0.02 * options["settlement_max"])
    if options["quantity"] == "reaction":
        if options["settlement_max"] is not None:
            _fit_y_to_shown(ax, [(1e3 * ds.step_settlement.values, ds.step_reaction.values) for ds in incremental])
        _room_for_strips(ax, rows)
    if len(incremental) == 1 and not limits and not sweeps:
        ax.set_title(f"{title_of(incremental[0])}\n{mf.headline_text(incremental[0])}", fontsize="medium")
    else:
        ax.set_title(str(datasets[0].attrs.get("title", "")), fontsize="medium")


def _fit_y_to_shown(ax, curves: Sequence[tuple[np.ndarray, np.ndarray]]) -> None:
    """Rescale y to the curves' points inside the x range (after a zoom on the settlement)."""
    low, high = ax.get_xlim()
    ys = [y[(x >= low) & (x <= high)] for x, y in curves]
    ys = [y for y in ys if y.size]
    if ys:
        ax.set_ylim(min(0.0, min(float(np.min(y)) for y in ys)), 1.05 * max(float(np.max(y)) for y in ys))


def _draw_damage(ax, incremental, labels, colours) -> None:
    """The widest crack of every result against the settlement on one crack-width axis whose damage
    categories are bands (their limits from ``mf.DAMAGE_LIMITS``, named at the right): the category a curve
    is in is the band it crosses, with no second axis to misread. Linear up to 0.1 mm (category 0, where a
    crack may be 0), logarithmic above."""
    for ds in incremental:
        _require(ds, ["step_damage_category", "step_crack_width_max"], "history --option quantity=damage",
                 "a result with crack widths (fdem or jmm)")
    names = {v: k.replace("_", " ") for k, v in mf.flags("step_damage_category").items()}
    limits_mm = [0.0, *(1e3 * v for v in mf.DAMAGE_LIMITS)]
    widest = max(float(np.max(ds.step_crack_width_max.values, initial=0.0)) for ds in incremental) * 1e3
    top = max(2.0 * limits_mm[-1], 1.5 * widest)
    ax.set_yscale("symlog", linthresh=limits_mm[1], linscale=0.6)
    for category, low in enumerate(limits_mm):
        high = limits_mm[category + 1] if category + 1 < len(limits_mm) else top
        ax.axhspan(low, high, color=DAMAGE_COLOURS[category], alpha=0.13, lw=0, zorder=0)
        ax.text(1.01, np.sqrt(max(low, 1e-2) * high) if category else 0.5 * high, f"{category} {names[category]}",
                transform=ax.get_yaxis_transform(), va="center", ha="left", fontsize="small", color="0.2")
    for ds, label, colour in zip(incremental, labels, colours):
        s = 1e3 * ds.step_settlement.values
        ax.plot(s, 1e3 * ds.step_crack_width_max.values, color=colour, lw=1.3, label=label)
    ax.set_ylim(0.0, top)
    ax.set_yticks(limits_mm, [f"{v:g}" for v in limits_mm])
    ax.minorticks_off()
    ax.set_ylabel("widest crack in the masonry [mm]")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, fontsize="small", frameon=False,
              title="damage category: the band the curve is in (Burland et al. 1977)", title_fontsize="small")


def history_table(datasets: Sequence[xr.Dataset], options: Mapping[str, Any]) -> tuple[list[str], list[list]]:
    """The history plot's curves as rows: one per record of every incremental result (the la references
    as rows with no record), in SI units."""
    incremental, limits, sweeps = _split_history(datasets, "history")
    header = ["result", "record", "stage", "settlement_m", "reaction_N", "crack_width_max_m", "damage_category"]
    rows: list[list] = []
    for ds, label in zip(incremental, distinct_labels(incremental)):
        s = ds.step_settlement.values
        gravity = gravity_records(s)
        width = ds.step_crack_width_max.values if "step_crack_width_max" in ds else [None] * s.size
        damage = ds.step_damage_category.values if "step_damage_category" in ds else [None] * s.size
        for k in range(s.size):
            rows.append([label, k, "gravity" if k < gravity else "settlement", float(s[k]),
                         float(ds.step_reaction.values[k]), None if width[k] is None else float(width[k]),
                         None if damage[k] is None else int(damage[k])])
    for ds in limits:
        r0, alpha = mf.dead_reaction(ds), float(ds.collapse_multiplier.values)
        rows.append([mf.result_label(ds), None, "collapse (1 - alpha) R0", None, (1 - alpha) * r0, None, None])
    for sweep in sweeps:
        for k, (where, s_min, r_min, s_plateau, r_plateau) in enumerate(sweep_points(sweep)):
            rows.append([f"sweep {where}", k, "smallest reaction", s_min, r_min, None, None])
            rows.append([f"sweep {where}", k, "plateau", s_plateau, r_plateau, None, None])
    return header, rows


#: The one-result kinds and the variable each needs (the first the drawing reads).
SINGLE_RESULT_KINDS = {"mechanism": "block_displacement", "cracks": "interface_opening",
                       "forces": "interface_normal_force", "plastic": "qp_failure"}


def drawable_kinds(ds: xr.Dataset) -> list[str]:
    """The one-result kinds ``ds`` can be drawn as, in the order of :data:`SINGLE_RESULT_KINDS`; then ``ltsm``
    for a result over a settlement profile with a settlement to assess."""
    kinds = [kind for kind, needs in SINGLE_RESULT_KINDS.items() if needs in ds]
    assessed = ("step_settlement" in ds and ds.step_settlement.size) or "settlement_target" in ds
    return kinds + (["ltsm"] if ds.attrs.get("settlement_profile") and assessed else [])


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
    """Joints with ``crack_indicator > threshold`` drawn heavy over the undeformed wall."""
    geo = mf.derive_geometry(ds)
    _draw_blocks(ax, geo, geo.node_x.values, geo.node_y.values, np.array(["0.93"] * geo.sizes["block"], dtype=object))
    cracked = ds.crack_indicator.values > threshold
    ax.add_collection(LineCollection(
        _segments(geo.interface_x.values[cracked], geo.interface_y.values[cracked]), colors="k", linewidths=2.2,
    ))
    _finish(ax, ds)


def score_caption(comparison: xr.Dataset) -> str:
    """Short caption of the main scores of a comparison (only those computed)."""
    parts = [
        (label, comparison[name].item()) for label, name in (
            ("F1", "crack_f1"), ("ARI", "macro_block_ari"), ("cos", "mechanism_cosine"), ("d", "locus_distance"),
        ) if name in comparison
    ]
    return ", ".join(f"{label} {value:.2f}" for label, value in parts) or "no common score"


def panel_axes(ax, count: int) -> list:
    """``count`` side-by-side Axes in the place of ``ax`` (which stays as an invisible frame)."""
    figure = ax.figure
    spec = ax.get_subplotspec()
    ax.set_axis_off()
    if spec is not None:
        grid = spec.subgridspec(1, count)
        return [figure.add_subplot(grid[0, i]) for i in range(count)]
    left, bottom, width, height = ax.get_position().bounds
    return [figure.add_axes((left + i * width / count, bottom, width / count, height)) for i in range(count)]


def draw_compare(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """Results side by side, the first titled with the wall; each later panel's title carries its scores
    against the first. The panels keep their drawings and drop their legends (the single-result kinds
    explain them); a mechanism's amplification goes under its panel."""
    if len(datasets) < 2:
        raise mf.MasonryError(f"the compare plot needs two or more results of one model, got {len(datasets)}")
    kinds = [panel_kind(ds) for ds in datasets]
    captions = ["reference"] + [
        score_caption(mf.compare(datasets[0], ds, "crack", {"threshold": options["threshold"]})) for ds in datasets[1:]
    ]
    wall = str(datasets[0].attrs.get("title", ""))
    for k, (panel, ds, kind, caption) in enumerate(zip(panel_axes(ax, len(datasets)), datasets, kinds, captions)):
        if kind == "mechanism":
            draw_mechanism([ds], panel, options)
            amplification = panel.get_legend().get_title().get_text()
            panel.set_xlabel(f"x [m]; {amplification}")
        elif kind == "plastic":
            draw_plastic([ds], panel, {"marker_size": 4.0})
        else:
            draw_indicator(ds, panel, options["threshold"])
        if panel.get_legend() is not None:
            panel.get_legend().remove()
        alpha = f", alpha = {ds.collapse_multiplier.item():.4g}" if "collapse_multiplier" in ds else ""
        heading = f"{wall}\n" if k == 0 and wall else ""
        panel.set_title(f"{heading}{mf.result_label(ds)}{alpha}\n{caption}", fontsize="medium")
