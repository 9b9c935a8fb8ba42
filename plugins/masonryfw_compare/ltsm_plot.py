"""The ``ltsm`` plot: the engineers' stage 2 of a result over a settlement profile.

Above, the greenfield trough under the wall with its sagging and hogging parts (a building's: its plan over the
greenfield settlement, each wall coloured by its LTSM category); below, the classic interaction chart (Burland
1995; Boscardin & Cording 1989) for every part of the wall (a building's worst wall): the deflection ratio
against the horizontal strain, the zones of the LTSM categories for that part's length over height and kind
(sagging, hogging), and the part as a point at the assessed settlement. The numbers are
:mod:`masonryfw.ground.assessment`'s.
"""
from __future__ import annotations

import json
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.patches import Rectangle

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .figure_parts import DAMAGE_COLOURS, TITLE_WIDTH, single_result, title_of

ZONE_NAMES = ("0 negligible", "1 very slight", "2 slight", "3 moderate", "4-5 severe to very severe")


def assessed_settlement(ds: xr.Dataset) -> float:
    """The settlement parameter the plot assesses: the last record's, else the model's settlement_target."""
    if "step_settlement" in ds and ds.step_settlement.size:
        return float(ds.step_settlement.values[-1])
    if "settlement_target" in ds:
        return float(ds.settlement_target.values)
    raise mf.MasonryError("the ltsm plot needs a settlement: a result with a history (fdem, jmm) or a model with "
                          "a settlement_target (a tunnel's S_max)")


def zone_boundary(limit: float, strain: np.ndarray, part: mfp.Part, height: float) -> np.ndarray:
    """The deflection ratio at which a part like ``part`` (its length, height and neutral axis) reaches the
    LTSM strain ``limit`` at the horizontal strains ``strain``: the smaller of the bending and the diagonal
    route; nan where the horizontal strain alone reaches it."""
    length = part.end - part.start
    per_bending, per_diagonal = mfp.deep_beam_strains(1.0, length, height, part.sagging)
    bending = (limit - strain) / per_bending
    nu = mfp.POISSON
    square = (limit - strain * (1 - nu) / 2) ** 2 - (strain * (1 + nu) / 2) ** 2
    diagonal = np.sqrt(np.where(square > 0, square, np.nan)) / per_diagonal
    ratio = np.fmin(bending, diagonal)
    return np.where((ratio >= 0) & (limit - strain * (1 - nu) / 2 > 0), ratio, np.nan)


def draw_ltsm(datasets: Sequence[xr.Dataset], ax, options: Mapping[str, Any]) -> None:
    """The trough under the wall and the interaction chart with the wall's parts (module docstring)."""
    ds = single_result(datasets, "ltsm")
    settlement = assessed_settlement(ds)
    stages = mfp.assess(ds, settlement)
    if stages is None and mfp.space(ds) == 3 and ds.attrs.get("settlement_profile"):
        raise mf.MasonryError("the ltsm plot needs walls to assess: a 3D drawing's blocks name none (a building "
                              "built from a [building] spec has them)")
    if stages is None:
        raise mf.MasonryError("the ltsm plot needs a model built over a settlement profile ([settlement] in its spec)")
    figure, spec = ax.figure, ax.get_subplotspec()
    ax.set_axis_off()
    rows = spec.subgridspec(2, 1, height_ratios=(1.3, 2) if "building_walls" in ds.attrs else (1, 2), hspace=0.12)
    top = figure.add_subplot(rows[0])
    if "building_walls" in ds.attrs:
        if not mfp.size_asked(figure):
            figure.set_size_inches(8.5, 8.5)  # a plan above the charts
        walls = json.loads(ds.attrs["building_walls"])
        worst = _draw_plan(top, ds, walls, stages, settlement)
        _draw_charts(figure, rows[1], replace(stages, parts=tuple(p for p in stages.parts if p.wall == worst["name"])),
                     settlement, worst["height"])
        where = f" (worst wall: {worst['name']!r})"
    else:
        x_a, x_b, height = mfp.wall_extent(ds)
        _draw_trough(top, mf.model_profile(ds), stages, settlement, x_a, x_b, height)
        _draw_charts(figure, rows[1], stages, settlement, height)
        where = ""
    width = max(30, int(TITLE_WIDTH * figure.get_size_inches()[0] / 7.0))  # the title wrapped to the page
    lines = [f"{title_of(ds)}: stage 2 (LTSM) at S_max = {1e3 * settlement:.3g} mm",
             f"LTSM strain {100 * stages.strain:.3g} %, category {ZONE_NAMES[stages.category]}{where}; stage 1: "
             f"slope 1/{1 / max(stages.slope, 1e-12):.0f}, settlement {1e3 * stages.greenfield_settlement:.3g} mm"
             f"{' (screened out)' if stages.screened_out else ''}"]
    figure.suptitle("\n".join(textwrap.fill(line, width) for line in lines), fontsize="medium")  # over every panel


def _draw_plan(ax, ds: xr.Dataset, walls: list[dict], stages, settlement: float) -> dict:
    """A building's plan over the greenfield settlement at ``settlement`` (contours), the trough's axis (and a
    tunnel's face), each wall coloured by its LTSM category and labelled with its strain and, of a run with each
    wall's cracks, a second line inside it in the colour of the wall's category in the run; returns the worst
    wall (by the LTSM)."""
    ground = mfp.ground_in_plan(ds)
    ends = np.array([[w["start"], w["end"]] for w in walls]).reshape(-1, 2)
    low, high = ends.min(axis=0), ends.max(axis=0)
    margin = 0.35 * float((high - low).max()) + 0.5
    x, y = np.meshgrid(np.linspace(low[0] - margin, high[0] + margin, 160),
                       np.linspace(low[1] - margin, high[1] + margin, 160))
    rate, _ = ground.greenfield(np.c_[x.ravel(), y.ravel()])
    shown = ax.contourf(x, y, 1e3 * settlement * rate.reshape(x.shape), levels=12, cmap="Blues", alpha=0.55)
    ax.figure.colorbar(shown, ax=ax, label="greenfield settlement [mm]", shrink=0.9, pad=0.02)
    if ground.profile.kind in ("gaussian", "tunnel"):
        reach = np.array([-1.0, 1.0])[:, None] * 3 * margin * ground.axis + ground.point
        ax.plot(*reach.T, color="0.3", lw=1.0, ls="--", label="trough axis" if ground.profile.kind == "gaussian"
                else "tunnel axis")
        if ground.face is not None:  # the face across the tunnel (its diameter wide), an arrow the way it goes
            face = ground.point + ground.face * ground.axis
            half = 0.5 * (ground.profile.diameter or 0.2 * margin) * ground.across
            ax.plot(*np.array([face - half, face + half]).T, color="0.1", lw=3,
                    label=f"tunnel face, {ground.face:.3g} m along the axis")
            ax.annotate("", xy=face + 0.25 * margin * ground.axis, xytext=face,
                        arrowprops={"arrowstyle": "->", "color": "0.1", "lw": 1.5})
    strain = {w["name"]: max((settlement * p.strain for p in stages.parts if p.wall == w["name"]), default=0.0)
              for w in walls}
    centre = ends.mean(axis=0)
    stage_3 = stage_3_categories(ds)
    inset = 0.05 * float((high - low).max())
    for w, wall in enumerate(walls):
        category = int(mfp.ltsm_category(strain[wall["name"]]))
        line = np.array([wall["start"], wall["end"]])
        ax.plot(*line.T, color=DAMAGE_COLOURS[category], lw=6, solid_capstyle="butt")
        along = (line[1] - line[0]) / np.linalg.norm(line[1] - line[0])
        outward = np.array([-along[1], along[0]])
        outward *= np.sign(outward @ (line.mean(axis=0) - centre)) or 1.0
        angle = np.degrees(np.arctan2(along[1], along[0]))
        angle = (angle + 90.0) % 180.0 - 90.0  # upright text
        label = f"{wall['name']}: {100 * strain[wall['name']]:.3g} %, cat. {category}"
        if stage_3 is not None:  # beside it, inside the building: the wall's own category in the run
            inner = line - inset * outward + inset * np.array([along, -along])
            ax.plot(*inner.T, color=DAMAGE_COLOURS[int(stage_3[w])], lw=6, solid_capstyle="butt")
            label += f"; {ds.attrs.get('solver', 'run')}: cat. {int(stage_3[w])}"
        ax.annotate(label, line.mean(axis=0) + 0.25 * margin * outward, fontsize="small", ha="center", va="center",
                    rotation=angle, bbox={"boxstyle": "round,pad=0.2", "fc": "white", "alpha": 0.8, "lw": 0})
    if stage_3 is not None:
        ax.plot([], [], color="0.5", lw=6, label="each wall: stage 2 (LTSM) on its line,\nstage 3 "
                                                 f"({ds.attrs.get('solver', 'run')}) inside it")
    ax.set_aspect("equal")
    ax.set_xlim(x.min(), x.max())
    ax.set_ylim(y.min(), y.max())
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(loc="upper left", bbox_to_anchor=(1.25, 1.0), fontsize="small", frameon=False)
    return max(walls, key=lambda w: strain[w["name"]])


def stage_3_categories(ds: xr.Dataset) -> np.ndarray | None:
    """Each wall's largest damage category over the run (``step_wall_damage_category``), None without them."""
    if "step_wall_damage_category" not in ds or not ds.step_settlement.size:
        return None
    return np.asarray(ds.step_wall_damage_category.values).max(axis=0)


def _draw_trough(ax, profile, stages, settlement: float, x_a: float, x_b: float, height: float) -> None:
    """The greenfield settlement below the wall, drawn as a box, its parts shaded by kind; a trough's axis (a
    tunnel's) marked, the view widened to it where it is off the wall."""
    margin = 0.5 * (x_b - x_a)
    low, high = x_a - margin, x_b + margin
    axis = profile.center if profile.kind in ("gaussian", "tunnel") else None
    if axis is not None:
        low, high = min(low, axis - 0.25 * margin), max(high, axis + 0.25 * margin)
    x = np.linspace(low, high, 600)
    ax.plot(x, -1e3 * settlement * profile.rate(x), color="0.2", lw=1.4, label="greenfield settlement")
    if axis is not None:
        ax.axvline(axis, color="0.35", lw=1.0, ls="--")
        ax.annotate(f"{'tunnel' if profile.kind == 'tunnel' else 'trough'} axis, x = {axis:.3g} m", (axis, 0.0),
                    xytext=(-4, -4), textcoords="offset points", ha="right", va="top", fontsize="small",
                    color="0.25")
    depth = 1e3 * settlement
    for part in stages.parts:
        colour = "#4575b4" if part.sagging else "#d73027"
        ax.add_patch(Rectangle((part.start, 0.15 * depth), part.end - part.start, 0.5 * depth, facecolor=colour,
                               alpha=0.35, edgecolor=colour))
        ax.text(0.5 * (part.start + part.end), 0.4 * depth, "sagging" if part.sagging else "hogging", ha="center",
                va="center", fontsize="small")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlim(low, high)
    ax.set_ylim(-1.15 * depth, 0.8 * depth)
    ax.set_ylabel("settlement [mm]")
    ax.set_xlabel(f"x [m]; the wall from {x_a:.3g} to {x_b:.3g} m, {height:.3g} m high (boxes: its parts)")
    ax.grid(alpha=0.3)


def _draw_charts(figure, spec, stages, settlement: float, height: float) -> None:
    """One interaction chart per part of the wall, each with the zones of its own length over height and kind
    (a sagging part's zones are not a hogging one's), side by side; the zones' legend beside the last."""
    parts = list(stages.parts)
    grid = spec.subgridspec(1, len(parts), wspace=0.3)
    axes = [figure.add_subplot(grid[0, k]) for k in range(len(parts))]
    for ax, part in zip(axes, parts):
        _draw_chart(ax, part, stages.category, settlement, height)
    axes[0].set_ylabel("deflection ratio [%]")
    axes[-1].legend(*axes[-1].get_legend_handles_labels(), loc="upper left", bbox_to_anchor=(1.02, 1.0),
                    fontsize="small", title="LTSM category", title_fontsize="small", frameon=False)


def _draw_chart(ax, part, worst: int, settlement: float, height: float) -> None:
    """Deflection ratio against horizontal strain [%] for ``part``: its zones up to one category above the worst
    part's (so the point is not lost in the corner of a chart of every zone), the part as a point."""
    x, y = 100 * settlement * part.horizontal_strain, 100 * settlement * part.deflection_ratio
    shown = min(worst, len(mfp.LTSM_LIMITS) - 1)  # the limit above the worst category (the last: itself)
    top_strain = max(1.15 * 100 * mfp.LTSM_LIMITS[shown], 1.3 * x)
    low_strain = min(0.0, 1.3 * x)
    strain = np.linspace(low_strain, top_strain, 600)
    boundaries = [100 * zone_boundary(limit, strain / 100, part, height) for limit in mfp.LTSM_LIMITS]
    ceiling = max(1.15 * float(np.nanmax(boundaries[shown])), 1.3 * y)
    lower = np.zeros_like(strain)
    for category, upper in enumerate([*boundaries, np.full_like(strain, ceiling)]):
        upper = np.where(np.isnan(upper), 0.0, np.minimum(upper, ceiling))
        ax.fill_between(strain, lower, np.maximum(upper, lower), color=DAMAGE_COLOURS[category], alpha=0.35, lw=0,
                        label=ZONE_NAMES[category])
        lower = np.maximum(upper, lower)
    kind = "sagging" if part.sagging else "hogging"
    ax.plot(x, y, "o" if part.sagging else "s", ms=8, color="k", mfc="#4575b4" if part.sagging else "#d73027")
    ax.set_title(f"{part.wall + ': ' if part.wall else ''}{kind} {part.start:.3g}..{part.end:.3g} m, "
                 f"L/H {(part.end - part.start) / height:.2g}:\n"
                 f"strain {100 * settlement * part.strain:.3g} %", fontsize="small")
    ax.set_xlim(low_strain, top_strain)
    ax.set_ylim(0.0, ceiling)
    ax.set_xlabel("horizontal strain [%]\n(tension positive)")
    ax.grid(alpha=0.3)
