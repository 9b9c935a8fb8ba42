"""The engineers' assessment of a building over a greenfield trough, stages 1 and 2 (Mair, Taylor & Burland
1996), one definition for every result over a settlement profile.

**Stage 1, the screen**: the largest greenfield slope and settlement under the wall; a building whose slope
stays under 1/500 and settlement under 10 mm is screened out (negligible risk).

**Stage 2, the limiting tensile strain method (LTSM)**: the wall as a deep elastic beam that follows the
greenfield trough (Burland & Wroth 1974), with horizontal strain added (Boscardin & Cording 1989; Burland
1995). Exactly:

0. the wall is the horizontal extent ``[x_a, x_b]`` of the masonry resting on the ground and its height
   ``H`` (the masonry's vertical extent); the profile is the continuous greenfield ``S_v``, ``S_h`` at the
   settlement parameter t (not the support segments);
1. the wall's length is split at the trough's inflection points ``center +- i`` into sagging
   (``|x - center| < i``) and hogging parts (a profile without inflection points is one part, sagging where
   it lies below its chord); each part of length ``L`` is assessed on its own;
2. per part: ``Delta`` the largest distance of ``S_v`` from the chord joining the part's ends, and the
   average horizontal strain ``eps_h = (S_h(end) - S_h(start)) / L`` (tension positive);
3. a deep beam of height ``H``, ``E/G = 2.6``, ``nu = 0.3``; neutral axis at mid-height in sagging
   (``t = H/2, I = H^3/12``), at the bottom edge in hogging (``t = H, I = H^3/3``):
   ``eps_b = (Delta/L) / (L/(12 t) + 3 I E / (2 t L H G))``,
   ``eps_d = (Delta/L) / (1 + H L^2 G / (18 I E))``;
4. ``eps_br = eps_b + eps_h``, ``eps_dr = eps_h (1 - nu)/2 + sqrt(eps_h^2 ((1 + nu)/2)^2 + eps_d^2)``; the
   LTSM strain is the largest of ``eps_br``, ``eps_dr`` over the parts and its category counts the limits
   0.05 %, 0.075 %, 0.15 %, 0.3 % it reaches (``strain >= limit``: 0 negligible .. 4 severe to very
   severe; the LTSM does not separate categories 4 and 5).

Every quantity is linear in t, so a history's LTSM is its value at t = 1 times each record's settlement.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..format.model3d import space
from ..format.roles import masonry_blocks, support_blocks
from ..format.schema import variable_attrs
from ..geometry.polygons import block_bounds
from .ground_plan import SurfaceCut, ground_in_plan
from .profiles import Profile, model_profile

if TYPE_CHECKING:  # annotations only
    import xarray as xr

#: Limiting tensile strains of LTSM categories 1 to 4 (Boscardin & Cording 1989; Burland 1995).
LTSM_LIMITS = (5.0e-4, 7.5e-4, 1.5e-3, 3.0e-3)
E_OVER_G = 2.6
#: Poisson's ratio of the deep beam of the LTSM (Burland & Wroth 1974: E/G = 2.6 for masonry).
POISSON = 0.3
#: Stage 1: a building is screened out when its greenfield slope and settlement stay under these.
SCREEN_SLOPE = 1.0 / 500.0
SCREEN_SETTLEMENT = 0.010  # m
#: Points per part at which the profile is evaluated (Delta's error ~ (L / n)^2 S_v'' / 8).
SAMPLES = 4001


@dataclass(frozen=True)
class Part:
    """One sagging or hogging part of the wall and its LTSM strains per unit of the settlement parameter."""

    start: float
    end: float
    sagging: bool
    deflection_ratio: float  # Delta / L
    horizontal_strain: float  # eps_h, tension positive
    bending_strain: float  # eps_br = eps_b + eps_h
    diagonal_strain: float  # eps_dr
    wall: str = ""  # a building's wall the part belongs to (its coordinates are along that wall's base line)

    @property
    def strain(self) -> float:
        return max(self.bending_strain, self.diagonal_strain)


def deep_beam_strains(deflection_ratio: float, length: float, height: float, sagging: bool) -> tuple[float, float]:
    """``(eps_b, eps_d)``: the extreme bending and diagonal strains of the deep beam of step 3 (module docstring)
    bent to ``deflection_ratio`` over ``length``."""
    t, inertia = (height / 2.0, height**3 / 12.0) if sagging else (height, height**3 / 3.0)
    bending = deflection_ratio / (length / (12.0 * t) + 3.0 * inertia * E_OVER_G / (2.0 * t * length * height))
    diagonal = deflection_ratio / (1.0 + height * length**2 / (18.0 * inertia * E_OVER_G))
    return bending, diagonal


def combined_strains(bending: float, diagonal: float, horizontal: float) -> tuple[float, float]:
    """``(eps_br, eps_dr)`` of step 4: horizontal strain added to the bending and the diagonal strain."""
    nu = POISSON
    return (bending + horizontal,
            horizontal * (1.0 - nu) / 2.0 + math.sqrt(horizontal**2 * ((1.0 + nu) / 2.0) ** 2 + diagonal**2))


def ltsm_category(strain) -> np.ndarray:
    """int8 LTSM category 0..4 of strains: the number of :data:`LTSM_LIMITS` reached."""
    return np.searchsorted(np.array(LTSM_LIMITS), np.asarray(strain, dtype=float), side="right").astype(np.int8)


def _splits(profile: Profile | SurfaceCut, x_a: float, x_b: float) -> list[float]:
    """The part ends: the wall's ends and the inflection points between them."""
    if isinstance(profile, SurfaceCut):
        inner = profile.inflections(x_a, x_b, SAMPLES)
    else:
        inner = [profile.center - profile.width, profile.center + profile.width] if profile.kind in TROUGHS else []
    return [x_a, *sorted(x for x in inner if x_a < x < x_b), x_b]


#: Profiles with inflection points at ``center +- width``.
TROUGHS = ("gaussian", "tunnel")


def _largest(f, a: float, b: float) -> float:
    """The largest value of ``f`` on ``[a, b]``: the best of :data:`SAMPLES` points, refined by the parabola
    through it and its neighbours (the error of a smooth maximum falls from O(h^2) to O(h^3))."""
    x = np.linspace(a, b, SAMPLES)
    y = f(x)
    k = int(np.argmax(y))
    if 0 < k < x.size - 1:
        curvature = y[k - 1] - 2.0 * y[k] + y[k + 1]
        if curvature < 0:
            shift = 0.5 * (y[k - 1] - y[k + 1]) / curvature
            return float(max(y[k], f(np.array([x[k] + shift * (x[1] - x[0])]))[0]))
    return float(y[k])


def ltsm_parts(profile: Profile | SurfaceCut, x_a: float, x_b: float, height: float) -> list[Part]:
    """The sagging and hogging parts of a wall ``[x_a, x_b]`` of ``height`` over ``profile`` at t = 1."""
    ends = _splits(profile, x_a, x_b)
    parts = []
    for start, end in zip(ends[:-1], ends[1:]):
        length = end - start
        if length <= 0:
            continue
        s0, s1 = profile.rate(np.array([start, end]))

        def offset(x, s0=s0, s1=s1, start=start, length=length):  # > 0 where the ground lies below its chord
            return profile.rate(x) - (s0 + (s1 - s0) * (x - start) / length)

        below, above = _largest(offset, start, end), _largest(lambda x, f=offset: -f(x), start, end)
        mid = 0.5 * (start + end)
        sagging = abs(mid - profile.center) < profile.width if isinstance(profile, Profile) and \
            profile.kind in TROUGHS else below >= above
        ratio = max(below, above) / length
        horizontal = float(profile.horizontal(np.array([end]))[0] - profile.horizontal(np.array([start]))[0]) / length
        bending, diagonal = deep_beam_strains(ratio, length, height, sagging)
        parts.append(Part(start, end, sagging, ratio, horizontal, *combined_strains(bending, diagonal, horizontal)))
    return parts


def wall_extent(model: xr.Dataset) -> tuple[float, float, float]:
    """``(x_a, x_b, H)``: the horizontal extent of the masonry resting on the ground (its joints with the
    supports) and the masonry's height."""
    role = np.asarray(model.block_role.values)
    ground = support_blocks(role)
    sides = np.asarray(model.interface_blocks.values, dtype=np.int64)
    on_ground = ground[sides].any(axis=1) & ~ground[sides].all(axis=1)
    x = np.asarray(model.interface_x.values)[on_ground]
    masonry = masonry_blocks(role)
    _, _, ymin, ymax = block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    return float(x.min()), float(x.max()), float(ymax[masonry].max() - ymin[masonry].min())


def greenfield_screen(profile: Profile | SurfaceCut, x_a: float, x_b: float) -> tuple[float, float]:
    """Stage 1 at t = 1: ``(largest |slope|, largest settlement)`` of the greenfield profile over the wall."""
    x = np.linspace(x_a, x_b, SAMPLES)
    settled = profile.rate(x)
    return float(np.abs(np.gradient(settled, x)).max()), float(settled.max())


@dataclass(frozen=True)
class Assessment:
    """Stages 1 and 2 of a wall over its greenfield profile at one settlement parameter t."""

    settlement: float  # t [m]
    slope: float  # the largest greenfield slope under the wall
    greenfield_settlement: float  # the largest greenfield settlement under the wall [m]
    parts: tuple[Part, ...]  # per unit t

    @property
    def screened_out(self) -> bool:
        """Stage 1: slope under 1/500 and settlement under 10 mm, negligible risk."""
        return self.slope < SCREEN_SLOPE and self.greenfield_settlement < SCREEN_SETTLEMENT

    @property
    def strain(self) -> float:
        """The LTSM strain: the largest over the parts."""
        return abs(self.settlement) * max((p.strain for p in self.parts), default=0.0)

    @property
    def category(self) -> int:
        return int(ltsm_category(self.strain))


def assess(model: xr.Dataset, settlement: float) -> Assessment | None:
    """Stages 1 and 2 of ``model``'s wall over its greenfield profile (``mf.model_profile``) at ``settlement``;
    None for a model built without a profile, and for a 3D model that is not a building (a drawing's blocks do
    not say which walls to assess)."""
    profile = model_profile(model)
    if profile is None:
        return None
    if "building_walls" in model.attrs:
        return assess_building(model, profile, settlement)
    if space(model) == 3:
        return None
    x_a, x_b, height = wall_extent(model)
    slope, settled = greenfield_screen(profile, x_a, x_b)
    return Assessment(settlement, abs(settlement) * slope, abs(settlement) * settled,
                      tuple(ltsm_parts(profile, x_a, x_b, height)))


def assess_building(model: xr.Dataset, profile: Profile, settlement: float) -> Assessment:
    """Stages 1 and 2 of a building: its largest slope, settlement and strain are its worst wall's
    (:func:`assess_walls`)."""
    walls = assess_walls(model, settlement, profile)
    return Assessment(settlement, max((w.slope for w in walls.values()), default=0.0),
                      max((w.greenfield_settlement for w in walls.values()), default=0.0),
                      tuple(part for w in walls.values() for part in w.parts))


def assess_walls(model: xr.Dataset, settlement: float, profile: Profile | None = None) -> dict[str, Assessment]:
    """Stages 1 and 2 of every wall of a building (its ``building_walls``, in their order, by name) over the
    greenfield profile in plan (``settlement_axis``): each wall's line cut from the greenfield surface
    (:func:`wall_profile`; with a tunnel's face, a :class:`SurfaceCut`), its own length and height; empty for
    a model that is no building or has no profile."""
    profile = model_profile(model) if profile is None else profile
    ground = ground_in_plan(model)
    if profile is None or ground is None or "building_walls" not in model.attrs:
        return {}
    point, direction = ground.point, ground.across
    walls = {}
    for wall in json.loads(model.attrs["building_walls"]):
        start, end = np.array(wall["start"]), np.array(wall["end"])
        along = (end - start) / np.linalg.norm(end - start)
        x_a, x_b = wall["ground"]
        cut: Profile | SurfaceCut | None = SurfaceCut(ground, start, along) if ground.face is not None else \
            wall_profile(profile, float((start - point) @ direction), float(along @ direction))
        if cut is None:  # the wall runs along the trough's axis: its ground settles uniformly
            uniform = float(profile.rate(np.array([(start - point) @ direction]))[0])
            walls[wall["name"]] = Assessment(settlement, 0.0, abs(settlement) * uniform, ())
            continue
        slope, most = greenfield_screen(cut, x_a, x_b)
        parts = tuple(replace(part, wall=wall["name"]) for part in ltsm_parts(cut, x_a, x_b, wall["height"]))
        walls[wall["name"]] = Assessment(settlement, abs(settlement) * slope, abs(settlement) * most, parts)
    return walls


#: A wall within this cosine of the trough's axis has a uniform greenfield settlement along it.
PARALLEL = 1e-9


def wall_profile(profile: Profile, offset: float, cosine: float) -> Profile | None:
    """The greenfield profile along a wall whose base line starts ``offset`` across the axis and runs at
    ``cosine`` to the profile's direction: the profile coordinate is ``u = offset + cosine * s`` along the wall,
    so a trough's centre moves to ``(center - offset) / cosine``, its width grows to ``width / |cosine|`` and its
    horizontal movement (towards the axis, ``-(u - c) / z0 * rate``) along the wall is that of a depth
    ``z0 / cosine^2``; None for a wall along the axis (no curvature, no horizontal strain along it)."""
    if abs(cosine) <= PARALLEL:
        return None

    def along(u: float) -> float:
        return (u - offset) / cosine

    if profile.kind in TROUGHS:
        return replace(profile, center=along(profile.center), width=profile.width / abs(cosine),
                       depth=None if profile.depth is None else profile.depth / cosine**2)
    if profile.kind in ("linear", "step"):
        start, end = along(profile.start), along(profile.end)
        return replace(profile, start=start, end=end) if profile.kind == "linear" else \
            replace(profile, start=min(start, end), end=max(start, end))
    points = sorted((along(u), rate) for u, rate in profile.points)
    return replace(profile, points=tuple(points))


def ltsm_variables(model: xr.Dataset, settlement: np.ndarray) -> dict[str, tuple]:
    """``step_ltsm_strain`` and ``step_ltsm_category`` at every record's settlement (linear in t), or nothing
    for a model built without a profile."""
    unit = assess(model, 1.0)
    if unit is None:
        return {}
    strain = np.abs(np.asarray(settlement, dtype=float)) * unit.strain
    return {"step_ltsm_strain": ("step", strain, variable_attrs("step_ltsm_strain")),
            "step_ltsm_category": ("step", ltsm_category(strain), variable_attrs("step_ltsm_category"))}


# ---------------------------------------------------------------- where each category is first reached

def ltsm_thresholds(model: xr.Dataset) -> np.ndarray | None:
    """Stage 2 backwards: the settlement parameter t [m] at which the LTSM strain first reaches each limit of
    :data:`LTSM_LIMITS` (categories 1 to 4; inf where the strain stays zero), None without a profile."""
    unit = assess(model, 1.0)
    return None if unit is None else unit_ltsm_thresholds(unit)


def unit_ltsm_thresholds(unit: Assessment) -> np.ndarray:
    """:func:`ltsm_thresholds` of one assessment at t = 1 (a wall's, a building's)."""
    with np.errstate(divide="ignore"):
        return np.array(LTSM_LIMITS) / unit.strain if unit.strain > 0 else np.full(len(LTSM_LIMITS), np.inf)


def screen_threshold(model: xr.Dataset) -> float | None:
    """Stage 1 backwards: the smallest t [m] at which the wall is no longer screened out (the greenfield slope
    reaches 1/500 or the settlement 10 mm under it), None without a profile."""
    unit = assess(model, 1.0)
    return None if unit is None else unit_screen_threshold(unit)


def unit_screen_threshold(unit: Assessment) -> float:
    """:func:`screen_threshold` of one assessment at t = 1 (a wall's, a building's)."""
    bounds = [limit / value for limit, value in ((SCREEN_SLOPE, unit.slope),
                                                 (SCREEN_SETTLEMENT, unit.greenfield_settlement)) if value > 0]
    return min(bounds, default=math.inf)


def volume_loss_per_settlement(model: xr.Dataset) -> float | None:
    """A tunnel's volume loss [%] per metre of its S_max (the trough keeps its shape: S_max is proportional to
    V_L), None for any other model."""
    profile = model_profile(model)
    if profile is None or profile.kind != "tunnel" or not profile.target or profile.volume_loss is None:
        return None
    return profile.volume_loss / profile.target
