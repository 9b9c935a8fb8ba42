"""What a settlement does to a wall, one definition for every solver: crack widths, damage
categories and the distortion of the imposed settlement profile.

- **crack width** of a state: the widest opening of a joint *within the masonry*
  (both sides masonry blocks), from the block motions
  (:func:`masonryfw.plugin_api.relative_motion`). The joint between the wall and the ground
  is no crack in the masonry: its widest opening is the **base gap**, reported
  apart. Solvers report per recorded step ``step_crack_width_max``, the joint it
  is at (``step_crack_interface``) and ``step_base_gap_max``
  (:func:`widest_crack`);
- **damage category** (``step_damage_category``, derived by the core): Burland et
  al. (1977) and Boscardin & Cording (1989), by the crack width, upper limits
  inclusive: 0 negligible (<= 0.1 mm), 1 very slight (<= 1 mm), 2 slight
  (<= 5 mm), 3 moderate (<= 15 mm), 4 severe (<= 25 mm), 5 very severe;
- **imposed profile**: the vertical motion of every support at the midpoint of
  the masonry resting on it (0 for fixed supports), per unit of the settlement
  parameter; with the supports sorted by that midpoint, the **deflection ratio**
  is the largest distance of the profile from the chord joining its first and
  last points over the chord's length, positive where the profile sags below the
  chord, negative where it hogs above it (Burland & Wroth 1974, over the whole
  wall rather than per sagging or hogging zone); the **angular distortion** is
  the largest slope between neighbouring points once the chord's tilt is
  removed. Both grow linearly with the settlement parameter
  (``step_deflection_ratio``, ``step_angular_distortion``);
- **where each category is first reached** (``category_settlement``, derived by the core from one run's
  history): the settlement at which the widest crack first exceeds the category's lower width, linear
  between the two records around it; beside it the settlement at which the LTSM (stage 2) first reaches
  the category and the one at which the greenfield screen (stage 1) first fails, both linear in t, and
  for a tunnel the volume loss of each (S_max is proportional to V_L: one run to a larger settlement
  answers every smaller volume loss);
- the engineers' **stage 2** on the continuous greenfield profile a model was
  built over, the LTSM strain and its category (``step_ltsm_strain``,
  ``step_ltsm_category``, :mod:`masonryfw.ground.assessment`), beside the model's own
  damage;
- **a wall that does not stand**: a result whose ``stood = 0`` (a block moved more than a tenth of a unit
  height before any settlement, ``gravity_motion`` at ``gravity_motion_x``, ``gravity_motion_y``) holds no
  settlement's damage: :func:`standing_text` says so, and ``capacity``, ``compare`` and the report read no
  damage from it.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..format.model3d import space
from ..format.roles import masonry_blocks, support_blocks
from ..format.schema import variable_attrs
from ..ground.assessment import (
    assess_walls,
    ltsm_thresholds,
    ltsm_variables,
    screen_threshold,
    unit_ltsm_thresholds,
    unit_screen_threshold,
    volume_loss_per_settlement,
)
from ..runtime.errors import SolveError
from .semantics import relative_motion
from .semantics3d import padded, vertex_motion

if TYPE_CHECKING:  # annotations only
    import xarray as xr

#: Upper crack widths [m] of damage categories 0 to 4 (category 5 beyond the last).
DAMAGE_LIMITS = (1.0e-4, 1.0e-3, 5.0e-3, 15.0e-3, 25.0e-3)
#: Variables the core derives from a result's history (a solver must not return them).
DERIVED_STEP_VARIABLES = ("step_damage_category", "step_deflection_ratio", "step_angular_distortion",
                          "step_ltsm_strain", "step_ltsm_category", "category", "category_settlement",
                          "category_settlement_resolution", "category_ltsm_settlement", "screen_settlement",
                          "category_volume_loss",
                          "category_ltsm_volume_loss", "screen_volume_loss", "wall_name", "step_wall_damage_category",
                          "wall_category_settlement", "wall_category_settlement_resolution",
                          "wall_category_ltsm_settlement", "wall_screen_settlement", "wall_category_volume_loss",
                          "wall_category_ltsm_volume_loss", "wall_screen_volume_loss")


def damage_category(width) -> np.ndarray:
    """int8 damage category 0..5 of crack widths [m] (module docstring)."""
    return np.searchsorted(np.array(DAMAGE_LIMITS), np.asarray(width, dtype=float), side="left").astype(np.int8)


@dataclass(frozen=True)
class Cracks:
    """The widest openings of one state of a wall (module docstring)."""

    width: float  # widest opening of a joint between two masonry blocks [m]
    interface: int  # that joint, -1 when none opens
    base_gap: float  # widest opening of a joint between the wall and a support [m]
    wall_width: tuple[float, ...] = ()  # a building's: each wall's widest crack [m] (:func:`wall_cracks`)
    wall_interface: tuple[int, ...] = ()  # and its joint, -1 where none of the wall opens


def widest_crack(model: xr.Dataset, u: np.ndarray, rotations: str = "finite") -> Cracks:
    """The widest crack in the masonry and the widest base gap under block motions ``u`` (block, 3; a 3D model's
    (block, 6), its openings at the interfaces' vertices: :func:`masonryfw.results.semantics3d.vertex_motion`)."""
    if space(model) == 3:
        vertex_opening, _ = vertex_motion(model, u, rotations)
        opening = padded(vertex_opening, model.interface_node_count.values.astype(np.int64))
    else:
        opening, _ = relative_motion(model, u, rotations)
    opening = np.maximum(opening, 0.0).max(axis=1, initial=0.0)
    masonry = masonry_blocks(model.block_role.values)[model.interface_blocks.values.astype(np.int64)]
    inside, base = masonry.all(axis=1), masonry.any(axis=1) & ~masonry.all(axis=1)
    crack = np.where(inside, opening, 0.0)
    width, widest = _widest(crack)
    wall_width, wall_interface = wall_cracks(model, crack)
    return Cracks(width, widest, float(opening[base].max(initial=0.0)), wall_width, wall_interface)


def _widest(crack: np.ndarray) -> tuple[float, int]:
    """The largest of the joints' ``crack`` widths and its joint (-1 when none opens)."""
    widest = int(np.argmax(crack)) if crack.size else -1
    width = float(crack[widest]) if widest >= 0 else 0.0
    return width, widest if width > 0 else -1


def wall_cracks(model: xr.Dataset, crack: np.ndarray) -> tuple[tuple[float, ...], tuple[int, ...]]:
    """Each wall's widest crack of a building (``block_wall``) and its joint, from every joint's ``crack`` width:
    a wall's joints are those with a block laid in it on either side (a joint between two walls, at a corner or
    a junction, cracks both); nothing for a model without walls."""
    if "block_wall" not in model:
        return (), ()
    sides = model.block_wall.values[model.interface_blocks.values.astype(np.int64)]
    found = [_widest(np.where((sides == w).any(axis=1), crack, 0.0)) for w in range(wall_count(model))]
    return tuple(width for width, _ in found), tuple(joint for _, joint in found)


def wall_count(model: xr.Dataset) -> int:
    """How many walls a building has (``building_walls``), 0 for any other model."""
    return len(json.loads(model.attrs["building_walls"])) if "building_walls" in model.attrs else 0


def support_profile(model: xr.Dataset) -> tuple[np.ndarray, np.ndarray]:
    """``(x, v)``: every support's contact midpoint with the masonry [m] and its vertical motion there
    per unit settlement parameter (the small-rotation motion of a rotating support), sorted by x."""
    sides = model.interface_blocks.values.astype(np.int64)
    ground = support_blocks(model.block_role.values)
    touching = ground[sides].any(axis=1) & ~ground[sides].all(axis=1)
    support = np.where(ground[sides[:, 0]], sides[:, 0], sides[:, 1])[touching]
    length = model.interface_length.values[touching]
    mid = model.interface_x.values[touching].mean(axis=1)
    n = model.sizes["block"]
    contact = np.bincount(support, weights=length, minlength=n)
    which = np.flatnonzero(contact > 0)
    x = np.bincount(support, weights=length * mid, minlength=n)[which] / contact[which]
    d = model.settlement_direction.values[which]
    v = d[:, 1] + d[:, 2] * (x - model.block_centroid_x.values[which])
    order = np.argsort(x, kind="stable")
    return x[order], v[order]


def distortion(x: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    """``(deflection ratio, angular distortion)`` of a profile ``v(x)`` (module docstring)."""
    if x.size < 2 or not x[-1] > x[0]:
        return 0.0, 0.0
    span = x[-1] - x[0]
    tilt = (v[-1] - v[0]) / span
    offset = v[0] + tilt * (x - x[0]) - v  # > 0 where the profile sags below the chord
    largest = int(np.argmax(np.abs(offset)))
    step = np.diff(x)
    moving = step > 0
    slopes = np.diff(v)[moving] / step[moving]
    return float(offset[largest] / span), float(np.abs(slopes - tilt).max(initial=0.0))


def first_exceeding(settlement: np.ndarray, width: np.ndarray, limit: float) -> tuple[float, float]:
    """The settlement at which ``width`` first exceeds ``limit``, linear between the records around it, and the
    spacing of those two records, to which it is known (NaN when it never does; the first record's settlement,
    known exactly, when it already does)."""
    over = np.flatnonzero(width > limit)
    if over.size == 0:
        return float("nan"), float("nan")
    k = int(over[0])
    if k == 0:
        return float(settlement[k]), 0.0
    spacing = float(settlement[k] - settlement[k - 1])
    if width[k] == width[k - 1]:
        return float(settlement[k]), spacing
    share = (limit - width[k - 1]) / (width[k] - width[k - 1])
    return float(settlement[k - 1] + share * (settlement[k] - settlement[k - 1])), spacing


def category_variables(model: xr.Dataset, settlement: np.ndarray, width: np.ndarray) -> dict[str, tuple]:
    """Where the run first reaches damage categories 1 to 5 (stage 3), beside stage 2 and stage 1 and, of a
    tunnel, their volume losses (module docstring)."""
    categories = np.arange(1, len(DAMAGE_LIMITS) + 1, dtype=np.int8)
    ltsm, screen = ltsm_thresholds(model), screen_threshold(model)
    return {"category": ("category", categories, variable_attrs("category")),
            **_stage_variables(model, "", (), _first_reached(settlement, width),
                               None if ltsm is None else np.r_[ltsm, np.nan], screen)}


def wall_category_variables(model: xr.Dataset, settlement: np.ndarray, wall_width: np.ndarray) -> dict[str, tuple]:
    """:func:`category_variables` wall by wall of a building, from each wall's widest crack ``wall_width``
    (step, wall) and each wall's stages 1 and 2 (:func:`masonryfw.ground.assessment.assess_walls`); the walls'
    names and each record's category per wall."""
    names = [wall["name"] for wall in json.loads(model.attrs["building_walls"])]
    stages = assess_walls(model, 1.0)
    reached = np.stack([_first_reached(settlement, wall_width[:, w]) for w in range(len(names))], axis=1)
    ltsm = np.array([np.r_[unit_ltsm_thresholds(stages[name]), np.nan] for name in names]) if stages else None
    screen = np.array([unit_screen_threshold(stages[name]) for name in names]) if stages else None
    return {"wall_name": ("wall", np.array(names, dtype=str), variable_attrs("wall_name", "result3d")),
            "step_wall_damage_category": (("step", "wall"), damage_category(wall_width),
                                          variable_attrs("step_wall_damage_category", "result3d")),
            **_stage_variables(model, "wall_", ("wall",), reached, ltsm, screen)}


def _first_reached(settlement: np.ndarray, width: np.ndarray) -> np.ndarray:
    """(2, category): the settlement at which ``width`` first exceeds each category's lower width and the
    spacing of the records around it (:func:`first_exceeding`)."""
    return np.array([first_exceeding(settlement, width, limit) for limit in DAMAGE_LIMITS]).T


def _stage_variables(model: xr.Dataset, prefix: str, lead: tuple[str, ...], reached: np.ndarray,
                     ltsm: np.ndarray | None, screen: np.ndarray | float | None) -> dict[str, tuple]:
    """The three stages' thresholds as variables named ``prefix + name`` over ``lead + (category,)``: stage 3's
    ``reached`` (settlement, spacing), stage 2's ``ltsm`` and stage 1's ``screen`` where the model has a
    profile, and of a tunnel the volume loss of each."""
    kind = "result3d" if prefix else "result"
    per_category = (*lead, "category")
    values: dict[str, tuple] = {"category_settlement": (per_category, reached[0]),
                                "category_settlement_resolution": (per_category, reached[1])}
    if ltsm is not None:
        values["category_ltsm_settlement"] = (per_category, ltsm)
    if screen is not None:
        values["screen_settlement"] = (lead, screen)
    per_metre = volume_loss_per_settlement(model)
    if per_metre is not None:
        for name in ("category_settlement", "category_ltsm_settlement", "screen_settlement"):
            if name in values:
                dims, settled = values[name]
                values[name.replace("settlement", "volume_loss")] = (dims, per_metre * np.asarray(settled))
    return {prefix + name: (dims, value, variable_attrs(prefix + name, kind)) for name, (dims, value) in values.items()}


def damage_variables(model: xr.Dataset, produced: xr.Dataset) -> dict[str, tuple]:
    """The damage variables the core derives from a solver's history: the category of every
    ``step_crack_width_max``, where each category is first reached beside stages 1 and 2 and, of a 2D wall, the
    distortion of the imposed profile at every ``step_settlement``; of a building, each wall's (its
    ``step_wall_crack_width_max``)."""
    derived: dict[str, tuple] = {}
    if "step_crack_width_max" in produced:
        derived["step_damage_category"] = ("step", damage_category(produced.step_crack_width_max.values),
                                           variable_attrs("step_damage_category"))
    if "step_settlement" not in produced:
        return derived
    settlement = np.asarray(produced.step_settlement.values, dtype=float)
    if space(model) == 2:
        ratio, angle = distortion(*support_profile(model))
        derived["step_deflection_ratio"] = ("step", ratio * settlement, variable_attrs("step_deflection_ratio"))
        derived["step_angular_distortion"] = ("step", angle * settlement, variable_attrs("step_angular_distortion"))
    derived.update(ltsm_variables(model, settlement))
    if "step_crack_width_max" in produced:
        derived.update(category_variables(model, settlement, np.asarray(produced.step_crack_width_max.values)))
    if "step_wall_crack_width_max" in produced:
        derived.update(wall_category_variables(model, settlement,
                                               np.asarray(produced.step_wall_crack_width_max.values)))
    return derived


def standing_text(result: xr.Dataset) -> str | None:
    """What a result whose masonry did not stand under its own weight says about it (``stood = 0``: the block that
    moved most before any settlement, how far and from where), or None when it stood (or says nothing)."""
    if int(result.attrs.get("stood", 1)):
        return None
    where = (f" (block {int(result.attrs['gravity_motion_block'])}, which started at x "
             f"{float(result.attrs['gravity_motion_x']):.4g} m, {'z' if int(result.attrs.get('masonryfw_space', 2)) == 3 else 'y'} "
             f"{float(result.attrs['gravity_motion_y']):.4g} m)") if "gravity_motion_block" in result.attrs else ""
    moved = f"moved {float(result.attrs['gravity_motion']) * 1e3:.3g} mm" if "gravity_motion" in result.attrs else "moved"
    return (f"the masonry did not stand under its own weight: a block {moved}{where} before any settlement; its "
            "cracks are not the settlement's damage (is the wall as built stable? la's collapse multiplier, or "
            "fdem's gravity phase alone, --option settlement=0, tell)")


def refuse_not_standing(results, what: str) -> None:
    """Raise a :class:`masonryfw.SolveError` naming the first of ``results`` whose masonry did not stand: ``what``
    (capacity, a comparison of damage) cannot be read from it."""
    for result in results:
        text = standing_text(result)
        if text:
            raise SolveError(f"{what}: {result.attrs.get('solver', 'the run')}: {text}")
