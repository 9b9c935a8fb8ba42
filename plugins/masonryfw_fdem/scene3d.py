"""Rigid polyhedra as the 3D kernels take them (:mod:`.kernels3d`; the 2D scene is :mod:`.scene`): the blocks'
shapes, masses and inertia from their polyhedra, the first state, and the face pairs found at a state with the
contact histories carried over from the pairs before.

The kernels work in the units they are given; a scene made from a model is non-dimensional as in 2D
(lengths over the model's size, forces over its weight, time over ``sqrt(length / g)``).
"""
from __future__ import annotations

import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp

from . import kernels
from .kernels3d import MAX_FACE_VERTICES, Bodies3, Motion3, Pairs3, detect_face_pairs3, place_vertices3


def bodies_of(poly: mfp.Polyhedra, unit_weight: np.ndarray, driven: np.ndarray, moving: np.ndarray,
              direction: np.ndarray) -> Bodies3:
    """The :class:`.kernels3d.Bodies3` of the polyhedra ``poly`` weighing ``unit_weight`` a volume (their mass,
    with ``g`` = 1), ``driven`` (supports) moving as ``direction`` (block, 6) per unit settlement."""
    volume, centroid = mfp.volumes_centroids(poly)
    if np.any(poly.face_node_count > MAX_FACE_VERTICES):
        face = int(np.argmax(poly.face_node_count > MAX_FACE_VERTICES))
        raise mf.SolveError(f"fdem: block {int(poly.face_block()[face])} has a face of "
                             f"{int(poly.face_node_count[face])} vertices (at most {MAX_FACE_VERTICES})")
    unit_weight = np.broadcast_to(np.asarray(unit_weight, dtype=float), volume.shape)
    mass = unit_weight * volume
    moments = unit_weight[:, None, None] * mfp.second_moments(poly)
    inertia = np.trace(moments, axis1=1, axis2=2)[:, None, None] * np.eye(3) - moments
    free = ~np.asarray(driven, dtype=bool)
    inv_inertia = np.zeros_like(inertia)
    inv_inertia[free] = np.linalg.inv(inertia[free])
    owner = np.repeat(np.arange(poly.n_block), poly.block_node_count)
    local = poly.vertices - centroid[owner]
    radius = np.zeros(poly.n_block)
    np.maximum.at(radius, owner, np.linalg.norm(local, axis=1))
    return Bodies3(centroid, radius, local, mfp.block_offsets(poly.block_node_count),
                   mfp.block_offsets(poly.block_face_count), mfp.block_offsets(poly.face_node_count),
                   poly.face_vertex_index().astype(np.int64), poly.face_block().astype(np.int64), mass, inertia,
                   inv_inertia, np.asarray(driven, dtype=bool), np.asarray(moving, dtype=bool),
                   np.asarray(direction, dtype=float))


def at_rest(bodies: Bodies3) -> Motion3:
    """Every block at its rest position and orientation, still."""
    n = bodies.pos0.shape[0]
    quat = np.zeros((n, 4))
    quat[:, 0] = 1.0
    return Motion3(bodies.pos0.copy(), quat, np.zeros((n, 3)), np.zeros((n, 3)), bodies.pos0.copy(), quat.copy(),
                   np.zeros(kernels.N_ACC))


def world_vertices(bodies: Bodies3, motion: Motion3) -> np.ndarray:
    """Every vertex's position at ``motion``."""
    world = np.empty_like(bodies.vertices)
    place_vertices3(motion.pos, motion.quat, bodies, world)
    return world


def face_pairs(bodies: Bodies3, motion: Motion3, buffer: float, max_penetration: float, min_cos: float
               ) -> np.ndarray:
    """(pair, 2) the face pairs at ``motion``: blocks whose boxes come within ``buffer`` (core's broad phase; none
    between two supports), then faces that face each other (:func:`.kernels3d.detect_face_pairs3`)."""
    world = world_vertices(bodies, motion)
    low = np.minimum.reduceat(world, bodies.vertex_offs[:-1], axis=0)
    high = np.maximum.reduceat(world, bodies.vertex_offs[:-1], axis=0)
    a, b = mfp.box_pairs(low, high, buffer)
    keep = ~(bodies.driven[a] & bodies.driven[b])
    return detect_face_pairs3(bodies, world, np.c_[a[keep], b[keep]].astype(np.int64), buffer, max_penetration,
                              min_cos)


def new_pairs(bodies: Bodies3, faces: np.ndarray, props: np.ndarray, bonded_start: np.ndarray,
              old: Pairs3 | None = None) -> Pairs3:
    """The :class:`.kernels3d.Pairs3` of ``faces`` with their ``props`` (pair, 3); a pair that was in ``old``
    keeps its points' histories, a new one starts with its points bonded where ``bonded_start`` says."""
    counts = np.diff(bodies.face_offs)
    most = int((counts[faces[:, 0]] + counts[faces[:, 1]]).max(initial=3))
    keys = np.full((faces.shape[0], most), -1, dtype=np.int64)
    shear = np.zeros((faces.shape[0], most, 3))
    bonded = np.repeat(np.asarray(bonded_start, dtype=np.int64)[:, None], most, axis=1)
    if old is not None and old.faces.size and faces.size:
        n_face = bodies.face_offs.size - 1
        before = old.faces[:, 0] * n_face + old.faces[:, 1]
        order = np.argsort(before)
        now = faces[:, 0] * n_face + faces[:, 1]
        at = np.clip(np.searchsorted(before[order], now), 0, before.size - 1)
        kept = before[order][at] == now
        source = order[at[kept]]
        width = min(most, old.keys.shape[1])
        keys[kept, :width] = old.keys[source, :width]
        shear[kept, :width] = old.shear[source, :width]
        bonded[kept, :width] = old.bonded[source, :width]
    return Pairs3(faces, np.asarray(props, dtype=float), keys, shear, bonded, np.zeros((faces.shape[0], most)))
