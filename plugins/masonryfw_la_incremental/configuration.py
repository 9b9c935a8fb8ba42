"""A wall in a moved configuration, as the arrays ``la``'s programme reads (:class:`masonryfw_la.Wall`).

What does not change through the run (the model's polygons, loads, materials and scales) is read once
into a :class:`Reference`; :func:`wall_at` places the blocks at a pose, finds their contacts again
(:mod:`.contacts`) and gives every contact the friction of the joint between its two blocks (the
smaller of their joints' where they were not in contact in the model), and a joint's cohesion and tensile
strength as long as it has not opened or slid by more than the gap (:func:`intact_joints`: a broken
bond does not heal). Moving supports are placed by the settlement parameter alone and move on at their
velocity in the moved configuration.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import xarray as xr

import masonryfw.plugin_api as mfp
from masonryfw_la import Scales, Wall, wall_scales

from . import motion
from .contacts import Contacts, Polygons, find_contacts

#: A vertex this many gaps inside a face still touches it (steps may leave it at most one gap deeper than before:
#: one that slipped past a gap must be held, not freed, by the next programme).
DEPTH_IN_CONTACT = 5.0


@dataclass(frozen=True)
class Reference:
    """The model's configuration and everything a moved one keeps."""

    wall: Wall
    scales: Scales
    node_x: np.ndarray  # the vertices of the convex pieces of every block (a convex block is its own piece)
    node_y: np.ndarray
    counts: np.ndarray  # (piece,)
    owner: np.ndarray  # (node,) its block
    piece_block: np.ndarray  # (piece,) its block
    ground: np.ndarray  # support blocks: their mutual contacts do not count
    radius: np.ndarray  # (block,) largest distance of a vertex from the centroid [m]
    unit_height: float  # median height of the masonry units [m]: the length steps are measured in
    model: xr.Dataset  # where the joints' relative motion is measured (``mfp.relative_motion``)
    joints: mfp.PairIndex  # the model's interfaces, found by their two blocks
    block_friction: np.ndarray  # the smallest friction of a block's joints
    gap: float  # a vertex this far outside a face still touches it [m]
    cornered: np.ndarray  # sorted pair keys of blocks that meet corner to corner in the model

    @property
    def centroid(self) -> np.ndarray:
        return self.wall.centroid

    @property
    def n_block(self) -> int:
        return self.wall.n_block


def reference(model: xr.Dataset, gap_share: float) -> Reference:
    """The :class:`Reference` of ``model``; contacts within ``gap_share`` of the median unit height."""
    wall = Wall.from_model(model)
    counts = model.block_node_count.values.astype(np.int64)
    owner = np.repeat(np.arange(counts.size), counts)
    x, y = model.node_x.values.astype(float), model.node_y.values.astype(float)
    radius = np.zeros(counts.size)
    np.maximum.at(radius, owner, np.hypot(x - wall.centroid[owner, 0], y - wall.centroid[owner, 1]))
    masonry = mfp.masonry_blocks(wall.role)
    _, _, ymin, ymax = mfp.block_bounds(x, y, counts)
    unit_height = float(np.median((ymax - ymin)[masonry]))
    block_friction = np.full(counts.size, np.inf)
    for side in (0, 1):
        np.minimum.at(block_friction, wall.sides[:, side], wall.friction)
    block_friction[~np.isfinite(block_friction)] = float(np.median(wall.friction)) if wall.friction.size else 0.0
    ground = mfp.support_blocks(wall.role)
    gap = gap_share * unit_height
    px, py, piece_counts, piece_block = mfp.convex_pieces(x, y, counts)
    at_rest = find_contacts(Polygons.of(px, py, piece_counts), ground, gap, gap, group=piece_block)
    points = at_rest.length <= 2 * gap  # in the model's configuration every contact is a face but a corner on a corner
    cornered = np.unique(mfp.pair_key(at_rest.sides[points], counts.size))
    return Reference(wall, wall_scales(model, wall), px, py, piece_counts, np.repeat(piece_block, piece_counts),
                     piece_block, ground, radius, unit_height, model, mfp.pair_index(wall.sides, counts.size), block_friction, gap, cornered)


def model_joint(ref: Reference, sides: np.ndarray) -> np.ndarray:
    """The model's interface between each contact's two blocks, -1 where they had none."""
    return mfp.find_pairs(ref.joints, sides)


def intact_joints(ref: Reference, pose: np.ndarray, intact: np.ndarray) -> np.ndarray:
    """The model's joints still intact at ``pose``: intact before and opened or slid by no more than the gap at
    either end (a bond that broke does not heal)."""
    if not intact.any():
        return intact
    opening, slip = mfp.relative_motion(ref.model, pose, "finite")
    return intact & (np.hypot(np.maximum(opening, 0.0), slip).max(axis=1) <= ref.gap)


def still_cornered(ref: Reference, pose: np.ndarray) -> np.ndarray:
    """The pairs that met corner to corner in the model and have not moved apart since (their relative motion
    under the gap): they have no contact, as in the model; once they move, their corners hold each other."""
    a, b = np.divmod(ref.cornered, ref.n_block)
    relative = pose[a] - pose[b]
    shift = np.hypot(relative[:, 0], relative[:, 1]) + np.abs(relative[:, 2]) * np.maximum(ref.radius[a],
                                                                                         ref.radius[b])
    return ref.cornered[shift < ref.gap]


def wall_at(ref: Reference, pose: np.ndarray, intact: np.ndarray) -> tuple[Wall, Contacts]:
    """The wall with every block at ``pose`` ``(block, 3)`` and its contacts found again; a contact on a model's
    joint still ``intact`` keeps that joint's cohesion and tensile strength (the contact is the whole joint)."""
    x, y = motion.vertices(pose, ref.centroid, ref.node_x, ref.node_y, ref.owner)
    contacts = find_contacts(Polygons.of(x, y, ref.counts), ref.ground, ref.gap, DEPTH_IN_CONTACT * ref.gap,
                             still_cornered(ref, pose), group=ref.piece_block)
    joint = model_joint(ref, contacts.sides)
    bonded = (joint >= 0) & intact[np.maximum(joint, 0)]
    direction = np.where(ref.wall.moving[:, None], motion.current_twist(ref.wall.direction, pose), 0.0)
    wall = dataclasses.replace(
        ref.wall,
        direction=direction,
        settlement_weights=direction,
        centroid=ref.centroid + pose[:, :2],
        node_x=x,
        node_y=y,
        sides=contacts.sides,
        end_x=contacts.end_x,
        end_y=contacts.end_y,
        normal=contacts.normal,
        tangent=contacts.tangent,
        length=contacts.length,
        friction=np.where(joint >= 0, ref.wall.friction[joint],
                          np.minimum(ref.block_friction[contacts.sides[:, 0]], ref.block_friction[contacts.sides[:, 1]])),
        cohesion=np.where(bonded, ref.wall.cohesion[joint], 0.0),
        tensile_strength=np.where(bonded, ref.wall.tensile_strength[joint], 0.0),
    )
    return wall, contacts
