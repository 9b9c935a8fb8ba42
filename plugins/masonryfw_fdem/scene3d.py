"""Rigid polyhedra as the 3D kernels take them (:mod:`.kernels3d`; the 2D scene is :mod:`.scene`): a 3D model
made non-dimensional (:func:`build_scene3`), the blocks' shapes, masses and inertia from their polyhedra, the
first state, and the face pairs found at a state with the contact histories carried over from the pairs before.

Units as in 2D: lengths over the model's size, forces over the masonry's weight, time over ``sqrt(length / g)``;
masses are weight shares, so gravity has unit acceleration. Cohesion and tensile strength are per area
(``c length^2 / W``), the contact stiffness per area and per length of penetration.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from . import kernels
from .kernels3d import (
    MAX_FACE_VERTICES,
    Bodies3,
    Motion3,
    Pairs3,
    detect_corners3,
    detect_edges3,
    detect_face_pairs3,
    place_vertices3,
)
from .scene import GRAVITY, Scales, Scene, build_scene


@dataclass
class Scene3:
    """A 3D model's blocks and joints, non-dimensional (module docstring), the 2D :class:`.scene.Scene`'s
    counterpart."""

    DOFS = 6  # a block's force and moment components
    VERTICAL = 2  # the up component

    scales: Scales
    model: xr.Dataset  # the checked model the scene was built from
    bodies: Bodies3
    dead: np.ndarray  # (block, 6) dead load on free blocks (force, moment about the centroid)
    live: np.ndarray  # (block, 6)
    unit_height: float  # median height of the masonry blocks
    support_area: float  # area of the masonry's contact with the supports
    joints: mfp.PairIndex  # the model's interfaces, found by their two blocks
    friction: np.ndarray  # (interface,)
    cohesion: np.ndarray  # (interface,) per area
    tension: np.ndarray  # (interface,) per area
    default_friction: float

    @property
    def pos0(self) -> np.ndarray:
        return self.bodies.pos0

    @property
    def radius(self) -> np.ndarray:
        return self.bodies.radius

    @property
    def driven(self) -> np.ndarray:
        return self.bodies.driven

    @property
    def moving(self) -> np.ndarray:
        return self.bodies.moving

    @property
    def direction(self) -> np.ndarray:
        """(block, 6) every moving support's motion per unit (non-dimensional) settlement, 0 for the others."""
        return self.bodies.direction

    @property
    def base_pressure(self) -> float:
        """The masonry's weight over its contact area with the supports."""
        return 1.0 / self.support_area

    def masonry_height(self) -> float:
        """Top of the highest minus bottom of the lowest free block's vertex."""
        owner = np.repeat(np.arange(self.driven.size), np.diff(self.bodies.vertex_offs))
        z = (self.bodies.pos0[owner, 2] + self.bodies.vertices[:, 2])[~self.driven[owner]]
        return float(np.ptp(z))

    def critical_time_step(self, kn: float) -> float:
        """2 / omega_max over the free blocks, each held by springs of ``kn`` per area (normal and shear alike,
        an upper bound for ``kt <= kn``) over its whole surface, a face's at its vertices (an equal share each,
        as the contact points carry it): omega^2 the largest eigenvalue of ``M^-1 K`` (:func:`block_stiffness`)
        over its mass and inertia, doubled (a spring joins two blocks that can move against each other).
        Bounding translation by ``kn S / m`` and rotation by ``kn S R^2 / I_min`` instead (the 2D bound's form)
        took 1.5-7x the planar run's steps on the bundled walls' twins (this bound: 1.6-1.75x); without the
        doubling Test 12C's twin blew up."""
        free = np.flatnonzero(~self.driven)
        if free.size == 0:
            return np.inf
        mass = np.zeros((free.size, 6, 6))
        mass[:, :3, :3] = self.bodies.mass[free, None, None] * np.eye(3)
        mass[:, 3:, 3:] = self.bodies.inertia[free]
        # twice: a spring joins two blocks, and in the highest mode its neighbours move against it (Gershgorin)
        largest = 2.0 * np.linalg.eigvals(np.linalg.solve(mass, kn * block_stiffness(self)[free])).real.max()
        return 2.0 / np.sqrt(largest) if largest > 0 else np.inf


def block_stiffness(scene: Scene3) -> np.ndarray:
    """(block, 6, 6) each block's stiffness under unit springs per area over its whole surface, a face's area
    shared equally by its vertices: ``K = sum a B^T B``, ``B = [I, -[r]x]`` at a vertex r from the centroid."""
    poly = polyhedra(scene)
    _, area, _ = mfp.face_normals_areas(poly)
    vertex = poly.face_vertex_index()
    share = np.repeat(area / poly.face_node_count, poly.face_node_count)
    block = np.repeat(poly.face_block(), poly.face_node_count)
    r = scene.bodies.vertices[vertex]
    skew = np.zeros((r.shape[0], 3, 3))
    skew[:, 0, 1], skew[:, 0, 2], skew[:, 1, 2] = -r[:, 2], r[:, 1], -r[:, 0]
    skew -= skew.transpose(0, 2, 1)
    b = np.concatenate([np.broadcast_to(np.eye(3), skew.shape), -skew], axis=2)  # (vertex, 3, 6)
    stiffness = np.zeros((scene.driven.size, 6, 6))
    np.add.at(stiffness, block, share[:, None, None] * np.einsum("vij,vik->vjk", b, b))
    return stiffness


def with_rotation_scaled(scene: Scene3) -> Scene3:
    """``scene`` with each free block's inertia tensor times the factor (at least 1) that brings its rotation's
    highest frequency down to the highest translational one of any block (:func:`block_stiffness`), so the time
    step is translation's. A box's corners hold its rotation three times as stiffly as its translation (per
    mass), so the physical inertia takes sqrt(3) as many steps. The masses, the loads and the static
    equilibria are unchanged; only how fast a block turns when it is out of balance changes, which a
    quasi-static run does not depend on (docs/fdem.md, "In 3D", checked on the house, the corner building,
    the twins and against LMGC90)."""
    free = np.flatnonzero(~scene.driven)
    if free.size == 0:
        return scene
    stiffness = block_stiffness(scene)[free]
    translation = np.linalg.eigvalsh(stiffness[:, :3, :3]).max(axis=1) / scene.bodies.mass[free]
    rotation = np.linalg.eigvals(np.linalg.solve(scene.bodies.inertia[free], stiffness[:, 3:, 3:])).real.max(axis=1)
    factor = np.ones(scene.driven.size)
    factor[free] = np.maximum(rotation / translation.max(), 1.0)
    bodies = scene.bodies._replace(inertia=scene.bodies.inertia * factor[:, None, None],
                                   inv_inertia=scene.bodies.inv_inertia / factor[:, None, None])
    return replace(scene, bodies=bodies)


def polyhedra(scene: Scene3) -> mfp.Polyhedra:
    """The scene's blocks at rest as polyhedra (non-dimensional)."""
    poly = mfp.polyhedra_of(scene.model)
    return poly._replace(vertices=poly.vertices / scene.scales.length)


def build_scene3(model: xr.Dataset) -> Scene3:
    """The non-dimensional :class:`Scene3` of a checked 3D ``model``; raises ModelError on what the method cannot
    take (masonry without weight)."""
    role = model.block_role.values.astype(np.int64)
    driven = mfp.support_blocks(role)
    moving = mfp.moving_blocks(role)
    poly = mfp.polyhedra_of(model)
    weight = model.block_unit_weight.values * model.block_volume.values
    total = float(weight[~driven].sum())
    if not total > 0:
        raise mf.ModelError("block_unit_weight: the masonry blocks weigh nothing; fdem needs their masses")
    weightless = np.flatnonzero(~driven & ~(weight > 0))
    if weightless.size:
        raise mf.ModelError(f"block(s) {mfp.listed(weightless)}: block_unit_weight * volume is not positive; a free "
                            "block needs a mass in fdem")
    length = float(np.linalg.norm(np.ptp(poly.vertices, axis=0))) or 1.0  # the bounding box's diagonal
    scales = Scales(length=length, force=total, time=float(np.sqrt(length / GRAVITY)))
    unit_weight = model.block_unit_weight.values * length**3 / total
    direction = model.settlement_direction.values.astype(float).copy()
    direction[:, 3:] *= length
    direction[~moving] = 0.0
    bodies = bodies_of(poly._replace(vertices=poly.vertices / length), unit_weight, driven, moving, direction)
    load_scale = np.array([total] * 3 + [total * length] * 3)
    dead = np.where(driven[:, None], 0.0, mfp.block_loads(model, "dead") / load_scale)
    live = np.where(driven[:, None], 0.0, mfp.block_loads(model, "live") / load_scale)
    z = poly.vertices[:, 2] / length
    height = np.maximum.reduceat(z, bodies.vertex_offs[:-1]) - np.minimum.reduceat(z, bodies.vertex_offs[:-1])
    sides = model.interface_blocks.values.astype(np.int64)
    on_support = driven[sides].any(axis=1) & ~driven[sides].all(axis=1)
    area = model.interface_area.values / length**2
    support_area = float(area[on_support].sum())
    if not support_area > 0:
        raise mf.ModelError("fdem: no masonry rests on a support (no interface between a support and the masonry)")
    per_area = length**2 / total
    friction = model.interface_friction.values.astype(float)
    return Scene3(scales, model, bodies, dead, live, float(np.median(height[~driven])), support_area,
                  mfp.pair_index(sides, role.size), friction, model.interface_cohesion.values * per_area,
                  model.interface_tensile_strength.values * per_area,
                  float(np.median(friction)) if friction.size else 0.0)


def face_properties3(scene: Scene3, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(pair, 3) friction, cohesion and tensile strength per area of each face pair, and whether it starts bonded:
    a pair between blocks that share a model interface takes its properties, others the model's median friction
    and no strength (the 2D rule, :func:`.scene.face_properties`)."""
    block = scene.bodies.face_block[faces] if faces.size else np.zeros((0, 2), dtype=np.int64)
    props = block_pair_properties(scene, block)
    return props, (props[:, 1] > 0) | (props[:, 2] > 0)


def block_pair_properties(scene: Scene3, block: np.ndarray) -> np.ndarray:
    """(k, 3) friction, cohesion and tensile strength per area between the (k, 2) blocks: their model
    interface's, or the model's median friction and no strength."""
    joint = mfp.find_pairs(scene.joints, block)
    hit = joint >= 0
    at = np.maximum(joint, 0)
    props = np.c_[np.where(hit, scene.friction[at] if scene.friction.size else 0.0, scene.default_friction),
                  np.where(hit, scene.cohesion[at] if scene.cohesion.size else 0.0, 0.0),
                  np.where(hit, scene.tension[at] if scene.tension.size else 0.0, 0.0)]
    return props


def friction_between3(scene: Scene3, blocks: np.ndarray) -> np.ndarray:
    """(k,) the friction coefficient of a corner or edge contact between the blocks ``(k, 2)``: their model
    interface's, or the model's median (:func:`face_properties3`'s rule)."""
    return block_pair_properties(scene, blocks.reshape(-1, 2))[:, 0]


def bodies_of(poly: mfp.Polyhedra, unit_weight: np.ndarray, driven: np.ndarray, moving: np.ndarray,
              direction: np.ndarray) -> Bodies3:
    """The :class:`.kernels3d.Bodies3` of the polyhedra ``poly`` weighing ``unit_weight`` a volume (their mass,
    with ``g`` = 1), ``driven`` (supports) moving as ``direction`` (block, 6) per unit settlement."""
    volume, centroid = mfp.volumes_centroids(poly)
    if np.any(poly.face_node_count > MAX_FACE_VERTICES):
        face = int(np.argmax(poly.face_node_count > MAX_FACE_VERTICES))
        raise mf.SolveError(f"fdem: block {int(poly.face_block()[face])} has a face of "
                             f"{int(poly.face_node_count[face])} vertices (at most {MAX_FACE_VERTICES})")
    refuse_non_convex_faces(poly)
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
    _, face_area, _ = mfp.face_normals_areas(poly)
    surface = np.bincount(poly.face_block(), weights=face_area, minlength=poly.n_block)
    return Bodies3(centroid, radius, local, mfp.block_offsets(poly.block_node_count),
                   mfp.block_offsets(poly.block_face_count), mfp.block_offsets(poly.face_node_count),
                   poly.face_vertex_index().astype(np.int64), poly.face_block().astype(np.int64), mass, inertia,
                   inv_inertia, np.asarray(driven, dtype=bool), np.asarray(moving, dtype=bool),
                   np.asarray(direction, dtype=float), surface / (3.0 * poly.block_node_count), convex_blocks(poly),
                   *block_edges(poly))


def block_edges(poly: mfp.Polyhedra) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every block's edges (edge, 2: global vertex numbers, block after block), the two faces each one joins
    (edge, 2) and the blocks' offsets into them. A side shared by other than two faces (a vertex of one face
    on another's side) is not an edge of a convex block's and is left out."""
    index = poly.face_vertex_index().astype(np.int64)
    following = index[mfp.next_node(poly.face_node_count)]
    face = np.repeat(np.arange(poly.face_node_count.size), poly.face_node_count)
    low, high = np.minimum(index, following), np.maximum(index, following)
    n_vertex = max(poly.vertices.shape[0], 1)
    key = low * n_vertex + high
    order = np.argsort(key, kind="stable")
    unique, first, count = np.unique(key[order], return_index=True, return_counts=True)
    kept = count == 2
    sides = order[first[kept]]
    edges = np.c_[low[sides], high[sides]]
    faces = np.c_[face[order[first[kept]]], face[order[first[kept] + 1]]]
    block = poly.face_block()[faces[:, 0]]
    by_block = np.argsort(block, kind="stable")
    counts = np.bincount(block, minlength=poly.n_block)
    return edges[by_block], faces[by_block], mfp.block_offsets(counts)


def convex_blocks(poly: mfp.Polyhedra) -> np.ndarray:
    """(block,) whether each block lies behind every one of its faces' planes (to 1e-9 of its size): convex."""
    normal, _, _ = mfp.face_normals_areas(poly)
    index = poly.face_vertex_index()
    face_point = poly.vertices[index[mfp.block_offsets(poly.face_node_count)[:-1]]]
    face_block = poly.face_block()
    starts = mfp.block_offsets(poly.block_node_count)
    counts = poly.block_node_count[face_block]
    face = np.repeat(np.arange(face_block.size), counts)
    vertex = np.concatenate([np.arange(starts[b], starts[b + 1]) for b in face_block]) if face_block.size else \
        np.zeros(0, dtype=np.int64)
    height = np.einsum("ij,ij->i", poly.vertices[vertex] - face_point[face], normal[face])
    size = np.ptp(poly.vertices, axis=0).max() if poly.vertices.size else 1.0
    outside = np.zeros(poly.n_block, dtype=bool)
    np.logical_or.at(outside, face_block[face], height > 1e-9 * size)
    return ~outside


def refuse_non_convex_faces(poly: mfp.Polyhedra) -> None:
    """Refuse a face that turns against its normal at a vertex: the face pairs' clipping takes convex faces (the
    format allows non-convex ones; la takes them, fdem in 3D does not yet)."""
    normal, area, _ = mfp.face_normals_areas(poly)
    index = poly.face_vertex_index()
    following = mfp.next_node(poly.face_node_count)
    edge = poly.vertices[index[following]] - poly.vertices[index]
    turn = np.einsum("ij,ij->i", np.cross(edge, edge[following]), np.repeat(normal, poly.face_node_count, axis=0))
    size = np.repeat(area, poly.face_node_count)
    bad = np.flatnonzero(turn < -1e-9 * size)
    if bad.size:
        face = int(np.repeat(np.arange(poly.face_node_count.size), poly.face_node_count)[bad[0]])
        raise mf.ModelError(f"block {int(poly.face_block()[face])}: face {face} is not convex; fdem in 3D takes "
                            "convex faces (split the face, or solve with la)")


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


def contacts(bodies: Bodies3, motion: Motion3, buffer: float, max_penetration: float, min_cos: float
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The contacts at ``motion`` of blocks whose boxes come within ``buffer`` (core's broad phase; none between two
    supports): (pair, 2) the face pairs, faces that face each other (:func:`.kernels3d.detect_face_pairs3`), and of
    the blocks that have none (a block turned past ``max_contact_angle``) (corner, 3) the corner contacts, a corner
    against a face (:func:`.kernels3d.detect_corners3`), and (edge contact, 4) the edge contacts, an edge across an
    edge (:func:`.kernels3d.detect_edges3`)."""
    world = world_vertices(bodies, motion)
    low = np.minimum.reduceat(world, bodies.vertex_offs[:-1], axis=0)
    high = np.maximum.reduceat(world, bodies.vertex_offs[:-1], axis=0)
    a, b = mfp.box_pairs(low, high, buffer)
    keep = ~(bodies.driven[a] & bodies.driven[b])
    blocks = np.c_[a[keep], b[keep]].astype(np.int64)
    faces = detect_face_pairs3(bodies, world, blocks, buffer, max_penetration, min_cos)
    n = bodies.pos0.shape[0]
    joined = np.isin(mfp.pair_key(blocks, n), mfp.pair_key(bodies.face_block[faces], n))
    return (faces, detect_corners3(bodies, world, blocks, joined, buffer, max_penetration, buffer),
            detect_edges3(bodies, world, motion.pos, blocks, joined, buffer, max_penetration, buffer))


def rows_before(before: np.ndarray, now: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Which of the keys ``now`` were among ``before`` (a mask of ``now``) and their rows there."""
    order = np.argsort(before)
    at = np.clip(np.searchsorted(before[order], now), 0, before.size - 1)
    kept = before[order][at] == now
    return kept, order[at[kept]]


def new_pairs(bodies: Bodies3, faces: np.ndarray, props: np.ndarray, bonded_start: np.ndarray,
              corners: np.ndarray, corner_friction: np.ndarray, edges: np.ndarray, edge_friction: np.ndarray,
              old: Pairs3 | None = None) -> Pairs3:
    """The :class:`.kernels3d.Pairs3` of ``faces`` with their ``props`` (pair, 3) and of the ``corners`` and
    ``edges`` with their friction coefficients; a pair that was in ``old`` keeps its points' histories, a new one
    starts with its points bonded where ``bonded_start`` says; a corner or edge contact that was in ``old`` keeps
    its shear spring."""
    counts = np.diff(bodies.face_offs)
    most = int((counts[faces[:, 0]] + counts[faces[:, 1]]).max(initial=3))
    held = np.full((faces.shape[0], most), -1, dtype=np.int64)
    points = np.zeros((faces.shape[0], most, 3))
    shear = np.zeros((faces.shape[0], most, 3))
    bonded = np.repeat(np.asarray(bonded_start, dtype=np.int64)[:, None], most, axis=1)
    if old is not None and old.faces.size and faces.size:
        n_face = bodies.face_offs.size - 1
        kept, source = rows_before(old.faces[:, 0] * n_face + old.faces[:, 1], faces[:, 0] * n_face + faces[:, 1])
        width = min(most, old.held.shape[1])
        for mine, theirs in ((held, old.held), (points, old.points), (shear, old.shear), (bonded, old.bonded)):
            mine[kept, :width] = theirs[source, :width]
    corner_shear = np.zeros((corners.shape[0], 3))
    if old is not None and old.corners.size and corners.size:
        n = bodies.pos0.shape[0]
        kept, source = rows_before(old.corners[:, 0] * n + old.corners[:, 2], corners[:, 0] * n + corners[:, 2])
        corner_shear[kept] = old.corner_shear[source]
    edge_shear = np.zeros((edges.shape[0], 3))
    if old is not None and old.edges.size and edges.size:
        n_edge = bodies.edges.shape[0]
        kept, source = rows_before(old.edges[:, 0] * n_edge + old.edges[:, 2], edges[:, 0] * n_edge + edges[:, 2])
        edge_shear[kept] = old.edge_shear[source]
    return Pairs3(faces, np.asarray(props, dtype=float), held, points, shear, bonded,
                  np.zeros((faces.shape[0], most)), np.full(faces.shape[0], -1, dtype=np.int64),
                  np.zeros((faces.shape[0], most)), np.zeros((faces.shape[0], 7)), corners.astype(np.int64),
                  np.asarray(corner_friction, dtype=float), corner_shear, edges.astype(np.int64),
                  np.asarray(edge_friction, dtype=float), edge_shear)


def scene_of(model: xr.Dataset, options: Mapping[str, Any]) -> Scene | Scene3:
    """The scene of ``model``, made once (the estimate's, then the solve's): blocks in the plane, or polyhedra
    (their rotation's inertia scaled where ``options`` say, :func:`with_rotation_scaled`)."""
    if mfp.space(model) == 3:
        scene = mfp.made_once(model, "fdem scene 3d", build_scene3)
        return with_rotation_scaled(scene) if options["rotational_inertia"] == "scaled" else scene
    return mfp.made_once(model, "fdem scene", build_scene)
