"""The masonry's fabric: the direction of every block's bed joints, and the units' size along and across it.

The Jointed Masonry Model has two joint planes per point: the bed plane and the head
plane across it. In a wall of courses the bed joints are horizontal; in an arch they
are the radial joints between voussoirs; in irregular masonry they follow the stones.
So every block takes its **bed direction from its own joints**: the mean direction of
the interfaces around it, each weighted by its length times the vertical component of
its normal, ``w = L |n_y|`` (the joints that carry weight, across which gravity acts;
directions are axial, so the mean is taken on doubled angles:
``theta = atan2(sum w sin 2 phi, sum w cos 2 phi) / 2``). A unit of a course, however
tall, gets the direction of its beds (its head joints weigh nothing); a voussoir's two
radial joints give the radial direction between them, the keystone's nearly vertical
ones included. A block whose joints are all vertical weighs them by length alone; one
without joints, or whose joints cancel out, keeps the horizontal. A **voussoir** (the
``voussoir`` role: a unit of an arch or flat arch laid in a wall) takes the mean of its
joints with the voussoirs beside it alone, weighted by length: embedded in a wall, its
extrados joint with the courses above would otherwise outweigh its radial joints, and a
ring whose beds run along it carries no thrust (a gable house's arched and flat-arched
heads did not stand under their own weight, measured).

A joint of a block is a **head joint** of it when it runs more than 45 deg off the
block's bed direction. A block without head joints (a voussoir of a one-ring arch, a
unit as wide as its pier) has no head plane: the material across its beds is the unit
itself, so its points check the bed faces only.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

import masonryfw.plugin_api as mfp


def bed_angles(model: xr.Dataset) -> np.ndarray:
    """``(block,)`` bed direction [rad] in ``(-pi/2, pi/2]`` (module docstring)."""
    sides = model.interface_blocks.values.astype(np.int64)
    dx = model.interface_x.values[:, 1] - model.interface_x.values[:, 0]
    dy = model.interface_y.values[:, 1] - model.interface_y.values[:, 0]
    doubled = 2.0 * np.arctan2(dy, dx)
    length = np.hypot(dx, dy)
    n = model.sizes["block"]

    def mean_direction(weight):
        cos2 = np.bincount(sides.ravel(), np.repeat(weight * np.cos(doubled), 2), minlength=n)
        sin2 = np.bincount(sides.ravel(), np.repeat(weight * np.sin(doubled), 2), minlength=n)
        total = np.bincount(sides.ravel(), np.repeat(weight, 2), minlength=n)
        return 0.5 * np.arctan2(sin2, cos2), np.hypot(cos2, sin2) > 1e-9 * np.maximum(total, 1e-300)

    carrying, by_carrying = mean_direction(np.abs(dx))  # L |n_y| = |dx|
    any_joint, by_length = mean_direction(length)
    voussoir = model.block_role.values == mfp.ROLE["voussoir"]
    radial, by_radial = mean_direction(length * voussoir[sides].all(axis=1))  # the joints between voussoirs
    angle = np.where(by_carrying, carrying, np.where(by_length, any_joint, 0.0))
    angle = np.where(voussoir & by_radial, radial, angle)
    angle[np.abs(angle) < 1e-12] = 0.0  # level beds are exactly level: no rotation at all (problem.bed_rotations)
    return np.where(angle <= -np.pi / 2 + 1e-12, angle + np.pi, angle)


def head_joints(model: xr.Dataset, angle: np.ndarray) -> np.ndarray:
    """``(block,)`` whether the block has a joint more than 45 deg off its bed direction (a head joint)."""
    sides = model.interface_blocks.values.astype(np.int64)
    direction = np.arctan2(np.diff(model.interface_y.values, axis=1)[:, 0],
                           np.diff(model.interface_x.values, axis=1)[:, 0])
    off = np.abs(np.sin(direction[:, None] - angle[sides])) >= np.sqrt(0.5)  # (interface, side)
    return np.bincount(sides.ravel(), off.ravel(), minlength=model.sizes["block"]) > 0


def extents_along(model: xr.Dataset, angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(length, height)`` of every block: its extent along its bed direction and across it."""
    counts = model.block_node_count.values
    owner = np.repeat(np.arange(counts.size), counts)
    c, s = np.cos(angle)[owner], np.sin(angle)[owner]
    x, y = model.node_x.values, model.node_y.values
    along, across = c * x + s * y, -s * x + c * y
    start = np.concatenate(([0], np.cumsum(counts)[:-1]))
    length = np.maximum.reduceat(along, start) - np.minimum.reduceat(along, start)
    height = np.maximum.reduceat(across, start) - np.minimum.reduceat(across, start)
    return length, height


def stress_rotation(angle: np.ndarray) -> np.ndarray:
    """``(n, 3, 3)`` Voigt matrices ``T`` with ``[s_bed_bed, s_nn, s_tn] = T [sxx, syy, sxy]``.

    The local axes are the bed direction (``x'``, at ``angle`` from x) and its normal
    (``y'``); the local ``syy`` is the stress normal to the bed plane and the local
    ``sxx`` the one normal to the head plane, as the JMM's faces read them. ``T^-1`` is
    ``T`` of ``-angle``; strains (engineering shear) turn with ``T^-T``.
    """
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([
        np.stack([c * c, s * s, 2 * c * s], axis=-1),
        np.stack([s * s, c * c, -2 * c * s], axis=-1),
        np.stack([-c * s, c * s, c * c - s * s], axis=-1),
    ], axis=-2)
