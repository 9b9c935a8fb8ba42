"""Plot kinds: the drawing functions behind the ``Plotter`` records of :mod:`.records`.

Every kind draws on one matplotlib Axes with equal axes, metres on both axes and
a title made of the model's ``title`` and the solver; ``history`` plots reaction
against settlement instead. A kind that needs a variable the result lacks raises
a :class:`masonryfw.MasonryError` naming the variable and the kind of result it needs.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.lines import Line2D

import masonryfw as mf

from .comparison import solver_label
from .shapes import deformed_nodes, deformed_points, largest_vertex_motion, padded_block_nodes

# Default amplification: the largest vertex displacement drawn as this share of the model size.
DRAWN_MOTION_SHARE = 0.10
STATE_COLOURS = {"open": "tab:red", "slide": "tab:blue", "open_slide": "tab:purple"}
FAILURE_COLOURS = {"tensile": "tab:blue", "shear": "0.55", "tensile_shear": "navy"}
SUPPORT_COLOUR = "0.45"
THRUST_REFERENCE_PERCENTILE = 95.0
# tab20 entries for macro-blocks: the dark shades first, then the light ones, so that
# neighbouring labels differ in hue; its greys (14, 15) are left to the supports.
MACRO_BLOCK_HUES = tuple(i for i in (*range(0, 20, 2), *range(1, 20, 2)) if i not in (14, 15))


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
    label = solver_label(ds) if "solver" in ds.attrs else "model"
    return f"{ds.attrs.get('title', 'untitled')} - {label}"


def _finish(ax, ds: xr.Dataset) -> None:
    """Equal axes in metres, titled with the model and the solver."""
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title_of(ds), fontsize="medium")


def _block_verts(geo: xr.Dataset, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    idx = padded_block_nodes(geo.block_node_count.values)
    return np.stack([x[idx], y[idx]], axis=-1)


def _supports(geo: xr.Dataset) -> np.ndarray:
    return mf.support_blocks(geo.block_role.values)


def _draw_blocks(ax, geo, x, y, facecolors, *, edge="0.3", width=0.3, zorder=1) -> None:
    """Masonry blocks filled with ``facecolors`` (per block), supports hatched grey."""
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


def macro_block_colours(ds: xr.Dataset) -> np.ndarray:
    """One colour per block from its macro-block label (tab20 cycled); light grey without labels."""
    if "macro_block" not in ds:
        return np.array(["0.85"] * ds.sizes["block"], dtype=object)
    _, rank = np.unique(ds.macro_block.values, return_inverse=True)
    palette = colormaps["tab20"].colors
    return np.array([palette[MACRO_BLOCK_HUES[r % len(MACRO_BLOCK_HUES)]] for r in range(rank.max() + 1)],
                    dtype=object)[rank]


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
    fastest = float(np.linalg.norm(geo.settlement_direction.values[moving, :2], axis=1).max(initial=0.0))
    for block in moving:  # arrows as long as the rates: a settlement profile shows its shape
        direction = geo.settlement_direction.values[block, :2]
        if np.linalg.norm(direction) > 0:
            start = np.array([geo.block_centroid_x.values[block], geo.block_centroid_y.values[block]])
            tip = start + 0.08 * size * direction / fastest
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


def draw_mechanism(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """The wall in its amplified deformed configuration, blocks coloured by macro-block, cracks heavy."""
    ds = _single(datasets, "mechanism")
    _require(ds, ["block_displacement"], "mechanism", "block displacements (a discrete la or fdem result)")
    geo = mf.derive_geometry(ds)
    u = mf.block_motion(ds)
    amplification = options["amplification"] or default_amplification(geo, u)
    _draw_outline(ax, geo)
    x, y = deformed_nodes(geo, u, amplification)
    _draw_blocks(ax, geo, x, y, macro_block_colours(ds))
    if "crack_indicator" in ds:
        cracked = ds.crack_indicator.values > options["threshold"]
        blocks = geo.interface_blocks.values[cracked].astype(np.int64)
        px, py = geo.interface_x.values[cracked], geo.interface_y.values[cracked]
        x0, y0 = deformed_points(geo, u, amplification, px, py, blocks[:, [0, 0]])
        x1, y1 = deformed_points(geo, u, amplification, px, py, blocks[:, [1, 1]])
        ax.add_collection(LineCollection(
            _segments(0.5 * (x0 + x1), 0.5 * (y0 + y1)), colors="k", linewidths=2.2, zorder=3,
        ))
    ax.text(0.01, 0.01, f"displacements x {amplification:.3g}", transform=ax.transAxes, fontsize="small")
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
    ax.legend(handles=handles, loc="upper left", fontsize="small", framealpha=0.8)
    _finish(ax, ds)


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
    loaded = total > 1e-9 * max(np.max(np.abs(total), initial=0.0), np.finfo(float).tiny)
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


def draw_forces(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """Contact forces at collapse as thrust segments through each joint's centre of pressure."""
    ds = _single(datasets, "forces")
    _require(
        ds, ["interface_normal_force", "interface_shear_force"], "forces",
        "contact forces (a limit analysis la result)",
    )
    geo = mf.derive_geometry(ds)
    _draw_blocks(ax, geo, geo.node_x.values, geo.node_y.values, np.array(["0.93"] * geo.sizes["block"], dtype=object))
    px, py, magnitude, segments = thrust_segments(
        geo, ds.interface_normal_force.values, ds.interface_shear_force.values, options["scale"]
    )
    if magnitude.size:
        width = 0.5 + 2.5 * np.minimum(magnitude / np.percentile(magnitude, THRUST_REFERENCE_PERCENTILE), 1.0)
        ax.add_collection(LineCollection(segments, colors="tab:red", linewidths=width, zorder=3))
        ax.scatter(px, py, s=2, c="k", zorder=4)
        ax.text(0.01, 0.01, f"largest joint force {magnitude.max():.3g} N", transform=ax.transAxes, fontsize="small")
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
    ax.legend(loc="upper left", fontsize="small", framealpha=0.8, markerscale=2)
    _finish(ax, ds)


def draw_history(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """The reaction on the moving supports, or the damage (category and widest crack), against the settlement."""
    ds = _single(datasets, "history")
    _require(ds, ["step_settlement", "step_reaction"], "history", "an incremental (fdem or jmm) result")
    ax.set_title(title_of(ds), fontsize="medium")
    ax.grid(True, lw=0.3)
    ax.set_xlabel("settlement [mm]")
    settlement = 1e3 * ds.step_settlement.values
    if options.get("quantity", "reaction") == "reaction":
        ax.plot(settlement, ds.step_reaction.values, marker=".", ms=3)
        ax.set_ylabel("reaction on the moving supports [N]")
        return
    _require(ds, ["step_damage_category", "step_crack_width_max"], "history --option quantity=damage",
             "a result with crack widths (fdem or jmm, issue 14 or later)")
    names = mf.flags("step_damage_category")
    ax.step(settlement, ds.step_damage_category.values, where="post", color="C3", label="damage category")
    ax.set_yticks(list(names.values()), [f"{v} {k.replace('_', ' ')}" for k, v in names.items()], fontsize="small")
    ax.set_ylim(-0.3, 5.3)
    ax.set_ylabel("damage category (Burland et al. 1977)")
    width = ax.twinx()
    width.plot(settlement, 1e3 * ds.step_crack_width_max.values, color="0.3", lw=1.0, label="widest crack")
    width.set_ylabel("widest crack [mm]")
    lines = ax.get_lines() + width.get_lines()
    ax.legend(lines, [line.get_label() for line in lines], loc="upper left", fontsize="small", framealpha=0.8)


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
    """Results side by side; each later panel's title carries its scores against the first."""
    if len(datasets) < 2:
        raise mf.MasonryError(f"the compare plot needs two or more results of one model, got {len(datasets)}")
    kinds = [panel_kind(ds) for ds in datasets]
    captions = ["reference"] + [
        score_caption(mf.compare(datasets[0], ds, "crack", {"threshold": options["threshold"]})) for ds in datasets[1:]
    ]
    for panel, ds, kind, caption in zip(panel_axes(ax, len(datasets)), datasets, kinds, captions):
        if kind == "mechanism":
            draw_mechanism([ds], panel, options)
        elif kind == "plastic":
            draw_plastic([ds], panel, {"marker_size": 4.0})
        else:
            draw_indicator(ds, panel, options["threshold"])
        alpha = f", alpha = {ds.collapse_multiplier.item():.4g}" if "collapse_multiplier" in ds else ""
        panel.set_title(f"{solver_label(ds)}{alpha}\n{caption}", fontsize="medium")
    ax.figure.suptitle(str(datasets[0].attrs.get("title", "")), fontsize="large")
