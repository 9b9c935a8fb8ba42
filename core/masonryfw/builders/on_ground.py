"""A 3D model of masonry standing on ground blocks that follow a settlement profile: what a building laid from a
spec (:mod:`masonryfw.builders.building`) and a drawn 3D model (:mod:`masonryfw.builders.drawn3d`) share once their blocks and
the ground's motions are known.

The masonry comes first, then the ground blocks. A ground block that moves is a moving support carrying the
weight of the masonry standing on it: the masonry's weight W times the area of its contact with the masonry
over the contact area of all the ground, ``W A_s / A_total``, up as a dead load and the same down as the live
load (the paper's convention, the 2D rule with contact areas for contact lengths: docs/format.md); a ground
block under a door touches no masonry and carries nothing. One that does not move is fixed. Interfaces on a
ground block are support joints, the others bed joints when they face up or down and head joints otherwise.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
import xarray as xr

from ..format.model3d import model_from_polyhedra
from ..format.roles import ROLE
from ..format.schema import flags
from ..geometry import polyhedra
from ..readers.spec import Material
from ..runtime.errors import SpecError
from .blocks import carried_weight


def model_on_ground(poly: polyhedra.Polyhedra, masonry_role: np.ndarray, weight: np.ndarray, ground_motion: np.ndarray,
                    material: Material, attrs: dict, tol: float, where: str, label: Callable[[int], str]
                    ) -> xr.Dataset:
    """The model of ``poly``'s blocks, the masonry first (its ``masonry_role`` and ``weight`` [N]), then the
    ground (each ground block's motion per unit t); ``where`` names the ground in the error of a ground that does
    not move at all, ``label(block)`` a masonry block in the error of blocks that the ground does not carry."""
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
    contacts = polyhedra.find_contacts(poly, tol)
    refuse_unconnected(contacts.sides, n_masonry, n, label)
    share = carried_weight(np.sum(weight), support_contact_areas(contacts, ground), moving)
    dead = np.zeros((n, 3))
    live = np.zeros((n, 3))
    dead[:n_masonry, 2] = -np.asarray(weight)
    dead[moving, 2] = share[moving]  # the paper's convention (carried_weight): up, the same down as live load
    live[moving, 2] = -share[moving]
    fixed = np.zeros((n, 6), dtype=np.int8)
    fixed[ground & ~moving] = 1
    normal_z = np.abs(contacts.normal[:, 2])
    support = ground[contacts.sides].any(axis=1)
    kind = flags("interface_kind")
    kind = np.where(support, kind["support"], np.where(normal_z > 0.5, kind["bed"], kind["head"])).astype(np.int8)
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


def support_contact_areas(contacts: polyhedra.Contacts, ground: np.ndarray) -> np.ndarray:
    """``(block,)``: the area of each ground block's contacts with the masonry (0 for the masonry, and for ground
    that touches none)."""
    on_ground = ground[contacts.sides]
    masonry_on = on_ground.any(axis=1) & ~on_ground.all(axis=1)
    support = np.where(on_ground[:, 0], contacts.sides[:, 0], contacts.sides[:, 1])[masonry_on]
    area = np.bincount(support, weights=contacts.area[masonry_on], minlength=ground.size)
    return area


def refuse_unconnected(sides: np.ndarray, n_masonry: int, n: int, label: Callable[[int], str]) -> None:
    """Refuse masonry blocks that no chain of contacts joins to the ground (the blocks ``n_masonry`` on): a block
    touching nothing, or a group of blocks touching only each other, would fall; the first few are named."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    ground = np.arange(n_masonry, n)
    edges = np.r_[sides, np.c_[np.full(max(ground.size - 1, 0), n_masonry), ground[1:]]]  # the ground as one body
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    _, piece = connected_components(graph, directed=False)
    loose = np.flatnonzero(piece[:n_masonry] != piece[n_masonry]) if ground.size else np.arange(n_masonry)
    if loose.size:
        touching = np.bincount(sides.ravel(), minlength=n)[loose] > 0
        what = "touches nothing" if not touching[0] else "touches only blocks that do not reach the ground"
        names = "; ".join(label(int(b)) for b in loose[:3]) + (f" and {loose.size - 3} more" if loose.size > 3 else "")
        raise SpecError(f"{names}: {what}: {loose.size} block(s) the ground does not carry would fall; place them "
                        "on the masonry or leave them out")


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
