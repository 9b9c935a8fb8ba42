"""A 3D model of masonry standing on ground blocks that follow a settlement profile: what a building laid from a
spec (:mod:`masonryfw.building`) and a drawn 3D model (:mod:`masonryfw.drawing3d`) share once their blocks and
the ground's motions are known.

The masonry comes first, then the ground blocks. A ground block that moves is a moving support carrying the
masonry's weight by its share of the footprint, up as a dead load and the same down as the live load (the
paper's convention, as in 2D); one that does not move is fixed. Interfaces on a ground block are support
joints, the others bed joints when they face up or down and head joints otherwise.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from . import polyhedra
from .errors import SpecError
from .model3d import model_from_polyhedra
from .roles import ROLE
from .spec import Material

KIND = {"bed": 0, "head": 1, "support": 2, "other": 3}


def model_on_ground(poly: polyhedra.Polyhedra, masonry_role: np.ndarray, weight: np.ndarray, ground_motion: np.ndarray,
                    footprint: np.ndarray, material: Material, attrs: dict, tol: float, where: str) -> xr.Dataset:
    """The model of ``poly``'s blocks, the masonry first (its ``masonry_role`` and ``weight`` [N]), then the
    ground (each ground block's motion per unit t and its ``footprint`` area under the masonry); ``where`` names
    the ground in the error of a ground that does not move at all."""
    n, n_masonry = poly.n_block, len(masonry_role)
    ground = np.arange(n) >= n_masonry
    motion = np.zeros((n, 6))
    motion[ground] = ground_motion
    moving = ground & (np.abs(motion).max(axis=1) > 0)
    if not moving.any():
        raise SpecError(f"spec table 'settlement': the ground settles at most the profile's cutoff times S_max under "
                        f"every {where}: nothing settles under it (move the profile's axis under it, center_x and "
                        "center_y, or lower the cutoff)")
    role = np.r_[masonry_role, np.where(moving[ground], ROLE["moving_support"], ROLE["fixed_support"])].astype(np.int8)
    motion[~moving] = 0.0
    share = np.r_[np.zeros(n_masonry), np.sum(weight) * footprint / np.sum(footprint)]
    dead = np.zeros((n, 3))
    live = np.zeros((n, 3))
    dead[:n_masonry, 2] = -np.asarray(weight)
    dead[moving, 2] = share[moving]  # the paper's convention: up the weight it carries uniformly, the same down live
    live[moving, 2] = -share[moving]
    fixed = np.zeros((n, 6), dtype=np.int8)
    fixed[ground & ~moving] = 1
    contacts = polyhedra.find_contacts(poly, tol)
    normal_z = np.abs(contacts.normal[:, 2])
    support = ground[contacts.sides].any(axis=1)
    kind = np.where(support, KIND["support"], np.where(normal_z > 0.5, KIND["bed"], KIND["head"])).astype(np.int8)
    m = contacts.n_interface
    arrays = {"block_role": role, "block_unit_weight": np.where(ground, 0.0, material.unit_weight),
              "interface_kind": kind, "interface_friction": np.full(m, material.friction),
              "interface_cohesion": np.full(m, material.cohesion),
              "interface_tensile_strength": np.full(m, material.tensile_strength),
              "dead_load": dead, "dead_moment": np.zeros((n, 3)), "live_load": live, "live_moment": np.zeros((n, 3)),
              "block_fixed": fixed, "settlement_direction": motion + 0.0}
    for name in ("young_modulus", "poisson_ratio"):
        value = getattr(material, name)
        if value is not None:
            arrays[f"block_{name}"] = np.full(n, value)
    return model_from_polyhedra(poly, contacts, arrays, attrs)


def plane_motion(down: np.ndarray, horizontal: np.ndarray, points: np.ndarray, centre: np.ndarray, depth: float
                 ) -> np.ndarray:
    """``(6,)``: the rigid motion per unit t, at the centroid ``depth / 2`` below ``centre`` (the middle of its top
    face, in plan), of a ground block whose top face's vertices ``points`` (n, 2, not all on a line) the ground
    moves ``down`` and ``horizontal`` (n, 2): the plane through the settlements by least squares (exact where
    they lie in one), sideways by their mean."""
    offsets = points - centre
    design = np.c_[np.ones(len(points)), offsets]
    (mean, slope_x, slope_y), *_ = np.linalg.lstsq(design, down, rcond=None)
    rotation = np.array([-slope_y, slope_x, 0.0])  # uz = -down: d(uz)/dy = rx, d(uz)/dx = -ry
    top = np.r_[horizontal.mean(axis=0), -mean]
    return np.r_[top + np.cross(rotation, [0.0, 0.0, -0.5 * depth]), rotation]
