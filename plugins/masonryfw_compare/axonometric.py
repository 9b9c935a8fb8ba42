"""3D models and results drawn in axonometry (matplotlib's 3D axes): the model by role, the mechanism amplified
with its macro-blocks coloured and its cracked interfaces outlined. What the ``model`` and ``mechanism`` kinds
draw for a 3D dataset."""
from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .figure_parts import SUPPORT_COLOUR, legend_beside, title_text

#: The view: elevation and azimuth [degrees] (the front, y = 0, seen from the south-west, from above).
VIEW = (22.0, -58.0)
#: The largest vertex motion of a mechanism is drawn as this share of the model's size by default.
DRAWN_MOTION_SHARE = 0.05
CRACK_COLOUR = "k"
WIDEST_RING = "#0050d0"


def axes_3d(ax):
    """A 3D axes in the place of ``ax`` (the figure :func:`masonryfw.render` made is a 2D one); ``ax`` itself if it
    is one (a panel of the compare plot)."""
    if ax.name == "3d":
        return ax
    figure, where = ax.figure, ax.get_subplotspec()
    ax.remove()
    return figure.add_subplot(where, projection="3d")


def faces(geo: xr.Dataset, points: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """Every block face as a polygon of ``points`` (the blocks' vertices, moved or not), and its block."""
    poly = mfp.polyhedra_of(geo)
    index = poly.face_vertex_index()
    split = np.cumsum(poly.face_node_count)[:-1]
    return np.split(points[index], split), poly.face_block()


def moved_points(geo: xr.Dataset, u: np.ndarray, amplification: float) -> np.ndarray:
    """The blocks' vertices moved by ``amplification`` times the mechanism ``u`` (block, 6), linearised."""
    owner = np.repeat(np.arange(geo.sizes["block"]), geo.block_node_count.values)
    points = np.c_[geo.node_x.values, geo.node_y.values, geo.node_z.values]
    centre = np.c_[geo.block_centroid_x.values, geo.block_centroid_y.values, geo.block_centroid_z.values]
    return points + amplification * mfp.carried_motion(u, centre, points, owner)


def default_amplification(geo: xr.Dataset, u: np.ndarray) -> float:
    largest = float(np.linalg.norm(moved_points(geo, u, 1.0) - moved_points(geo, u, 0.0), axis=1).max(initial=0.0))
    size = float(np.ptp(np.c_[geo.node_x.values, geo.node_y.values, geo.node_z.values], axis=0).max())
    return DRAWN_MOTION_SHARE * size / largest if largest > 0 else 1.0


#: The 3D box drawn this much larger than matplotlib's default (which leaves a wide margin round it).
ZOOM = 0.85
#: The share of the axes' width the z axis' labels stand out of a 3D box: a legend beside it keeps clear of them.
TICKS_3D = 0.1


def finish_3d(ax, ds: xr.Dataset, points: np.ndarray) -> None:
    """Equal scales on the three axes fitted to ``points`` (the box as long, deep and high as what is drawn, so
    that a building fills its page rather than a cube round it), the view, labels, the walls named and the
    title wrapped to the page."""
    low, high = points.min(axis=0), points.max(axis=0)
    span = np.maximum(high - low, 1e-3 * float((high - low).max()))
    for setter, a, b in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), low, low + span):
        setter(a, b)
    ax.set_box_aspect(tuple(span / span.max()), zoom=ZOOM)
    for axis, length in zip((ax.xaxis, ax.yaxis, ax.zaxis), span / span.max()):
        axis.set_major_locator(MaxNLocator(max(2, round(6 * length)), steps=[1, 2, 5, 10]))  # a short axis, few ticks
    ax.view_init(*VIEW)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    name_walls(ax, ds)
    ax.set_title(title_text(ax, ds), fontsize="medium")


def name_walls(ax, ds: xr.Dataset) -> None:
    """Each wall of a building (``building_walls``) named over the middle of its top."""
    if "building_walls" not in ds.attrs:
        return
    for wall in json.loads(ds.attrs["building_walls"]):
        (x0, y0), (x1, y1) = wall["start"], wall["end"]
        ax.text(0.5 * (x0 + x1), 0.5 * (y0 + y1), 1.04 * wall["height"], wall["name"], ha="center", va="bottom",
                fontsize="small", fontweight="bold", zorder=5,
                bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none", "alpha": 0.8})


def draw_model_3d(ds: xr.Dataset, ax, colours: Mapping[str, str]) -> None:
    """The blocks by role (``colours``: role name to colour), the moving supports in their colour."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    ax = axes_3d(ax)
    geo = mfp.derive_geometry(ds)
    names = {value: name for name, value in mfp.ROLE.items()}
    role = [names[int(r)] for r in geo.block_role.values]
    points = np.c_[geo.node_x.values, geo.node_y.values, geo.node_z.values]
    polygons, block = faces(geo, points)
    ax.add_collection3d(Poly3DCollection(polygons, facecolors=[colours[role[b]] for b in block], edgecolors="0.35",
                                         linewidths=0.2))
    present = sorted(set(role), key=list(colours).index)
    legend_beside(ax, TICKS_3D, handles=[Patch(facecolor=colours[r], edgecolor="0.35", label=r.replace("_", " "))
                                         for r in present], fontsize="small", frameon=False)
    finish_3d(ax, ds, points)


def draw_mechanism_3d(ds: xr.Dataset, ax, options: Mapping[str, Any], pieces, piece_colours) -> None:
    """The blocks moved by the amplified mechanism relative to the largest macro-block, coloured by macro-block
    (``piece_colours`` per block), the supports grey, the cracked interfaces outlined on side 0's face."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    ax = axes_3d(ax)
    ax.computed_zorder = False  # the cracked interfaces over the blocks, whose faces are sorted among themselves
    geo = mfp.derive_geometry(ds)
    u = relative_to_largest(geo, mfp.block_motion(ds), pieces)
    amplification = options["amplification"] or default_amplification(geo, u)
    points = moved_points(geo, u, amplification)
    polygons, block = faces(geo, points)
    support = mfp.support_blocks(geo.block_role.values)
    colours = [SUPPORT_COLOUR if support[b] else piece_colours[b] for b in block]
    ax.add_collection3d(Poly3DCollection(polygons, facecolors=colours, edgecolors="0.3", linewidths=0.15, zorder=1))
    handles = [Patch(facecolor=piece_colours[np.flatnonzero(pieces.number == k)[0]], edgecolor="0.3",
                     label=f"macro-block ({k})") for k in range(1, pieces.dominant + 1)]
    if pieces.small:
        handles.append(Patch(facecolor=piece_colours[np.flatnonzero((pieces.number == 0) & ~support)[0]],
                             edgecolor="0.3", label=f"small pieces ({pieces.small})"))
    if "crack_indicator" in ds:
        cracked = mf.cracked_joints(ds, options["threshold"])
        outlines = cracked_outlines(geo, u, amplification, cracked)
        ax.add_collection3d(Line3DCollection(outlines, colors=CRACK_COLOUR, linewidths=0.9, zorder=2))
        handles.append(Line2D([], [], color=CRACK_COLOUR, lw=1.5, label=f"cracked interfaces ({int(cracked.sum())}), "
                                                                       "seen through the masonry"))
    reference = "macro-block (1)" if pieces.dominant else "the ground"
    legend_beside(ax, TICKS_3D, handles=handles, fontsize="small", frameon=False,
                  title=f"motion relative to {reference}, x {amplification:.3g}", title_fontsize="small")
    finish_3d(ax, ds, points)


def relative_to_largest(geo: xr.Dataset, u: np.ndarray, pieces) -> np.ndarray:
    """``u`` (block, 6) less the rigid motion of the largest macro-block (its blocks then stand still): a building
    settles with the ground by far more than its parts move against each other, and the drawing is of the
    latter."""
    largest = np.flatnonzero(pieces.number == 1)
    if largest.size == 0:
        return u
    reference = largest[0]
    centre = np.c_[geo.block_centroid_x.values, geo.block_centroid_y.values, geo.block_centroid_z.values]
    rigid = np.c_[u[reference, :3] + np.cross(u[reference, 3:], centre - centre[reference]),
                  np.broadcast_to(u[reference, 3:], (u.shape[0], 3))]
    return u - rigid


def cracked_outlines(geo: xr.Dataset, u: np.ndarray, amplification: float, cracked: np.ndarray) -> list[np.ndarray]:
    """The polygon of every cracked interface, closed, carried by its side-0 block's amplified motion."""
    count = geo.interface_node_count.values.astype(np.int64)
    points = mfp.interface_points(geo)
    side0 = geo.interface_blocks.values[np.repeat(np.arange(count.size), count), 0].astype(np.int64)
    centre = np.c_[geo.block_centroid_x.values, geo.block_centroid_y.values, geo.block_centroid_z.values]
    moved = points + amplification * mfp.carried_motion(u, centre, points, side0)
    polygons = np.split(moved, np.cumsum(count)[:-1])
    return [np.vstack([p, p[:1]]) for p, crack in zip(polygons, cracked) if crack]


#: Crack colours by damage category 1 to 5 (a joint opening under category 1's 0.1 mm is not drawn).
CATEGORY_COLOURS = ("#fdd49e", "#fc8d59", "#e34a33", "#b30000", "#4a0000")
MASONRY_FACE = (0.93, 0.93, 0.93, 0.25)  # light and see-through: the cracks of the far walls show through


def draw_cracks_3d(ds: xr.Dataset, ax, threshold: float, state_colours: Mapping[str, str]) -> None:
    """The building as built, see-through, and its joints in the masonry over it: of a result with crack widths
    (an incremental solver) every joint that opens at the last record by a damage category's width (0.1 mm and
    more) filled in that category's colour, each wall's widest crack ringed and listed with its width and
    category (``step_wall_crack_width_max``); of a mechanism (limit analysis: a shape, not a size) the cracked
    joints at ``threshold`` by how they move (``state_colours``: open, slide, both). The walls named."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    ax = axes_3d(ax)
    ax.computed_zorder = False  # the cracks over the see-through blocks
    geo = mfp.derive_geometry(ds)
    points = np.c_[geo.node_x.values, geo.node_y.values, geo.node_z.values]
    polygons, block = faces(geo, points)
    support = mfp.support_blocks(geo.block_role.values)
    ax.add_collection3d(Poly3DCollection([p for p, b in zip(polygons, block) if not support[b]],
                                         facecolors=[MASONRY_FACE], edgecolors=(0.5, 0.5, 0.5, 0.25),
                                         linewidths=0.1, zorder=1))
    count = geo.interface_node_count.values.astype(np.int64)
    joints = np.split(mfp.interface_points(geo), np.cumsum(count)[:-1])
    widths = "step_crack_width_max" in ds and ds.step_crack_width_max.size > 0
    groups = category_groups(ds) if widths else state_groups(ds, threshold, state_colours)
    handles = []
    for z, (label, colour, chosen) in enumerate(groups):
        if chosen.size:
            ax.add_collection3d(Poly3DCollection([joints[j] for j in chosen], facecolors=colour, edgecolors=colour,
                                                 linewidths=1.2, zorder=3 + z))
        handles.append(Patch(facecolor=colour, edgecolor=colour, label=f"{label} ({chosen.size})"))
    if widths:
        handles += ring_widest_per_wall(ds, ax, joints)
    title = ("joints opening at the last record, by the\ndamage category of their width (Burland et al. 1977)"
             if widths else f"cracked joints (threshold {threshold:g}): a mechanism's\nshape, not its size (no widths)")
    legend_beside(ax, TICKS_3D, handles=handles, fontsize="small", frameon=False, title=title, title_fontsize="small")
    finish_3d(ax, ds, points)


def category_groups(ds: xr.Dataset) -> list[tuple[str, str, np.ndarray]]:
    """``(label, colour, joints)`` of damage categories 1 to 5 by the width each joint opens at the last record."""
    category = mf.damage_category(joint_openings(ds))
    names = {value: name.replace("_", " ") for name, value in mfp.flags("step_damage_category").items()}
    groups = []
    for k, colour in enumerate(CATEGORY_COLOURS, start=1):
        lower = f"{mf.DAMAGE_LIMITS[k - 1] * 1e3:.3g}"
        widths = f"{lower} - {mf.DAMAGE_LIMITS[k] * 1e3:.3g} mm" if k < len(mf.DAMAGE_LIMITS) else f"over {lower} mm"
        groups.append((f"{k} {names[k]}: {widths}", colour, np.flatnonzero(category == k)))
    return groups


def state_groups(ds: xr.Dataset, threshold: float, colours: Mapping[str, str]) -> list[tuple[str, str, np.ndarray]]:
    """``(label, colour, joints)`` of the joints in the masonry cracked at ``threshold``, by their state."""
    derived = mf.at_threshold(ds, threshold)
    state = derived.interface_state.values
    masonry = mfp.masonry_blocks(derived.block_role.values)[derived.interface_blocks.values.astype(np.int64)]
    flag = mfp.flags("interface_state")
    return [(meaning.replace("_", " + "), colour, np.flatnonzero((state == flag[meaning]) & masonry.all(axis=1)))
            for meaning, colour in colours.items()]


def joint_openings(ds: xr.Dataset) -> np.ndarray:
    """Every joint's widest opening at its vertices [m] at the last record, 0 for a joint with the ground (a base
    gap is no crack in the masonry)."""
    derived = mf.at_threshold(ds)  # the relative motion at the vertices (no threshold in it)
    count = derived.interface_node_count.values.astype(np.int64)
    opening = np.maximum.reduceat(np.maximum(derived.interface_opening.values, 0.0), np.r_[0, np.cumsum(count)[:-1]])
    masonry = mfp.masonry_blocks(derived.block_role.values)[derived.interface_blocks.values.astype(np.int64)]
    return np.where(masonry.all(axis=1), opening, 0.0)


def ring_widest_per_wall(ds: xr.Dataset, ax, joints: list[np.ndarray]) -> list:
    """Each wall's widest crack at the last record ringed, the widest of them in :data:`WIDEST_RING`; their legend
    lines (wall, width, category, course and place along the wall), in the walls' order."""
    if "step_wall_crack_width_max" not in ds or not ds.step_settlement.size:
        return []
    width = ds.step_wall_crack_width_max.values[-1]
    joint = ds.step_wall_crack_interface.values[-1].astype(np.int64)
    worst = int(np.argmax(width))
    opened = [w for w in range(width.size) if joint[w] >= 0]
    for w in sorted(opened, key=lambda w: w == worst):  # the worst ring drawn last, over a ring it shares
        ax.scatter(*joints[joint[w]].mean(axis=0), s=160, facecolors="none", linewidths=1.8, zorder=9,
                   edgecolors=WIDEST_RING if w == worst else "k", depthshade=False)
    handles = []
    for w in opened:
        place = mfp.crack_place(ds, int(joint[w]), w)
        where = f", course {place.course}, {place.along:.2f} m along" if place else ""
        handles.append(Line2D([], [], marker="o", markersize=9, markerfacecolor="none", linestyle="none",
                              markeredgecolor=WIDEST_RING if w == worst else "k", markeredgewidth=1.6,
                              label=f"{ds.wall_name.values[w]}: {width[w] * 1e3:.3g} mm, category "
                                    f"{int(mf.damage_category(width[w]))}{where}"))
    return handles
