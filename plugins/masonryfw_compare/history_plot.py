"""The ``history`` plot kind: settlement reaction (or damage) against settlement, of results and sweeps
together, with its table (the CSV of ``plot --table``)."""
from __future__ import annotations

import itertools
from collections import Counter
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.patches import Patch

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .figure_parts import DAMAGE_COLOURS, require_variables, title_of

STRIP_SHARE = 0.035  # of the axes' height: one damage strip


def distinct_labels(datasets: Sequence[xr.Dataset]) -> list[str]:
    """Each result's label (:func:`masonryfw.result_label`); results that share one get the solver options
    in which they differ, e.g. ``fdem (mode=deformable)``, else their titles, else their file names, else
    their place in the list: no two results share a label."""
    labels = [mf.result_label(ds) for ds in datasets]
    details = [
        lambda ds: mfp.result_options(ds),
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
    names = {v: k.replace("_", " ") for k, v in mfp.flags("step_damage_category").items()}
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
    moving = mfp.ROLE["moving_support"]
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
    models = [ds for ds in datasets if "block_role" in ds]  # a sweep has no blocks to say what moves them
    word = mf.load_word(models[0]) if models else "settlement"
    ax.set_xlabel(f"{'spread of the supports' if word == 'spread' else word} [mm]")
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
            handles += _mark_collapse(ax, ds, label, colour, word)
            if first > 0 and not log:  # the reactions of the gravity stage, at zero settlement
                low, high = float(r[:first + 1].min()), float(r[:first + 1].max())
                handles.append(ax.vlines(0.0, low, high, color=colour, lw=4, alpha=0.35,
                                         label=f"{label}: gravity stage, {first + 1} records, "
                                               f"{mfp.force_text(low)}..{mfp.force_text(high)}"))
        handles += _draw_sweeps(ax, sweeps, len(incremental))
        references = [*incremental, *limits]
        r0 = mf.dead_reaction(references[0]) if references else 0.0
        if r0 > 0:
            handles.append(ax.axhline(r0, ls="--", lw=0.9, color="0.35", label=f"dead reaction R0 = {mfp.force_text(r0)}"))
        for ds, style in zip(limits, (":", "-.", (0, (1, 3)), (0, (5, 2)))):
            collapse = (1 - float(ds.collapse_multiplier.values)) * mf.dead_reaction(ds)
            handles.append(ax.axhline(collapse, ls=style, lw=1.2, color="k",
                                      label=f"{mf.result_label(ds)}: (1 - alpha) R0 = {mfp.force_text(collapse)}"))
        strips, rows = _damage_strips(ax, incremental)
        unit = _force_axis(ax, r0)
        ax.set_ylabel(f"thrust on the moving support [{unit}]" if word == "spread" else
                      f"settlement reaction [{unit}]" if _profiled(references) else
                      f"reaction on the moving support [{unit}]")
        ax.set_ylim(bottom=min(0.0, ax.get_ylim()[0]))
        ax.legend(handles=handles + strips, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2,
                  fontsize="small", frameon=False)
    if options["settlement_max"] is not None:
        ax.set_xlim(right=options["settlement_max"], left=None if log else -0.02 * options["settlement_max"])
    if options["quantity"] == "reaction":
        if options["settlement_max"] is not None:
            _fit_y_to_shown(ax, [(1e3 * ds.step_settlement.values, ds.step_reaction.values) for ds in incremental])
        _room_for_strips(ax, rows)
    _volume_loss_axis(ax, incremental)
    if len(incremental) == 1 and not limits and not sweeps:
        ax.set_title(f"{title_of(incremental[0])}\n{mf.headline_text(incremental[0])}", fontsize="medium")
    else:
        ax.set_title(str(datasets[0].attrs.get("title", "")), fontsize="medium")


def _volume_loss_axis(ax, results: Sequence[xr.Dataset]) -> None:
    """Over one tunnel's trough, a second settlement axis along the top in volume loss (S_max is proportional to
    V_L: ``mfp.volume_loss_per_settlement``)."""
    rates = {mfp.volume_loss_per_settlement(ds) for ds in results}
    if len(rates) != 1 or None in rates:
        return
    per_mm = rates.pop() / 1e3
    top = ax.secondary_xaxis("top", functions=(lambda mm: mm * per_mm, lambda loss: loss / per_mm))
    top.set_xlabel("tunnel volume loss V_L [%]", fontsize="small")
    top.tick_params(labelsize="small")


def _mark_collapse(ax, ds: xr.Dataset, label: str, colour: str, word: str) -> list:
    """The collapse of a run that collapsed (:func:`masonryfw.key_numbers`' ``settlement_capacity``: la-incremental's
    own, or where fdem's masonry broke away) as a cross on its curve, said in the legend."""
    numbers = {n.name: n.value for n in mf.key_numbers(ds)}
    if "settlement_capacity" not in numbers:
        return []
    at, reaction = 1e3 * numbers["settlement_capacity"], numbers.get("capacity_reaction", float("nan"))
    return ax.plot([at], [reaction], ls="none", marker="X", ms=9, color=colour, markeredgecolor="k", zorder=5,
                   label=f"{label}: collapses at a {word} of {at:.3g} mm")


def _force_axis(ax, reference: float) -> str:
    """The force axis in kN where the forces are kN-sized (R0, else the largest drawn, from 1 kN), else N; the
    unit its label gives. The curves keep newtons: only the ticks are written in kN."""
    from matplotlib.ticker import FuncFormatter

    largest = max(abs(reference), *(abs(v) for v in ax.get_ylim()))
    if largest < 1000:
        return "N"
    ax.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value / 1000:g}"))
    return "kN"


def _fit_y_to_shown(ax, curves: Sequence[tuple[np.ndarray, np.ndarray]]) -> None:
    """Rescale y to the curves' points inside the x range (after a zoom on the settlement)."""
    low, high = ax.get_xlim()
    ys = [y[(x >= low) & (x <= high)] for x, y in curves]
    ys = [y for y in ys if y.size]
    if ys:
        ax.set_ylim(min(0.0, min(float(np.min(y)) for y in ys)), 1.05 * max(float(np.max(y)) for y in ys))


#: Line styles of a building's walls in the damage history (the building's widest crack is the solid line).
WALL_STYLES = ("--", ":", "-.", (0, (5, 1, 1, 1, 1, 1)), (0, (1, 3)))


def _draw_damage(ax, incremental, labels, colours) -> None:
    """The widest crack of every result against the settlement on one crack-width axis whose damage
    categories are bands (their limits from ``mf.DAMAGE_LIMITS``, named at the right): the category a curve
    is in is the band it crosses, with no second axis to misread. Linear up to 0.1 mm (category 0, where a
    crack may be 0), logarithmic above. One building's result: each wall's widest crack too."""
    for ds in incremental:
        require_variables(ds, ["step_damage_category", "step_crack_width_max"], "history --option quantity=damage",
                 "a result with crack widths (fdem or jmm)")
    names = {v: k.replace("_", " ") for k, v in mfp.flags("step_damage_category").items()}
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
        if len(incremental) == 1 and "step_wall_crack_width_max" in ds:  # a building's: each wall's widest crack
            for w, (name, style) in enumerate(zip(ds.wall_name.values, itertools.cycle(WALL_STYLES))):
                ax.plot(s, 1e3 * ds.step_wall_crack_width_max.values[:, w], color=colour, lw=0.9, ls=style,
                        alpha=0.8, label=f"wall {name}")
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


