"""A kit for solver authors (and the project's own tests): small models, and a conformance suite.

Small models from rectangles (and a semicircular arch, :func:`arch_model`)::

    import masonryfw.testing as mt

    model = mt.rectangles_model(
        [(0.0, -0.1, 0.6, 0.0), (0.6, -0.1, 1.0, 0.0), (0.0, 0.0, 1.0, 0.2)],
        ["fixed_support", "moving_support", "unit"],
    )

The conformance suite checks a solver against the contract every masonryfw
solver keeps (docs/format.md, ``masonryfw.contract.hookspecs``). In the plugin's tests::

    from masonryfw.testing import SolverConformance

    class TestToy(SolverConformance):
        solver = "toy"               # its registered name
        options = {"scale": 2.0}     # options for a quick run (default: its defaults)

It checks that the result passes :func:`masonryfw.check` with the schema's
names, dims and units, that every variable it adds has ``units`` and a
``long_name``, that progress is reported in [0, 1], that an interruption
(``KeyboardInterrupt`` raised from the progress callback) either propagates or
returns a result marked ``interrupted = 1``, that every declared option's
default obeys its own rules and that values breaking them are refused, and that
the solve depends neither on the order of the blocks nor on mm against m (to a
relative ``invariance_tolerance`` of the key numbers). Needs pytest.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from .builders import blocks
from .builders.kinds import build
from .format.model import checked_model
from .format.roles import ROLE, fixed_blocks, support_blocks
from .readers.material import Material

if TYPE_CHECKING:  # annotations only
    import xarray as xr



def rectangles_model(
    rects: Sequence[Sequence[float]],
    roles: Sequence[str | int],
    *,
    friction: float = 0.4,
    unit_weight: float = 12e3,
    thickness: float = 0.1,
    loading: str = "settlement",
    cohesion: float = 0.0,
    tensile_strength: float = 0.0,
    young_modulus: float | None = None,
    poisson_ratio: float | None = None,
    motions: Mapping[int, tuple[str, tuple[float, float] | None]] | None = None,
    length_unit: float = 1.0,
    title: str = "test wall",
) -> xr.Dataset:
    """A checked model of axis-aligned rectangles ``(x0, y0, x1, y1)`` [m], one role each.

    Roles are the format's (``unit``, ``lintel``, ``fixed_support``,
    ``moving_support``, names or flags). Moving supports translate straight down
    unless ``motions`` maps their block index to ``("rotation", pivot)`` or ``("translation", (dx, dy))``
    (along that direction: a springing moving out).
    ``loading``: ``settlement`` (the paper's) or ``tilt`` (horizontal live load =
    weight, supports held). ``length_unit`` scales the coordinates and thickness
    (1e3: the same wall in mm, with unit weight, cohesion, tensile strength and
    Young's modulus rescaled so that the loads in N and the strains are the same).
    """
    rects = np.asarray(rects, dtype=float).reshape(-1, 4) * length_unit
    role = np.array([ROLE[r] if isinstance(r, str) else int(r) for r in roles], dtype=np.int8)
    if role.size != rects.shape[0]:
        raise ValueError(f"{rects.shape[0]} rectangles but {role.size} roles")
    motions = dict(motions or {})
    supports = []
    for b in np.flatnonzero(support_blocks(role)):
        if fixed_blocks(role[b]):
            supports.append(blocks.Support(f"support block {b}"))
        else:
            motion, point = motions.get(int(b), ("translation", None))
            if motion == "translation":  # the point, if given, is the direction it moves in
                direction = (0.0, -1.0) if point is None else tuple(np.asarray(point, float) / np.hypot(*point))
                supports.append(blocks.Support(f"support block {b}", "moving", motion, direction=direction))
                continue
            pivot = None if point is None else (point[0] * length_unit, point[1] * length_unit)
            supports.append(blocks.Support(f"support block {b}", "moving", motion, pivot))
    material = Material(unit_weight / length_unit**3, friction, cohesion / length_unit**2,
                               tensile_strength / length_unit**2,
                               None if young_modulus is None else young_modulus / length_unit**2, poisson_ratio)
    x0, y0, x1, y1 = rects.T
    ds = blocks.model_from_blocks(*blocks.rectangle_nodes(x0, x1, y0, y1), role, thickness * length_unit,
                                  material, supports, loading, attrs={"title": title})
    return checked_model(ds, repr(title))


def small_settlement_wall(length_unit: float = 1.0) -> xr.Dataset:
    """Three courses of 0.2 x 0.1 m units in running bond, 0.8 m wide, the right 0.3 m of the base settling."""
    rects, roles = [], []
    for course in range(3):
        y = 0.1 * course
        cuts = [0.0, 0.2, 0.4, 0.6, 0.8] if course % 2 == 0 else [0.0, 0.1, 0.3, 0.5, 0.7, 0.8]
        rects += [(a, y, b, y + 0.1) for a, b in zip(cuts[:-1], cuts[1:])]
        roles += ["unit"] * (len(cuts) - 1)
    rects += [(0.0, -0.1, 0.5, 0.0), (0.5, -0.1, 0.8, 0.0)]
    roles += ["fixed_support", "moving_support"]
    return rectangles_model(rects, roles, young_modulus=1.2e9, poisson_ratio=0.2, length_unit=length_unit,
                            title="conformance wall")


def arch_model(thickness_ratio: float, voussoirs: int = 40, radius: float = 1.0, friction: float = 0.8,
               spreading: bool = True) -> xr.Dataset:
    """A semicircular arch of ``voussoirs`` equal voussoirs, mean radius ``radius`` and thickness
    ``thickness_ratio * radius`` (0.1 m deep, 20 kN/m3), on two springings: the left one fixed, the right
    one moving out to the right (``spreading``) or down. A semicircular arch stands under its own weight
    only from ``thickness_ratio`` = 0.1075 on (Milankovitch 1907; Heyman 1969: 0.106)."""
    inner, outer = radius * (1 - thickness_ratio / 2), radius * (1 + thickness_ratio / 2)
    angles = np.linspace(np.pi, 0.0, voussoirs + 1)
    a0, a1 = angles[1:, None], angles[:-1, None]  # a0 < a1, left to right
    xs = np.hstack([outer * np.cos(a0), outer * np.cos(a1), inner * np.cos(a1), inner * np.cos(a0)])
    ys = np.hstack([outer * np.sin(a0), outer * np.sin(a1), inner * np.sin(a1), inner * np.sin(a0)])
    depth, overhang = 0.2 * radius, 0.05 * radius
    for x0, x1 in ((-outer - overhang, -inner + overhang), (inner - overhang, outer + overhang)):
        xs = np.vstack([xs, [x0, x1, x1, x0]])
        ys = np.vstack([ys, [-depth, -depth, 0.0, 0.0]])
    role = np.array([ROLE["voussoir"]] * voussoirs + [ROLE["fixed_support"], ROLE["moving_support"]], np.int8)
    supports = [blocks.Support("left springing"),
                blocks.Support("right springing", "moving", "translation",
                               direction=(1.0, 0.0) if spreading else (0.0, -1.0))]
    ds = blocks.model_from_blocks(xs.ravel(), ys.ravel(), np.full(voussoirs + 2, 4), role, 0.1,
                                  Material(20e3, friction), supports, "settlement",
                                  attrs={"title": f"semicircular arch, t/R = {thickness_ratio:g}"})
    return checked_model(ds, "arch")


def corner_building(bond: str = "running", angle: float = 90.0) -> xr.Dataset:
    """A small building in 3D (:mod:`masonryfw.builders.building`): two walls toothed at a corner (``angle`` degrees between
    them), 1.44 and 1.2 m long and 0.96 m high in 0.24 x 0.12 m units, a door in the first, over a trough whose
    axis runs at 30 degrees to x; one leaf (0.12 m) thick in running ``bond``, two leaves (0.24 m) in English or
    Flemish."""
    thickness = 0.12 if bond == "running" else 0.24
    turn = math.radians(angle)
    end = [1.44 - 1.2 * math.cos(turn), 1.2 * math.sin(turn)]
    walls = [{"name": "a", "start": [0.0, 0.0], "end": [1.44, 0.0], "height": 0.96, "thickness": thickness,
              "openings": [{"x": 0.48, "y": 0.0, "width": 0.48, "height": 0.6}]},
             {"name": "b", "start": [1.44, 0.0], "end": end, "height": 0.96, "thickness": thickness}]
    return build({"title": "corner", "building": {"unit": {"length": 0.24, "height": 0.12, "depth": 0.12},
                                                  "walls": walls, "bond": bond},
                  "material": {"unit_weight": 20000.0, "friction_angle": 30.0},
                  "settlement": {"profile": "gaussian", "width": 0.6, "axis_angle": 30.0, "center_x": 1.4,
                                 "center_y": 0.2}})


def permuted(model: xr.Dataset, block_order: np.ndarray, interface_order: np.ndarray) -> xr.Dataset:
    """The same model with its blocks and interfaces listed in another order (a checked model; in 3D each
    interface keeps its polygon)."""
    counts = model.block_node_count.values.astype(np.int64)
    start = np.concatenate(([0], np.cumsum(counts)))
    nodes = np.concatenate([np.arange(start[b], start[b + 1]) for b in block_order])
    new_index = np.empty_like(block_order)
    new_index[block_order] = np.arange(block_order.size)
    ragged = {"node": nodes}
    if "interface_node_count" in model:  # 3D: the interfaces' polygons follow their interfaces
        count = model.interface_node_count.values.astype(np.int64)
        first = np.concatenate(([0], np.cumsum(count)))
        ragged["interface_node"] = np.concatenate([np.arange(first[i], first[i + 1]) for i in interface_order])
    ds = model.isel(block=block_order, interface=interface_order, **ragged)
    ds = ds.assign(interface_blocks=(("interface", "side"), new_index[ds.interface_blocks.values].astype(np.int32),
                                     ds.interface_blocks.attrs))
    return checked_model(ds)


def scaled(model: xr.Dataset, factor: float) -> xr.Dataset:
    """The same model with every length times ``factor`` and the loads [N], strains and strengths kept."""
    lengths = ("node_x", "node_y", "interface_x", "interface_y", "block_thickness")
    per_area = ("interface_cohesion", "interface_tensile_strength", "block_young_modulus")
    changed = {name: model[name] * factor for name in lengths}
    changed.update({name: model[name] / factor**2 for name in per_area if name in model})
    changed["block_unit_weight"] = model.block_unit_weight / factor**3
    changed["dead_moment"] = model.dead_moment * factor
    changed["live_moment"] = model.live_moment * factor
    rotation = model.settlement_direction.values.copy()
    rotation[:, 2] /= factor  # rad per metre of the settlement parameter
    changed["settlement_direction"] = model.settlement_direction.copy(data=rotation)
    return checked_model(model.assign(changed))


def __getattr__(name: str):
    """:class:`SolverConformance` from :mod:`masonryfw.conformance` (which imports pytest) when it is asked for."""
    if name == "SolverConformance":
        from .conformance import SolverConformance

        return SolverConformance
    raise AttributeError(f"module 'masonryfw.testing' has no attribute {name!r}")
