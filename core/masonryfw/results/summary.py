"""Headline numbers and agreement scores as short tables: what ``compare`` prints and reports show.

One place turns :func:`masonryfw.key_numbers` and comparison datasets into rows of
text, so the command line, a report and a test read the same numbers the same way.
A row is ``(label, cells, note)``: one cell per result (or per pair of results),
``-`` where a result has no such number, and a note saying what the row means.
"""
from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..format.model3d import interface_points, space
from ..format.roles import masonry_blocks, moving_blocks
from ..format.schema import flags
from ..geometry.polygons import block_bounds
from ..ground.assessment import assess, assess_walls
from .damage import standing_text
from .semantics import CRACK_THRESHOLD, at_threshold, dead_reaction, model_scales

if TYPE_CHECKING:  # annotations only
    import xarray as xr

#: The reaction history is at its plateau from the first settlement after which it stays within
#: this share of the dead reaction of its final value.
PLATEAU_SHARE = 0.01
#: A history whose settlement records have a median unbalanced force ratio above this is dynamic, not
#: quasi-static (the gable house's fdem run at the default loading rate: 0.18, its reaction swinging 92..146 kN;
#: at a fifth of the rate 0.021 and 128..138 kN; Test 12C 0.0017; docs/fdem.md).
QUASI_STATIC_RATIO = 0.05
MISSING = "-"
#: Scores a comparison table shows first, in this order; then any other scalar score of the comparator ...
SHOWN_SCORES = ("crack_f1", "crack_jaccard", "crack_overlap", "crack_spearman", "macro_block_ari",
                "mechanism_cosine", "locus_distance")
#: ... but for these details, in the comparison dataset and its JSON (the counts make one row of their own).
DETAIL_SCORES = ("length_scale", "collapse_multiplier_a", "collapse_multiplier_b", "crack_count_a", "crack_count_b",
                 "crack_count_both", "crack_precision", "crack_recall", "locus_distance_a_to_b",
                 "locus_distance_b_to_a")


# ---------------------------------------------------------------- the numbers a user came for

@dataclass(frozen=True)
class KeyNumber:
    """One headline number of a result, with its unit and what it is."""

    name: str
    value: float
    units: str
    long_name: str

    def __str__(self) -> str:
        unit = f" {self.units}" if self.units not in ("", "1") else ""
        return f"{self.name} = {self.value:.6g}{unit}"


def plateau_start(settlement: np.ndarray, reaction: np.ndarray, band: float) -> int:
    """Index of the first record after which the reaction stays within ``band`` of its final value."""
    outside = np.flatnonzero(np.abs(reaction - reaction[-1]) > band)
    return int(outside[-1] + 1) if outside.size else 0


def load_word(result: xr.Dataset) -> str:
    """What moves the masonry, in a word: ``settlement`` (supports moving down), ``spread`` (moving sideways: an
    arch's springings moving apart) or ``tilt`` (no moving support: a live load on the masonry, a tilting
    table)."""
    moving = moving_blocks(result.block_role.values)
    if not moving.any():
        return "tilt"
    direction = np.asarray(result.settlement_direction.values, dtype=float)[moving]
    vertical = np.abs(direction[:, 2 if direction.shape[1] == 6 else 1])
    horizontal = np.hypot(direction[:, 0], direction[:, 1]) if direction.shape[1] == 6 else np.abs(direction[:, 0])
    return "spread" if horizontal.sum() > vertical.sum() else "settlement"


def collapse_record(result: xr.Dataset) -> int | None:
    """The record of a history at which its masonry began to collapse, or None when it did not (and for a
    history that says its own collapse: la-incremental's ``settlement_capacity``). It collapsed when its widest
    crack came to be wider than the ground has moved by more than a unit (the square root of the median block
    area): a block fallen away from the rest; it began to where that crack started to open faster than the
    ground moves, for good (a mechanism the ground drives opens no faster than it: an arch on spreading
    supports, 0.33 mm a mm until 108 mm, then 1.1, 3, 10, 31 mm a mm; la-incremental: collapse at 108.3 mm)."""
    if "settlement_capacity" in result or not {"step_crack_width_max", "step_settlement"} <= set(result.variables) \
            or int(result.attrs.get("masonryfw_space", 2)) == 3:
        return None
    moving = moving_blocks(result.block_role.values)
    direction = np.asarray(result.settlement_direction.values, dtype=float)[moving]
    rate = float(np.hypot(direction[:, 0], direction[:, 1]).max(initial=0.0))
    ground = np.asarray(result.step_settlement.values, dtype=float) * rate
    width = np.asarray(result.step_crack_width_max.values, dtype=float)
    over = np.flatnonzero(width - ground > model_scales(result).block)
    if not over.size:
        return None
    fell = int(over[0])
    keeping_up = np.flatnonzero(np.diff(width[:fell + 1]) <= np.diff(ground[:fell + 1]))  # intervals
    return int(keeping_up[-1]) + 1 if keeping_up.size else 0


def _collapse_numbers(result: xr.Dataset, fell: int) -> list[KeyNumber]:
    """The settlement at collapse from a history (:func:`collapse_record`): the record where the masonry began to
    fall away, its reaction, and where it broke away (the widest crack of that record)."""
    numbers = [KeyNumber("settlement_capacity", float(result.step_settlement.values[fell]), "m",
                         "settlement at collapse: where the widest crack began to open faster than the ground "
                         "moves, for good, until a block fell away")]
    if "step_reaction" in result:
        numbers.append(KeyNumber("capacity_reaction", float(result.step_reaction.values[fell]), "N",
                                 "settlement reaction where the collapse began"))
    interface = int(result.step_crack_interface.values[fell]) if "step_crack_interface" in result else -1
    if interface >= 0:
        numbers += [KeyNumber("collapse_x", float(result.interface_x.values[interface].mean()), "m",
                              "where the masonry broke away: x of the joint that opened"),
                    KeyNumber("collapse_y", float(result.interface_y.values[interface].mean()), "m",
                              "where the masonry broke away: y of the joint that opened")]
    return numbers


def _history_numbers(result: xr.Dataset) -> list[KeyNumber]:
    settlement = np.asarray(result.step_settlement.values, dtype=float)
    reaction = np.asarray(result.step_reaction.values, dtype=float)
    if settlement.size == 0:
        return []
    loaded = np.flatnonzero(settlement <= 0)
    first = int(loaded[-1]) if loaded.size else 0
    r0 = float(reaction[first])
    numbers = [KeyNumber("dead_reaction", r0, "N", "settlement reaction before the supports settle (R0)")]
    s, r = settlement[first:], reaction[first:]
    if s.size < 2:
        return numbers
    low = int(np.argmin(r))
    start = plateau_start(s, r, PLATEAU_SHARE * abs(r0))
    return numbers + [
        KeyNumber("minimum_reaction", float(r[low]), "N", "smallest settlement reaction"),
        KeyNumber("minimum_reaction_settlement", float(s[low]), "m", "settlement at the smallest reaction"),
        KeyNumber("plateau_reaction", float(r[start:].mean()), "N",
                  f"mean settlement reaction from the plateau on (within {PLATEAU_SHARE:.0%} of R0 of the final value)"),
        KeyNumber("plateau_settlement", float(s[start]), "m", "settlement where the plateau starts"),
        KeyNumber("final_settlement", float(s[-1]), "m", "settlement of the last record"),
    ]


def joint_midpoint(model: xr.Dataset, interface: int) -> np.ndarray:
    """The midpoint of an interface: its two ends' mean in 2D (x, y), its polygon's vertices' mean in 3D
    (x, y, z)."""
    if space(model) == 3:
        first = int(model.interface_node_count.values[:interface].sum())
        return interface_points(model)[first:first + int(model.interface_node_count.values[interface])].mean(axis=0)
    return np.array([model.interface_x.values[interface].mean(), model.interface_y.values[interface].mean()])


@dataclass(frozen=True)
class CrackPlace:
    """Where a joint of a building is: its wall (index and name), course and place along the wall."""

    wall: int
    name: str
    course: int  # 0 the bottom course; a bed joint is under the course it names
    along: float  # the midpoint's distance along the wall's base line from its start [m]


def crack_place(model: xr.Dataset, interface: int, wall: int | None = None) -> CrackPlace | None:
    """Where ``interface`` of a building is in ``wall`` (by default the wall of its side-0 block): the course
    whose bed levels its midpoint lies at or above, and its distance along the base line; None for a model
    without walls or a joint of no wall."""
    if "block_wall" not in model:
        return None
    sides = model.block_wall.values[model.interface_blocks.values[interface]]
    wall = int(sides[0]) if wall is None else wall
    if wall < 0 or wall not in sides:
        return None
    spec = json.loads(model.attrs["building_walls"])[wall]
    start, end = np.array(spec["start"]), np.array(spec["end"])
    mid = joint_midpoint(model, interface)
    laid = (model.block_wall.values == wall) & masonry_blocks(model.block_role.values)
    _, _, bottom, _ = block_bounds(model.node_x.values, model.node_z.values, model.block_node_count.values)
    bottoms = np.unique(np.round(bottom[laid], 9))
    course = max(int(np.searchsorted(bottoms, round(float(mid[2]), 9), side="right")) - 1, 0)
    along = float((mid[:2] - start) @ (end - start) / np.linalg.norm(end - start))
    return CrackPlace(wall, spec["name"], course, along)


def _crack_numbers(result: xr.Dataset) -> list[KeyNumber]:
    """The widest crack over the run, where and when it is, the damage category it gives; the last
    record's crack and category; the widest base gap."""
    width = np.asarray(result.step_crack_width_max.values, dtype=float)
    if width.size == 0:
        return []
    widest = int(np.argmax(width))
    numbers = [KeyNumber("crack_width", float(width[widest]), "m", "widest crack in the masonry over the run")]
    if "step_settlement" in result:
        numbers.append(KeyNumber("crack_settlement", float(result.step_settlement.values[widest]), "m",
                                 "settlement at the record of the widest crack"))
    interface = int(result.step_crack_interface.values[widest]) if "step_crack_interface" in result else -1
    if interface >= 0:
        numbers.append(KeyNumber("crack_interface", float(interface), "1", "the joint of the widest crack"))
        numbers += [KeyNumber(f"crack_{axis}", float(value), "m", f"{axis} of that joint's midpoint")
                    for axis, value in zip("xyz", joint_midpoint(result, interface))]
        place = crack_place(result, interface, int(np.argmax(result.step_wall_crack_width_max.values[widest]))
                            if "step_wall_crack_width_max" in result else None)
        if place is not None:
            numbers += [KeyNumber("crack_wall", float(place.wall), "1",
                                  f"the wall of the widest crack (its index in building_walls: {place.name!r})"),
                        KeyNumber("crack_course", float(place.course), "1",
                                  "the course of that joint in its wall (0 the bottom course)"),
                        KeyNumber("crack_along", place.along, "m", "where that joint's midpoint is along the wall's "
                                                                   "base line, from its start")]
    if "step_damage_category" in result:
        category = np.asarray(result.step_damage_category.values)
        numbers += [
            KeyNumber("damage_category", float(category.max()), "1",
                      "largest damage category over the run (0 negligible .. 5 very severe)"),
            KeyNumber("damage_category_final", float(category[-1]), "1", "damage category at the last record"),
        ]
    numbers.append(KeyNumber("crack_width_final", float(width[-1]), "m", "widest crack at the last record"))
    if "step_base_gap_max" in result and result.step_base_gap_max.size:
        numbers.append(KeyNumber("base_gap", float(np.max(result.step_base_gap_max.values)), "m",
                                 "widest gap between the wall and the ground over the run (not a crack in the masonry)"))
    return numbers


def assessed_settlement(result: xr.Dataset) -> float | None:
    """The settlement parameter stages 1 and 2 are assessed at: the last record's, or the model's
    ``settlement_target`` for a result without a history (limit analysis); None without either."""
    if "step_settlement" in result and result.step_settlement.size:
        return float(result.step_settlement.values[-1])
    if "settlement_target" in result:
        return float(result.settlement_target.values)
    return None


def _assessment_numbers(result: xr.Dataset) -> list[KeyNumber]:
    """The engineers' stages 1 and 2 (:mod:`masonryfw.ground.assessment`) at the :func:`assessed_settlement`."""
    settlement = assessed_settlement(result)
    if settlement is None:
        return []
    stages = assess(result, settlement)
    if stages is None:
        return []
    return [
        KeyNumber("assessed_settlement", settlement, "m", "settlement parameter of the stage 1 and 2 assessment"),
        KeyNumber("greenfield_slope", stages.slope, "1", "stage 1: largest greenfield slope under the wall"),
        KeyNumber("greenfield_settlement", stages.greenfield_settlement, "m",
                  "stage 1: largest greenfield settlement under the wall"),
        KeyNumber("screened_out", float(stages.screened_out), "1",
                  "stage 1: 1 if the slope stays under 1/500 and the settlement under 10 mm (negligible risk)"),
        KeyNumber("ltsm_strain", stages.strain, "1", "stage 2: the limiting tensile strain method's governing strain"
                  + governing_wall(stages)),
        KeyNumber("ltsm_category", float(stages.category), "1",
                  "stage 2: LTSM damage category (0 negligible .. 4 severe to very severe)"),
    ]


def governing_wall(stages) -> str:
    """`` (wall 'east')`` when the governing LTSM part belongs to a named wall of a building, else nothing."""
    governing = max(stages.parts, key=lambda part: part.strain, default=None)
    return f" (wall {governing.wall!r})" if governing is not None and governing.wall else ""


def key_numbers(result: xr.Dataset) -> list[KeyNumber]:
    """The numbers a user came for, whatever the solver.

    Limit analysis: alpha, the dead reaction R0 and the settlement reaction at collapse (the solver's
    ``moving_support_reaction``, else ``(1 - alpha) R0``). Incremental solvers: the dead reaction, the
    smallest and the plateau settlement reaction with their settlements; the widest crack over the run
    with its joint, place and settlement, the largest damage category, and the last record's
    (:mod:`masonryfw.results.damage`). Both: the number of masonry macro-blocks when the result has them. R0 and
    the reactions are settlement reactions (:func:`settlement_reaction`), one definition for every solver.
    """
    numbers: list[KeyNumber] = []
    if "collapse_multiplier" in result:
        alpha = float(result.collapse_multiplier.values)
        numbers.append(KeyNumber("alpha", alpha, "1", "collapse multiplier"))
        r0 = dead_reaction(result)
        if r0 > 0:
            numbers.append(KeyNumber("dead_reaction", r0, "N",
                                     "settlement reaction of the dead loads W L_s / L_total on the moving supports (R0)"))
        if "moving_support_reaction" in result:
            numbers.append(KeyNumber("collapse_reaction", float(result.moving_support_reaction.values), "N",
                                     "settlement reaction at collapse"))
        elif r0 > 0:
            numbers.append(KeyNumber("collapse_reaction", (1.0 - alpha) * r0, "N",
                                     "settlement reaction at collapse, (1 - alpha) R0"))
    fell = collapse_record(result)
    history = result if fell is None else result.isel(step=slice(0, fell + 1))  # the records to the collapse
    if "step_reaction" in result and "step_settlement" in result:
        numbers += _history_numbers(history)
    if fell is not None:
        numbers += _collapse_numbers(result, fell)
    for name, unit, what in (("settlement_capacity", "m", "settlement at collapse (the last moved configuration "
                                                          "that carries its dead load)"),
                             ("capacity_reaction", "N", "settlement reaction of the configuration at collapse"),
                             ("displacement_capacity", "m", "largest block translation where the live load's "
                                                            "multiplier of the moved configuration falls to zero")):
        if name in result:
            numbers.append(KeyNumber(name, float(result[name].values), unit, what))
    if "step_crack_width_max" in result:
        numbers += _crack_numbers(history)
    for name, what in (("deflection_ratio", "deflection ratio of the imposed profile at the last record "
                                              "(sagging positive, Burland & Wroth 1974)"),
                       ("angular_distortion", "angular distortion of the imposed profile at the last record [rad]")):
        if f"step_{name}" in result and result[f"step_{name}"].size:
            numbers.append(KeyNumber(name, float(result[f"step_{name}"].values[-1]), "1" if "ratio" in name else "rad",
                                     what))
    numbers += _assessment_numbers(result)
    if "unbalanced_ratio" in result.attrs:
        numbers += [KeyNumber("unbalanced_ratio", float(result.attrs["unbalanced_ratio"]), "1",
                              "median unbalanced force ratio of the settlement records (quasi-static under "
                              f"{QUASI_STATIC_RATIO:g})"),
                    KeyNumber("kinetic_energy_ratio", float(result.attrs.get("kinetic_energy_ratio", np.nan)), "1",
                              "median kinetic over stored elastic energy of the settlement records")]
    derived = at_threshold(result)
    if "crack_indicator" in derived:
        numbers.append(KeyNumber("cracked_joints", float(np.count_nonzero(derived.crack_indicator.values)), "1",
                                 f"joints moving more than {CRACK_THRESHOLD:g} of the largest joint motion"))
    if "macro_block" in derived:
        masonry = masonry_blocks(derived.block_role.values)
        count = np.unique(derived.macro_block.values[masonry]).size
        numbers.append(KeyNumber("macro_blocks", float(count), "1", "macro-blocks of the masonry"))
    return numbers


# ---------------------------------------------------------------- rows of text

@dataclass(frozen=True)
class Row:
    """A table row: a label, one text cell per column, what the row means, and the raw values (None = missing)."""

    label: str
    cells: tuple[str, ...]
    note: str
    values: tuple[float | None, ...]


def _mm(metres: float) -> str:
    return f"{1e3 * metres:.3g} mm"


def force_text(newtons: float) -> str:
    """A force as an engineer writes it: ``133.9 kN`` from a thousand newtons up, else ``985.2 N``."""
    return f"{newtons / 1000:.4g} kN" if abs(newtons) >= 1000 else f"{newtons:.4g} N"


def _crack_text(numbers: dict) -> str:
    """``0.272 mm (joint 41 at x 3.1 m, y 0.125 m; S = 15 mm)``: the widest crack, where and when."""
    where = []
    if "crack_interface" in numbers:
        where.append(f"joint {int(numbers['crack_interface'])} at x {_place(numbers['crack_x'])} m, "
                     f"y {_place(numbers['crack_y'])} m")
    if "crack_settlement" in numbers:
        where.append(f"settlement {_mm(numbers['crack_settlement'])}")
    return _mm(numbers["crack_width"]) + (f" ({'; '.join(where)})" if where else "")


def _stage_1(numbers: dict) -> str:
    verdict = "screened out" if numbers["screened_out"] else "to assess"
    return (f"slope {_slope(numbers['greenfield_slope'])}, settlement {_mm(numbers['greenfield_settlement'])}: "
            f"{verdict}")


def _stage_2(numbers: dict) -> str:
    names = {value: name.replace("_", " ") for name, value in flags("step_ltsm_category").items()}
    return f"{int(numbers['ltsm_category'])} {names[int(numbers['ltsm_category'])]}, strain {100 * numbers['ltsm_strain']:.3g} %"


def stages_text(result: xr.Dataset) -> str:
    """The engineers' three stages side by side in one line (empty for a result without a profile): the
    greenfield screen, the LTSM, and the model's own answer (its damage category and widest crack, or alpha and
    the collapse reaction)."""
    numbers = {n.name: n.value for n in key_numbers(result)}
    if "ltsm_category" not in numbers:
        return ""
    if "damage_category" in numbers:
        own = f"{_damage_name(numbers['damage_category'])}, widest crack {_crack_text(numbers)}"
    else:
        own = f"alpha {numbers['alpha']:.4f}, collapse reaction {force_text(numbers.get('collapse_reaction', float('nan')))}"
    return (f"at S = {_mm(numbers['assessed_settlement'])}{_short_of_target(result)}: stage 1 {_stage_1(numbers)}; "
            f"stage 2 (LTSM) {_stage_2(numbers)}; stage 3 ({result_label(result)}) {own}")


def wall_rows(result: xr.Dataset) -> list[Row]:
    """A building's walls, one row each: stage 1 and stage 2 at the :func:`assessed_settlement`
    (:func:`masonryfw.ground.assessment.assess_walls`) and, of a history with each wall's cracks, stage 3: the
    wall's largest damage category over the run and its widest crack (course, place along the wall, settlement);
    empty for a model that is no building."""
    settlement = assessed_settlement(result)
    walls = assess_walls(result, settlement) if settlement is not None else {}
    if not walls:
        return []
    rows = []
    for w, (name, stages) in enumerate(walls.items()):
        stage_1 = {"greenfield_slope": stages.slope, "greenfield_settlement": stages.greenfield_settlement,
                   "screened_out": stages.screened_out}
        cells = [_stage_1(stage_1), _stage_2({"ltsm_category": stages.category, "ltsm_strain": stages.strain})]
        values: list[float | None] = [float(stages.screened_out), float(stages.category)]
        if "step_wall_crack_width_max" in result:
            width = np.asarray(result.step_wall_crack_width_max.values[:, w], dtype=float)
            k = int(np.argmax(width))
            category = int(result.step_wall_damage_category.values[k, w])
            joint = int(result.step_wall_crack_interface.values[k, w])
            place = crack_place(result, joint, w) if joint >= 0 else None
            where = f" (course {place.course}, {_place(place.along)} m along" if place else " ("
            cells.append(f"{_damage_name(category)}: {_mm(float(width[k]))}{where}; settlement "
                         f"{_mm(float(result.step_settlement.values[k]))})")
            values += [float(category), float(width[k])]
        rows.append(Row(name, tuple(cells), "", tuple(values)))
    return rows


def walls_text(result: xr.Dataset) -> str:
    """:func:`wall_rows` as a table under the stages' heads, the worst wall of stage 3 named last (empty for a
    model that is no building)."""
    rows = wall_rows(result)
    if not rows:
        return ""
    header = ["wall", "stage 1: greenfield", "stage 2: LTSM"]
    if len(rows[0].cells) > 2:
        header.append(f"stage 3: {result_label(result)}, widest crack over the run")
    lines = [f"wall by wall at S = {_mm(assessed_settlement(result) or 0.0)}:", text_table(header, rows, note=False)]
    if len(rows[0].cells) > 2:
        worst = max(rows, key=lambda row: (row.values[2], row.values[3]))
        lines.append(f"worst wall: {worst.label} ({_damage_name(worst.values[2] or 0)})")
    return "\n".join(lines)


def _short_of_target(result: xr.Dataset) -> str:
    """``, reached, short of the model's 15 mm (step limit)`` for a run that stopped before the model's
    ``settlement_target`` (a tunnel's S_max): its stages are at the settlement reached, not at the target."""
    reached = short_of_target(result)
    if reached is None:
        return ""
    target = float(result.settlement_target.values)
    return f", reached, short of the model's {_mm(target)} ({result.attrs.get('stop_reason') or 'stopped'})"


def short_of_target(result: xr.Dataset) -> float | None:
    """The settlement a run reached when it stopped short of its model's ``settlement_target`` [m], else None."""
    if "settlement_target" not in result or "step_settlement" not in result or not result.step_settlement.size:
        return None
    target, reached = float(result.settlement_target.values), float(result.step_settlement.values[-1])
    return reached if reached < target * (1 - 1e-3) else None


def _at(result: xr.Dataset, settlement: float, loss: float | None, resolution: float | None = None) -> str:
    """``12.3 mm (V_L 1.4 %)``, with ``+- 0.5 mm`` where the records it lies between are that far apart, or
    ``0 mm (under its own weight)`` for what the first record already had."""
    if not np.isfinite(settlement):
        return "not reached"
    if settlement == 0 and resolution == 0:
        return "0 mm (under its own weight, before any settlement)"
    known = f" +- {_mm(resolution)}" if resolution else ""
    return _mm(settlement) + known + ("" if loss is None else f" (V_L {loss:.3g} %)")


def _per_category(result: xr.Dataset, name: str) -> np.ndarray:
    values = result[name].values if name in result else np.full(result.sizes.get("category", 0), np.nan)
    return np.asarray(values, dtype=float)


def capacity_text(result: xr.Dataset, category: int | None = None) -> str:
    """Where the run first reached each damage category (stage 3), beside the LTSM (stage 2) and the greenfield
    screen (stage 1), in settlement and, of a tunnel, volume loss (``mf.damage``: derived by the core); with
    ``category`` that one's sentence first. Empty for a result without them."""
    if "category_settlement" not in result:
        return ""
    tunnel = "category_volume_loss" in result
    names = {value: name.replace("_", " ") for name, value in flags("step_damage_category").items()}
    model, ltsm = _per_category(result, "category_settlement"), _per_category(result, "category_ltsm_settlement")
    resolution = _per_category(result, "category_settlement_resolution")
    model_loss = _per_category(result, "category_volume_loss")
    ltsm_loss = _per_category(result, "category_ltsm_volume_loss")
    solver = result.attrs.get("solver", "the run")
    last = float(result.step_settlement.values[-1]) if result.step_settlement.size else 0.0
    per_metre = float(model_loss[0] / model[0]) if tunnel and np.isfinite(model_loss[0]) and model[0] else None
    reach = _mm(last) + ("" if per_metre is None else f" (V_L {per_metre * last:.3g} %)")
    rows = []
    for k, n in enumerate(result.category.values.astype(int)):
        stage3 = _at(result, model[k], model_loss[k] if tunnel else None, resolution[k])
        stage2 = "lumped with 4" if n == 5 and "category_ltsm_settlement" in result else \
            _at(result, ltsm[k], ltsm_loss[k] if tunnel else None) if "category_ltsm_settlement" in result else "-"
        rows.append(Row(f"{n} {names.get(n, '')}", (stage3, stage2), "", (model[k], ltsm[k])))
    lines = [text_table(("category", f"stage 3: {solver} (to {reach})", "stage 2: LTSM"), rows, note=False)]
    numbers = {n.name: n.value for n in key_numbers(result)}
    if "settlement_capacity" in numbers:
        capacity = numbers["settlement_capacity"]
        lines.insert(0, f"the masonry collapsed at a {load_word(result)} of {_at(result, capacity, per_metre * capacity if per_metre else None)}: "
                        "the categories not reached by then are not reached; the run holds nothing past its collapse")
    if "screen_settlement" in result:
        loss = float(result.screen_volume_loss.values) if "screen_volume_loss" in result else None
        lines.append(f"stage 1: the greenfield screen (slope 1/500 or 10 mm under the wall) fails at "
                     f"{_at(result, float(result.screen_settlement.values), loss)}")
    walls = wall_capacity_text(result)
    if walls:
        lines.append(walls)
    if category is not None:
        k = int(category) - 1
        if not 0 <= k < model.size:
            raise ValueError(f"--category {category}: the damage categories are 1 to {model.size}")
        found = (f"first reached at {_at(result, model[k], model_loss[k] if tunnel else None, resolution[k])} in "
                 f"the {solver} run"
                 if np.isfinite(model[k]) else
                 f"not reached in the {solver} run, which went to {reach}: run it further (--settlement"
                 f"{' or --volume-loss' if tunnel else ''})")
        lines.insert(0, f"category {category} ({names.get(int(category), '')}): {found}")
    return "\n".join(lines)


def wall_capacity_text(result: xr.Dataset) -> str:
    """A building's :func:`capacity_text` wall by wall: for each wall and category where the run first reached
    it (stage 3) and where the wall's LTSM does (stage 2), and where the wall's greenfield screen fails (stage 1);
    as a tunnel's volume loss, else as the settlement. Empty for a result without each wall's cracks."""
    if "wall_category_settlement" not in result:
        return ""
    tunnel = "wall_category_volume_loss" in result
    kind = "volume_loss" if tunnel else "settlement"

    def at(value: float) -> str:
        if not np.isfinite(value):
            return "-"
        if value == 0:
            return "own weight"
        return f"{value:.3g} %" if tunnel else _mm(value)

    stage_3 = np.asarray(result[f"wall_category_{kind}"].values, dtype=float)
    stage_2 = np.asarray(result[f"wall_category_ltsm_{kind}"].values, dtype=float) \
        if f"wall_category_ltsm_{kind}" in result else np.full_like(stage_3, np.nan)
    stage_1 = np.asarray(result[f"wall_screen_{kind}"].values, dtype=float) \
        if f"wall_screen_{kind}" in result else np.full(stage_3.shape[0], np.nan)
    categories = result.category.values.astype(int)
    rows = [Row(str(name), (at(stage_1[w]), *(f"{at(stage_3[w, k])} / {'(4)' if n == 5 else at(stage_2[w, k])}"
                                                for k, n in enumerate(categories))), "", ())
            for w, name in enumerate(result.wall_name.values)]
    what = "volume loss V_L" if tunnel else "settlement"
    return "\n".join([f"wall by wall, the {what} at which each category is first reached: stage 3 "
                      f"({result_label(result)}) / stage 2 (LTSM; it lumps 5 with 4); '-' not reached, 'own weight' before any settlement",
                      text_table(("wall", "stage 1 fails", *(_damage_name(n) for n in categories)), rows,
                                 note=False)])


def _slope(radians: float) -> str:
    """``1/830`` (the engineers' way of writing a small slope), ``0`` for none, ``2.4/1`` for one steeper than
    1/1 (which the 1/N form wrote as 1/0)."""
    if not radians:
        return "0"
    return f"1/{1 / abs(radians):.0f}" if abs(radians) < 1 else f"{abs(radians):.3g}/1"


def _damage_name(category: float) -> str:
    names = {value: name.replace("_", " ") for name, value in flags("step_damage_category").items()}
    return f"{int(category)} {names.get(int(category), '')}".strip()


#: key number -> (label, how to write it given all numbers of the result, note)
_HEADLINES = (
    ("alpha", "alpha", lambda n: f"{n['alpha']:.4f}",
     "collapse multiplier (limit analysis): the share of R0 the settling supports shed at collapse"),
    ("collapse_reaction", "collapse reaction", lambda n: force_text(n['collapse_reaction']),
     "reaction on the settling supports when the mechanism forms, (1 - alpha) R0"),
    ("dead_reaction", "dead reaction R0", lambda n: force_text(n['dead_reaction']),
     "reaction of the settling ground under the weight alone (over a profile the settlement reaction: each "
     "part weighted by its settlement per unit of the settlement parameter, S_max for a trough)"),
    ("minimum_reaction", "minimum reaction", lambda n: f"{force_text(n['minimum_reaction'])} at "
     f"{_mm(n['minimum_reaction_settlement'])}", "smallest reaction of the history, and the settlement there"),
    ("plateau_reaction", "plateau reaction", lambda n: f"{force_text(n['plateau_reaction'])} from "
     f"{_mm(n['plateau_settlement'])}", "the reaction once it stops changing (within 1 % of R0)"),
    ("final_settlement", "final settlement", lambda n: _mm(n["final_settlement"]), "settlement of the last record"),
    ("settlement_capacity", "settlement at collapse", lambda n: f"{_mm(n['settlement_capacity'])}, reaction "
     f"{force_text(n['capacity_reaction'])}", "la-incremental: the last moved configuration that carries its dead "
     "load; fdem: where its widest crack began to open faster than the ground moves, until a block fell away; "
     "and the reaction there"),
    ("crack_width", "widest crack", lambda n: _crack_text(n),
     "widest opening of a joint in the masonry over the run: the joint, its midpoint, the settlement"),
    ("damage_category", "damage category", lambda n: _damage_name(n["damage_category"]),
     "largest over the run, Burland et al. (1977) by crack width: 0 negligible .. 5 very severe"),
    ("base_gap", "base gap", lambda n: _mm(n["base_gap"]),
     "widest gap between the wall and the ground over the run (not a crack in the masonry)"),
    ("greenfield_slope", "stage 1: greenfield", lambda n: _stage_1(n),
     "the screen at the assessed settlement: the largest greenfield slope and settlement under the wall; under "
     "1/500 and 10 mm the risk is negligible (Mair, Taylor & Burland 1996)"),
    ("ltsm_category", "stage 2: LTSM", lambda n: _stage_2(n),
     "the limiting tensile strain method on the greenfield trough at the assessed settlement: the wall as a deep "
     "beam (Burland & Wroth 1974; Boscardin & Cording 1989; Burland 1995)"),
    ("deflection_ratio", "deflection ratio", lambda n: f"{n['deflection_ratio']:.3g}",
     "of the imposed ground at the last record: its largest distance from the chord over the chord's length "
     "(sagging positive)"),
    ("angular_distortion", "angular distortion", lambda n: _slope(n["angular_distortion"]),
     "of the imposed ground at the last record: its largest slope less the chord's tilt"),
    ("unbalanced_ratio", "quasi-static check", lambda n: quasi_static_text(n),
     "medians over the settlement records of the unbalanced force over the applied load and of the kinetic over "
     "the stored elastic energy: a reaction history is quasi-static, so its minimum meaningful, when the first is "
     f"under {QUASI_STATIC_RATIO:g}"),
    ("cracked_joints", "cracked joints", lambda n: f"{int(n['cracked_joints'])}",
     "joints moving more than a tenth of the largest joint motion (the one crack threshold of every plot, "
     "comparison and diagnosis)"),
    ("macro_blocks", "macro-blocks", lambda n: f"{int(n['macro_blocks'])}",
     "pieces the masonry breaks into (blocks joined by intact joints)"),
)


def result_options(result: xr.Dataset) -> dict:
    """The solver options a result records (``solver_options``, JSON); empty when absent or unreadable."""
    try:
        options = json.loads(result.attrs.get("solver_options", "{}") or "{}")
    except (TypeError, ValueError):
        return {}
    return options if isinstance(options, dict) else {}


def result_label(result: xr.Dataset) -> str:
    """``solver`` plus the method it says it ran (its ``method`` attribute), else the backend its options name,
    e.g. ``la (highs)``."""
    name = str(result.attrs.get("solver", result.attrs.get("plugin", "?")))
    options = result_options(result)
    detail = ([str(result.attrs["method"])] if "method" in result.attrs
              else [str(options[k]) for k in ("solver", "backend") if options.get(k) is not None])
    return f"{name} ({', '.join(detail)})" if detail else name


def headline_text(result: xr.Dataset) -> str:
    """A result's headline in a few words (a figure's title), the answer first in the words of the load
    (:func:`load_word`): a masonry that did not stand under its own weight says so; limit analysis: alpha, what it
    means, and the collapse reaction; an incremental run that collapsed: where and at what settlement (spread,
    tilt), then R0 and the smallest and plateau reactions before it; empty for a model."""
    if "solver" not in result.attrs:
        return ""
    fallen = standing_text(result)
    if fallen:
        return fallen[0].upper() + fallen[1:]
    numbers = {n.name: n.value for n in key_numbers(result)}
    word = load_word(result)
    force = "thrust" if word == "spread" else "reaction"
    collapse = ""
    if "settlement_capacity" in numbers and "alpha" not in numbers:
        where = (f" (the masonry broke away at x {_place(numbers['collapse_x'])} m, y {_place(numbers['collapse_y'])} m)"
                 if "collapse_x" in numbers else "")
        collapse = (f"collapses at a {word} of {_mm(numbers['settlement_capacity'])}{where}, {force} "
                    f"{force_text(numbers.get('capacity_reaction', float('nan')))}; ")
    if "alpha" in numbers:
        if "dead_reaction" not in numbers:
            return f"alpha = {numbers['alpha']:.4f} (the live load's multiplier at collapse)"
        reaction = f", collapse reaction {force_text(numbers['collapse_reaction'])}" \
            if "collapse_reaction" in numbers else ""
        return (f"alpha = {numbers['alpha']:.4f} (the share of R0 = {force_text(numbers['dead_reaction'])} the "
                f"settling ground sheds before collapse){reaction}")
    if "minimum_reaction" in numbers:
        dynamic = numbers.get("unbalanced_ratio", 0.0) > QUASI_STATIC_RATIO
        before = " before it" if collapse else ""
        return (f"{collapse}R0 {force_text(numbers['dead_reaction'])}, min {force_text(numbers['minimum_reaction'])}"
                f" at {_mm(numbers['minimum_reaction_settlement'])}, plateau "
                f"{force_text(numbers['plateau_reaction'])}{before}"
                + (f" (DYNAMIC: unbalanced force ratio {numbers['unbalanced_ratio']:.2g})" if dynamic else ""))
    return collapse.rstrip("; ")


def _place(coordinate: float) -> str:
    """A coordinate [m] to the millimetre, without round-off's -0 or 6e-17."""
    return f"{round(coordinate, 3) + 0.0:.4g}"


def quasi_static_text(numbers: dict) -> str:
    """``quasi-static (unbalanced 0.021, kinetic/stored 0.0034)``, or the warning that the history is dynamic."""
    ratios = f"unbalanced {numbers['unbalanced_ratio']:.2g}, kinetic/stored {numbers['kinetic_energy_ratio']:.2g}"
    if numbers["unbalanced_ratio"] <= QUASI_STATIC_RATIO:
        return f"quasi-static ({ratios})"
    return f"DYNAMIC ({ratios}): the reactions depend on the loading; rerun with a smaller loading_rate"


#: Results whose R0 differ by more than this share get :func:`r0_text`'s explanation.
R0_SPREAD = 0.005


def r0_text(results: Sequence[xr.Dataset], labels: Sequence[str]) -> str:
    """Why results of one model report different R0 (empty when they agree within :data:`R0_SPREAD`): which R0
    each reports, and that over ground partly fixed and partly settling the split of the weight is statically
    indeterminate."""
    numbers = {label: {n.name: n.value for n in key_numbers(result)} for label, result in zip(labels, results)}
    r0 = {label: n["dead_reaction"] for label, n in numbers.items() if "dead_reaction" in n}
    if len(r0) < 2 or max(r0.values()) - min(r0.values()) <= R0_SPREAD * max(abs(v) for v in r0.values()):
        return ""
    said = [f"{label} reports {force_text(value)}, "
            + ("W L_s / L_total, the weight shared between the ground's parts by their contact lengths (the "
               "convention of limit analysis: alpha is a share of it)" if "alpha" in numbers[label] else
               "the reaction it computes at rest under the weight, before the ground settles")
            for label, value in r0.items()]
    return ("R0 is not one number here: " + "; ".join(said) + ". A wall on ground that is partly fixed and partly "
            "settling is statically indeterminate: equilibrium alone does not fix how its weight divides between "
            "the parts; the stiffness of the contacts and the openings over each part do (a pier over a part "
            "carries more than its length's share). A computed R0 is that split at rest, the convention is the "
            "same for every wall; compare collapse or minimum reactions in kN, or each as a share of its own R0.")


def _flow(result: xr.Dataset) -> str:
    """How a result's joints slide: ``dilatant`` (la's associative flow, la-incremental's associative option),
    ``non-dilatant`` (Coulomb's friction without opening: fdem, la-incremental's default, la's non-associative
    flow), or the solver's continuum."""
    solver, flow = str(result.attrs.get("solver", "")), str(result.attrs.get("flow_rule", ""))
    if solver in ("jmm", "jmm-limit"):
        return "a continuum (the joints smeared in elastic-plastic elements)"
    if flow == "associative" or solver == "la" and flow != "nonassociative":
        return "dilatant rigid joints (associative flow: a sliding joint opens by mu |slip|)"
    return ("elastic joints, non-dilatant (Coulomb friction, no opening on sliding)" if solver == "fdem" else
            "rigid joints, non-dilatant (sliding without opening)")


def damage_text(results: Sequence[xr.Dataset], labels: Sequence[str]) -> str:
    """Why results of one model give different damage answers (empty when they do not differ): which did not
    stand under its own weight, which collapsed and where, the largest category each reached and at what
    settlement, and how each one's joints slide, with the numbers that show it."""
    said, categories, flows = [], {}, {}
    for label, result in zip(labels, results):
        fallen = standing_text(result)
        if fallen:
            said.append(f"{label} {fallen.removeprefix('the masonry ')}")
            continue
        numbers = {n.name: n.value for n in key_numbers(result)}
        flows[label] = _flow(result)
        if "settlement_capacity" in numbers and "alpha" not in numbers:
            said.append(f"{label} collapses at a {load_word(result)} of {_mm(numbers['settlement_capacity'])}")
        if "damage_category" in numbers:
            categories[label] = int(numbers["damage_category"])
            said.append(f"{label} reaches category {_damage_name(numbers['damage_category'])} (widest crack "
                        f"{_mm(numbers['crack_width'])} at {_mm(numbers.get('crack_settlement', float('nan')))})")
        elif "alpha" in numbers:
            said.append(f"{label} gives the collapse multiplier alone (alpha {numbers['alpha']:.4f}): a mechanism's "
                        "shape, no crack width")
    differ = len(set(categories.values())) > 1 or any("did not stand" in t or "collapses" in t for t in said)
    if len(set(flows.values())) > 1:
        said.append("their joints differ: " + "; ".join(f"{label} {flow}" for label, flow in flows.items())
                    + ". Dilatant joints carry by the opening sliding forces on them (an upper bound on what the "
                    "wall sheds); elastic non-dilatant ones open and slide at once, so their cracks come earlier "
                    "and wider")
        differ = differ or len(set(flows.values())) > 1 and bool(categories)
    return ("The damage answers differ: " + "; ".join(said) + ".") if differ and len(results) > 1 else ""


def headline_rows(results: Sequence[xr.Dataset]) -> list[Row]:
    """One row per headline number any of ``results`` has, one cell per result."""
    numbers = [{k.name: k.value for k in key_numbers(result)} for result in results]
    rows = []
    for name, label, write, note in _HEADLINES:
        if any(name in n for n in numbers):
            rows.append(Row(label, tuple(write(n) if name in n else MISSING for n in numbers), note,
                            tuple(n.get(name) for n in numbers)))
    return rows


def _score_names(comparisons: Sequence[xr.Dataset]) -> list[str]:
    names = {str(n) for c in comparisons for n in c.data_vars if c[n].ndim == 0 and str(n) not in DETAIL_SCORES}
    return [n for n in SHOWN_SCORES if n in names] + sorted(names - set(SHOWN_SCORES))


def score_rows(comparisons: Sequence[xr.Dataset]) -> list[Row]:
    """One row per score any comparison has (:data:`SHOWN_SCORES` first, no :data:`DETAIL_SCORES`, the crack
    counts as one row), one cell per comparison."""
    rows = []
    if any("crack_count_a" in c for c in comparisons):
        rows.append(Row("cracked joints a/b/both", tuple(
            "/".join(str(int(c[n])) for n in ("crack_count_a", "crack_count_b", "crack_count_both"))
            if "crack_count_a" in c else MISSING for c in comparisons),
            "joints with crack_indicator above the threshold in a, in b, in both", tuple(None for _ in comparisons)))
    for name in _score_names(comparisons):
        present = [c for c in comparisons if name in c]
        values = tuple(float(c[name]) if name in c else None for c in comparisons)
        rows.append(Row(name, tuple(MISSING if v is None else f"{v:.4g}" for v in values),
                        str(present[0][name].attrs.get("comment", present[0][name].attrs.get("long_name", ""))),
                        values))
    return rows


#: The columns of a diagnosis's candidate table (``diagnosis_rows``).
DIAGNOSIS_COLUMNS = ("scenario", "score", "cracks", "levelling", "settlement", "plausible", "unexplained",
                     "unobserved", "verified")


def candidate_text(ds: xr.Dataset, k: int) -> str:
    """Candidate ``k`` of a diagnosis dataset in words: ``step 1.2..1.5 m``, ``tilt from 1.2 m down to 0 m``,
    ``gaussian trough at 4 m, i 2 m``."""
    profile = str(ds.candidate_profile.values[k])
    if profile == "gaussian":
        return f"gaussian trough at {float(ds.candidate_center[k]):.4g} m, i {float(ds.candidate_width[k]):.4g} m"
    start, end = float(ds.candidate_start[k]), float(ds.candidate_end[k])
    return f"step {start:.4g}..{end:.4g} m" if profile == "step" else f"tilt from {start:.4g} m down to {end:.4g} m"


def _finite(value: float) -> float | None:
    return value if np.isfinite(value) else None


def diagnosis_rows(diagnosis: xr.Dataset, count: int) -> list[Row]:
    """The best ``count`` candidates of a ``diagnosis`` dataset (and every plausible one), one row each
    (:data:`DIAGNOSIS_COLUMNS`); the note says what the candidate leaves out."""
    shown = max(count, int(diagnosis.candidate_plausible.values.sum()))
    levelled = "candidate_levelling_score" in diagnosis
    verified = "candidate_verified_crack_width" in diagnosis
    rows = []
    for k in range(min(shown, diagnosis.sizes["candidate"])):
        score, crack = float(diagnosis.candidate_score[k]), float(diagnosis.candidate_crack_score[k])
        level = float(diagnosis.candidate_levelling_score[k]) if levelled else float("nan")
        magnitude = float(diagnosis.candidate_magnitude[k])
        width = float(diagnosis.candidate_verified_crack_width[k]) if verified else float("nan")
        unexplained, unobserved = (int(diagnosis[f"candidate_{n}"][k]) for n in ("unexplained_cracks",
                                                                                   "unobserved_joints"))
        cells = (candidate_text(diagnosis, k), f"{score:.3f}", f"{crack:.3f}",
                 f"{level:.3f}" if np.isfinite(level) else MISSING, _mm(magnitude) if np.isfinite(magnitude) else MISSING,
                 "yes" if diagnosis.candidate_plausible.values[k] else "no", str(unexplained), str(unobserved),
                 _mm(width) if np.isfinite(width) else MISSING)
        note = (f"leaves {unexplained} surveyed crack(s) unexplained, cracks {unobserved} joint(s) nobody surveyed"
                if unexplained or unobserved else "explains every surveyed crack and cracks nothing else")
        rows.append(Row(str(k + 1), cells, note, (None, score, crack, _finite(level), _finite(magnitude), None,
                                                  float(unexplained), float(unobserved), _finite(width))))
    return rows


def text_table(header: Sequence[str], rows: Sequence[Row], note: bool = True) -> str:
    """Rows as aligned plain text, the note (what the row means) last."""
    lines = [[str(h) for h in header]] + [[r.label, *r.cells] + ([r.note] if note else []) for r in rows]
    if note:
        lines[0].append("")
    widths = [max(len(line[i]) for line in lines) for i in range(len(lines[0]) - (1 if note else 0))]
    out = []
    for line in lines:
        cells = [cell.ljust(width) for cell, width in zip(line, widths)]
        out.append("  ".join(cells + line[len(widths):]).rstrip())
    return "\n".join(out)


def csv_text(header: Sequence[str], rows: Sequence[Sequence]) -> str:
    """RFC 4180 CSV; floats with every digit (repr), a missing value as an empty field."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([["" if v is None else repr(float(v)) if isinstance(v, float) else v for v in row] for row in rows])
    return buffer.getvalue()
