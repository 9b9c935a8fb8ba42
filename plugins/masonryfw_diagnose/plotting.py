"""The ``diagnosis`` plot: what was surveyed, what the best candidates crack, how every candidate scored.

Top row: the survey over the wall (surveyed lines red, the joints they run along heavy, lines that match no
joint dashed), then the best candidates' mechanisms (amplified, blocks that move tinted) with their cracked
joints in blue under the surveyed lines. Bottom row: every candidate's score by rank (the plausible set
shaded), the Gaussian troughs' scores over their centre and width when they were tried, and with a levelling
the measured points beside the best candidates' fits.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

FAMILY_COLOURS = {"step": "tab:blue", "gaussian": "tab:orange", "linear": "tab:green"}
SURVEY_COLOUR = "tab:red"
CRACK_COLOUR = "tab:blue"
#: The largest motion drawn as this share of the wall's size (amplification auto).
DRAWN_MOTION = 0.08


def _rings(ds: xr.Dataset, x: np.ndarray, y: np.ndarray, blocks: np.ndarray) -> list[np.ndarray]:
    starts = np.r_[0, np.cumsum(ds.block_node_count.values)[:-1]]
    counts = ds.block_node_count.values
    return [np.c_[x[starts[b]:starts[b] + counts[b]], y[starts[b]:starts[b] + counts[b]]] for b in blocks]


def _survey_lines(ax, ds: xr.Dataset, style: str = "-", width: float = 1.6) -> None:
    owner = ds.survey_point_crack.values
    matched = ds.survey_crack_matched.values
    for k in range(ds.sizes["survey_crack"]):
        points = owner == k
        ax.plot(ds.survey_point_x.values[points], ds.survey_point_y.values[points], style if matched[k] else "--",
                color=SURVEY_COLOUR, lw=width, solid_capstyle="round", zorder=4)


def _joints(ax, ds: xr.Dataset, joints: np.ndarray, colour: str, widths) -> None:
    from matplotlib.collections import LineCollection

    if joints.size:
        segments = np.stack([ds.interface_x.values[joints], ds.interface_y.values[joints]], axis=-1)
        ax.add_collection(LineCollection(segments, colors=colour, linewidths=widths, zorder=3, capstyle="round"))


def _wall(ax, ds: xr.Dataset, x: np.ndarray, y: np.ndarray, moving: np.ndarray | None = None) -> None:
    from matplotlib.collections import PolyCollection

    blocks = np.arange(ds.sizes["block"])
    support = mfp.support_blocks(ds.block_role.values)
    face = np.where(support, "#b9b9b9", "#f1ece4").astype(object)
    if moving is not None:
        face[moving & ~support] = "#e8cfa6"
    ax.add_collection(PolyCollection(_rings(ds, x, y, blocks), facecolors=list(face), edgecolors="#8c8c8c",
                                     linewidths=0.3, zorder=1))
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xticks([])
    ax.set_yticks([])


def _deformed(ds: xr.Dataset, kept: int, amplification: float | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Node positions of the ``kept`` mechanism amplified, and which blocks move (over 2 % of the largest)."""
    u = ds.kept_block_displacement.values[kept]
    theta = ds.kept_block_rotation.values[kept]
    block = np.repeat(np.arange(ds.sizes["block"]), ds.block_node_count.values)
    dx = ds.node_x.values - ds.block_centroid_x.values[block]
    dy = ds.node_y.values - ds.block_centroid_y.values[block]
    mx = u[block, 0] - theta[block] * dy
    my = u[block, 1] + theta[block] * dx
    largest = float(np.hypot(mx, my).max())
    size = float(np.hypot(np.ptp(ds.node_x.values), np.ptp(ds.node_y.values)))
    scale = amplification if amplification is not None else (DRAWN_MOTION * size / largest if largest > 0 else 0.0)
    speed = np.hypot(u[:, 0], u[:, 1])
    return ds.node_x.values + scale * mx, ds.node_y.values + scale * my, speed > 0.02 * speed.max(initial=0.0)


def _survey_panel(ax, ds: xr.Dataset) -> None:
    _wall(ax, ds, ds.node_x.values, ds.node_y.values)
    _joints(ax, ds, np.flatnonzero(ds.observed_joint.values), "#6b0000", 2.4)
    _survey_lines(ax, ds)
    unmatched = int((ds.survey_crack_matched.values == 0).sum())
    ax.set_title(f"survey: {ds.sizes['survey_crack']} lines, {int(ds.observed_joint.values.sum())} joints"
                 + (f", {unmatched} on no joint (dashed)" if unmatched else ""), fontsize=8)


def _candidate_panel(ax, ds: xr.Dataset, kept: int, amplification: float | None) -> None:
    k = int(ds.kept_candidate.values[kept])
    x, y, moving = _deformed(ds, kept, amplification)
    _wall(ax, ds, x, y, moving)
    indicator = ds.kept_crack_indicator.values[kept]
    masonry = mfp.masonry_blocks(ds.block_role.values)
    inner = masonry[ds.interface_blocks.values.astype(np.int64)].all(axis=1)
    cracked = np.flatnonzero(inner & (indicator > 0))
    _joints(ax, ds, cracked, CRACK_COLOUR, 0.6 + 2.4 * indicator[cracked])
    _survey_lines(ax, ds, width=0.9)
    magnitude = float(ds.candidate_magnitude.values[k])
    size = f", t {1e3 * magnitude:.3g} mm" if np.isfinite(magnitude) else ""
    if "candidate_reranked_score" in ds and np.isfinite(ds.candidate_reranked_score.values[k]):
        size += f", {ds.attrs.get('ranked_by', '')} {float(ds.candidate_reranked_score.values[k]):.2f}"
    ax.set_title(f"{k + 1}: {mfp.candidate_text(ds, k)}\nscore {float(ds.candidate_score.values[k]):.2f}{size}"
                 + (" (plausible)" if ds.candidate_plausible.values[k] else ""), fontsize=8)


def _score_panel(ax, ds: xr.Dataset) -> None:
    score = ds.candidate_score.values
    rank = np.arange(1, score.size + 1)
    families = ds.candidate_profile.values.astype(str)
    plausible = ds.candidate_plausible.values.astype(bool)
    for family, colour in FAMILY_COLOURS.items():
        mine = families == family
        if mine.any():
            ax.scatter(rank[mine], score[mine], s=9, color=colour, label=family, zorder=2)
    ax.scatter(rank[plausible], score[plausible], s=40, facecolors="none", edgecolors="k", lw=0.7, zorder=3,
               label="plausible")
    ax.axhline(float(ds.attrs.get("explained_threshold", 0.5)), color="k", lw=0.6, ls=":",
               label="explained well above")
    ax.set_xscale("log")
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel(f"rank (the first {int(ds.attrs['reranked'])} by {ds.attrs.get('ranked_by', '')})"
                  if int(ds.attrs.get("reranked", 0)) else "rank")
    ax.set_ylabel("score")
    ax.set_title(f"{score.size} candidates", fontsize=8)
    ax.legend(fontsize=7, loc="upper right", frameon=False)


def _gaussian_panel(ax, ds: xr.Dataset) -> None:
    gaussian = ds.candidate_profile.values.astype(str) == "gaussian"
    centres, widths = ds.candidate_center.values[gaussian], ds.candidate_width.values[gaussian]
    scores = ds.candidate_score.values[gaussian]
    xs, ws = np.unique(np.round(centres, 9)), np.unique(np.round(widths, 9))
    grid = np.full((ws.size, xs.size), np.nan)
    grid[np.searchsorted(ws, np.round(widths, 9)), np.searchsorted(xs, np.round(centres, 9))] = scores
    mesh = ax.pcolormesh(np.arange(xs.size + 1) - 0.5, np.arange(ws.size + 1) - 0.5, grid, cmap="viridis",
                         vmin=0.0, vmax=1.0, shading="flat")
    ax.figure.colorbar(mesh, ax=ax, label="score", shrink=0.9)
    step = max(1, xs.size // 8)
    ax.set_xticks(np.arange(xs.size)[::step], [f"{v:.3g}" for v in xs[::step]], fontsize=7)
    ax.set_yticks(np.arange(ws.size), [f"{v:.3g}" for v in ws], fontsize=7)
    masonry = mfp.masonry_blocks(ds.block_role.values)
    xmin, xmax, _, _ = mfp.block_bounds(ds.node_x.values, ds.node_y.values, ds.block_node_count.values)
    for edge in (xmin[masonry].min(), xmax[masonry].max()):
        ax.axvline(np.interp(edge, xs, np.arange(xs.size)), color="w", lw=0.8, ls="--")
    ax.set_xlabel("trough centre [m] (dashed: the wall's ends)")
    ax.set_ylabel("trough width i [m]")
    ax.set_title("gaussian troughs", fontsize=8)


def _levelling_panel(ax, ds: xr.Dataset) -> None:
    order = np.argsort(ds.levelling_x.values)
    x = ds.levelling_x.values[order]
    ax.plot(x, 1e3 * ds.levelling_dy.values[order], "o", color=SURVEY_COLOUR, ms=4, label="levelling")
    for kept in range(ds.sizes.get("kept", 0)):
        candidate = int(ds.kept_candidate.values[kept])
        ax.plot(x, 1e3 * ds.kept_levelling_fit.values[kept][order], "-", lw=1.0,
                label=f"{candidate + 1}: {1e3 * float(ds.candidate_magnitude.values[candidate]):.3g} "
                      f"+/- {2e3 * float(ds.candidate_magnitude_spread.values[candidate]):.2g} mm")
    if "free_profile_settlement" in ds:
        ax.plot(ds.free_profile_x.values, -1e3 * ds.free_profile_settlement.values, ":", color="0.4", lw=1.2,
                label="free profile (ground settlement, its own datum)")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("dy [mm] (negative down)")
    ax.set_title(f"levelling (sigma {1e3 * float(ds.attrs.get('levelling_sigma', 0.0)):.2g} mm) and the fits", fontsize=8)
    ax.legend(fontsize=7, frameon=False)


def draw_diagnosis(datasets, ax, options) -> None:
    """The plot (module docstring) of one diagnosis dataset, drawn over ``ax``'s figure."""
    if len(datasets) != 1 or datasets[0].attrs.get("masonryfw_format") != "diagnosis":
        raise mf.MasonryError("the diagnosis plot draws one diagnosis dataset (written by `masonryfw diagnose`)")
    ds = mfp.derive_geometry(datasets[0])
    figure = ax.figure
    figure.delaxes(ax)
    kept = ds.sizes.get("kept", 0)
    columns = 1 + kept
    width = float(np.ptp(ds.node_x.values))
    height = float(np.ptp(ds.node_y.values))
    panel = 3.6
    if not mfp.size_asked(figure):
        figure.set_size_inches(panel * columns, panel * height / width + 3.4)
    grid = figure.add_gridspec(2, columns, height_ratios=[max(height / width, 0.25), 0.9])
    _survey_panel(figure.add_subplot(grid[0, 0]), ds)
    for k in range(kept):
        _candidate_panel(figure.add_subplot(grid[0, 1 + k]), ds, k, options.get("amplification"))
    panels = [_score_panel]
    if (ds.candidate_profile.values.astype(str) == "gaussian").any():
        panels.append(_gaussian_panel)
    if "levelling_dy" in ds:
        panels.append(_levelling_panel)
    bottom = grid[1, :].subgridspec(1, len(panels), wspace=0.25)
    for k, draw in enumerate(panels):
        draw(figure.add_subplot(bottom[0, k]), ds)
    verdict = str(ds.attrs.get("verdict", ""))
    if int(ds.attrs.get("interrupted", 0)):
        tried = ds.sizes.get("candidate", 0) + int(ds.attrs.get("failed_candidates", 0))
        verdict = (f"PARTIAL: the search was interrupted after {tried} of {int(ds.attrs.get('scenarios_planned', 0))} "
                   f"scenarios; the ranking is of those tried\n{verdict}")
    figure.suptitle(verdict, fontsize=9, color="#b00000" if int(ds.attrs.get("interrupted", 0)) else "black")
