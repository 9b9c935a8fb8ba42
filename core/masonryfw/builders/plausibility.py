"""Inputs that are valid but plainly wrong: warnings that name the key, the value and what was probably meant.

A model can be consistent (``check`` finds no problem) and still describe no real
wall: a unit weight typed in kN/m3, metre values under ``length_unit = "mm"``, a
friction angle in radians. :func:`plausibility` compares a model with the ranges
of real masonry and says, for each value outside them, which spec key it came
from, what it is and the nearest plausible reading:

- unit weight 5-40 kN/m3 (brick, stone, concrete block; a density in kg/m3 or a
  value in kN/m3 is recognised);
- units (the median masonry block) 10 mm to 2 m in each direction, the masonry
  at least 0.1 m wide and high (metres under ``length_unit = "mm"`` are
  recognised), at most 1 km (a drawing in the wrong unit);
- friction angles 10-60 degrees (a coefficient or radians typed as degrees is
  recognised);
- Young's modulus 0.1-100 GPa (MPa or GPa typed as Pa is recognised);
- a tunnel's volume loss 0.1-5 % (a fraction typed for a percentage is recognised), its diameter 1-20 m, and
  its greenfield S_max at most the wall's height;
- a building's floor loads 0.1-200 kN/m on the walls (kN/m typed as N/m is recognised) and its walls 50 mm to
  3 m thick.

They are warnings, not errors: a laboratory model or a deliberately extreme
study may step outside. ``masonryfw build`` and ``solve`` print them,
``masonryfw check`` lists them after the problems and ``check --strict`` counts
them as problems. The ranges are wide on purpose: a warning that cries wolf is
soon ignored.
"""
from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING

import numpy as np

from ..format.model3d import space
from ..format.roles import masonry_blocks
from ..geometry.polygons import block_bounds
from ..ground.profiles import model_profile
from ..readers.spec import read_spec

if TYPE_CHECKING:  # annotations only
    import xarray as xr

UNIT_WEIGHT = (5.0e3, 40.0e3)  # N m-3
UNIT_SIZE = (0.01, 2.0)  # m, each side of the median masonry block
WALL_SIZE = 0.1  # m, the masonry's smallest extent
WALL_SIZE_MAX = 1000.0  # m, its largest
FRICTION_ANGLE = (10.0, 60.0)  # degrees
YOUNG_MODULUS = (0.1e9, 100.0e9)  # Pa
VOLUME_LOSS = (0.1, 5.0)  # %: 0.5-3 % is common, soft ground up to about 5 % (Mair et al. 1996)
TUNNEL_DIAMETER = (1.0, 20.0)  # m: a micro-tunnel to the largest bored tunnels
FLOOR_LOAD = (100.0, 200.0e3)  # N/m: a light roof on a short span to heavy floors of many storeys on one wall
WALL_THICKNESS = (0.05, 3.0)  # m: a half-brick partition to a castle's wall
GRAVITY = 9.81  # m s-2


class PlausibilityWarning(UserWarning):
    """A value outside the range of real masonry (see :mod:`masonryfw.builders.plausibility`)."""


def _within(value: float, bounds: tuple[float, float]) -> bool:
    return bounds[0] <= value <= bounds[1]


def _reading(value: float, bounds: tuple[float, float], readings) -> str:
    """The first ``(factor, text)`` of ``readings`` that brings ``value`` into ``bounds``, as advice."""
    for factor, text in readings:
        if _within(value * factor, bounds):
            return f"; probably {text}: {value * factor:.6g}"
    return ""


def _spec_info(model: xr.Dataset) -> tuple[bool, str]:
    """``(drawn, length unit)`` of the spec the model was built from (parametric, m when unknown)."""
    text = str(model.attrs.get("source_spec", ""))
    drawn = "source_drawing" in model.attrs
    unit = "m"
    for line in text.splitlines():
        key, _, value = line.partition("=")
        if key.strip() == "length_unit":
            unit = value.split("#")[0].strip().strip("\"'")
    return drawn, unit


def plausibility(model: xr.Dataset) -> list[str]:
    """One message per implausible value of ``model`` (a model or result dataset; module docstring)."""
    role = np.asarray(model.block_role.values)
    masonry = masonry_blocks(role)
    if not masonry.any():
        return []
    drawn, length_unit = _spec_info(model)
    messages = []
    weight = float(np.median(model.block_unit_weight.values[masonry]))
    if not _within(weight, UNIT_WEIGHT):
        advice = _reading(weight, UNIT_WEIGHT, [(1e3, "kN/m3 were meant, in N/m3"),
                                                (GRAVITY, "a density in kg/m3 was given; its weight in N/m3 is")])
        messages.append(f"material.unit_weight (block_unit_weight) = {weight:.6g} N/m3: masonry weighs "
                        f"{UNIT_WEIGHT[0] / 1e3:g}-{UNIT_WEIGHT[1] / 1e3:g} kN/m3{advice}")
    unit_sizes, extent = (_sizes_3d if space(model) == 3 else _sizes)(model, masonry)
    metres = "; probably metres were meant: remove length_unit = \"mm\" (it scales every length by 0.001)" \
        if length_unit == "mm" else ""
    for side, size in unit_sizes.items():
        if not _within(size, UNIT_SIZE):
            where = f"the drawing's median block {side}" if drawn else f"unit.{side}"
            advice = metres if size < UNIT_SIZE[0] and metres else ""
            messages.append(f"{where} = {size:.6g} m: masonry units are {UNIT_SIZE[0] * 1e3:g} mm to "
                            f"{UNIT_SIZE[1]:g} m{advice}")
    for side, size in extent.items():
        where = "the drawing" if drawn else f"wall.{side}"
        measured = f"{where}: the masonry is {size:.6g} m {'wide' if side == 'width' else 'high'}"
        if size < WALL_SIZE:
            messages.append(f"{measured}, less than {WALL_SIZE:g} m{metres}")
        elif size > WALL_SIZE_MAX:
            unit = "; is geometry.drawing_unit right?" if drawn else ""
            messages.append(f"{measured}, more than {WALL_SIZE_MAX:g} m (the longest buildings are a few hundred "
                            f"metres){unit}")
    messages += _friction(model)
    messages += _tunnel(model, extent["height"])
    messages += _building(model)
    if "block_young_modulus" in model:
        young = float(np.median(model.block_young_modulus.values[masonry]))
        if young > 0 and not _within(young, YOUNG_MODULUS):
            advice = _reading(young, YOUNG_MODULUS, [(1e6, "MPa were meant, in Pa"), (1e9, "GPa were meant, in Pa"),
                                                     (1e3, "kPa were meant, in Pa")])
            messages.append(f"material.young_modulus (block_young_modulus) = {young:.6g} Pa: masonry has "
                            f"{YOUNG_MODULUS[0] / 1e9:g}-{YOUNG_MODULUS[1] / 1e9:g} GPa{advice}")
    return messages


def _sizes(model: xr.Dataset, masonry: np.ndarray) -> tuple[dict[str, float], dict[str, float]]:
    """The median unit's length and height, and the masonry's width and height, of a 2D model [m]."""
    xmin, xmax, ymin, ymax = block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    return ({"length": float(np.median((xmax - xmin)[masonry])), "height": float(np.median((ymax - ymin)[masonry]))},
            {"width": float(xmax[masonry].max() - xmin[masonry].min()),
             "height": float(ymax[masonry].max() - ymin[masonry].min())})


def _sizes_3d(model: xr.Dataset, masonry: np.ndarray) -> tuple[dict[str, float], dict[str, float]]:
    """The same of a 3D model: a unit's length its longer side in plan, the width the longer side of the plan."""
    owner = np.repeat(np.arange(masonry.size), model.block_node_count.values)
    points = np.c_[model.node_x.values, model.node_y.values, model.node_z.values]
    low = np.full((masonry.size, 3), np.inf)
    high = np.full((masonry.size, 3), -np.inf)
    np.minimum.at(low, owner, points)
    np.maximum.at(high, owner, points)
    size = (high - low)[masonry]
    span = high[masonry].max(axis=0) - low[masonry].min(axis=0)
    return ({"length": float(np.median(size[:, :2].max(axis=1))), "height": float(np.median(size[:, 2]))},
            {"width": float(span[:2].max()), "height": float(span[2])})


def _friction(model: xr.Dataset) -> list[str]:
    """The joints' median friction angle, with the readings that would make it plausible: a coefficient or
    radians typed as the angle in degrees, or degrees typed as the coefficient."""
    if model.sizes.get("interface", 0) == 0:
        return []
    mu = float(np.median(model.interface_friction.values))
    angle = math.degrees(math.atan(mu))
    if _within(angle, FRICTION_ANGLE):
        return []
    readings = []
    if _within(math.degrees(math.atan(angle)), FRICTION_ANGLE):
        readings.append(f"the coefficient mu = {angle:.3g} ({math.degrees(math.atan(angle)):.3g} deg) given as "
                        "friction_angle (write friction = ...)")
    if _within(math.degrees(angle), FRICTION_ANGLE):
        readings.append(f"radians: {angle:.3g} rad is {math.degrees(angle):.3g} deg")
    if _within(mu, FRICTION_ANGLE):
        readings.append(f"degrees given as the coefficient: write friction_angle = {mu:.6g}")
    advice = f"; probably {' or '.join(readings)}" if readings else ""
    return [f"material.friction_angle (or friction) = {angle:.3g} deg (interface_friction mu = {mu:.6g}): masonry "
            f"joints have {FRICTION_ANGLE[0]:g}-{FRICTION_ANGLE[1]:g} deg{advice}"]


def _tunnel(model: xr.Dataset, height: float) -> list[str]:
    """A tunnel's volume loss, diameter and greenfield S_max against those of real tunnels and the wall."""
    profile = model_profile(model)
    if profile is None or profile.kind != "tunnel":
        return []
    messages = []
    if not _within(profile.volume_loss, VOLUME_LOSS):
        advice = _reading(profile.volume_loss, VOLUME_LOSS, [(100.0, "a fraction was given for a percentage")])
        messages.append(f"settlement.volume_loss = {profile.volume_loss:.6g} %: tunnels lose {VOLUME_LOSS[0]:g}-"
                        f"{VOLUME_LOSS[1]:g} % (0.5-3 % is common){advice}")
    if not _within(profile.diameter, TUNNEL_DIAMETER):
        messages.append(f"settlement.diameter = {profile.diameter:.6g} m: tunnels are {TUNNEL_DIAMETER[0]:g}-"
                        f"{TUNNEL_DIAMETER[1]:g} m across")
    if profile.target > height:
        messages.append(f"the greenfield S_max = {profile.target:.6g} m of the tunnel (settlement.volume_loss, "
                        f"diameter, depth, trough_width_factor) is more than the wall's height ({height:.6g} m)")
    return messages


def _building(model: xr.Dataset) -> list[str]:
    """A building's keys that the blocks do not show: the floors' line loads and the walls' thicknesses (read from
    the spec the model was built from)."""
    try:
        spec = read_spec(str(model.attrs.get("source_spec", "")))[0]
    except Exception:  # noqa: BLE001 - a model written by hand, or from an older spec: nothing to read
        return []
    building = spec.get("building") if isinstance(spec, dict) else None
    if not isinstance(building, dict):
        return []
    messages = []
    for k, floor in enumerate(building.get("floors", []) if isinstance(building.get("floors"), list) else []):
        load = floor.get("load") if isinstance(floor, dict) else None
        if isinstance(load, (int, float)) and load > 0 and not _within(load, FLOOR_LOAD):
            advice = _reading(load, FLOOR_LOAD, [(1e3, "kN/m were meant, in N/m")])
            messages.append(f"building.floors[{k}].load = {load:.6g} N/m: floors bear on walls with "
                            f"{FLOOR_LOAD[0] / 1e3:g}-{FLOOR_LOAD[1] / 1e3:g} kN/m{advice}")
    scale = {"m": 1.0, "cm": 0.01, "mm": 0.001}.get(spec.get("length_unit", "m"), 1.0)
    for k, wall in enumerate(building.get("walls", []) if isinstance(building.get("walls"), list) else []):
        thickness = wall.get("thickness") if isinstance(wall, dict) else None
        if isinstance(thickness, (int, float)) and not _within(thickness * scale, WALL_THICKNESS):
            messages.append(f"building.walls[{k}].thickness = {thickness:.6g} {spec.get('length_unit', 'm')}: "
                            f"masonry walls are {WALL_THICKNESS[0] * 1e3:g} mm to {WALL_THICKNESS[1]:g} m thick")
    return messages


def warn_implausible(model: xr.Dataset) -> None:
    """Issue a :class:`PlausibilityWarning` for each message of :func:`plausibility`."""
    for message in plausibility(model):
        warnings.warn(message, PlausibilityWarning, stacklevel=2)
