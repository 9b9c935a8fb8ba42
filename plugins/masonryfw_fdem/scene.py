"""From a model dataset to the flat non-dimensional arrays of the rigid-block kernels.

Units inside the solver: lengths over ``length`` (the model's bounding-box
diagonal), forces over ``force`` (the total weight of the masonry), time over
``sqrt(length / g)``. Masses become weight shares (``m g / W``), so gravity has
unit acceleration. A wall given in mm or in m, or scaled as a whole with its
loads, gives the same non-dimensional problem.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

GRAVITY = 9.81  # m s-2: turns unit weights into masses
ROLE = mfp.ROLE


@dataclass(frozen=True)
class Scales:
    length: float  # m
    force: float  # N
    time: float  # s

    @property
    def velocity(self) -> float:
        return self.length / self.time


@dataclass
class Scene:
    """Flat non-dimensional arrays of one model (see the module docstring)."""

    scales: Scales
    model: xr.Dataset  # the checked model the scene was built from
    offs: np.ndarray  # (block + 1) node offsets
    lx: np.ndarray  # node coordinates relative to the block centroid
    ly: np.ndarray
    pos0: np.ndarray  # (block, 3) centroid x, y and rotation at rest
    radius: np.ndarray  # largest centroid-vertex distance
    perimeter: np.ndarray
    mass: np.ndarray  # (block, 3): m, m, I
    inv_mass: np.ndarray  # (block,) 1 / m, 0 on driven blocks
    free: np.ndarray  # (block, 3) bool: component free to move (never on driven blocks)
    driven: np.ndarray  # (block,) bool: supports, whose motion is imposed
    moving: np.ndarray  # (block,) bool: moving supports
    direction: np.ndarray  # (block, 3) settlement direction (rotation per unit length)
    dead: np.ndarray  # (block, 3) dead load on free blocks
    live: np.ndarray  # (block, 3) live load on free blocks
    unit_height: float  # median height of the masonry blocks
    support_length: float  # wall-on-support contact length
    joints: mfp.PairIndex  # the model's interfaces, found by their two blocks
    friction: np.ndarray
    cohesion_per_length: np.ndarray  # c * thickness, non-dimensional
    tension_per_length: np.ndarray  # ft * thickness, non-dimensional
    default_friction: float

    DOFS = 3  # a block's force and moment components
    VERTICAL = 1  # the up component

    @property
    def base_pressure(self) -> float:
        """The masonry's weight over its contact length with the supports."""
        return 1.0 / self.support_length

    def masonry_height(self) -> float:
        """Top of the highest minus bottom of the lowest free block (non-dimensional)."""
        y = self.pos0[:, 1][np.repeat(np.arange(self.driven.size), np.diff(self.offs))] + self.ly
        free_nodes = ~np.repeat(self.driven, np.diff(self.offs))
        return float(np.ptp(y[free_nodes]))

    def critical_time_step(self, kn: float) -> float:
        """2 / omega_max, omega^2 bounded per free block by the stiffness of springs all round its perimeter:
        kn P / m in translation, kn P R^2 / I in rotation."""
        free = ~self.driven
        translation = kn * self.perimeter[free] / self.mass[free, 0]
        rotation = kn * self.perimeter[free] * self.radius[free] ** 2 / self.mass[free, 2]
        omega = np.sqrt(max(translation.max(initial=0.0), rotation.max(initial=0.0)))
        return 2.0 / omega if omega > 0 else np.inf


def build_scene(model: xr.Dataset) -> Scene:
    """The non-dimensional arrays of ``model``; raises ModelError on what the method cannot take."""
    role = model.block_role.values.astype(np.int64)
    n_block = role.size
    driven = mfp.support_blocks(role)
    moving = mfp.moving_blocks(role)
    offs = mfp.block_offsets(model.block_node_count.values)
    area = model.block_area.values
    thickness = model.block_thickness.values
    weight = model.block_unit_weight.values * area * thickness
    total = float(weight[~driven].sum())
    if not total > 0:
        raise mf.ModelError("block_unit_weight: the masonry blocks weigh nothing; fdem needs their masses")
    length = mfp.model_scales(model).length
    weightless = np.flatnonzero(~driven & ~(weight > 0))
    if weightless.size:
        raise mf.ModelError(
            f"block(s) {mfp.listed(weightless)}: block_unit_weight * area * thickness is not positive; "
            "a free block needs a mass in fdem"
        )
    scales = Scales(length=length, force=total, time=float(np.sqrt(length / GRAVITY)))

    cx, cy = model.block_centroid_x.values, model.block_centroid_y.values
    owner = mfp.node_block(model.block_node_count.values)
    lx = (model.node_x.values - cx[owner]) / length
    ly = (model.node_y.values - cy[owner]) / length
    radius = np.maximum.reduceat(np.hypot(lx, ly), offs[:-1])
    nxt = np.arange(lx.size) + 1
    nxt[offs[1:] - 1] = offs[:-1]
    perimeter = np.add.reduceat(np.hypot(lx[nxt] - lx, ly[nxt] - ly), offs[:-1])
    mass_share = weight / total
    polar = mfp.polar_moment(model.node_x.values, model.node_y.values, model.block_node_count.values)
    inertia = mass_share * polar / np.where(area > 0, area * length**2, 1.0)
    mass = np.stack((mass_share, mass_share, inertia), axis=1)
    mass[driven] = 1.0  # never used: driven blocks follow their imposed motion

    free = (model.block_fixed.values == 0) & ~driven[:, None]
    direction = model.settlement_direction.values.astype(float).copy()
    direction[:, 2] *= length
    direction[~moving] = 0.0
    load_scale = np.array([total, total, total * length])
    dead = np.where(driven[:, None], 0.0, mfp.block_loads(model, "dead") / load_scale)
    live = np.where(driven[:, None], 0.0, mfp.block_loads(model, "live") / load_scale)

    height = np.maximum.reduceat(ly, offs[:-1]) - np.minimum.reduceat(ly, offs[:-1])
    unit_height = float(np.median(height[~driven]))
    sides = model.interface_blocks.values.astype(np.int64)
    on_support = driven[sides].any(axis=1)
    support_length = float(model.interface_length.values[on_support].sum()) / length
    if not support_length > 0:
        support_length = float(np.ptp(model.node_x.values)) / length

    t_pair = np.minimum(thickness[sides[:, 0]], thickness[sides[:, 1]])
    per_length = t_pair * length / total
    friction = model.interface_friction.values.astype(float)
    return Scene(
        scales=scales,
        model=model,
        offs=offs.astype(np.int64),
        lx=lx,
        ly=ly,
        pos0=np.stack((cx / length, cy / length, np.zeros(n_block)), axis=1),
        radius=radius,
        perimeter=perimeter,
        mass=mass,
        inv_mass=np.where(driven, 0.0, 1.0 / np.where(driven, 1.0, mass_share)),
        free=free,
        driven=driven,
        moving=moving,
        direction=direction,
        dead=dead,
        live=live,
        unit_height=unit_height,
        support_length=support_length,
        joints=mfp.pair_index(sides, n_block),
        friction=friction,
        cohesion_per_length=model.interface_cohesion.values * per_length,
        tension_per_length=model.interface_tensile_strength.values * per_length,
        default_friction=float(np.median(friction)) if friction.size else 0.0,
    )


def face_properties(scene: Scene, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(face, 4) friction, cohesion, tensile strength (per unit length), model interface index
    (-1 if none) of each face pair; and whether each pair starts bonded.

    A face pair between two blocks that share a model interface takes that
    interface's properties; blocks that only meet during the motion get the
    model's median friction and no cohesion.
    """
    interface = mfp.find_pairs(scene.joints, faces[:, [0, 2]])
    hit = interface >= 0
    props = np.zeros((faces.shape[0], 4))
    props[:, 0] = np.where(hit, scene.friction[interface], scene.default_friction)
    props[:, 1] = np.where(hit, scene.cohesion_per_length[interface], 0.0)
    props[:, 2] = np.where(hit, scene.tension_per_length[interface], 0.0)
    props[:, 3] = interface
    bonded = (props[:, 1] > 0) | (props[:, 2] > 0)
    return props, bonded
